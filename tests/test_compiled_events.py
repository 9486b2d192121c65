"""Event conditions compiled: text and sympy conditions become programs of the stack machine
(``mbdyn.compiled.programs``), evaluated after every step inside the compiled loops.

Checked against independent routes: numpy's evaluation of the same sympy expression
(``lambdify``), and the same run with the conditions given as Python functions, which
Python checks after each stretch of steps.
"""
import numpy as np
import pytest
import sympy as sp

import mbdyn as mb
from mbdyn.integrate.events import as_event
from mbdyn.kernels import adaptive as ka
from mbdyn.compiled.programs import EventPrograms

L, THETA0 = 0.8, 1.0

# every function a model file may call, constants, parameters, powers and t
CONDITIONS = [
    "theta >= 0.25", "sin(theta) + cos(2*theta_dot) - tan(theta/3)",
    "asin(theta/2) - acos(theta/3) + atan(theta_dot)", "atan2(theta, theta_dot) < 1",
    "sinh(theta) * cosh(theta_dot) - tanh(t)", "sqrt(theta) - exp(-t) + log(t + 1)",
    "log(theta_dot, 10) - 0.1", "abs(theta_dot) - 1", "sign(theta) * theta_dot**2 - 0.5",
    "min(theta, theta_dot, 0.3) + max(t, 2*theta) - 1", "theta**3 - 0.7 / (theta_dot + 2)",
    "(theta - 0.5)**(1/3) + pi", "theta_dot**-2 - t**2.5",
]


@pytest.fixture(scope="module")
def pendulum():
    s = mb.System("pendulum")
    s.add_body("bob", mass=1.3, com=(0, 0, -L))
    s.add_joint("theta", "revolute", "ground", "bob", axis="x")
    return s.compile()


def _condition(pendulum, text):
    return as_event(mb.Event("e", text), pendulum).condition


@pytest.mark.parametrize("text", CONDITIONS)
def test_a_condition_program_gives_numpys_value(pendulum, text):
    """The compiled program and numpy's evaluation of the same expression agree to the last
    bits on random states, NaN where numpy gives NaN (a square root or logarithm of a
    negative number, an arcsine beyond 1)."""
    g = _condition(pendulum, text)
    assert g.program is not None, text            # every model-file function compiles
    rng = np.random.default_rng(7)
    ts = rng.uniform(0, 3, 200)
    ys = rng.uniform(-2.5, 2.5, (200, 2))
    with np.errstate(all="ignore"):
        expected = np.array([float(g.fn(t, *y)) for t, y in zip(ts, ys)])
    got = g.rows(ts, ys)
    one_by_one = np.array([g(t, y[:1], y[1:]) for t, y in zip(ts, ys)])
    assert np.array_equal(got, one_by_one, equal_nan=True)
    finite = np.isfinite(expected)
    assert finite.sum() >= 20
    assert np.array_equal(np.isnan(got), np.isnan(expected)), text
    assert np.allclose(got[finite], expected[finite], rtol=1e-13, atol=1e-14), text


def test_conditions_the_machine_cannot_read_stay_with_numpy(pendulum):
    """A Piecewise (or a Python function) has no program: the run checks it in Python,
    and a set with one such condition is checked in Python as a whole."""
    theta, t = sp.Symbol("theta"), sp.Symbol("t")
    piecewise = as_event(mb.Event("p", sp.Piecewise((theta, t < 1), (theta - 0.1, True))),
                         pendulum)
    assert piecewise.condition.program is None
    assert EventPrograms.of([piecewise]) is None
    text = as_event(mb.Event("x", "theta <= 0"), pendulum)
    function = as_event(mb.Event("f", lambda t, q, u: q[0]), pendulum)
    assert EventPrograms.of([text]) is not None
    assert EventPrograms.of([text, function]) is None
    res = mb.simulate(pendulum, 1.5, {"theta": THETA0}, integrator="DOP853",
                      events=[mb.Event("p", piecewise.condition, direction=-1)])
    assert [n for n, _ in res.events] == ["p"]


def _events(kind):
    """Four events, as text (compiled) or as the same functions of (t, q, u) (Python)."""
    if kind == "text":
        return [mb.Event("down", "theta <= 0"), mb.Event("slow", "abs(theta_dot) - 1.2"),
                mb.Event("half way up", "theta <= -0.5"),
                mb.Event("late", "t >= 2.3451", terminal=True)]
    return [mb.Event("down", lambda t, q, u: q[0], direction=-1),
            mb.Event("slow", lambda t, q, u: abs(u[0]) - 1.2),
            mb.Event("half way up", lambda t, q, u: q[0] + 0.5, direction=-1),
            mb.Event("late", lambda t, q, u: t - 2.3451, terminal=True, direction=1)]


@pytest.mark.parametrize("integrator", ["DOP853", "RK45", "rk4", "semi-implicit-euler"])
def test_compiled_conditions_find_the_events_python_finds(pendulum, integrator):
    """The same steps, the same events at the same times, and the run ends at the terminal
    one, whether the loops check the conditions or Python does."""
    kw = dict(integrator=integrator, rtol=1e-10, atol=1e-12) if integrator.isupper() \
        else dict(integrator=integrator, dt=2e-3)
    a = mb.simulate(pendulum, 6.0, {"theta": THETA0}, events=_events("text"), **kw)
    b = mb.simulate(pendulum, 6.0, {"theta": THETA0}, events=_events("functions"), **kw)
    assert [n for n, _ in a.events] == [n for n, _ in b.events]
    assert len(a.events) >= 6 and a.events[-1][0] == "late"
    assert np.allclose([t for _, t in a.events], [t for _, t in b.events], rtol=0, atol=1e-13)
    assert np.array_equal(a.t[:-1], b.t[:-1]) and abs(a.t[-1] - b.t[-1]) < 1e-13
    assert np.allclose(a.q, b.q, rtol=0, atol=1e-12) and a.stats["steps"] == b.stats["steps"]


def test_a_fixed_step_loop_stops_at_the_terminal_event(pendulum):
    """No step is taken past the terminal event: the evaluations are the steps' (four an
    RK4 step), where Python's check after a stretch of steps would have wasted the rest of
    the stretch."""
    stop = mb.Event("down", "theta <= 0", terminal=True)
    res = mb.simulate(pendulum, 5.0, {"theta": THETA0}, integrator="rk4", dt=1e-3,
                      events=[stop])
    steps = res.stats["steps"]
    assert res["theta"][-2] > 0 >= res["theta"][-1] or res.t[-1] == res.events[0][1]
    assert res.stats["rhs_evaluations"] == 4 * steps
    python = mb.simulate(pendulum, 5.0, {"theta": THETA0}, integrator="rk4", dt=1e-3,
                         events=[mb.Event("down", lambda t, q, u: q[0], True, -1)])
    assert python.stats["steps"] == steps
    assert python.stats["rhs_evaluations"] > 4 * steps     # it ran to the stretch's end


def test_an_adaptive_stretch_ends_at_a_crossing_with_its_stages(pendulum):
    """The kernel stops after the step in which a condition crossed zero, keeps that step's
    stages (for the dense output), and leaves the conditions at every step in ``out_g``."""
    events = [as_event(mb.Event("down", "theta <= 0"), pendulum)]
    programs = EventPrograms.of(events)
    tab = ka.TABLEAUS["DOP853"]
    y = np.array([THETA0, 0.0])
    f = pendulum.state_derivative(0.0, y)
    m, n = 500, y.size
    out = (np.empty(m), np.empty((m, n)), np.empty(m), np.empty(m, np.int64),
           np.empty(m, np.int64), np.empty((1, tab.stages, n)), np.empty(n + 1),
           np.zeros(1, np.int64))
    checks = programs.arguments([THETA0], m, True)
    no_drives = (np.empty((0, 2), np.int64), np.empty(0), np.zeros(1, np.int64))
    acc, status, _, _ = ka.rk_stretch(*tab.arrays(), 0.0, 10.0, y, f, 0.01, 1e-10, 1e-12,
                                      np.inf, m, np.empty(0), 0, np.empty((0, n)), *no_drives,
                                      *pendulum.loop_arguments(), *out, checks,
                                      ka.stretch_scratch(tab.A, tab.D, n, 0))
    theta = out[1][:acc, 0]
    assert status == 0 and 2 < acc < m
    assert theta[-1] <= 0 < theta[-2]                         # the crossing step, and no more
    assert np.array_equal(checks[6][:acc, 0], theta)          # g = theta at every step
    assert checks[5][0] == theta[-1]
    K = out[5][0]                                             # the last step's stages
    assert np.allclose(K[0], pendulum.state_derivative(out[0][acc - 2], out[1][acc - 2]),
                       rtol=1e-14, atol=1e-14)


def test_a_state_of_the_wrong_size_is_refused_before_the_compiled_program_reads_it(pendulum):
    g = _condition(pendulum, "theta + theta_dot")
    assert g(0.0, [0.25], [0.5]) == 0.75
    with pytest.raises(mb.ModelError, match="expected q and u of 2 values in all.*got 1"):
        g(0.0, [0.25], [])
    with pytest.raises(mb.ModelError, match=r"one state row per time \(3\), got states of shape \(2, 2\)"):
        g.rows(np.zeros(3), np.zeros((2, 2)))
    with pytest.raises(mb.ModelError, match="got 3"):
        g.rows(np.zeros(2), np.zeros((2, 3)))


def test_a_condition_compiled_for_one_model_is_recompiled_for_another_order(pendulum):
    """A compiled condition reads the state by position: given to a model whose
    coordinates and speeds come in another order, it is compiled again by name."""
    s = mb.System("two")
    s.add_body("a", mass=1.0, com=(0, 0, -L))
    s.add_joint("phi", "revolute", "ground", "a", axis="x")
    s.add_body("b", mass=1.0, com=(0, 0, -L))
    s.add_joint("theta", "revolute", "a", "b", axis="x", position=(0, 0, -L))
    two = s.compile()
    g = _condition(pendulum, "theta - 2 * theta_dot")          # pendulum: y = [theta, theta_dot]
    again = as_event(mb.Event("e", g), two).condition           # two: [phi, theta, phi_dot, ...]
    assert again is not g
    assert again(0.0, [0.1, 0.7], [0.2, 0.3]) == pytest.approx(0.7 - 2 * 0.3, abs=1e-15)
    assert as_event(mb.Event("e", g), pendulum).condition is g   # same order: kept as it is
    s2 = mb.System("other")
    s2.add_body("c", mass=1.0, com=(0, 0, -L))
    s2.add_joint("psi", "revolute", "ground", "c", axis="x")
    with pytest.raises(mb.ModelError, match="theta.*not t, coordinates or speeds"):
        as_event(mb.Event("e", g), s2.compile())
