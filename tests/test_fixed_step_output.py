"""Fixed-step output that keeps its accuracy (issue 27, item 7): the last step lands on
``t_end`` exactly, so an output time ``t_end`` is kept, and output times between the steps
are interpolated by cubic Hermite polynomials on ``q`` and ``u`` (from the derivatives the
steps computed), so that the samples are as accurate as the steps."""
from __future__ import annotations

import numpy as np
import pytest

import mbdyn as mb
from mbdyn.integrate.fixed_step import step_plan, step_times
from mbdyn.integrate.samples import hermite

T_EVAL = np.linspace(0, 4, 41)


@pytest.fixture(scope="module")
def pendulum2():
    return mb.load_model("models/double_pendulum.toml")


@pytest.mark.parametrize("n", [44000, 44001, 88000])
def test_steps_that_reach_t_end_within_rounding_end_on_it(n):
    """44,000 steps of 4/44000 add up to 3.9999999999999996: the last one's time is
    ``t_end`` itself, and no sliver of a step follows."""
    times, h_last = step_plan(0.0, 4.0, 4 / n)
    assert len(times) == n and times[-1] == 4.0 and h_last == 0.0
    assert [len(ts) for _, ts in step_times(0.0, 4.0, 4 / n)] == [n]


def test_a_dt_that_does_not_divide_the_interval_shortens_the_last_step():
    times, h_last = step_plan(0.0, 1.0, 0.3)
    np.testing.assert_allclose(times, [0.3, 0.6, 0.9], rtol=0, atol=1e-15)
    assert h_last == pytest.approx(0.1, abs=1e-15)
    steps = step_times(0.0, 1.0, 0.3)
    assert steps[0][0] == 0.3 and steps[-1][1][-1] == 1.0
    (h, ts), = step_times(0.0, 0.1, 0.3)                   # one short step
    assert h == pytest.approx(0.1) and list(ts) == [0.1]


@pytest.mark.parametrize("n", [44000, 44001, 88000])
def test_every_output_time_is_kept_up_to_t_end(pendulum2, n):
    res = mb.simulate(pendulum2.model, 4.0, pendulum2.q0, pendulum2.u0, integrator="rk4",
                      dt=4 / n, t_eval=T_EVAL)
    assert len(res.t) == 41 and res.t[-1] == 4.0 and res.stats["steps"] == n
    np.testing.assert_array_equal(res.t, T_EVAL)


def test_a_shortened_last_step_ends_on_t_end_and_keeps_its_sample(pendulum2):
    res = mb.simulate(pendulum2.model, 1.0, pendulum2.q0, pendulum2.u0, integrator="rk4",
                      dt=0.003, t_eval=[0.0, 0.5, 0.9995, 1.0])
    assert list(res.t) == [0.0, 0.5, 0.9995, 1.0] and res.stats["steps"] == 334
    full = mb.simulate(pendulum2.model, 1.0, pendulum2.q0, pendulum2.u0, integrator="rk4",
                       dt=0.003)
    assert full.t[-1] == 1.0 and np.array_equal(full.q[-1], res.q[-1])


@pytest.fixture(scope="module")
def reference(pendulum2):
    return mb.simulate(pendulum2.model, 4.0, pendulum2.q0, pendulum2.u0,
                       integrator="DOP853", rtol=1e-12, atol=1e-14, t_eval=T_EVAL)


def test_output_between_the_steps_costs_no_accuracy(pendulum2, reference):
    """RK4 at 48,007 steps (4/48007 does not divide 0.1): its steps are off by about
    6e-9 rad, and so are the samples at 0.1, 0.2, ...; linear interpolation between the
    steps was off by 1.6e-6."""
    kw = {"integrator": "rk4", "dt": 4 / 48007}
    res = mb.simulate(pendulum2.model, 4.0, pendulum2.q0, pendulum2.u0, t_eval=T_EVAL, **kw)
    full = mb.simulate(pendulum2.model, 4.0, pendulum2.q0, pendulum2.u0, **kw)
    at_steps = mb.simulate(pendulum2.model, 4.0, pendulum2.q0, pendulum2.u0,
                           integrator="DOP853", rtol=1e-12, atol=1e-14, t_eval=full.t[::97])
    step_error = np.abs(full.q[::97] - at_steps.q).max()
    sample_error = np.abs(res.q - reference.q).max()
    assert step_error < 1e-8
    assert sample_error < 1.5 * step_error
    assert np.abs(res.u - reference.u).max() < 1e-6
    linear = np.column_stack([np.interp(T_EVAL, full.t, full.q[:, c]) for c in range(2)])
    assert np.abs(linear - reference.q).max() > 100 * sample_error     # what it replaced


@pytest.mark.parametrize("integrator", ["euler", "semi-implicit-euler", "rk4",
                                        "implicit-midpoint"])
def test_dense_output_is_the_hermite_cubic_of_the_steps(pendulum2, integrator):
    """Each sample is the cubic through the two steps that bracket it with the
    right-hand side's derivatives there, in the compiled loops and in Python alike."""
    model, dt = pendulum2.model, 1e-3
    te = np.array([0.0, 0.0013, 0.025, 0.03, 0.04567, 0.0999, 0.1])
    full = mb.simulate(model, 0.1, pendulum2.q0, pendulum2.u0, integrator=integrator, dt=dt)
    y = np.hstack([full.q, full.u])
    f = np.array([model.state_derivative(t, row) for t, row in zip(full.t, y)])
    i = np.clip(np.searchsorted(full.t, te), 1, len(full.t) - 1)
    h = (full.t[i] - full.t[i - 1])[:, None]
    want = hermite(((te - full.t[i - 1])[:, None]) / h, h, y[i - 1], f[i - 1], y[i], f[i])
    want[0] = y[0]
    for compiled in (True, False):
        res = mb.simulate(model, 0.1, pendulum2.q0, pendulum2.u0, integrator=integrator,
                          dt=dt, t_eval=te, compiled_loop=compiled)
        np.testing.assert_allclose(np.hstack([res.q, res.u]), want, rtol=0, atol=1e-12)


def test_hermite_is_exact_for_cubics():
    s = np.linspace(0, 1, 7)[:, None]
    def p(t):
        return 2 * t ** 3 - t ** 2 + 0.5 * t - 1

    def dp(t):
        return 6 * t ** 2 - 2 * t + 0.5

    t0, t1 = 0.3, 1.1
    got = hermite(s, t1 - t0, p(t0), dp(t0), p(t1), dp(t1))
    np.testing.assert_allclose(got[:, 0], p(t0 + s[:, 0] * (t1 - t0)), rtol=0, atol=1e-14)


@pytest.mark.filterwarnings("ignore:overflow:RuntimeWarning")
def test_a_failed_run_keeps_the_samples_up_to_its_last_good_step():
    s = mb.System("blow-up", gravity=(0, 0, 0))
    s.add_body("b", mass=1.0, com=(0, 0, 0))
    s.add_joint("x", "prismatic", parent="ground", child="b", axis="x")
    s.add_load("push", "b", force=lambda t, q, u: (1e300 * np.exp(50 * t), 0, 0))
    with pytest.raises(mb.SimulationError) as info:
        mb.simulate(s, 10.0, integrator="rk4", dt=0.01, t_eval=np.linspace(0, 10, 101))
    res = info.value.result
    assert len(res.t) >= 1 and np.all(np.isfinite(res.q)) and res.t[-1] < 10
