"""Equilibrium, linearisation, modes and Campbell diagrams, against free responses,
closed forms and the symbolic route."""
import sys
import warnings
from pathlib import Path

import numpy as np
import pytest

import mbdyn as mb
from mbdyn.analysis.equilibrium import EquilibriumError
from mbdyn.errors import ModelError, SingularMassMatrixError

HERE = Path(__file__).resolve().parent
MODELS = HERE.parent / "models"
sys.path.insert(0, str(HERE))

from random_trees import random_tree  # noqa: E402


def scene(name, **kw):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", mb.ModelWarning)
        return mb.load_model(MODELS / f"{name}.toml", **kw)


def peaks(t, x):
    """Times and values of the local maxima of samples ``x(t)``, refined by a parabola."""
    k = np.flatnonzero((x[1:-1] > x[:-2]) & (x[1:-1] >= x[2:])) + 1
    out_t, out_x = [], []
    for i in k:
        a, b, c = x[i - 1], x[i], x[i + 1]
        h = t[i + 1] - t[i]
        d = 0.5 * (a - c) / (a - 2 * b + c)
        out_t.append(t[i] + d * h)
        out_x.append(b - 0.25 * (a - c) * d)
    return np.array(out_t), np.array(out_x)


# ----------------------------------------------------------------------------- free response
def test_modes_match_a_free_response_of_the_damped_oscillator():
    sc = scene("mass_spring_damper")
    md = mb.modes(mb.linearize(sc.model))
    mode = md[0]
    res = mb.simulate(sc.model, 3.0, {"x": 1e-4}, integrator="DOP853", rtol=1e-12,
                      atol=1e-16, t_eval=np.linspace(0, 3, 30001))
    tp, xp = peaks(res.t, res["x"])
    wd = 2 * np.pi / np.mean(np.diff(tp))
    decrement = np.mean(np.log(xp[:-1] / xp[1:]))
    assert wd == pytest.approx(mode.damped_frequency, rel=1e-4)
    assert decrement == pytest.approx(mode.log_decrement, rel=1e-4)
    # and the closed form: w_n = sqrt(k/m), zeta = c / (2 sqrt(k m))
    assert mode.natural_frequency == pytest.approx(20.0, rel=1e-9)
    assert mode.damping_ratio == pytest.approx(0.05, rel=1e-9)


def rotating_pendulum_frequency(p, beta):
    """The textbook's equation of the rotating pendulum linearised about beta, with the
    disk at rest on the arm (omega = 0, W = Omega): d(rhs)/d(beta)."""
    g, l, b, r, W = p["g"], p["l"], p["b"], p["r"], p["Omega"]
    return np.sqrt(g / l * np.cos(beta) + (b * W ** 2 + r * W ** 2) / l * np.sin(beta)
                   - W ** 2 * np.cos(2 * beta))


def test_rotating_pendulum_relative_equilibrium_and_frequency_closed_form():
    sc = scene("rotating_pendulum", overrides={"parameters.omega": 0.0,
                                               "parameters.Omega": 2.5})
    p = sc.parameters
    eq = mb.equilibrium(sc.model, {"beta": 0.3})
    beta = eq.q[0]
    g, l, b, r, W = p["g"], p["l"], p["b"], p["r"], p["Omega"]
    # the text's equation of motion at rest: g sin b - (b W^2 + r W^2) cos b - l W^2 sin b cos b
    assert (g * np.sin(beta) - (b + r) * W ** 2 * np.cos(beta)
            - l * W ** 2 * np.sin(beta) * np.cos(beta)) == pytest.approx(0, abs=1e-10)
    assert not eq.time_dependent
    md = mb.modes(mb.linearize(sc.model, eq.q))
    assert md[0].natural_frequency == pytest.approx(rotating_pendulum_frequency(p, beta),
                                                    rel=1e-7)
    # the free response about the equilibrium
    res = mb.simulate(sc.model, 6.0, {"beta": beta + 1e-5}, integrator="DOP853", rtol=1e-13,
                      atol=1e-16, t_eval=np.linspace(0, 6, 60001))
    tp, _ = peaks(res.t, res["beta"])
    assert 2 * np.pi / np.mean(np.diff(tp)) == pytest.approx(md[0].damped_frequency, rel=1e-4)


def test_rotating_pendulum_with_the_disk_turning_is_only_instantaneously_at_rest():
    sc = scene("rotating_pendulum")
    eq = mb.equilibrium(sc.model, {"beta": 0.3}, t=0.0)
    assert eq.time_dependent


# ----------------------------------------------------------------------------- closed forms
def test_double_pendulum_of_equal_masses_has_the_classic_frequencies():
    """Two equal point masses on equal massless rods: w^2 = (g/l)(2 -+ sqrt 2) (Landau and
    Lifshitz, Mechanics, section 23, problem 1; Goldstein, Classical Mechanics, ch. 6)."""
    g, l, m = 9.81, 0.5, 1.3
    s = mb.System("double pendulum", gravity=(0, -g, 0))
    s.add_body("m1", mass=m, com=(0, -l, 0))
    s.add_joint("t1", "revolute", parent="ground", child="m1", axis="z")
    s.add_body("m2", mass=m, com=(0, -l, 0))
    s.add_joint("t2", "revolute", parent="m1", child="m2", axis="z", position=(0, -l, 0))
    md = mb.modes(mb.linearize(s.compile()))
    w = sorted(mode.natural_frequency for mode in md)
    assert w == pytest.approx(np.sqrt(g / l * np.array([2 - np.sqrt(2), 2 + np.sqrt(2)])),
                              rel=1e-9)
    assert md.stable


def isotropic_rotor(k=1e4, m=2.0, c=4.0):
    s = mb.System("isotropic rotor", gravity=(0, 0, 0), parameters={"Omega": 100.0})
    Omega = s.symbols("Omega")
    s.add_frame("cy")
    s.add_joint("y", "prismatic", parent="ground", child="cy", axis="y")
    s.add_frame("centre")
    s.add_joint("z", "prismatic", parent="cy", child="centre", axis="z")
    s.add_body("disk", mass=m, inertia=[0.02, 0.01, 0.01])
    s.add_joint("spin", "revolute", parent="centre", child="disk", axis="x",
                drive=Omega * mb.t)
    s.add_force("bearing", "bearing", body="disk", axis="x", kxx=k, kyy=k, cxx=c, cyy=c)
    return s


def test_isotropic_jeffcott_rotor_critical_speed_is_sqrt_k_over_m():
    k, m, c = 1e4, 2.0, 4.0

    def build(Omega):
        s = isotropic_rotor(k, m, c)
        s.parameters["Omega"] = Omega
        return s.compile()
    cb = mb.campbell(build, "Omega", np.linspace(20, 120, 11), whirl=[("y", "z")])
    wd = np.sqrt(k / m) * np.sqrt(1 - (c / (2 * np.sqrt(k * m))) ** 2)
    assert np.allclose(cb.frequency, wd, rtol=1e-9)
    crit = [v for mode, order, v in cb.critical]
    assert crit and all(v == pytest.approx(wd, rel=1e-9) for v in crit)
    whirls = {cb.whirl[0][j] for j in range(2)}
    assert whirls == {"forward", "backward"}
    assert not cb.onset


def test_cross_coupled_bearing_gives_an_onset_of_instability_at_the_predicted_speed():
    """Circulatory stiffness a = kxy = -kyx on an isotropic rotor with damping c: the forward
    mode's real part is (a/(m w_n) - c/m)/2 to first order; with a growing with speed
    (a = beta * Omega), the onset is where beta Omega = c w_n -- check it against the
    exact eigenvalue crossing."""
    k, m, c, beta = 1e4, 2.0, 8.0, 6.0
    wn = np.sqrt(k / m)

    def build(Omega):
        s = mb.System("rotor", gravity=(0, 0, 0))
        s.add_frame("cy")
        s.add_joint("y", "prismatic", parent="ground", child="cy", axis="y")
        s.add_body("disk", mass=m, inertia=[0.02, 0.01, 0.01])
        s.add_joint("z", "prismatic", parent="cy", child="disk", axis="z")
        s.add_force("bearing", "bearing", body="disk", axis="x", kxx=k, kyy=k, cxx=c,
                    cyy=c, kxy=beta * Omega, kyx=-beta * Omega)
        return s.compile()
    cb = mb.campbell(build, "Omega", np.linspace(50, 150, 21), whirl=[("y", "z")])
    assert len(cb.onset) == 1
    mode, value = cb.onset[0]
    # exact: the eigenvalues of m s^2 + c s + k -+ i a = 0 cross the axis at a = c sqrt(k/m)
    assert value == pytest.approx(c * wn / beta, rel=2e-3)     # linear interpolation
    assert cb.whirl[-1][mode] == "forward"


def test_fast_top_nutation_frequency_against_the_routhian_and_c_spin_over_a():
    """Heavy symmetric top in steady precession: the nutation frequency from the modes
    against the reduced (Routhian) system -- w^2 = U''(theta)/A with the effective potential
    U = (p_psi - p_phi cos th)^2 / (2 A sin^2 th) + m g h cos th at the conserved momenta --
    and, for a fast top, against C w3 / A."""
    sc = scene("top", overrides={"parameters.Mz": 0.0})
    p = sc.parameters
    m, g, h, A, C = p["m"], p["g"], p["h"], p["A"], p["C"]
    theta = 0.5
    for spin in (50.0, 200.0, 800.0):
        # steady precession rate (slow root) for this spin: C w3 psi' - A psi'^2 cos = m g h
        w3 = spin
        a_, b_, c_ = A * np.cos(theta), -C * w3, m * g * h
        psid = (-b_ - np.sqrt(b_ ** 2 - 4 * a_ * c_)) / (2 * a_)
        phid = w3 - psid * np.cos(theta)
        q = {"psi": 0.0, "theta": theta, "phi": 0.0}
        u = {"psi_dot": psid, "theta_dot": 0.0, "phi_dot": phid}
        acc = sc.model.forward_dynamics(sc.model.q_vector(q), sc.model.u_vector(u))
        assert np.abs(acc).max() < 1e-9 * max(1.0, psid * phid)       # steady indeed
        md = mb.modes(mb.linearize(sc.model, q, u))
        nut = max(md, key=lambda mo: mo.damped_frequency).damped_frequency
        p_phi = C * w3
        p_psi = A * psid * np.sin(theta) ** 2 + p_phi * np.cos(theta)

        def U(th):
            return ((p_psi - p_phi * np.cos(th)) ** 2 / (2 * A * np.sin(th) ** 2)
                    + m * g * h * np.cos(th))
        dth = 1e-4
        U2 = (U(theta + dth) - 2 * U(theta) + U(theta - dth)) / dth ** 2
        assert nut == pytest.approx(np.sqrt(U2 / A), rel=1e-6)
        if spin >= 800:
            assert nut == pytest.approx(C * w3 / A, rel=2e-2)


# ----------------------------------------------------------------------------- two routes
def assert_same_linearisation(a, b, tol=1e-7):
    """Relative agreement, made dimensionless by the mass matrix: M^-1 (D, G) against the
    model's frequency scale w, M^-1 (K, N) against w^2 (w^2 = the largest entry of
    M^-1 (K + N); 1 if there is no stiffness)."""
    assert np.abs(a.M - b.M).max() <= tol * np.abs(b.M).max()
    Minv = np.linalg.inv(b.M)
    w2 = np.abs(Minv @ (b.K + b.N)).max()
    w = np.sqrt(w2) if w2 > 0 else max(np.abs(Minv @ (b.D + b.G)).max(), 1.0)
    for key, scale in (("D", w), ("G", w), ("K", w * w), ("N", w * w)):
        err = np.abs(Minv @ (getattr(a, key) - getattr(b, key))).max()
        assert err <= tol * scale, (key, err, scale)

@pytest.mark.parametrize("name, case", [("double_pendulum", None), ("rotating_pendulum", None),
                                        ("top", "a"), ("spherical_pendulum", None),
                                        ("gyroscope", None), ("mass_spring_damper", None),
                                        ("jeffcott_rotor", None)])
def test_symbolic_and_numeric_linearisations_agree(name, case):
    sc = scene(name, case=case)
    model = sc.model
    rng = np.random.default_rng(3)
    q = sc.q0 + rng.uniform(-0.2, 0.2, model.nq) * (model.nq > 0)
    model.normalize_quaternions(q)
    u = sc.u0 + rng.uniform(-0.5, 0.5, model.nu)
    a = mb.linearize(model, q, u, t=0.3)
    b = mb.linearize(model, q, u, t=0.3, route="symbolic")
    assert_same_linearisation(a, b)
    assert a.error < 1e-7


@pytest.mark.parametrize("seed", [1, 2, 3, 4])
def test_symbolic_and_numeric_linearisations_agree_on_random_trees(seed):
    tree = random_tree(100 + seed, 4, loads=False)
    model = tree.model
    a = mb.linearize(model, tree.q, tree.u, t=tree.t)
    b = mb.linearize(model, tree.q, tree.u, t=tree.t, route="symbolic")
    assert_same_linearisation(a, b)
    assert len(a.names) == model.nu                # quaternions: 3 tangent coordinates


def test_random_trees_cover_quaternion_joints():
    kinds = set()
    for seed in (1, 2, 3, 4):
        kinds |= random_tree(100 + seed, 4, loads=False).kinds
    assert {"spherical", "free"} & kinds


# ----------------------------------------------------------------------------- Campbell
def test_campbell_keeps_mode_identity_through_a_crossing():
    """Two uncoupled oscillators, x with stiffness p (rising) and y fixed: their frequencies
    cross at p = 400.  Sorting by frequency would swap the labels; MAC tracking must not."""
    def build(p):
        s = mb.System("two oscillators", gravity=(0, 0, 0))
        s.add_frame("cx")
        s.add_joint("x", "prismatic", parent="ground", child="cx", axis="x")
        s.add_body("b", mass=1.0, inertia=[1e-3] * 3)
        s.add_joint("y", "prismatic", parent="cx", child="b", axis="y")
        s.add_force("kx", "joint-spring-damper", joint="x", stiffness=p, damping=0.1)
        s.add_force("ky", "joint-spring-damper", joint="y", stiffness=400.0, damping=0.3)
        return s.compile()
    values = np.linspace(100, 900, 17) + 7.0           # never exactly at the crossing
    cb = mb.campbell(build, "p", values, spin_is_parameter=False)
    lin0 = mb.linearize(build(values[0]))
    first = mb.modes(lin0)
    x_mode = [k for k, mo in enumerate(first) if mo.participation[0] > 0.99][0]
    # the tracked x mode follows sqrt(p) all the way, through the crossing
    assert cb.frequency[:, x_mode] == pytest.approx(np.sqrt(values - 0.1 ** 2 / 4), rel=1e-6)
    assert cb.mac.min() > 0.99


# ----------------------------------------------------------------------------- errors
def test_no_equilibrium_is_an_error_carrying_the_last_iterate():
    sc = scene("top")          # a spinning, precessing top has no static equilibrium
    with pytest.raises(EquilibriumError) as info:
        mb.equilibrium(sc.model, sc.q0, sc.u0)
    assert info.value.last is not None and np.all(np.isfinite(info.value.last))
    assert "no equilibrium" in str(info.value)


def test_steady_precession_of_the_top_holding_the_cyclic_angles():
    """Given the precession and spin rates, the nutation angle of steady precession:
    sin th (m g h + psi'^2 (A - C) cos th - C phi' psi') = 0."""
    sc = scene("top", overrides={"parameters.Mz": 0.0})
    p = sc.parameters
    m, g, h, A, C = p["m"], p["g"], p["h"], p["A"], p["C"]
    target, phid = 0.45, 60.0
    a_, b_, c_ = (A - C) * np.cos(target), -C * phid, m * g * h
    psid = min(np.roots([a_, b_, c_]).real, key=abs)     # the slow precession
    u = {"psi_dot": psid, "phi_dot": phid}
    eq = mb.equilibrium(sc.model, {"theta": 0.4}, u, fixed=["psi", "phi"])
    theta = eq.q[sc.model.coordinate_index("theta")]
    assert np.cos(theta) == pytest.approx((C * phid * psid - m * g * h)
                                          / (psid ** 2 * (A - C)), rel=1e-9)
    assert theta == pytest.approx(target, rel=1e-9)
    with pytest.warns(mb.SingularityWarning):        # the only root for these rates: th = 0
        mb.equilibrium(sc.model, sc.q0, sc.u0, fixed=["psi", "phi"])


def test_singular_mass_matrix_at_the_operating_point_is_named():
    sc = scene("top")
    with pytest.raises(SingularMassMatrixError):
        mb.linearize(sc.model, {"psi": 0, "theta": 0.0, "phi": 0})


def test_unknown_parameter_and_bad_input_are_clear_errors():
    sc = scene("jeffcott_rotor")
    with pytest.raises(ModelError, match="'Omegaa' is not a parameter.*Omega"):
        mb.campbell(sc, "Omegaa", [100, 200])
    with pytest.raises(ModelError, match="unknown coordinate 'nope'"):
        mb.equilibrium(sc.model, fixed=["nope"])
    with pytest.raises(ModelError, match="whirl pair"):
        mb.modes(mb.linearize(sc.model), whirl=[("y", "w")])


# ----------------------------------------------------------------------------- commands
def run_cli(*args):
    import subprocess
    return subprocess.run([sys.executable, "-m", "mbdyn", *args], capture_output=True,
                          text=True, cwd=HERE.parent, timeout=600)


def test_commands_json_and_plot(tmp_path):
    import json
    out = run_cli("modes", "models/mass_spring_damper.toml", "--json")
    assert out.returncode == 0, out.stderr
    d = json.loads(out.stdout)
    assert d["modes"][0]["natural_frequency"] == pytest.approx(20.0, rel=1e-9)
    assert d["linearization"]["coordinates"] == ["x"]
    assert d["stable"] is True
    plot = tmp_path / "campbell.png"
    out = run_cli("campbell", "models/jeffcott_rotor.toml", "--parameter", "Omega",
                  "--values", "100:500:5", "--whirl", "y,z", "--json", "--plot", str(plot))
    assert out.returncode == 0, out.stderr
    d = json.loads(out.stdout)["campbell"]
    assert d["parameter"] == "Omega" and len(d["values"]) == 5
    assert plot.stat().st_size > 10000
    out = run_cli("equilibrium", "models/top.toml", "--set", "parameters.Mz=0",
                  "--fixed", "psi,phi", "--json")
    assert out.returncode == 0, out.stderr
    assert json.loads(out.stdout)["equilibrium"]["residual"] < 1e-9
    out = run_cli("campbell", "models/jeffcott_rotor.toml", "--parameter", "Omega",
                  "--values", "1:2:1")
    assert out.returncode == 1 and "START:STOP:N" in out.stderr


def test_geometric_stiffness_of_a_preloaded_spring():
    """A string under tension T resists a sideways displacement with stiffness T / L (its
    own stiffness k acts only along it): both routes, and the string's frequency."""
    L, T, k, m = 0.8, 50.0, 3000.0, 0.4
    s = mb.System("string", gravity=(0, 0, 0))
    s.add_body("bead", mass=m)
    s.add_joint("y", "prismatic", parent="ground", child="bead", axis="y")
    s.add_force("string", "spring-damper", body_a="ground", point_a=(-L, 0, 0),
                body_b="bead", stiffness=k, free_length=L, preload=T)
    model = s.compile()
    for route in ("numeric", "symbolic"):
        lin = mb.linearize(model, route=route)
        assert lin.K[0, 0] == pytest.approx(T / L, rel=1e-7), route
    assert mb.modes(mb.linearize(model))[0].natural_frequency == pytest.approx(
        np.sqrt(T / (L * m)), rel=1e-7)

def test_a_guess_where_newton_cannot_start_settles_by_dynamic_relaxation():
    # an arm held horizontal: gravity's torque has no stiffness there (a singular
    # Jacobian), so Newton and scipy's root fail from it; the model settles hanging down
    import math
    s = mb.System("arm", gravity=(0, 0, -9.81))
    s.add_body("upper", mass=2.0, com=(0.3, 0, 0), inertia=(0.01, 0.05, 0.05))
    s.add_joint("shoulder", "revolute", parent="ground", child="upper", axis="y")
    s.add_body("fore", mass=1.0, com=(0.25, 0, 0), inertia=(0.005, 0.02, 0.02))
    s.add_joint("elbow", "revolute", parent="upper", child="fore", axis="y",
                position=(0.6, 0, 0))
    m = s.compile()
    eq = mb.equilibrium(m)
    assert eq.method == "dynamic relaxation, then newton"
    # hanging: both links along -z, i.e. shoulder = +pi/2 about y, elbow = 0
    assert abs(math.remainder(eq.q[0] - math.pi / 2, 2 * math.pi)) < 1e-9
    assert abs(eq.q[1]) < 1e-9 and eq.residual < 1e-9


def test_campbell_crossings_of_heavily_damped_modes_are_no_critical_speeds():
    """A spin line crossed by a lightly damped mode is a critical speed; by a mode damped
    above ``CRITICALLY_DAMPED`` (amplification factor below 2.5, API 684), a crossing
    listed apart with its damping ratio, interpolated at the crossing."""
    from mbdyn.analysis.campbell import CRITICALLY_DAMPED, _crossings_of
    values = np.array([0.0, 100.0, 200.0])
    freq = np.array([[150.0, 150.0], [150.0, 100.0], [150.0, 50.0]])
    real = -np.ones((3, 2))
    zeta = np.array([[0.05, 0.1], [0.05, 0.5], [0.05, 0.9]])
    critical, onset, damped = _crossings_of(values, freq, real, zeta, [1], True)
    assert critical == [(0, 1, 150.0)] and onset == []
    assert damped[0][:3] == (1, 1, 100.0) and damped[0][3] == pytest.approx(0.5)
    assert 0.05 < CRITICALLY_DAMPED < 0.5
