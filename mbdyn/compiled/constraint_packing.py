"""Loop joints written as the kernels' primitive constraints (``kernels.constraints``):
each kind as a few points that coincide, vectors that stay perpendicular, a plane a point
stays in, a rod length or a gear ratio.  All vectors are put in body axes here.
"""
from __future__ import annotations

import numpy as np

from ..errors import ModelError
from ..kernels.constraints import COUPLE, DATA, DIST, PERP, POINT, ROWS, SLIDE


def perpendiculars(axis):
    """Two unit vectors completing ``axis`` (unit) to a right-handed triad."""
    helper = np.eye(3)[int(np.argmin(np.abs(axis)))]
    b1 = np.cross(axis, helper)
    b1 /= np.linalg.norm(b1)
    return b1, np.cross(axis, b1)


def primitives(joint, frame_index, model):
    """``[(kind, parent frame, child frame, int a, int b, data[DATA])]`` of one loop joint,
    and the labels of their rows (``"D.x"``, ``"D.perp1"`` ...)."""
    out, labels = [], []
    name = joint.name
    if joint.kind == "coupling":
        frames = []
        for role in ("follower", "leader"):
            jn = getattr(joint, role)
            j = model._joint.get(jn)
            if j is None:
                raise ModelError(f"joint {name!r}: {role} {jn!r} is not a tree joint of the "
                                 f"model (tree joints: {', '.join(model.joints)})") from None
            if j.kind not in ("revolute", "prismatic"):
                raise ModelError(f"joint {name!r}: {role} {jn!r} is a {j.kind} joint; a "
                                 "coupling joins two revolute or prismatic coordinates")
            frames.append(model.frame_index(j.child))
        data = np.zeros(DATA)
        data[12], data[13] = joint.ratio, joint.offset
        return [(COUPLE, -1, -1, frames[0], frames[1], data)], [name]
    ip = frame_index(joint.parent)
    ic = frame_index(joint.child)
    sp, sc = joint.position, joint.child_position
    Cp, Cc = joint.orientation, joint.child_orientation

    def add(kind, A=np.zeros(3), B=np.zeros(3), scalar=0.0, label=""):
        data = np.zeros(DATA)
        data[0:3], data[3:6], data[6:9], data[9:12], data[12] = sp, sc, A, B, scalar
        out.append((kind, ip, ic, 0, 0, data))
        labels.extend([f"{name}.{c}" for c in "xyz"] if kind == POINT else [f"{name}.{label}"])

    kind = joint.kind
    a_p, a_c = Cp @ joint.axis, Cc @ joint.axis
    n1, n2 = perpendiculars(joint.axis)
    if kind in ("revolute", "spherical", "fixed", "universal"):
        add(POINT)
    if kind in ("revolute", "cylindrical"):
        add(PERP, a_p, Cc @ n1, label="perp1")
        add(PERP, a_p, Cc @ n2, label="perp2")
    if kind in ("prismatic", "fixed"):
        e, f = Cp.T, Cc.T                       # rows: the joint frame's axes in body axes
        add(PERP, e[1], f[2], label="rx")       # e2.f3, e3.f1, e1.f2: the three small
        add(PERP, e[2], f[0], label="ry")       # rotations about x, y, z
        add(PERP, e[0], f[1], label="rz")
    if kind in ("prismatic", "cylindrical"):
        add(SLIDE, Cp @ n1, label="slide1")
        add(SLIDE, Cp @ n2, label="slide2")
    if kind == "universal":
        add(PERP, a_p, Cc @ joint.axis2, label="cross")
    if kind == "distance":
        add(DIST, scalar=joint.length, label="length")
    del a_c
    return out, labels


def pack_constraints(model, loop_joints):
    """``(con_int, con_data, row labels, row owner joint, primitive owner)`` of the
    model's loop joints."""
    ints, datas, labels, owners, prim_owner = [], [], [], [], []

    def index(frame):
        return -1 if frame == "ground" else model.frame_index(frame)

    for j in loop_joints:
        prims, lab = primitives(j, index, model)
        for kind, ip, ic, a, b, data in prims:
            ints.append((kind, ip, ic, a, b))
            datas.append(data)
            prim_owner.append(j.name)
            owners.extend([j.name] * ROWS[kind])
        labels.extend(lab)
    con_int = np.array(ints, np.int64).reshape(len(ints), 5)
    con_data = np.array(datas, float).reshape(len(datas), DATA)
    return con_int, con_data, tuple(labels), tuple(owners), tuple(prim_owner)

