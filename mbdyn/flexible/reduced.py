"""A reduced flexible body: what a floating-frame body needs, whichever way it was made
(a Craig-Bampton or free-interface reduction of a beam, or data from another program).
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import scipy.linalg

from ..errors import ModelError
from .invariants import Invariants


@dataclass(frozen=True, eq=False)
class ReducedBody:
    """A flexible body in its floating frame, ``n`` elastic coordinates ``eta``.

    * ``mass_matrix``, ``stiffness_matrix``, ``damping_matrix``: ``M_ee``, ``K_ee``,
      ``C_ee`` (n, n) of ``M_ee eta'' + C_ee eta' + K_ee eta = ...``;
    * ``modes`` (n_nodes, 6, n): each node's displacement (u, v, w) and small rotation
      (rx, ry, rz) per unit ``eta_k``, body axes, relative to the floating frame;
    * ``nodes`` (n_nodes, 3): node positions in body axes, from the frame origin;
    * ``node_names``: {name: node index}; ``interface``: the nodes where joints and loads
      attach; ``reference``: the node the frame is attached to (its modes vanish), or
      ``None`` if the modes are not clamped at a node;
    * ``frequencies`` (n,): natural frequencies in Hz with the frame held still;
    * ``invariants``: the :class:`~mbdyn.flexible.invariants.Invariants`;
    * ``geometric_stiffness``: {load case: (n, n) matrix per unit load}, the beam's
      ``"centrifugal"`` (per unit ``omega_y^2 + omega_z^2``: axial force ``s_out(x)``)
      and ``"axial_acceleration"`` (per unit ``a_x`` of the frame origin minus ``g_x``);
    * ``gyroscopic``: ``G_ee`` (n, n, skew) per unit spin about the body's x axis, of
      ``M_ee eta'' + Omega G_ee eta' + K_ee eta = ...`` in a frame that does not spin
      (``flexible.rotor``), or ``None``.
    """
    method: str
    mass_matrix: np.ndarray
    stiffness_matrix: np.ndarray
    damping_matrix: np.ndarray
    modes: np.ndarray
    nodes: np.ndarray
    invariants: Invariants
    frequencies: np.ndarray
    interface: tuple = ()
    reference: int | None = None
    node_names: dict = field(default_factory=dict)
    geometric_stiffness: dict = field(default_factory=dict)
    gyroscopic: np.ndarray | None = None

    @property
    def n_modes(self):
        return self.mass_matrix.shape[0]

    @property
    def n_nodes(self):
        return self.nodes.shape[0]

    def node(self, which):
        """A node's index from its name or index."""
        if isinstance(which, str):
            if which not in self.node_names:
                raise ModelError(f"no node named {which!r}; named nodes: "
                                 f"{', '.join(self.node_names) or 'none'}")
            return self.node_names[which]
        if not 0 <= int(which) < self.n_nodes:
            raise ModelError(f"node {which} is not one of 0 .. {self.n_nodes - 1}")
        return int(which)


def frame_held_modes(K, M):
    """Frequencies (Hz) and mass-normalised eigenvectors of ``(K, M)``."""
    lam, vec = scipy.linalg.eigh(K, M)
    return np.sqrt(np.clip(lam, 0.0, None)) / (2 * np.pi), vec


def modal_damping(K, M, ratios):
    """The damping matrix that gives each mode of ``(K, M)`` its damping ratio:
    ``C = M X diag(2 zeta_k omega_k) X^T M`` with ``X`` the mass-normalised modes (so
    ``X^T C X = diag(2 zeta omega)``).  ``ratios``: one number or one per mode."""
    f, X = frame_held_modes(K, M)
    zeta = np.broadcast_to(np.asarray(ratios, dtype=float), f.shape)
    MX = M @ X
    return MX @ np.diag(2.0 * zeta * 2.0 * np.pi * f) @ MX.T
