"""Joints at the nodes of flexible bodies, laid out at compile: each joint (tree or loop)
that attaches to a flexible body at a point its modes move is re-hung from that point's
node frame (``elements.flexible_nodes``), whose chain of 1-DoF joints is inserted in the
tree right after the body.  Joints at the same point share one node frame.  A point the
modes do not move (the root of a clamped reduction) keeps its joint on the body's frame,
as before.
"""
from __future__ import annotations

import dataclasses

import numpy as np

from ..elements.flexible_nodes import node_frame

ORIGIN = np.zeros(3)


class _NodeFrames:
    """The node frames made so far, per flexible body, and the names they took."""

    def __init__(self, system, on):
        self.flexible = {b.name: b for b in on}
        self.taken = (set(system.graph.nodes) | set(system._joints)
                      | set(system._loop_joints) | set(system._state_names)
                      | set(system._loads) | set(system._forces))
        self.made = {}                  # body -> [(NodeFrame, bodies, joints)]

    def at(self, frame, position):
        """``(frame, position)`` a joint at ``position`` of ``frame`` attaches to: the
        point's node frame (at its origin) on a flexible body whose modes move it, else
        as given."""
        record = self.flexible.get(frame)
        if record is None:
            return frame, position
        for made in self.made.get(frame, []):
            if made[0].same_point(position):
                return made[0].name, ORIGIN.copy()
        built = node_frame(record, position, self.taken)
        if built is None:
            return frame, position
        self.made.setdefault(frame, []).append(built)
        return built[0].name, ORIGIN.copy()


def attach_at_nodes(system, bodies, joints, loop_joints, on):
    """``(bodies, joints, loop_joints, node_frames)``: the tree's records in topological
    order with the node frames' chains inserted after their bodies, the joints at nodes
    re-hung from the node frames, and the ``NodeFrame`` records in tree order.  ``on``:
    the flexible bodies whose flexibility is on (none: everything as given)."""
    if not on:
        return bodies, joints, loop_joints, ()
    nodes = _NodeFrames(system, on)
    tree_joints = []
    for j in joints:
        parent, position = nodes.at(j.parent, j.position)
        tree_joints.append(j if parent == j.parent else
                           dataclasses.replace(j, parent=parent, position=position))
    loops = []
    for lj in loop_joints:
        if lj.kind == "coupling":
            loops.append(lj)
            continue
        parent, position = nodes.at(lj.parent, lj.position)
        child, child_position = nodes.at(lj.child, lj.child_position)
        loops.append(lj if (parent, child) == (lj.parent, lj.child) else dataclasses.replace(
            lj, parent=parent, position=position, child=child,
            child_position=child_position))
    out_bodies, out_joints, frames = [], [], []
    for body, joint in zip(bodies, tree_joints):
        out_bodies.append(body)
        out_joints.append(joint)
        for nf, chain_bodies, chain_joints in nodes.made.get(body.name, []):
            out_bodies.extend(chain_bodies)
            out_joints.extend(chain_joints)
            frames.append(nf)
    return out_bodies, out_joints, loops, tuple(frames)
