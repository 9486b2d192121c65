"""Contact between shapes on bodies (issue 28, item 3): each force and each geometry
against a closed form or an independent route, conservation laws, the broad phase against
every pair, events on the gap, the step-size hint and the errors (docs/contact.md)."""
import math
import warnings

import numpy as np
import pytest
from scipy.integrate import solve_ivp

import mbdyn as mb
from mbdyn.elements.force_kinds import hunt_crossley_factor


def balls_on_a_line(n=2, gap=0.002, e=1.0, k=1e7, v=0.5, masses=None, r=0.01, **kw):
    """``n`` balls on a frictionless line (prismatic joints along x), ``gap`` apart."""
    s = mb.System("row", gravity=(0, 0, 0))
    for i in range(n):
        m = masses[i] if masses is not None else 0.03
        s.add_body(f"b{i}", mass=m, inertia=[0.4 * m * r * r] * 3)
        s.add_joint(f"x{i}", "prismatic", parent="ground", child=f"b{i}", axis="x",
                    position=(i * (2 * r + gap), 0, 0))
        s.add_shape(f"s{i}", "sphere", f"b{i}", radius=r)
    s.add_contact("c", group=[f"s{i}" for i in range(n)], stiffness=k, restitution=e,
                  impact_speed=v, **kw)
    return s.compile()


def free_balls(positions, radii=(0.01, 0.012), masses=(0.1, 0.2), **contact):
    s = mb.System("free balls", gravity=(0, 0, 0))
    for k, (x, rad, m) in enumerate(zip(positions, radii, masses)):
        s.add_body(f"b{k}", mass=m, inertia=[0.4 * m * rad * rad] * 3)
        s.add_joint(f"j{k}", "free", parent="ground", child=f"b{k}", position=x)
        s.add_shape(f"s{k}", "sphere", f"b{k}", radius=rad)
    s.add_contact("c", pairs=[("s0", "s1")], **({"stiffness": 1e7} | contact))
    return s.compile()


def identity_state(model):
    q = np.zeros(model.nq)
    q[3::7] = 1.0                      # free joints: (x, y, z, w, qx, qy, qz)
    return q


# ----------------------------------------------------------------------------- spheres
def test_sphere_sphere_force_is_hertz_along_the_line_of_centres():
    k, r1, r2, m1, m2 = 2e7, 0.01, 0.012, 0.1, 0.2
    direction = np.array([0.3, -0.5, 0.81])
    direction /= np.linalg.norm(direction)
    overlap = 4e-4
    model = free_balls([(0, 0, 0), tuple((r1 + r2 - overlap) * direction)], stiffness=k)
    q = identity_state(model)
    ud = model.forward_dynamics(q, np.zeros(model.nu))
    F = k * overlap ** 1.5
    assert ud[0:3] == pytest.approx(-F / m1 * direction, rel=1e-10)
    assert ud[6:9] == pytest.approx(F / m2 * direction, rel=1e-10)
    assert np.abs(ud[3:6]).max() < 1e-9 and np.abs(ud[9:12]).max() < 1e-9  # through the centres
    V, P = model.element_energy(q, np.zeros(model.nu))
    assert V == pytest.approx(k * overlap ** 2.5 / 2.5, rel=1e-12) and P == 0.0
    assert model.contact_gap("c", q) == pytest.approx(-overlap, rel=1e-9)


def test_hunt_crossley_damping_force_at_an_approach_speed():
    k, e, v_imp, overlap, approach = 1e7, 0.6, 2.0, 3e-4, 0.7
    model = free_balls([(0, 0, 0), (0.022 - overlap, 0, 0)], stiffness=k, restitution=e,
                       impact_speed=v_imp)
    u = np.zeros(model.nu)
    u[6] = -approach                   # ball 1 moves towards ball 0
    ud = model.forward_dynamics(identity_state(model), u)
    c = hunt_crossley_factor(e, 1.5) / v_imp
    assert ud[6] * 0.2 == pytest.approx(k * overlap ** 1.5 * (1 + c * approach), rel=1e-10)
    V, P = model.element_energy(identity_state(model), u)
    assert P == pytest.approx(-k * overlap ** 1.5 * c * approach * approach, rel=1e-10)


def test_two_balls_obey_newtons_law_of_restitution_at_the_impact_speed():
    """Hunt-Crossley's e holds at impact_speed (the damping is calibrated there); at
    another speed it is the e of the scaled impact x'' = -x^n (1 + z x'), z = c v,
    integrated here independently."""
    e, v = 0.7, 0.5
    model = balls_on_a_line(2, e=e, v=v)
    res = mb.simulate(model, 0.02, u0={"x0_dot": v}, rtol=1e-12, atol=1e-14, max_step=1e-5)
    assert res["x0_dot"][-1] == pytest.approx(v * (1 - e) / 2, rel=1e-7)
    assert res["x1_dot"][-1] == pytest.approx(v * (1 + e) / 2, rel=1e-7)
    slow = v / 3
    res = mb.simulate(model, 0.05, u0={"x0_dot": slow}, rtol=1e-12, atol=1e-14, max_step=1e-5)
    e_slow = (res["x1_dot"][-1] - res["x0_dot"][-1]) / slow
    z = hunt_crossley_factor(e, 1.5) * slow / v

    def rhs(s, y):
        return [y[1], -max(y[0], 0.0) ** 1.5 * max(1 + z * y[1], 0.0)]

    def released(s, y):
        return y[0] if s > 0 else 1.0
    released.terminal, released.direction = True, -1
    ref = solve_ivp(rhs, (0, 100), [0, 1], events=released, rtol=1e-12, atol=1e-14)
    assert e_slow == pytest.approx(-ref.y_events[0][0][1], rel=1e-6)
    assert e_slow > e + 0.05


def test_an_oblique_free_collision_with_friction_conserves_momentum():
    model = free_balls([(0, 0, 0), (0.03, 0.008, 0.003)], stiffness=1e7, restitution=0.6,
                       impact_speed=1.0, friction=0.4, slip_speed=1e-3)
    u0 = np.zeros(model.nu)
    u0[0:6] = [1.0, 0.1, 0.0, 0, 0, 30.0]
    u0[6:12] = [-0.5, 0.0, 0.2, 10.0, 0, 0]
    res = mb.simulate(model, 0.03, identity_state(model), u0, rtol=1e-11, atol=1e-13, max_step=1e-5)
    p0, L0 = model.momentum(res.q[0], res.u[0])
    p1, L1 = model.momentum(res.q[-1], res.u[-1])
    assert np.abs(p1 - p0).max() < 1e-9 * np.abs(p0).max()
    assert np.abs(L1 - L0).max() < 1e-9 * np.abs(L0).max()
    assert np.abs(res.u[-1][6:9] - u0[6:9]).max() > 0.1           # they did collide


# ----------------------------------------------------------------------------- cradle
def test_newtons_cradle_passes_momentum_and_energy_down_the_row():
    v = 0.5
    model = balls_on_a_line(5, e=1.0, v=v)
    res = mb.simulate(model, 0.05, u0={"x0_dot": v}, rtol=1e-11, atol=1e-13, max_step=1e-4,
                      outputs=("energy",))
    speeds = np.array([res[f"x{i}_dot"][-1] for i in range(5)])
    assert speeds[4] == pytest.approx(v, rel=1e-8)
    assert np.abs(speeds[:4]).max() < 1e-8
    assert res.stats["energy_drift"] < 1e-8


def test_newtons_cradle_model_file_swings_the_last_ball_up():
    """The first ball, a compound pendulum (length ``L + 0.4 r^2 / L`` equivalent),
    touches the second past the bottom, at ``theta_c = -asin(gap / L)``: from ``theta0``
    that takes ``sqrt(Le/g) (K(k) + F(phi_c, k))``, ``k = sin(theta0/2)``,
    ``sin phi = sin(|theta|/2)/k``."""
    from scipy.special import ellipk, ellipkinc
    scene = mb.load_model("models/newtons_cradle.toml")
    res = scene.simulate(t_end=0.5)
    first, last = res["swing1"], res["swing5"]
    p = scene.parameters
    theta0 = p["theta0"]
    k = math.sin(theta0 / 2)
    phi_c = math.asin(math.sin(math.asin(p["gap"] / p["L"]) / 2) / k)
    Le = p["L"] + 0.4 * p["r"] ** 2 / p["L"]
    onset = math.sqrt(Le / p["g"]) * (ellipk(k * k) + ellipkinc(phi_c, k * k))
    assert [name for name, _ in res.events][0] == "first_impact"
    assert res.events[0].t == pytest.approx(onset, rel=1e-7)
    assert np.abs(first[res.t > 0.3]).max() < 0.03 * theta0          # the first ball stops
    assert np.abs(last).max() == pytest.approx(theta0, rel=0.02)     # the last swings as high


# ----------------------------------------------------------------------------- cam
ECC, RC = 0.01, 0.04


def eccentric_profile(n=72):
    """An eccentric circle (radius RC, centre ECC from the axis) as radius against angle."""
    a = np.linspace(0, 2 * np.pi, n, endpoint=False)
    return np.column_stack([a, ECC * np.cos(a) + np.sqrt(RC ** 2 - (ECC * np.sin(a)) ** 2)])


def cam_follower(omega, follower="flat", roller=0.01, mass=0.5, ks=2000.0, F0=20.0, k=1e8,
                 points=72):
    s = mb.System("cam", gravity=(0, 0, 0))
    s.add_body("cam", mass=1.0, inertia=[1e-3] * 3)
    s.add_joint("theta", "revolute", parent="ground", child="cam", axis="z",
                drive=omega * mb.t)
    s.add_body("f", mass=mass)
    s.add_joint("y", "prismatic", parent="ground", child="f", axis="y")
    s.add_force("spring", "joint-spring-damper", joint="y", stiffness=ks, rest=RC - ECC,
                preload=F0)
    s.add_shape("profile", "cam", "cam", profile=eccentric_profile(points))
    if follower == "flat":
        s.add_shape("face", "plane", "f", normal=(0, -1, 0))
    else:
        s.add_shape("face", follower, "f", radius=roller, **(
            {"length": 0.01} if follower == "cylinder" else {}))
    s.add_contact("c", pairs=[("profile", "face")], stiffness=k, restitution=0.5,
                  impact_speed=0.1)
    return s.compile()


def test_a_flat_follower_lifts_as_the_eccentric_cam_turns():
    """Below the critical speed (``test_..._leaves_the_cam``) the face stays on the
    profile, whose support is the offset circle's: lift ``RC + ECC sin(omega t)``."""
    mass, ks, F0 = 0.5, 2000.0, 20.0
    omega = 0.9 * math.sqrt((F0 + 2 * ks * ECC) / (mass * ECC))
    model = cam_follower(omega)
    t = np.linspace(0, 0.4, 801)
    q0 = {"y": RC - ((F0 + ks * ECC) / 1e8) ** (2 / 3)}      # the follower rides on the cam
    res = mb.simulate(model, 0.4, q0, {"y_dot": omega * ECC}, rtol=1e-10, atol=1e-13,
                      max_step=1e-4, t_eval=t)
    gap = np.array([model.contact_gap("c", q, tk) for q, tk in zip(res.q, res.t)])
    assert gap.max() < 0                                    # in contact all along
    assert np.abs(res["y"] - gap - (RC + ECC * np.sin(omega * t))).max() < 2e-8


def follower_release(k, omega, mass=0.5, ks=2000.0, F0=20.0):
    """The time the face leaves the cam (the gap rises through zero), simulated; the
    profile a spline through 360 points of the circle (72 shift the time by 1e-5)."""
    model = cam_follower(omega, k=k, points=360)
    q0 = {"y": RC - ((F0 + ks * ECC) / k) ** (2 / 3)}
    res = mb.simulate(model, 0.012, q0, {"y_dot": omega * ECC}, rtol=1e-11, atol=1e-14,
                      max_step=1e-5, events=[mb.contact_event(model, "c", direction=1)])
    return res.events[0].t


def test_the_follower_leaves_the_cam_above_the_critical_speed():
    """Rigid contact: ``N = F0 + ks ECC (1 + s) - m ECC omega^2 s`` (``s = sin omega t``)
    stays positive while ``omega^2 < (F0 + 2 ks ECC) / (m ECC)``, and above it falls to
    zero at ``s* = (F0 + ks ECC) / (m ECC omega^2 - ks ECC)``.  A compliant contact lets go
    a little later (its deflection ``(N/k)^(2/3)`` unwinds as N falls: a lag that shrinks
    like ``k^(-2/7)``); the simulated release matches the same compliant follower
    integrated on its own (the analytic lift, the Hunt-Crossley law) to 1e-6."""
    mass, ks, F0, k = 0.5, 2000.0, 20.0, 1e8
    omega = 1.1 * math.sqrt((F0 + 2 * ks * ECC) / (mass * ECC))
    rigid = math.asin((F0 + ks * ECC) / (mass * ECC * omega ** 2 - ks * ECC)) / omega
    c = hunt_crossley_factor(0.5, 1.5) / 0.1

    def rhs(t, y):
        delta = RC + ECC * math.sin(omega * t) - y[0]
        rate = ECC * omega * math.cos(omega * t) - y[1]
        fn = max(k * max(delta, 0.0) ** 1.5 * (1 + c * rate), 0.0)
        return [y[1], (fn - F0 - ks * (y[0] - RC + ECC)) / mass]

    def released(t, y):
        return RC + ECC * math.sin(omega * t) - y[0] if t > 0 else 1.0
    released.terminal, released.direction = True, -1
    y0 = [RC - ((F0 + ks * ECC) / k) ** (2 / 3), omega * ECC]
    ref = solve_ivp(rhs, (0, 0.012), y0, events=released, rtol=1e-12, atol=1e-15,
                    max_step=1e-5, method="DOP853").t_events[0][0]
    assert follower_release(k, omega) == pytest.approx(ref, rel=1e-6)
    assert follower_release(1e11, omega) == pytest.approx(rigid, rel=0.015)


@pytest.mark.parametrize("case", [None, "lift_off"])
def test_cam_follower_model_file_keeps_contact_below_the_critical_speed_only(case):
    scene = mb.load_model("models/cam_follower.toml", case=case)
    res = scene.simulate()
    p = scene.parameters
    gap = np.array([scene.model.contact_gap("cam", q, t) for q, t in zip(res.q, res.t)])
    lift = p["Rc"] + p["ecc"] * np.sin(p["Omega"] * res.t)
    assert np.abs(res["y"] - gap - lift).max() < 1e-8        # the face on the profile
    assert (gap.max() < 0) == (case is None)


@pytest.mark.parametrize("follower", ["sphere", "cylinder"])
def test_a_roller_follows_the_offset_circle(follower):
    """A roller of radius rho on the line x = 0 rides on the circle of radius RC + rho
    about the disk's centre: ``y = ECC sin + sqrt((RC + rho)^2 - (ECC cos)^2)``; its gap
    is its distance from that centre less RC + rho."""
    rho, omega = 0.01, 20.0
    model = cam_follower(omega, follower, roller=rho)
    t = np.linspace(0, 0.3, 301)
    y0 = math.sqrt((RC + rho) ** 2 - ECC ** 2) - (40 / 1e8) ** (2 / 3)
    res = mb.simulate(model, 0.3, {"y": y0}, {"y_dot": ECC * omega}, rtol=1e-10, atol=1e-13,
                      max_step=1e-4, t_eval=t)
    gap = np.array([model.contact_gap(("profile", "face"), q, tk)
                    for q, tk in zip(res.q, res.t)])
    th = omega * t
    touching = ECC * np.sin(th) + np.sqrt((RC + rho) ** 2 - (ECC * np.cos(th)) ** 2)
    assert gap.max() < 0
    assert np.abs(res["y"] - touching).max() < 1e-4          # rides on the circle
    exact = np.hypot(ECC * np.cos(th), res["y"] - ECC * np.sin(th)) - RC - rho
    assert np.abs(gap - exact).max() < 1e-7                   # its gap is the circle's


# ----------------------------------------------------------------------------- box
def box_on_incline(theta, mu, half_length, half_height, slip=1e-3, k=1e7):
    s = mb.System("incline", gravity=(0, 0, -9.81))
    s.add_frame("slope")
    s.add_joint("tilt", "fixed", parent="ground", child="slope", orientation=("y", theta))
    s.add_frame("cx")
    s.add_joint("x", "prismatic", parent="slope", child="cx", axis="x")
    s.add_frame("cz")
    s.add_joint("z", "prismatic", parent="cx", child="cz", axis="z")
    s.add_body("box", mass=1.0, inertia=[((2 * half_length) ** 2 + 4 * half_height ** 2) / 12] * 3)
    s.add_joint("phi", "revolute", parent="cz", child="box", axis="y")
    s.add_shape("incline", "plane", "ground", normal=(math.sin(theta), 0, math.cos(theta)))
    s.add_shape("block", "box", "box", half_sizes=(half_length, 0.05, half_height))
    s.add_contact("c", pairs=[("incline", "block")], stiffness=k, restitution=0.3,
                  impact_speed=0.1, friction=mu, slip_speed=slip)
    model = s.compile()
    z0 = half_height - (9.81 * math.cos(theta) / 4 / k) ** (2 / 3)
    return model, {"z": z0}


@pytest.mark.parametrize("ratio", [0.95, 1.05])
def test_a_box_slides_down_the_incline_when_tan_theta_exceeds_mu(ratio):
    """Below: it creeps at the regularised friction's speed ``slip r / sqrt(1 - r^2)``
    (``r = tan theta / mu``); above: it slides at ``g (sin theta - mu cos theta)``."""
    mu, slip = 0.5, 1e-3
    theta = math.atan(ratio * mu)
    model, q0 = box_on_incline(theta, mu, 0.2, 0.05, slip=slip)
    res = mb.simulate(model, 1.0, q0, rtol=1e-8, atol=1e-10, max_step=1e-3,
                      t_eval=np.linspace(0, 1, 501))
    late = res.t > 0.3
    if ratio < 1:
        assert res["x_dot"][-1] == pytest.approx(slip * ratio / math.sqrt(1 - ratio ** 2),
                                                 rel=1e-6)
    else:
        a = np.polyfit(res.t[late], res["x_dot"][late], 1)[0]
        assert a == pytest.approx(9.81 * (math.sin(theta) - mu * math.cos(theta)), rel=2e-3)
    assert abs(res["phi"]).max() < 1e-3                     # it does not tip


@pytest.mark.parametrize("ratio", [0.95, 1.05])
def test_a_tall_box_tips_over_when_tan_theta_exceeds_its_width_over_height(ratio):
    a, b = 0.05, 0.1                        # half length along the slope, half height
    theta = math.atan(ratio * a / b)
    model, q0 = box_on_incline(theta, 1.0, a, b)
    res = mb.simulate(model, 1.0, q0, rtol=1e-8, atol=1e-10, max_step=1e-3)
    if ratio < 1:                           # it rocks as it settles, then rests
        assert abs(res["phi"]).max() < 1e-2 and abs(res["phi"][-1]) < 2e-3
        assert abs(res["x"]).max() < 1e-3                   # and does not slide (mu = 1)
    else:
        assert abs(res["phi"]).max() > 0.5


def test_box_incline_model_file_slides_as_the_closed_form_says():
    scene = mb.load_model("models/box_incline.toml")
    res = scene.simulate()
    p = scene.parameters
    late = res.t > 0.3
    acc = np.polyfit(res.t[late], res["x_dot"][late], 1)[0]
    assert acc == pytest.approx(9.81 * (math.sin(p["theta"]) - p["mu"] * math.cos(p["theta"])),
                                rel=5e-3)


# ----------------------------------------------------------------------------- energy
def test_energy_balance_of_a_tumbling_box_and_capsule_with_friction():
    s = mb.System("tumble", gravity=(0, 0, -9.81))
    s.add_body("box", mass=0.5, inertia=[1e-3, 2e-3, 2.5e-3])
    s.add_joint("jb", "free", parent="ground", child="box", position=(0, 0, 0.1))
    s.add_body("rod", mass=0.2, inertia=[5e-4, 5e-4, 2e-5])
    s.add_joint("jr", "free", parent="ground", child="rod", position=(0.12, 0, 0.12))
    s.add_shape("floor", "plane", "ground")
    s.add_shape("block", "box", "box", sizes=(0.1, 0.06, 0.04), orientation=("x", 0.3))
    s.add_shape("stick", "capsule", "rod", radius=0.01, length=0.1, axis=(1, 0.2, 0.3))
    s.add_contact("c", pairs=[("floor", "block"), ("floor", "stick")], stiffness=1e6,
                  restitution=0.5,
                  impact_speed=1.0, friction=0.3, slip_speed=1e-2)
    model = s.compile()
    u0 = np.zeros(model.nu)
    u0[:6] = [0.5, 0.2, -0.5, 3.0, -2.0, 1.0]
    u0[6:12] = [-0.3, 0.1, -0.8, 0.0, 5.0, 2.0]
    res = mb.simulate(model, 0.4, None, u0, rtol=1e-10, atol=1e-12, max_step=5e-4,
                      t_eval=np.linspace(0, 0.4, 8001), outputs=("energy",))
    assert res.energy["dissipated"][-1] > 0.1 * res.energy["kinetic"][0]
    assert res.stats["energy_drift"] < 1e-4


# ----------------------------------------------------------------------------- broad phase
def cloud(mode, n=30, seed=3):
    """Spheres and capsules in a 0.2 m cube against a floor and a wall: one contact of
    the whole group (``mode`` "sweep" or "all") or of every pair listed ("pairs")."""
    rng = np.random.default_rng(seed)
    s = mb.System("cloud", gravity=(0, 0, -9.81))
    names = []
    for i in range(n):
        s.add_body(f"b{i}", mass=0.1 + rng.random(), inertia=[1e-4] * 3)
        s.add_joint(f"j{i}", "free", parent="ground", child=f"b{i}",
                    position=tuple(rng.uniform(-0.1, 0.1, 3)))
        if i % 2:
            s.add_shape(f"s{i}", "capsule", f"b{i}", radius=0.01, length=0.04,
                        axis=tuple(rng.normal(size=3)), position=(0.01, 0, 0))
        else:
            s.add_shape(f"s{i}", "sphere", f"b{i}", radius=0.02)
        names.append(f"s{i}")
    s.add_shape("floor", "plane", "ground", position=(0, 0, -0.08))
    s.add_shape("wall", "plane", "ground", position=(0.08, 0, 0), normal="-x")
    group = names + ["floor", "wall"]
    law = dict(stiffness=1e5, restitution=0.5, friction=0.3)
    if mode == "pairs":
        s.add_contact("c", pairs=[(a, b) for i, a in enumerate(group) for b in group[i + 1:]
                                  if {a, b} != {"floor", "wall"}], **law)
    else:
        s.add_contact("c", group=group, broad_phase=mode == "sweep", **law)
    return s.compile()


def test_the_broad_phase_finds_the_same_forces_as_every_pair():
    rng = np.random.default_rng(7)
    models = [cloud("sweep"), cloud("all"), cloud("pairs")]
    q = models[0].default_coordinates()
    for _ in range(3):
        u = rng.normal(size=models[0].nu)
        outs = [m.forward_dynamics(q, u) for m in models]
        energies = [m.element_energy(q, u) for m in models]
        for other, e in zip(outs[1:], energies[1:]):
            assert np.abs(outs[0] - other).max() <= 1e-10 * np.abs(other).max()
            assert energies[0] == pytest.approx(e, rel=1e-12)
        assert energies[0][0] > 0           # some shapes overlap: the test tests something
    touching = sum(models[1].contact_gap((a.name, b.name), q) < 0
                   for i, a in enumerate(models[1].force_element("c").params["shapes"])
                   for b in models[1].force_element("c").params["shapes"][i + 1:]
                   if {a.name, b.name} != {"floor", "wall"})
    assert touching >= 5


# ----------------------------------------------------------------------------- geometry
def one_pair(kind_a, keys_a, kind_b, keys_b, frame_b=None):
    """Shape a on the ground, shape b on a body placed by the joint's ``frame_b``
    ``(position, orientation)``; the model and its coordinates."""
    s = mb.System("pair", gravity=(0, 0, 0))
    s.add_body("b", mass=1.0, inertia=[1e-3] * 3)
    pos, orient = frame_b or ((0, 0, 0), None)
    s.add_joint("j", "free", parent="ground", child="b", position=pos, orientation=orient)
    s.add_shape("A", kind_a, "ground", **keys_a)
    s.add_shape("B", kind_b, "b", **keys_b)
    s.add_contact("c", pairs=[("A", "B")], stiffness=1e6)
    model = s.compile()
    return model, model.default_coordinates()


def tilt(angle):
    return ("y", angle)


@pytest.mark.parametrize("case", [
    # a capsule lying tilted over the floor: its lower end sphere
    ("plane", {}, "capsule", {"radius": 0.02, "length": 0.2, "axis": "x"},
     ((0, 0, 0.1), tilt(0.3)), lambda: 0.1 - 0.1 * math.sin(0.3) - 0.02),
    # a cylinder tilted over the floor: the deepest point of its lower rim
    ("plane", {}, "cylinder", {"radius": 0.05, "length": 0.2, "axis": "z"},
     ((0, 0, 0.3), tilt(0.4)), lambda: 0.3 - 0.1 * math.cos(0.4) - 0.05 * math.sin(0.4)),
    # a box turned about y over the floor: its lowest corner
    ("plane", {}, "box", {"half_sizes": (0.1, 0.05, 0.02)}, ((0, 0, 0.2), tilt(0.5)),
     lambda: 0.2 - 0.1 * math.sin(0.5) - 0.02 * math.cos(0.5)),
    # a sphere beside a box's face, and beyond its edge
    ("box", {"half_sizes": (0.1, 0.2, 0.3)}, "sphere", {"radius": 0.05},
     ((0.17, 0.0, 0.1), None), lambda: 0.07 - 0.05),
    ("box", {"half_sizes": (0.1, 0.2, 0.3)}, "sphere", {"radius": 0.05},
     ((0.13, 0.24, 0.1), None), lambda: math.hypot(0.03, 0.04) - 0.05),
    # a sphere whose centre is inside a box: the nearest face
    ("box", {"half_sizes": (0.1, 0.2, 0.3)}, "sphere", {"radius": 0.05},
     ((0.08, 0.0, 0.0), None), lambda: -0.02 - 0.05),
    # two capsules crossed at right angles, one above the other
    ("capsule", {"radius": 0.01, "length": 0.2, "axis": "x"}, "capsule",
     {"radius": 0.02, "length": 0.2, "axis": "y"}, ((0.05, 0.03, 0.04), None),
     lambda: 0.04 - 0.03),
    # a sphere beyond the end of a capsule
    ("capsule", {"radius": 0.01, "length": 0.2, "axis": "x"}, "sphere", {"radius": 0.02},
     ((0.13, 0.04, 0.0), None), lambda: 0.05 - 0.03),
    # a sphere under a plane of the ground facing down (a ceiling)
    ("plane", {"normal": "-z", "position": (0, 0, 1.0)}, "sphere", {"radius": 0.1},
     ((0.3, 0, 0.85), None), lambda: 0.05),
], ids=["capsule-plane", "cylinder-plane", "box-plane", "sphere-box-face",
        "sphere-box-edge", "sphere-inside-box", "capsule-capsule", "sphere-capsule-end",
        "sphere-ceiling"])
def test_gaps_of_each_pair_of_kinds_against_their_closed_forms(case):
    kind_a, keys_a, kind_b, keys_b, frame, expected = case
    model, q = one_pair(kind_a, keys_a, kind_b, keys_b, frame)
    assert model.contact_gap("c", q) == pytest.approx(expected(), abs=1e-12)


def test_a_penetrating_edge_pushes_along_the_plane_normal_at_its_corners():
    """A box turned about y with its lowest edge (two corners) 1 mm into the floor: each
    corner pushes up with k delta^n at the corner, which also turns the box."""
    k, depth, a = 1e6, 1e-3, np.array([0.1, 0.05, 0.02])
    model, q = one_pair("plane", {}, "box", {"half_sizes": tuple(a)})
    q[2] = a[0] * math.sin(0.5) + a[2] * math.cos(0.5) - depth
    q[3:7] = mb.rotations.from_axis_angle((0, 1, 0), 0.5)
    ud = model.forward_dynamics(q, np.zeros(model.nu))
    F = np.array([0, 0, k * depth ** 1.5])
    assert ud[:3] == pytest.approx(2 * F, rel=1e-9, abs=1e-9)          # mass 1
    R = mb.rotations.to_matrix(q[3:7])
    moment = sum(np.cross(R @ (a * (1, side, -1)), F) for side in (-1, 1))
    assert ud[3:6] == pytest.approx(R.T @ moment / 1e-3, rel=1e-9, abs=1e-9)
    assert abs(moment[1]) > 0


# ----------------------------------------------------------------------------- events, hints
def test_a_contact_event_fires_at_the_onset_and_the_release():
    v, gap0 = 0.5, 0.002
    model = balls_on_a_line(2, gap=gap0, v=v)
    onset = mb.contact_event(model, "c")
    release = mb.contact_event(model, ("s0", "s1"), name="release", direction=1)
    res = mb.simulate(model, 0.02, u0={"x0_dot": v}, rtol=1e-12, atol=1e-14, max_step=1e-5,
                      events=[onset, release])
    names = [name for name, _ in res.events]
    assert names == ["contact-c", "release"]
    assert res.events[0].t == pytest.approx(gap0 / v, rel=1e-9)
    assert model.contact_gap("c", model.default_coordinates()) == pytest.approx(gap0)


def test_an_adaptive_run_without_max_step_is_told_the_contact_s_time_scale():
    model = balls_on_a_line(2)
    with pytest.warns(mb.ModelWarning, match=r"contact 'c': an impact .* lasts about "
                      r"(\S+) s .* give max_step <= (\S+)") as record:
        mb.simulate(model, 0.001, u0={"x0_dot": 0.5})
    text = str(record[0].message)
    m, k, v = 0.015, 1e7, 0.5                  # reduced mass of two 30 g balls
    x_max = (2.5 * m * v * v / (2 * k)) ** 0.4
    duration = 2 * x_max / v * 1.4718          # the integral of ds / sqrt(1 - s^2.5)
    assert f"{duration:.2g}" in text
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        mb.simulate(model, 0.001, u0={"x0_dot": 0.5}, max_step=1e-4)


# ----------------------------------------------------------------------------- errors
def small_system():
    s = mb.System("errors")
    s.add_body("b", mass=1.0)
    s.add_joint("z", "prismatic", parent="ground", child="b", axis="z")
    s.add_shape("ball", "sphere", "b", radius=0.1)
    s.add_shape("floor", "plane", "ground")
    s.add_shape("crate", "box", "b", sizes=(1, 1, 1))
    s.add_shape("crate2", "box", "ground", sizes=(1, 1, 1))
    return s


@pytest.mark.parametrize("call, match", [
    (lambda s: s.add_contact("c", pairs=[("ball", "nope")], stiffness=1e6),
     r"contact 'c': pairs names unknown shape 'nope'"),
    (lambda s: s.add_shape("x", "sphere", "nobody", radius=0.1),
     r"shape 'x': unknown body 'nobody'"),
    (lambda s: s.add_contact("c", pairs=[("crate", "crate2")], stiffness=1e6),
     r"contact 'c': pairs \('crate', 'crate2'\): box-box contact is not supported; the "
     r"supported pairs are sphere-sphere"),
    (lambda s: s.add_contact("c", group=["crate", "crate2", "floor"], stiffness=1e6),
     r"box-box contact is not supported.*list the pairs you need"),
    (lambda s: s.add_shape("x", "sphere", "b", radius=-0.1),
     r"shape 'x': radius must be >= 0, got -0.1"),
    (lambda s: s.add_shape("x", "capsule", "b", radius=0.1),
     r"shape 'x': missing length of the capsule"),
    (lambda s: s.add_contact("c", pairs=[("ball", "crate")], stiffness=1e6),
     r"both shapes are on 'b'"),
    (lambda s: s.add_contact("c", pairs=[("ball", "floor")]),
     r"contact 'c': missing stiffness"),
    (lambda s: s.add_contact("c", pairs=[("ball", "floor")], stiffness=1e6, restitution=2),
     r"contact 'c': restitution must be in \(0, 1\]"),
    (lambda s: s.add_shape("x", "cam", "b", profile=[[0, 1], [1, 1], [2, 1], [7, 1]]),
     r"shape 'x': profile angles must increase and span less than one turn"),
])
def test_bad_input_names_the_element_and_the_key(call, match):
    with pytest.raises(mb.ModelError, match=match):
        call(small_system())


def test_a_model_file_error_names_the_entry(tmp_path):
    path = tmp_path / "bad.toml"
    path.write_text("""
[[bodies]]
name = "b"
mass = 1
[[joints]]
name = "z"
kind = "prismatic"
child = "b"
axis = "z"
[[shapes]]
name = "ball"
kind = "sphere"
body = "b"
radius = 0.1
[[contacts]]
name = "c"
pairs = [["ball", "floor"]]
stiffness = 1e6
""")
    with pytest.raises(mb.ModelFileError, match=r"contacts\[0\].*unknown shape 'floor'"):
        mb.load_model(path)


def test_a_contact_is_an_effect_and_off_it_is_gone():
    s = mb.System("row", gravity=(0, 0, 0))
    for i, x in enumerate((0.0, 0.019)):                     # overlapping by 1 mm
        s.add_body(f"b{i}", mass=0.03)
        s.add_joint(f"x{i}", "prismatic", parent="ground", child=f"b{i}", axis="x",
                    position=(x, 0, 0))
        s.add_shape(f"s{i}", "sphere", f"b{i}", radius=0.01)
    s.add_contact("c", pairs=[("s0", "s1")], stiffness=1e7)
    on, off = s.compile(), s.compile(effects="-c")
    q, u = np.zeros(2), np.zeros(2)
    assert on.forward_dynamics(q, u)[1] == pytest.approx(1e7 * 1e-3 ** 1.5 / 0.03)
    assert "c" in on.forces and "c" not in off.forces
    assert np.all(off.forward_dynamics(q, u) == 0.0)
    with pytest.raises(mb.ModelError, match="unknown contact 'c'.*switched off"):
        off.contact_gap("c", q)
    assert "s0-s1; k = 1e+07" in on.force_element("c").describe()


def test_pictures_draw_the_contact_shapes_where_they_are():
    from mbdyn.viz.drawing import extra_primitives
    from mbdyn.viz.meshes import primitive_mesh
    model, q = one_pair("plane", {}, "box", {"half_sizes": (0.1, 0.05, 0.02)},
                        ((0, 0, 0.3), None))
    from mbdyn.viz.contact_shapes import ground_planes
    prims = extra_primitives(model, model.kinematics(q, np.zeros(model.nu)))
    assert [p[0] for p in prims] == ["box"]         # the ground's plane is a ground plane
    (_, point, normal), = ground_planes(model)
    assert normal == pytest.approx([0, 0, 1]) and point == pytest.approx([0, 0, 0])
    box = primitive_mesh(*prims[0])[0]
    assert box.min(axis=0) == pytest.approx([-0.1, -0.05, 0.28])
    assert box.max(axis=0) == pytest.approx([0.1, 0.05, 0.32])


def test_info_describes_the_contact_and_its_event(capsys):
    from mbdyn.cli import main
    assert main(["info", "models/newtons_cradle.toml"]) == 0
    out = capsys.readouterr().out
    assert "balls          shape-contact: every pair of s1, s2, s3, s4, s5 (sweep and prune)" in out
    assert "first_impact   gap of contact ['s1', 's2']  (falling)" in out


def _resting_ball(floor_kind):
    m, k, radius = 2.0, 1e6, 0.05
    delta = (m * 9.81 / k) ** (2 / 3)               # Hertz: k delta^1.5 = m g
    s = mb.System("rest", gravity=(0, 0, -9.81))
    s.add_body("ball", mass=m, inertia=[1e-3] * 3)
    s.add_joint("j", "free", parent="ground", child="ball")
    if floor_kind == "shapes":
        s.add_shape("b", "sphere", "ball", radius=radius)
        s.add_shape("floor", "plane", "ground", normal="z")
        s.add_contact("c", pairs=[("floor", "b")], stiffness=k)
    else:
        s.add_force("c", "contact", body="ball", radius=radius, stiffness=k)
    model = s.compile()
    q = model.default_coordinates()
    q[2] = radius - delta
    return model, q, m, delta


@pytest.mark.parametrize("floor_kind", ["shapes", "floor"])
def test_contact_forces_of_a_ball_at_rest_are_its_weight_at_its_lowest_point(floor_kind):
    model, q, m, delta = _resting_ball(floor_kind)
    f = model.contact_forces(q, np.zeros(model.nu))
    assert f.shape == (1, 6)
    # a pair of shapes touches midway through the overlap; the floor contact at the
    # sphere's lowest point
    depth = delta / 2 if floor_kind == "shapes" else delta
    assert f[0, :3] == pytest.approx([0, 0, -depth], abs=1e-12)
    assert f[0, 3:] == pytest.approx([0, 0, m * 9.81], rel=1e-12)
    assert np.abs(model.forward_dynamics(q, np.zeros(model.nu))).max() < 1e-9


def test_contact_forces_drawn_as_arrows_when_asked(tmp_path):
    from mbdyn.viz.geometry import ARROW, prepare
    from mbdyn.viz.view_data import view_data
    model, q, m, delta = _resting_ball("shapes")
    res = mb.simulate(model, 0.1, q0=q, t_eval=np.linspace(0, 0.1, 5))
    run = prepare(res, res.t, contact_forces=True)
    assert len(run.arrows) == 5 and all(a.shape == (1, 2, 3) for a in run.arrows)
    lengths = [np.linalg.norm(a[0, 1] - a[0, 0]) for a in run.arrows]
    assert max(lengths) == pytest.approx(ARROW * run.half)      # the peak force's length
    assert len(view_data(run, "t", 1.0, 30, 10)["arrows"]) == 5
    assert prepare(res, res.t).arrows == []                      # not asked: none
    out = tmp_path / "rest.html"
    n = res.animate(str(out), contact_forces=True)
    import json
    import re
    page = json.loads(re.search(r'id="mbdyn-data">(.*?)</script>', out.read_text(),
                                re.DOTALL).group(1))
    assert len(page["arrows"]) == n and all(len(a) == 6 for a in page["arrows"])
