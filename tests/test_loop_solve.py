"""The closed mechanisms' solve outside runs (``kernels.rank_qr``: a column-pivoted QR of
``Y = L^-1 G^T``, minimum-norm multipliers) against numpy's SVD, and the packed Python
entry point (``kernels.constrained.constrained_accelerations_packed``) against the
equations it solves."""
from __future__ import annotations

import numpy as np
import pytest

import mbdyn as mb
from mbdyn.errors import ModelError
from mbdyn.kernels.rank_qr import WELL_CONDITIONED, _gram_solve, pivoted_qr, qr_solve, work_size


def _problem(rng, trial):
    """A random consistent ``M u' = f + G^T lam``, ``G u' = gamma`` with redundant rows."""
    nu, m = int(rng.integers(1, 9)), int(rng.integers(1, 16))
    r = int(rng.integers(0, min(nu, m) + 1))
    G = (rng.standard_normal((m, r)) @ rng.standard_normal((r, nu)) if r
         else np.zeros((m, nu)))
    if trial % 3 == 0 and m > 1:
        G[1] = G[0]                                   # a repeated row
    if trial % 4 == 1 and m > 2:                      # rows of zeros (a planar loop's
        G[rng.choice(m, m // 2, replace=False)] = 0.0  # out-of-plane rows): left out
    A = rng.standard_normal((nu, nu))
    M = A @ A.T + nu * np.eye(nu)
    return M, rng.standard_normal(nu), G, G @ rng.standard_normal(nu)


def test_qr_solve_equals_the_minimum_norm_svd_solution():
    """``u'`` and the minimum-norm multipliers by ``pinv`` (numpy's SVD) to 1e-10, the
    rank as numpy counts singular values of ``Y`` above 1e-9 of the largest, on 300
    random problems of every rank (none, full, redundant, repeated rows, rows of zeros)."""
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


def _conditioned(rng, nu, m, ratio):
    """``Y`` (nu x m) whose smallest singular value is ``ratio`` of its largest."""
    U = np.linalg.qr(rng.standard_normal((nu, m)))[0]
    V = np.linalg.qr(rng.standard_normal((m, m)))[0]
    return U @ np.diag(np.geomspace(1.0, ratio, m)) @ V.T * rng.uniform(0.1, 10.0)


def test_well_conditioned_rows_take_the_normal_equations_and_others_the_qr():
    """``_gram_solve`` (the pivoted Cholesky of ``Y^T Y``): on independent rows whose
    conditioning is above ``WELL_CONDITIONED`` it solves, with the same ``u'`` and
    multipliers as numpy's least squares (1e-12) and the same conditioning figure as
    the pivoted QR (``info[1]``, 1e-10); below it (or with more rows than speeds) it
    declines and changes nothing, and ``qr_solve`` still gives the right answer."""
    rng = np.random.default_rng(37)
    taken = declined = 0
    for trial in range(200):
        nu = int(rng.integers(2, 10))
        m = int(rng.integers(1, nu + 1))
        ratio = float(10.0 ** rng.uniform(-4.0, 0.0)) if m > 1 else 1.0
        A = rng.standard_normal((nu, nu))
        Lm = np.linalg.cholesky(A @ A.T + nu * np.eye(nu))
        Y = _conditioned(rng, nu, m, ratio)
        G = (Lm @ Y).T                                  # Y = L^-1 G^T
        res = rng.standard_normal(m)
        ud0 = rng.standard_normal(nu)
        ud, lam, info = ud0.copy(), np.zeros(m), np.zeros(6 + m)
        B, perm, w, z = np.empty((m, m)), np.empty(m), np.empty(nu), np.empty(nu)
        ok = _gram_solve(Y.copy(), m, res, np.arange(m, dtype=float), Lm, ud, lam, info, B,
                         perm, np.empty(m), w, z)
        sv = np.linalg.svd(Y, compute_uv=False)
        if not ok:
            declined += 1
            assert sv[-1] / sv[0] < 10 * WELL_CONDITIONED, trial
            assert (ud == ud0).all() and (lam == 0).all() and (info == 0).all()
            continue
        taken += 1
        assert sv[-1] / sv[0] > WELL_CONDITIONED / 10, trial
        lam_ref = np.linalg.lstsq(Y.T @ Y, res, rcond=None)[0]
        ud_ref = ud0 + np.linalg.solve(Lm.T, Y @ lam_ref)
        np.testing.assert_allclose(lam, lam_ref, atol=1e-12 * (1 + np.abs(lam_ref).max()))
        np.testing.assert_allclose(ud, ud_ref, atol=1e-12 * (1 + np.abs(ud_ref).max()))
        A, Rd, beta = Y.copy(), np.empty(m), np.empty(m)
        r, first = pivoted_qr(A, 1e-9, np.empty(m), Rd, beta)
        assert info[0] == r == m
        assert abs(info[1] - abs(Rd[r - 1]) / first) <= 1e-10 * info[1], trial
    assert taken > 50 and declined > 20
    # more rows than speeds: declined, whatever their conditioning
    Y = rng.standard_normal((2, 3))
    assert not _gram_solve(Y, 3, np.ones(3), np.arange(3.0), np.eye(2), np.zeros(2),
                           np.zeros(3), np.zeros(9), np.empty((3, 3)), np.empty(3), np.empty(3),
                           np.empty(2), np.empty(2))


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
    # from the first call on, the kernel is called frozen, before any check in Python:
    # its own size check is what refuses a wrong length below
    assert ("closed", "jourdain") in m._fast_calls
    assert np.array_equal(m.forward_dynamics(q, u), ref)
    ro = q.copy()
    ro.flags.writeable = False
    strided = np.repeat(q, 2)[::2]
    for qq in (list(q), ro, strided):
        assert np.array_equal(m.forward_dynamics(qq, u), ref)
    q32 = q.astype(np.float32)
    assert np.array_equal(m.forward_dynamics(q32, u), m.forward_dynamics(q32.astype(float), u))
    with pytest.raises(ModelError, match="length"):
        m.forward_dynamics(q[:-1], u)
    with pytest.raises(ModelError, match="length"):
        m.forward_dynamics(q, np.append(u, 0.0))


def _closed_chain(n):
    """``n`` revolute links (axes z, gravity -y) hanging in a half circle from the origin,
    the last one's end pinned back to the ground where it lies (as
    ``benchmarks/constraints.py``'s chains): 5 equations of rank 2, mobility n - 2."""
    length, mass, w = 2.0 / n, 2.0 / n, 0.02
    angles = -np.pi / 2 + np.pi * (np.arange(n) + 0.5) / n
    s = mb.System(f"closed chain of {n}", gravity=(0, -9.81, 0))
    parent = "ground"
    for i in range(n):
        s.add_body(f"link{i}", mass=mass, com=(length / 2, 0, 0),
                   inertia=(mass * 2 * w * w / 12, mass * (length ** 2 + w * w) / 12,
                            mass * (length ** 2 + w * w) / 12))
        s.add_joint(f"q{i}", "revolute", parent, f"link{i}", axis="z",
                    position=(0 if i == 0 else length, 0, 0))
        parent = f"link{i}"
    end = length * np.array([np.cos(angles).sum(), np.sin(angles).sum()])
    s.add_joint("close", "revolute", "ground", parent, axis="z",
                position=(end[0], end[1], 0.0), child_position=(length, 0, 0))
    m = s.compile()
    q0 = np.concatenate([[angles[0]], np.diff(angles)])
    return m, m.project(q0, np.random.default_rng(n).uniform(-0.5, 0.5, n))


def test_articulated_route_on_a_long_closed_chain():
    """A 40-link closed chain (``"auto"`` takes the articulated-body route from 16 speeds): the
    accelerations satisfy ``M u' - f = G^T lam`` (the efforts lie in the row space of
    ``G``, by the recursive Newton-Euler inverse dynamics) and ``G u' = gamma`` (by
    differences of ``G u``), and equal the mass-matrix route's and the Newton-Euler
    system's."""
    m, (q, u) = _closed_chain(40)
    ud = m.forward_dynamics(q, u)
    assert np.array_equal(ud, m.forward_dynamics(q, u, method="articulated"))
    effort = m.effort_array(q, u, ud)
    G = m.constraint_jacobian(q)
    Uq, sv, _ = np.linalg.svd(G.T, full_matrices=False)
    basis = Uq[:, sv > 1e-9 * sv[0]]
    assert np.abs(effort - basis @ (basis.T @ effort)).max() <= 1e-12 * np.abs(effort).max()
    h, qd = 1e-6, m.coordinate_rates(q, u)
    Gdot_u = (m.constraint_jacobian(q + h * qd) - m.constraint_jacobian(q - h * qd)) @ u / (2 * h)
    assert np.abs(G @ ud + Gdot_u).max() <= 1e-6 * (1 + np.abs(G @ ud).max())
    for method in ("jourdain", "newton-euler"):
        other = m.forward_dynamics(q, u, method=method)
        assert np.abs(ud - other).max() <= 1e-9 * np.abs(ud).max(), method
    assert ("closed", "articulated") in m._fast_calls      # called frozen from now on:
    with pytest.raises(ModelError, match="length"):       # the kernel checks the sizes
        m.forward_dynamics(q, u[:-1])


@pytest.mark.parametrize("path, case", [("models/andrews_squeezer.toml", None),
                                        ("models/four_bar.toml", "free"),
                                        ("models/four_bar.toml", "motor")])
def test_articulated_route_equals_the_mass_matrix_route(path, case):
    """``method="articulated"`` (``kernels.loop_articulated``: the tree's articulated-body
    factors, one light solve per independent row, no mass matrix) against the mass-matrix
    route to 1e-10, drives and motors included; with rows chosen that are dependent (a zero
    row, as near a singular configuration) it hands over to the mass-matrix route."""
    from mbdyn.kernels.loop_solve import ROWS
    scene = mb.load_model(path, case)
    m = scene.model
    q, u = m.project(scene.q0, scene.u0 + 0.2)
    ref = m.forward_dynamics(q, u, method="jourdain")
    art = m.forward_dynamics(q, u, method="articulated")
    assert np.abs(art - ref).max() <= 1e-10 * (1 + np.abs(ref).max())
    G = m.constraint_jacobian(q)
    zero = [k for k in range(G.shape[0]) if not G[k].any()]
    info = m._con[7]
    if zero:
        try:                                          # a run's rows, one of them zero
            info[2] = m.constraint_rank(q)[0]
            m.project(q, u)                           # chooses the rows
            info[ROWS + 1] = zero[0]
            again = m.forward_dynamics(q, u, method="articulated")
            assert np.abs(again - ref).max() <= 1e-10 * (1 + np.abs(ref).max())
        finally:
            info[2] = info[ROWS] = -1.0
    y = np.concatenate([q, u])
    assert np.allclose(m.state_derivative(0.0, y, method="articulated")[m.nq:], ref,
                       rtol=0, atol=1e-10 * (1 + np.abs(ref).max()))


def test_runs_by_the_articulated_route():
    """Compiled runs take the articulated-body route (``"auto"`` from 16 free speeds,
    ``kernels.route_entry``'s function by address): a 20-link closed chain over 0.3 s by DOP853
    follows the mass-matrix route's motion and stays on its constraints; a parallelogram
    four-bar forced onto that route passes its singular configuration as the mass-matrix
    route does (named, on the parallelogram branch)."""
    m, (q, u) = _closed_chain(20)
    assert m.formulation() == "articulated"
    runs = {meth: mb.simulate(m, 0.3, q, u, integrator="DOP853", rtol=1e-10, atol=1e-12,
                              method=meth) for meth in ("auto", "jourdain")}
    assert runs["auto"].stats["compiled"]
    assert np.abs(runs["auto"].q[-1] - runs["jourdain"].q[-1]).max() <= 1e-8
    assert runs["auto"].stats["constraint_drift"] <= 1e-10
    from loop_mechanisms import four_bar
    fb = four_bar(a=0.1, b=0.3, c=0.1, d=0.3, g=0.0)
    q, u = fb.assemble({"th2": 2.0}, {"th2": 3.0}, guess={"th3": -2.0, "th4": 2.0})
    with pytest.warns(mb.SingularityWarning, match="singular configuration near t="):
        res = mb.simulate(fb, 0.8, q, u, t_eval=np.linspace(0, 0.8, 81), method="articulated")
    th2 = res.q[:, fb.coordinate_index("th2")]
    assert abs(res.stats["singular_configuration"]["t"] - np.interp(np.pi, th2, res.t)) <= 0.011
    np.testing.assert_allclose(res.q[:, fb.coordinate_index("th4")], th2, atol=1e-8)


def test_min_norm_step_on_chosen_rows_equals_least_squares():
    """A run's minimum-norm step (``min_norm.min_norm_step``) equals numpy's least
    squares on 200 random consistent problems with redundant rows: first by the pivoted
    factorisation (which records its rows and their conditioning), then on the rows it
    chose; rows that lost their conditioning are chosen again."""
    from mbdyn.kernels.loop_solve import ROWS
    from mbdyn.kernels.min_norm import min_norm_step, min_norm_work
    rng = np.random.default_rng(11)
    for trial in range(200):
        nu, m = int(rng.integers(1, 9)), int(rng.integers(1, 16))
        r = int(rng.integers(1, min(nu, m) + 1))
        G = rng.standard_normal((m, r)) @ rng.standard_normal((r, nu))
        rhs = G @ rng.standard_normal(nu)
        ref = np.linalg.lstsq(G, rhs, rcond=1e-9)[0]
        info, work = np.zeros(ROWS + 2 + m), np.empty(min_norm_work(m))
        info[ROWS] = -1.0
        for path in ("pivoted", "chosen"):
            du = np.zeros(nu)
            ratio = min_norm_step(G, rhs, r, du, info, work)
            assert info[ROWS] == r and 0 < ratio <= 1, (trial, path)
            assert np.abs(du - ref).max() <= 1e-8 * (1 + np.abs(ref).max()), (trial, path)
        chosen = info[ROWS + 1:ROWS + 1 + r].copy()
        if r < m:                                     # a weak row among the chosen ones
            weak = int(np.argmin(np.abs(G).sum(axis=1)))
            G[weak] *= 1e-4
            rhs = G @ rng.standard_normal(nu)
            if weak in chosen:
                min_norm_step(G, rhs, r, np.zeros(nu), info, work)
                assert weak not in info[ROWS + 1:ROWS + 1 + r] or np.linalg.matrix_rank(
                    np.delete(G, weak, axis=0), 1e-9) < r, trial


@pytest.mark.parametrize("path, case", [("models/andrews_squeezer.toml", None),
                                        ("models/four_bar.toml", "free")])
def test_projection_steps_on_the_chosen_rows(path, case):
    """A run's projection takes its minimum-norm steps on the rows the last pivoted
    factorisation chose (``min_norm._min_norm_chosen``: ``r x r``, no pivoting) while they
    keep their conditioning: the projected state equals the one the pivoted steps give (to
    rounding), the rows stay chosen; a zero row among them (as near a singular
    configuration) fails the conditioning test and the rows are chosen again."""
    from mbdyn.kernels.loop_solve import ROWS
    scene = mb.load_model(path, case)
    m = scene.model
    info = m._con[7]
    nrows = len(m.constraint_rows)
    rng = np.random.default_rng(3)
    q0, u0 = m.project(scene.q0, scene.u0 + 0.3)
    rank = m.constraint_rank(q0)[0]
    try:
        info[2] = rank                                # as a run holds it
        m.project(q0, u0)                             # the pivoted steps choose the rows
        chosen = info[ROWS:ROWS + 1 + rank].copy()
        assert info[ROWS] == rank < nrows and info[ROWS + 1 + nrows] > 0
        for trial in range(5):
            dq = 1e-6 * rng.standard_normal(m.nq)
            du = 1e-3 * rng.standard_normal(m.nu)
            info[ROWS] = -1.0                         # pivoted steps: the reference
            q_ref, u_ref = m.project(q0 + dq, u0 + du)
            info[ROWS:ROWS + 1 + rank] = chosen
            q_fast, u_fast = m.project(q0 + dq, u0 + du)
            assert np.array_equal(info[ROWS:ROWS + 1 + rank], chosen), trial
            assert np.abs(q_fast - q_ref).max() <= 1e-13, trial
            assert np.abs(u_fast - u_ref).max() <= 1e-12 * (1 + np.abs(u_ref).max()), trial
            phi, psi = m.constraint_residuals(q_fast, u_fast)
            assert np.abs(phi).max() <= 1e-13 and np.abs(psi).max() <= 1e-12
        G = m.constraint_jacobian(q0)
        zero = [k for k in range(nrows) if not G[k].any()]
        if zero:                                      # a planar loop's out-of-plane row
            info[ROWS:ROWS + 1 + rank] = chosen
            info[ROWS + 1] = zero[0]
            q1, u1 = m.project(q0 + dq, u0 + du)
            assert zero[0] not in info[ROWS + 1:ROWS + 1 + rank]
            assert np.abs(q1 - q_ref).max() <= 1e-13
            assert np.abs(u1 - u_ref).max() <= 1e-12 * (1 + np.abs(u_ref).max())
    finally:
        info[2] = info[ROWS] = -1.0
