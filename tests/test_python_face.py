"""The Python interface agrees with model files (issue 14's first points)."""
import numpy as np
import pytest

from pathlib import Path

import mbdyn as mb
from mbdyn.io.loader import DEFAULT_SIMULATION

ROOT = Path(__file__).resolve().parent.parent


def pendulum():
    s = mb.System("pendulum", gravity=(0, 0, -9.81))
    s.add_body("bob", mass=1.0, com=(0, 0, -1.0))
    s.add_joint("theta", "revolute", parent="ground", child="bob", axis="y")
    return s.compile()


def test_one_set_of_defaults_for_python_and_files():
    assert mb.simulate.__kwdefaults__["integrator"] == DEFAULT_SIMULATION["integrator"] == \
        "DOP853"
    assert mb.simulate.__kwdefaults__["rtol"] == DEFAULT_SIMULATION["rtol"] == 1e-9
    assert mb.simulate.__kwdefaults__["atol"] == DEFAULT_SIMULATION["atol"] == 1e-12
    # the pendulum's small-amplitude period through Python defaults is good to ~1e-9
    model = pendulum()
    res = mb.simulate(model, 2.0, {"theta": 1e-3}, t_eval=np.linspace(0, 2, 4001))
    assert res.stats["integrator"] == "DOP853"
    w = np.sqrt(9.81)
    assert np.abs(res["theta"] - 1e-3 * np.cos(w * res.t)).max() < 1e-9


def test_u0_accepts_a_coordinate_name_for_its_rate_as_files_do():
    model = pendulum()
    assert model.u_vector({"theta": 1.5}) == pytest.approx([1.5])
    res = mb.simulate(model, 0.1, u0={"theta": 1.5})
    assert res["theta_dot"][0] == 1.5
    with pytest.raises(mb.ModelError, match="given twice"):
        model.u_vector({"theta": 1.0, "theta_dot": 2.0})
    with pytest.raises(mb.ModelError, match="unknown speed 'phi'"):
        model.u_vector({"phi": 1.0})


def test_a_particle_on_a_spherical_joint_is_refused_with_the_remedy():
    s = mb.System("conical pendulum")
    s.add_body("bob", mass=1.0, com=(0, 0, -1.0))
    s.add_joint("ball", "spherical", parent="ground", child="bob")
    with pytest.raises(mb.ModelError, match=r"two revolute joints.*small isotropic inertia"):
        s.compile()


def swinging():
    model = pendulum()
    return model, {"theta": 0.5}


def test_events_accept_the_files_text_and_sympy_and_carry_the_state():
    import sympy
    model, q0 = swinging()
    w = np.sqrt(9.81)
    # small-angle crossings of theta = 0 at (k + 1/2) pi / w; 0.5 rad is not small, so the
    # reference is a text event against a callable one, both located to 1e-9
    text = mb.simulate(model, 2.0, q0, events=[mb.Event("cross", "theta")])
    func = mb.simulate(model, 2.0, q0, events=[mb.Event("cross", lambda t, q, u: q[0])])
    assert [round(t, 9) for _, t in text.events] == [round(t, 9) for _, t in func.events]
    assert len(text.events) == 2 and abs(text.events[0].t - 0.5 * np.pi / w) < 0.02
    down = mb.simulate(model, 2.0, q0, events=[mb.Event("down", "theta < 0")])
    assert [e.t for e in down.events] == [text.events[0].t]     # falling only
    th = sympy.Symbol("theta")
    sym = mb.simulate(model, 2.0, q0, events=[mb.Event("down", th < 0)])
    assert [e.t for e in sym.events] == pytest.approx([e.t for e in down.events], abs=1e-12)
    rec = down.events[0]
    name, t = rec                                   # unpacks as (name, t), as before
    assert name == "down" and rec.q[0] == pytest.approx(0.0, abs=1e-9)
    assert rec.state["theta_dot"] == pytest.approx(rec.u[0]) and rec.u[0] < 0
    # terminal, with the rates named as in files
    stop = mb.simulate(model, 2.0, q0, events=[mb.Event("turn", "theta_dot > 0", True)])
    assert stop.t[-1] == pytest.approx(stop.events[0].t)


def test_a_bool_condition_is_refused_with_the_remedy():
    model, q0 = swinging()
    with pytest.raises(mb.ModelError, match=r"returned .*a bool.*'theta < 0'"):
        mb.simulate(model, 2.0, q0, events=[mb.Event("down", lambda t, q, u: q[0] < 0)])
    with pytest.raises(mb.ModelError, match="event 'bad'.*not allowed|event 'bad'"):
        mb.simulate(model, 1.0, q0, events=[mb.Event("bad", "__import__('os')")])
    with pytest.raises(mb.ModelError, match="uses phi"):
        import sympy
        mb.simulate(model, 1.0, q0, events=[mb.Event("bad", sympy.Symbol("phi"))])


def test_inverse_dynamics_round_trips_forward_dynamics_and_gives_the_reactions():
    s = mb.System("arm", gravity=(0, 0, -9.81))
    s.add_body("upper", mass=2.0, com=(0.2, 0, 0), inertia=[0.01, 0.03, 0.03])
    s.add_joint("shoulder", "revolute", parent="ground", child="upper", axis="y")
    s.add_body("fore", mass=1.0, com=(0.15, 0, 0), inertia=[0.005, 0.01, 0.01])
    s.add_joint("elbow", "revolute", parent="upper", child="fore", axis="y",
                position=(0.4, 0, 0))
    model = s.compile()
    rng = np.random.default_rng(4)
    q, u = rng.uniform(-1, 1, 2), rng.uniform(-1, 1, 2)
    # free motion: zero efforts, and the reactions of the forward solution
    ud = model.forward_dynamics(q, u)
    efforts, reac = model.inverse_dynamics(q, u, ud)
    assert np.abs(list(efforts.values())).max() < 1e-12
    ref = model.reactions(q, u)
    for j in ref:
        assert np.abs(reac[j][0] - ref[j][0]).max() < 1e-10
    # a prescribed acceleration: the efforts, applied as loads, reproduce it
    want = np.array([0.7, -1.3])
    efforts, reac = model.inverse_dynamics(q, u, want)
    s.add_load("tau_s", "upper", moment=(0, efforts["shoulder_dot"], 0))
    s.add_load("tau_e", "fore", moment=(0, efforts["elbow_dot"], 0))
    s.add_load("tau_e_back", "upper", moment=(0, -efforts["elbow_dot"], 0))
    assert s.compile().forward_dynamics(q, u) == pytest.approx(want, rel=1e-10)
    # the elbow's reaction moment about its axis is the elbow effort
    axis = model.kinematics(q).R[1] @ np.array([0, 1.0, 0])
    assert reac["elbow"][1] @ axis == pytest.approx(efforts["elbow_dot"], rel=1e-10)


def test_inverse_dynamics_along_a_prescribed_trajectory():
    """A pendulum made to follow theta = A sin(w t): the torque is m l^2 theta'' +
    m g l sin(theta) (the closed form of a point mass at l)."""
    model = pendulum()
    t = np.linspace(0, 2, 2001)
    A, w = 0.3, 2.0
    th = A * np.sin(w * t)
    thd = A * w * np.cos(w * t)
    efforts, reac = model.inverse_dynamics_along(t, th[:, None], thd[:, None])
    exact = -A * w * w * np.sin(w * t) + 9.81 * np.sin(th)    # m = l = 1
    # the effort about the joint axis y: sign of the axis' sense
    assert np.abs(efforts[2:-2, 0] - exact[2:-2]).max() < 1e-5
    assert reac["theta"].shape == (2001, 6)


def test_rotation_helpers_for_quaternion_initial_states():
    from mbdyn import rotations as rot
    rng = np.random.default_rng(8)
    for _ in range(5):
        angles = rng.uniform(-2, 2, 3)
        q = rot.from_euler(angles, "ZXZ")
        # against the product of the elementary rotations about moving axes
        def Rk(k, a):
            c, s = np.cos(a), np.sin(a)
            i, j = (k + 1) % 3, (k + 2) % 3
            R = np.eye(3)
            R[i, i] = R[j, j] = c
            R[i, j], R[j, i] = -s, s
            return R
        R = Rk(2, angles[0]) @ Rk(0, angles[1]) @ Rk(2, angles[2])
        assert rot.to_matrix(q) == pytest.approx(R, abs=1e-14)
        assert rot.from_matrix(R) == pytest.approx(q * np.sign(q[0]), abs=1e-14)
        w = rng.normal(size=3)
        assert rot.parent_rates(q, rot.body_rates(q, w)) == pytest.approx(w, abs=1e-14)
    assert rot.from_axis_angle("z", np.pi / 2) == pytest.approx(
        [np.cos(np.pi / 4), 0, 0, np.sin(np.pi / 4)])
    # the spherical pendulum tilted by 0.3 about x, spun at 2 rad/s about the world z
    s = mb.System("sphere")
    s.add_body("bob", mass=1.0, com=(0, 0, -1), inertia=[0.01] * 3)
    s.add_joint("ball", "spherical", parent="ground", child="bob")
    model = s.compile()
    q = rot.from_axis_angle("x", 0.3)
    q0 = model.q_vector({"ball": q})
    u0 = model.u_vector({"ball": rot.body_rates(q, [0, 0, 2.0])})
    kin = model.kinematics(q0, u0)
    assert kin.w[0] == pytest.approx([0, 0, 2.0], abs=1e-14)


def test_an_exception_in_a_load_function_names_the_load():
    s = mb.System("pendulum", gravity=(0, 0, -9.81))
    s.add_body("bob", mass=1.0, com=(0, 0, -1.0))
    s.add_joint("theta", "revolute", parent="ground", child="bob", axis="y")
    s.add_load("push", "bob", force=lambda t, q, u: (1.0 / 0.0, 0, 0))
    with pytest.raises(mb.ModelError, match=r"load 'push': its function raised "
                                            r"ZeroDivisionError"):
        s.compile().forward_dynamics([0.1], [0.0])


def test_python_matches_files_inertia_about_reaction_frame_and_csv(tmp_path):
    import warnings
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", mb.ModelWarning)
        scene = mb.load_model(ROOT / "models/top.toml", case="a")
        s = mb.System("top", gravity=(0, 0, -9.81))
        s.add_body("top", mass=0.582, com=(0, 0, 0.0558),
                   inertia=[0.00209393, 0.00209393, 0.0022058], inertia_about="origin")
    assert s.bodies["top"].inertia == pytest.approx(scene.model.body("top").inertia,
                                                    rel=1e-12)
    model = pendulum()
    res = mb.simulate(model, 0.5, {"theta": 0.3}, outputs=("reactions", "energy"),
                      reactions_frame="child")
    F_child = res.reactions["theta"][:, :3]
    kin = model.kinematics(res.q[-1])
    world = model.reactions(res.q[-1], res.u[-1], res.t[-1])["theta"][0]
    assert kin.R[0] @ F_child[-1] == pytest.approx(world, rel=1e-9)
    path = tmp_path / "r.csv"
    res.to_csv(path)
    header = path.read_text().splitlines()[0].split(",")
    assert header[:3] == ["t", "theta", "theta_dot"] and "energy_balance" in header
    data = np.loadtxt(path, delimiter=",", skiprows=1)
    assert np.array_equal(data[:, 1], res["theta"])


def test_momentum_output_is_conserved_by_a_torque_free_body():
    scene = mb.load_model(ROOT / "models/free_body.toml")
    res = mb.simulate(scene.model, 2.0, scene.q0, scene.u0, outputs=("momentum",),
                      rtol=1e-12, atol=1e-14)
    L = res.momentum["angular"]
    p = res.momentum["linear"]
    g = scene.model.gravity
    m = sum(scene.model.body(b).mass for b in scene.model.bodies)
    # gravity changes p by m g t; the angular momentum about the centre of mass,
    # L - r_G x p, is conserved (uniform gravity exerts no moment about it)
    assert p[-1] - p[0] == pytest.approx(m * g * (res.t[-1] - res.t[0]), abs=1e-8)
    body = scene.model.frame_index(scene.model.bodies[0])
    rG = np.array([scene.model.kinematics(q).r_com[body] for q in res.q])
    LG = L - np.cross(rG, p)
    assert np.abs(LG - LG[0]).max() < 1e-8 * np.abs(LG).max()


def test_info_shows_a_joints_orientation(tmp_path):
    import subprocess
    import sys
    text = (ROOT / "models/mass_spring_damper.toml").read_text().replace(
        'axis = "x"\n', 'axis = "x"\norientation = { axis = "z", angle = "pi/2" }\n', 1)
    path = tmp_path / "turned.toml"
    path.write_text(text)
    r = subprocess.run([sys.executable, "-m", "mbdyn", "info", str(path)],
                       capture_output=True, text=True, cwd=ROOT)
    assert "turned by quaternion [0.707107, 0, 0, 0.707107]" in r.stdout, r.stdout


def test_derive_substitutes_by_name_or_plain_symbol():
    import sympy
    s = mb.System("double pendulum", gravity=(0, -9.81, 0))
    s.add_body("m1", mass=1.0, com=(0, -1, 0))
    s.add_joint("theta1", "revolute", parent="ground", child="m1", axis="z")
    s.add_body("m2", mass=1.0, com=(0, -1, 0))
    s.add_joint("theta2", "revolute", parent="m1", child="m2", axis="z", position=(0, -1, 0))
    d = mb.derive(s.compile())
    flat = d.subs({sympy.Symbol("theta2"): 0, "theta2_dot": 0})
    assert flat.mass_matrix == sympy.Matrix([[5, 2], [2, 1]])     # cos(0) = 1
    assert "theta2" not in {x.name for x in flat.forcing.free_symbols}
    with pytest.raises(mb.ModelError, match="'theta3' is not a name"):
        d.subs({"theta3": 0})


@pytest.mark.parametrize("kwargs, message", [
    ({"t_eval": [0.0, 0.5, 3.0]}, "outside t0..t_end"),
    ({"t_eval": [0.2, 0.1]}, "must increase"),
    ({"t_eval": [0.1, float("nan")]}, "NaN"),
    ({"rtol": 0.0}, "rtol must be a positive"),
    ({"atol": -1.0}, "atol must be a positive"),
    ({"max_step": 0.0}, "max_step must be positive"),
])
def test_bad_simulate_arguments_are_refused_not_ignored(kwargs, message):
    with pytest.raises(mb.ModelError, match=message):
        mb.simulate(pendulum(), 1.0, {"theta": 0.1}, **kwargs)
