"""The shipped mechanisms (models/) against their closed forms and published references
(tests/loop_references.py, derived independently of the engine): Freudenstein's four-bar
with its drive torque by a power balance, the slider-crank's exact piston motion, Andrews'
squeezer against the IVP test set's reference at t = 0.03 s, the flyball governor against
its 1-DoF equation, and Bricard's overconstrained linkage (mobility 1 where Grubler's count
says 0)."""
from __future__ import annotations

import numpy as np
import pytest
from scipy.integrate import solve_ivp

import mbdyn as mb
import loop_references as ref


def params(scene, *names):
    return [float(scene.parameters[n]) for n in names]


@pytest.mark.parametrize("case,branch", [("open", "open"), ("crossed", "crossed")])
def test_four_bar_model_against_freudenstein_and_power_balance(case, branch):
    scene = mb.load_model("models/four_bar.toml", case=case)
    m = scene.model
    a, b, c, d, Om, phi0 = params(scene, "a", "b", "c", "d", "Omega", "phi0")
    res = scene.simulate(t_end=1.0, outputs=("reactions",))
    th2 = Om * res.t + phi0
    (_, t3, t4), (_, w3, w4), _ = ref.fourbar_state(th2, Om, 0.0, a, b, c, d, branch)
    q = {n: res.q[:, m.coordinate_index(n)] for n in m.coordinates}
    u = {n: res.u[:, m.speed_index(n + "_dot")] for n in m.coordinates}
    assert np.abs(ref.wrap(q["rocker"] - t4)).max() < 1e-9
    assert np.abs(ref.wrap(q["coupler"] + th2 - t3)).max() < 1e-9
    assert np.abs(u["rocker"] - w4).max() < 1e-8 and np.abs(u["coupler"] + Om - w3).max() < 1e-8
    bodies = [m.body(n) for n in ("crank", "coupler", "rocker")]
    tau = ref.fourbar_drive_torque(th2, Om, 0.0, a, b, c, d, [bb.mass for bb in bodies],
                                   [tuple(bb.com[:2]) for bb in bodies],
                                   [bb.inertia[2, 2] for bb in bodies],
                                   gravity=tuple(m.gravity[:2]), branch=branch)
    got = res.drive_efforts["crank"]
    assert np.abs(got - tau).max() < 1e-9 * (1 + np.abs(tau).max())
    assert res.stats["constraint_drift"] <= 1e-10
    assert res.stats["mobility"] == 0


def test_slider_crank_model_piston_follows_the_crank():
    scene = mb.load_model("models/slider_crank.toml")
    m = scene.model
    r, l, e = params(scene, "r", "l", "e")
    res = scene.simulate(t_end=0.04)
    th = res.q[:, m.coordinate_index("theta")]
    w = res.u[:, m.speed_index("theta_dot")]
    ix, iv = m.coordinate_index("xp"), m.speed_index("xp_dot")
    for k in range(0, len(res.t), 20):
        ud = m.forward_dynamics(res.q[k], res.u[k], res.t[k])
        x, v, acc = ref.slider_crank(th[k], w[k], ud[m.speed_index("theta_dot")], r, l, e)
        assert abs(res.q[k, ix] - x) < 1e-10 and abs(res.u[k, iv] - v) < 1e-8
        assert abs(ud[iv] - acc) < 1e-8 * (1 + abs(acc))
    assert res.stats["constraint_drift"] <= 1e-10 and res.stats["mobility"] == 1


def test_andrews_squeezer_against_the_published_reference():
    scene = mb.load_model("models/andrews_squeezer.toml")
    m = scene.model
    res = scene.simulate()
    assert res.t[-1] == ref.ANDREWS_T_REF
    idx = [m.coordinate_index(n) for n in ref.ANDREWS_NAMES]
    assert np.abs(res.q[-1, idx] - ref.ANDREWS_Q_REF).max() < 1e-7
    assert res.stats["constraint_drift"] <= 1e-10
    assert res.stats["mobility"] == 1
    # the published initial accelerations (index-1 form at t = 0)
    ud = m.forward_dynamics(scene.q0, scene.u0)
    np.testing.assert_allclose(ud[idx], ref.ANDREWS_W0, rtol=1e-9, atol=1e-6)


def test_governor_against_its_one_degree_of_freedom_equation():
    scene = mb.load_model("models/watt_governor.toml")
    m = scene.model
    Om = float(scene.parameters["Omega"])
    res = scene.simulate(t_end=1.0)
    ia = m.coordinate_index("alpha1")
    y0 = [res.q[0, ia], res.u[0, m.speed_index("alpha1_dot")]]
    sol = solve_ivp(ref.governor_rhs, (0, 1.0), y0, args=(Om,), t_eval=res.t, rtol=1e-12,
                    atol=1e-12, method="DOP853")
    assert np.abs(res.q[:, ia] - sol.y[0]).max() < 1e-7
    assert np.abs(res.q[:, ia] - res.q[:, m.coordinate_index("alpha2")]).max() < 1e-9
    assert res.stats["constraint_drift"] <= 1e-10


def test_governor_steady_state():
    scene = mb.load_model("models/watt_governor.toml", case="steady")
    res = scene.simulate(t_end=0.5)
    ia = scene.model.coordinate_index("alpha1")
    assert np.abs(res.q[:, ia] - np.radians(30)).max() < 1e-8


def test_bricard_mobility_one_and_energy():
    scene = mb.load_model("models/bricard.toml")
    m = scene.model
    assert len(m.constraint_rows) == 5 and ref.bricard_grubler() == 0
    assert m.mobility(scene.q0) == 1
    res = mb.simulate(m, 1.0, scene.q0, scene.u0, rtol=1e-11, atol=1e-13,
                      outputs=("energy",))
    assert res.stats["energy_drift"] < 1e-8
    assert res.stats["constraint_drift"] <= 1e-10
    q1 = res.q[:, m.coordinate_index("q1")]
    on_path = np.array([ref.bricard_q(x) for x in q1])
    assert np.abs(res.q - on_path).max() < 1e-8          # the motion stays on its one path
    sol = solve_ivp(ref.bricard_reduced_rhs, (0, 1.0), [0.0, 0.0], t_eval=res.t, rtol=1e-11,
                    atol=1e-12, method="DOP853")
    assert np.abs(q1 - sol.y[0]).max() < 1e-6
