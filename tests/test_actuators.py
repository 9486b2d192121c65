"""Joint actuators, controllers and stops (issue 28): each against a closed form or an
independent route (a joint spring-damper, a law evaluated in Python, the energy balance)."""
import math

import numpy as np
import pytest
import sympy

import mbdyn as mb
from mbdyn.errors import ModelError

J_ARM = 0.1 + 2.0 * 0.5 ** 2          # the arm's inertia about its axle


def arm(gravity=(0, 0, -9.81)):
    s = mb.System("arm", gravity=gravity)
    s.add_body("arm", mass=2.0, com=(0.5, 0, 0), inertia=(0.01, 0.1, 0.1))
    s.add_joint("th", "revolute", parent="ground", child="arm", axis="y")
    return s


def wheel(J=0.5):
    s = mb.System("wheel", gravity=(0, 0, -9.81))
    s.add_body("w", mass=1.0, inertia=(1.0, 1.0, J))
    s.add_joint("th", "revolute", parent="ground", child="w", axis="z")
    return s


def second_order_step(t, s, wn, zeta):
    """Step response of x'' + 2 zeta wn x' + wn^2 x = wn^2 s from rest at 0."""
    wd = wn * math.sqrt(1 - zeta ** 2)
    return s * (1 - np.exp(-zeta * wn * t) * (np.cos(wd * t)
                                             + zeta / math.sqrt(1 - zeta ** 2) * np.sin(wd * t)))


def test_pd_with_gravity_compensation_is_the_closed_form_second_order_response():
    kp, kd = 200.0, 6.0
    s = arm()
    s.add_actuator("ctl", "th", "pd", kp=kp, kd=kd, setpoint=0.3, gravity_compensation=True)
    t = np.linspace(0, 2, 201)
    res = mb.simulate(s.compile(), 2.0, t_eval=t, rtol=1e-11, atol=1e-13)
    wn, zeta = math.sqrt(kp / J_ARM), kd / (2 * math.sqrt(kp * J_ARM))
    assert 0.05 < zeta < 0.5                 # underdamped: the overshoot is checked too
    assert np.max(np.abs(res["th"] - second_order_step(t, 0.3, wn, zeta))) < 1e-8


def test_pd_without_compensation_sags_by_the_gravity_torque_over_kp():
    kp, kd = 400.0, 40.0
    s = arm()
    s.add_actuator("ctl", "th", "pd", kp=kp, kd=kd, setpoint=0.0)
    res = mb.simulate(s.compile(), 6.0)
    # about y, the arm along x: gravity's moment is +m g 0.5 cos(th) (x cross -z = +y),
    # which the PD balances at kp th
    th = res["th"][-1]
    assert th > 0 and abs(kp * th - 2.0 * 9.81 * 0.5 * math.cos(th)) < 1e-6 * kp


def test_pd_tracks_an_expression_setpoint_with_its_exact_rate():
    # error dynamics J e'' + kd e' + kp e = J s'' (s = a sin(w t)): compare with a
    # joint-spring-damper route that knows nothing of setpoints: the same ODE
    kp, kd, a, w = 300.0, 30.0, 0.2, 3.0
    t_ = sympy.Symbol("t")
    s1 = arm(gravity=(0, 0, 0))
    s1.add_actuator("ctl", "th", "pd", kp=kp, kd=kd, setpoint=a * sympy.sin(w * t_))
    s2 = arm(gravity=(0, 0, 0))
    s2.add_actuator("ctl", "th", "torque",
                    value=kp * (a * sympy.sin(w * t_) - sympy.Symbol("th"))
                    + kd * (a * w * sympy.cos(w * t_) - sympy.Symbol("th_dot")))
    t = np.linspace(0, 3, 61)
    r1 = mb.simulate(s1.compile(), 3.0, t_eval=t, rtol=1e-11, atol=1e-13)
    r2 = mb.simulate(s2.compile(), 3.0, t_eval=t, rtol=1e-11, atol=1e-13)
    assert np.max(np.abs(r1["th"] - r2["th"])) < 1e-9
    assert np.max(np.abs(r1["th"][-20:] - a * np.sin(w * t[-20:]))) < 0.02


def test_a_torque_of_the_state_equals_a_joint_spring_damper():
    k, c = 50.0, 0.8
    s1 = wheel()
    th, thd = sympy.symbols("th th_dot")
    s1.add_actuator("spring", "th", "torque", value=-k * th - c * thd)
    s2 = wheel()
    s2.add_force("spring", "joint-spring-damper", joint="th", stiffness=k, damping=c)
    t = np.linspace(0, 2, 41)
    r1 = mb.simulate(s1.compile(), 2.0, q0={"th": 0.4}, t_eval=t)
    r2 = mb.simulate(s2.compile(), 2.0, q0={"th": 0.4}, t_eval=t)
    assert np.max(np.abs(r1.q - r2.q)) < 1e-12
    assert not s1.compile()._laws                   # compiled: no Python per evaluation


def test_torque_table_of_time_and_its_saturation():
    J = 0.5
    s = wheel(J)
    s.add_actuator("m", "th", "torque", value=[[0, 0], [1, 4], [2, 4]], limit=3.0,
                   interpolation="linear")
    t = np.linspace(0, 2, 21)
    res = mb.simulate(s.compile(), 2.0, t_eval=t, rtol=1e-11, atol=1e-13)
    # tau = min(4 t, 3) up to t = 1, then 3: speed = integral / J
    t1 = 0.75
    expect = np.where(t < t1, 2 * t ** 2, 2 * t1 ** 2 + 3 * (t - t1)) / J
    assert np.max(np.abs(res["th_dot"] - expect)) < 1e-7


def test_pid_removes_the_steady_state_error_of_a_constant_disturbance():
    kp, kd, ki = 200.0, 30.0, 400.0
    errors = {}
    for kind in ("pd", "pid"):
        s = arm(gravity=(0, 0, 0))
        s.add_load("disturbance", "arm", moment=(0, 5.0, 0))
        extra = {"ki": ki} if kind == "pid" else {}
        s.add_actuator("ctl", "th", kind, kp=kp, kd=kd, setpoint=0.2, **extra)
        res = mb.simulate(s.compile(), 8.0)
        errors[kind] = 0.2 - res["th"][-1]
        if kind == "pid":
            assert res.stats["sampling_instants"] == 8000        # 1 kHz by default
    assert abs(errors["pd"] + 5.0 / kp) < 1e-8      # PD: e = -d / kp
    assert abs(errors["pid"]) < 1e-6


def test_pid_anti_windup_limits_the_overshoot_after_saturation():
    peaks, integral = {}, {}
    for aw in (True, False):
        s = wheel(0.5)
        s.add_actuator("ctl", "th", "pid", kp=20.0, kd=4.0, ki=40.0, setpoint=2.0,
                       limit=5.0, anti_windup=aw)
        m = s.compile()
        res = mb.simulate(m, 6.0, t_eval=np.linspace(0, 6, 601))
        peaks[aw] = res["th"].max()
        integral[aw] = m._force_data[m._samplers[0].slot]
    assert peaks[True] < peaks[False] - 0.1
    assert abs(integral[True]) <= 5.0


def test_sampled_controller_holds_its_effort_between_samples_and_stays_compiled():
    J, rate = 0.5, 20.0
    calls = []

    def control(t, q, u):
        calls.append(t)
        return [math.cos(3 * t)]
    s = wheel(J)
    s.add_controller("ctl", control, rate=rate, joints=["th"])
    t = np.arange(0, 41) / rate
    res = mb.simulate(s.compile(), 2.0, t_eval=t, rtol=1e-12, atol=1e-14)
    # zero-order hold: the speed at the samples is the sum of the held torques / J
    held = np.cos(3 * t[:-1])
    expect = np.concatenate([[0.0], np.cumsum(held) / rate / J])
    assert np.max(np.abs(res["th_dot"] - expect)) < 1e-10
    assert np.allclose(calls, t[:-1])
    assert res.stats["compiled"] and res.stats["sampling_instants"] == 40


def test_controller_errors_name_the_controller():
    s = wheel()
    s.add_controller("ctl", lambda t, q, u: [1.0, 2.0], rate=10, joints=["th"])
    with pytest.raises(ModelError, match="controller 'ctl'.*returned 2 values.*return 1"):
        mb.simulate(s.compile(), 1.0)
    with pytest.raises(ModelError, match="rate must be a positive"):
        wheel().add_controller("c", lambda t, q, u: [0.0], rate=0, joints=["th"])


def test_motor_spins_a_flywheel_up_along_its_exponential():
    for case, command in ((None, 1.0), ("half_voltage", 0.5)):
        scene = mb.load_model("models/motor_flywheel.toml", case=case)
        res = scene.simulate(rtol=1e-11, atol=1e-13)
        J, gear, stall, w0 = 0.05 + 100 * 1e-4, 10.0, 0.5, 400.0
        tau = J * w0 / (gear ** 2 * stall)
        expect = command * w0 / gear * (1 - np.exp(-res.t / tau))
        assert np.max(np.abs(res["spin_dot"] - expect)) < 1e-8
        # energy: what the motor put in is the kinetic energy gained (no losses modelled)
        e = res.energy
        assert abs(e["work"][-1] - (e["kinetic"][-1] - e["kinetic"][0])) < 1e-6 * e["work"][-1]
        assert np.max(np.abs(e["balance"] - e["balance"][0])) < 1e-6 * e["work"][-1]


def test_joint_stop_bounds_the_coordinate_and_balances_energy():
    s = arm()
    s.add_force("stop", "joint-stop", joint="th", lower=-0.5, upper=0.5, stiffness=1e5,
                damping=50.0)
    res = mb.simulate(s.compile(), 2.0, t_eval=np.linspace(0, 2, 20001),
                      outputs=("energy",), max_step=1e-3)
    assert res["th"].max() < 0.5 + 0.02 and res["th"].max() > 0.5
    e = res.energy
    assert e["dissipated"][-1] > 1.0                # the stop's damper took energy out
    # the damper's force jumps at contact: the balance's quadrature converges at first
    # order in the sampling (0.17 J at 4,001 samples, 0.025 J at 40,001)
    assert np.max(np.abs(e["balance"])) < 0.01 * e["dissipated"][-1]


def test_compiled_law_equals_the_same_law_in_python():
    x, v = sympy.symbols("x v")
    law = 30.0 * sympy.tanh(v / 0.01) + 200 * x + 5 * sympy.Max(x - 0.1, 0) ** 2
    runs = []
    for given in (law, sympy.lambdify((x, v), law, "math")):
        s = wheel()
        s.add_force("f", "joint-spring-damper", joint="th", law=given)
        m = s.compile()
        assert bool(m._laws) == (not isinstance(given, sympy.Basic))   # Python only for a function
        runs.append(mb.simulate(m, 1.0, q0={"th": 0.3}, t_eval=np.linspace(0, 1, 11)).q)
    assert np.max(np.abs(runs[0] - runs[1])) < 1e-12


def test_actuator_is_a_named_effect():
    s = wheel()
    s.add_actuator("m", "th", "torque", value=1.0)
    assert "m" in s.effect_names()
    off = s.compile(effects="-m")
    res = mb.simulate(off, 1.0)
    assert abs(res["th_dot"][-1]) < 1e-14 and "m" not in off.forces


@pytest.mark.parametrize("kwargs, message", [
    (dict(joint="nope", kind="torque", value=1.0), "unknown joint 'nope'"),
    (dict(joint="th", kind="spring", value=1.0), "unknown kind 'spring'"),
    (dict(joint="th", kind="pd"), "needs kp"),
    (dict(joint="th", kind="torque"), "needs value"),
    (dict(joint="th", kind="torque", value="2*t"), "is text"),
    (dict(joint="th", kind="torque", value=1.0, gain=2), "unknown key.*gain"),
    (dict(joint="th", kind="motor", stall_torque=1.0), "needs stall_torque and no_load_speed"),
    (dict(joint="th", kind="pd", kp=-1.0), "kp must be >= 0"),
    (dict(joint="th", kind="torque", value=1.0, limit=0.0), "limit must be positive"),
])
def test_actuator_errors_name_the_actuator_and_key(kwargs, message):
    s = wheel()
    joint, kind = kwargs.pop("joint"), kwargs.pop("kind")
    with pytest.raises(ModelError, match="actuator 'a'.*" + message):
        s.add_actuator("a", joint, kind, **kwargs)


def test_actuator_refuses_what_it_cannot_act_on():
    s = wheel()
    s.add_body("b", mass=1.0, inertia=(1, 1, 1))
    s.add_joint("ball", "spherical", parent="w", child="b")
    with pytest.raises(ModelError, match="joint 'ball' is spherical"):
        s.add_actuator("a", "ball", "torque", value=1.0)
    s.add_body("c", mass=1.0, inertia=(1, 1, 1))
    s.add_joint("turn", "revolute", parent="b", child="c", axis="z")
    with pytest.raises(ModelError, match="rotor_inertia.*hangs from 'b'"):
        s.add_actuator("m", "turn", "motor", stall_torque=1, no_load_speed=10,
                       rotor_inertia=1e-3)
    s2 = mb.System("d")
    s2.add_body("w", mass=1.0, inertia=(1, 1, 1))
    s2.add_joint("th", "revolute", parent="ground", child="w", axis="z", drive=2 * mb.t)
    with pytest.raises(ModelError, match="joint 'th' is driven"):
        s2.add_actuator("a", "th", "torque", value=1.0)
    s3 = wheel()
    s3.add_actuator("a", "th", "torque", value=sympy.Symbol("speed") * 2)
    with pytest.raises(ModelError, match="uses speed, which are neither"):
        s3.compile()


def test_symbolic_equations_agree_with_the_kernels():
    t_ = sympy.Symbol("t")
    s = arm()
    s.add_actuator("ctl", "th", "pd", kp=50.0, kd=3.0, setpoint=0.2 * sympy.sin(2 * t_),
                   limit=20.0)
    s.add_force("stop", "joint-stop", joint="th", lower=-0.3, upper=0.25, stiffness=1e4,
                damping=20.0)
    s.add_body("w", mass=0.5, inertia=(0.01, 0.01, 0.02))
    s.add_joint("spin", "revolute", parent="arm", child="w", axis="z", position=(1, 0, 0))
    s.add_actuator("push", "spin", "torque", value=0.3 * sympy.cos(t_)
                   - 0.1 * sympy.Symbol("spin_dot"))
    m = s.compile()
    rng = np.random.default_rng(3)
    rhs = mb.symbolic.compiled_rhs(m)
    for _ in range(4):
        q, u, t = rng.uniform(-0.5, 0.5, 2), rng.uniform(-1, 1, 2), rng.uniform(0, 2)
        assert np.allclose(rhs.accelerations(q, u, t), m.forward_dynamics(q, u, t),
                           rtol=1e-10, atol=1e-10)
    s.add_actuator("i", "spin", "pid", kp=1.0, ki=1.0)
    with pytest.raises(ModelError, match="actuator 'i'.*not PID integrals"):
        mb.symbolic.compiled_rhs(s.compile()).accelerations(q, u, t)


def test_generated_equations_are_not_reused_across_force_elements():
    # the generated code's cache key once left force elements out: a model differing only
    # in a spring's stiffness (or an actuator's gain) reused the first one's equations
    out = []
    for k in (10.0, 20.0):
        s = wheel()
        s.add_force("spring", "joint-spring-damper", joint="th", stiffness=k)
        m = s.compile()
        out.append(mb.symbolic.compiled_rhs(m).accelerations([0.1], [0.0]))
        assert np.allclose(out[-1], m.forward_dynamics([0.1], [0.0]), rtol=1e-12)
    assert out[0][0] != out[1][0]


def test_pd_arm_holds_its_pose_and_sags_by_gravity_over_kp_without_compensation():
    pose = np.array([0.5, -0.6, 1.2])
    hold = mb.load_model("models/pd_arm.toml", case="hold").simulate()
    assert np.max(np.abs(hold.q[-1] - pose)) < 1e-6
    assert hold.stats["compiled"]
    b = hold.energy["balance"]
    assert np.max(np.abs(b - b[0])) < 1e-2 * np.max(np.abs(hold.energy["work"]))
    scene = mb.load_model("models/pd_arm.toml", case="no_compensation")
    q = scene.simulate(t_end=6.0).q[-1]
    # at rest, kp (s - q) is the effort that holds the arm against gravity: the inverse
    # dynamics of the same arm without its actuators, at rest at q
    bare = scene.system.compile(effects="-drive_pan,-drive_shoulder,-drive_elbow")
    efforts, _ = bare.inverse_dynamics(q, np.zeros(3), np.zeros(3))
    assert np.allclose(400.0 * (pose - q), [efforts[s] for s in bare.speeds], atol=1e-6)
    assert abs(q[1] - pose[1]) > 0.01                 # it did sag


def test_pd_arm_tracks_a_trajectory_of_time():
    res = mb.load_model("models/pd_arm.toml", case="track").simulate()
    target = np.array([0.5, -0.6, 1.2]) + 0.3 * np.sin(2 * res.t)[:, None]
    assert np.max(np.abs(res.q - target)) < 0.01
    assert res.stats["compiled"]


def test_computed_torque_feedforward_tracks_with_a_tiny_error():
    # with the computed torque fed forward, the tracking error of a 2-link arm comes from
    # the zero-order hold alone: far below the same PD's error without it
    t_ = sympy.Symbol("t")
    errors = {}
    for ff in (False, True):
        s = arm()
        s.add_body("fore", mass=1.0, com=(0.4, 0, 0), inertia=(0.005, 0.05, 0.05))
        s.add_joint("el", "revolute", parent="arm", child="fore", axis="y",
                    position=(1.0, 0, 0))
        for joint, phase in (("th", 0.0), ("el", 1.0)):
            s.add_actuator(f"pd_{joint}", joint, "pd", kp=100.0, kd=20.0,
                           setpoint=0.5 * sympy.sin(2 * t_ + phase), feedforward=ff,
                           gravity_compensation=not ff, rate=2000.0)
        m = s.compile()
        assert (m._plant is not None) == ff
        t = np.linspace(0, 2, 201)
        q0 = {"th": 0.0, "el": 0.5 * math.sin(1.0)}
        u0 = {"th": 1.0, "el": math.cos(1.0)}
        res = mb.simulate(m, 2.0, q0=q0, u0=u0, t_eval=t)
        target = np.stack([0.5 * np.sin(2 * t), 0.5 * np.sin(2 * t + 1.0)], axis=1)
        errors[ff] = np.max(np.abs(res.q - target))
    assert errors[True] < 2e-3 and errors[True] < errors[False] / 10
    with pytest.raises(ModelError, match="feedforward or gravity_compensation, not both"):
        wheel().add_actuator("x", "th", "pd", kp=1.0, feedforward=True,
                             gravity_compensation=True)


def test_gravity_compensated_pd_equals_the_same_law_as_python_loads():
    # an independent route: the PD and g(q) written as Python-function loads (+tau on the
    # child, -tau on the parent), g from the inverse dynamics of the bare arm at rest
    scene = mb.load_model("models/pd_arm.toml")
    system = scene.system
    bare = system.compile(effects="-drive_pan,-drive_shoulder,-drive_elbow")
    pose = np.array([0.5, -0.6, 1.2])
    s = mb.System("loads", gravity=(0, 0, -9.81))
    for b in ("base", "upper_arm", "forearm"):
        rec = system.bodies[b]
        s.add_body(b, mass=rec.mass, com=rec.com, inertia=rec.inertia)
    for k, (name, j) in enumerate(system.joints.items()):
        s.add_joint(name, "revolute", parent=j.parent, child=j.child, axis=j.axis,
                    position=j.position)

        def tau(t, q, u, k=k):
            g = bare.inverse_dynamics(q, np.zeros(3), np.zeros(3))[0]
            return 400.0 * (pose[k] - q[k]) - 40.0 * u[k] + g[bare.speeds[k]]
        a = np.asarray(j.axis, float)      # the same components in parent and child axes
        s.add_load(f"{name}_c", j.child, frame="body", moment=lambda t, q, u, f=tau, a=a:
                   f(t, q, u) * a)
        if j.parent != "ground":
            s.add_load(f"{name}_p", j.parent, frame="body", moment=lambda t, q, u, f=tau,
                       a=a: -f(t, q, u) * a)
    r1 = scene.simulate(t_end=0.5)
    r2 = mb.simulate(s.compile(), 0.5, q0=scene.q0, u0=scene.u0, t_eval=r1.t)
    assert np.max(np.abs(r1.q - r2.q)) < 1e-9


def test_a_controller_sampled_too_slowly_is_named_as_the_suspect():
    # a digital PD whose derivative gain over the inertia exceeds 2 / rate is unstable
    s = wheel(0.1)
    s.add_controller("slow", lambda t, q, u: [-100.0 * q[0] - 30.0 * u[0]], rate=20.0,
                     joints=["th"])
    with pytest.raises(mb.SimulationError, match="sampled too slowly.*raise its rate"):
        mb.simulate(s.compile(), 20.0, q0={"th": 0.1}, max_steps=20000)
