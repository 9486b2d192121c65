"""Hard cases that must stay numerically stable -- or fail loudly, never silently.

Each test would fail if the engine returned garbage without a word: a singular
configuration passed through, a badly conditioned model, NaN in the results, a failed
integrator without its partial results, quaternions off the unit sphere.
"""
import warnings

import numpy as np
import pytest

import mbdyn as mb
from closed_forms import quaternion_zxz
from textbook_systems import TOP_DATA, double_pendulum_system

M_TOP, H_TOP = TOP_DATA["m"], TOP_DATA["h"]
A_TOP, C_TOP = TOP_DATA["A"], TOP_DATA["C"]


def top(joint):
    """The listing's top on an Euler-angle ("ZXZ") or a spherical (quaternion) joint."""
    s = mb.System("top")
    inertia = mb.inertia.about_com(np.diag([A_TOP, A_TOP, C_TOP]), M_TOP, (0, 0, H_TOP))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", mb.ModelWarning)     # the listing's data: see models/top.toml
        s.add_body("top", mass=M_TOP, com=(0, 0, H_TOP), inertia=inertia)
    if joint == "euler":
        s.add_joint("contact", "euler", "ground", "top", coordinates=("psi", "theta", "phi"))
    else:
        s.add_joint("contact", "spherical", "ground", "top")
    return s.compile()


# A top that swings through the vertical: thrown at theta = 0.3 rad towards it at 6 rad/s
# (enough to climb over the upright position against gravity, which needs ~3.7 rad/s),
# with neither spin nor precession, it passes through theta = 0 after about 0.05 s.
THROUGH_VERTICAL = {"theta": 0.3}, {"theta_dot": -6.0}


def test_euler_top_through_theta_zero_stops_before_the_singularity_and_names_the_remedy():
    model = top("euler")
    with pytest.raises(mb.SimulationError) as info:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", mb.SingularityWarning)
            mb.simulate(model, 2.0, *THROUGH_VERTICAL, integrator="DOP853", rtol=1e-10,
                        atol=1e-12)
    msg = str(info.value)
    assert "joint 'contact'" in msg and "singular" in msg and "spherical" in msg
    partial = info.value.result
    assert partial is not None and len(partial.t) > 2
    assert np.all(np.isfinite(partial.q)) and np.all(np.isfinite(partial.u))
    # what was kept is trustworthy: it stops before theta reaches zero
    assert np.all(partial["theta"] > 0) and 0.02 < partial.t[-1] < 0.06


def test_euler_top_approaching_the_singularity_warns_first():
    model = top("euler")
    with pytest.warns(mb.SingularityWarning, match="contact.*spherical"):
        with pytest.raises(mb.SimulationError):
            mb.simulate(model, 2.0, *THROUGH_VERTICAL, integrator="rk4", dt=1e-4)


def test_quaternion_top_passes_through_theta_zero_conserving_energy():
    model = top("spherical")
    q0 = quaternion_zxz(0.0, 0.3, 0.0)
    res = mb.simulate(model, 10.0, q0, [-6.0, 0.0, 0.0], integrator="DOP853", rtol=1e-12,
                      atol=1e-12, outputs=("energy",))
    assert res.t[-1] == pytest.approx(10.0)
    # it did pass through the vertical: the motion stays in the plane normal to x, and the
    # tilt about x (2 asin(qx)) changed sign
    assert np.abs(res.q[:, 2:]).max() < 1e-9
    assert res.q[:, 1].min() < -0.01 and res.q[:, 1].max() > 0.01
    E = res.energy["total"]
    scale = np.abs(res.energy["kinetic"]).max() + np.abs(res.energy["potential"]).max()
    assert np.abs(E - E[0]).max() / scale < 1e-9
    assert res.stats["energy_drift"] < 1e-9
    assert np.allclose(np.linalg.norm(res.q, axis=1), 1.0, atol=1e-14)
    assert res.stats["quaternion_drift"] < 1e-8


def test_quaternion_and_euler_top_agree_away_from_the_singularity():
    """The same precessing top in both parametrisations: the same centre-of-mass path."""
    q_e = {"psi": 0.2, "theta": 0.5, "phi": 0.1}
    u_e = {"psi_dot": 2.0, "theta_dot": 0.3, "phi_dot": 40.0}
    me, mq = top("euler"), top("spherical")
    re = mb.simulate(me, 1.0, q_e, u_e, integrator="DOP853", rtol=1e-11, atol=1e-12,
                     t_eval=np.linspace(0, 1, 51))
    # angular velocity of the top in its own axes, from the Euler rates
    ps, th, ph = 0.2, 0.5, 0.1
    dps, dth, dph = 2.0, 0.3, 40.0
    w_body = np.array([dps * np.sin(th) * np.sin(ph) + dth * np.cos(ph),
                       dps * np.sin(th) * np.cos(ph) - dth * np.sin(ph),
                       dps * np.cos(th) + dph])
    rq = mb.simulate(mq, 1.0, quaternion_zxz(ps, th, ph), w_body, integrator="DOP853",
                     rtol=1e-11, atol=1e-12, t_eval=np.linspace(0, 1, 51))
    for k in range(0, 51, 10):
        ke = me.kinematics(re.q[k], re.u[k])
        kq = mq.kinematics(rq.q[k], rq.u[k])
        assert np.allclose(ke.r_com, kq.r_com, atol=1e-8)
        assert np.allclose(ke.w, kq.w, rtol=1e-7, atol=1e-7)


def test_double_pendulum_with_a_feather_light_first_mass():
    """m1 = 1e-6 m2: a badly scaled mass matrix; both formulations and the integrators
    still agree with a reference."""
    model = double_pendulum_system(m1=0.0046e-6, m2=0.0046, l1=0.07, l2=0.07).compile()
    rng = np.random.default_rng(7)
    for _ in range(10):
        q = rng.uniform(-np.pi, np.pi, 2)
        u = rng.uniform(-5, 5, 2)
        a_j = model.forward_dynamics(q, u, method="jourdain")
        a_n = model.forward_dynamics(q, u, method="newton-euler")
        assert np.linalg.norm(a_j - a_n) <= 1e-8 * np.linalg.norm(a_j)
    q0 = {"theta1": 0.4, "theta2": -0.3}
    t_eval = np.linspace(0, 0.3, 31)
    ref = mb.simulate(model, 0.3, q0, integrator="DOP853", rtol=1e-12, atol=1e-12,
                      t_eval=t_eval)
    for integ in ("Radau", "LSODA", "RK45"):
        res = mb.simulate(model, 0.3, q0, integrator=integ, rtol=1e-8, atol=1e-10,
                          t_eval=t_eval)
        assert np.abs(res.q - ref.q).max() < 1e-4, integ
    # the two formulations' right-hand sides differ by rounding only, which the light
    # link's fast motion amplifies over the run
    res = mb.simulate(model, 0.3, q0, integrator="DOP853", rtol=1e-12, atol=1e-12,
                      t_eval=t_eval, method="newton-euler")
    assert np.abs(res.q - ref.q).max() < 1e-6


@pytest.fixture(scope="module")
def chaotic_pendulum():
    """A double pendulum of two 1 kg masses on 1 m rods, released near the inverted
    position: chaotic, so no integrator follows its trajectory for long."""
    return double_pendulum_system(m1=1.0, m2=1.0, l1=1.0, l2=1.0).compile()


@pytest.mark.parametrize("integrator, kwargs, bound, growth", [
    # error-controlled: drift far below the tolerance's order
    ("DOP853", {"rtol": 1e-10, "atol": 1e-12}, 1e-7, None),
    # symmetric implicit midpoint: an O(h^2) drift that oscillates and does not grow
    ("implicit-midpoint", {"dt": 5e-3}, 5e-3, 2.0),
    # the textbook's scheme in (q, q') coordinates: the mass matrix depends on q, so the
    # scheme is not symplectic here and its drift grows -- reported, and bounded over 100 s
    ("semi-implicit-euler", {"dt": 1e-3}, 1.0, None),
])
def test_chaotic_double_pendulum_energy_drift_bounded_over_100_s(chaotic_pendulum, integrator,
                                                                  kwargs, bound, growth):
    res = mb.simulate(chaotic_pendulum, 100.0, {"theta1": np.pi * 0.999, "theta2": np.pi / 4},
                      integrator=integrator, outputs=("energy",),
                      t_eval=np.linspace(0, 100, 1001), **kwargs)
    assert res.t[-1] == pytest.approx(100.0)
    drift = res.stats["energy_drift"]
    E = res.energy["total"]
    # drift = max |E - E(0)| over the energy scale max(|E(0)|, max T, max |V|)
    scale = max(abs(E[0]), np.abs(res.energy["kinetic"]).max(),
                np.abs(res.energy["potential"]).max())
    assert drift == pytest.approx(np.abs(E - E[0]).max() / scale, rel=1e-9)
    assert np.isfinite(drift) and drift < bound
    if growth is not None:            # bounded, not growing: the second half as the first
        half = len(E) // 2
        first = np.abs(E[:half] - E[0]).max()
        second = np.abs(E[half:] - E[0]).max()
        assert second <= growth * first


def test_nearly_singular_mass_matrix_is_reported_with_its_condition():
    s = mb.System("tiny rotor")
    s.add_body("arm", mass=1.0, com=(0.5, 0, 0), inertia=(0.01, 0.1, 0.1))
    s.add_joint("swing", "revolute", "ground", "arm", axis="z")
    s.add_body("rotor", mass=1e-3, inertia=(1e-13, 1e-13, 1e-13))
    s.add_joint("spin", "revolute", "arm", "rotor", axis="x", position=(1, 0, 0))
    model = s.compile()
    with pytest.warns(mb.SingularityWarning, match=r"condition number.*spin_dot"):
        res = mb.simulate(model, 0.01, u0={"swing_dot": 1.0}, integrator="RK45")
    assert res.stats["mass_matrix_condition_initial"] > 1e10
    cond, weak = model.mass_matrix_condition(model.default_coordinates())
    M = model.mass_matrix(model.default_coordinates())
    assert cond == pytest.approx(np.linalg.cond(M), rel=1e-6)
    assert weak == ["spin_dot"]


def test_nan_from_a_load_stops_the_run_with_time_state_and_element():
    s = mb.System("pendulum")
    s.add_body("bob", mass=1.0, com=(0, 0, -1))
    s.add_joint("beta", "revolute", "ground", "bob", axis="x")
    s.add_load("kick", "bob", force=lambda t, q, u: (np.nan if t > 0.5 else 0.0, 0.0, 0.0))
    model = s.compile()
    for integrator, kw in (("RK45", {}), ("rk4", {"dt": 0.01})):
        with pytest.raises(mb.SimulationError, match=r"t=0\.5[0-9]*: load 'kick' returned non-finite") as info:
            mb.simulate(model, 1.0, {"beta": 0.2}, integrator=integrator, **kw)
        assert "beta=" in str(info.value)        # the last good state
        kept = info.value.result
        assert kept.t[-1] <= 0.5 + 1e-12 and len(kept.t) > 3
        assert np.all(np.isfinite(kept.q)) and np.all(np.isfinite(kept.u))


@pytest.mark.parametrize("method", ["jourdain", "newton-euler"])
def test_both_formulations_name_a_non_finite_load_and_a_missing_inertia(method):
    s = mb.System("pendulum")
    s.add_body("bob", mass=1.0, com=(0, 0, -1))
    s.add_joint("beta", "revolute", "ground", "bob", axis="x")
    s.add_load("kick", "bob", force=lambda t, q, u: (np.inf if t > 0.5 else 0.0, 0.0, 0.0))
    model = s.compile()
    assert np.all(np.isfinite(model.forward_dynamics([0.2], [0.0], 0.4, method=method)))
    with pytest.raises(mb.NonFiniteError, match=r"t=0\.6: load 'kick' returned non-finite"):
        model.forward_dynamics([0.2], [0.0], 0.6, method=method)
    s.add_body("bead", mass=1.0)                 # a particle spinning about its own axis
    s.add_joint("spin", "revolute", parent="bob", child="bead", axis="z")
    model = s.compile(check_inertia=False)
    with pytest.raises(mb.SingularMassMatrixError, match=r"spin \(joint 'spin'\)"):
        model.forward_dynamics([0.2, 0.0], [0.0, 0.0], 0.0, method=method)


def test_failing_integrator_keeps_the_results_before_the_failure():
    """A load that turns singular in finite time (1/(t_s - t)): the step size underflows."""
    s = mb.System("blow-up")
    s.add_body("slider", mass=1.0)
    s.add_joint("x", "prismatic", "ground", "slider", axis="x")
    s.add_load("push", "slider", force=lambda t, q, u: (1.0 / (0.3 - t) ** 3, 0.0, 0.0))
    model = s.compile()
    with pytest.raises(mb.SimulationError, match=r"(failed|non-finite).*t=0\.[23]") as info:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", RuntimeWarning)
            mb.simulate(model, 1.0, integrator="RK45", rtol=1e-8, atol=1e-10)
    kept = info.value.result
    assert kept is not None and 0.2 < kept.t[-1] <= 0.3 and len(kept.t) > 5
    assert np.all(np.isfinite(kept.q))


def test_fixed_step_quaternions_stay_on_the_unit_sphere_and_drift_is_reported():
    model = top("spherical")
    q0 = quaternion_zxz(0.0, 0.5, 0.0)
    for integrator in ("euler", "rk4", "semi-implicit-euler", "implicit-midpoint"):
        res = mb.simulate(model, 0.5, q0, [0.5, 0.3, 40.0], integrator=integrator, dt=1e-3)
        assert np.allclose(np.linalg.norm(res.q, axis=1), 1.0, atol=1e-14), integrator
        assert "quaternion_drift" in res.stats


@pytest.mark.parametrize("stretches", [1, 3])
def test_vectorized_singularity_watch_matches_the_step_by_step_one(stretches):
    """Fixed-step runs check whole stretches of steps at once (``check_rows``); it must
    stop at the same row, with the same message, closest approach and warnings, as the
    one-step check the adaptive runs use."""
    from mbdyn.integrate.monitor import Monitor as _Monitor
    model = top("euler")
    ts = np.linspace(0.0, 0.1, 100)
    ys = np.zeros((100, 6))
    ys[:, 1] = np.linspace(0.3, -0.1, 100)          # theta passes 0 between two rows
    step, vector = _Monitor(model, 1e-6), _Monitor(model, 1e-6)
    with warnings.catch_warnings(record=True) as w_step:
        warnings.simplefilter("always")
        n_step, f_step = len(ts), None
        for i in range(len(ts)):
            f_step = step.check(ts[i], ys[i])
            if f_step:
                n_step = i
                break
    with warnings.catch_warnings(record=True) as w_vector:
        warnings.simplefilter("always")
        n_vector, f_vector = 0, None
        for chunk in np.array_split(np.arange(len(ts)), stretches):
            n, f_vector = vector.check_rows(ts[chunk], ys[chunk])
            n_vector += n
            if f_vector:
                break
    assert f_step is not None and "between t=" in f_step
    assert (n_vector, f_vector) == (n_step, f_step)
    assert vector.closest == pytest.approx(step.closest)
    assert [str(x.message) for x in w_vector] == [str(x.message) for x in w_step]
    assert len(w_step) == 1
