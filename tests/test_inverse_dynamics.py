"""Inverse dynamics and the mass matrix by one compiled call each (``kernels.inverse``): the
recursive Newton-Euler algorithm (``Model.effort_array``, ``inverse_dynamics``,
``LowLevel.inverse_dynamics``) and composite rigid bodies on the joints' motion subspaces
(``Model.mass_matrix``, ``LowLevel.mass_matrix``).

Independent routes they are held to:

* the efforts of the motion forward dynamics gives are zero (the route that makes ``u'``
  shares no code with the backward recursion);
* ``Q(u') - Q(0) = M u'`` with ``M`` by the run's own route (composite inertias with the
  full Jacobians, ``dynamics.composite_mass_matrix``), and ``Q(0) = -f``;
* the joint wrenches of that motion are the reactions of ``Model.reactions`` (dense
  Newton-Euler system with reaction unknowns);
on seeded random trees of every joint kind (drives, massless frames, state-dependent
loads), with the gyroscopic effect on and off, with force elements and actuators, and on
a closed mechanism.
"""
import numpy as np
import pytest

import mbdyn as mb
from random_trees import StateLoad, build_system, cached_tree


def rel(a, b):
    a, b = np.asarray(a, float), np.asarray(b, float)
    return np.abs(a - b).max() / max(np.abs(a).max(), np.abs(b).max(), 1e-300)


def check_model(m, q, u, t, rtol=1e-12):
    """The checks of the module docstring on one model at one state."""
    ud_free = m.forward_dynamics(q, u, t)
    scale = np.abs(m.mass_matrix(q, t) @ ud_free).max() + np.abs(m.forcing(q, u, t)).max()
    assert np.abs(m.effort_array(q, u, ud_free, t)).max() <= rtol * scale
    M_run = m._mass_matrix(q, t, m._jourdain_terms)
    M = m.mass_matrix(q, t)
    assert rel(M, M_run) < 1e-13 and np.array_equal(M, M.T)
    ud = np.random.default_rng(len(q)).normal(size=m.nu)
    Q0 = m.effort_array(q, u, np.zeros(m.nu), t)
    assert rel(Q0, -m.forcing(q, u, t)) < rtol
    assert rel(m.effort_array(q, u, ud, t) - Q0, M_run @ ud) < 1e-11
    efforts, wrenches = m.inverse_dynamics(q, u, ud_free, t)
    assert list(efforts) == list(m.speeds)
    reactions = m.reactions(q, u, t, method="newton-euler-dense")
    for name, (F, Mo) in reactions.items():
        scale_j = max(np.abs(F).max(), np.abs(Mo).max(), 1.0)
        assert np.abs(wrenches[name][0] - F).max() < 1e-10 * scale_j
        assert np.abs(wrenches[name][1] - Mo).max() < 1e-10 * scale_j


@pytest.mark.parametrize("seed", range(16))
def test_random_trees_gyroscopic_on_and_off(seed):
    t = cached_tree(seed)
    if t.model.nu == 0:
        pytest.skip("no free speed")
    check_model(t.model, t.q, t.u, t.t)
    if seed % 4 == 0:
        system, loads = build_system(t.spec)
        off = system.compile(effects={"gyroscopic": False})
        for _, fv, mv in loads:
            for fn in (fv, mv):
                if isinstance(fn, StateLoad):
                    fn.bind(off)
        check_model(off, t.q, t.u, t.t)


@pytest.mark.parametrize("path", ["models/quarter_car.toml", "models/pd_arm.toml",
                                  "models/jeffcott_rotor.toml", "models/rotating_pendulum.toml",
                                  "models/motor_flywheel.toml", "models/gyroscope.toml"])
def test_models_with_force_elements_actuators_and_drives(path):
    scene = mb.load_model(path)
    m = scene.model
    rng = np.random.default_rng(3)
    q = np.asarray(scene.q0, float) + 0.1 * rng.normal(size=m.nq)
    m.normalize_quaternions(q)
    u = rng.normal(size=m.nu)
    check_model(m, q, u, 0.37, rtol=1e-11)


def test_closed_mechanism_takes_its_trees_equations():
    scene = mb.load_model("models/four_bar.toml")
    m = scene.model
    q, u = np.asarray(scene.q0, float), np.asarray(scene.u0, float)
    ud = np.linspace(-1, 1, m.nu)
    assert rel(m.mass_matrix(q), m._mass_matrix(q, 0.0, m._jourdain_terms)) < 1e-13
    Q = m.effort_array(q, u, ud)
    assert rel(Q, m._mass_matrix(q, 0.0, m._jourdain_terms) @ ud - m.forcing(q, u)) < 1e-12
    with pytest.raises(mb.ModelError, match="closed loops"):
        m.lowlevel().inverse_dynamics(q, u, ud)


def test_lowlevel_gives_the_checked_answers_and_refuses_bad_arrays():
    t = cached_tree(7)
    m = t.model
    low = m.lowlevel()
    ud = np.linspace(-2, 2, m.nu)
    assert np.array_equal(low.inverse_dynamics(t.q, t.u, ud, t.t),
                          m.effort_array(t.q, t.u, ud, t.t))
    out, M = np.empty(m.nu), np.empty((m.nu, m.nu))
    assert low.inverse_dynamics(t.q, t.u, ud, t.t, out=out) is out
    assert low.mass_matrix(t.q, t.t, out=M) is M
    assert np.array_equal(M, m.mass_matrix(t.q, t.t))
    with pytest.raises(mb.ModelError, match=r"u_dot must be a contiguous.*list"):
        low.inverse_dynamics(t.q, t.u, list(ud), t.t)
    with pytest.raises(mb.ModelError, match=r"out must be .* shape \(%d, %d\)" % (m.nu, m.nu)):
        low.mass_matrix(t.q, t.t, out=np.empty(m.nu))


def test_ordinary_api_takes_any_numbers_and_names_what_is_wrong():
    t = cached_tree(7)
    m = t.model
    ud = np.linspace(-2, 2, m.nu)
    expected = m.effort_array(t.q, t.u, ud, t.t)
    frozen = t.q.copy()
    frozen.flags.writeable = False
    for q in (list(t.q), frozen, np.repeat(t.q, 2)[::2], t.q.astype(np.float32)):
        tol = 1e-5 if np.asarray(q).dtype == np.float32 else 0
        assert rel(m.effort_array(q, list(t.u), list(ud), t.t), expected) <= tol
        assert rel(m.mass_matrix(q, t.t), m.mass_matrix(t.q, t.t)) <= tol
        assert rel(m.forward_dynamics(q, t.u, t.t), m.forward_dynamics(t.q, t.u, t.t)) <= tol
    with pytest.raises(mb.ModelError, match=f"u_dot needs {m.nu} values"):
        m.effort_array(t.q, t.u, ud[:-1], t.t)
    with pytest.raises(mb.ModelError, match=f"expects q of length {m.nq}"):
        m.mass_matrix(t.q[:-1], t.t)
    bad = t.u.copy()
    bad[0] = np.nan
    with pytest.raises(mb.NonFiniteError, match=m.speeds[0]):
        m.effort_array(t.q, bad, ud, t.t)


@pytest.mark.parametrize("seed", [3, 7, 11])
@pytest.mark.parametrize("bad", [np.nan, np.inf])
def test_mass_matrix_is_finite_or_refused_and_exactly_symmetric(seed, bad):
    """``mass_matrix`` checks only the diagonal for NaN and Inf (``composite_mass_matrix_s``:
    whatever spoils an entry spoils the diagonal entries of the speeds it joins): with one
    coordinate at a time NaN or Inf, on trees of every joint kind, the matrix it returns is
    finite everywhere, or it refuses with ``NonFiniteError``; and it is exactly symmetric
    (the lower triangle mirrored)."""
    t = cached_tree(seed)
    m = t.model
    M = m.mass_matrix(t.q, t.t)
    assert np.array_equal(M, M.T)
    assert rel(M, m._mass_matrix(t.q, t.t, m._jourdain_terms)) < 1e-13
    refused = 0
    for k in range(m.nq):
        q = t.q.copy()
        q[k] = bad
        try:
            M = m.mass_matrix(q, t.t)
        except mb.NonFiniteError:
            refused += 1
            continue
        assert np.isfinite(M).all(), (m.coordinates[k], M)
    assert refused > 0
