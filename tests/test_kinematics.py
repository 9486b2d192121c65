"""Kinematics and Jacobians: against finite differences on random trees, and against
hand-written formulas for each joint kind (the textbook's ZXZ top among them).

Finite differences follow the motion ``q(t +- h) = q +- h N(q) u`` (``Model.coordinate_rates``),
``u(t +- h) = u +- h u'``, ``t +- h`` (drives move with time): central differences of
positions give velocities, of velocities give accelerations; ``R' R^T`` is the skew matrix
of the angular velocity.
"""
import numpy as np
import pytest

import mbdyn as mb
from random_trees import axis_rotation, cached_tree, quat_mul, quat_to_matrix, skew

SEEDS = range(30)
H = 1e-6


def vee(W):
    return np.array([W[2, 1] - W[1, 2], W[0, 2] - W[2, 0], W[1, 0] - W[0, 1]]) / 2


def angular_velocity_fd(Rp, Rm, R, h):
    """Angular velocities (world) from central differences of rotation matrices, and the
    largest symmetric part of ``R' R^T`` (must vanish)."""
    W = np.einsum("nij,nkj->nik", (Rp - Rm) / (2 * h), R)
    sym = np.abs(W + np.transpose(W, (0, 2, 1))).max()
    return np.array([vee(x) for x in W]), sym


def close(a, b, tol, what):
    a, b = np.asarray(a), np.asarray(b)
    scale = 1.0 + max(np.abs(a).max(initial=0), np.abs(b).max(initial=0))
    err = np.abs(a - b).max(initial=0) / scale
    assert err <= tol, f"{what}: differs by {err:.2e} (relative to {scale:.3g})"


# ----------------------------------------------------------------------------- random trees
@pytest.mark.parametrize("seed", SEEDS)
def test_velocities_are_derivatives_of_positions(seed):
    tr = cached_tree(seed)
    m, q, u, t = tr.model, tr.q, tr.u, tr.t
    kin = m.kinematics(q, u, t=t)
    qd = m.coordinate_rates(q, u)
    kp = m.kinematics(q + H * qd, u, t=t + H)
    km = m.kinematics(q - H * qd, u, t=t - H)
    close(kin.v, (kp.r - km.r) / (2 * H), 1e-7, f"seed {seed}: frame velocities")
    close(kin.v_com, (kp.r_com - km.r_com) / (2 * H), 1e-7, f"seed {seed}: com velocities")
    w, sym = angular_velocity_fd(kp.R, km.R, kin.R, H)
    assert sym < 1e-7 * (1 + np.abs(w).max())
    close(kin.w, w, 1e-7, f"seed {seed}: angular velocities (R' = [w]x R)")
    # rotation matrices are proper and the body-frame views are consistent
    RtR = np.einsum("nji,njk->nik", kin.R, kin.R)
    assert np.abs(RtR - np.eye(3)).max() < 1e-12
    assert np.all(np.abs(np.linalg.det(kin.R) - 1) < 1e-12)
    close(kin.w_body, np.einsum("nji,nj->ni", kin.R, kin.w), 1e-14, "w_body")
    close(kin.T, np.transpose(kin.R, (0, 2, 1)), 0, "T = R^T")


@pytest.mark.parametrize("seed", SEEDS)
def test_accelerations_are_derivatives_of_velocities(seed):
    tr = cached_tree(seed)
    m, q, u, t = tr.model, tr.q, tr.u, tr.t
    ud = np.random.default_rng(seed).normal(size=m.nu)
    kin = m.kinematics(q, u, ud, t=t)
    qd = m.coordinate_rates(q, u)
    kp = m.kinematics(q + H * qd, u + H * ud, t=t + H)
    km = m.kinematics(q - H * qd, u - H * ud, t=t - H)
    close(kin.a, (kp.v - km.v) / (2 * H), 1e-7, f"seed {seed}: frame accelerations")
    close(kin.a_com, (kp.v_com - km.v_com) / (2 * H), 1e-7, f"seed {seed}: com accelerations")
    close(kin.alpha, (kp.w - km.w) / (2 * H), 1e-7, f"seed {seed}: angular accelerations")
    close(kin.alpha_body, np.einsum("nji,nj->ni", kin.R, kin.alpha), 1e-14, "alpha_body")
    # without ud: the velocity-product part, i.e. the accelerations at ud = 0
    k0 = m.kinematics(q, u, t=t)
    kz = m.kinematics(q, u, np.zeros(m.nu), t=t)
    close(k0.a, kz.a, 0, "bias acceleration")
    close(k0.alpha, kz.alpha, 0, "bias angular acceleration")


@pytest.mark.parametrize("seed", SEEDS)
def test_jacobians_match_velocities_and_finite_differences(seed):
    tr = cached_tree(seed)
    m, q, u, t = tr.model, tr.q, tr.u, tr.t
    rng = np.random.default_rng(1000 + seed)
    points = rng.uniform(-0.5, 0.5, (m.n_frames, 3))
    JT = np.array([m.jacobian_translation(q, f, points[i], t=t) for i, f in enumerate(m.frames)])
    JR = np.array([m.jacobian_rotation(q, f, t=t) for f in m.frames])
    assert JT.shape == JR.shape == (m.n_frames, 3, m.nu)

    def point_velocity(kin):
        return kin.v + np.cross(kin.w, np.einsum("nij,nj->ni", kin.R, points))

    # velocity is affine in u with the Jacobians as its slope (drives give the offset)
    k1 = m.kinematics(q, u, t=t)
    k0 = m.kinematics(q, np.zeros(m.nu), t=t)
    close(point_velocity(k1), point_velocity(k0) + JT @ u, 1e-12, "v = v(u=0) + J_T u")
    close(k1.w, k0.w + JR @ u, 1e-12, "w = w(u=0) + J_R u")
    # each column: the motion of the point when only that speed is 1 (time frozen)
    for k in range(m.nu):
        e = np.zeros(m.nu)
        e[k] = 1.0
        qd = m.coordinate_rates(q, e)
        kp = m.kinematics(q + H * qd, u, t=t)
        km = m.kinematics(q - H * qd, u, t=t)
        rp = kp.r + np.einsum("nij,nj->ni", kp.R, points)
        rm = km.r + np.einsum("nij,nj->ni", km.R, points)
        close(JT[:, :, k], (rp - rm) / (2 * H), 1e-7, f"seed {seed}: J_T column {m.speeds[k]}")
        w, _ = angular_velocity_fd(kp.R, km.R, k1.R, H)
        close(JR[:, :, k], w, 1e-7, f"seed {seed}: J_R column {m.speeds[k]}")
    # default point: the centre of mass (frame origin of a massless frame)
    for i, f in enumerate(m.frames):
        com = m.body(f).com
        close(m.jacobian_translation(q, f, t=t), m.jacobian_translation(q, f, com, t=t), 0,
              "default point")


@pytest.mark.parametrize("seed", SEEDS)
def test_coordinate_rates(seed):
    """q' = N(q) u: angle and displacement rates are the speeds; a quaternion's rate is
    1/2 q (x) (0, w) with w in child components, orthogonal to q."""
    tr = cached_tree(seed)
    m, q, u = tr.model, tr.q, tr.u
    qd = m.coordinate_rates(q, u)
    for name in m.joints:
        j = m.joint(name)
        if j.drive is not None or j.kind == "fixed":
            continue
        qi = [m.coordinate_index(c) for c in j.coordinates]
        ui = [m.speed_index(s) for s in j.speeds]
        if j.kind in ("revolute", "prismatic", "euler"):
            assert np.array_equal(qd[qi], u[ui])
            continue
        if j.kind == "free":
            assert np.array_equal(qd[qi[:3]], u[ui[:3]])
            qi, ui = qi[3:], ui[3:]
        expected = 0.5 * quat_mul(q[qi], np.concatenate([[0.0], u[ui]]))
        close(qd[qi], expected, 1e-15, f"quaternion rate of {name}")
        assert abs(q[qi] @ qd[qi]) < 1e-14 * (1 + np.abs(u[ui]).max())


# ----------------------------------------------------------------------------- joint by joint
def Rz(a):
    return axis_rotation(2, a)


def Rx(a):
    return axis_rotation(0, a)


def Ry(a):
    return axis_rotation(1, a)


def Tz(a):
    """The textbook's T_z(a) (parent components -> rotated components)."""
    return Rz(a).T


def Tx(a):
    return Rx(a).T


def test_revolute_about_z_by_hand():
    s = mb.System("revolute")
    s.add_body("arm", mass=2.0, com=(0.7, 0, 0), inertia=(0.1, 0.2, 0.3))
    s.add_joint("a", "revolute", "ground", "arm", axis="z")
    m = s.compile()
    a, ad, add = 0.8, 1.3, -0.4
    k = m.kinematics([a], [ad], [add])
    c, sn = np.cos(a), np.sin(a)
    assert np.allclose(k.R[0], [[c, -sn, 0], [sn, c, 0], [0, 0, 1]], atol=1e-15)
    assert np.allclose(k.T[0], [[c, sn, 0], [-sn, c, 0], [0, 0, 1]], atol=1e-15)  # T_z(a)
    assert np.allclose(k.r[0], 0) and np.allclose(k.v[0], 0)
    assert np.allclose(k.r_com[0], [0.7 * c, 0.7 * sn, 0], atol=1e-15)
    assert np.allclose(k.w[0], [0, 0, ad]) and np.allclose(k.alpha[0], [0, 0, add])
    assert np.allclose(k.v_com[0], 0.7 * ad * np.array([-sn, c, 0]), atol=1e-15)
    assert np.allclose(k.a_com[0], 0.7 * (add * np.array([-sn, c, 0])
                                          - ad**2 * np.array([c, sn, 0])), atol=1e-14)
    assert np.allclose(m.jacobian_translation([a], "arm"), [[-0.7 * sn], [0.7 * c], [0]])
    assert np.allclose(m.jacobian_rotation([a], "arm"), [[0], [0], [1]])
    assert m.coordinates == ("a",) and m.speeds == ("a_dot",)


def test_revolute_with_placement_by_hand():
    s = mb.System("placed revolute")
    s.add_body("b", mass=1.0, inertia=(0.1, 0.1, 0.1))
    s.add_joint("j", "revolute", "ground", "b", axis="z", position=(1, 2, 3),
                orientation=("x", np.pi / 2))
    m = s.compile()
    C = np.array([[1, 0, 0], [0, 0, -1], [0, 1, 0]])        # 90 degrees about x
    a, ad = 0.6, 2.0
    k = m.kinematics([a], [ad])
    assert np.allclose(k.R[0], C @ Rz(a), atol=1e-15)
    assert np.allclose(k.r[0], [1, 2, 3])
    assert np.allclose(k.w[0], [0, -ad, 0], atol=1e-15)     # C e_z = -e_y
    p = np.array([1.0, 0, 0])                               # a point on the body
    c, sn = np.cos(a), np.sin(a)
    assert np.allclose(k.r[0] + k.R[0] @ p, [1 + c, 2, 3 + sn], atol=1e-15)
    assert np.allclose(m.jacobian_translation([a], "b", p)[:, 0], [-sn, 0, c], atol=1e-15)


def test_revolute_about_a_general_axis_by_hand():
    n = np.array([1.0, 2.0, 2.0]) / 3.0
    s = mb.System("tilted")
    s.add_body("b", mass=1.0, inertia=(0.1, 0.2, 0.3))
    s.add_joint("j", "revolute", "ground", "b", axis=(1, 2, 2))
    m = s.compile()
    a = 1.1
    K = skew(n)
    R = np.eye(3) + np.sin(a) * K + (1 - np.cos(a)) * K @ K      # Rodrigues
    k = m.kinematics([a], [0.5])
    assert np.allclose(k.R[0], R, atol=1e-15)
    assert np.allclose(k.w[0], 0.5 * n)
    assert np.allclose(k.R[0] @ n, n)                           # the axis is fixed


def test_prismatic_by_hand():
    s = mb.System("slider", gravity=(0, 0, 0))
    s.add_body("base", mass=1.0, inertia=(0.1, 0.1, 0.1))
    s.add_joint("spin", "revolute", "ground", "base", axis="z")
    s.add_body("slider", mass=1.0, inertia=(0.1, 0.1, 0.1))
    s.add_joint("x", "prismatic", "base", "slider", axis=(1, 1, 0), position=(0, 0, 0.5),
                orientation=(np.cos(np.pi / 4), 0, 0, np.sin(np.pi / 4)))  # 90 deg about z
    m = s.compile()
    C = Rz(np.pi / 2)
    n = C @ np.array([1, 1, 0]) / np.sqrt(2)                   # (-1, 1, 0)/sqrt 2
    a, ad, x, xd, xdd = 0.4, 1.5, 0.3, -0.7, 0.2
    k = m.kinematics([a, x], [ad, xd], [0.0, xdd])
    i = k.frame("slider")
    d = np.array([0, 0, 0.5]) + x * n                          # in the base frame
    assert np.allclose(k.R[i], Rz(a) @ C, atol=1e-15)
    assert np.allclose(k.r[i], Rz(a) @ d, atol=1e-15)
    w = np.array([0, 0, ad])
    vrel = Rz(a) @ (xd * n)
    assert np.allclose(k.v[i], np.cross(w, Rz(a) @ d) + vrel, atol=1e-14)
    # centripetal + Coriolis + relative
    acc = np.cross(w, np.cross(w, Rz(a) @ d)) + 2 * np.cross(w, vrel) + Rz(a) @ (xdd * n)
    assert np.allclose(k.a[i], acc, atol=1e-14)


def top_model(sequence="ZXZ", h=0.0558):
    s = mb.System("top")
    s.add_body("disk", mass=0.582, com=(0, 0, h), inertia=(2e-4, 2e-4, 3e-4))
    s.add_joint("top", "euler", "ground", "disk", sequence=sequence,
                coordinates=("psi", "theta", "phi"))
    return s.compile()


def test_euler_zxz_matches_the_textbook_top():
    """EXAMPLES.md, heavy top: B1 = T_z(psi) I, B2 = T_x(theta) B1, body = T_z(phi) B2;
    B2 omega = [theta', psi' sin theta, psi' cos theta + phi'] and B2 a_G."""
    h = 0.0558
    m = top_model(h=h)
    assert m.coordinates == ("psi", "theta", "phi")
    psi, th, phi = 0.7, 0.5, -1.2
    psid, thd, phid = 1.3, -0.8, 40.0
    psidd, thdd, phidd = 0.4, 2.1, -3.0
    k = m.kinematics([psi, th, phi], [psid, thd, phid], [psidd, thdd, phidd])
    T = Tz(phi) @ Tx(th) @ Tz(psi)
    assert np.allclose(k.T[0], T, atol=1e-15)
    s, c = np.sin(th), np.cos(th)
    w2 = np.array([thd, psid * s, psid * c + phid])             # B2 components
    assert np.allclose(k.w_body[0], Tz(phi) @ w2, atol=1e-13)
    T2 = Tx(th) @ Tz(psi)                                        # I -> B2
    assert np.allclose(T2 @ k.w[0], w2, atol=1e-13)
    # angular acceleration in B2: d/dt w2 + Omega x w2, Omega = B2 frame's own rate
    alpha2 = np.array([thdd + phid * psid * s,
                       psidd * s + psid * thd * c - phid * thd,
                       psidd * c - psid * thd * s + phidd])
    assert np.allclose(T2 @ k.alpha[0], alpha2, atol=1e-12)
    aG2 = h * np.array([2 * psid * thd * c + psidd * s,
                        psid**2 * s * c - thdd,
                        -psid**2 * s**2 - thd**2])
    assert np.allclose(T2 @ k.a_com[0], aG2, atol=1e-14)
    assert np.allclose(T2 @ k.r_com[0], [0, 0, h], atol=1e-15)


@pytest.mark.parametrize("sequence", ["XYZ", "ZYX", "YXY"])
def test_other_euler_sequences_by_hand(sequence):
    m = top_model(sequence)
    rot = {"X": Rx, "Y": Ry, "Z": Rz}
    e = {"X": np.eye(3)[0], "Y": np.eye(3)[1], "Z": np.eye(3)[2]}
    a, b, c = 0.3, 0.9, -0.5
    ad, bd, cd = 0.7, -1.1, 2.0
    k = m.kinematics([a, b, c], [ad, bd, cd])
    R0, R1, R2 = rot[sequence[0]](a), rot[sequence[1]](b), rot[sequence[2]](c)
    assert np.allclose(k.R[0], R0 @ R1 @ R2, atol=1e-15)
    w_world = ad * e[sequence[0]] + bd * R0 @ e[sequence[1]] + cd * R0 @ R1 @ e[sequence[2]]
    assert np.allclose(k.w[0], w_world, atol=1e-14)


def test_spherical_by_hand():
    s = mb.System("ball")
    s.add_body("b", mass=1.0, com=(0, 0, -1), inertia=(0.1, 0.2, 0.3))
    s.add_joint("ball", "spherical", "ground", "b", position=(0, 0, 2))
    m = s.compile()
    assert m.coordinates == ("ball_qw", "ball_qx", "ball_qy", "ball_qz")
    n = np.array([2.0, -1.0, 2.0]) / 3
    a = 0.9
    q = np.concatenate([[np.cos(a / 2)], np.sin(a / 2) * n])
    K = skew(n)
    R = np.eye(3) + np.sin(a) * K + (1 - np.cos(a)) * K @ K
    u = np.array([0.3, -0.2, 1.5])                 # angular velocity, child components
    k = m.kinematics(q, u)
    assert np.allclose(k.R[0], R, atol=1e-15)
    assert np.allclose(k.w[0], R @ u, atol=1e-15)
    assert np.allclose(k.w_body[0], u, atol=1e-15)
    assert np.allclose(k.r_com[0], [0, 0, 2] + R @ [0, 0, -1], atol=1e-15)
    assert np.allclose(k.v_com[0], np.cross(R @ u, R @ [0, 0, -1]), atol=1e-15)
    assert np.allclose(m.coordinate_rates(q, u),
                       0.5 * quat_mul(q, np.concatenate([[0], u])), atol=1e-16)


def test_free_joint_by_hand():
    s = mb.System("free")
    s.add_body("base", mass=1.0, inertia=(0.1, 0.1, 0.1))
    s.add_joint("spin", "revolute", "ground", "base", axis="z")
    s.add_body("b", mass=1.0, inertia=(0.1, 0.2, 0.3))
    s.add_joint("fly", "free", "base", "b", position=(0.5, 0, 0), orientation=("y", 0.3))
    m = s.compile()
    assert m.coordinates == ("spin", "fly_x", "fly_y", "fly_z", "fly_qw", "fly_qx", "fly_qy",
                             "fly_qz")
    quat = np.array([1.0, 2.0, -1.0, 0.5])
    quat /= np.linalg.norm(quat)
    x = np.array([0.1, -0.2, 0.3])
    a, ad = 0.25, 0.0                                     # parent at rest: plain relative motion
    u = np.array([ad, 1.0, 2.0, -0.5, 0.4, 0.1, -0.3])
    k = m.kinematics(np.concatenate([[a], x, quat]), u)
    C = Ry(0.3)
    i = k.frame("b")
    assert np.allclose(k.R[i], Rz(a) @ C @ quat_to_matrix(quat), atol=1e-15)
    assert np.allclose(k.r[i], Rz(a) @ ([0.5, 0, 0] + C @ x), atol=1e-15)
    assert np.allclose(k.v[i], Rz(a) @ C @ u[1:4], atol=1e-15)      # J0 components
    assert np.allclose(k.w[i], k.R[i] @ u[4:7], atol=1e-15)         # child components
    qd = m.coordinate_rates(np.concatenate([[a], x, quat]), u)
    assert np.allclose(qd[1:4], u[1:4])
    assert np.allclose(qd[4:], 0.5 * quat_mul(quat, np.concatenate([[0], u[4:]])))


def test_fixed_joint_by_hand():
    s = mb.System("fixed")
    s.add_body("arm", mass=1.0, inertia=(0.1, 0.1, 0.1))
    s.add_joint("a", "revolute", "ground", "arm", axis="z")
    s.add_body("tip", mass=0.5, inertia=(0.01, 0.01, 0.01))
    s.add_joint("weld", "fixed", "arm", "tip", position=(1, 0, 0), orientation=("x", 0.5))
    s.add_frame("marker")
    s.add_joint("mark", "fixed", "tip", "marker", position=(0, 0.2, 0))
    m = s.compile()
    assert m.nq == m.nu == 1
    a, ad, add = 0.3, 2.0, 0.5
    k = m.kinematics([a], [ad], [add])
    i, j = k.frame("tip"), k.frame("marker")
    assert np.allclose(k.R[i], Rz(a) @ Rx(0.5), atol=1e-15)
    assert np.allclose(k.R[j], k.R[i], atol=1e-15)
    r_tip = Rz(a) @ [1, 0, 0]
    assert np.allclose(k.r[i], r_tip)
    assert np.allclose(k.r[j], r_tip + Rz(a) @ Rx(0.5) @ [0, 0.2, 0])
    assert np.allclose(k.w[j], [0, 0, ad]) and np.allclose(k.alpha[j], [0, 0, add])
    w = np.array([0, 0, ad])
    assert np.allclose(k.a[j], np.cross([0, 0, add], k.r[j]) + np.cross(w, np.cross(w, k.r[j])))


def test_driven_joint_kinematics_follow_the_expression():
    """A driven revolute has no coordinate; its angle, rate and acceleration come from the
    sympy expression exactly."""
    Om = 0.75
    s = mb.System("arm")
    s.add_frame("arm")
    s.add_joint("Omega", "revolute", "ground", "arm", axis="z", drive=Om * mb.t + 0.2 * mb.t**2)
    s.add_body("m", mass=1.0, com=(0, 0, -1))
    s.add_joint("beta", "revolute", "arm", "m", axis="x", position=(0, 1, 0))
    m = s.compile()
    assert m.coordinates == ("beta",) and m.driven_joints == ("Omega",)
    t = 1.7
    k = m.kinematics([0.0], [0.0], [0.0], t=t)
    ang, rate, acc = Om * t + 0.2 * t**2, Om + 0.4 * t, 0.4
    i = k.frame("arm")
    assert np.allclose(k.R[i], Rz(ang), atol=1e-15)
    assert np.allclose(k.w[i], [0, 0, rate]) and np.allclose(k.alpha[i], [0, 0, acc])
    j = k.frame("m")
    assert np.allclose(k.r[j], Rz(ang) @ [0, 1, 0])
    # the pivot moves on a circle of radius 1
    assert np.allclose(k.a[j], Rz(ang) @ [-acc, -rate**2, 0])
