"""The compiled adaptive pairs (``mbdyn/kernels/adaptive.py``): RK45 and DOP853 as compiled
stretches against scipy's solvers of the same names (``scipy-RK45``, ``scipy-DOP853``),
against closed forms, and through events, output times, budgets and failures."""
import warnings

import numpy as np
import pytest
import sympy as sp

import mbdyn as mb
import importlib
from mbdyn.io import load_model
from mbdyn.kernels import adaptive as ka
from mbdyn.integrate.compiled_adaptive import dense_values
from mbdyn.compiled.programs import EventPrograms

from closed_forms import quaternion_zxz
from textbook_systems import DOUBLE_PENDULUM_DATA, TOP_DATA, double_pendulum_system, top_system

budgets = importlib.import_module("mbdyn.integrate.budget")
MODELS = __import__("pathlib").Path(__file__).resolve().parents[1] / "models"
PAIRS = ("RK45", "DOP853")


@pytest.fixture(scope="module")
def pendulum():
    return double_pendulum_system(**DOUBLE_PENDULUM_DATA).compile()


@pytest.fixture(scope="module")
def top():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", mb.ModelWarning)     # the listing's top data
        return top_system(**TOP_DATA, Mz=0.0, joint="spherical").compile()


@pytest.fixture(scope="module")
def oscillator():
    return load_model(MODELS / "mass_spring_damper.toml")


P0 = {"theta1": -np.pi / 4, "theta2": np.pi / 4}


# ------------------------------------------------------------------------ the tableaus
@pytest.mark.parametrize("name, order", [("RK45", 5), ("DOP853", 8)])
def test_tableaus_satisfy_their_order_conditions(name, order):
    """Row sums ``A 1 = c``; the quadrature conditions ``b . c^(k-1) = 1/k`` up to the
    order; the error weights annihilate polynomials the embedded formula integrates."""
    tab = ka.TABLEAUS[name]
    A, B, C = tab.A, tab.B, tab.C
    s = tab.stages
    assert np.allclose(A[:, :].sum(axis=1), C, atol=1e-15)
    c = C[:s - 1]
    for k in range(1, order + 1):
        assert B @ c ** (k - 1) == pytest.approx(1 / k, abs=1e-14), k
    # the step's weights are the last stage's row (first same as last)
    assert np.array_equal(A[s - 1, :s - 1], B) and C[s - 1] == 1.0
    # the difference of a pair integrates low powers exactly: its moments vanish
    cc = C[:s]
    for k in range(1, (4 if name == "RK45" else 5) + 1):
        assert tab.E @ cc ** (k - 1) == pytest.approx(0.0, abs=1e-13), k
    if name == "DOP853":
        for k in range(1, 3 + 1):
            assert tab.E3 @ cc ** (k - 1) == pytest.approx(0.0, abs=1e-13), k


@pytest.mark.parametrize("name", PAIRS)
def test_dense_output_reproduces_polynomials_of_its_degree(name):
    """On ``y' = p(t)`` every stage derivative is ``p`` at the stage time, so the dense
    polynomial must equal the integral of ``p`` exactly up to its order (4 resp. 7)."""
    tab = ka.TABLEAUS[name]
    degree = 3 if name == "RK45" else 6            # p of this degree: y of degree + 1
    coeffs = np.arange(1.0, degree + 2)             # p(t) = sum a_k t^k
    p = lambda t: sum(a * t ** k for k, a in enumerate(coeffs))
    Y = lambda t: sum(a * t ** (k + 1) / (k + 1) for k, a in enumerate(coeffs))
    h = 0.7
    K = np.array([[p(c * h)] for c in tab.C])
    y_old, y_new = np.array([Y(0.0)]), np.array([Y(h)])
    n_dense = 3 + tab.D.shape[0]
    F = np.empty((n_dense, 1))
    F[0] = y_new - y_old
    F[1] = h * K[0] - F[0]
    F[2] = F[0] - h * K[tab.stages - 1] - F[1]
    F[3:] = h * tab.D @ K
    x = np.linspace(0, 1, 11)
    got = dense_values(F, y_old, x)[:, 0]
    assert np.allclose(got, [Y(v * h) for v in x], rtol=1e-13, atol=1e-13)


def test_a_non_finite_stage_stops_the_kernel_with_its_state(pendulum):
    """Status 1 and the offending stage state in ``fail_y`` when a stage's derivative is
    not finite (here a derivative so large that the first stage overflows)."""
    args = pendulum.loop_arguments()
    tab = ka.TABLEAUS["DOP853"]
    y = np.array([0.1, 0.2, 0.0, 0.0])
    f = np.array([0.0, 0.0, 1e308, 1e308])
    m, n = 4, y.size
    out = (np.empty(m), np.empty((m, n)), np.empty(m), np.empty(m, np.int64),
           np.empty(m, np.int64), np.empty((0, tab.stages, n)), np.empty(n + 1),
           np.zeros(1, np.int64))
    no_drives = (np.empty((0, 2), np.int64), np.empty(0), np.zeros(1, np.int64))
    acc, status, _, _ = ka.rk_stretch(*tab.arrays(), 0.0, 1.0, y, f, 10.0, 1e-9, 1e-12,
                                      np.inf, m, np.empty(0), 0, np.empty((0, n)), *no_drives,
                                      *args, *out, EventPrograms.none(),
                                      ka.stretch_scratch(tab.A, tab.D, n, 0))
    assert (acc, status) == (0, 1)
    with pytest.raises(mb.NonFiniteError, match="non-finite"):
        pendulum.state_derivative(out[6][0], out[6][1:])    # the stage it left


# ---------------------------------------------------------------- against scipy's solvers
def _pair(model, integrator, t_end, q0=None, u0=None, **kw):
    a = mb.simulate(model, t_end, q0, u0, integrator=integrator, **kw)
    b = mb.simulate(model, t_end, q0, u0, integrator="scipy-" + integrator, **kw)
    assert a.stats["compiled"] is True and b.stats["compiled"] is False
    return a, b


@pytest.mark.parametrize("integrator", PAIRS)
def test_double_pendulum_agrees_with_scipy(pendulum, integrator):
    rtol, atol = 1e-9, 1e-12
    a, b = _pair(pendulum, integrator, 2.0, P0, rtol=rtol, atol=atol)
    assert abs(a.stats["steps"] - b.stats["steps"]) <= 0.03 * b.stats["steps"]
    assert np.allclose(a.q[-1], b.q[-1], rtol=0, atol=1e-7)
    assert np.allclose(a.u[-1], b.u[-1], rtol=0, atol=1e-6)
    # nearly the same step sequence: the first steps' error estimates are at the level of
    # roundoff (the compiled loop's right-hand side and the Python entry's, which scipy
    # calls, round differently: sums in another order, fused multiply-adds), so the first
    # step sizes differ (from rest, by up to 50 % at the fourth step, depending on which
    # specializations numba's cache holds), up to 1.3 % still at t = 0.05 s, until the
    # controller settles
    assert len(a.t) == len(b.t)
    late, settled = b.t > 0.05, b.t > 1.0
    assert np.allclose(a.t[late], b.t[late], rtol=3e-2, atol=5e-5)
    assert np.allclose(a.t[settled], b.t[settled], rtol=1e-3, atol=5e-5)


@pytest.mark.parametrize("integrator", PAIRS)
def test_top_with_a_quaternion_joint_agrees_with_scipy(top, integrator):
    q0 = quaternion_zxz(0.0, 0.5, 0.0)
    a, b = _pair(top, integrator, 1.0, q0, [0.5, 0.3, 40.0], rtol=1e-8, atol=1e-10)
    assert abs(a.stats["steps"] - b.stats["steps"]) <= max(2, 0.03 * b.stats["steps"])
    assert np.allclose(a.q[-1], b.q[-1], atol=1e-6) and np.allclose(a.u[-1], b.u[-1], atol=1e-4)
    assert a.stats["quaternion_drift"] == pytest.approx(b.stats["quaternion_drift"], abs=1e-7)


def _oscillator_closed_form(t, x0=0.1, m=2.0, k=800.0, c=4.0):
    wn = np.sqrt(k / m)
    zeta = c / (2 * np.sqrt(k * m))
    wd = wn * np.sqrt(1 - zeta ** 2)
    return x0 * np.exp(-zeta * wn * t) * (np.cos(wd * t)
                                         + zeta / np.sqrt(1 - zeta ** 2) * np.sin(wd * t))


@pytest.mark.parametrize("integrator", PAIRS)
def test_force_element_oscillator_matches_scipy_and_the_closed_form(oscillator, integrator):
    """The damped oscillator of ``models/mass_spring_damper.toml`` (spring-damper force
    elements) at the file's output times: compiled dense output against scipy's and against
    ``x(t)``."""
    res = oscillator.simulate(integrator=integrator, rtol=1e-10, atol=1e-12)
    ref = oscillator.simulate(integrator="scipy-" + integrator, rtol=1e-10, atol=1e-12)
    assert res.stats["compiled"] and not ref.stats["compiled"]
    assert np.array_equal(res.t, ref.t) and len(res.t) == 3001
    assert np.abs(res["x"] - ref["x"]).max() < 1e-9
    assert np.abs(res["x"] - _oscillator_closed_form(res.t)).max() < 1e-8
    assert abs(res.stats["steps"] - ref.stats["steps"]) <= max(2, 0.03 * ref.stats["steps"])


@pytest.mark.parametrize("integrator", PAIRS)
def test_samples_at_output_times_match_the_states_there(pendulum, integrator):
    """Dense output at ``t_eval`` equals a run that steps to each of those times."""
    t_eval = np.linspace(0.0, 1.0, 7)[1:]
    dense = mb.simulate(pendulum, 1.0, P0, integrator=integrator, t_eval=t_eval,
                        rtol=1e-10, atol=1e-12)
    assert np.array_equal(dense.t, t_eval)
    for k, te in enumerate(t_eval):
        direct = mb.simulate(pendulum, te, P0, integrator=integrator, rtol=1e-12, atol=1e-14)
        assert np.allclose(dense.q[k], direct.q[-1], atol=5e-9), te
    ref = mb.simulate(pendulum, 1.0, P0, integrator="scipy-" + integrator, t_eval=t_eval,
                      rtol=1e-10, atol=1e-12)
    assert np.allclose(dense.q, ref.q, atol=1e-9) and np.allclose(dense.u, ref.u, atol=1e-8)


# ------------------------------------------------------------------------------ events
@pytest.mark.parametrize("integrator", PAIRS)
def test_events_match_scipys_path(pendulum, integrator):
    events = [mb.Event("theta1 up", "theta1 >= 0"),                    # text: vectorized
              mb.Event("theta2 down", lambda t, q, u: q[1], direction=-1),
              mb.Event("either", lambda t, q, u: u[0], direction=0),
              mb.Event("stop", "theta1 >= 0.7", terminal=True)]
    a, b = _pair(pendulum, integrator, 3.0, P0, events=events)
    assert [e.name for e in a.events] == [e.name for e in b.events] and len(a.events) > 3
    assert np.allclose([e.t for e in a.events], [e.t for e in b.events], rtol=0, atol=1e-9)
    assert a.events[-1].name == "stop" and a.t[-1] == a.events[-1].t
    assert np.allclose(a.q[-1], a.events[-1].q, atol=0) and a.q[-1][0] == pytest.approx(0.7)
    assert a.stats["steps"] == b.stats["steps"]
    # with output times: those up to the terminal event, then the event's state
    t_eval = np.linspace(0, 3.0, 31)
    a, b = _pair(pendulum, integrator, 3.0, P0, events=events, t_eval=t_eval)
    assert np.allclose(a.t, b.t, atol=1e-9) and np.allclose(a.q, b.q, atol=1e-8)


def test_an_event_that_turns_non_finite_fails_as_on_scipys_path(pendulum):
    bad = mb.Event("log", lambda t, q, u: np.log(q[1] + 0.8))
    with pytest.raises(mb.SimulationError, match="event 'log': the condition is not a finite") \
            as a:
        mb.simulate(pendulum, 3.0, P0, events=[bad])
    with pytest.raises(mb.SimulationError) as b:
        mb.simulate(pendulum, 3.0, P0, events=[bad], integrator="scipy-DOP853")
    # the same message; the step it names ends where each solver's steps fall
    assert str(a.value).split("(integration")[0].split(" at t=")[0] == \
        str(b.value).split("(integration")[0].split(" at t=")[0]
    ta, tb = a.value.result.t[-1], b.value.result.t[-1]
    assert abs(ta - tb) < 0.02 and np.log(a.value.result.q[-1][1] + 0.8) > -np.inf


# ---------------------------------------------------------------- budgets and failures
@pytest.mark.parametrize("integrator", PAIRS)
def test_max_steps_and_max_samples_stop_where_scipys_path_stops(pendulum, integrator):
    for kw, what in ((dict(max_steps=37), "max_steps = 37"),
                     (dict(max_samples=20), "max_samples = 20")):
        with pytest.raises(mb.SimulationError, match=what) as a:
            mb.simulate(pendulum, 4.0, P0, integrator=integrator, **kw)
        with pytest.raises(mb.SimulationError, match=what) as b:
            mb.simulate(pendulum, 4.0, P0, integrator="scipy-" + integrator, **kw)
        ra, rb = a.value.result, b.value.result
        assert ra.stats["steps"] == rb.stats["steps"] and len(ra.t) == len(rb.t)
        # the first steps' sizes differ (roundoff-level error estimates, up to 50 % at the
        # fourth step from rest; see test_double_pendulum_agrees_with_scipy): the two stop
        # at the same step, near the same time
        assert ra.t[-1] == pytest.approx(rb.t[-1], rel=0.05)


def test_the_step_projection_trips_as_on_scipys_path(pendulum, monkeypatch):
    monkeypatch.setattr(budgets, "PROJECTION_STEPS", 50)
    for integrator in ("DOP853", "scipy-DOP853"):
        with pytest.raises(mb.SimulationError, match="would need about") as info:
            mb.simulate(pendulum, 40.0, P0, integrator=integrator, max_steps=2000)
        assert info.value.result.stats["steps"] == 50


def test_step_size_underflow_fails_as_on_scipys_path():
    """A body spinning at 1e153 rad/s needs steps below the roundoff of t."""
    s = mb.System("spinner", gravity=(0, 0, 0))
    s.add_body("b", mass=1.0, inertia=np.diag([1.0, 2.0, 3.0]))
    s.add_joint("j", "spherical", "ground", "b")
    model = s.compile()
    messages = []
    for integrator in ("DOP853", "scipy-DOP853"):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", RuntimeWarning)
            with pytest.raises(mb.SimulationError, match="Required step size") as info:
                mb.simulate(model, 1.0, None, [1e153, 1e153, 0.0], integrator=integrator)
        messages.append(str(info.value).replace("scipy-", ""))
        assert np.all(np.isfinite(info.value.result.q))
    assert messages[0] == messages[1]


def test_the_singularity_monitor_stops_both_paths_alike():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        model = top_system(**TOP_DATA, Mz=0.0, joint="euler").compile()
        out = []
        for integrator in ("DOP853", "scipy-DOP853"):
            with pytest.raises(mb.SimulationError, match="singular configuration") as info:
                mb.simulate(model, 2.0, {"theta": 0.05}, {"psi": 0.0, "theta": -2.0,
                                                          "phi": 1.0},
                            integrator=integrator, singularity_threshold=1e-2)
            out.append(info.value)
    assert str(out[0]) .split(" between")[0] == str(out[1]).split(" between")[0]
    assert out[0].result.stats["steps"] == out[1].result.stats["steps"]


# ---------------------------------------------------------------------- where it applies
def test_models_with_function_loads_or_untranslatable_drives_take_scipys_path(pendulum):
    s = double_pendulum_system(**DOUBLE_PENDULUM_DATA)
    s.add_load("push", "link2", force=lambda t, q, u: (0.001 * np.sin(t), 0.0, 0.0))
    assert not mb.simulate(s.compile(), 0.2, P0).stats["compiled"]
    assert not mb.simulate(pendulum, 0.2, P0, compiled_loop=False).stats["compiled"]
    assert not mb.simulate(pendulum, 0.2, P0, method="newton-euler").stats["compiled"]
    assert mb.simulate(pendulum, 0.2, P0).stats["compiled"]
    t = mb.t
    for drive in (sp.Piecewise((t ** 3, t < 1), (3 * t - 2, True)),            # no program
                  (lambda x: 0.1 * x, lambda x: 0.1, lambda x: 0.0)):          # Python
        s = mb.System("driven", gravity=(0, -9.81, 0))
        s.add_body("arm", mass=1.0, com=(0.1, 0, 0), inertia=np.eye(3) * 1e-3)
        s.add_joint("turn", "revolute", "ground", "arm", axis="y", drive=drive)
        s.add_body("bob", mass=1.0, com=(0, -0.5, 0))
        s.add_joint("swing", "revolute", "arm", "bob", axis="z", position=(0.1, 0, 0))
        assert not mb.simulate(s.compile(), 0.2, {"swing": 0.3}).stats["compiled"]


@pytest.mark.parametrize("integrator", PAIRS)
def test_driven_models_run_compiled_and_agree_with_scipy(integrator):
    """Drives as programs evaluated at each stage time (``mbdyn.compiled.programs``): the rotating
    pendulum (two driven joints) and a drive with elementary functions."""
    rot = load_model(MODELS / "rotating_pendulum.toml")
    assert rot.model.driven_joints
    a = rot.simulate(t_end=0.5, integrator=integrator)
    b = rot.simulate(t_end=0.5, integrator="scipy-" + integrator)
    assert a.stats["compiled"] and not b.stats["compiled"]
    assert np.array_equal(a.t, b.t) and np.abs(a.q - b.q).max() < 1e-8
    t = mb.t
    s = mb.System("shaken", gravity=(0, -9.81, 0))
    s.add_body("cart", mass=1.0)
    s.add_joint("shake", "prismatic", "ground", "cart", axis="x",
                drive=0.05 * sp.sin(7 * t) * sp.exp(-t / 2) + sp.atan(t) ** 2 / 10)
    s.add_body("bob", mass=1.0, com=(0, -0.5, 0))
    s.add_joint("swing", "revolute", "cart", "bob", axis="z")
    model = s.compile()
    a, b = _pair(model, integrator, 2.0, {"swing": 0.3}, rtol=1e-10, atol=1e-12,
                 t_eval=np.linspace(0, 2, 21))
    assert np.abs(a.q - b.q).max() < 1e-8 and np.abs(a.u - b.u).max() < 1e-7
    assert abs(a.stats["steps"] - b.stats["steps"]) <= max(2, 0.03 * b.stats["steps"])


def test_drive_programs_evaluate_as_the_drives_do():
    from mbdyn.elements.joints import make_drive
    from mbdyn.kernels.programs import STACK, drive_values
    from mbdyn.compiled.programs import drive_programs
    t = mb.t
    exprs = (3 * t, sp.sin(2 * t) ** 2 + sp.exp(-t / 3) * sp.cos(t),
             sp.Rational(1, 2) * t ** 2 - sp.pi * t, sp.sqrt(t + 1) + sp.log(t + 2) + sp.atan(t),
             sp.tanh(t) * sp.cosh(t / 4) + sp.atan2(t, 2) + sp.asin(t / 9) * sp.tan(t / 5))
    drives = [make_drive(e, "j") for e in exprs]
    programs = drive_programs(drives)
    out = np.empty((len(drives), 3))
    for tt in (0.0, 0.37, 1.9, -0.6):
        drive_values(*programs, tt, np.empty(STACK), out)
        ref = [[d.position(tt), d.velocity(tt), d.acceleration(tt)] for d in drives]
        assert np.allclose(out, ref, rtol=1e-14, atol=1e-14), tt


def test_scipy_names_are_valid_in_model_files(tmp_path):
    text = (MODELS / "mass_spring_damper.toml").read_text()
    text = text.replace("[simulation]\n", '[simulation]\nintegrator = "scipy-RK45"\n')
    path = tmp_path / "msd.toml"
    path.write_text(text)
    res = load_model(path).simulate(t_end=0.1)
    assert res.stats["integrator"] == "scipy-RK45" and not res.stats["compiled"]
    assert "scipy-DOP853" in mb.INTEGRATORS


def test_a_tolerance_below_roundoff_is_raised_as_scipy_does(pendulum):
    for integrator in PAIRS:
        with pytest.warns(UserWarning, match="rtol` is too small"):
            a = mb.simulate(pendulum, 0.02, P0, integrator=integrator, rtol=1e-17)
        with pytest.warns(UserWarning, match="rtol` is too small"):
            b = mb.simulate(pendulum, 0.02, P0, integrator="scipy-" + integrator, rtol=1e-17)
        assert abs(a.stats["steps"] - b.stats["steps"]) <= max(2, 0.03 * b.stats["steps"])
        assert np.allclose(a.q[-1], b.q[-1], atol=1e-12)


def test_scipy_names_on_the_command_line(capsys):
    from mbdyn.cli import main
    path = str(MODELS / "mass_spring_damper.toml")
    for name in ("scipy-DOP853", "scipy-RK45", "RK45"):
        assert main(["run", path, "--t-end", "0.05", "--integrator", name]) == 0
        assert f"integrator {name}," in capsys.readouterr().out


def test_max_wall_time_stops_the_compiled_path_between_stretches(pendulum):
    with pytest.raises(mb.SimulationError, match="max_wall_time") as info:
        mb.simulate(pendulum, 40.0, P0, max_wall_time=1e-9)
    kept = info.value.result
    assert kept.stats["compiled"] and 0 < kept.t[-1] < 40.0
    assert kept.stats["steps"] == len(kept.t) - 1
