"""Eigenvalue problems of a structure given by its matrices: natural frequencies and mode
shapes with some DoFs held, and the whirl of a spinning rotor (Campbell diagrams).
"""
from __future__ import annotations

import numpy as np
import scipy.linalg

from ..errors import ModelError


def free_dofs(n_dofs, fixed=()):
    """The DoFs that are not in ``fixed``, in order."""
    keep = np.ones(n_dofs, dtype=bool)
    keep[np.asarray(fixed, dtype=int)] = False
    return np.flatnonzero(keep)


def natural_modes(K, M, fixed=()):
    """Natural frequencies (Hz, ascending) and mass-normalised mode shapes (n_dofs, n)
    of ``M q'' + K q = 0`` with the DoFs ``fixed`` held at zero (their rows of the modes
    are zero)."""
    free = free_dofs(len(K), fixed)
    try:
        lam, vec = scipy.linalg.eigh(K[np.ix_(free, free)], M[np.ix_(free, free)])
    except np.linalg.LinAlgError:
        raise ModelError("the mass matrix of the free DoFs is not positive definite: a DoF "
                         "without inertia (e.g. a massless node's rotation) must be held "
                         "or given inertia") from None
    modes = np.zeros((len(K), len(free)))
    modes[free] = vec
    return np.sqrt(np.clip(lam, 0.0, None)) / (2 * np.pi), modes


def natural_frequencies(K, M, fixed=()):
    """Natural frequencies in Hz, ascending, with the DoFs ``fixed`` held."""
    return natural_modes(K, M, fixed)[0]


def whirl(M, G, K, spin, fixed=(), *, y_dof=None, z_dof=None):
    """Whirl frequencies of ``M q'' + spin G q' + K q = 0`` (spin in rad/s about x), the
    DoFs ``fixed`` held: ``(frequencies in Hz ascending, direction)``, each of the modes
    with a positive frequency.  ``direction`` is +1 for forward whirl (the orbit turns
    with the spin, from y towards z for a positive spin), -1 for backward, judged at the
    DoFs ``y_dof`` and ``z_dof`` (a node's v and w) of the full numbering; 0 where no
    DoFs are given or the orbit is a line."""
    free = free_dofs(len(K), fixed)
    Mf, Gf, Kf = (A[np.ix_(free, free)] for A in (M, G, K))
    n = len(free)
    # first-order form: [K 0; 0 M] z' = [0 K; -K -spin G] z with z = (q, q')
    A = np.block([[np.zeros((n, n)), np.eye(n)],
                  [-np.linalg.solve(Mf, Kf), -spin * np.linalg.solve(Mf, Gf)]])
    lam, vec = np.linalg.eig(A)
    keep = lam.imag > 1e-9 * max(1.0, np.abs(lam).max())
    lam, vec = lam[keep], vec[:n, keep]
    order = np.argsort(lam.imag)
    lam, vec = lam[order], vec[:, order]
    direction = np.zeros(len(lam), dtype=int)
    if y_dof is not None and z_dof is not None:
        where = {d: i for i, d in enumerate(free)}
        if y_dof not in where or z_dof not in where:
            raise ModelError(f"y_dof {y_dof} and z_dof {z_dof} must be free DoFs (not held)")
        V, W = vec[where[y_dof]], vec[where[z_dof]]
        sense = np.imag(V * np.conj(W)) * np.sign(spin if spin else 1.0)
        scale = np.abs(V) ** 2 + np.abs(W) ** 2
        direction = np.where(sense > 1e-6 * scale, 1, np.where(sense < -1e-6 * scale, -1, 0))
    return lam.imag / (2 * np.pi), direction
