"""Force-element records laid out for the compiled kernel (``kernels.forces``).

Called by ``Model`` at compile: resolves frame, joint and speed names to indices and
writes each element's numbers and tables into one float array.
"""
from __future__ import annotations

import numpy as np

from ..errors import ModelError
from ..elements.forces import BEARING_COEFFICIENTS, Table
from ..kernels import forces as kf
from ..kernels.actuation import PROGRAM
from .actuator_packing import law_block, pack_actuator, pack_joint_stop
from .contact_packing import pack_contact
from .states import frame_slot


def speed_slot(model, name, element):
    """Joint-space speed index of a spin speed given by name: a free speed, the coordinate
    of a 1-DoF joint, or a driven joint (its prescribed rate)."""
    if name in model._speed_index:
        return int(model._free_u[model._speed_index[name]])
    for i, j in enumerate(model.elements[1]):
        if j.nu == 1 and (name == j.name or name in j.coordinates):
            return int(model._uoff[i])
    raise ModelError(f"{element}: unknown speed {name!r}; give a speed "
                     f"({', '.join(model.speeds) or 'none'}), the coordinate of a 1-DoF joint, "
                     "or a driven joint's name")


class _Data:
    """The float array being written: each element's numbers and tables, appended."""

    def __init__(self):
        self.values = []

    def put(self, values):
        """Append ``values``; their offset."""
        at = len(self.values)
        self.values.extend(float(v) for v in np.asarray(values, float).reshape(-1))
        return at

    def put_table(self, table):
        """Append a table's block; ``(offset, interpolation mode)``, ``(0, NO_TABLE)``
        for none."""
        if table is None:
            return 0, kf.NO_TABLE
        return self.put(table.block()), table.mode


def pack_forces(model, forces):
    """``(force_int, force_data, laws)`` for the enabled force elements; ``laws`` lists
    ``(element, data index of its force slot, law)`` for the laws evaluated in Python."""
    rows, data, laws = [], _Data(), []
    for el in forces:
        row = [0] * kf.ROW
        what = "actuator" if el.kind == "actuator" else "force"
        _PACKERS[el.kind](model, el, f"{what} {el.name!r}", row, data, laws)
        rows.append(row)
    force_int = np.array(rows, np.int64).reshape(len(rows), kf.ROW)
    force_data = np.array(data.values, float)
    return force_int, force_data, laws


def _two_bodies(model, el, element):
    ia, ib = (frame_slot(model, n, element) for n in el.frames)
    if ia == ib:
        raise ModelError(f"{element}: body_a and body_b are both {el.frames[0]!r}; a "
                         "spring acts between two bodies (or a body and the ground)"
                         if el.kind == "spring-damper" else
                         f"{element}: body_a and body_b are both {el.frames[0]!r}")
    return ia, ib


def _spring_damper(model, el, element, row, data, laws):
    p = el.params
    ia, ib = _two_bodies(model, el, element)
    off = data.put(np.concatenate([p["point_a"], p["point_b"],
                                   [p["stiffness"], p["damping"], p["free_length"],
                                    p["preload"], p["min_length"]]]))
    row[:4] = [kf.SPRING_DAMPER, ia, ib, off]
    row[4:6] = data.put_table(p["force_table"])
    row[6:8] = data.put_table(p["damping_table"])
    _law(row, data, laws, el, off + 9, p.get("law"))


def _joint_spring_damper(model, el, element, row, data, laws):
    p = el.params
    name = p["joint"]
    if name not in model._joint:
        raise ModelError(f"{element}: unknown joint {name!r}; the model's joints are "
                         f"{', '.join(model.joints)}")
    j = model._joint[name]
    if j.kind not in ("revolute", "prismatic"):
        raise ModelError(f"{element}: joint {name!r} is {j.kind}; a joint spring acts "
                         "on the coordinate of a revolute or prismatic joint (use a "
                         "bushing for other joints)")
    i = model._frame_index[j.child]
    off = data.put([p["rest"], p["stiffness"], p["damping"], p["preload"],
                    1.0 if j.kind == "prismatic" else 0.0])
    row[:4] = [kf.JOINT_SPRING_DAMPER, i, int(model._parent[i]), off]
    row[4:6] = data.put_table(p["force_table"])
    row[6:8] = data.put_table(p["damping_table"])
    row[8:10] = [int(model._qoff[i]), int(model._uoff[i])]
    _law(row, data, laws, el, off + 3, p.get("law"))


def _law(row, data, laws, el, slot, law):
    """A force law: compiled (a program, ``kernels.actuation``) when the stack machine can
    evaluate it, else evaluated in Python before each evaluation into ``slot``."""
    if law is None:
        return
    block = law_block(law)
    if block is not None:
        row[4:6] = data.put(block), PROGRAM
    else:
        row[5] = kf.LAW
        laws.append((el, slot, law))


def _bushing(model, el, element, row, data, laws):
    p = el.params
    ia, ib = _two_bodies(model, el, element)
    off = data.put(np.concatenate([p["point_a"], p["point_b"], p["stiffness"].ravel(),
                                   p["damping"].ravel()]))
    row[:4] = [kf.BUSHING, ia, ib, off]


def _bearing(model, el, element, row, data, laws):
    p = el.params
    ia, ib = (frame_slot(model, n, element) for n in el.frames)
    if ia == ib or ia < 0:
        raise ModelError(f"{element}: the shaft body must be a body other than the "
                         "housing")
    fixed = p["speed"] in model.parameters and p["speed"] not in model._speed_index
    if fixed:            # a spin given by a parameter: the coefficients at that speed
        spin = float(model.parameters[p["speed"]])
        consts = [p[c](spin) if isinstance(p[c], Table) else p[c]
                  for c in BEARING_COEFFICIENTS]
    else:
        consts = [0.0 if isinstance(p[c], Table) else p[c] for c in BEARING_COEFFICIENTS]
    off = data.put(np.concatenate([p["point"], p["center"], p["e1"], p["e2"], consts,
                                   -np.ones(8)]))
    mode = kf.NO_TABLE
    for k, c in enumerate(BEARING_COEFFICIENTS):
        if isinstance(p[c], Table) and not fixed:
            data.values[off + 20 + k] = float(data.put(p[c].block()))
            mode = p[c].mode
    slot = -1 if p["speed"] is None or fixed else speed_slot(model, p["speed"], element)
    row[:4] = [kf.BEARING, ia, ib, off]
    row[5] = mode
    row[8] = slot


def _contact(model, el, element, row, data, laws):
    p = el.params
    i = frame_slot(model, el.frames[0], element)
    if i < 0:
        raise ModelError(f"{element}: the ground cannot touch the ground; name a body")
    off = data.put(np.concatenate([p["center"], [p["radius"]], p["plane_point"],
                                   p["plane_normal"],
                                   [p["stiffness"], p["exponent"], p["damping_factor"],
                                    p["friction"], p["slip_speed"]], p["axis"]]))
    kind = kf.CONTACT_DISK if p["shape"] == "disk" else kf.CONTACT_SPHERE
    row[:4] = [kind, i, -1, off]


#: each force-element kind's packer: its row of integers and its numbers in the data
_PACKERS = {"spring-damper": _spring_damper, "joint-spring-damper": _joint_spring_damper,
            "bushing": _bushing, "bearing": _bearing, "contact": _contact,
            "actuator": pack_actuator, "joint-stop": pack_joint_stop,
            "shape-contact": pack_contact}


def warn_outside_tables(model, t, u):
    """Warn when a bearing's spin speed left the range of its coefficient table along a
    motion (times ``t``, free speeds ``u`` row by row): the coefficients are held at the
    table's end values there, which is a guess."""
    import warnings
    from ..errors import ModelWarning
    for el in model._force_elements:
        if el.kind != "bearing" or el.params["speeds"] is None or not len(t):
            continue
        name = el.params["speed"]
        if name in model.speeds:
            spin = np.asarray(u)[:, model.speed_index(name)]
        elif name in model.parameters:            # a constant spin
            spin = np.full(len(t), float(model.parameters[name]))
        else:
            drive = next((d for jn, _, _, d in model._driven
                          if jn == name or name in model._joint[jn].coordinates), None)
            if drive is None:
                continue
            spin = np.array([drive.velocity(tk) for tk in t])
        lo, hi = float(el.params["speeds"][0]), float(el.params["speeds"][-1])
        out = (spin < lo - 1e-12 * abs(lo)) | (spin > hi + 1e-12 * abs(hi))
        if np.any(out):
            k = int(np.argmax(out))
            warnings.warn(f"force {el.name!r}: the spin speed {name} = {spin[k]:.6g} at "
                          f"t = {t[k]:.6g} is outside its coefficient table ({lo:g} .. {hi:g}); "
                          "the coefficients are held at the table's end values there -- "
                          "extend the table to cover the motion", ModelWarning, stacklevel=3)
