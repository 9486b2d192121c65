"""Reactions of the joints of models with flexible bodies (docs/flexible.md, "Reactions"):
Newton-Euler inverse dynamics after the Jourdain route's accelerations, against the loop
multipliers of the same mechanism closed at the node, Newton's law for the system and for
a body, a power balance of a drive and the energy balance of runs."""
from __future__ import annotations

import numpy as np
import pytest

import mbdyn as mb
from test_flexible_loops import _loop_state, _tip_pendulum
from test_flexible_slider_crank import _scene

EB = {"length": 1.0, "elements": 8, "E": 7e10, "rho": 2700.0, "nu": 0.3,
      "rect": [0.03, 0.02], "theory": "euler-bernoulli"}


def _state(m, seed=11):
    rng = np.random.default_rng(seed)
    n = len(m.modal_coordinates)
    return (np.r_[0.3, -0.5, rng.uniform(-2e-3, 2e-3, n)],
            np.r_[1.5, -2.0, rng.uniform(-0.3, 0.3, n)])


def _rate(m, fn, q, u, t=0.0, h=1e-6):
    """``d fn(q, u, t) / dt`` along the motion, by central differences."""
    ud, qd = m.forward_dynamics(q, u, t), m.coordinate_rates(q, u)
    return (np.asarray(fn(q + h * qd, u + h * ud, t + h))
            - np.asarray(fn(q - h * qd, u - h * ud, t - h))) / (2 * h)


def test_a_joint_at_a_node_transmits_what_the_loop_multipliers_say():
    """The pendulum at the beam's tip: its joint's reaction by inverse dynamics (a tree
    joint at the node) equals the loop joint's, the multipliers of the Jourdain route
    (the same mechanism closed at the node), and so does the pin's; the free joint of
    the loop's bob transmits nothing."""
    tree, loop = _tip_pendulum(False), _tip_pendulum(True)
    q, u = _state(tree)
    ql, ul = _loop_state(tree, loop, q, u)
    rt, rl = tree.reactions(q, u), loop.reactions(ql, ul)
    assert set(rl) == {"pin", "float", "hang"}
    for name in ("pin", "hang"):
        for a, b in zip(rt[name], rl[name]):
            assert np.allclose(a, b, rtol=0, atol=1e-12 * np.abs(rt[name][0]).max())
    assert np.abs(np.concatenate(rl["float"])).max() < 1e-11
    # a revolute transmits no moment about its axis (the node frame's z, tilted)
    kin = tree.kinematics(q)
    for name, frame in (("pin", "beam"), ("hang", "bob")):
        axis = kin.R[tree.frame_index(frame)][:, 2]
        assert abs(rt[name][1] @ axis) < 1e-12 * np.abs(rt[name][1]).max()
    child = tree.reactions(q, u, frame="child")["hang"]
    R = kin.R[tree.frame_index("bob")]
    assert np.allclose(child[0], R.T @ rt["hang"][0], rtol=0, atol=1e-12)


def _with_elements():
    """The pinned beam with the pendulum at its tip, a spring-damper from the beam's
    mid node to the bob, a load at its tip and a bushing from the ground to its mid."""
    s = mb.System("elements", gravity=(0, -9.81, 0.5))
    s.add_body("beam", flexible={"beam": {**EB, "nodes": {"mid": 0.5}}, "modes": 4})
    s.add_joint("pin", "revolute", "ground", "beam", axis="z")
    s.add_body("bob", mass=0.5, com=(0.02, -0.2, 0.01), inertia=[1e-3, 2e-3, 3e-3])
    s.add_joint("hang", "revolute", "beam", "bob", axis="z", position="tip")
    s.add_force("link", "spring-damper", body_a="beam", point_a="mid", body_b="bob",
                point_b=(0.0, -0.2, 0.0), stiffness=300.0, damping=2.0, free_length=0.4)
    s.add_force("mount", "bushing", body_a="ground", point_a=(0.5, 0, 0), body_b="beam",
                point_b="mid", stiffness=[1e3, 2e3, 3e3, 10, 20, 30], damping=[1] * 6)
    s.add_load("push", "beam", force=(3.0, -2.0, 1.0), moment=(0, 0, 0.4), point="tip")
    return s.compile()


def test_newtons_law_of_the_system_and_of_the_bob_with_elements_at_nodes():
    """``F_pin + F_mount + F_push + m g = dp/dt`` (the linear momentum of beam and bob by
    differences along the motion); the bob: ``m a_G = m g + R_hang + F_link``."""
    m = _with_elements()
    q, u = _state(m)
    r = m.reactions(q, u)
    p_dot = _rate(m, lambda q, u, t: m.momentum(q, u, t)[0], q, u)
    kin = m.kinematics(q, u)
    x_mid = np.array([0.5, 0, 0]) + m.flexible["beam"].reduced.modes[
        m.flexible["beam"].reduced.node("mid"), :3] @ q[2:]
    ib = m.frame_index("beam")
    mid = kin.r[ib] + kin.R[ib] @ x_mid                  # the bushing's point on the beam
    F_mount = -_bushing_force(m, q, u, mid)
    total = m.body("beam").mass + 0.5
    assert np.allclose(r["pin"][0] + F_mount + [3.0, -2.0, 1.0] + total * m.gravity, p_dot,
                       rtol=0, atol=1e-7 * np.abs(p_dot).max())
    # the bob alone: what the spring pulls it with, from the element's own evaluation
    ud = m.forward_dynamics(q, u)
    kin = m.kinematics(q, u, ud)
    i = m.frame_index("bob")
    link = _link_force_on_bob(m, q, u)
    assert np.allclose(0.5 * (kin.a_com[i] - m.gravity), r["hang"][0] + link, rtol=0,
                       atol=1e-10 * np.abs(r["hang"][0]).max())
    assert np.abs(link).max() > 1.0                       # the spring does pull


def _link_force_on_bob(m, q, u):
    from mbdyn.algorithms.flexible_forces import wrenches
    qx, ux = m._extended(q, u)
    m.tree._kinematics_kernel(qx[:m.tree.nq], ux[:m.tree.nu], 0.0)
    pk = next(p for p in m._flex_elements if p.record.name == "link")
    return wrenches(m, pk, qx, ux, 0.0, jacobians=False)[0][1][1]


def _bushing_force(m, q, u, mid):
    """The bushing's force on the ground's side (the opposite acts on the beam)."""
    from mbdyn.algorithms.flexible_forces import wrenches
    qx, ux = m._extended(q, u)
    m.tree._kinematics_kernel(qx[:m.tree.nq], ux[:m.tree.nu], 0.0)
    pk = next(p for p in m._flex_elements if p.record.name == "mount")
    (on_beam, F, _), _ = wrenches(m, pk, qx, ux, 0.0, jacobians=False)[0]
    assert np.allclose(on_beam[0], mid, atol=1e-14)
    return -F


def test_the_drive_torque_of_the_flexible_slider_crank_by_its_power():
    """The crank's drive torque (the reaction's moment along its axis) times 150 rad/s is
    the rate of the mechanism's energy (by differences), along a run; the energy
    balance of a run with the drive's work closes; the planar loop's out-of-plane
    components are flagged as not unique (as on rigid mechanisms)."""
    scene = _scene()
    m = scene.model
    res = scene.simulate(t_end=0.005, rtol=1e-9, atol=1e-12, output_dt=2e-5,
                         outputs=("energy", "reactions"))
    assert res.stats["energy_drift"] < 1e-8
    for k in (60, 125, 200):
        t, q, u = res.t[k], res.q[k], res.u[k]
        power = m.drive_efforts(q, u, t)["phi1"] * 150.0
        dE = _rate(m, lambda q, u, t: sum(m.energy(q, u, t)), q, u, t, h=1e-7)
        assert power == pytest.approx(dE, rel=1e-8)
        assert res.drive_efforts["phi1"][k] == pytest.approx(power / 150.0, rel=1e-12)
    assert res.stats["reactions_not_unique"]["B"] == ["Fz", "Mx", "My"]
    f, _ = m.reactions(res.q[125], res.u[125], res.t[125])["B"]
    ud, lam = m.multipliers(res.q[125], res.u[125], res.t[125])
    assert np.allclose(f, lam[:3], rtol=0, atol=1e-9 * np.abs(lam).max())
