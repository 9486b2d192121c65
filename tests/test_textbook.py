"""The textbook's three systems, built through the Python API, against the closed forms of
EXAMPLES.md (``closed_forms.py``) at random states and random parameter values.

Comparisons are norm-wise relative at 1e-10: every component of a group of quantities that
share units (the accelerations of a model, a force vector, the rod forces R and T) is
compared against ``1e-10 * scale``, with ``scale`` the largest magnitude in the expected
group (never less than a natural scale of the group, e.g. the weight ``m g`` for forces), so
that a quantity that happens to be near zero is not asked for more digits than the
quantities it is computed together with.

The first tests check the transcribed closed forms themselves against independent
derivations (a Newton solve, finite differences of positions and angular momenta), so that a
failure further down points at the engine, not at a typo in the transcription.
"""
import math
import warnings

import numpy as np
import pytest

import closed_forms as cf
import mbdyn as mb
from textbook_systems import (DOUBLE_PENDULUM_DATA, TOP_DATA, double_pendulum_system,
                              rotating_pendulum_system, top_system)

RTOL = 1e-10
N_STATES = 24
METHODS = ("jourdain", "newton-euler")


def assert_group_close(actual, expected, floor=0.0, rtol=RTOL, what=""):
    """``|actual - expected|_inf <= rtol * max(|expected|_inf, floor)``."""
    actual = np.atleast_1d(np.asarray(actual, dtype=float))
    expected = np.atleast_1d(np.asarray(expected, dtype=float))
    assert actual.shape == expected.shape, (what, actual.shape, expected.shape)
    scale = max(np.abs(expected).max(), floor)
    err = np.abs(actual - expected).max()
    assert err <= rtol * scale, (f"{what}: max error {err:.3e} > {rtol:g} * {scale:.3e}\n"
                                 f"  actual   {actual.tolist()}\n  expected {expected.tolist()}")


def loguniform(rng, lo, hi):
    return float(math.exp(rng.uniform(math.log(lo), math.log(hi))))


# =======================================================================================
# Example 1: the rotating pendulum
# =======================================================================================
def random_rotating_pendulum(rng, textbook=False):
    """Random parameters and state; ``textbook=True`` keeps Omega = omega = pi/4 (the text's
    figure) and the rest plausible: a = 1, b = 0.5, c = 0.2, r = 0.3, h = 0.25, l = 0.4,
    m = 1 (the text gives no dimensions)."""
    if textbook:
        p = dict(Omega=math.pi / 4, omega=math.pi / 4, a=1.0, b=0.5, c=0.2, r=0.3, h=0.25,
                 l=0.4, m=1.0, g=9.81)
    else:
        p = dict(Omega=rng.uniform(-4, 4), omega=rng.uniform(-4, 4), a=rng.uniform(0, 2),
                 b=loguniform(rng, 0.05, 2), c=rng.uniform(-0.5, 1), r=loguniform(rng, 0.02, 1),
                 h=rng.uniform(-0.5, 1), l=loguniform(rng, 0.05, 2), m=loguniform(rng, 0.01, 10),
                 g=rng.uniform(1, 20))
    state = dict(beta=rng.uniform(-math.pi, math.pi), beta_dot=rng.uniform(-6, 6),
                 t=rng.uniform(0, 10))
    return p, state


def closed_rotating(p, st):
    return cf.rotating_pendulum(st["beta"], st["beta_dot"], st["t"], p["Omega"], p["omega"],
                                p["b"], p["r"], p["l"], p["m"], g=p["g"])


def rotating_scales(p, st):
    W = p["Omega"] + p["omega"]
    acc = (p["g"] + p["b"] * p["Omega"]**2 + p["r"] * W**2) / p["l"] + W**2
    force = p["m"] * (p["g"] + p["b"] * p["Omega"]**2 + p["r"] * W**2
                      + p["l"] * (st["beta_dot"]**2 + W**2 + 2 * abs(W * st["beta_dot"])))
    return acc, force


def test_rotating_pendulum_closed_forms_are_consistent():
    """The transcribed beta'', R, T satisfy Newton with the transcribed B3 a_E, and B3 w3,
    alpha3, a_E agree with finite differences of the text's transformation matrices and
    position vectors (independent of mbdyn)."""
    rng = np.random.default_rng(1)
    for _ in range(10):
        p, st = random_rotating_pendulum(rng)
        beta, bd, t = st["beta"], st["beta_dot"], st["t"]
        bdd, R, T = closed_rotating(p, st)
        w3, al3, aE = cf.rotating_pendulum_kinematics(beta, bd, bdd, t, p["Omega"], p["omega"],
                                                      p["b"], p["r"], p["l"])
        m, g = p["m"], p["g"]
        weight = np.array([0.0, -m * g * math.sin(beta), -m * g * math.cos(beta)])
        _, fscale = rotating_scales(p, st)
        assert_group_close(m * aE - weight, [R, 0.0, T], floor=fscale, what="Newton on E")

        def position(tau):
            b_ = beta + bd * tau + 0.5 * bdd * tau**2
            T1, T2, T3 = cf.rotating_pendulum_transformations(b_, t + tau, p["Omega"], p["omega"])
            return (np.array([0, 0, p["a"]]) + T1.T @ [0, p["b"], 0] + T2.T @ [0, 0, p["c"]]
                    + T2.T @ [0, p["r"], p["h"]] + T3.T @ [0, 0, -p["l"]])

        def T3(tau):
            b_ = beta + bd * tau + 0.5 * bdd * tau**2
            return cf.rotating_pendulum_transformations(b_, t + tau, p["Omega"], p["omega"])[2]

        def w_body(tau, d=1e-6):
            Td = (T3(tau + d) - T3(tau - d)) / (2 * d)
            S = T3(tau) @ Td.T              # [w]x in B3 components
            return np.array([S[2, 1], S[0, 2], S[1, 0]])

        tau = 1e-4
        a_fd = (position(tau) - 2 * position(0) + position(-tau)) / tau**2
        acc, _ = rotating_scales(p, st)
        assert_group_close(T3(0) @ a_fd, aE, floor=acc * p["l"], rtol=1e-5, what="a_E")
        assert_group_close(w_body(0), w3, floor=1.0, rtol=1e-7, what="w3")
        al_fd = (w_body(1e-4) - w_body(-1e-4)) / 2e-4
        assert_group_close(al_fd, al3, floor=acc, rtol=1e-5, what="alpha3")


@pytest.mark.parametrize("method", METHODS)
def test_rotating_pendulum_beta_ddot_R_T(method):
    rng = np.random.default_rng(11)
    for k in range(N_STATES):
        p, st = random_rotating_pendulum(rng, textbook=(k < 4))
        model = rotating_pendulum_system(**p).compile()
        assert model.coordinates == ("beta",)
        assert set(model.driven_joints) == {"Omega", "omega"}
        q, u, t = [st["beta"]], [st["beta_dot"]], st["t"]
        bdd, R, T = closed_rotating(p, st)
        acc, fscale = rotating_scales(p, st)
        ud = model.forward_dynamics(q, u, t=t, method=method)
        assert_group_close(ud, [bdd], floor=acc, what=f"beta'' ({method})")
        reac = model.reactions(q, u, t=t, method=method)
        force, moment = reac["beta"]
        # the rod force on E in B3 components: the text's [R, 0, T]
        T3 = cf.rotating_pendulum_transformations(st["beta"], t, p["Omega"], p["omega"])[2]
        assert_group_close(T3 @ force, [R, 0.0, T], floor=fscale, what=f"[R, 0, T] ({method})")
        # reduced to the hinge D: r_DE x (force on E) = [0,0,-l] x [R,0,T] = [0, -l R, 0]
        assert_group_close(T3 @ moment, [0.0, -p["l"] * R, 0.0], floor=fscale * p["l"],
                           what=f"hinge moment ({method})")


def test_rotating_pendulum_kinematics_as_the_text_writes_them():
    """B3 w3, B3 alpha3 and B3 a_E, and the transformation matrices T of B1, B2, B3."""
    rng = np.random.default_rng(12)
    for k in range(N_STATES):
        p, st = random_rotating_pendulum(rng, textbook=(k < 2))
        model = rotating_pendulum_system(**p).compile()
        beta, bd, t = st["beta"], st["beta_dot"], st["t"]
        bdd = rng.uniform(-20, 20)          # kinematics hold for any beta''
        kin = model.kinematics([beta], [bd], [bdd], t=t)
        w3, al3, aE = cf.rotating_pendulum_kinematics(beta, bd, bdd, t, p["Omega"], p["omega"],
                                                      p["b"], p["r"], p["l"])
        i = kin.frame("pendulum")
        W = p["Omega"] + p["omega"]
        assert_group_close(kin.w_body[i], w3, floor=abs(W) + 1e-3, what="B3 w3")
        assert_group_close(kin.alpha_body[i], al3, floor=abs(bdd), what="B3 alpha3")
        acc, _ = rotating_scales(p, st)
        assert_group_close(kin.T[i] @ kin.a_com[i], aE, floor=p["l"] * (acc + abs(bdd)),
                           what="B3 a_E")
        T1, T2, T3 = cf.rotating_pendulum_transformations(beta, t, p["Omega"], p["omega"])
        for name, T in (("arm", T1), ("disk", T2), ("pendulum", T3)):
            assert_group_close(kin.T[kin.frame(name)], T, floor=1.0, what=f"T of {name}")
        # the arm and disk angular velocities: B1 w1 = [0,0,Omega], B2 w2 = [0,0,W]
        assert_group_close(kin.w_body[kin.frame("arm")], [0, 0, p["Omega"]],
                           floor=abs(p["Omega"]) + 1e-3, what="B1 w1")
        assert_group_close(kin.w_body[kin.frame("disk")], [0, 0, W], floor=abs(W) + 1e-3,
                           what="B2 w2")


# =======================================================================================
# Example 2: the double pendulum
# =======================================================================================
def random_double_pendulum(rng, textbook=False):
    if textbook:
        p = dict(DOUBLE_PENDULUM_DATA, g=9.81)
    else:
        m1 = loguniform(rng, 1e-3, 5.0)
        p = dict(m1=m1, m2=m1 * loguniform(rng, 0.01, 100.0), l1=loguniform(rng, 0.02, 2.0),
                 l2=loguniform(rng, 0.02, 2.0), g=rng.uniform(1, 20))
    st = dict(t1=rng.uniform(-math.pi, math.pi), t2=rng.uniform(-math.pi, math.pi),
              dt1=rng.uniform(-8, 8), dt2=rng.uniform(-8, 8))
    return p, st


def double_scales(p, st):
    lmin, lmax = min(p["l1"], p["l2"]), max(p["l1"], p["l2"])
    acc = p["g"] / lmin + (abs(st["dt1"]) + abs(st["dt2"]))**2 * lmax / lmin
    force = (p["m1"] + p["m2"]) * (p["g"] + lmax * (abs(st["dt1"]) + abs(st["dt2"]))**2)
    return acc, force


def test_double_pendulum_listing_agrees_with_a_newton_solve():
    """The listing's closed forms against an independent solve of the particles' Newton
    equations (inertial components; unknowns T1, T2, theta1'', theta2'')."""
    rng = np.random.default_rng(2)
    for k in range(20):
        p, st = random_double_pendulum(rng, textbook=(k < 3))
        m1, m2, l1, l2, g = p["m1"], p["m2"], p["l1"], p["l2"], p["g"]
        t1, t2, dt1, dt2 = st["t1"], st["t2"], st["dt1"], st["dt2"]
        e1 = np.array([-math.sin(t1), -math.cos(t1)])            # O -> particle 1
        n1 = np.array([-math.cos(t1), math.sin(t1)])             # d e1 / d t1
        e2 = np.array([-math.sin(t1 + t2), -math.cos(t1 + t2)])  # particle 1 -> particle 2
        n2 = np.array([-math.cos(t1 + t2), math.sin(t1 + t2)])
        gv = np.array([0.0, -g])
        # a1 = l1 (t1'' n1 - t1'^2 e1);  a2 = a1 + l2 ((t1''+t2'') n2 - (t1'+t2')^2 e2)
        # m1 a1 = -T1 e1 + T2 e2 + m1 g;  m2 a2 = -T2 e2 + m2 g     unknowns [T1, T2, dd1, dd2]
        A = np.zeros((4, 4))
        b = np.zeros(4)
        A[0:2, 0] = e1
        A[0:2, 1] = -e2
        A[0:2, 2] = m1 * l1 * n1
        b[0:2] = m1 * gv + m1 * l1 * dt1**2 * e1
        A[2:4, 1] = e2
        A[2:4, 2] = m2 * (l1 * n1 + l2 * n2)
        A[2:4, 3] = m2 * l2 * n2
        b[2:4] = m2 * gv + m2 * (l1 * dt1**2 * e1 + l2 * (dt1 + dt2)**2 * e2)
        T1, T2, dd1, dd2 = np.linalg.solve(A, b)
        ddt1, ddt2, Tr1, Tr2 = cf.double_pendulum(t1, t2, dt1, dt2, m1, m2, l1, l2, g=g)
        acc, force = double_scales(p, st)
        assert_group_close([ddt1, ddt2], [dd1, dd2], floor=acc, rtol=1e-8, what="accelerations")
        assert_group_close([Tr1, Tr2], [T1, T2], floor=force, rtol=1e-8, what="rod forces")
    # at rest, hanging: the rods carry the weights below them
    _, _, Tr1, Tr2 = cf.double_pendulum(0, 0, 0, 0, 2.0, 3.0, 1.0, 1.0, g=10.0)
    assert Tr1 == pytest.approx(50.0) and Tr2 == pytest.approx(30.0)


@pytest.mark.parametrize("method", METHODS)
def test_double_pendulum_accelerations_and_rod_forces(method):
    rng = np.random.default_rng(21)
    for k in range(N_STATES):
        p, st = random_double_pendulum(rng, textbook=(k < 4))
        model = double_pendulum_system(**p).compile()
        assert model.coordinates == ("theta1", "theta2")
        q = model.q_vector({"theta1": st["t1"], "theta2": st["t2"]})
        u = model.u_vector({"theta1_dot": st["dt1"], "theta2_dot": st["dt2"]})
        t = rng.uniform(0, 5)
        ddt1, ddt2, T1, T2 = cf.double_pendulum(st["t1"], st["t2"], st["dt1"], st["dt2"],
                                                p["m1"], p["m2"], p["l1"], p["l2"], g=p["g"])
        acc, force = double_scales(p, st)
        ud = model.forward_dynamics(q, u, t=t, method=method)
        assert_group_close(ud, [ddt1, ddt2], floor=acc, what=f"theta'' ({method})")
        reac = model.reactions(q, u, t=t, method=method)
        kin = model.kinematics(q, u, ud, t=t)
        T_link1 = kin.T[kin.frame("link1")]
        T_link2 = kin.T[kin.frame("link2")]
        # rod force = +y component in the child frame (the -y axis runs along the rod);
        # a massless rod between pins carries no transverse force and no moment
        F1, M1 = reac["theta1"]
        F2, M2 = reac["theta2"]
        assert_group_close(np.concatenate([T_link1 @ F1, T_link2 @ F2]),
                           [0.0, T1, 0.0, 0.0, T2, 0.0], floor=force, what=f"T1, T2 ({method})")
        assert_group_close(np.concatenate([M1, M2]), np.zeros(6),
                           floor=force * max(p["l1"], p["l2"]), what=f"pin moments ({method})")


def test_double_pendulum_positions_are_the_listings():
    rng = np.random.default_rng(22)
    for k in range(N_STATES):
        p, st = random_double_pendulum(rng, textbook=(k < 2))
        model = double_pendulum_system(**p).compile()
        kin = model.kinematics([st["t1"], st["t2"]], [st["dt1"], st["dt2"]])
        x1, y1, x2, y2 = cf.double_pendulum_positions(st["t1"], st["t2"], p["l1"], p["l2"])
        got = np.concatenate([kin.r_com[kin.frame("link1")], kin.r_com[kin.frame("link2")]])
        assert_group_close(got, [x1, y1, 0.0, x2, y2, 0.0], floor=p["l1"] + p["l2"],
                           what="particle positions")


# =======================================================================================
# Example 3: the heavy top
# =======================================================================================
def random_top(rng, textbook=False):
    if textbook:
        p = dict(TOP_DATA, Mz=rng.choice([-0.025, -0.001]), g=9.81)
    else:
        m = loguniform(rng, 0.05, 5.0)
        h = loguniform(rng, 0.005, 0.3)
        A_G = m * loguniform(rng, 0.005, 0.1)**2
        C = m * loguniform(rng, 0.005, 0.1)**2      # may break the triangle inequality
        p = dict(m=m, h=h, A=A_G + m * h * h, C=C, Mz=rng.uniform(-0.1, 0.1),
                 g=rng.uniform(1, 20))
    st = dict(psi=rng.uniform(-math.pi, math.pi), theta=rng.uniform(0.25, math.pi - 0.25),
              phi=rng.uniform(-math.pi, math.pi), dpsi=rng.uniform(-15, 15),
              dtheta=rng.uniform(-8, 8), dphi=rng.uniform(-300, 300))
    return p, st


def closed_top(p, st):
    dd = cf.top(st["psi"], st["theta"], st["phi"], st["dpsi"], st["dtheta"], st["dphi"],
                p["m"], p["h"], p["A"], p["C"], p["Mz"], g=p["g"])
    F = cf.top_contact_force_B2(st["theta"], st["dpsi"], st["dtheta"], dd[0], dd[1],
                                p["m"], p["h"], g=p["g"])
    return np.array(dd), F


def build_top(p, joint):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", mb.ModelWarning)
        return top_system(**p, joint=joint).compile()


def test_top_listing_agrees_with_the_angular_momentum_theorem():
    """The listing's psi'', theta'', phi'' against ``dH_O/dt = M_O`` by central differences of
    the angular momentum about O (inertial components), independent of mbdyn; and the
    contact force against finite differences of the centre of mass position."""
    rng = np.random.default_rng(3)
    for k in range(12):
        p, st = random_top(rng, textbook=(k < 2))
        dd, F = closed_top(p, st)
        I_O = np.diag([p["A"], p["A"], p["C"]])
        ang = np.array([st["psi"], st["theta"], st["phi"]])
        rates = np.array([st["dpsi"], st["dtheta"], st["dphi"]])

        def at(tau):
            a = ang + rates * tau + 0.5 * dd * tau**2
            r = rates + dd * tau
            return a, r

        def H(tau):
            a, r = at(tau)
            T2 = cf.top_B2(a[0], a[1])
            return T2.T @ (I_O @ cf.top_angular_velocity_B2(a[1], r[0], r[1], r[2]))

        def r_G(tau):
            a, _ = at(tau)
            return cf.top_B2(a[0], a[1]).T @ [0.0, 0.0, p["h"]]

        d = 1e-5
        dH = (H(d) - H(-d)) / (2 * d)
        T2 = cf.top_B2(st["psi"], st["theta"])
        weight = np.array([0.0, 0.0, -p["m"] * p["g"]])
        M_O = np.cross(r_G(0), weight) + T2.T @ [0.0, 0.0, p["Mz"]]
        assert_group_close(dH, M_O, floor=np.abs(dH).max(), rtol=1e-6, what="dH/dt = M_O")
        d = 1e-4
        a_G = (r_G(d) - 2 * r_G(0) + r_G(-d)) / d**2
        assert_group_close(T2 @ (p["m"] * a_G - weight), F, floor=p["m"] * p["g"], rtol=1e-5,
                           what="contact force")


def test_top_textbook_data_warns_and_runs():
    """The listing's data break the triangle inequality about the centre of mass: a
    ModelWarning names the body, the model keeps the message and still runs."""
    with pytest.warns(mb.ModelWarning, match=r"body 'top'.*triangle inequality"):
        s = top_system(**TOP_DATA, Mz=-0.025)
    with warnings.catch_warnings():
        # compile() re-checks and records the warning in model.warnings (it may or may not
        # re-emit it; the warning at add_body above is the one the user sees)
        warnings.simplefilter("ignore", mb.ModelWarning)
        model = s.compile()
    assert any("triangle inequality" in w for w in model.warnings)
    # case a of the listing
    q = [0.0, (15 / 180) * 2 * 3.14159, 0.0]
    u = [(200 / 180) * 2 * 3.14159, 0.0, 7 * 2 * 3.14159]
    p = dict(TOP_DATA, Mz=-0.025, g=9.81)
    dd, F = closed_top(p, dict(psi=q[0], theta=q[1], phi=q[2], dpsi=u[0], dtheta=u[1],
                               dphi=u[2]))
    for method in METHODS:
        assert_group_close(model.forward_dynamics(q, u, method=method), dd, what=method)
    res = mb.simulate(model, t_end=0.05, q0=dict(zip(model.coordinates, q)),
                      u0=dict(zip(model.speeds, u)), integrator="RK45", rtol=1e-8, atol=1e-10)
    assert np.all(np.isfinite(res.q)) and res.t[-1] == pytest.approx(0.05)


@pytest.mark.parametrize("method", METHODS)
def test_top_euler_angles_and_contact_force(method):
    rng = np.random.default_rng(31)
    for k in range(N_STATES):
        p, st = random_top(rng, textbook=(k < 4))
        model = build_top(p, "euler")
        assert model.coordinates == ("psi", "theta", "phi")
        q = [st["psi"], st["theta"], st["phi"]]
        u = [st["dpsi"], st["dtheta"], st["dphi"]]
        t = rng.uniform(0, 10)
        dd, F = closed_top(p, st)
        ud = model.forward_dynamics(q, u, t=t, method=method)
        assert_group_close(ud, dd, what=f"psi'', theta'', phi'' ({method})")
        force, moment = model.reactions(q, u, t=t, method=method)["contact"]
        T2 = cf.top_B2(st["psi"], st["theta"])
        assert_group_close(T2 @ force, F, floor=p["m"] * p["g"], what=f"contact force ({method})")
        # a point contact transmits no moment
        assert_group_close(moment, np.zeros(3), floor=np.abs(F).max() * p["h"],
                           what=f"contact moment ({method})")


@pytest.mark.parametrize("method", METHODS)
def test_top_quaternion_joint_and_contact_force(method):
    """The same states through a spherical (quaternion) joint: speeds are the top's angular
    velocity in its own axes, their rates its angular acceleration there."""
    rng = np.random.default_rng(32)
    for k in range(N_STATES):
        p, st = random_top(rng, textbook=(k < 4))
        model = build_top(p, "spherical")
        assert model.nq == 4 and model.nu == 3
        ang = (st["psi"], st["theta"], st["phi"])
        rates = (st["dpsi"], st["dtheta"], st["dphi"])
        dd, F = closed_top(p, st)
        w3, alpha3 = cf.top_body_rates(*ang, *rates, *dd)
        q = cf.quaternion_zxz(*ang)
        t = rng.uniform(0, 10)
        kin = model.kinematics(q, w3, t=t)
        i = kin.frame("top")
        assert_group_close(kin.T[i], cf.top_body_T(*ang), floor=1.0, what="attitude")
        assert_group_close(kin.w_body[i], w3, floor=1.0, what="angular velocity")
        ud = model.forward_dynamics(q, w3, t=t, method=method)
        assert_group_close(ud, alpha3, what=f"body angular acceleration ({method})")
        force, _ = model.reactions(q, w3, t=t, method=method)["contact"]
        T2 = cf.top_B2(st["psi"], st["theta"])
        assert_group_close(T2 @ force, F, floor=p["m"] * p["g"], what=f"contact force ({method})")


def test_quaternion_helper_matches_the_text_matrices():
    """``quaternion_zxz`` (used above) is the transpose of ``T_z(phi) T_x(theta) T_z(psi)``."""
    rng = np.random.default_rng(4)
    for _ in range(10):
        a = rng.uniform(-math.pi, math.pi, 3)
        q = cf.quaternion_zxz(*a)
        assert abs(np.linalg.norm(q) - 1) < 1e-14
        np.testing.assert_allclose(cf.quaternion_matrix(q), cf.top_body_T(*a).T, atol=1e-14)
