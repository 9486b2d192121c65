"""Frames rigidly attached to their parent merged into the nearest moving ancestor, for the
per-call dynamics kernels (the articulated-body algorithm, inverse dynamics, the mass
matrix).

A frame whose joint is ``fixed`` moves with its parent: its mass, centre of mass and
inertia can be added to the *carrier*, the nearest ancestor whose joint moves (or the
ground), once at compile, and the frame left out of the sweeps.  A URDF robot is full of
such frames (TIAGo: 26 of 38; a UR5: 4 of 10), which the kernels otherwise walk like any
other.  The merged tree has the same coordinates and speeds in the same order (a fixed
joint has none) and gives the same ``u'``, ``Q = M u' - f`` and ``M`` to rounding.

A fixed frame is kept (not merged) when something acts on it by its index: a point load, a
force element between frames (its points are in the frame's axes).  A force element on a
joint's coordinate acts on the joint's child, which moves, and on its parent at the joint
origin: the parent's carrier takes it there (the same world point).  No frame is merged
when a force element names frames inside its numbers (contacts between shapes, an
actuator's gravity compensation) or is of a kind not listed here, nor when loop joints
close the tree: those read the full tree's indices.

The joint reactions (``reactions``, ``reaction_array``, ``inverse_dynamics``), the
kinematics of every frame, the Jourdain route and the compiled integrators keep the full
tree.  ``plan`` returns the merged tree's arrays, ``None`` when nothing merges.
"""
from __future__ import annotations

import numpy as np

from ..kernels import forces as kf
from ..kernels.actuation import A_CARRIED
from ..kernels.joints import FIXED

#: force kinds whose frames are the row's two frame columns only, their points in those
#: frames' axes: the frames are kept
BETWEEN_FRAMES = (kf.SPRING_DAMPER, kf.BUSHING, kf.BEARING, kf.CONTACT_SPHERE,
                  kf.CONTACT_DISK)
#: force kinds on a joint's coordinate: the child (column 1) moves, the parent (column 2)
#: may be merged (the effort on it acts at the joint origin)
ON_A_JOINT = (kf.JOINT_SPRING_DAMPER, kf.JOINT_STOP, kf.ACTUATOR)


def kept_frames(model):
    """Which frames keep their own place in the merged tree (a bool per frame), or
    ``None`` when the model cannot be merged (see the module docstring)."""
    keep = model._kind != FIXED
    keep[model._load_body] = True
    for row in model._force_int:
        kind = row[0]
        if kind in BETWEEN_FRAMES:
            for i in row[1:3]:
                if i >= 0:
                    keep[i] = True
        elif kind in ON_A_JOINT:
            if kind == kf.ACTUATOR and model._force_data[row[3] + A_CARRIED] > 0:
                return None             # gravity compensation: body indices in its data
            keep[row[1]] = True
        else:
            return None                 # contacts between shapes, or a kind not known here
    return keep


def placements(model):
    """Each frame's carrier (the nearest ancestor-or-self kept, -1 the ground) and its
    placement there: ``R_cm`` (the frame's axes in the carrier's) and ``p_cm`` (its origin
    from the carrier's, carrier axes); for a kept frame, itself and the identity."""
    n = model.n_frames
    carrier = np.arange(n)
    R = np.tile(np.eye(3), (n, 1, 1))
    p = np.zeros((n, 3))
    keep = model._keep
    for i in range(n):               # parents first
        if keep[i]:
            continue
        par = model._parent[i]
        # a fixed joint: the frame's axes are the joint frame's, placed by (pos, C)
        if par < 0:
            carrier[i], R[i], p[i] = -1, model._C[i], model._pos[i]
        else:
            carrier[i] = carrier[par]
            R[i] = R[par] @ model._C[i]
            p[i] = p[par] + R[par] @ model._pos[i]
    return carrier, R, p


def merged_bodies(model, carrier, R, p, index):
    """Mass, centre of mass (carrier axes) and inertia about it of each kept frame with
    the frames it carries."""
    m = len(index)
    mass, first, second = np.zeros(m), np.zeros((m, 3)), np.zeros((m, 3, 3))
    for i in range(model.n_frames):
        c = carrier[i]
        if c < 0:
            continue                 # on the ground: no dynamics sees it
        k = index[c]
        mi = model._mass[i]
        x = p[i] + R[i] @ model._com[i]  # its centre of mass, carrier axes
        mass[k] += mi
        first[k] += mi * x
        # inertia about the carrier's origin: R I R^T + m (|x|^2 E - x x^T)
        second[k] += (R[i] @ model._inertia[i] @ R[i].T
                      + mi * (x @ x * np.eye(3) - np.outer(x, x)))
    com = np.zeros((m, 3))
    inertia = np.empty((m, 3, 3))
    for k in range(m):
        if mass[k] > 0.0:
            com[k] = first[k] / mass[k]
        x = com[k]
        inertia[k] = second[k] - mass[k] * (x @ x * np.eye(3) - np.outer(x, x))
        inertia[k] = 0.5 * (inertia[k] + inertia[k].T)
    has = np.array([mass[k] > 0.0 or bool(np.any(inertia[k] != 0.0)) for k in range(m)])
    return mass, com, inertia, has


def plan(model, loop_joints=0):
    """The merged tree's arrays, by the names of ``kernels.packed.FLOATS`` and ``INTS``
    (``parent`` .. ``has_inertia``, ``load_body``, ``force_int``), and ``n`` its frames;
    ``None`` when no frame merges or the model cannot be merged."""
    keep = None if loop_joints else kept_frames(model)
    if keep is None or keep.all() or not keep.any() or model.nu == 0:
        return None
    model._keep = keep
    carrier, R, p = placements(model)
    kept = np.flatnonzero(keep)
    index = -np.ones(model.n_frames, np.int64)
    index[kept] = np.arange(len(kept))

    def reduced(i):                  # a frame's carrier in the merged tree (-1: ground)
        return -1 if i < 0 or carrier[i] < 0 else int(index[carrier[i]])
    parent = np.array([reduced(model._parent[i]) for i in kept], np.int64)
    pos, C = np.empty((len(kept), 3)), np.empty((len(kept), 3, 3))
    for k, i in enumerate(kept):     # the joint frame placed in the parent's carrier
        par = model._parent[i]
        Rp, pp = (R[par], p[par]) if par >= 0 else (np.eye(3), np.zeros(3))
        pos[k] = pp + Rp @ model._pos[i]
        C[k] = Rp @ model._C[i]
    mass, com, inertia, has = merged_bodies(model, carrier, R, p, index)
    force_int = model._force_int.copy()
    for row in force_int:            # kept frames stand for themselves, a joint's parent
        row[1], row[2] = reduced(row[1]), reduced(row[2])   # for its carrier
    return {"n": len(kept), "parent": parent, "kind": model._kind[kept].copy(),
            "axis": model._axis[kept].copy(), "seq": model._seq[kept].copy(), "pos": pos,
            "C": C, "qoff": model._qoff[kept].copy(), "uoff": model._uoff[kept].copy(),
            "ucol": model._ucol[kept].copy(), "mass": mass, "com": com,
            "inertia": inertia, "has_inertia": has,
            "load_body": np.array([index[i] for i in model._load_body], np.int64),
            "force_int": force_int}
