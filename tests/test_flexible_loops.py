"""Closed loops through flexible bodies (docs/flexible.md, "Closed loops through flexible
bodies"): the constraint rows against finite differences, the constrained dynamics
against the same mechanism written as a tree, energy of a free closed mechanism, the
assembly, the projection and the drift reported by runs in Python."""
from __future__ import annotations

import numpy as np
import pytest

import mbdyn as mb
from mbdyn.errors import ModelError

ROD = {"length": 0.3, "elements": 6, "E": 2e11, "rho": 7870.0, "nu": 0.3,
       "rect": [0.006, 0.008], "theory": "euler-bernoulli"}
EB = {"length": 1.0, "elements": 8, "E": 7e10, "rho": 2700.0, "nu": 0.3,
      "rect": [0.03, 0.02], "theory": "euler-bernoulli"}


def _slider_crank(drive=True, modes=3):
    """A crank (driven, or free with a flywheel), a flexible rod whose tip is pinned to
    a slider by a loop revolute: every component of the tip's motion in the loop."""
    s = mb.System("flexible slider-crank", gravity=(0, -9.81, 0))
    s.add_body("crank", mass=0.36, com=(0.075, 0, 0), inertia=[1e-4, 1e-3, 1e-3])
    s.add_joint("phi1", "revolute", "ground", "crank", axis="z",
                drive=150 * mb.t if drive else None)
    s.add_body("rod", flexible={"beam": ROD, "modes": modes})
    s.add_joint("phi2", "revolute", "crank", "rod", axis="z", position=(0.15, 0, 0))
    s.add_body("slider", mass=0.076, inertia=[1e-5, 1e-5, 1e-5])
    s.add_joint("x3", "prismatic", "ground", "slider", axis="x")
    s.add_joint("B", "revolute", "rod", "slider", axis="z", position="tip",
                child_position=(0, 0, 0))
    return s


def _in_plane(m):
    """The rod's modal coordinates that bend it in the plane of the mechanism (x-y)."""
    red = m.flexible["rod"].reduced
    tip = red.modes[red.node("tip")]
    return [c for k, c in enumerate(m.modal_coordinates) if abs(tip[1, k]) > abs(tip[2, k])]


def _assembled(m, drive=True):
    """On the constraints: the in-plane modes held (the others must keep the tip on the
    slider's line), the crank at 0.4 rad and 150 rad/s when free."""
    held = dict(zip(_in_plane(m), (2e-4, -1e-4)))
    rates = dict.fromkeys(m.modal_coordinates, 0.0)
    if not drive:
        held["phi1"] = 0.4
        rates["phi1"] = 150.0
    q, u = m.assemble(initial=held, initial_speeds=rates, guess={"phi2": -0.2, "x3": 0.42},
                      t=0.0)
    return q, u


# ------------------------------------------------------------------ rows
def test_G_and_gamma_against_finite_differences():
    """``d phi/dt = G u`` (plus the drive's part) and ``d psi/dt = G u' - gamma`` by
    central differences along ``(q', u', t)``, off the constraints (random state)."""
    m = _slider_crank().compile(effects="-geometric_stiffening")
    assert m.constraint_rows == ("B.x", "B.y", "B.z", "B.perp1", "B.perp2")
    rng = np.random.default_rng(7)
    # mass-normalised modes: a unit of eta turns the tip by ~100 rad, so the modal
    # coordinates and rates are kept to the mechanism's scale (0.03 rad, 3 rad/s)
    q = np.r_[0.41, -0.3, rng.uniform(-3e-4, 3e-4, 3)]
    u = np.r_[rng.uniform(-20, 20, 2), rng.uniform(-0.03, 0.03, 3)]
    ud = np.r_[rng.uniform(-1e3, 1e3, 2), rng.uniform(-3.0, 3.0, 3)]
    t, h = 0.013, 1e-6
    qd = m.coordinate_rates(q, u)
    phi, psi = m.constraint_residuals(q, u, t)
    G = m.constraint_jacobian(q, t)
    assert np.abs(phi).max() > 1e-3 and np.abs(G[:, 2:]).max() > 10    # modal columns
    dphi = (m.constraint_residuals(q + h * qd, u, t + h)[0]
            - m.constraint_residuals(q - h * qd, u, t - h)[0]) / (2 * h)
    assert np.allclose(psi, dphi, atol=1e-8 * np.abs(psi).max(), rtol=0)
    gamma = _gamma(m, q, u, t)
    dpsi = (m.constraint_residuals(q + h * qd, u + h * ud, t + h)[1]
            - m.constraint_residuals(q - h * qd, u - h * ud, t - h)[1]) / (2 * h)
    assert np.allclose(G @ ud - gamma, dpsi, atol=1e-7 * np.abs(dpsi).max(), rtol=0)


def _gamma(m, q, u, t):
    from mbdyn.algorithms.flexible_loops import constraint_terms
    return constraint_terms(m, q, u, t)[3]


# ------------------------------------------------------------------ dynamics
def _tip_pendulum(loop):
    """A pendulum at the tip of a pinned beam: by a tree joint at the tip's node, or
    (``loop``) as a free body pinned to the tip by a loop revolute: the same mechanism."""
    s = mb.System("tip pendulum", gravity=(0, -9.81, 0.5))
    s.add_body("beam", flexible={"beam": EB, "modes": 4})
    s.add_joint("pin", "revolute", "ground", "beam", axis="z")
    s.add_body("bob", mass=0.5, com=(0.02, -0.2, 0.01), inertia=[1e-3, 2e-3, 3e-3])
    if loop:
        s.add_joint("float", "free", "ground", "bob")
        s.add_joint("hang", "revolute", "beam", "bob", axis="z", position="tip",
                    child_position=(0, 0, 0))
    else:
        s.add_joint("hang", "revolute", "beam", "bob", axis="z", position="tip")
    return s.compile(effects="-geometric_stiffening")


def _loop_state(tree, loop, q, u):
    """The loop model's state where the tree model is at ``(q, u)``: the bob's pose and
    velocity as its free joint's coordinates and speeds."""
    from mbdyn.elements.rotations import from_matrix as quaternion_from_matrix
    kin = tree.kinematics(q, u)
    i = tree.frame_index("bob")
    values = {c: q[tree.coordinate_index(c)] for c in tree.coordinates if c != "hang"}
    values.update(dict(zip(("float_x", "float_y", "float_z"), kin.r[i])))
    quat = quaternion_from_matrix(kin.R[i])
    values.update(dict(zip(("float_qw", "float_qx", "float_qy", "float_qz"), quat)))
    rates = {s: u[tree.speed_index(s)] for s in tree.speeds if s != "hang_dot"}
    rates.update(dict(zip(("float_vx", "float_vy", "float_vz"), kin.v[i])))
    rates.update(dict(zip(("float_wx", "float_wy", "float_wz"), kin.R[i].T @ kin.w[i])))
    return loop.q_vector(values), loop.u_vector(rates)


def test_a_loop_at_a_node_moves_as_the_same_joint_in_the_tree():
    tree, loop = _tip_pendulum(False), _tip_pendulum(True)
    assert loop.has_loops and loop.mobility(loop.default_coordinates()) == 6
    rng = np.random.default_rng(11)
    q = np.r_[0.3, -0.5, rng.uniform(-2e-3, 2e-3, 4)]
    u = np.r_[1.5, -2.0, rng.uniform(-0.3, 0.3, 4)]
    ql, ul = _loop_state(tree, loop, q, u)
    assert np.abs(np.concatenate(loop.constraint_residuals(ql, ul))).max() < 1e-13
    ud = tree.forward_dynamics(q, u)
    udl, lam = loop.multipliers(ql, ul)
    for name in ("pin_dot",) + tuple(f"beam_m{k}_dot" for k in range(1, 5)):
        assert udl[loop.speed_index(name)] == pytest.approx(
            ud[tree.speed_index(name)], rel=1e-9, abs=1e-9 * np.abs(ud).max())
    i, il = tree.frame_index("bob"), loop.frame_index("bob")
    a, al = tree.kinematics(q, u, ud), loop.kinematics(ql, ul, udl)
    assert np.allclose(a.a[i], al.a[il], rtol=0, atol=1e-9 * np.abs(a.a[i]).max())
    assert np.allclose(a.alpha[i], al.alpha[il], rtol=0, atol=1e-9 * np.abs(a.alpha[i]).max())
    # the multipliers of the point: the force the beam's tip exerts on the bob (world),
    # m (a_G - g) by Newton's law, the pin transmitting no other force to it
    m_bob, g = 0.5, loop.gravity
    assert np.allclose(lam[:3], m_bob * (al.a_com[il] - g), rtol=1e-9, atol=1e-12)
    # over a run both stay together
    rt = mb.simulate(tree, 0.01, q, u, rtol=1e-10, atol=1e-13, t_eval=[0.0, 0.01])
    rl = mb.simulate(loop, 0.01, ql, ul, rtol=1e-10, atol=1e-13, t_eval=[0.0, 0.01])
    assert rl["pin"][-1] == pytest.approx(rt["pin"][-1], abs=1e-9)
    assert rl["beam_m1"][-1] == pytest.approx(rt["beam_m1"][-1], abs=1e-11)
    assert rl.stats["constraint_drift"] < 1e-12


def test_free_closed_mechanism_conserves_energy_and_stays_on_its_constraints():
    """The crank free (started at 150 rad/s), no damping, no stiffening: energy kept by
    scipy's DOP853 and by the Python RK4 loop, which projects every step."""
    m = _slider_crank(drive=False).compile(effects="-geometric_stiffening")
    q, u = _assembled(m, drive=False)
    E0 = sum(m.energy(q, u))
    res = mb.simulate(m, 0.005, q, u, integrator="DOP853", rtol=1e-10, atol=1e-13,
                      outputs=("energy",))
    E = res.energy["total"]
    assert np.abs(E - E0).max() < 1e-9 * res.energy["kinetic"].max()
    assert res.stats["constraint_drift"] < 1e-12
    assert res.stats["constraint_drift_unprojected"] < 1e-9
    # x, y; z and the tilt both read the one out-of-plane mode: rank 3 of 5 rows
    assert res.stats["constraint_rank"] == 3 and res.stats["mobility"] == 3
    rk = mb.simulate(m, 1e-3, q, u, integrator="rk4", dt=2e-6, outputs=("energy",))
    assert rk.stats["constraint_drift_unprojected"] < 1e-13      # projected each step
    E = rk.energy["total"]
    assert np.abs(E - E0).max() < 1e-6 * rk.energy["kinetic"].max()


def test_a_loop_between_two_flexible_bodies_conserves_energy():
    """A four-bar of three beams (two modes each, in and out of the plane): the coupler on
    the crank's tip node, the loop revolute between the coupler's tip and the rocker's,
    node frames on both sides.  The assembly holds the modal coordinates (at 0: none
    guessed); free motion under gravity keeps its energy and its constraints."""
    beam = {**EB, "length": 0.5, "elements": 4, "rect": [0.02, 0.03]}
    s = mb.System("three beams", gravity=(0, -9.81, 0))
    s.add_body("a", flexible={"beam": beam, "modes": 2})
    s.add_joint("pa", "revolute", "ground", "a", axis="z")
    s.add_body("b", flexible={"beam": beam, "modes": 2})
    s.add_joint("pb", "revolute", "ground", "b", axis="z", position=(0.7, 0, 0))
    s.add_body("c", flexible={"beam": {**beam, "length": 0.8}, "modes": 2})
    s.add_joint("pc", "revolute", "a", "c", axis="z", position="tip")
    s.add_joint("K", "revolute", "c", "b", axis="z", position="tip", child_position="tip")
    m = s.compile(effects="-geometric_stiffening")
    assert m.joint("K").parent == "c.tip" and m.joint("K").child == "b.tip"
    q, u = m.assemble({"pa": 1.2}, {"pa": 1.0}, {"pb": 1.9, "pc": -1.2})
    assert not np.any(q[3:]) and not np.any(u[3:])
    assert m.constraint_rank(q)[0] == 5                   # 2 in the plane, 3 out of it
    res = mb.simulate(m, 0.005, q, u, rtol=1e-10, atol=1e-13, outputs=("energy",))
    E = res.energy["total"]
    assert np.abs(E - E[0]).max() < 1e-10 * res.energy["kinetic"].max()
    assert res.stats["constraint_drift_unprojected"] < 1e-12
    assert np.ptp(res["a_m1"]) > 1e-6                     # the beams do bend


# ------------------------------------------------------------------ assembly and errors
def test_assembly_holds_the_modal_coordinates_and_closes_the_loop():
    m = _slider_crank().compile()
    q, u = _assembled(m)
    held = _in_plane(m)
    assert len(held) == 2 and q[m.coordinate_index(held[1])] == -1e-4      # held
    assert not np.any(u[2:]) and not q[m.coordinate_index(
        next(c for c in m.modal_coordinates if c not in held))]   # the others: held at 0
    phi, psi = m.constraint_residuals(q, u)
    assert np.abs(phi).max() < 1e-12 and np.abs(psi).max() < 1e-12 * np.abs(u).max()
    tip = m.kinematics(q).r[m.frame_index("rod.tip")]
    assert tip[1] == pytest.approx(0, abs=1e-13)                # on the slider's line
    with pytest.raises(ModelError, match="does not close the loop of joint 'B'"):
        mb.simulate(m, 0.01, m.q_vector({"x3": 0.3}))
    qp, up = m.project(q + 1e-6, u)
    assert np.abs(m.constraint_residuals(qp, up)[0]).max() < 1e-13


def test_redundant_rows_take_the_minimum_norm_multipliers():
    """A spatial revolute's five rows of rank three here (the tip's out-of-plane
    displacement and tilt both read the one out-of-plane mode): the multipliers are the
    smallest that produce the accelerations, orthogonal to the self-balanced sets
    ``G^T z = 0``, and the accelerations satisfy both equations."""
    m = _slider_crank().compile(effects="-geometric_stiffening")
    q, u = _assembled(m)
    ud, lam = m.multipliers(q, u)
    G = m.constraint_jacobian(q)
    _, s, Vt = np.linalg.svd(G.T)
    null = Vt[np.count_nonzero(s > 1e-9 * s[0]):]
    assert null.shape[0] == 2                                   # rank 3 of 5
    assert np.abs(null @ lam).max() < 1e-10 * np.abs(lam).max()
    M = m.mass_matrix(q)
    f = m.forcing(q, u)
    assert np.allclose(M @ ud, f + G.T @ lam, rtol=0, atol=1e-9 * np.abs(f).max())
    assert np.allclose(G @ ud, _gamma(m, q, u, 0.0), rtol=0, atol=1e-9 * np.abs(G @ ud).max())
