"""Flexible bodies in models (docs/flexible.md, "Flexible bodies in models"): records and
modal coordinates, the Jourdain terms against closed forms and published values, the
effects, model files and bad input."""
from __future__ import annotations

import numpy as np
import pytest
import sympy

import mbdyn as mb
from mbdyn.compiled.model import Model
from mbdyn.errors import ModelError

STEEL = {"length": 1.0, "elements": 10, "E": 2.1e11, "rho": 7850.0, "nu": 0.3,
         "section": {"circle": 0.02}}
EB = {**STEEL, "theory": "euler-bernoulli"}


def _area_inertia(d=0.02):
    return np.pi * d ** 2 / 4, np.pi * d ** 4 / 64


def _crossing_frequency(t, x):
    """Frequency (Hz) from the upward zero crossings of ``x(t)`` (cubic-free: dense t)."""
    x = x - x.mean()
    i = np.flatnonzero((x[:-1] < 0) & (x[1:] >= 0))
    tc = t[i] - x[i] * (t[i + 1] - t[i]) / (x[i + 1] - x[i])
    return 1.0 / np.diff(tc).mean()


# ------------------------------------------------------------------ records, coordinates
def test_records_mass_properties_and_modal_coordinates():
    s = mb.System("r", gravity=(0, 0, 0))
    s.add_body("shaft", flexible={"beam": EB, "modes": 3})
    s.add_joint("float", "free", "ground", "shaft")
    m = s.compile()
    assert m.coordinates[-3:] == ("shaft_m1", "shaft_m2", "shaft_m3")
    assert m.speeds[-3:] == ("shaft_m1_dot", "shaft_m2_dot", "shaft_m3_dot")
    assert (m.nq, m.nu) == (10, 9)
    A, I = _area_inertia()
    mass = 7850 * A * 1.0
    body = m.body("shaft")
    assert body.mass == pytest.approx(mass, rel=1e-12)
    assert np.allclose(body.com, [0.5, 0, 0], atol=1e-14)
    assert body.inertia[1, 1] == pytest.approx(mass / 12, rel=1e-12)   # m L^2 / 12
    assert body.inertia[0, 0] == pytest.approx(7850 * 2 * I, rel=1e-12)   # rho Ip L
    # a rigid part at the frame: mass, com and inertia added by the parallel-axis rule
    s2 = mb.System("r2", gravity=(0, 0, 0))
    s2.add_body("shaft", mass=2.0, com=(0, 0.1, 0), inertia=[0.01, 0.02, 0.03],
                flexible={"beam": EB, "modes": 3})
    s2.add_joint("float", "free", "ground", "shaft")
    b2 = s2.compile().body("shaft")
    assert b2.mass == pytest.approx(mass + 2.0)
    assert b2.com == pytest.approx([0.5 * mass / (mass + 2), 0.2 / (mass + 2), 0])
    # named values in q and u: a modal coordinate's name stands for its rate in u
    assert m.u_vector({"shaft_m2": 0.5})[m.speed_index("shaft_m2_dot")] == 0.5


def test_models_without_flexible_bodies_are_as_before():
    s = mb.System("rigid")
    s.add_body("b", mass=1.0, inertia=[1, 1, 1])
    s.add_joint("j", "revolute", "ground", "b", axis="y")
    assert s.effect_names() == ("gravity", "gyroscopic")
    assert type(s.compile()) is Model


def _pendulum(flexible):
    s = mb.System("p")
    if flexible:
        s.add_body("arm", flexible={"beam": STEEL, "modes": 2})
    else:
        rec = _pendulum(True)[1]
        s.add_body("arm", mass=rec.mass, com=rec.com, inertia=rec.inertia)
    s.add_joint("pin", "revolute", "ground", "arm", axis="y")
    return s, s.bodies["arm"]


def test_flexibility_off_is_the_rigid_body_bit_for_bit():
    flex, _ = _pendulum(True)
    rigid, _ = _pendulum(False)
    a = flex.compile(effects="-flexibility_arm")
    b = rigid.compile()
    assert type(a) is Model and a.coordinates == ("pin",)
    ra = mb.simulate(a, 0.5, {"pin": 0.3})
    rb = mb.simulate(b, 0.5, {"pin": 0.3})
    assert np.array_equal(ra.t, rb.t) and np.array_equal(ra.q, rb.q)
    assert np.array_equal(ra.u, rb.u)


# ------------------------------------------------------------------ dynamics
def test_free_floating_beam_conserves_energy_and_momentum():
    s = mb.System("free", gravity=(0, 0, 0))
    s.add_body("shaft", flexible={"beam": STEEL, "modes": 4})
    s.add_joint("float", "free", "ground", "shaft")
    m = s.compile(effects="-geometric_stiffening")
    assert not m.flexible_forces
    u0 = {"float_vx": 0.3, "float_vy": -0.2, "float_wx": 1.0, "float_wy": 2.0,
          "float_wz": 3.0, "shaft_m1_dot": 0.05}
    res = mb.simulate(m, 0.05, {"shaft_m1": 1e-3, "shaft_m3": -5e-4}, u0, rtol=1e-10,
                      atol=1e-12, outputs=("energy", "momentum"),
                      t_eval=np.linspace(0, 0.05, 101))
    E = res.energy["total"]
    assert np.abs(E - E[0]).max() / E[0] < 1e-9
    p, L = res.momentum["linear"], res.momentum["angular"]
    assert np.abs(p - p[0]).max() < 1e-9 * np.abs(p[0]).max()
    assert np.abs(L - L[0]).max() < 1e-9 * np.abs(L[0]).max()
    assert np.abs(res["shaft_m1"]).max() > 1e-3        # the modes do move


def test_cantilever_vibrates_at_its_first_bending_frequency():
    s = mb.System("cantilever", gravity=(0, 0, 0))
    s.add_body("beam", flexible={"beam": EB, "modes": 2})
    s.add_joint("clamp", "fixed", "ground", "beam")
    m = s.compile()
    f_reduced = m.flexible["beam"].reduced.frequencies[0]
    A, I = _area_inertia()
    f_euler_bernoulli = 1.8751040687 ** 2 / (2 * np.pi) * np.sqrt(2.1e11 * I / (7850 * A))
    t = np.linspace(0, 0.3, 6001)
    res = mb.simulate(m, 0.3, {"beam_m1": 1e-3}, rtol=1e-10, atol=1e-13, t_eval=t)
    f_sim = _crossing_frequency(res.t, res["beam_m1"])
    assert abs(f_sim / f_reduced - 1) < 1e-5
    assert abs(f_reduced / f_euler_bernoulli - 1) < 1e-5


def test_cantilever_sags_under_gravity_as_q_L4_over_8_E_I():
    s = mb.System("sag")
    s.add_body("beam", flexible={"beam": EB, "modes": 6})
    s.add_joint("clamp", "fixed", "ground", "beam")
    m = s.compile()
    fb, red = m._flex[0], m.flexible["beam"].reduced
    eta = np.linalg.solve(fb.stiffness, fb.invariants.modal_first_moment.T @ m.gravity)
    assert np.abs(m.forward_dynamics(eta, np.zeros(m.nu))).max() < 1e-9   # at rest
    A, I = _area_inertia()
    tip = red.modes[red.node("tip"), 2] @ eta
    assert tip / (-7850 * A * 9.81 / (8 * 2.1e11 * I)) == pytest.approx(1, abs=5e-4)


def _spinning(spin, modes=3):
    """A rectangular blade (b = 2 h) turning at ``spin`` rad/s about z, Euler-Bernoulli."""
    s = mb.System("spin", gravity=(0, 0, 0))
    s.add_body("blade", flexible={"beam": {"length": 1.0, "elements": 12, "E": 7e10,
                                           "rho": 2700.0, "rect": [0.02, 0.01],
                                           "theory": "euler-bernoulli"}, "modes": modes})
    s.add_joint("hub", "revolute", "ground", "blade", axis="z", drive=spin * mb.t)
    return s.compile()


@pytest.mark.parametrize("plane, ref", [("flap", 3.6816), ("lag", None)])
def test_rotating_cantilever_frequencies(plane, ref):
    """Steady spin at Omega = sqrt(E I_y / (rho A L^4)): flapwise (out of the plane of
    rotation) Hodges & Rutkowski (AIAA J. 19(11), 1981) give 3.6816 in units of that
    rate; lagwise (in plane) the centrifugal stiffening less the spin softening,
    omega^2 = omega_0^2 + (1.1933 - 1) Omega^2 (Southwell)."""
    scale = np.sqrt(7e10 * 0.02 * 0.01 ** 3 / 12 / (2700 * 2e-4))
    m = _spinning(scale)
    red = m.flexible["blade"].reduced
    comp = 2 if plane == "flap" else 1
    tip = red.modes[red.node("tip")]
    k = next(j for j in range(red.n_modes) if abs(tip[comp, j]) > 10 * abs(tip[3 - comp, j]))
    T = 5 / red.frequencies[k]
    res = mb.simulate(m, T, {f"blade_m{k + 1}": 1e-4}, rtol=1e-9, atol=1e-13,
                      t_eval=np.linspace(0, T, 2001))
    x = np.column_stack([res[c] for c in m.coordinates]) @ tip[comp]
    w = 2 * np.pi * _crossing_frequency(res.t, x) / scale
    if ref is None:                     # lag: I_z = 4 I_y, so omega_0 = 2 * 3.5160
        ref = np.sqrt((2 * 1.87510407 ** 2) ** 2 + 0.1933)
    assert w == pytest.approx(ref, rel=5e-4)


def _spin_up(stiffening, t_end):
    """Kane, Ryan and Banerjee (J. Guidance 10(2), 1987): L = 10 m, E = 7e10 Pa,
    A = 4e-4 m^2, I = 2e-7 m^4, rho = 3000 kg/m^3, theta(t) up to Omega_s = 6 rad/s in
    T_s = 15 s.  A tube with that A and I; the tip's deflection in the plane of rotation."""
    A, I, Ws, Ts = 4e-4, 2e-7, 6.0, 15.0
    d_out = np.sqrt((16 * I / A + 4 * A / np.pi) / 2)
    d_in = np.sqrt((16 * I / A - 4 * A / np.pi) / 2)
    t = mb.t
    theta = sympy.Piecewise(
        (Ws / Ts * (t ** 2 / 2 + (Ts / (2 * sympy.pi)) ** 2 * (sympy.cos(2 * sympy.pi * t / Ts) - 1)),
         t < Ts), (Ws * (t - Ts / 2), True))
    s = mb.System("spin_up", gravity=(0, 0, 0))
    s.add_body("beam", flexible={"beam": {"length": 10.0, "elements": 10, "E": 7e10,
                                          "rho": 3000.0, "tube": [d_out, d_in],
                                          "theory": "euler-bernoulli"}, "modes": 4})
    s.add_joint("hub", "revolute", "ground", "beam", axis="z", drive=theta)
    m = s.compile(effects=None if stiffening else "-geometric_stiffening")
    red = m.flexible["beam"].reduced
    res = mb.simulate(m, t_end, rtol=1e-8, atol=1e-10, t_eval=np.linspace(0, t_end, 401))
    eta = np.column_stack([res[c] for c in m.coordinates])
    return res.t, eta @ red.modes[red.node("tip"), 1]


def test_spin_up_beam_stays_bounded_with_geometric_stiffening():
    t, v = _spin_up(True, 20.0)
    # the quasi-static deflection under the peak tangential load rho A alpha x
    # (alpha = 2 Omega_s / T_s at t = T_s / 2) without stiffening: 11 q0 L^4 / (120 E I)
    quasi_static = 11 * (1.2 * 0.8 * 10) * 1e4 / (120 * 14000)        # 0.629 m
    assert -quasi_static < v.min() < -0.8 * quasi_static              # stiffened: less
    assert 6.0 < t[v.argmin()] < 8.5                                  # near T_s / 2
    assert np.abs(v[t > 16]).max() < 0.01                             # back to ~0


def test_spin_up_beam_diverges_without_geometric_stiffening():
    t, v = _spin_up(False, 12.0)
    assert v.min() < -100.0           # spin softening beyond the first bending stiffness


# ------------------------------------------------------------------ routes and refusals
def test_the_jourdain_and_newton_euler_routes_and_the_python_integrators():
    s = mb.System("c", gravity=(0, 0, 0))
    s.add_body("beam", flexible={"beam": STEEL, "modes": 2})
    s.add_joint("clamp", "fixed", "ground", "beam")
    m = s.compile()
    assert m.formulation("auto") == "jourdain" and m.has_callable_loads
    assert m.formulation("newton-euler") == "newton-euler"
    with pytest.raises(ModelError, match="not 'articulated'"):
        mb.simulate(m, 0.01, method="articulated")
    with pytest.raises(ModelError, match="generated right-hand side does not take flex"):
        mb.simulate(m, 0.01, method="symbolic")
    with pytest.raises(ModelError, match="inverse_dynamics is not there yet"):
        m.inverse_dynamics(m.default_coordinates(), np.zeros(m.nu), np.zeros(m.nu))
    res = mb.simulate(m, 0.01, {"beam_m1": 1e-4}, integrator="rk4", dt=1e-4)
    assert res.stats["method"] == "jourdain" and np.all(np.isfinite(res.q))


@pytest.mark.parametrize("flexible, match", [
    ({"beam": STEEL, "modes": 2, "mode": 3}, r"flexible\.mode: unknown key"),
    ({"beam": STEEL}, "give modes = N"),
    ({"beam": STEEL, "data": "x.npz", "modes": 2}, "exactly one of beam"),
    ({"beam": {**STEEL, "section": {"square": 1}}, "modes": 2}, r"flexible\.beam\.section"),
    ({"beam": {**STEEL, "E": -1}, "modes": 2}, r"flexible\.beam\.E: must be > 0"),
    ({"beam": STEEL, "modes": 0}, r"flexible\.modes: must be a whole number"),
    ({"beam": STEEL, "modes": 2, "reduction": "guyan"}, r"flexible\.reduction"),
    ({"data": "/nonexistent/blade.npz"}, r"flexible\.data: no file"),
    ("beam", "must be a table"),
])
def test_bad_flexible_input_names_the_body_and_key(flexible, match):
    s = mb.System("bad")
    with pytest.raises(ModelError, match=match) as info:
        s.add_body("shaft", flexible=flexible)
    assert "body 'shaft'" in str(info.value)


def test_what_attaches_to_a_flexible_body_in_this_step():
    s = mb.System("a")
    s.add_body("shaft", flexible={"beam": STEEL, "modes": 2})
    s.add_joint("clamp", "fixed", "ground", "shaft")
    s.add_body("disk", mass=1.0, inertia=[1, 1, 1])
    s.add_joint("tip", "revolute", "shaft", "disk", axis="x", position=(1, 0, 0))
    assert s.compile().joint("tip").parent == "shaft.tip"     # at the tip's node frame
    s.compile(effects="-flexibility_shaft")           # rigid: anything goes
    s2 = mb.System("b")
    s2.add_body("shaft", flexible={"beam": STEEL, "modes": 2})
    s2.add_joint("pin", "revolute", "ground", "shaft", axis="y")
    s2.add_load("push", "shaft", force=(0, 0, 1), point=(1, 0, 0))
    s2.compile()                                      # loads at nodes are there
    s2.add_force("floor", "contact", body="shaft", center=(1, 0, 0), radius=0.01,
                 stiffness=1e5)
    with pytest.raises(ModelError, match="force 'floor'.*contact at the flexible body "
                                         "'shaft' is not there yet"):
        s2.compile()
    with pytest.raises(ModelError, match="must be an identifier"):
        mb.System("c").add_body("my shaft", flexible={"beam": STEEL, "modes": 2})


# ------------------------------------------------------------------ model files
MODEL = """
[model]
name = "shaft"
gravity = [0, 0, 0]

[[bodies]]
name = "shaft"
flexible = { modes = 6, damping = 0.01, beam = { length = 1.0, elements = 10, E = 2.1e11, rho = 7850, nu = 0.3, section = { circle = 0.02 } } }

[[joints]]
name = "clamp"
kind = "fixed"
parent = "ground"
child = "shaft"

[initial]
shaft_m1 = 1e-3

[simulation]
t_end = 0.02
"""


def test_model_file_flexible_key_initial_values_and_overrides(tmp_path):
    path = tmp_path / "shaft.toml"
    path.write_text(MODEL)
    scene = mb.load_model(path)
    assert scene.model.coordinates == tuple(f"shaft_m{k}" for k in range(1, 7))
    res = scene.simulate()
    assert res["shaft_m1"][0] == 1e-3 and abs(res["shaft_m1"][-1]) < 1e-3
    two = mb.load_model(path, overrides={"bodies.shaft.flexible.modes": 2})
    assert two.model.coordinates == ("shaft_m1", "shaft_m2")
    with pytest.warns(mb.ModelWarning, match="shaft_m1 is ignored"):
        rigid = mb.load_model(path, effects="-flexibility_shaft")
    assert rigid.model.coordinates == ()
    path.write_text(MODEL.replace("modes = 6", "modes = 6, mode = 2"))
    with pytest.raises(mb.ModelError, match=r"bodies\[0\]\.flexible\.mode"):
        mb.load_model(path)


def test_equilibrium_and_modes_see_the_modal_coordinates():
    """A steel beam hanging from a pin: the equilibrium (found among the pin angle and the
    modal coordinates) hangs straight down, and its pendulum mode is the rigid body's
    (flexibility off) to 1e-4 (measured 8.5e-6 below it: the beam gives)."""
    s = mb.System("pendulum", gravity=(0, 0, -9.81))
    s.add_body("shaft", flexible={"beam": STEEL, "modes": 4})
    s.add_joint("pin", "revolute", "ground", "shaft", axis="y")
    found = {}
    for effects in (None, "-flexibility_shaft"):
        m = s.compile(effects=effects)
        q0 = m.default_coordinates()
        q0[0] = 1.5
        eq = mb.equilibrium(m, q0, np.zeros(m.nu))
        assert eq.q[0] == pytest.approx(np.pi / 2, abs=1e-9)
        lin = mb.linearize(m, eq.q, np.zeros(m.nu))
        assert lin.names[:1] == ("pin",) and len(lin.names) == m.nu
        found[effects] = mb.modes(lin).modes[0].natural_frequency
    assert found[None] == pytest.approx(found["-flexibility_shaft"], rel=1e-4)
    assert found[None] < found["-flexibility_shaft"]
