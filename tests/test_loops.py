"""Closed kinematic loops (issue 24): constraint equations against finite differences,
assembly and kinematics against Freudenstein's equation and the slider-crank's exact
formulas, the drive torque by a power balance, Jourdain with multipliers against
Newton-Euler with reaction unknowns, redundant constraints, drift and energy over long
runs, and the errors a user meets."""
from __future__ import annotations

import warnings

import numpy as np
import pytest

import mbdyn as mb
from loop_mechanisms import four_bar, four_bar_rates, freudenstein, piston, slider_crank


def wrap(x):
    return (x + np.pi) % (2 * np.pi) - np.pi


@pytest.fixture(scope="module")
def driven_four_bar():
    return four_bar(drive=2.0 * mb.t + 0.3)


@pytest.fixture(scope="module")
def free_four_bar():
    return four_bar()


# ------------------------------------------------------------- equations and Jacobians
def test_constraint_jacobian_and_gamma_by_finite_differences(free_four_bar):
    m = free_four_bar
    q, u = m.assemble({"th2": 0.7}, {"th2": 1.3}, guess={"th3": 0.5, "th4": 1.5})
    rng = np.random.default_rng(1)
    qx = q + rng.normal(scale=0.1, size=3)           # off the manifold: G is still exact
    ux = rng.normal(size=3)
    G = m.constraint_jacobian(qx)
    h = 1e-6
    for k in range(3):
        dq = np.zeros(3)
        dq[k] = h
        fd = (m.constraint_residuals(qx + dq)[0] - m.constraint_residuals(qx - dq)[0]) / (2 * h)
        np.testing.assert_allclose(fd, G[:, k], atol=1e-8)
    psi = m.constraint_residuals(qx, ux)[1]
    np.testing.assert_allclose(psi, G @ ux, atol=1e-13)
    # gamma: d psi / dt along (q' = u, u' = ud) equals G ud - gamma, for any ud
    ud = rng.normal(size=3)
    m.constraint_residuals(qx, ux)
    gamma = m._con[5].copy()
    fd = (m.constraint_residuals(qx + h * ux, ux + h * ud)[1]
          - m.constraint_residuals(qx - h * ux, ux - h * ud)[1]) / (2 * h)
    np.testing.assert_allclose(fd, G @ ud - gamma, atol=1e-7)


def test_redundant_planar_loop_rank_and_mobility(free_four_bar):
    m = free_four_bar
    q, _ = m.assemble({"th2": 0.7}, guess={"th3": 0.5, "th4": 1.5})
    assert len(m.constraint_rows) == 5
    assert m.constraint_rank(q)[0] == 2
    assert m.mobility(q) == 1
    unique = m.reaction_uniqueness(q)
    for joint in ("th2", "th3", "th4", "D"):      # in-plane forces and the z moment only
        assert unique[joint].tolist() == [True, True, False, False, False, True]


# ------------------------------------------------------------- assembly and kinematics
@pytest.mark.parametrize("branch", [+1, -1])
def test_four_bar_kinematics_against_freudenstein(driven_four_bar, branch):
    """Positions, rates and accelerations over a full crank turn, both assembly branches;
    the crank is driven, so the mechanism's mobility is 0 (a kinematic analysis)."""
    m = driven_four_bar
    t_values = np.linspace(0.0, np.pi, 13)            # th2 = 2 t + 0.3: a full turn
    worst = 0.0
    for t in t_values:
        th2 = 2.0 * t + 0.3
        th4, th3a = freudenstein(th2, branch)
        # a rough guess (0.2 rad off) picks the branch
        q, u = m.assemble(guess={"th3": wrap(th3a - th2) + 0.2, "th4": th4 - 0.2}, t=t)
        assert m.mobility(q, t) == 0
        i3, i4 = m.coordinate_index("th3"), m.coordinate_index("th4")
        w3, w4, al3, al4 = four_bar_rates(th2, 2.0, 0.0, th3a, th4)
        ud = m.forward_dynamics(q, u, t)
        got = np.array([wrap(q[i3] + th2 - th3a), wrap(q[i4] - th4), u[i3] + 2.0 - w3,
                        u[i4] - w4, ud[i3] - al3, ud[i4] - al4])
        worst = max(worst, np.abs(got).max())
    assert worst < 1e-9


def test_slider_crank_against_exact_formulas():
    m = slider_crank(drive=3.0 * mb.t + 0.2)
    ix = m.coordinate_index("x")
    for t in np.linspace(0, 2.0, 9):
        th = 3.0 * t + 0.2
        x, v, a = piston(th, 3.0, 0.0)
        q, u = m.assemble(guess={"x": x + 0.01, "phi": -np.arcsin((0.05 * np.sin(th) - 0.01)
                                                                  / 0.2) - th}, t=t)
        ud = m.forward_dynamics(q, u, t)
        assert abs(q[ix] - x) < 1e-9 and abs(u[ix] - v) < 1e-9 and abs(ud[ix] - a) < 1e-8


def test_drive_torque_by_power_balance(driven_four_bar):
    """tau * w = d(T + V)/dt, the right side from the bodies' velocities and
    accelerations (``Model.kinematics``), not from the reactions."""
    m = driven_four_bar
    for t in (0.0, 0.4, 1.1, 2.5):
        th2 = 2.0 * t + 0.3
        th4, th3a = freudenstein(th2, +1)
        q, u = m.assemble(guess={"th3": wrap(th3a - th2), "th4": th4}, t=t)
        ud = m.forward_dynamics(q, u, t)
        tau = m.drive_efforts(q, u, t)["th2"]
        kin = m.kinematics(q, u, ud, t)
        power = 0.0
        for i, name in enumerate(m.frames):
            body = m.body(name)
            Iw = kin.R[i] @ body.inertia @ kin.R[i].T
            power += body.mass * kin.v_com[i] @ (kin.a_com[i] - m.gravity)
            power += kin.w[i] @ (Iw @ kin.alpha[i])
        assert abs(tau * 2.0 - power) < 1e-9 * (1 + abs(power))


# ------------------------------------------------------------- the two formulations
def test_newton_euler_with_reactions_agrees_with_jourdain(driven_four_bar, free_four_bar):
    for m, t in ((driven_four_bar, 0.0), (free_four_bar, 0.0)):
        q, u = m.assemble(guess={"th3": 0.5, "th4": 1.5}, t=t,
                          **({} if m.driven_joints else {"initial": {"th2": 0.9},
                                                         "initial_speeds": {"th2": -1.5}}))
        a = m.forward_dynamics(q, u, t)
        b = m.forward_dynamics(q, u, t, method="newton-euler")
        assert np.abs(a - b).max() < 1e-10 * (1 + np.abs(a).max())
        r1 = m.reactions(q, u, t)
        r2 = m.reactions(q, u, t, method="newton-euler")
        unique = m.reaction_uniqueness(q, t)
        for joint in m.reaction_joints:
            d = np.concatenate(r1[joint]) - np.concatenate(r2[joint])
            assert np.abs(d[unique[joint]]).max() < 1e-10 * (1 + np.abs(np.concatenate(
                r1[joint])).max())


@pytest.mark.parametrize("closer", ["spherical", "cylindrical", "universal"])
def test_same_loop_closed_by_other_joints_moves_the_same(free_four_bar, closer):
    """A planar loop closed by a revolute (5 equations, rank 2) and by other kinds whose
    equations hold the same planar motion: the same accelerations."""
    other = four_bar(closer=closer)
    q, u = free_four_bar.assemble({"th2": 0.9}, {"th2": -1.5}, guess={"th3": 0.5, "th4": 1.5})
    a = free_four_bar.forward_dynamics(q, u)
    b = other.forward_dynamics(q, u)
    np.testing.assert_allclose(a, b, atol=1e-11)
    assert other.mobility(q) == 1


# ------------------------------------------------------------- runs
def test_free_four_bar_conserves_energy_and_stays_closed(free_four_bar):
    m = free_four_bar
    q, u = m.assemble({"th2": 0.9}, {"th2": -4.0}, guess={"th3": 0.5, "th4": 1.5})
    with warnings.catch_warnings():
        warnings.simplefilter("error", mb.SingularityWarning)
        res = mb.simulate(m, 10.0, q, u, rtol=1e-11, atol=1e-13, outputs=("energy",))
    assert res.stats["constraint_drift"] <= 1e-10
    assert res.stats["constraint_drift_velocity"] <= 1e-10
    assert res.stats["energy_drift"] < 1e-8
    assert res.stats["mobility"] == 1


@pytest.mark.parametrize("integrator,kw", [("RK45", {}), ("rk4", {"dt": 2e-4}),
                                           ("semi-implicit-euler", {"dt": 1e-4})])
def test_every_integrator_stays_on_the_constraints(free_four_bar, integrator, kw):
    m = free_four_bar
    q, u = m.assemble({"th2": 0.9}, {"th2": -4.0}, guess={"th3": 0.5, "th4": 1.5})
    res = mb.simulate(m, 1.0, q, u, integrator=integrator, **kw)
    assert res.stats["constraint_drift"] <= 1e-10
    assert res.stats["constraint_drift_velocity"] <= 1e-10


def test_python_fixed_step_loop_projects_like_the_compiled_loop(free_four_bar):
    """A fixed-step run stepped in Python (``compiled_loop=False``, as models with Python-
    function loads are) projects every step onto the constraints as the compiled loop
    does: the same motion, and no drift before the samples' own projection."""
    m = free_four_bar
    q, u = m.assemble({"th2": 0.9}, {"th2": -4.0}, guess={"th3": 0.5, "th4": 1.5})
    t_eval = np.linspace(0.0, 0.5, 11)
    runs = [mb.simulate(m, 0.5, q, u, integrator="rk4", dt=1e-3, t_eval=t_eval,
                        compiled_loop=flag) for flag in (True, False)]
    for res in runs:
        assert res.stats["constraint_drift_unprojected"] <= 1e-10
    assert np.abs(runs[0].q - runs[1].q).max() < 1e-9
    assert np.abs(runs[0].u - runs[1].u).max() < 1e-8


# ------------------------------------------------------------- errors
def test_inconsistent_given_values_name_the_loop(free_four_bar):
    with pytest.raises(mb.ModelError, match="joint 'D'.*residual"):
        free_four_bar.assemble({"th2": 0.3, "th3": 0.1, "th4": 0.2})


def test_unreachable_assembly_is_refused():
    # a = 0.2, b = 0.1, c = 0.15, d = 0.3 fails Grashof's condition: at th2 = pi the crank
    # pin is 0.5 from the rocker's pivot, beyond the reach b + c = 0.25
    m = four_bar(a=0.2, b=0.1, c=0.15, d=0.3)
    with pytest.raises(mb.ModelError, match="joint 'D' cannot be assembled"):
        m.assemble({"th2": np.pi}, guess={"th3": 0.3, "th4": 2.0})


def test_inconsistent_initial_state_in_simulate_points_to_assemble(free_four_bar):
    with pytest.raises(mb.ModelError, match="assemble"):
        mb.simulate(free_four_bar, 0.1, {"th2": 0.3, "th3": 0.1, "th4": 0.2})


def test_loop_joint_errors():
    s = four_bar(compile_=False)
    with pytest.raises(mb.ModelError, match="parent and child are both"):
        s.add_joint("E", "revolute", "coupler", "coupler", axis="z", child_position=(0, 0, 0))
    with pytest.raises(mb.ModelError, match="unknown child body 'nothing'"):
        s.add_joint("E", "spherical", "coupler", "nothing", child_position=(0, 0, 0))
    with pytest.raises(mb.ModelError, match="give this joint child_position"):
        s.add_joint("E", "revolute", "crank", "rocker", axis="z")
    with pytest.raises(mb.ModelError, match="needs child_position"):
        s.add_joint("E", "revolute", "crank", "rocker", axis="z", cut=True)
    with pytest.raises(mb.ModelError, match="cannot close a loop"):
        s.add_joint("E", "free", "crank", "rocker", child_position=(0, 0, 0))
    t = mb.System("only loops")
    t.add_body("a", mass=1.0, inertia=(1, 1, 1))
    t.add_joint("j", "spherical", "ground", "a", child_position=(0, 0, 0))
    with pytest.raises(mb.ModelError, match="hangs from no tree joint"):
        t.compile()


# ------------------------------------------------------------- distance and coupling
def test_distance_constraint_is_a_spherical_pendulum():
    """A free body held by a massless rod to the ground moves as the same body on a
    spherical joint at the rod's end point... with the rod's point on the body."""
    L = 0.8
    s = mb.System("rod pendulum")
    s.add_body("bob", mass=2.0, inertia=(0.01, 0.02, 0.03))
    s.add_joint("float", "free", "ground", "bob")
    s.add_joint("rod", "distance", "ground", "bob", position=(0, 0, 0),
                child_position=(0, 0, 0), length=L)
    m = s.compile()
    q, u = m.assemble({"float_x": L * np.sin(0.4), "float_y": 0.0,
                       "float_z": -L * np.cos(0.4)}, {"float_vy": 1.2, "float_vx": 0.0,
                                                       "float_vz": 0.0})
    res = mb.simulate(m, 2.0, q, u, rtol=1e-10, atol=1e-12, outputs=("energy",))
    assert res.stats["energy_drift"] < 1e-8
    assert res.stats["constraint_drift"] <= 1e-10
    xyz = res.q[:, :3]
    np.testing.assert_allclose(np.linalg.norm(xyz, axis=1), L, atol=1e-10)


def test_coupling_gears_two_wheels():
    s = mb.System("gears", gravity=(0, 0, 0))
    s.add_body("w1", mass=1.0, inertia=(0.1, 0.1, 0.2))
    s.add_body("w2", mass=1.0, inertia=(0.1, 0.1, 0.05))
    s.add_joint("a", "revolute", "ground", "w1", axis="z")
    s.add_joint("b", "revolute", "ground", "w2", axis="z", position=(1, 0, 0))
    s.add_joint("mesh", "coupling", follower="b", leader="a", ratio=-2.0, offset=0.0)
    s.add_load("torque", "w1", moment=(0, 0, 1.0))
    m = s.compile()
    q, u = m.assemble({"a": 0.0}, {"a": 0.0})
    ud = m.forward_dynamics(q, u)
    # one degree of freedom a: (I1 + 4 I2) a'' = tau
    ia, ib = m.speed_index("a_dot"), m.speed_index("b_dot")
    assert abs(ud[ia] - 1.0 / (0.2 + 4 * 0.05)) < 1e-12
    assert abs(ud[ib] + 2 * ud[ia]) < 1e-12


def test_four_bar_model_file(tmp_path):
    text = """
[model]
name = "fb"
gravity = [0, -9.81, 0]
[[bodies]]
name = "crank"
mass = 1.0
com = [0.05, 0, 0]
inertia = [1e-4, 8.3e-4, 9.3e-4]
[[bodies]]
name = "coupler"
mass = 2.0
com = [0.15, 0, 0]
inertia = [1e-4, 0.015, 0.0151]
[[bodies]]
name = "rocker"
mass = 1.5
com = [0.125, 0, 0]
inertia = [1e-4, 0.0078, 0.0079]
[[joints]]
name = "th2"
kind = "revolute"
child = "crank"
axis = "z"
[[joints]]
name = "th3"
kind = "revolute"
parent = "crank"
child = "coupler"
axis = "z"
position = [0.1, 0, 0]
[[joints]]
name = "th4"
kind = "revolute"
child = "rocker"
axis = "z"
position = [0.3, 0, 0]
[[joints]]
name = "D"
kind = "revolute"
parent = "coupler"
child = "rocker"
axis = "z"
position = [0.3, 0, 0]
child_position = [0.25, 0, 0]
[initial]
th2 = 0.7
[initial_speeds]
th2 = 1.0
[guess]
th3 = -1.5
th4 = -1.2
[simulation]
t_end = 0.5
[outputs]
reactions = true
"""
    path = tmp_path / "fb.toml"
    path.write_text(text)
    scene = mb.load_model(str(path))
    th4, th3a = freudenstein(0.7, +1)      # the "elbow-down" branch the guess points to
    assert abs(wrap(scene.q0[scene.model.coordinate_index("th4")] - th4)) < 1e-9
    res = scene.simulate()
    assert set(res.reactions) == {"th2", "th3", "th4", "D"}
    assert res.stats["reactions_not_unique"]["D"] == ["Fz", "Mx", "My"]
    bad = path.with_name("bad.toml")
    bad.write_text(text.replace("th3 = -1.5\n", "th3 = -1.5\nth2 = 1\n"))
    with pytest.raises(mb.ModelError, match="guess"):
        mb.load_model(str(bad))



def test_parallelogram_passing_its_singular_configuration_is_reported():
    """A parallelogram four-bar (a = c, b = d) turning through th2 = pi, where its links
    lie in line and its mobility jumps: the run names the passage and its time, and goes
    on along the parallelogram branch (the rocker follows the crank)."""
    m = four_bar(a=0.1, b=0.3, c=0.1, d=0.3, g=0.0)
    q, u = m.assemble({"th2": 2.0}, {"th2": 3.0}, guess={"th3": -2.0, "th4": 2.0})
    with pytest.warns(mb.SingularityWarning, match="singular configuration near t="):
        res = mb.simulate(m, 0.8, q, u, t_eval=np.linspace(0, 0.8, 81))
    passage = res.stats["singular_configuration"]["t"]
    th2 = res.q[:, m.coordinate_index("th2")]
    t_pi = np.interp(np.pi, th2, res.t)
    assert abs(passage - t_pi) <= 0.011       # the nearest sample to the passage
    np.testing.assert_allclose(res.q[:, m.coordinate_index("th4")], th2, atol=1e-8)


def test_sweeps_of_a_closed_mechanism_batched_and_serial_agree():
    """A batched sweep (one compiled call, members in parallel) runs the same projected
    steps as single runs."""
    from mbdyn.analysis.sweep import sweep
    finals = {}
    for batched in (False, True):
        res = sweep("models/four_bar.toml", {"initial.crank": [0.0, 0.5]}, cases=["free"],
                    fixed={"simulation.t_end": 0.2, "simulation.integrator": "rk4",
                           "simulation.dt": 1e-3}, batched=batched)
        finals[batched] = np.array([[v for k, v in row.items() if k.startswith("final.")]
                                    for row in res.rows], float)
    assert finals[True].shape[0] == 2 and finals[True].shape[1] >= 4
    np.testing.assert_allclose(finals[True], finals[False], atol=1e-13)


def test_force_elements_effects_and_events_on_a_closed_mechanism():
    """A spring-damper across the loop, switched off as an effect, and a terminal event on
    the rocker's angle: each works as on a tree, and the energy balance holds."""
    s = four_bar(compile_=False)
    s.add_force("spring", "spring-damper", body_a="coupler", point_a=(0.15, 0, 0),
                body_b="ground", point_b=(0.2, 0.3, 0), stiffness=200.0, free_length=0.2,
                damping=0.5)
    m = s.compile()
    q, u = m.assemble({"th2": 0.9}, {"th2": -4.0}, guess={"th3": 0.5, "th4": 1.5})
    # the dissipated energy is integrated over the samples (Simpson): sample densely
    res = mb.simulate(m, 2.0, q, u, rtol=1e-11, atol=1e-13, outputs=("energy",),
                      t_eval=np.linspace(0, 2, 4001))
    assert res.stats["energy_drift"] < 1e-7 and res.energy["dissipated"][-1] > 0
    off = s.compile(effects="-spring")
    assert off.forces == ()
    stop = mb.Event("rocker_up", "th4 >= 2.0", terminal=True)
    res = mb.simulate(m, 2.0, q, u, events=[stop])    # the rocker swings 1.52 .. 2.42
    assert len(res.events) == 1 and res.events[0][1] == res.t[-1] < 2.0
    assert abs(res.q[-1, m.coordinate_index("th4")] - 2.0) < 1e-8
    assert res.stats["constraint_drift"] <= 1e-10


HOOKE_BETA = 0.5        # rad between the input and output shafts


def _hooke(tree_universal):
    """Hooke's (Cardan) joint: input shaft along x (driven), output shaft along
    d = (cos b, sin b, 0); the cross joins the input yoke's arm y to the output yoke's arm
    z.  Closed by a universal loop joint between the shafts, or (``tree_universal``) the
    output shaft hung on a universal tree joint and closed by its bearing, a revolute about
    d to the ground."""
    d = (np.cos(HOOKE_BETA), np.sin(HOOKE_BETA), 0.0)
    s = mb.System("hooke", gravity=(0, 0, 0))
    s.add_body("A", mass=1.0, inertia=(0.01, 0.02, 0.02))
    s.add_body("B", mass=1.0, inertia=(0.01, 0.02, 0.02))
    s.add_joint("input", "revolute", "ground", "A", axis="x", drive=1.0 * mb.t)
    if tree_universal:
        s.add_joint("cross", "universal", "A", "B", axis="y", axis2="z")
        s.add_joint("bearing", "revolute", "ground", "B", axis=d, child_position=(0, 0, 0))
    else:
        s.add_joint("out", "revolute", "ground", "B", axis=d)
        s.add_joint("cross", "universal", "A", "B", axis="y", axis2="z",
                    child_position=(0, 0, 0))
    return s.compile()


@pytest.mark.parametrize("tree_universal", [False, True])
def test_hookes_joint_against_its_closed_form(tree_universal):
    """tan th2 = tan th1 / cos b (the input yoke's arm in the shafts' plane at th1 = 0):
    a universal joint closing the loop, and a universal tree joint, both give it; the
    output's rate is th1' cos b / (cos^2 b cos^2 th1 + sin^2 th1)."""
    m = _hooke(tree_universal)
    d = np.array([np.cos(HOOKE_BETA), np.sin(HOOKE_BETA), 0.0])
    cb = np.cos(HOOKE_BETA)
    for t in np.linspace(0.05, 3.0, 7):
        th2 = np.arctan2(np.sin(t), np.cos(t) * cb)
        guess = ({"cross_1": 0.0, "cross_2": 0.0} if tree_universal else {"out": th2 + 0.1})
        q, u = m.assemble(guess=guess, t=t)
        assert m.mobility(q, t) == 0
        kin = m.kinematics(q, u, t=t)
        iB = m.frame_index("B")
        arm = kin.R[iB][:, 2]                          # the output yoke's arm, world
        expected = np.cos(th2) * np.array([0, 0, 1.0]) + np.sin(th2) * np.cross(d, [0, 0, 1])
        if not tree_universal:
            assert abs(wrap(q[m.coordinate_index("out")] - th2)) < 1e-10
        np.testing.assert_allclose(arm, expected, atol=1e-10)
        rate = cb / (cb ** 2 * np.cos(t) ** 2 + np.sin(t) ** 2)
        assert abs(kin.w[iB] @ d - rate) < 1e-10


def test_tree_universal_and_cylindrical_are_two_joints_through_a_cross():
    s = mb.System("parts")
    s.add_body("b", mass=1.0, inertia=(1, 1, 1))
    s.add_body("c", mass=1.0, inertia=(1, 1, 1))
    s.add_joint("u", "universal", "ground", "b", axis="z", axis2="x")
    s.add_joint("cy", "cylindrical", "b", "c", axis="y", position=(0, 0, -1))
    m = s.compile()
    assert m.coordinates == ("u_1", "u_2", "cy_slide", "cy_turn")
    assert "u.cross" in m.frames
    with pytest.raises(mb.ModelError, match="not perpendicular"):
        s.add_joint("bad", "universal", "c", "ground", axis="z", axis2=(1, 0, 1))


def test_run_solve_on_the_chosen_rows_equals_the_svd_solve():
    """During a run the accelerations are solved on the rows the last projection chose
    (``kernels.constrained._chosen_rows_solve``: ``S`` of the rank's size, no pivoting);
    they equal the minimum-norm SVD solve's.  Rows that no longer span the constraints
    (a zero row chosen) fail its pivot test and the solve pivots again."""
    from mbdyn.kernels.loop_solve import ROWS
    for path in ("models/andrews_squeezer.toml", "models/four_bar.toml"):
        scene = mb.load_model(path)
        m = scene.model
        q, u = scene.q0.copy(), scene.u0.copy()
        reference = m.forward_dynamics(q, u)              # rank by the SVD, minimum norm
        info = m._con[7]
        rank = m.constraint_rank(q)[0]
        try:
            info[2] = rank                                # as a run holds it
            m.project(q, u)                               # chooses the rows
            assert info[ROWS] == rank and rank < len(m.constraint_rows)
            fast = m.forward_dynamics(q, u)
            assert np.abs(fast - reference).max() <= 1e-12 * np.abs(reference).max()
            G = m.constraint_jacobian(q)
            zero = [k for k in range(G.shape[0]) if not G[k].any()]
            if zero:                                      # a planar loop's out-of-plane row
                info[ROWS + 1] = zero[0]
                again = m.forward_dynamics(q, u)
                assert np.abs(again - reference).max() <= 1e-12 * np.abs(reference).max()
        finally:
            info[2] = info[ROWS] = -1.0
