"""Simulation: energy conservation, the two heavy tops, every integrator's convergence and
order, events against the pendulum's exact solution, failures with partial results, and
quaternion bookkeeping.

Expectations come from outside the engine: the simple pendulum's exact solution (Jacobi
elliptic functions), energies computed here from the kinematics, the analytic blow-up of
``u' = u^2``, and rotation matrices written by hand.
"""
import inspect
import re

import numpy as np
import pytest
from scipy import integrate, special

import mbdyn as mb
from random_trees import (axis_rotation, energy_of, matrix_to_quat, quat_to_matrix,
                          random_rotation, random_tree)

G = 9.81


# ----------------------------------------------------------------------------- the pendulum
L = 0.8
THETA0 = 1.0
W0 = np.sqrt(G / L)
K_MOD = np.sin(THETA0 / 2)
QUARTER = special.ellipk(K_MOD**2) / W0          # time from rest to the vertical


def exact_theta(t):
    """Simple pendulum released from rest at THETA0: 2 asin(k sn(K - w0 t | k^2))."""
    sn, cn, dn, ph = special.ellipj(special.ellipk(K_MOD**2) - W0 * np.asarray(t), K_MOD**2)
    return 2 * np.arcsin(K_MOD * sn)


def time_of_angle(theta):
    """First time after release at which the angle is ``theta`` (|theta| <= THETA0), on the
    way down: sn(K - w0 t) = sin(theta/2)/k."""
    phi = np.arcsin(np.sin(theta / 2) / K_MOD)
    return (special.ellipk(K_MOD**2) - special.ellipkinc(phi, K_MOD**2)) / W0


@pytest.fixture(scope="module")
def pendulum():
    s = mb.System("pendulum")
    s.add_body("bob", mass=1.3, com=(0, 0, -L))            # a particle
    s.add_joint("theta", "revolute", "ground", "bob", axis="x")
    return s.compile()


def test_exact_solution_is_right():
    """The reference itself: the ODE theta'' = -(g/l) sin theta, by scipy at tight tolerance."""
    sol = integrate.solve_ivp(lambda t, y: [y[1], -W0**2 * np.sin(y[0])], (0, 2),
                              [THETA0, 0.0], rtol=1e-12, atol=1e-12, dense_output=True)
    ts = np.linspace(0, 2, 9)
    assert np.allclose(sol.sol(ts)[0], exact_theta(ts), atol=1e-9)
    assert abs(exact_theta(QUARTER)) < 1e-12


ORDERS = {"euler": 1, "semi-implicit-euler": 1, "rk4": 4, "implicit-midpoint": 2}


@pytest.mark.parametrize("integrator", mb.INTEGRATORS)
def test_every_integrator_runs_and_converges(pendulum, integrator):
    t_end = 1.0
    if integrator in mb.FIXED_STEP:
        errors = []
        dts = (0.01, 0.005, 0.0025)
        for dt in dts:
            res = mb.simulate(pendulum, t_end, {"theta": THETA0}, integrator=integrator, dt=dt)
            assert res.stats["status"] == "ok"
            assert np.isclose(res.t[-1], t_end) and len(res.t) == round(t_end / dt) + 1
            assert np.allclose(np.diff(res.t), dt)
            errors.append(np.abs(res["theta"] - exact_theta(res.t)).max())
        orders = np.log2(np.array(errors[:-1]) / np.array(errors[1:]))
        if integrator in ORDERS:
            p = ORDERS[integrator]
            assert np.all(np.abs(orders - p) < 0.25), (integrator, errors, orders)
        else:
            assert np.all(orders > 0.8), (integrator, errors, orders)
        assert errors[-1] < 0.05
    else:
        rtol = 1e-8 if integrator == "RK23" else 1e-10       # RK23 is slow at 1e-10
        res = mb.simulate(pendulum, t_end, {"theta": THETA0}, integrator=integrator,
                          rtol=rtol, atol=1e-12)
        assert res.stats["status"] == "ok" and res.t[-1] == t_end
        err = np.abs(res["theta"] - exact_theta(res.t)).max()
        assert err < 1e-6, (integrator, err)
        # a looser tolerance is less accurate: the solver really adapts
        loose = mb.simulate(pendulum, t_end, {"theta": THETA0}, integrator=integrator,
                            rtol=1e-4, atol=1e-6)
        assert loose.stats["steps"] < res.stats["steps"]
    assert res.stats["rhs_evaluations"] > 0


def test_fixed_step_compiled_and_python_loops_agree(pendulum):
    if "compiled_loop" not in inspect.signature(mb.simulate).parameters:
        pytest.skip("no compiled fixed-step loop")
    for integrator in mb.FIXED_STEP:
        a = mb.simulate(pendulum, 0.5, {"theta": THETA0}, integrator=integrator, dt=0.01)
        b = mb.simulate(pendulum, 0.5, {"theta": THETA0}, integrator=integrator, dt=0.01,
                        compiled_loop=False)
        assert np.allclose(a.t, b.t, rtol=0, atol=1e-14)
        assert np.abs(a.q - b.q).max() < 1e-12 and np.abs(a.u - b.u).max() < 1e-12, integrator


def test_semi_implicit_euler_is_the_textbook_scheme(pendulum):
    """Velocities first, then positions with the new velocities -- written out here."""
    dt, n = 0.01, 50
    th, om = THETA0, 0.0
    for _ in range(n):
        om = om - dt * W0**2 * np.sin(th)
        th = th + dt * om
    res = mb.simulate(pendulum, n * dt, {"theta": THETA0}, integrator="semi-implicit-euler",
                      dt=dt)
    assert abs(res["theta"][-1] - th) < 1e-12 and abs(res["theta_dot"][-1] - om) < 1e-12


# ----------------------------------------------------------------------------- events
def test_events_located_accurately(pendulum):
    down = mb.Event("down", lambda t, q, u: q[0], direction=-1)
    up = mb.Event("up", lambda t, q, u: q[0], direction=+1)
    either = mb.Event("either", lambda t, q, u: q[0])
    t_end = 4.5 * QUARTER                        # crossings at QUARTER (down), 3 QUARTER (up)
    res = mb.simulate(pendulum, t_end, {"theta": THETA0}, integrator="DOP853", rtol=1e-12,
                      atol=1e-12, events=[down, up, either])
    assert res.t[-1] == t_end                    # non-terminal: runs to the end
    got = {}
    for name, te in res.events:
        got.setdefault(name, []).append(te)
    assert set(got) == {"down", "up", "either"}
    assert np.allclose(got["down"], [QUARTER], atol=1e-9), got["down"]
    assert np.allclose(got["up"], [3 * QUARTER], atol=1e-9), got["up"]
    assert np.allclose(got["either"], [QUARTER, 3 * QUARTER], atol=1e-9), got["either"]
    times = [te for _, te in res.events]
    assert times == sorted(times)


@pytest.mark.parametrize("integrator", ["RK45", "DOP853", "Radau"])
def test_terminal_event_stops_the_run(pendulum, integrator):
    target = -THETA0 / 2
    stop = mb.Event("half way up", lambda t, q, u: q[0] - target, terminal=True, direction=-1)
    res = mb.simulate(pendulum, 5.0, {"theta": THETA0}, integrator=integrator, rtol=1e-11,
                      atol=1e-12, events=[stop])
    te = time_of_angle(target)
    assert len(res.events) == 1 and res.events[0][0] == "half way up"
    assert abs(res.events[0][1] - te) < 1e-7, (res.events, te)
    assert res.t[-1] == res.events[0][1]
    assert abs(res["theta"][-1] - target) < 1e-7
    assert res["theta_dot"][-1] < 0


def test_fixed_step_events_are_found_roughly(pendulum):
    stop = mb.Event("vertical", lambda t, q, u: q[0], terminal=True, direction=-1)
    res = mb.simulate(pendulum, 2.0, {"theta": THETA0}, integrator="rk4", dt=1e-3,
                      events=[stop])
    assert res.events[0][0] == "vertical"
    assert abs(res.events[0][1] - QUARTER) < 1e-5
    assert res.t[-1] < QUARTER + 2e-3


@pytest.mark.parametrize("integrator", ["rk4", "semi-implicit-euler"])
def test_fixed_step_events_interpolate_between_the_steps_that_bracket_them(pendulum,
                                                                          integrator):
    """Events of a fixed-step run are found on whole stretches of steps at once; each must
    be where a step-by-step pass puts it: the linear interpolation of its condition between
    the two steps that bracket the crossing, in time order, the run ending at the row of
    the first terminal one."""
    either = mb.Event("either", lambda t, q, u: q[0])
    slow = mb.Event("slow", lambda t, q, u: abs(u[0]) - 1.0)
    target = -THETA0 / 2
    half = mb.Event("half way up", lambda t, q, u: q[0] - target, direction=-1)
    late = mb.Event("late", lambda t, q, u: t - 2.3451, terminal=True)
    dt = 2e-3
    res = mb.simulate(pendulum, 8.0, {"theta": THETA0}, integrator=integrator, dt=dt,
                      events=[either, slow, half, late])
    t, th, om = res.t, res["theta"], res["theta_dot"]
    assert np.allclose(np.diff(t), dt)                    # every step is a sample
    expected = []
    for name, g in (("either", th), ("slow", np.abs(om) - 1.0), ("half way up", th - target),
                    ("late", t - 2.3451)):
        for k in np.flatnonzero((g[:-1] != 0) & (np.sign(g[:-1]) != np.sign(g[1:]))):
            if name == "half way up" and g[k] < 0:
                continue                                  # direction -1 only
            expected.append((t[k] + (t[k + 1] - t[k]) * g[k] / (g[k] - g[k + 1]), name))
    expected.sort()
    assert [n for n, _ in res.events] == [n for _, n in expected]
    assert np.allclose([te for _, te in res.events], [te for te, _ in expected],
                       rtol=0, atol=1e-14)
    assert res.events[-1][0] == "late" and t[-2] < res.events[-1][1] <= t[-1]
    assert len(res.events) >= 8                           # several in one stretch


def test_a_fixed_step_event_that_turns_non_finite_names_itself_and_keeps_the_steps(pendulum):
    bad = mb.Event("log", lambda t, q, u: np.log(q[0] + 0.5))
    with pytest.raises(mb.SimulationError, match="event 'log': the condition is not a finite") \
            as info:
        mb.simulate(pendulum, 3.0, {"theta": THETA0}, integrator="rk4", dt=1e-3, events=[bad])
    kept = info.value.result
    assert np.all(kept.q[:, 0] + 0.5 > 0)                 # every kept step was finite
    assert kept.q[-1, 0] + 0.5 < 0.01                     # and the next one was not


# ----------------------------------------------------------------------------- failures
def test_nan_in_a_load_names_the_load_and_the_time():
    s = mb.System("pendulum with a bad load")
    s.add_body("bob", mass=1.3, com=(0, 0, -L))
    s.add_joint("theta", "revolute", "ground", "bob", axis="x")
    t_bad = 0.3
    s.add_load("gust", "bob", force=lambda t, q, u: (np.nan if t > t_bad else 0.0, 0.1, 0.0))
    m = s.compile()
    for integrator, kw in (("RK45", {}), ("DOP853", {}), ("Radau", {}), ("rk4", {"dt": 0.01})):
        with pytest.raises(mb.SimulationError) as info:
            mb.simulate(m, 1.0, {"theta": THETA0}, integrator=integrator, **kw)
        exc = info.value
        msg = str(exc)
        assert "'gust'" in msg, msg
        # the first time in the message is where the load went bad: just after t_bad
        times = [float(x) for x in re.findall(r"t=([-+0-9.eE]+\d)", msg)]
        assert times and t_bad < times[0] < t_bad + 0.1, (integrator, msg)
        res = exc.result
        assert res is not None and len(res.t) > 2, integrator
        assert res.stats.get("status") == "failed"
        assert 0.1 < res.t[-1] <= t_bad + 1e-12, (integrator, res.t[-1])
        assert res.t[-1] <= times[0]
        assert np.all(np.isfinite(res.q)) and np.all(np.isfinite(res.u))


@pytest.mark.filterwarnings("ignore:overflow:RuntimeWarning")
def test_blow_up_gives_simulation_error_with_partial_results():
    """u' = u^2 (a load m u^2 on a slider), u(0) = 1: u = 1/(1 - t), x = -ln(1 - t),
    which no integrator can follow past t = 1: the adaptive step collapses."""
    s = mb.System("blow-up", gravity=(0, 0, 0))
    s.add_body("slider", mass=2.0)
    s.add_joint("x", "prismatic", "ground", "slider", axis="x")
    s.add_load("push", "slider", force=lambda t, q, u: (2.0 * u[0] ** 2, 0, 0))
    m = s.compile()
    with pytest.raises(mb.SimulationError) as info:
        mb.simulate(m, 2.0, u0={"x_dot": 1.0}, integrator="RK45", rtol=1e-8, atol=1e-10)
    assert "RK45" in str(info.value)
    res = info.value.result
    assert res is not None and res.stats["status"] == "failed"
    assert 0.99 < res.t[-1] < 1.0 + 1e-6
    ok = res.t < 0.99
    assert ok.sum() > 10
    assert np.allclose(res["x"][ok], -np.log(1 - res.t[ok]), rtol=1e-5)
    assert np.allclose(res["x_dot"][ok], 1 / (1 - res.t[ok]), rtol=1e-5)
    # fixed step: explicit Euler runs into inf; the finite steps before it are kept
    with pytest.raises(mb.SimulationError) as info:
        mb.simulate(m, 100.0, u0={"x_dot": 1.0}, integrator="euler", dt=0.1)
    res = info.value.result
    assert len(res.t) > 3 and np.all(np.isfinite(res.u))
    u_euler = [1.0]
    for _ in range(len(res.t) - 1):                 # u_{k+1} = u_k + dt u_k^2
        u_euler.append(u_euler[-1] + 0.1 * u_euler[-1] ** 2)
    assert np.allclose(res["x_dot"], u_euler, rtol=1e-12)


def test_singular_force_makes_an_adaptive_solver_fail_cleanly():
    """A pull ``1/(0.5 - x)^3`` towards a wall at x = 0.5: the slider reaches it in finite
    time and RK23 cannot go on; the error says when, the result keeps the way there."""
    s = mb.System("wall", gravity=(0, 0, 0))
    s.add_body("b", mass=1.0)
    s.add_joint("x", "prismatic", "ground", "b", axis="x")
    s.add_load("pull", "b", force=lambda t, q, u: (1.0 / (0.5 - q[0]) ** 3, 0, 0))
    m = s.compile()
    with pytest.raises(mb.SimulationError) as info:
        mb.simulate(m, 10.0, integrator="RK23", rtol=1e-6, atol=1e-9)
    res = info.value.result
    assert len(res.t) > 2 and 0.4 < res["x"][-1] < 0.5
    # energy x' ^2 / 2 = 1/(2 (0.5 - x)^2) - 2: holds along the kept samples
    E = 0.5 * res["x_dot"] ** 2 - 0.5 / (0.5 - res["x"]) ** 2
    early = res["x"] < 0.45
    assert np.allclose(E[early], -2.0, rtol=1e-3)
    assert "t=" in str(info.value)


# ----------------------------------------------------------------------------- conservation
def spherical_chain(n=2):
    s = mb.System("spherical chain")
    parent = "ground"
    for k in range(n):
        s.add_body(f"b{k}", mass=1.0, com=(0.05, 0, -0.5), inertia=(0.02, 0.03, 0.01))
        s.add_joint(f"s{k}", "spherical", parent, f"b{k}", position=(0, 0, 0 if k == 0 else -1))
        parent = f"b{k}"
    return s.compile()


def own_energy_drift(model, res):
    E = np.array([sum(energy_of(model, q, u, t)) for t, q, u in zip(res.t, res.q, res.u)])
    TV = np.array([energy_of(model, q, u, t) for t, q, u in zip(res.t, res.q, res.u)])
    return np.abs(E - E[0]).max() / np.abs(TV).sum(axis=1).max()


@pytest.mark.parametrize("case", ["random tree", "spherical chain"])
def test_conservative_model_keeps_its_energy(case):
    if case == "random tree":
        tr = random_tree(302, 4, kinds=("revolute", "prismatic", "spherical", "fixed"),
                         drives=False, loads=False)
        model, q0, u0 = tr.model, tr.q, tr.u
    else:
        model = spherical_chain(2)
        rng = np.random.default_rng(7)
        q0 = np.concatenate([random_rotation(rng), random_rotation(rng)])
        u0 = rng.normal(size=6) * 0.5
    res = mb.simulate(model, 10.0, q0, u0, integrator="DOP853", rtol=1e-12, atol=1e-12,
                      t_eval=np.linspace(0, 10, 201), outputs=("energy",))
    assert res.t[-1] == 10.0
    drift = own_energy_drift(model, res)
    assert drift < 1e-9, drift
    assert res.stats["energy_drift"] < 1e-9
    assert np.allclose(res.energy["total"], res.energy["kinetic"] + res.energy["potential"])
    # the motion is not trivial: energy moves between kinetic and potential
    assert np.ptp(res.energy["kinetic"]) > 0.05 * np.abs(res.energy["total"]).max()
    # and the engine's energy is ours
    E = [sum(energy_of(model, q, u, t)) for t, q, u in zip(res.t[::40], res.q[::40], res.u[::40])]
    assert np.allclose(res.energy["total"][::40], E, rtol=1e-12, atol=1e-12)


def test_energy_drift_detects_a_poor_integration():
    """The drift statistic is not blind: explicit Euler visibly gains energy."""
    model = spherical_chain(1)
    res = mb.simulate(model, 2.0, [np.cos(0.5), np.sin(0.5), 0, 0], [0, 0, 1.0],
                      integrator="euler", dt=0.01, outputs=("energy",))
    assert res.stats["energy_drift"] > 1e-3
    assert abs(own_energy_drift(model, res) - res.stats["energy_drift"]) < 0.5 * \
        res.stats["energy_drift"]


def test_both_methods_integrate_the_same_motion_and_outputs_match_the_model():
    """A random tree with drives and loads of every sort: simulate by Jourdain and by
    Newton-Euler; the requested reactions and drive efforts are the model's at each sample."""
    tr = random_tree(11, 6)
    m = tr.model
    assert tr.driven and m.nu
    ts = np.linspace(0, 0.3, 7)
    kw = dict(integrator="DOP853", rtol=1e-11, atol=1e-12, t_eval=ts)
    a = mb.simulate(m, 0.3, tr.q, tr.u, method="jourdain", outputs=("reactions",), **kw)
    b = mb.simulate(m, 0.3, tr.q, tr.u, method="newton-euler", **kw)
    assert np.allclose(a.t, ts) and np.allclose(b.t, ts)
    assert np.abs(a.q - b.q).max() < 1e-8 and np.abs(a.u - b.u).max() < 1e-7
    for k in (0, 3, 6):
        reac = m.reactions(a.q[k], a.u[k], a.t[k])
        for j, (f, mo) in reac.items():
            assert np.allclose(a.reactions[j][k], np.concatenate([f, mo]), rtol=1e-12,
                               atol=1e-12)
        for j, val in m.drive_efforts(a.q[k], a.u[k], a.t[k]).items():
            assert np.isclose(a.drive_efforts[j][k], val, rtol=1e-12, atol=1e-12)


# ----------------------------------------------------------------------------- quaternions
def test_quaternions_unit_in_outputs_and_drift_reported():
    model = spherical_chain(2)
    rng = np.random.default_rng(9)
    q0 = np.concatenate([random_rotation(rng), random_rotation(rng)])
    u0 = rng.normal(size=6) * 3
    res = mb.simulate(model, 1.0, q0, u0, integrator="RK23", rtol=1e-4, atol=1e-6)
    norms = np.linalg.norm(res.q.reshape(len(res.t), 2, 4), axis=2)
    assert np.abs(norms - 1).max() < 1e-14
    drift = res.stats["quaternion_drift"]
    # the same integration done here with scipy's solve_ivp: the same steps, so the same
    # raw (un-normalised) states
    rhs = lambda t, y: np.concatenate([model.coordinate_rates(y[:8], y[8:]),
                                       model.forward_dynamics(y[:8], y[8:], t)])
    ref = integrate.solve_ivp(rhs, (0, 1.0), np.concatenate([q0, u0]), method="RK23",
                              rtol=1e-4, atol=1e-6)
    raw = ref.y[:8].T.reshape(-1, 2, 4)
    expected = np.abs(np.linalg.norm(raw, axis=2) - 1).max()
    assert expected > 1e-9                     # RK23 at this tolerance does drift
    if len(res.t) == len(ref.t) and np.allclose(res.t, ref.t, rtol=0, atol=1e-12):
        assert np.isclose(drift, expected, rtol=1e-6, atol=1e-15), (drift, expected)
    else:                                      # simulate steps differently: same magnitude
        assert expected / 3 < drift < 3 * expected, (drift, expected)
    # fixed-step schemes project onto the unit sphere after every step
    res = mb.simulate(model, 0.5, q0, u0, integrator="rk4", dt=0.01)
    assert res.stats["quaternion_drift"] < 1e-14
    assert np.abs(np.linalg.norm(res.q.reshape(-1, 2, 4), axis=2) - 1).max() < 1e-14


# ----------------------------------------------------------------------------- heavy tops
TOP = dict(m=0.582, h=0.0558, A=0.00209393, C=0.00220580, Mz=-0.025)


def Rz(a):
    return axis_rotation(2, a)


def Rx(a):
    return axis_rotation(0, a)


def top(kind):
    s = mb.System(f"top ({kind})")
    I_O = np.diag([TOP["A"], TOP["A"], TOP["C"]])
    with pytest.warns(mb.ModelWarning, match="triangle"):
        s.add_body("disk", mass=TOP["m"], com=(0, 0, TOP["h"]),
                   inertia=mb.inertia.about_com(I_O, TOP["m"], (0, 0, TOP["h"])))
    if kind == "euler":
        s.add_joint("top", "euler", "ground", "disk", sequence="ZXZ",
                    coordinates=("psi", "theta", "phi"))
    else:
        s.add_joint("top", "spherical", "ground", "disk")
    s.add_load("resist", "disk", moment=(0, 0, TOP["Mz"]), frame="body")
    return s.compile()


def test_heavy_top_with_euler_angles_and_with_a_quaternion_agree():
    """Case a of the textbook: the same motion over 1 s (theta stays well away from 0)."""
    psi, th, phi = 0.0, (15 / 180) * 2 * 3.14159, 0.0
    psid, thd, phid = (200 / 180) * 2 * 3.14159, 0.0, 7 * 2 * 3.14159
    me, ms = top("euler"), top("spherical")
    assert any("triangle" in w for w in me.warnings)          # the model carries the warning
    R0 = Rz(psi) @ Rx(th) @ Rz(phi)
    w2 = np.array([thd, psid * np.sin(th), psid * np.cos(th) + phid])   # B2 components
    w_body = Rz(phi).T @ w2
    ts = np.linspace(0, 1.0, 51)
    kw = dict(integrator="DOP853", rtol=1e-11, atol=1e-12, t_eval=ts)
    re = mb.simulate(me, 1.0, [psi, th, phi], [psid, thd, phid], **kw)
    rs = mb.simulate(ms, 1.0, matrix_to_quat(R0), w_body, **kw)
    assert np.allclose(re.t, ts) and np.allclose(rs.t, ts)
    assert re["theta"].min() > 0.3                      # away from the singularity
    assert np.ptp(re["psi"]) > 1.0 and np.ptp(re["theta"]) > 0.05   # it precesses and nods
    Re = np.array([Rz(a) @ Rx(b) @ Rz(c) for a, b, c in re.q])
    Rs = np.array([quat_to_matrix(qq) for qq in rs.q])
    assert np.abs(Re - Rs).max() < 1e-7, np.abs(Re - Rs).max()
    # centres of mass from the engine's kinematics agree with the hand-made ones
    h = TOP["h"]
    G_e = np.array([me.kinematics(q, u, t=t).r_com[0] for t, q, u in zip(re.t, re.q, re.u)])
    assert np.allclose(G_e, Re @ [0, 0, h], atol=1e-14)
    G_s = np.array([ms.kinematics(q, u, t=t).r_com[0] for t, q, u in zip(rs.t, rs.q, rs.u)])
    assert np.abs(G_e - G_s).max() < 1e-7 * h
    # body angular velocities
    wb_e = np.array([Rz(c).T @ [bd, ad * np.sin(b), ad * np.cos(b) + cd]
                     for (a, b, c), (ad, bd, cd) in zip(re.q, re.u)])
    assert np.abs(wb_e - rs.u).max() < 1e-6 * np.abs(rs.u).max()
