"""Joints at the nodes of flexible bodies (docs/flexible.md, "Joints at nodes"): the node
frame's placement against the point formula, its velocity, Jacobians and accelerations
against finite differences, statics against the cantilever's closed form, energy of a
free system, flexibility off against the rigid model, node names and model files."""
from __future__ import annotations

import numpy as np
import pytest
import scipy.linalg

import mbdyn as mb
from mbdyn.compiled.model import Model
from mbdyn.errors import ModelError
from mbdyn.flexible.invariants import skew

EB = {"length": 1.0, "elements": 8, "E": 7e10, "rho": 2700.0, "nu": 0.3,
      "rect": [0.03, 0.02], "theory": "euler-bernoulli"}


def _rot(k, a):
    c, s = np.cos(a), np.sin(a)
    i, j = (k + 1) % 3, (k + 2) % 3
    R = np.eye(3)
    R[i, i] = R[j, j] = c
    R[i, j], R[j, i] = -s, s
    return R


def _spatial(point=(1.0, 0.0, 0.0), modes=4):
    """A beam on a spherical joint, a body hanging from a point near its tip by a
    revolute about a skew axis, turned by an orientation: every component moves."""
    s = mb.System("spatial", gravity=(0.3, -9.81, 1.2))
    s.add_body("beam", flexible={"beam": EB, "modes": modes})
    s.add_joint("ball", "spherical", "ground", "beam")
    s.add_body("bob", mass=0.7, com=(0.05, -0.2, 0.03), inertia=[2e-3, 1e-3, 3e-3])
    s.add_joint("hang", "revolute", "beam", "bob", axis=(0.2, 0.3, 1.0), position=point,
                orientation=("x", 0.4))
    return s


def _state(m, seed=3):
    rng = np.random.default_rng(seed)
    q = m.q_vector({"ball": [0.9, 0.2, -0.3, 0.25], "hang": 0.7})
    m.normalize_quaternions(q)
    for c in m.modal_coordinates:
        q[m.coordinate_index(c)] = rng.uniform(-2e-3, 2e-3)
    u = rng.uniform(-2.0, 2.0, m.nu)
    ud = rng.uniform(-30.0, 30.0, m.nu)
    return q, u, ud


# ------------------------------------------------------------------ kinematics
def test_node_frame_is_placed_by_the_point_formula():
    """``r = r_0 + R (x_p + (Phi_i - s~ Psi_i) eta)``, turned by ``Rx Ry Rz`` of
    ``theta = Psi_i eta``: the mode shapes read from the reduced body directly."""
    x_p = np.array([0.97, 0.01, -0.02])                 # off the tip node by s
    m = _spatial(point=x_p).compile()
    q, _, _ = _state(m)
    kin = m.kinematics(q)
    red = m.flexible["beam"].reduced
    i = red.node("tip")
    s = x_p - red.nodes[i]
    eta = q[[m.coordinate_index(c) for c in m.modal_coordinates]]
    Phi, Psi = red.modes[i, :3], red.modes[i, 3:]
    theta = Psi @ eta
    R0, r0 = kin.R[m.frame_index("beam")], kin.r[m.frame_index("beam")]
    ib = m.frame_index("bob")
    assert np.allclose(kin.r[ib], r0 + R0 @ (x_p + (Phi - skew(s) @ Psi) @ eta),
                       atol=1e-15, rtol=0)
    j = m.joint("hang")
    turn = scipy.linalg.expm(skew(j.axis * q[m.coordinate_index("hang")]))
    R_xyz = _rot(0, theta[0]) @ _rot(1, theta[1]) @ _rot(2, theta[2])
    assert np.abs(kin.R[ib] - R0 @ R_xyz @ j.orientation @ turn).max() < 1e-14
    # the small rotation: the rotation vector theta to first order
    exact = R0 @ scipy.linalg.expm(skew(theta)) @ j.orientation @ turn
    assert 1e-12 < np.abs(kin.R[ib] - exact).max() < 2 * np.abs(theta).max() ** 2
    assert np.abs(theta).max() > 1e-4                   # the node does turn


def test_velocities_jacobians_and_accelerations_against_finite_differences():
    m = _spatial(point=(0.97, 0.01, -0.02)).compile()
    q, u, ud = _state(m)
    ib = m.frame_index("bob")
    qd = m.coordinate_rates(q, u)
    h = 1e-6

    def pose(q, u=None):
        k = m.kinematics(q, u)
        return k.r[ib], k.R[ib], k.v[ib], k.w[ib]

    rp, Rp, *_ = pose(q + h * qd)
    rm, Rm, *_ = pose(q - h * qd)
    r, R, v, w = pose(q, u)
    assert np.allclose(v, (rp - rm) / (2 * h), atol=1e-8 * np.abs(v).max(), rtol=0)
    W = (Rp - Rm) / (2 * h) @ R.T                       # w~ = R' R^T
    assert np.allclose(w, [W[2, 1], W[0, 2], W[1, 0]], atol=1e-8 * np.abs(w).max(), rtol=0)
    # the Jacobians' columns: v = JT u, w = JR u for any speeds (no drives)
    JT = m.jacobian_translation(q, "bob", point=np.zeros(3))
    JR = m.jacobian_rotation(q, "bob")
    assert np.allclose(JT @ u, v, atol=1e-13) and np.allclose(JR @ u, w, atol=1e-13)
    # modal columns: nonzero, and equal to d r / d eta by differences
    k = m.speed_index("beam_m2_dot")
    e = np.zeros(m.nq)
    e[m.coordinate_index("beam_m2")] = h
    assert np.abs(JT[:, k]).max() > 0.1
    assert np.allclose(JT[:, k], (pose(q + e)[0] - pose(q - e)[0]) / (2 * h), atol=1e-8)
    # accelerations: a = JT u' + a_bias, d/dt of the velocities along (q', u')
    kin = m.kinematics(q, u, ud)
    vp, wp = pose(q + h * qd, u + h * ud)[2:]
    vm, wm = pose(q - h * qd, u - h * ud)[2:]
    assert np.allclose(kin.a[ib], (vp - vm) / (2 * h), atol=1e-6 * np.abs(kin.a[ib]).max())
    assert np.allclose(kin.alpha[ib], (wp - wm) / (2 * h),
                       atol=1e-6 * np.abs(kin.alpha[ib]).max())


def test_kinetic_energy_is_half_u_M_u_and_gravity_is_minus_dV_dq():
    """The mass matrix against the kinetic energy (each body's own velocities), and the
    static forcing against the potential by differences (q' = u for every coordinate
    of a pin and a revolute; the axial stiffening, a force no potential gives, off)."""
    m = _spatial(point=(0.97, 0.01, -0.02)).compile()
    q, u, _ = _state(m)
    assert 0.5 * u @ m.mass_matrix(q) @ u == pytest.approx(m.energy(q, u)[0], rel=1e-12)
    s = mb.System("pin", gravity=(0.0, -9.81, 0.0))
    s.add_body("beam", flexible={"beam": EB, "modes": 4})
    s.add_joint("pin", "revolute", "ground", "beam", axis=(0.1, 0.2, 1.0))
    s.add_body("bob", mass=0.7, com=(0.05, -0.2, 0.03), inertia=[2e-3, 1e-3, 3e-3])
    s.add_joint("hang", "revolute", "beam", "bob", axis=(0.2, 0.3, 1.0),
                position=(0.97, 0.01, -0.02))
    m = s.compile(effects="-geometric_stiffening")
    rng = np.random.default_rng(5)
    q = rng.uniform(-1, 1, m.nq) * np.r_[1.0, 1.0, [2e-3] * 4]
    f = m.forcing(q, np.zeros(m.nu))
    grad = np.array([(m.energy(q + d, np.zeros(m.nu))[1] - m.energy(q - d, np.zeros(m.nu))[1])
                     / 2e-7 for d in np.eye(m.nq) * 1e-7])
    assert np.allclose(f, -grad, atol=1e-6 * np.abs(f).max(), rtol=0)


# ------------------------------------------------------------------ statics and energy
def test_a_load_hung_from_the_tip_deflects_it_as_the_cantilever_closed_form():
    """A pendulum of mass m hung from the tip of a horizontal cantilever (every mode
    kept: the FE solution, exact at the nodes for Euler-Bernoulli elements): at rest it
    hangs straight down and the tip sags by m g L^3 / 3EI + rho A g L^4 / 8EI."""
    s = mb.System("hang", gravity=(0, -9.81, 0))
    s.add_body("beam", flexible={"beam": EB, "modes": 6 * 8})      # every DoF
    s.add_joint("clamp", "fixed", "ground", "beam")
    s.add_body("bob", mass=2.0, com=(0, -0.3, 0), inertia=[1e-3, 1e-3, 1e-3])
    s.add_joint("hang", "revolute", "beam", "bob", axis="z", position="tip")
    m = s.compile(effects="-geometric_stiffening")
    eq = mb.equilibrium(m, tol=1e-12)
    red = m.flexible["beam"].reduced
    eta = eq.q[[m.coordinate_index(c) for c in m.modal_coordinates]]
    tip = red.modes[red.node("tip")] @ eta
    A, I = 0.03 * 0.02, 0.02 * 0.03 ** 3 / 12           # b = 0.03 along y: I_z
    sag = 2.0 * 9.81 / (3 * 7e10 * I) + 2700 * A * 9.81 / (8 * 7e10 * I)
    assert tip[1] == pytest.approx(-sag, rel=1e-9)
    # the pendulum hangs plumb: its angle takes back the tip's slope
    assert eq.q[m.coordinate_index("hang")] == pytest.approx(-tip[5], rel=1e-9)


def _pin_and_pendulum(flexible=True, E=7e10):
    """A beam on a pin, a rigid pendulum hanging from its tip (the issue's example)."""
    s = mb.System("pendulum at a tip", gravity=(0, -9.81, 0))
    beam = {**EB, "E": E}
    if flexible:
        s.add_body("beam", flexible={"beam": beam, "modes": 3})
    else:
        rec = _pin_and_pendulum(True)[1]
        s.add_body("beam", mass=rec.mass, com=rec.com, inertia=rec.inertia)
    s.add_joint("pin", "revolute", "ground", "beam", axis="z")
    s.add_body("bob", mass=0.5, com=(0, -0.2, 0), inertia=[1e-3, 1e-3, 1e-3])
    s.add_joint("hang", "revolute", "beam", "bob", axis="z", position=(1.0, 0, 0))
    return s, s.bodies["beam"]


def test_pendulum_at_the_tip_of_a_pinned_beam_conserves_energy():
    s, _ = _pin_and_pendulum()
    m = s.compile(effects="-geometric_stiffening")
    assert [nf.name for nf in m.node_frames] == ["beam.tip"]
    q0 = {"pin": -0.3, "hang": 0.4, "beam_m1": 1e-3, "beam_m2": -2e-4}
    u0 = {"pin": 1.0, "hang": -2.0, "beam_m1": 0.1}
    res = mb.simulate(m, 0.05, q0, u0, rtol=1e-10, atol=1e-12, outputs=("energy",))
    E = res.energy["total"]
    assert np.abs(E - E[0]).max() < 1e-10 * np.abs(res.energy["kinetic"]).max()
    assert np.ptp(res["beam_m1"]) > 1e-3                  # the beam does vibrate


def test_flexibility_off_is_the_rigid_model_bit_for_bit():
    flex, _ = _pin_and_pendulum(True)
    rigid, _ = _pin_and_pendulum(False)
    a = flex.compile(effects="-flexibility_beam")
    b = rigid.compile()
    assert type(a) is Model and a.coordinates == ("pin", "hang")
    ra = mb.simulate(a, 0.3, {"pin": 0.3, "hang": -0.2})
    rb = mb.simulate(b, 0.3, {"pin": 0.3, "hang": -0.2})
    assert np.array_equal(ra.q, rb.q) and np.array_equal(ra.u, rb.u)


# ------------------------------------------------------------------ names and records
def test_node_frames_are_shared_named_and_hidden_from_the_state():
    s = mb.System("names", gravity=(0, 0, 0))
    s.add_body("beam", flexible={"beam": {**EB, "nodes": {"mid": 0.5}}, "modes": 3})
    s.add_joint("pin", "revolute", "ground", "beam", axis="z")
    for name, where in (("a", "tip"), ("b", (1.0, 0, 0)), ("c", "mid")):
        s.add_body(name, mass=0.1, inertia=[1e-4] * 3)
        s.add_joint(name, "revolute", "beam", name, axis="z", position=where)
    s.add_body("root", mass=0.1, inertia=[1e-4] * 3)       # at the clamped root: the frame
    s.add_joint("root", "revolute", "beam", "root", axis="z")
    m = s.compile()
    assert [nf.name for nf in m.node_frames] == ["beam.tip", "beam.mid"]
    assert m.joint("a").parent == m.joint("b").parent == "beam.tip"
    assert m.joint("root").parent == "beam"
    assert m.coordinates == ("pin", "a", "b", "c", "root", "beam_m1", "beam_m2", "beam_m3")
    assert m.joints == ("pin", "a", "b", "c", "root")
    assert "beam.tip" in m.frames                          # the node frames are frames
    with pytest.raises(ModelError, match="joint 'x': position = 'tip' names a node, but "
                                         "'ground' is not a flexible body"):
        s.add_joint("x", "revolute", "ground", "a", axis="z", position="tip")
    with pytest.raises(ModelError, match="joint 'y': position.*no node named 'toe'"):
        s.add_joint("y", "revolute", "beam", "a", axis="z", position="toe")


MODEL = """
[model]
name = "pendulum at a tip"
gravity = [0, -9.81, 0]

[[bodies]]
name = "beam"
flexible = { modes = 3, beam = { length = 1.0, elements = 8, E = 7e10, rho = 2700, nu = 0.3, rect = [0.03, 0.02], theory = "euler-bernoulli" } }

[[bodies]]
name = "bob"
mass = 0.5
com = [0, -0.2, 0]
inertia = [1e-3, 1e-3, 1e-3]

[[joints]]
name = "pin"
kind = "revolute"
child = "beam"
axis = "z"

[[joints]]
name = "hang"
kind = "revolute"
parent = "beam"
child = "bob"
axis = "z"
position = "tip"

[initial]
pin = -0.3
beam_m1 = 1e-3
"""


def test_model_file_joint_at_a_named_node(tmp_path):
    path = tmp_path / "tip.toml"
    path.write_text(MODEL)
    scene = mb.load_model(path)
    s, _ = _pin_and_pendulum()
    m = s.compile()
    assert scene.model.coordinates == m.coordinates
    q, u = scene.q0, np.full(m.nu, 0.3)
    assert np.array_equal(scene.model.forward_dynamics(q, u), m.forward_dynamics(q, u))
