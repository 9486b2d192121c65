"""Points of a flexible body where loads and force elements act: a point rigidly
attached to its nearest node, moving with the node's elastic displacement and rotation.

A point ``x_p`` (body axes, from the frame origin) is tied to the node ``i`` nearest to
it, at the offset ``s = x_p - x_i``.  Its elastic displacement is the node's plus the
node's small rotation turning the offset:

    u_p = Phi_i eta + (Psi_i eta) x s = (Phi_i - s~ Psi_i) eta,     theta_p = Psi_i eta

so a force ``F`` and a moment ``N`` (body components) at the point do the generalised
work ``(Phi_i - s~ Psi_i)^T F + Psi_i^T N`` on the modal coordinates.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import ModelError
from .invariants import skew


@dataclass(frozen=True, eq=False)
class BodyPoint:
    """A point of a flexible body: its ``node``, its position ``x`` at ``eta = 0`` (body
    axes) and its displacement ``Phi`` (3, n) and rotation ``Psi`` (3, n) per unit
    modal coordinate."""
    node: int
    x: np.ndarray
    Phi: np.ndarray
    Psi: np.ndarray


def body_point(reduced, point):
    """The :class:`BodyPoint` of ``reduced`` at ``point``: three numbers (body axes; tied
    to the nearest node, the one with the lower index of two as near) or a node's name."""
    if isinstance(point, str):
        node = reduced.node(point)
        x = reduced.nodes[node].astype(float)
    else:
        x = np.asarray(point, dtype=float).reshape(3)
        gap = np.linalg.norm(reduced.nodes - x, axis=1)
        node = int(np.flatnonzero(gap <= gap.min() * (1 + 1e-12) + 1e-12)[0])
    Phi_i, Psi_i = reduced.modes[node, :3], reduced.modes[node, 3:]
    s = x - reduced.nodes[node]
    return BodyPoint(node, x, Phi_i - skew(s) @ Psi_i, Psi_i.copy())


def node_position(reduced, name, where):
    """A named node's position (body axes), for a point given by the node's name."""
    try:
        return reduced.nodes[reduced.node(name)].astype(float)
    except ModelError as exc:
        raise ModelError(f"{where}: {exc}") from None


#: the six components of a point's motion: displacement along x, y, z, then small
#: rotation about x, y, z (body axes)
COMPONENTS = ("ux", "uy", "uz", "rx", "ry", "rz")
#: a component whose mode-shape entries all stay below this fraction of the largest of
#: their kind (displacements, rotations) is taken as not moved by the modes: round-off
#: of the reduction (a planar beam's out-of-plane entries) is not a motion
NEGLIGIBLE = 1e-12


def moved_components(point):
    """The indices (into :data:`COMPONENTS`) of the components of ``point``'s motion that
    its modes move: rows of ``[Phi_p; Psi_p]`` with an entry above :data:`NEGLIGIBLE`
    times the largest entry of their kind (displacement or rotation)."""
    out = []
    for block, offset in ((point.Phi, 0), (point.Psi, 3)):
        scale = float(np.abs(block).max(initial=0.0))
        if scale == 0.0:
            continue
        out.extend(offset + k for k in range(3)
                   if np.abs(block[k]).max() > NEGLIGIBLE * scale)
    return tuple(out)
