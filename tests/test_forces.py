"""Force elements and effects, each checked against an independent route: closed forms,
energy balances, potentials by finite differences, and the other formulation."""
from pathlib import Path

import numpy as np
import pytest

import mbdyn as mb
from mbdyn.errors import ModelError

MODELS = Path(__file__).resolve().parent.parent / "models"


# ----------------------------------------------------------------------------- helpers
def oscillator(k=800.0, c=4.0, m=2.0, L0=0.5, **spring):
    s = mb.System("oscillator", gravity=(0, 0, -9.81))
    s.add_body("block", mass=m)
    s.add_joint("x", "prismatic", parent="ground", child="block", axis="x")
    s.add_force("spring", "spring-damper", body_a="ground", point_a=(-L0, 0, 0),
                body_b="block", free_length=L0, **({"stiffness": k} | spring))
    if c:
        s.add_force("damper", "spring-damper", body_a="ground", point_a=(-L0, 0, 0),
                    body_b="block", damping=c)
    return s


def every_kind_system():
    """Three bodies on revolute, spherical and prismatic joints with one element of every
    kind (and a tabulated spring), for cross-checks of the two formulations."""
    s = mb.System("all elements", gravity=(0, 0, -9.81))
    s.add_body("arm", mass=1.2, com=(0.2, 0, 0), inertia=[0.01, 0.02, 0.025])
    s.add_joint("a", "revolute", parent="ground", child="arm", axis="z")
    s.add_body("ball", mass=0.7, com=(0, 0, -0.1), inertia=[0.004, 0.005, 0.003])
    s.add_joint("b", "spherical", parent="arm", child="ball", position=(0.4, 0, 0))
    s.add_body("slider", mass=0.3, inertia=[1e-3, 1e-3, 1e-3])
    s.add_joint("c", "prismatic", parent="ball", child="slider", axis="z",
                position=(0, 0, -0.2))
    s.add_force("spring", "spring-damper", body_a="ground", point_a=(0.1, 0.3, 0.2),
                body_b="ball", point_b=(0.02, 0, -0.1), stiffness=150.0, damping=2.0,
                free_length=0.3, preload=4.0)
    s.add_force("progressive", "spring-damper", body_a="arm", point_a=(0.1, 0.05, 0),
                body_b="slider", point_b=(0, 0.03, 0),
                force_table=[[-0.2, -40], [0.0, 0.0], [0.1, 30], [0.3, 150]],
                damping_table=[[-1, -3], [0, 0], [1, 5]])
    s.add_force("torsion", "joint-spring-damper", joint="a", stiffness=30.0, damping=0.4,
                rest=0.2, preload=0.5)
    s.add_force("slide", "joint-spring-damper", joint="c", stiffness=200.0, damping=1.5)
    K = np.diag([400.0, 300.0, 500.0, 6.0, 5.0, 4.0])
    K[0, 1] = 50.0                                   # coupled, not symmetrised
    s.add_force("mount", "bushing", body_a="arm", point_a=(0.3, 0, 0), body_b="ball",
                point_b=(-0.1, 0, 0), stiffness=K, damping=[2, 2, 2, 0.02, 0.02, 0.02])
    s.add_force("journal", "bearing", body="slider", point=(0, 0, 0.01), center=(0.4, 0, -0.3),
                axis="z", kxx=2e3, kxy=400.0, kyx=-400.0, kyy=1.5e3, cxx=3.0, cyy=2.0,
                cxy=0.5, cyx=0.2)
    s.add_force("floor", "contact", body="slider", radius=0.05, stiffness=1e5,
                plane_point=(0, 0, -0.5), restitution=0.7, friction=0.4)
    return s


def random_state(model, rng, scale=0.4):
    q = model.default_coordinates() + rng.uniform(-scale, scale, model.nq)
    model.normalize_quaternions(q)
    return q, rng.uniform(-1.0, 1.0, model.nu)


# ----------------------------------------------------------------------------- closed forms
def test_damped_oscillator_closed_form_frequency_and_decay():
    scene = mb.load_model(MODELS / "mass_spring_damper.toml")
    res = scene.simulate(rtol=1e-12, atol=1e-14)
    m, k, c, x0 = 2.0, 800.0, 4.0, 0.1
    wn = np.sqrt(k / m)
    zeta = c / (2 * np.sqrt(k * m))
    wd = wn * np.sqrt(1 - zeta ** 2)
    t = res.t
    exact = x0 * np.exp(-zeta * wn * t) * (np.cos(wd * t) + zeta / np.sqrt(1 - zeta ** 2)
                                           * np.sin(wd * t))
    assert np.abs(res["x"] - exact).max() < 1e-9
    # the energy balance: kinetic + spring + dissipated is constant
    assert res.stats["energy_drift"] < 1e-7
    assert res.energy["dissipated"][-1] == pytest.approx(0.5 * k * x0 ** 2
                                                         - res.energy["total"][-1], rel=1e-6)


def test_switching_the_damper_off_gives_the_undamped_frequency():
    scene = mb.load_model(MODELS / "mass_spring_damper.toml", effects="-damper")
    assert scene.model.forces == ("spring",)
    res = scene.simulate(rtol=1e-12, atol=1e-14)
    assert np.abs(res["x"] - 0.1 * np.cos(20.0 * res.t)).max() < 1e-9


def test_spring_pendulum_conserves_energy_to_the_integrator_tolerance():
    s = mb.System("spring pendulum", gravity=(0, 0, -9.81))
    s.add_body("bob", mass=0.5, inertia=[1e-4, 1e-4, 1e-4])
    s.add_joint("fly", "free", parent="ground", child="bob")
    s.add_force("spring", "spring-damper", body_a="ground", body_b="bob",
                point_b=(0.01, 0, 0), stiffness=60.0, free_length=0.4)
    model = s.compile()
    q0 = model.q_vector({"fly_x": 0.3, "fly_z": -0.35})
    u0 = model.u_vector({"fly_vy": 0.8, "fly_wx": 2.0})
    res = mb.simulate(model, 3.0, q0, u0, integrator="DOP853", rtol=1e-12, atol=1e-14,
                      outputs=("energy",))
    E = res.energy["total"]
    assert np.abs(E - E[0]).max() / np.abs(res.energy["kinetic"]).max() < 1e-9
    assert np.all(res.energy["dissipated"] == 0.0)


# ----------------------------------------------------------------------------- contact
def test_restitution_of_an_impact_at_the_calibration_speed():
    v = 2.5
    s = mb.System("impact", gravity=(0, 0, 0))
    s.add_body("ball", mass=0.2, inertia=[1e-5] * 3)
    s.add_joint("z", "prismatic", parent="ground", child="ball", axis="z")
    s.add_force("floor", "contact", body="ball", radius=0.01, stiffness=5e5, exponent=1.5,
                restitution=0.6, impact_speed=v)
    model = s.compile()
    res = mb.simulate(model, 0.03, {"z": 0.0101}, {"z_dot": -v}, integrator="DOP853",
                      rtol=1e-12, atol=1e-14, max_step=1e-5)
    assert res["z_dot"][-1] == pytest.approx(0.6 * v, rel=1e-7)
    # a slower impact bounces back more (Hunt-Crossley's speed dependence)
    slow = mb.simulate(model, 0.06, {"z": 0.0101}, {"z_dot": -v / 4}, integrator="DOP853",
                       rtol=1e-12, atol=1e-14, max_step=1e-5)
    assert slow["z_dot"][-1] / (v / 4) > 0.6 + 0.1


def test_bouncing_ball_keeps_its_energy_balance_and_bounces_to_e_squared():
    # the dissipated energy is integrated over the samples: sample the 4 ms contact finely
    scene = mb.load_model(MODELS / "bouncing_ball.toml",
                          overrides={"simulation.output_dt": 2e-5})
    res = scene.simulate(t_end=0.6)
    z = res["z"] - 0.02
    first = np.argmax(res["vz"] > 0)                       # after the first impact
    apex = z[first:][np.argmax(res["vz"][first:] < 0)]     # the next apex
    assert apex / 0.5 == pytest.approx(0.8 ** 2, rel=1e-2)   # gravity acts during the contact too
    assert res.stats["energy_drift"] < 1e-5
    assert res.energy["dissipated"][-1] > 0.1


def test_block_sliding_to_rest_decelerates_at_mu_g():
    mu, g, v0 = 0.3, 9.81, 1.5
    s = mb.System("block", gravity=(0, 0, -g))
    s.add_frame("carriage")
    s.add_joint("x", "prismatic", parent="ground", child="carriage", axis="x")
    s.add_body("block", mass=1.0)
    s.add_joint("z", "prismatic", parent="carriage", child="block", axis="z")
    s.add_force("floor", "contact", body="block", radius=0.0, stiffness=1e7, exponent=1.0,
                restitution=0.2, impact_speed=0.1, friction=mu, slip_speed=1e-4)
    model = s.compile()
    z_static = -g / 1e7
    res = mb.simulate(model, 0.8, {"z": z_static}, {"x_dot": v0}, integrator="DOP853",
                      rtol=1e-10, atol=1e-12, max_step=1e-3, t_eval=np.linspace(0, 0.8, 801),
                      outputs=("energy",))
    sliding = (res.t > 0.05) & (res.t < 0.45)
    slope = np.polyfit(res.t[sliding], res["x_dot"][sliding], 1)[0]
    assert slope == pytest.approx(-mu * g, rel=1e-4)
    t_stop = v0 / (mu * g)
    assert abs(res["x_dot"][res.t > t_stop + 0.05]).max() < 1e-3
    # the kinetic energy went into friction
    assert res.energy["dissipated"][-1] == pytest.approx(0.5 * v0 ** 2, rel=1e-3)


# ----------------------------------------------------------------------------- bearings
def jeffcott(k=1e4, m=1.0, c=20.0, unbalance=1e-3, spin=60.0, **bearing):
    s = mb.System("jeffcott", gravity=(0, 0, 0))
    s.add_frame("cy")
    s.add_joint("y", "prismatic", parent="ground", child="cy", axis="y")
    s.add_frame("centre")
    s.add_joint("z", "prismatic", parent="cy", child="centre", axis="z")
    s.add_body("disk", mass=m, com=(0, unbalance, 0), inertia=[0.01, 0.005, 0.005])
    s.add_joint("spin", "revolute", parent="centre", child="disk", axis="x",
                drive=spin * mb.t)
    s.add_force("bearing", "bearing", body="disk", axis="x",
                **({"kxx": k, "kyy": k, "cxx": c, "cyy": c} | bearing))
    return s


def test_rotor_on_isotropic_bearings_whirls_as_the_analytic_unbalance_response():
    k, m, c, e = 1e4, 1.0, 20.0, 1e-3
    wn, zeta = np.sqrt(k / m), c / (2 * np.sqrt(k * m))
    for spin in (60.0, 100.0, 150.0):            # below, at and above the critical speed
        model = jeffcott(k, m, c, e, spin).compile()
        res = mb.simulate(model, 4.0, integrator="DOP853", rtol=1e-10, atol=1e-13,
                          t_eval=np.linspace(3.0, 4.0, 401))
        radius = np.hypot(res["y"], res["z"])
        rho = spin / wn
        expected = e * rho ** 2 / np.sqrt((1 - rho ** 2) ** 2 + (2 * zeta * rho) ** 2)
        # the centre's orbit (the centre of mass is e off it)
        assert radius.mean() == pytest.approx(expected, rel=1e-6), spin
        assert radius.std() < 1e-9 * expected + 1e-12


def test_cross_coupled_bearing_is_kept_unsymmetrised_and_destabilises():
    # kxy = -kyx: a circulatory force; beyond c w_n it feeds forward whirl
    stable = jeffcott(c=20.0, unbalance=0.0, kxy=150.0, kyx=-150.0).compile()
    unstable = jeffcott(c=20.0, unbalance=0.0, kxy=3000.0, kyx=-3000.0).compile()
    for model, grows in ((stable, False), (unstable, True)):
        res = mb.simulate(model, 1.0, {"y": 1e-3}, integrator="DOP853", rtol=1e-10,
                          atol=1e-13)
        r = np.hypot(res["y"], res["z"])
        assert (r[-1] > r[0]) == grows
    # the force itself: F = -K x with the unsymmetric K, at a displacement along y
    model = jeffcott(unbalance=0.0, kxy=700.0, kyx=-300.0).compile()
    f = model.forcing([0.002, 0.0], [0.0, 0.0])
    assert f == pytest.approx([-1e4 * 0.002, 300.0 * 0.002], rel=1e-12)


def test_tabulated_bearing_interpolates_against_spin_and_warns_outside_the_table():
    speeds = [0.0, 50.0, 100.0]
    model = jeffcott(unbalance=0.0, spin=75.0, speed="spin", speeds=speeds,
                     kxx=[1e4, 2e4, 4e4], kyy=[1e4, 2e4, 4e4]).compile()
    f = model.forcing([0.001, 0.0], [0.0, 0.0], t=0.3)
    table = mb.forces.make_table({"x": speeds, "y": [1e4, 2e4, 4e4]}, "t", "kxx")
    assert f[0] == pytest.approx(-table(75.0) * 0.001, rel=1e-12)
    assert 2e4 < table(75.0) < 4e4                     # monotone between the knots
    with pytest.warns(mb.errors.ModelWarning, match="outside"):
        mb.simulate(jeffcott(unbalance=0.0, spin=130.0, speed="spin", speeds=speeds,
                             kxx=[1e4, 2e4, 4e4], kyy=[1e4, 2e4, 4e4]).compile(), 0.01)


# ----------------------------------------------------------------------------- cross-checks
def test_both_formulations_agree_with_every_element_kind():
    model = every_kind_system().compile()
    rng = np.random.default_rng(7)
    for _ in range(10):
        q, u = random_state(model, rng)
        a = model.forward_dynamics(q, u, t=0.1)
        b = model.forward_dynamics(q, u, t=0.1, method="newton-euler")
        assert np.abs(a - b).max() < 1e-9 * max(1.0, np.abs(a).max())
        ra = model.reactions(q, u, 0.1)
        rb = model.reactions(q, u, 0.1, method="jourdain")
        for j in ra:
            for x, y in zip(ra[j], rb[j]):
                assert np.abs(x - y).max() < 1e-8 * max(1.0, np.abs(x).max())


def test_generalized_forces_are_minus_the_gradient_of_the_potential():
    """Finite differences of each conservative element's potential against the forces
    it puts into f (gravity off, at rest, so nothing else enters)."""
    s = every_kind_system()
    for name in ("spring", "progressive", "torsion", "slide", "floor"):
        others = [n for n in s.effect_names() if n not in (name, "gyroscopic")]
        model = s.compile(effects=[f"-{n}" for n in others])
        rng = np.random.default_rng(3)
        for _ in range(3):
            q, _ = random_state(model, rng, 0.3)
            if name == "floor":                      # push the slider into the floor
                q[model.coordinate_index("c")] = -0.35
            u = np.zeros(model.nu)
            f = model.forcing(q, u)
            # dV/du along each speed direction: V(q(eps)) with q' = N(q) du
            grad = np.empty(model.nu)
            for k in range(model.nu):
                du = np.zeros(model.nu)
                du[k] = 1.0
                vals = []
                for h in (1e-6, -1e-6):
                    qh = q + h * model.coordinate_rates(q, du)
                    model.normalize_quaternions(qh)
                    vals.append(model.element_energy(qh, u)[0])
                grad[k] = (vals[0] - vals[1]) / 2e-6
            if name == "floor":
                assert model.element_energy(q, u)[0] > 0
            assert np.abs(f + grad).max() < 1e-5 * max(1.0, np.abs(f).max()), name


@pytest.mark.filterwarnings("ignore:model 'all elements'. the gyroscopic effect is off")
def test_non_conservative_power_matches_the_damping_forces():
    """The power dampers, bushings and bearings report equals u . f of their forces."""
    s = every_kind_system()
    rng = np.random.default_rng(11)
    for name in ("mount", "journal"):
        others = [n for n in s.effect_names() if n not in (name, "gyroscopic")]
        model = s.compile(effects=[f"-{n}" for n in others] + ["-gyroscopic"])
        q, u = random_state(model, rng, 0.3)
        f_u = model.forcing(q, u)
        M = model.mass_matrix(q)
        # with gyroscopic terms off, f holds only the element's generalized forces
        assert model.element_energy(q, u)[1] == pytest.approx(u @ f_u, rel=1e-10)
        assert np.all(np.isfinite(M))


def test_energy_balance_with_every_element_and_friction():
    model = every_kind_system().compile()
    q0 = model.default_coordinates()
    res = mb.simulate(model, 1.0, q0, {"a_dot": 2.0}, integrator="DOP853", rtol=1e-11,
                      atol=1e-13, max_step=2e-3, t_eval=np.linspace(0, 1, 2001),
                      outputs=("energy",))
    assert res.stats["energy_drift"] < 1e-6
    assert res.energy["dissipated"][-1] > 0


# ----------------------------------------------------------------------------- effects
def test_effect_off_equals_element_deleted_bit_for_bit():
    full = every_kind_system()
    rng = np.random.default_rng(5)
    for name in ("spring", "journal", "floor", "mount"):
        off = full.compile(effects=f"-{name}")
        deleted = every_kind_system()
        del deleted._forces[name]
        gone = deleted.compile()
        q, u = random_state(off, rng)
        for method in ("jourdain", "newton-euler"):
            a = off.forward_dynamics(q, u, 0.2, method=method)
            b = gone.forward_dynamics(q, u, 0.2, method=method)
            assert np.array_equal(a, b), (name, method)
    off = full.compile(effects={"gravity": False})
    s0 = every_kind_system()
    s0.gravity = np.zeros(3)
    q, u = random_state(off, rng)
    assert np.array_equal(off.forward_dynamics(q, u), s0.compile().forward_dynamics(q, u))


def test_gyroscopic_off_drops_the_velocity_products_and_warns():
    s = mb.System("rotor", gravity=(0, 0, 0))
    s.add_body("disk", mass=1.0, inertia=[0.1, 0.2, 0.3])
    s.add_joint("ball", "spherical", parent="ground", child="disk")
    with pytest.warns(mb.errors.ModelWarning, match="no longer physical"):
        model = s.compile(effects="-gyroscopic")
    q, u = model.default_coordinates(), np.array([1.0, 2.0, 3.0])
    assert np.abs(model.forward_dynamics(q, u)).max() == 0.0
    full = s.compile()
    w = u
    I = np.array([0.1, 0.2, 0.3])
    assert full.forward_dynamics(q, u) == pytest.approx(-np.cross(w, I * w) / I, rel=1e-12)


def test_effects_parse_and_unknown_names_list_the_known_ones():
    s = oscillator()
    with pytest.raises(ModelError, match="gravity, gyroscopic, spring, damper"):
        s.compile(effects="-sprung")
    m = s.compile(effects={"off": ["damper"], "gravity": False})
    assert m.effects == {"gravity": False, "gyroscopic": True, "spring": True,
                         "damper": False}
    assert m.forces == ("spring",)


# ----------------------------------------------------------------------------- tables
def test_tables_are_monotone_and_integrated_exactly():
    tab = mb.forces.make_table([[0, 0], [1, 1], [2, 1.2], [3, 5]], "t", "force_table")
    xs = np.linspace(-0.5, 3.5, 801)
    ys = np.array([tab(x) for x in xs])
    assert np.all(np.diff(ys) >= -1e-12)             # PCHIP keeps monotone data monotone
    from mbdyn.kernels.forces import table_eval
    out = np.empty(3)
    blk = tab.block()
    # the integral the kernel reports against a fine quadrature of the interpolant
    from scipy.integrate import quad
    for x in (-0.3, 0.7, 2.5, 3.4):
        table_eval(blk, 0, tab.mode, x, out)
        assert out[2] == pytest.approx(quad(tab, 0.0, x, points=[p for p in (1, 2, 3) if p < x], limit=200, epsabs=1e-13)[0], abs=1e-10)
        h = 1e-6
        assert out[1] == pytest.approx((tab(x + h) - tab(x - h)) / (2 * h), rel=1e-6)


# ----------------------------------------------------------------------------- bad input
@pytest.mark.parametrize("kind, kw, message", [
    ("spring-damper", {"body_a": "nobody", "stiffness": 1.0}, "unknown body 'nobody'"),
    ("spring-damper", {"body_a": "block"}, "missing stiffness"),
    ("spring-damper", {"body_a": "block", "stiffness": 1.0, "damping": -2.0},
     "damping must be >= 0"),
    ("spring-damper", {"body_a": "block", "force_table": [[0, 0], [2, 1], [1, 3]]},
     "not monotone"),
    ("spring-damper", {"body_a": "block", "force_table": {"x": [0, 1, 2], "y": [0, 1]}},
     "3 abscissae but 2 values"),
    ("spring-damper", {"body_a": "block", "stiffness": 1.0, "colour": "red"},
     "unknown key"),
    ("joint-spring-damper", {"joint": "nojoint", "stiffness": 1.0}, "unknown joint"),
    ("bushing", {"body_a": "block"}, "missing stiffness"),
    ("bearing", {"body": "block", "kxx": 1.0}, "missing stiffness kyy"),
    ("bearing", {"body": "block", "kxx": [1.0, 2.0], "kyy": 1.0, "speeds": [0.0, 1.0]},
     "need `speed`"),
    ("bearing", {"body": "block", "kxx": [1.0, 2.0, 3.0], "kyy": 1.0, "speed": "x",
                 "speeds": [0.0, 1.0]}, "kxx has 3 values but speeds has 2"),
    ("contact", {"body": "block", "radius": 0.1}, "missing stiffness"),
    ("contact", {"body": "block", "stiffness": 1e5, "restitution": 1.5}, "restitution"),
    ("gravity", {}, "unknown kind"),
])
def test_malformed_force_elements_are_refused_naming_element_and_key(kind, kw, message):
    s = oscillator()
    with pytest.raises(ModelError, match=message) as info:
        s.add_force("bad", kind, **kw)
    assert "force 'bad'" in str(info.value)
    assert "bad" not in s.forces                      # nothing half-added


def test_malformed_force_elements_in_a_file_name_the_key(tmp_path):
    text = (MODELS / "mass_spring_damper.toml").read_text()
    bad = text.replace('damping = "c"', 'damping = "-c"')
    path = tmp_path / "bad.toml"
    path.write_text(bad)
    with pytest.raises(mb.ModelFileError, match=r"forces\[1\].*damping must be >= 0"):
        mb.load_model(path)
    path.write_text(text + '\n[effects]\noff = ["dampr"]\n')
    with pytest.raises(mb.ModelFileError, match="unknown effect 'dampr'.*spring, damper"):
        mb.load_model(path)
    path.write_text(text.replace('stiffness = "k"', 'force_table = [[0, 0], [0.1, 80], '
                                 '[0.05, 100]]'))
    with pytest.raises(mb.ModelFileError, match="not monotone"):
        mb.load_model(path)


# ----------------------------------------------------------------------------- symbolic
def sprung_double_pendulum():
    s = mb.System("sprung double pendulum", gravity=(0, -9.81, 0),
                  parameters={"k": 50.0, "c": 0.3})
    k, c = s.symbols("k c")
    s.add_body("m1", mass=0.5, com=(0, -0.3, 0))
    s.add_joint("th1", "revolute", parent="ground", child="m1", axis="z")
    s.add_body("m2", mass=0.4, com=(0, -0.3, 0), inertia=[0.01, 0.01, 0.02])
    s.add_joint("th2", "revolute", parent="m1", child="m2", axis="z", position=(0, -0.3, 0))
    s.add_force("spring", "spring-damper", body_a="ground", point_a=(0.3, 0.1, 0),
                body_b="m2", point_b=(0.05, -0.3, 0), stiffness=k, damping=c,
                free_length=0.2, preload=1.0)
    s.add_force("torsion", "joint-spring-damper", joint="th2", stiffness=2 * k, damping=c,
                rest=0.3)
    return s


@pytest.mark.parametrize("method", ["jourdain", "newton-euler", "lagrange"])
def test_symbolic_springs_and_dampers_agree_with_the_engine(method):
    from mbdyn.symbolic.compare import compare_numerically
    model = sprung_double_pendulum().compile()
    d = mb.derive(model, method=method, solve=method == "newton-euler")
    what = ("accelerations", "reactions") if method == "newton-euler" else ("mass_matrix",
                                                                             "forcing")
    for name, err in compare_numerically(d, what=what).items():
        assert err < 1e-12, (method, name, err)
    assert "k" in {s.name for s in d.forcing.free_symbols}     # parameters stay symbols


def test_eom_with_an_effect_off_equals_the_element_deleted():
    off = mb.derive(sprung_double_pendulum().compile(effects="-spring"))
    s = sprung_double_pendulum()
    del s._forces["spring"]
    gone = mb.derive(s.compile())
    assert off.forcing == gone.forcing and off.mass_matrix == gone.mass_matrix


def test_symbolic_layer_refuses_what_it_cannot_write_and_names_the_remedy():
    model = every_kind_system().compile()
    with pytest.raises(ModelError, match=r"--effects=-progressive"):
        mb.derive(model)


# ----------------------------------------------------------------------------- models
def test_top_on_the_floor_follows_the_fixed_point_top_then_lands_on_its_rim():
    import warnings
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", mb.ModelWarning)
        floor = mb.load_model(MODELS / "top.toml", case="floor").simulate(t_end=1.0)
        ref = mb.load_model(MODELS / "top.toml", case="a").simulate(
            integrator="DOP853", rtol=1e-10, atol=1e-12, t_end=1.0)
    theta = np.arccos(np.clip(1 - 2 * (floor["qx"] ** 2 + floor["qy"] ** 2), -1, 1))
    assert np.abs(theta - np.interp(floor.t, ref.t, ref["theta"])).max() < 0.02
    assert floor.stats["energy_drift"] < 1e-5
    assert np.abs(floor["z"]).max() < 1e-3           # the tip stays on the floor


def test_quarter_car_steady_response_matches_the_transfer_function():
    scene = mb.load_model(MODELS / "quarter_car.toml")
    p = scene.parameters
    res = scene.simulate(rtol=1e-11, atol=1e-13)
    w = 2 * np.pi * p["f"]
    M = np.diag([p["mb"], p["mw"]])
    C = np.array([[p["cs"], -p["cs"]], [-p["cs"], p["cs"]]])
    K = np.array([[p["ks"], -p["ks"]], [-p["ks"], p["ks"] + p["kt"]]])
    Z = np.linalg.solve(-w ** 2 * M + 1j * w * C + K, [0.0, p["kt"] * p["A"]])
    late = res.t > 8.0
    basis = np.column_stack([np.sin(w * res.t[late]), np.cos(w * res.t[late])])
    for name, z in (("zb", Z[0]), ("zw", Z[1])):
        (a, b), *_ = np.linalg.lstsq(basis, res[name][late], rcond=None)
        # A sin(wt) drives: the response is Im(Z e^{iwt}) = Re(Z) sin + Im(Z) cos
        assert a == pytest.approx(z.real, rel=1e-5, abs=1e-9)
        assert b == pytest.approx(z.imag, rel=1e-5, abs=1e-9)
    # undamped natural frequencies of the closed form, as the model file states them
    w2 = np.sort(np.linalg.eigvals(np.linalg.solve(M, K)).real)
    assert np.sqrt(w2) / (2 * np.pi) == pytest.approx([1.213, 11.29], rel=1e-3)
    assert res.stats["energy_drift"] < 1e-6


def test_symbolic_loads_on_massless_frames_count():
    """Regression: the symbolic Jourdain form skipped massless frames even when loaded."""
    from mbdyn.symbolic.compare import compare_numerically
    s = mb.System("carriage", gravity=(0, 0, -9.81))
    s.add_frame("carriage")
    s.add_joint("x", "prismatic", parent="ground", child="carriage", axis="x")
    s.add_body("bob", mass=1.0, com=(0, 0, -0.5), inertia=[0.01, 0.01, 0.01])
    s.add_joint("th", "revolute", parent="carriage", child="bob", axis="y")
    s.add_force("spring", "spring-damper", body_a="ground", point_a=(-1, 0, 0),
                body_b="carriage", stiffness=40.0, damping=1.0, free_length=1.0)
    s.add_load("push", "carriage", force=(3.0, 0, 0))
    model = s.compile()
    for method in ("jourdain", "newton-euler", "lagrange"):
        d = mb.derive(model, method=method, solve=method == "newton-euler")
        what = ("accelerations",) if method == "newton-euler" else ("forcing",)
        assert max(compare_numerically(d, what=what).values()) < 1e-12, method


# ----------------------------------------------------------------------------- force laws
def test_force_law_as_an_expression_matches_the_same_linear_spring():
    """law = k x + c v is the linear spring-damper: the same accelerations, in both
    formulations, and in closed form."""
    import sympy
    x, v = sympy.symbols("x v")
    lin = oscillator(k=800.0, c=4.0).compile()
    s = mb.System("law", gravity=(0, 0, -9.81), parameters={"k": 800.0, "c": 4.0})
    k, c = s.symbols("k c")
    s.add_body("block", mass=2.0)
    s.add_joint("x", "prismatic", parent="ground", child="block", axis="x")
    s.add_force("spring", "spring-damper", body_a="ground", point_a=(-0.5, 0, 0),
                body_b="block", free_length=0.5, law=k * x + c * v)
    law = s.compile()
    rng = np.random.default_rng(2)
    for _ in range(5):
        q, u = rng.uniform(-0.2, 0.2, 1), rng.uniform(-1, 1, 1)
        for method in ("jourdain", "newton-euler"):
            assert law.forward_dynamics(q, u, method=method) == pytest.approx(
                lin.forward_dynamics(q, u, method=method), rel=1e-13)
    from mbdyn.symbolic.compare import compare_numerically
    assert max(compare_numerically(mb.derive(law)).values()) < 1e-12
    # a law is non-conservative in the energy balance: its whole power is "dissipated"
    res = mb.simulate(law, 1.0, {"x": 0.1}, integrator="DOP853", rtol=1e-11, atol=1e-13,
                      t_eval=np.linspace(0, 1, 2001), outputs=("energy",))
    assert res.stats["energy_drift"] < 1e-7


def test_progressive_law_from_a_model_file_and_a_python_function(tmp_path):
    text = (MODELS / "mass_spring_damper.toml").read_text()
    text = text.replace('stiffness = "k"', 'law = "k*x + 4*k*x**3/L0**2"')
    path = tmp_path / "law.toml"
    path.write_text(text)
    model = mb.load_model(path).model
    q = np.array([0.2])
    f = model.forcing(q, [0.0])
    assert f[0] == pytest.approx(-(800 * 0.2 + 4 * 800 * 0.2 ** 3 / 0.25), rel=1e-12)
    s = mb.System("fn", gravity=(0, 0, 0))
    s.add_body("block", mass=2.0)
    s.add_joint("x", "prismatic", parent="ground", child="block", axis="x")
    s.add_force("stop", "joint-spring-damper", joint="x",
                law=lambda x, v: 1e4 * max(x - 0.1, 0.0) ** 2 + 3.0 * v)
    m = s.compile()
    assert m.forcing([0.15], [0.5])[0] == pytest.approx(-(1e4 * 0.05 ** 2 + 1.5), rel=1e-12)
    with pytest.raises(ModelError, match="law gives the whole force; remove stiffness"):
        s.add_force("bad", "joint-spring-damper", joint="x", stiffness=1.0,
                    law=lambda x, v: x)
    s.add_force("nan", "joint-spring-damper", joint="x", law=lambda x, v: float("nan"))
    with pytest.raises(mb.NonFiniteError, match="law of force 'nan'"):
        s.compile(check_inertia=False).forcing([0.0], [0.0])
