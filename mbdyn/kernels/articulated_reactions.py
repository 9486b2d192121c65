"""Joint reactions from the articulated-body algorithm's workspace: the wrench each joint's
parent exerts on its child (the back-substitution of the tree-order elimination, after
``articulated.articulated_body``) and the Newton-Euler system's reaction unknowns as
components of those wrenches.  World components.
"""

from .views import UNCOUNTED, c_view
from .internal import internal


@internal(**UNCOUNTED)
def joint_wrenches_tree(parent, r, IA, pA, acc, out, work):
    """The wrench each joint's parent exerts on its child, about the child's origin
    (world components), ``out[i] = (force, moment)``, after ``articulated_body``:
    ``W_i = Ia_i X_i A_p + pa_i`` -- the back-substitution of the tree-order elimination.
    """
    n = parent.shape[0]
    v = c_view(work, 0, (6,))
    for i in range(n):
        p = parent[i]
        for k in range(6):
            v[k] = 0.0
        if p >= 0:
            rx, ry, rz = r[i, 0] - r[p, 0], r[i, 1] - r[p, 1], r[i, 2] - r[p, 2]
            v[0], v[1], v[2] = acc[p, 0], acc[p, 1], acc[p, 2]
            v[3] = acc[p, 3] + acc[p, 1] * rz - acc[p, 2] * ry
            v[4] = acc[p, 4] + acc[p, 2] * rx - acc[p, 0] * rz
            v[5] = acc[p, 5] + acc[p, 0] * ry - acc[p, 1] * rx
        for a_ in range(6):
            s = pA[i, a_]
            for b_ in range(6):
                s += IA[i, a_, b_] * v[b_]
            # (moment, force) -> out (force, moment)
            if a_ < 3:
                out[i, 3 + a_] = s
            else:
                out[i, a_ - 3] = s


@internal(**UNCOUNTED)
def reaction_components(R, react_joint, react_force, react_moment, wrench, lam):
    """The reaction unknowns ``lambda_k`` of the Newton-Euler system from the joint
    wrenches: component k is the wrench of its joint (the child frame is
    ``react_joint[k]``) along its direction ``(R react_force[k], R react_moment[k])``; the
    directions of one joint are orthonormal and the wrench has no part along the joint's
    free motion, so the projection is exact."""
    for k in range(react_joint.shape[0]):
        i = react_joint[k]
        s = 0.0
        for a_ in range(3):
            fa = R[i, a_, 0] * react_force[k, 0] + R[i, a_, 1] * react_force[k, 1] \
                + R[i, a_, 2] * react_force[k, 2]
            ma = R[i, a_, 0] * react_moment[k, 0] + R[i, a_, 1] * react_moment[k, 1] \
                + R[i, a_, 2] * react_moment[k, 2]
            s += fa * wrench[i, a_] + ma * wrench[i, 3 + a_]
        lam[k] = s
