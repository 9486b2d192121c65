"""Independent coordinates of a closed mechanism about a configuration on its constraints.

Coordinate partitioning (Wehage and Haug, 1982): at ``q0`` the constraint Jacobian ``G``
(rows x speeds, ``d phi/dt = G u``) has rank ``r``; pivoted QR on its columns picks the
``r`` speeds whose columns are best conditioned as the *dependent* ones ``d`` (``G_d`` of
full column rank), the other ``nu - r`` are *independent* (``i``).  Then, near ``q0``:

* the independent tangent coordinates ``z`` (``analysis.tangent``) give a configuration:
  ``x_i = z`` held, the dependent ``x_d`` solved from ``phi(q) = 0`` by Newton-Raphson
  (``configuration``: a chart of the constraint manifold);
* the independent speeds ``w`` give the speeds: ``u_i = w``, ``u_d`` from ``psi = 0``,
  ``u_d = -G_d^+ (G_i w + drives' part)`` (``speeds``);
* the velocity map ``S = du/dw`` (``S_i = I``, ``S_d = -G_d^+ G_i``) is also ``dx/dz`` at
  ``q0``: the reduced mass matrix is ``S^T M S``.

Redundant rows (rank below the row count) are fine: ``G_d^+`` is a least-squares solve of
a consistent system.  Coordinates the caller holds (``held``) or names as independent
(``independent``) are kept out of the dependent set.
"""
from __future__ import annotations

import numpy as np
from scipy.linalg import qr

from ..errors import ModelError
from ..kernels.loop_solve import RANK_TOLERANCE
from .tangent import Tangent

#: a chart's residual ``|phi|`` above this (m, or dimensionless) is a failure to close
CLOSE_TOLERANCE = 1e-10
#: Newton-Raphson steps at most on the dependent coordinates
CLOSE_ITERATIONS = 40
#: a partition whose ``G_d`` has a conditioning (smallest singular value over the
#: largest) below this is chosen again where a solver can (``equilibrium``)
REPARTITION_BELOW = 1e-3


def speed_indices(model, tangent, names, where):
    """Tangent (speed) indices of coordinates, tangent coordinates or joints by name."""
    out = []
    for name in names:
        hits = [k for k, nm in enumerate(tangent.names)
                if nm == name or model._speed_joint[k] == name]
        if not hits:
            raise ModelError(f"{where}: unknown coordinate {name!r}; the coordinates are "
                             f"{', '.join(tangent.names)}")
        out += hits
    return sorted(set(out))


class Reduction:
    """The partition of ``model``'s speeds at ``q0`` (on the constraints) into dependent
    and independent ones, and the chart it gives.  ``dependent``: indices to use as they
    are (a partition kept from an earlier configuration); else chosen by pivoted QR, away
    from ``held`` and ``independent`` (speed indices)."""

    def __init__(self, model, q0, t=0.0, held=(), independent=(), dependent=None):
        self.model, self.t = model, float(t)
        self.tangent = Tangent(model, q0)
        self.q0 = self.tangent.q0
        n = self.tangent.n
        G = model.constraint_jacobian(self.q0, t)
        self.rank = _rank(G)
        if dependent is None:
            keep = set(held) | set(independent)
            dependent = _pivoted(G, [k for k in range(n) if k not in keep], self.rank)
            if dependent is None:
                names = ", ".join(self.tangent.names[k] for k in sorted(keep))
                raise ModelError(f"model {model.name!r}: {names} cannot all be independent "
                                 f"(or held): the mechanism has {n - self.rank} degree(s) "
                                 "of freedom here, and the other coordinates cannot close "
                                 "its loops alone; choose other independent coordinates")
        self.dependent = np.array(sorted(dependent), np.int64)
        self.independent = np.array([k for k in range(n) if k not in set(self.dependent)],
                                    np.int64)
        sv = np.linalg.svd(G[:, self.dependent], compute_uv=False)
        #: smallest singular value of ``G_d`` over the largest: small near a configuration
        #: where the independent coordinates no longer fix the others
        self.condition = float(sv[-1] / sv[0]) if sv.size and sv[0] > 0 else 1.0
        self.S = self.velocity_map(self.q0)
        self._last = (np.zeros(len(self.independent)), np.zeros(len(self.dependent)))

    @property
    def names(self):
        """The independent tangent coordinates' names."""
        return tuple(self.tangent.names[k] for k in self.independent)

    @property
    def n(self):
        return len(self.independent)

    def velocity_map(self, q):
        """``S`` (speeds x independent speeds): ``u = S w`` (plus the drives' part)."""
        G = self.model.constraint_jacobian(q, self.t)
        S = np.zeros((self.tangent.n, self.n))
        S[self.independent] = np.eye(self.n)
        if len(self.dependent):
            S[self.dependent] = -_solve(G[:, self.dependent], G[:, self.independent])
        return S

    def speeds(self, q, w):
        """The speeds at ``q`` with independent speeds ``w`` and the loops' rates zero."""
        u = np.zeros(self.tangent.n)
        u[self.independent] = w
        if len(self.dependent):
            psi = self.model.constraint_residuals(q, u, self.t)[1]
            G = self.model.constraint_jacobian(q, self.t)
            u[self.dependent] = -_solve(G[:, self.dependent], psi)
        return u

    def configuration(self, z):
        """The configuration on the constraints with independent tangent coordinates ``z``
        about ``q0``, or None where the loops cannot be closed (Newton-Raphson on the
        dependent ones, started from the last solution moved along ``S``)."""
        z = np.asarray(z, float)
        z_last, xd_last = self._last
        x = np.zeros(self.tangent.n)
        x[self.independent] = z
        x[self.dependent] = xd_last + self.S[self.dependent] @ (z - z_last)
        best = None
        for _ in range(CLOSE_ITERATIONS):
            q = self.tangent.retract(x)
            phi = self.model.constraint_residuals(q, None, self.t)[0]
            size = np.abs(phi).max(initial=0.0)
            if not np.isfinite(size):
                break
            if best is not None and size >= best[0] and best[0] <= CLOSE_TOLERANCE:
                break                              # round-off reached
            if best is None or size < best[0]:
                best = (size, x.copy())
            if size == 0.0:
                break
            G = self.model.constraint_jacobian(q, self.t)
            x[self.dependent] -= _solve(G[:, self.dependent], phi)
        if best is None or best[0] > CLOSE_TOLERANCE:
            return None
        x = best[1]
        self._last = (z.copy(), x[self.dependent].copy())
        q = self.tangent.retract(x)
        self.model.normalize_quaternions(q)
        return q


def _rank(G):
    if not G.size:
        return 0
    sv = np.linalg.svd(G, compute_uv=False)
    return int((sv > RANK_TOLERANCE * sv[0]).sum()) if sv[0] > 0 else 0


def _pivoted(G, candidates, rank):
    """``rank`` of the ``candidates`` columns of ``G`` chosen by QR with column pivoting
    (the best conditioned), or None if they do not reach the rank."""
    if rank == 0:
        return []
    if len(candidates) < rank:
        return None
    _, _, perm = qr(G[:, candidates], mode="economic", pivoting=True)
    chosen = [candidates[k] for k in perm[:rank]]
    if _rank(G[:, chosen]) < rank:
        return None
    return chosen


def _solve(A, b):
    """The least-squares solution of the consistent ``A x = b`` (redundant rows allowed)."""
    return np.linalg.lstsq(A, b, rcond=RANK_TOLERANCE)[0]
