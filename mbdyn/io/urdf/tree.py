"""The kinematic tree of a URDF ``Robot`` and the numbers of its placements and inertias.

``tree_order`` checks that the joints make one tree (every link named by a joint exists,
no link has two parents, no cycle, one root) and orders the joints parents first.
``rpy_matrix`` and ``link_inertia`` are the URDF specification's conventions, written
once: ``rpy`` are fixed-axis rotations, roll about x, then pitch about y, then yaw about
z, so ``R = Rz(yaw) Ry(pitch) Rx(roll)``; an ``<inertial>``'s tensor is given in the
inertial frame, whose origin is the centre of mass, and is turned into the link frame as
``R I R^T``.  ``check_inertia`` refuses what no body can have.
"""
from __future__ import annotations

import numpy as np

from ..wording import suggest

#: a triangle inequality broken by less than this (relative) is taken as printed digits
TRIANGLE_TOLERANCE = 1e-6
#: a principal moment below -this x the largest is negative; above, round-off set to 0
NEGATIVE_TOLERANCE = 1e-9


def rpy_matrix(rpy):
    """``Rz(yaw) Ry(pitch) Rx(roll)`` of ``rpy = (roll, pitch, yaw)``: maps the rotated
    frame's components to the reference frame's (URDF's ``<origin rpy>``)."""
    r, p, y = rpy
    cr, sr, cp, sp, cy, sy = np.cos(r), np.sin(r), np.cos(p), np.sin(p), np.cos(y), np.sin(y)
    Rx = np.array([[1.0, 0.0, 0.0], [0.0, cr, -sr], [0.0, sr, cr]])
    Ry = np.array([[cp, 0.0, sp], [0.0, 1.0, 0.0], [-sp, 0.0, cp]])
    Rz = np.array([[cy, -sy, 0.0], [sy, cy, 0.0], [0.0, 0.0, 1.0]])
    return Rz @ Ry @ Rx


def tree_order(reader, robot):
    """``(root link, joints parents first)``; errors name the link or joint at fault."""
    for joint in robot.joints.values():
        for role in ("parent", "child"):
            link = getattr(joint, role)
            if link not in robot.links:
                raise reader.error(f"joint {joint.name!r}", f"its {role} link {link!r} is "
                                   f"not defined; {suggest(link, robot.links)}add "
                                   f"<link name=\"{link}\"> or correct the name")
    parent_joint = {}
    for joint in robot.joints.values():
        if joint.child in parent_joint:
            other = parent_joint[joint.child].name
            raise reader.error(f"link {joint.child!r}", f"has two parents: joints {other!r} "
                               f"and {joint.name!r} both make it their child; a URDF is a "
                               "tree (close a loop in a TOML wrapper with a loop joint)")
        parent_joint[joint.child] = joint
    roots = [n for n in robot.links if n not in parent_joint]
    _check_cycles(reader, robot, parent_joint)
    if len(roots) != 1:
        raise reader.error("", f"has {len(roots)} root links ({', '.join(roots)}): links "
                           "that are no joint's child; a URDF is one tree -- join them")
    children = {n: [] for n in robot.links}
    for joint in robot.joints.values():
        children[joint.parent].append(joint)
    return roots[0], _depth_first(roots[0], children)


def _check_cycles(reader, robot, parent_joint):
    """A link whose ancestors come back to it is an error naming the cycle.  Each link is
    walked once (O(n)): a walk stops at a link an earlier walk has cleared."""
    cleared = set()
    for name in robot.links:
        path, on_path, link = [], set(), name
        while link not in cleared:
            if link in on_path:
                cycle = path[path.index(link):] + [link]
                raise reader.error(f"link {link!r}", "the joints form a cycle ("
                                   + " -> ".join(reversed(cycle)) + "); a URDF is a tree")
            path.append(link)
            on_path.add(link)
            if link not in parent_joint:
                break
            link = parent_joint[link].parent
        cleared.update(path)


def _depth_first(root, children):
    """The joints in depth-first order from ``root``, children in file order (the order
    Pinocchio and most tools number a URDF's joints)."""
    order, stack = [], list(reversed(children[root]))
    while stack:
        joint = stack.pop()
        order.append(joint)
        stack.extend(reversed(children[joint.child]))
    return order


def link_inertia(inertial):
    """``(mass, com, inertia about the centre of mass in link axes)`` of an ``Inertial``;
    an absent ``<inertia>`` is a particle."""
    com = np.array(inertial.xyz, dtype=float)
    if inertial.inertia is None:
        return inertial.mass, com, np.zeros((3, 3))
    ixx, ixy, ixz, iyy, iyz, izz = inertial.inertia
    I = np.array([[ixx, ixy, ixz], [ixy, iyy, iyz], [ixz, iyz, izz]])  # noqa: E741
    R = rpy_matrix(inertial.rpy)
    return inertial.mass, com, R @ I @ R.T


def check_inertia(reader, name, inertia, accept):
    """``(inertia, warning or None)``: the tensor of link ``name`` (about its centre of
    mass), refused when a principal moment is negative or the moments break the triangle
    inequality (``A + B >= C``), unless ``accept``: then a negative moment is set to zero
    and either is a warning.  Round-off (``NEGATIVE_TOLERANCE``, ``TRIANGLE_TOLERANCE``
    of the largest moment) passes."""
    moments, axes = np.linalg.eigh(inertia)
    scale = max(float(np.abs(moments).max()), 1e-300)
    shown = ", ".join(f"{m:.6g}" for m in moments)
    where = f"link {name!r}"
    if moments[0] < -NEGATIVE_TOLERANCE * scale:
        problem = (f"its inertia has a negative principal moment ({shown}); moments of "
                   "inertia cannot be negative")
        if not accept:
            raise reader.error(where, problem + "; correct the <inertia>, or accept it "
                               "(accept_inertia: the negative moment is then set to 0)")
        clipped = np.maximum(moments, 0.0)
        return axes @ np.diag(clipped) @ axes.T, (f"{reader.file}: {where}: {problem}; "
                                                  "accepted with the negative moment set to 0")
    if moments[0] < 0:
        moments = np.maximum(moments, 0.0)
        inertia = axes @ np.diag(moments) @ axes.T
    a, b, c = moments
    if a + b < c * (1 - TRIANGLE_TOLERANCE):
        problem = (f"its principal moments of inertia ({shown}) break the triangle "
                   "inequality (A + B >= C): no real body has them (moments about another "
                   "point than the centre of mass?)")
        if not accept:
            raise reader.error(where, problem + "; correct the <inertia>, or accept it "
                               "(accept_inertia)")
        return inertia, f"{reader.file}: {where}: {problem}; accepted"
    return inertia, None
