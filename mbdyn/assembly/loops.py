"""Closed loops in a ``System``: adding a loop joint, and at compile the check that the
joints form a spanning tree plus loop joints, with each loop's bodies found.

A body hangs from exactly one *tree* joint (a joint without ``child_position``); every
other joint into it is a *loop* joint, which closes the loop formed by its own path and
the tree's between its parent and its child.  ``networkx`` finds the spanning tree's
paths and checks the whole graph (``cycle_basis``: one independent loop per loop joint).
"""
from __future__ import annotations

import networkx as nx

from ..elements.constraints import LOOP_KINDS, make_loop_joint
from ..errors import ModelError
from ..names import label_problem

GROUND = "ground"
#: the keywords of ``System.add_joint`` that only loop joints take
LOOP_KEYS = ("child_position", "child_orientation", "cut", "axis2", "length", "follower",
             "leader", "ratio", "offset")


def add_loop_joint(system, name, kind, parent, child, *, axis=None, position=(0, 0, 0),
                   orientation=None, cut=None, **keys):
    """``System.add_joint`` for a joint that closes a loop (see there)."""
    element = f"joint {name!r}"
    problem = label_problem(name)
    if problem:
        raise ModelError(f"joint name {name!r} {problem}")
    unknown = sorted(set(keys) - set(LOOP_KEYS))
    if unknown:
        raise ModelError(f"{element}: unknown keyword(s) {', '.join(unknown)}; a joint takes "
                         "axis, position, orientation, sequence, coordinates, speeds, drive "
                         f"and, to close a loop, {', '.join(LOOP_KEYS)}")
    if name in system._joints or name in system._loop_joints:
        raise ModelError(f"{element}: the name is already used by another joint")
    if cut not in (None, True, False):
        raise ModelError(f"{element}: cut must be true or false, got {cut!r}")
    if not isinstance(kind, str) or kind not in LOOP_KINDS:
        raise ModelError(f"{element}: a {kind!r} joint cannot close a loop; use one of "
                         + ", ".join(repr(k) for k in LOOP_KINDS))
    if kind == "coupling":
        if parent is not None or child is not None:
            raise ModelError(f"{element}: a coupling joins two joints' coordinates (follower, "
                             "leader), not two bodies: remove parent and child")
        for key in ("follower", "leader"):
            other = keys.get(key)
            if isinstance(other, str) and other not in system._joints:
                raise ModelError(f"{element}: {key} {other!r} is not a joint of the tree; add "
                                 "it first (tree joints: "
                                 f"{', '.join(system._joints) or 'none'})")
    else:
        for role, frame in (("parent", parent), ("child", child)):
            if frame is None or frame not in system.graph:
                raise ModelError(f"{element}: unknown {role} body {frame!r}; a loop joint "
                                 "joins two bodies of the system (known: "
                                 f"{', '.join(system.graph.nodes)})")
    if kind != "coupling" and cut is False:
        raise ModelError(f"{element}: cut = false with child_position: a joint with "
                         "child_position always closes a loop; remove child_position to "
                         "make it a tree joint")
    joint = make_loop_joint(name, kind, parent, child, position=position,
                            orientation=orientation, axis=axis,
                            parameters=system.parameters, **keys)
    system._loop_joints[name] = joint
    return name


def check_loops(system):
    """The loop joints in the order added, after checking the whole graph: every body
    has its tree joint (one without ``child_position``) and every coupling's joints are
    1-DoF tree joints.  Returns a list of ``LoopJoint``."""
    loop_joints = list(system._loop_joints.values())
    for j in loop_joints:
        if j.kind != "coupling" and j.child != GROUND and \
                next(iter(system.graph.in_edges(j.child)), None) is None:
            raise ModelError(f"joint {j.name!r}: its child {j.child!r} hangs from no tree "
                             "joint -- every joint into it has child_position, which makes "
                             "it a loop joint; remove child_position (and cut) from the "
                             f"joint that should carry {j.child!r} in the tree")
    for j in loop_joints:
        if j.kind == "coupling":
            for role in ("follower", "leader"):
                tree = system._joints.get(getattr(j, role))
                if tree is None:
                    raise ModelError(f"joint {j.name!r}: {role} {getattr(j, role)!r} is not a "
                                     "tree joint")
                if tree.kind not in ("revolute", "prismatic"):
                    raise ModelError(f"joint {j.name!r}: {role} {tree.name!r} is a "
                                     f"{tree.kind} joint; a coupling joins revolute or "
                                     "prismatic coordinates")
    return loop_joints


def loop_bodies(system, joint):
    """The bodies of the loop a loop joint closes: the tree's path from its parent to
    its child (through their nearest common ancestor)."""
    if joint.kind == "coupling":
        return []
    tree = system.graph.to_undirected(as_view=True)
    return [n for n in nx.shortest_path(tree, joint.parent, joint.child)]
