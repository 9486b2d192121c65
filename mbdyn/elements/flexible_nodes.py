"""Node frames: where a joint attaches to a flexible body away from its frame origin.

A joint whose parent (or a loop joint whose parent or child) is a flexible body, at a
point ``x_p`` of it, attaches to the point's *node frame*: a massless frame that moves
with the nearest node ``i`` (``mbdyn.flexible.points``), displaced by
``(Phi_i - s~ Psi_i) eta`` (``s = x_p - x_i``) and turned by the node's small rotation
``theta = Psi_i eta``, as a load's point is.  In the compiled tree the node frame hangs
from the body's frame through a chain of 1-DoF joints, one per component its modes move:
a prismatic joint along x, y, z for each displacement component (the first placed at
``x_p``), then a revolute joint about x, y, z for each rotation component, so that

    r_N = r_0 + R (x_p + Phi_p eta),      R_N = R Rx(theta_x) Ry(theta_y) Rz(theta_z)

(successive rotations about the moved axes: the rotation vector ``theta`` to first
order, as every small rotation of the linear modes is).  Each chain coordinate is one
component of ``[Phi_p; Psi_p] eta`` and its speed the same of ``eta'``: a constant linear
map, so the tree's kinematics, Jacobians and velocity products of the chain's frames are
exact, and the modal columns of anything below the node frame are the tree's columns of
the chain times that map (``compiled.flexible_states``).  The chain's coordinates are
not the model's: they follow from ``eta``.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..flexible.points import COMPONENTS, body_point, moved_components
from .bodies import make_body
from .joints import make_joint


@dataclass(frozen=True, eq=False)
class NodeFrame:
    """A node frame of the flexible body ``body``: the frame ``name`` at the ``point``
    (``flexible.points.BodyPoint``: node, position, mode shapes), the ``components`` its
    modes move (indices into ``flexible.points.COMPONENTS``) and the chain's ``joints``
    and ``frames`` (one per component; the last frame is ``name``)."""
    name: str
    body: str
    point: object
    components: tuple
    joints: tuple
    frames: tuple

    @property
    def rows(self):
        """``(k, n)``: each chain coordinate per unit modal coordinate (the rows of
        ``[Phi_p; Psi_p]`` of its components)."""
        return np.vstack([self.point.Phi, self.point.Psi])[list(self.components)]

    def same_point(self, x):
        return np.array_equal(self.point.x, np.asarray(x, float))


def node_frame(record, position, taken):
    """The ``NodeFrame`` of the flexible body ``record`` (``FlexibleBody``) at
    ``position`` (body axes; tied to the nearest node) and its chain's records
    ``(bodies, joints)`` in tree order; ``None`` when the modes move no component there
    (the frame's root, clamped in every mode: a joint there attaches to the body's frame
    itself).  ``taken``: the frame, joint and coordinate names in use (the chain's are
    added)."""
    point = body_point(record.reduced, position)
    moved = moved_components(point)
    if not moved:
        return None
    label = _node_label(record, point.node)
    name = _free_name(f"{record.name}.{label}", taken)
    frames = tuple(f"{name}.{COMPONENTS[c]}" for c in moved[:-1]) + (name,)
    bodies, joints, parent = [], [], record.name
    for k, (c, frame) in enumerate(zip(moved, frames)):
        coordinate = _free_name(f"{record.name}_{label}_{COMPONENTS[c]}", taken)
        kind = "prismatic" if c < 3 else "revolute"
        joints.append(make_joint(
            _free_name(f"{name}:{COMPONENTS[c]}", taken), kind, parent, frame,
            axis="xyz"[c % 3], position=point.x if k == 0 else (0.0, 0.0, 0.0),
            coordinates=coordinate))
        bodies.append(make_body(frame))
        parent = frame
    nf = NodeFrame(name, record.name, point, moved, tuple(j.name for j in joints), frames)
    return nf, bodies, joints


def _node_label(record, node):
    """A node's name (``tip``) or ``n3``, to name its frame and chain coordinates."""
    names = [n for n, i in record.reduced.node_names.items() if i == node]
    return names[0] if names else f"n{node}"


def _free_name(base, taken):
    """``base``, or ``base_2``, ``base_3`` ... : the first not in ``taken`` (then taken)."""
    name, k = base, 1
    while name in taken:
        k += 1
        name = f"{base}_{k}"
    taken.add(name)
    return name
