"""The closed mechanisms' solve outside runs (``kernels.rank_qr``: a column-pivoted QR of
``Y = L^-1 G^T``, minimum-norm multipliers) against numpy's SVD, and the packed Python
entry point (``kernels.constrained.constrained_accelerations_packed``) against the
equations it solves."""
from __future__ import annotations

import numpy as np
import pytest

import mbdyn as mb
from mbdyn.errors import ModelError
from mbdyn.kernels.rank_qr import qr_solve, work_size


def _problem(rng, trial):
    """A random consistent ``M u' = f + G^T lam``, ``G u' = gamma`` with redundant rows."""
    nu, m = int(rng.integers(1, 9)), int(rng.integers(1, 16))
    r = int(rng.integers(0, min(nu, m) + 1))
    G = (rng.standard_normal((m, r)) @ rng.standard_normal((r, nu)) if r
         else np.zeros((m, nu)))
    if trial % 3 == 0 and m > 1:
        G[1] = G[0]                                   # a repeated row
    A = rng.standard_normal((nu, nu))
    M = A @ A.T + nu * np.eye(nu)
    return M, rng.standard_normal(nu), G, G @ rng.standard_normal(nu)


def test_qr_solve_equals_the_minimum_norm_svd_solution():
    """``u'`` and the minimum-norm multipliers by ``pinv`` (numpy's SVD) to 1e-10, the
    rank as numpy counts singular values of ``Y`` above 1e-9 of the largest, on 300
    random problems of every rank (none, full, redundant, repeated rows)."""
    rng = np.random.default_rng(7)
    for trial in range(300):
        M, f, G, gamma = _problem(rng, trial)
        m, nu = G.shape
        L = np.linalg.cholesky(M)
        ud, lam, info = np.linalg.solve(M, f), np.zeros(m), np.zeros(6 + m)
        qr_solve(L, ud, G, gamma, lam, info, 1e-9, np.empty(work_size(nu, m)))
        Y = np.linalg.solve(L, G.T)
        Yp = np.linalg.pinv(Y, rcond=1e-9)
        lam_ref = Yp @ (Yp.T @ (gamma - G @ np.linalg.solve(M, f)))
        ud_ref = np.linalg.solve(M, f + G.T @ lam_ref)
        assert np.abs(ud - ud_ref).max() <= 1e-10 * (1 + np.abs(ud_ref).max()), trial
        assert np.abs(lam - lam_ref).max() <= 1e-10 * (1 + np.abs(lam_ref).max()), trial
        sv = np.linalg.svd(Y, compute_uv=False)
        assert info[0] == (np.sum(sv > 1e-9 * sv[0]) if sv.size and sv[0] > 0 else 0)
        assert np.abs(G @ ud - gamma).max() <= 1e-9 * (1 + np.abs(gamma).max())


@pytest.mark.parametrize("path, case", [("models/andrews_squeezer.toml", None),
                                        ("models/four_bar.toml", "free")])
def test_forward_dynamics_solves_the_constrained_equations(path, case):
    """On shipped mechanisms with redundant rows: ``G u' = gamma`` (the constraints' second
    derivative vanishes: checked by differences of ``G u`` along the motion), ``M u' - f =
    G^T lam`` with the tree's equations (``effort_array``), and ``lam`` the minimum-norm
    multipliers (in the row space of ``G``, as ``pinv`` makes them)."""
    scene = mb.load_model(path, case)                # no drives: G u is the whole rate
    m = scene.model
    q, u = m.project(scene.q0, scene.u0 + 0.3)
    ud, lam = m.multipliers(q, u)
    G = m.constraint_jacobian(q)
    effort = m.effort_array(q, u, ud)
    scale = np.abs(effort).max() + np.abs(G.T @ lam).max()
    assert np.abs(G.T @ lam - effort).max() <= 1e-10 * scale
    U, sv, _ = np.linalg.svd(G, full_matrices=False)
    basis = U[:, sv > 1e-9 * sv[0]]                  # the column space of G: not null(G^T)
    assert np.abs(lam - basis @ (basis.T @ lam)).max() <= 1e-10 * np.abs(lam).max()
    # d/dt (G u) = G u' + G' u = 0 on the mechanism: G' u by a central difference
    h = 1e-6
    qd = m.coordinate_rates(q, u)
    Gdot_u = (m.constraint_jacobian(q + h * qd) - m.constraint_jacobian(q - h * qd)) @ u / (2 * h)
    assert np.abs(G @ ud + Gdot_u).max() <= 1e-6 * (1 + np.abs(G @ ud).max())


def test_packed_entry_takes_any_input_and_names_bad_ones():
    """Lists, read-only and strided arrays give the plain arrays' answer, float32 that of
    its values in float64; a wrong
    length is refused with the sizes named."""
    scene = mb.load_model("models/andrews_squeezer.toml")
    m = scene.model
    q, u = scene.q0.copy(), scene.u0 + 0.1
    ref = m.forward_dynamics(q, u)
    ro = q.copy()
    ro.flags.writeable = False
    strided = np.repeat(q, 2)[::2]
    for qq in (list(q), ro, strided):
        assert np.array_equal(m.forward_dynamics(qq, u), ref)
    q32 = q.astype(np.float32)
    assert np.array_equal(m.forward_dynamics(q32, u), m.forward_dynamics(q32.astype(float), u))
    with pytest.raises(ModelError, match="length"):
        m.forward_dynamics(q[:-1], u)
