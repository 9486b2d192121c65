"""Loop joints written as the kernels' primitive constraints (``kernels.constraints``):
each kind as a few points that coincide, vectors that stay perpendicular, a plane a point
stays in, a rod length or a gear ratio.  All vectors are put in body axes here.
"""
from __future__ import annotations

import numpy as np

from ..errors import ModelError
from ..kernels.constraints import COUPLE, DATA, DIST, PERP, POINT, ROWS, SLIDE
from ..kernels.joints import FIXED, PRISMATIC, REVOLUTE


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
    model's loop joints.  ``con_int``'s last column: 0 for a primitive whose rows are zero
    at every state (``moves``), which the per-call entries do not evaluate."""
    ints, datas, labels, owners, prim_owner = [], [], [], [], []

    def index(frame):
        return -1 if frame == "ground" else model.frame_index(frame)

    moving = rotation_axis(model)
    for j in loop_joints:
        prims, lab = primitives(j, index, model)
        for kind, ip, ic, a, b, data in prims:
            ints.append((kind, ip, ic, a, b, int(moves(kind, ip, ic, data, moving))))
            datas.append(data)
            prim_owner.append(j.name)
            owners.extend([j.name] * ROWS[kind])
        labels.extend(lab)
    con_int = np.array(ints, np.int64).reshape(len(ints), 6)
    con_data = np.array(datas, float).reshape(len(datas), DATA)
    return con_int, con_data, tuple(labels), tuple(owners), tuple(prim_owner)



#: a joint axis counts as parallel (perpendicular) to the plane's normal when its cross
#: (dot) product with it is below this: the rows left out must be exactly zero
PLANAR_TOLERANCE = 1e-14


def rotation_axis(model):
    """``(planar, n, R)``: whether every frame turns about one fixed world direction ``n``
    at every state, as in a planar mechanism (tree joints revolute about axes parallel to
    ``n``, prismatic along axes perpendicular to it, or fixed); ``n`` (None when no frame
    turns at all); each frame's rotation at ``q = 0``."""
    n_frames = len(model._parent)
    R = np.empty((n_frames, 3, 3))
    normal, slides = None, []
    for i in range(n_frames):
        p = int(model._parent[i])
        J = (R[p] if p >= 0 else np.eye(3)) @ model._C[i]
        R[i] = J                                   # revolute, prismatic: J at q = 0
        kind = int(model._kind[i])
        if kind == FIXED:
            continue
        if kind not in (REVOLUTE, PRISMATIC):
            return False, None, R
        e = J @ model._axis[i]
        e = e / np.linalg.norm(e)
        if kind == PRISMATIC:
            slides.append(e)
        elif normal is None:
            normal = e
        elif np.linalg.norm(np.cross(e, normal)) > PLANAR_TOLERANCE:
            return False, None, R
    if normal is not None and any(abs(e @ normal) > PLANAR_TOLERANCE for e in slides):
        return False, None, R
    return True, normal, R


def moves(kind, ip, ic, data, moving):
    """Whether a primitive's rows can be non-zero (``rotation_axis``'s ``moving``).  In a
    mechanism whose frames all turn about ``n``, a perpendicularity between ``a`` and
    ``b`` has the rate row ``(b x a) . (w_c - w_p)`` with both ``w`` along ``n``: zero at
    every state when ``a`` or ``b`` is along ``n`` (the out-of-plane rows of a revolute
    closing a planar loop), and when nothing turns.  Every other row may move."""
    planar, normal, R = moving
    if kind != PERP or not planar:
        return True
    if normal is None:
        return False
    for frame, vector in ((ip, data[6:9]), (ic, data[9:12])):
        v = vector if frame < 0 else R[frame] @ vector
        if np.linalg.norm(np.cross(v, normal)) <= PLANAR_TOLERANCE * np.linalg.norm(v):
            return False
    return True
