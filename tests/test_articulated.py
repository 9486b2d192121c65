"""The O(n) routes -- the articulated-body algorithm and the Newton-Euler system eliminated
in tree order -- against the dense routes and against an extended-precision reference.

* On seeded random trees of every joint kind (drives, massless frames, loads, callables),
  ``"articulated"`` and ``"newton-euler"`` (tree order) give the accelerations of
  ``"jourdain"`` and ``"newton-euler-dense"``, and the same reactions as the dense system;
* on a 50-link ball chain with cond(M) about 5e7 they keep 1e-12 against ``M u' = f``
  evaluated and solved in ``longdouble`` independently of the engine, where ``M u' = f``
  in double keeps about 1e-10;
* far from the world origin (1e4 m) every route keeps 1e-10;
* ``auto`` picks by size, the compiled loops run either route, and the low-level entry
  gives the checked calls' answers.
"""
import numpy as np
import pytest

import mbdyn as mb
from mbdyn.algorithms.forward_dynamics import ARTICULATED_FROM
from ball_chain import ball_chain, reference_accelerations
from random_trees import StateLoad, build_system, cached_tree

ROUTES = ("articulated", "newton-euler", "newton-euler-dense")


def rel(a, b):
    a, b = np.asarray(a, float), np.asarray(b, float)
    return np.linalg.norm(a - b) / max(np.linalg.norm(a), np.linalg.norm(b), 1e-300)


@pytest.mark.parametrize("seed", range(50))
def test_every_route_gives_the_same_accelerations_and_reactions_on_random_trees(seed):
    t = cached_tree(seed)
    m = t.model
    ref = m.forward_dynamics(t.q, t.u, t.t, method="jourdain")
    for route in ROUTES:
        ud = m.forward_dynamics(t.q, t.u, t.t, method=route)
        assert rel(ud, ref) < 1e-9, f"seed {seed}, {route}: {rel(ud, ref):.2e}"
    dense = m.reactions(t.q, t.u, t.t, method="newton-euler-dense")
    tree = m.reactions(t.q, t.u, t.t, method="newton-euler")
    inverse = m.reactions(t.q, t.u, t.t, method="articulated")
    scale = max([1.0] + [max(np.abs(f).max(), np.abs(mo).max()) for f, mo in dense.values()])
    for name in dense:
        for k in range(2):
            assert np.abs(tree[name][k] - dense[name][k]).max() <= 1e-9 * scale, name
            assert np.abs(inverse[name][k] - dense[name][k]).max() <= 1e-9 * scale, name
    if m.nu:
        y = np.concatenate([t.q, t.u])
        a = m.state_derivative(t.t, y, "articulated")
        b = m.state_derivative(t.t, y, "jourdain")
        assert rel(a, b) < 1e-9


@pytest.mark.parametrize("seed", [3, 11, 17])
def test_routes_agree_with_the_gyroscopic_effect_off(seed):
    t = cached_tree(seed)
    system, loads = build_system(t.spec)
    m = system.compile(effects={"gyroscopic": False})
    for _, fv, mv in loads:
        for fn in (fv, mv):
            if isinstance(fn, StateLoad):
                fn.bind(m)
    ref = m.forward_dynamics(t.q, t.u, t.t, method="jourdain")
    assert rel(ref, t.model.forward_dynamics(t.q, t.u, t.t)) > 1e-6   # the switch matters here
    for route in ROUTES:
        assert rel(m.forward_dynamics(t.q, t.u, t.t, method=route), ref) < 1e-9


@pytest.mark.parametrize("seed", range(12))
def test_mass_matrix_and_forcing_by_one_call_are_the_runs_numbers(seed):
    """``forcing`` takes one packed call; the checks of a run take the kernels one by one
    (no extra compiled entry point): bit for bit the same, with drives, state-dependent
    loads and the gyroscopic effect on or off.  ``mass_matrix`` takes another algorithm
    (composite rigid bodies on the joints' motion subspaces, ``kernels.inverse``) than the
    run's (the full Jacobians): the same to rounding, and exactly symmetric."""
    t = cached_tree(seed)
    models = [t.model]
    if seed % 3 == 0:
        system, loads = build_system(t.spec)
        off = system.compile(effects={"gyroscopic": False})
        for _, fv, mv in loads:
            for fn in (fv, mv):
                if isinstance(fn, StateLoad):
                    fn.bind(off)
        models.append(off)
    for m in models:
        M = m.mass_matrix(t.q, t.t)
        run = m._mass_matrix(t.q, t.t, m._jourdain_terms)
        assert np.abs(M - run).max() <= 1e-14 * np.abs(run).max()
        f = m.forcing(t.q, t.u, t.t)
        m._jourdain_terms(t.q, t.u, t.t)
        assert np.array_equal(f, m._f)
        assert np.array_equal(M, M.T)
        assert np.allclose(run, run.T, rtol=0, atol=1e-12 * np.abs(run).max())


@pytest.mark.skipif(np.finfo(np.longdouble).eps > 1e-18,
                    reason="needs an extended-precision longdouble for the reference")
def test_ill_conditioned_ball_chain_keeps_its_digits():
    model, q, u, spec = ball_chain(50, radius=0.02)
    cond = np.linalg.cond(model.mass_matrix(q))
    assert 1e7 < cond < 1e9
    exact, M = reference_accelerations(spec, q, u)
    # the reference is independent: its M agrees with the engine's to rounding
    assert rel(model.mass_matrix(q), M.astype(float)) < 1e-14
    exact = exact.astype(float)
    errors = {route: rel(model.forward_dynamics(q, u, method=route), exact)
              for route in ("jourdain",) + ROUTES}
    for route in ("articulated", "newton-euler"):       # the O(n) routes
        assert errors[route] < 1e-12, errors
    assert errors["jourdain"] < 1e-9, errors                  # M u' = f keeps ~1e-10
    assert errors["articulated"] < errors["jourdain"] / 10, errors


def _pendulum(offset):
    s = mb.System("double pendulum far away", gravity=(0, -9.81, 0))
    s.add_body("base")
    s.add_joint("place", "fixed", "ground", "base", position=offset)
    s.add_body("l1", mass=1.0, com=(0, -0.5, 0), inertia=mb.inertia.rod(1.0, 1.0, axis="y"))
    s.add_body("l2", mass=0.5, com=(0, -0.4, 0), inertia=mb.inertia.rod(0.5, 0.8, axis="y"))
    s.add_joint("theta1", "revolute", "base", "l1", axis="z")
    s.add_joint("theta2", "revolute", "l1", "l2", axis="x", position=(0, -1, 0))
    return s.compile()


def test_far_from_the_world_origin_no_route_loses_digits():
    q, u = np.array([0.3, -0.7]), np.array([1.5, -2.0])
    near = _pendulum((0, 0, 0)).forward_dynamics(q, u, method="articulated")
    assert rel(near, _pendulum((0, 0, 0)).forward_dynamics(q, u, method="jourdain")) < 1e-14
    far = _pendulum((1e4, -1e4, 1e4))       # positions themselves keep ~1e-12 m there
    errors = {route: rel(far.forward_dynamics(q, u, method=route), near)
              for route in ("articulated", "newton-euler", "jourdain")}
    assert errors["articulated"] < 1e-11 and errors["newton-euler"] < 1e-11, errors
    # the mass matrix is assembled about the first frame's origin, not the world's (about
    # the world origin it kept 3e-7 here)
    assert errors["jourdain"] < 1e-10, errors


def test_auto_picks_by_size_and_simulations_run_either_route():
    small = _pendulum((0, 0, 0))
    assert small.formulation() == "jourdain"
    chain, q, u, _ = ball_chain(4)
    assert chain.nu >= ARTICULATED_FROM and chain.formulation() == "articulated"
    with pytest.raises(mb.ModelError, match="unknown method 'crba'"):
        chain.formulation("crba")
    runs = {}
    for method in ("jourdain", "articulated"):
        for integrator, kw in (("rk4", {"dt": 1e-3}), ("DOP853", {"rtol": 1e-11})):
            res = mb.simulate(chain, 0.2, q, u, integrator=integrator, method=method, **kw)
            assert res.stats["method"] == method
            runs[method, integrator] = np.concatenate([res.q[-1], res.u[-1]])
    assert rel(runs["articulated", "rk4"], runs["jourdain", "rk4"]) < 1e-11
    assert rel(runs["articulated", "DOP853"], runs["jourdain", "DOP853"]) < 1e-8
    assert mb.simulate(chain, 0.01, q, u).stats["method"] == "articulated"


def test_a_degree_of_freedom_without_inertia_is_named_by_every_route():
    s = mb.System("massless leaf")
    s.add_body("arm", mass=1.0, com=(0.5, 0, 0), inertia=np.eye(3) * 0.1)
    s.add_body("tip")
    s.add_joint("shoulder", "revolute", "ground", "arm", axis="z")
    s.add_joint("wrist", "revolute", "arm", "tip", axis="z", position=(1, 0, 0))
    m = s.compile(check_inertia=False)
    for route in ("jourdain",) + ROUTES[:2]:
        with pytest.raises(mb.SingularMassMatrixError, match="wrist"):
            m.forward_dynamics([0.1, 0.2], [0.0, 0.0], method=route)
    with pytest.raises(mb.SingularMassMatrixError, match="wrist"):
        m.lowlevel("articulated").forward_dynamics(np.array([0.1, 0.2]), np.zeros(2))


def test_a_non_finite_state_is_named_by_the_articulated_route():
    m = _pendulum((0, 0, 0))
    with pytest.raises(mb.NonFiniteError, match="theta2"):
        m.forward_dynamics([0.1, np.nan], [0.0, 0.0], method="articulated")


def test_lowlevel_entry_gives_the_checked_answers_and_refuses_bad_arrays():
    t = cached_tree(5)
    m = t.model
    y = np.concatenate([t.q, t.u])
    for method in ("jourdain", "articulated"):
        fast = m.lowlevel(method)
        ud = fast.forward_dynamics(t.q, t.u, t.t)
        assert np.array_equal(ud, m.forward_dynamics(t.q, t.u, t.t, method=method))
        out = np.empty(m.nu)
        assert fast.forward_dynamics(t.q, t.u, t.t, out=out) is out
        assert np.array_equal(fast.state_derivative(y, t.t),
                              m.state_derivative(t.t, y, method))
    assert m.lowlevel().method == m.formulation()
    fast = m.lowlevel()
    frozen = t.q.copy()
    frozen.flags.writeable = False
    for bad, what in ((list(t.q), "list"), (t.q.astype(np.float32), "float32"),
                      (np.zeros(m.nq + 1), r"shape \(%d,\)" % (m.nq + 1)),
                      (np.zeros(2 * m.nq)[::2], "non-contiguous"), (frozen, "read-only")):
        with pytest.raises(mb.ModelError, match=f"q must be a contiguous, writable float64.*{what}"):
            fast.forward_dynamics(bad, t.u, t.t)
    with pytest.raises(mb.ModelError, match="y must be a contiguous, writable float64"):
        fast.state_derivative(t.q)
    with pytest.raises(mb.ModelError, match="out must be"):
        fast.state_derivative(y, t.t, out=np.empty(len(y) - 1))
    with pytest.raises(mb.ModelError, match=r"out must be.*shape \(%d,\)" % m.nu):
        fast.forward_dynamics(t.q, t.u, t.t, out=np.empty(m.nu + 1))
    assert len(fast._fd.signatures) == len(fast._sd.signatures) == 1   # nothing compiled anew
    with pytest.raises(mb.ModelError, match="unknown method"):
        m.lowlevel("newton-euler-dense")
