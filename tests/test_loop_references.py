"""Self-tests of the closed forms in ``tests/loop_references.py``, each against an
independent route (a numeric solve of the loop with scipy, finite differences, a Lagrange
computation, the published data), and of the loop models' geometry
(``tests/loop_model_check.py``).  Nothing here runs mbdyn; all of it takes a second or two.
"""
import math

import loop_model_check as check
import loop_references as ref
import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.optimize import brentq, least_squares, minimize_scalar

FOURBARS = [(0.1, 0.35, 0.3, 0.4),          # models/four_bar.toml
            (1.0, 3.0, 2.5, 2.2)]           # another crank-rocker
# models/four_bar.toml's links: masses, centres (along, across), inertias about them
W = 0.02
LINKS = {"masses": (0.5, 1.2, 1.0), "coms": ((0.05, 0.0), (0.175, 0.03), (0.15, 0.0)),
         "inertias": tuple(m * (L * L + W * W) / 12
                           for m, L in ((0.5, 0.1), (1.2, 0.35), (1.0, 0.3)))}


def wrapped(x):
    return np.abs(ref.wrap(np.asarray(x)))


def fsolve(f, x0):
    """A root of ``f`` near ``x0``: scipy's Levenberg-Marquardt at tolerances near
    round-off (MINPACK's hybrid method warns at such tolerances)."""
    return least_squares(f, np.asarray(x0, float), method="lm", xtol=1e-15, ftol=1e-15,
                         gtol=1e-15).x


# ======================================================================== four-bar
def numeric_fourbar(theta2s, a, b, c, d, start):
    """(theta3, theta4) along theta2s by fsolve on the vector loop, each step started
    from the previous solution (continuation from ``start``)."""
    out, x = [], np.asarray(start, float)
    for t2 in theta2s:
        def loop(x, t2=t2):
            return [a * math.cos(t2) + b * math.cos(x[0]) - c * math.cos(x[1]) - d,
                    a * math.sin(t2) + b * math.sin(x[0]) - c * math.sin(x[1])]
        x = fsolve(loop, x)
        out.append(x.copy())
    return np.array(out).T


@pytest.mark.parametrize("links", FOURBARS)
def test_freudenstein_closes_the_loop_over_a_full_turn_on_both_branches(links):
    a, b, c, d = links
    t2 = np.linspace(0, 2 * np.pi, 361)
    signs = {}
    for branch in ("open", "crossed"):
        t3, t4 = ref.fourbar_positions(t2, a, b, c, d, branch)
        assert np.all(np.isfinite(t3)) and np.all(np.isfinite(t4))
        residual = ref.fourbar_loop_residual(t2, t3, t4, a, b, c, d)
        assert np.abs(residual).max() < 1e-14 * (a + b + c + d)
        s = np.sign(np.sin(t4 - t3))
        assert np.all(s == s[0])                 # the branch keeps its orientation
        signs[branch] = s[0]
    assert signs["open"] == -signs["crossed"]


@pytest.mark.parametrize("links", FOURBARS)
def test_freudenstein_agrees_with_a_numeric_solve_of_the_loop_on_both_branches(links):
    a, b, c, d = links
    t2 = np.linspace(0, 2 * np.pi, 73)
    for branch in ("open", "crossed"):
        t3, t4 = ref.fourbar_positions(t2, a, b, c, d, branch)
        n3, n4 = numeric_fourbar(t2, a, b, c, d, start=(t3[0] + 0.1, t4[0] - 0.1))
        assert wrapped(n3 - t3).max() < 1e-10 and wrapped(n4 - t4).max() < 1e-10


def test_the_two_branches_are_mirror_images_at_a_crank_on_the_ground_line():
    a, b, c, d = FOURBARS[0]
    o3, o4 = ref.fourbar_positions(0.0, a, b, c, d, "open")
    x3, x4 = ref.fourbar_positions(0.0, a, b, c, d, "crossed")
    assert o3 == pytest.approx(-x3, abs=1e-14) and o4 == pytest.approx(-x4, abs=1e-14)
    assert math.degrees(o3) == pytest.approx(54.31, abs=0.01)       # the model's comment
    assert math.degrees(o4) == pytest.approx(108.63, abs=0.01)


@pytest.mark.parametrize("branch", ["open", "crossed"])
@pytest.mark.parametrize("links", FOURBARS)
def test_angular_velocities_and_accelerations_match_finite_differences(links, branch):
    a, b, c, d = links
    h = 1e-4
    for t0, w2, al2 in ((0.3, 2.0, 0.0), (2.0, -1.5, 4.0), (4.5, 7.0, -3.0)):
        def angles(t, t0=t0, w2=w2, al2=al2):
            t2 = t0 + w2 * t + 0.5 * al2 * t * t
            return ref.fourbar_positions(t2, a, b, c, d, branch)
        ts = np.array([-2 * h, -h, 0.0, h, 2 * h])
        th = np.unwrap(np.array([angles(t) for t in ts]).T, axis=1)      # (2, 5)
        rate = (8 * (th[:, 3] - th[:, 1]) - (th[:, 4] - th[:, 0])) / (12 * h)
        acc = (-th[:, 4] + 16 * th[:, 3] - 30 * th[:, 2] + 16 * th[:, 1] - th[:, 0]) / (12 * h * h)
        _, (_, w3, w4), (_, a3, a4) = ref.fourbar_state(t0, w2, al2, a, b, c, d, branch)
        np.testing.assert_allclose([w3, w4], rate, rtol=1e-8, atol=1e-9)
        np.testing.assert_allclose([a3, a4], acc, rtol=1e-5, atol=1e-5)


def test_grashof_classes():
    assert ref.grashof(0.1, 0.35, 0.3, 0.4) == (True, "crank-rocker")
    assert ref.grashof(2.0, 3.0, 3.5, 1.0) == (True, "double-crank")
    assert ref.grashof(2.0, 3.0, 4.0, 1.0) == (True, "change-point")
    assert ref.grashof(3.0, 1.0, 3.5, 3.0) == (True, "double-rocker")
    assert ref.grashof(1.0, 2.0, 1.0, 2.0) == (True, "change-point")
    assert ref.grashof(4.0, 2.0, 3.0, 5.5) == (False, "triple-rocker")


def test_a_non_grashof_crank_cannot_turn_fully():
    a, b, c, d = 4.0, 2.0, 3.0, 5.5
    _, t4 = ref.fourbar_positions(np.linspace(0, 2 * np.pi, 361), a, b, c, d)
    assert np.isnan(t4).any() and np.isfinite(t4).any()


def lagrange_drive_torque(theta2, omega2, alpha2, a, b, c, d, branch, g=(0.0, -ref.G)):
    """tau = J(t2) al2 + J'(t2) w2^2 / 2 + V'(t2) with J, V from a numeric (fsolve) loop
    solution and every derivative by central differences: Lagrange's equation of the
    1-DoF mechanism, independent of the closed forms' velocity formulas."""
    t3c, t4c = ref.fourbar_positions(theta2, a, b, c, d, branch)

    def config(t2):
        x = fsolve(lambda x: [a * math.cos(t2) + b * math.cos(x[0]) - c * math.cos(x[1]) - d,
                              a * math.sin(t2) + b * math.sin(x[0]) - c * math.sin(x[1])],
                   [t3c, t4c])
        angles = (t2, x[0], x[1])
        bases = (np.zeros(2), a * ref.e_(t2), np.array([d, 0.0]))
        coms = [base + p * ref.e_(t) + q * ref.n_(t)
                for base, (p, q), t in zip(bases, LINKS["coms"], angles)]
        return np.array(angles), np.array(coms)

    def d4(f, x, h):            # fourth-order central difference
        return (8 * (f(x + h) - f(x - h)) - (f(x + 2 * h) - f(x - 2 * h))) / (12 * h)

    def J(t2):
        dangles = d4(lambda s: config(s)[0], t2, 1e-3)
        dr = d4(lambda s: config(s)[1], t2, 1e-3)
        return sum(m * dr[k] @ dr[k] + I * dangles[k]**2
                   for k, (m, I) in enumerate(zip(LINKS["masses"], LINKS["inertias"])))

    def V(t2):
        return -sum(m * np.dot(g, r) for m, r in zip(LINKS["masses"], config(t2)[1]))

    return J(theta2) * alpha2 + 0.5 * d4(J, theta2, 4e-3) * omega2**2 + d4(V, theta2, 1e-3)


@pytest.mark.parametrize("branch", ["open", "crossed"])
def test_drive_torque_by_power_balance_equals_lagrange(branch):
    a, b, c, d = FOURBARS[0]
    for t2, w2, al2 in ((0.0, 2 * np.pi, 0.0), (1.3, 2 * np.pi, 0.0), (3.5, -4.0, 0.0),
                        (5.0, 3.0, 10.0)):
        tau = ref.fourbar_drive_torque(t2, w2, al2, a, b, c, d, **LINKS, branch=branch)
        assert tau == pytest.approx(lagrange_drive_torque(t2, w2, al2, a, b, c, d, branch),
                                    rel=1e-7, abs=1e-8)


def test_drive_torque_is_the_rate_of_the_energy_and_averages_to_zero():
    """tau w = dE/dt, with E differenced in time along the constant-speed motion; and at
    constant speed the drive does no net work over a turn (no losses)."""
    a, b, c, d = FOURBARS[0]
    w2, h = 2 * np.pi, 1e-5
    for t2 in (0.2, 2.0, 4.0):
        E = [sum(ref.fourbar_energy(t2 + w2 * s, w2, a, b, c, d, **LINKS)) for s in (-h, h)]
        tau = ref.fourbar_drive_torque(t2, w2, 0.0, a, b, c, d, **LINKS)
        assert tau * w2 == pytest.approx((E[1] - E[0]) / (2 * h), rel=1e-7)
    t2 = np.linspace(0, 2 * np.pi, 2001)[:-1]
    tau = ref.fourbar_drive_torque(t2, w2, 0.0, a, b, c, d, **LINKS)
    assert abs(tau.mean()) < 1e-12 * np.abs(tau).max() + 1e-12


def test_four_bar_model_file_holds_these_links():
    doc = check.load("four_bar")
    p = check.parameters(doc)
    assert (p["a"], p["b"], p["c"], p["d"]) == FOURBARS[0] and ref.grashof(*FOURBARS[0])[0]
    bodies = {b["name"]: b for b in doc["bodies"]}
    for k, name in enumerate(("crank", "coupler", "rocker")):
        body = bodies[name]
        assert check.value(body["mass"], p) == LINKS["masses"][k]
        assert tuple(check.vector(body["com"], p)[:2]) == pytest.approx(LINKS["coms"][k], abs=1e-15)
        assert check.value(body["inertia"][2], p) == pytest.approx(LINKS["inertias"][k], rel=1e-15)


# ======================================================================== slider-crank
SC = {"r": 0.05, "l": 0.16, "e": 0.01}


@pytest.mark.parametrize("e", [0.0, 0.01, -0.02])
def test_slider_crank_position_matches_a_numeric_solve_of_the_loop(e):
    r, l = SC["r"], SC["l"]
    for th in np.linspace(-np.pi, 3 * np.pi, 37):
        phi, x = fsolve(lambda v, th=th: [r * math.cos(th) + l * math.cos(v[0]) - v[1],
                                          r * math.sin(th) + l * math.sin(v[0]) - e],
                        [0.0, l])
        assert ref.slider_crank(th, 0.0, 0.0, r, l, e)[0] == pytest.approx(x, abs=1e-14)
        assert ref.slider_crank_rod(th, 0.0, 0.0, r, l, e)[0] == pytest.approx(phi, abs=1e-13)


def test_slider_crank_without_offset_is_the_textbook_form():
    r, l = SC["r"], SC["l"]
    th = np.linspace(0, 2 * np.pi, 50)
    np.testing.assert_allclose(ref.slider_crank(th, 0, 0, r, l)[0],
                               r * np.cos(th) + np.sqrt(l * l - (r * np.sin(th))**2), atol=1e-15)


@pytest.mark.parametrize("e", [0.0, 0.01])
def test_slider_crank_velocity_and_acceleration_match_finite_differences(e):
    r, l = SC["r"], SC["l"]
    h = 1e-5
    for th0, w, al in ((0.4, 157.0, 0.0), (2.5, -30.0, 500.0), (4.0, 10.0, -80.0)):
        def x(t, th0=th0, w=w, al=al):
            return ref.slider_crank(th0 + w * t + 0.5 * al * t * t, 0, 0, r, l, e)[0]

        def phi(t, th0=th0, w=w, al=al):
            return ref.slider_crank_rod(th0 + w * t + 0.5 * al * t * t, 0, 0, r, l, e)[0]
        for f, exact in ((x, ref.slider_crank(th0, w, al, r, l, e)),
                         (phi, ref.slider_crank_rod(th0, w, al, r, l, e))):
            v = (8 * (f(h) - f(-h)) - (f(2 * h) - f(-2 * h))) / (12 * h)
            acc = (-f(2 * h) + 16 * f(h) - 30 * f(0) + 16 * f(-h) - f(-2 * h)) / (12 * h * h)
            assert exact[1] == pytest.approx(v, rel=1e-8, abs=1e-9)
            assert exact[2] == pytest.approx(acc, rel=1e-4, abs=1e-3)


def test_gas_pressure_table_cycle_and_mean_torque():
    p = ref.gas_pressure
    assert p(np.radians(15.0)) == pytest.approx(52e5)
    assert p(0.0) == pytest.approx(38e5) and p(-np.pi) == pytest.approx(0.0)
    th = np.linspace(-7, 7, 101)
    np.testing.assert_allclose(p(th + 4 * np.pi), p(th), atol=1e-6)       # a 4 pi cycle
    # mean torque = work per cycle / (4 pi), the work integrated along x instead
    r, l, e = SC["r"], SC["l"], SC["e"]
    area = math.pi * 0.08**2 / 4
    theta = np.linspace(-2 * np.pi, 2 * np.pi, 200001)
    x = ref.slider_crank(theta, 0, 0, r, l, e)[0]
    F = -p(theta) * area
    work = np.sum((F[1:] + F[:-1]) / 2 * np.diff(x))
    T = ref.mean_gas_torque(r, l, e, area)
    assert T == pytest.approx(work / (4 * np.pi), rel=1e-6)
    model = check.parameters(check.load("slider_crank"))
    assert (model["r"], model["l"], model["e"]) == (r, l, e)
    assert model["A_p"] == pytest.approx(area, rel=1e-15)
    assert T == pytest.approx(model["T_mean"], abs=1e-4)


def test_hinge_expression_is_the_linear_interpolation():
    rng = np.random.default_rng(3)
    x = np.cumsum(rng.uniform(0.5, 2.0, 9)) - 6.0
    y = rng.uniform(-3, 3, 9)
    text = ref.hinge_expression(x, y, "v", scale="2")
    for v in np.linspace(x[0], x[-1], 301):
        assert check.value(text, {"v": v}) == pytest.approx(2 * np.interp(v, x, y), abs=1e-12)


# ======================================================================== Andrews
Q0, QREF, UREF = ref.ANDREWS_Q0, ref.ANDREWS_Q_REF, ref.ANDREWS_U_REF


def test_andrews_published_initial_values_satisfy_the_constraints():
    assert np.abs(ref.andrews_constraints(Q0)).max() < 1e-15      # lengths are ~0.05 m


def test_andrews_reference_solution_at_003_satisfies_the_constraints():
    assert np.abs(ref.andrews_constraints(QREF)).max() < 1e-15
    # and its speeds the velocity constraints, to the 16 printed digits (|G||u| ~ 50)
    assert np.abs(ref.andrews_constraint_jacobian(QREF) @ UREF).max() < 1e-8


def test_andrews_published_jacobian_is_the_derivative_of_the_constraints():
    h = 1e-6
    for q in (Q0, QREF, np.random.default_rng(0).uniform(-3, 3, 7)):
        G = np.array([(ref.andrews_constraints(q + h * e) - ref.andrews_constraints(q - h * e))
                      / (2 * h) for e in np.eye(7)]).T
        np.testing.assert_allclose(ref.andrews_constraint_jacobian(q), G, atol=1e-10)


def test_andrews_published_initial_accelerations_and_multipliers_balance():
    """M w0 + G^T lambda0 = f(q0, 0) and G w0 = 0 (speeds zero): the published consistent
    accelerations -- a check of the transcribed M, f and G."""
    M, G = ref.andrews_mass_matrix(Q0), ref.andrews_constraint_jacobian(Q0)
    f = ref.andrews_forces(Q0, ref.ANDREWS_U0)
    lhs = M @ ref.ANDREWS_W0 + G.T @ ref.ANDREWS_LAMBDA0
    np.testing.assert_allclose(lhs, f, atol=1e-12 * np.abs(f).max())
    assert np.abs(G @ ref.ANDREWS_W0).max() < 1e-12 * np.abs(G).max() * np.abs(ref.ANDREWS_W0).max()


def test_andrews_model_frames_rebuild_the_published_constraints_and_mass_matrix():
    rng = np.random.default_rng(1)
    for q in [Q0, QREF] + list(rng.uniform(-3, 3, (3, 7))):
        E2 = ref.andrews_point(q, "E_K2")
        g = ref.andrews_constraints(q)
        for k, key in enumerate(("E_K3", "E_K4", "E_K6")):
            np.testing.assert_allclose(E2 - ref.andrews_point(q, key), g[2 * k:2 * k + 2],
                                       atol=1e-16)
        M = ref.andrews_mass_matrix(q)
        T = ref.andrews_kinetic_energy
        I7 = np.eye(7)
        Mn = np.array([[T(q, I7[i] + I7[j]) - T(q, I7[i]) - T(q, I7[j]) for j in range(7)]
                       for i in range(7)])
        np.testing.assert_allclose(Mn, M, atol=1e-10 * np.abs(M).max())
    # the spring's end D of the model is the publication's (xd, yd)
    p, ga = ref.ANDREWS_PARAMETERS, Q0[2]
    D = ref.andrews_point(Q0, "D_K3")
    assert D == pytest.approx([p["sd"] * math.cos(ga) + p["sc"] * math.sin(ga) + p["xb"],
                               p["sd"] * math.sin(ga) - p["sc"] * math.cos(ga) + p["yb"]],
                              abs=1e-17)


def test_andrews_model_file_holds_the_published_data():
    doc = check.load("andrews_squeezer")
    p = check.parameters(doc)
    assert {k: p[k] for k in ref.ANDREWS_PARAMETERS} == ref.ANDREWS_PARAMETERS
    q0 = [check.value(doc["initial"][n], p) for n in ref.ANDREWS_NAMES]
    assert q0 == list(ref.ANDREWS_Q0)
    assert doc["simulation"]["t_end"] == ref.ANDREWS_T_REF


# ======================================================================== Bricard
def bricard_jacobian(q, h=1e-6):
    return np.array([(ref.bricard_loop_residual(q + h * e) - ref.bricard_loop_residual(q - h * e))
                     / (2 * h) for e in np.eye(5)]).T


def test_bricard_grubler_says_zero_the_loop_has_mobility_one():
    assert ref.bricard_grubler() == 0
    for th in np.linspace(-0.5, 3.6, 15):
        q = ref.bricard_q(th)
        assert np.abs(ref.bricard_loop_residual(q)).max() < 1e-14
        sv = np.linalg.svd(bricard_jacobian(q), compute_uv=False)
        assert sv[3] > 0.5 and sv[4] < 1e-8          # rank 4 of 5: one free motion
        # the free motion is the closed form's tangent
        t = np.array([1.0, ref.bricard_phi(th)[1], 1.0, ref.bricard_phi(th)[1], 1.0])
        assert np.abs(bricard_jacobian(q) @ t).max() < 1e-8


def test_bricard_closed_form_agrees_with_a_numeric_solve():
    x = np.zeros(4)
    for th in np.linspace(0.05, 3.0, 12):              # continuation from the cube
        x = least_squares(lambda x, th=th: ref.bricard_loop_residual(np.r_[th, x]), x,
                          xtol=1e-15, ftol=1e-15, gtol=1e-15).x
        np.testing.assert_allclose(np.r_[th, x], ref.bricard_q(th), atol=1e-10)


def test_bricard_released_from_rest_conserves_energy_and_falls_forward():
    sol = solve_ivp(ref.bricard_reduced_rhs, (0, 0.5), [0.0, 0.0], method="DOP853",
                    rtol=1e-11, atol=1e-12)
    E = [ref.bricard_energy(th, thd) for th, thd in sol.y.T]
    assert np.ptp(E) < 1e-9 and sol.y[0, -1] > 0.2 and sol.y[1, -1] > 0.0


def test_bricard_model_file_is_the_reference_geometry():
    m = check.LoopModel(check.load("bricard"))
    for th in (0.0, 0.7, 2.0):
        q = dict(zip(m.coordinates, ref.bricard_q(th)))
        assert np.abs(m.residual(q)).max() < 1e-14
        frames = m.frames(q)
        for k, (R, r) in enumerate(ref.bricard_frames(ref.bricard_q(th))):
            np.testing.assert_allclose(frames[f"rod{k + 1}"][0], R, atol=1e-14)
            np.testing.assert_allclose(frames[f"rod{k + 1}"][1], r, atol=1e-14)


# ======================================================================== governor
P = ref.GOVERNOR


def governor_bodies(alpha):
    """(mass, centre, R, inertia in body axes) of arm, ball, link of the +x side, from 3D
    rotations as the model builds them (spindle axes)."""
    (Iat, Iaa), (Ilt, Ila), Ib = ref.governor_inertias()
    hinge = np.array([P["h"], 0, P["H"]])
    Ra = ref.rotation((0, -1, 0), alpha)
    Rl = Ra @ ref.rotation((0, -1, 0), -2 * alpha)
    pin = hinge + Ra @ [0, 0, -P["a"]]
    return [(P["m_arm"], hinge + Ra @ [0, 0, -P["L"] / 2], Ra, np.diag([Iat, Iat, Iaa])),
            (P["m_ball"], hinge + Ra @ [0, 0, -P["L"]], Ra, np.eye(3) * Ib),
            (P["m_link"], pin + Rl @ [0, 0, -P["a"] / 2], Rl, np.diag([Ilt, Ilt, Ila]))]


def effective_potential(alpha, Omega):
    """V - Omega^2 Jz / 2 from the bodies' 3D placement (both sides, sleeve, spring)."""
    V = Jz = 0.0
    for m, r, R, I in governor_bodies(alpha):
        V += 2 * m * P["g"] * r[2]
        Jz += 2 * (m * (r[0]**2 + r[1]**2) + (R @ I @ R.T)[2, 2])
    zs = P["H"] - 2 * P["a"] * math.cos(alpha)
    V += P["m_sleeve"] * P["g"] * zs + 0.5 * P["k"] * (P["H"] - zs - P["L0"])**2
    return V - 0.5 * Omega**2 * Jz


def test_governor_terms_match_finite_differences():
    h = 1e-5
    for al in (0.2, 0.6, 1.0):
        t0, tp, tm = (ref.governor_terms(x) for x in (al, al + h, al - h))
        _, dM, Jz, dJz, ddJz, V, dV, ddV = t0
        assert dM == pytest.approx((tp[0] - tm[0]) / (2 * h), rel=1e-7)
        assert dJz == pytest.approx((tp[2] - tm[2]) / (2 * h), rel=1e-7)
        assert ddJz == pytest.approx((tp[3] - tm[3]) / (2 * h), rel=1e-6)
        assert dV == pytest.approx((tp[5] - tm[5]) / (2 * h), rel=1e-7)
        assert ddV == pytest.approx((tp[6] - tm[6]) / (2 * h), rel=1e-6)
        # Jz and V against the 3D placement (effective potential at two speeds)
        assert V == pytest.approx(effective_potential(al, 0.0), rel=1e-13)
        spin = effective_potential(al, 0.0) - effective_potential(al, 1.0)     # Jz / 2
        assert Jz == pytest.approx(2 * spin, rel=1e-12)


def test_governor_steady_state_is_the_minimum_of_the_effective_potential():
    for Omega in (9.450924596134259, 10.0, 12.0):
        al_cf = brentq(lambda al, W=Omega: ref.governor_equilibrium_speed(al) - W, 0.05, 1.4)
        al_num = minimize_scalar(lambda al, W=Omega: effective_potential(al, W),
                                 bounds=(0.05, 1.4), method="bounded",
                                 options={"xatol": 1e-12}).x
        assert al_num == pytest.approx(al_cf, abs=1e-6)
    assert ref.governor_equilibrium_speed(math.radians(30)) == pytest.approx(9.450924596134259,
                                                                             rel=1e-15)


def test_governor_small_oscillation_frequency_and_motion():
    al = math.radians(30)
    Omega = ref.governor_equilibrium_speed(al)
    # V_eff'' from the 3D placement over M from the bodies' speeds
    h = 1e-4
    Vpp = (effective_potential(al + h, Omega) - 2 * effective_potential(al, Omega)
           + effective_potential(al - h, Omega)) / h**2
    w = ref.governor_frequency(al)
    assert w**2 == pytest.approx(Vpp / ref.governor_terms(al)[0], rel=1e-5)
    # the reduced equation stays put at the steady state and oscillates at w near it
    sol = solve_ivp(ref.governor_rhs, (0, 1.0), [al, 0.0], args=(Omega,), rtol=1e-11, atol=1e-13)
    assert np.abs(sol.y[0] - al).max() < 1e-10
    T = 2 * np.pi / w
    sol = solve_ivp(ref.governor_rhs, (0, T), [al + 1e-5, 0.0], args=(Omega,),
                    rtol=1e-11, atol=1e-14, dense_output=True)
    assert sol.y[0, -1] - al == pytest.approx(1e-5, rel=1e-4)


def test_governor_model_file_holds_the_reference_parameters():
    p = check.parameters(check.load("watt_governor"))
    for key in ("h", "H", "L", "a", "m_arm", "r_arm", "m_ball", "r_ball", "m_link", "r_link",
                "m_sleeve", "k", "L0", "g"):
        assert p[key] == P[key], key
    steady = check.parameters(check.apply_case(check.load("watt_governor"), "steady"))
    assert steady["Omega"] == ref.governor_equilibrium_speed(steady["alpha0"])


# ======================================================================== the model files
def test_every_loop_model_closes_from_its_initial_values_and_guess():
    reports = check.check_all()
    assert {stem for stem, _ in reports} == set(check.LOOP_MODELS)
    for (stem, case), r in reports.items():
        where = f"{stem} case {case}"
        assert max(r["after"].values()) < 1e-12, where
        assert r["axes_aligned"] > 1 - 1e-12, where
        assert r["velocity_residual"] < 1e-10, where
        assert r["closed_form_q"] < 1e-12 and r["closed_form_u"] < 1e-9, where
        driven = stem == "four_bar" and case in (None, "open", "crossed")
        assert r["mobility"] == (0 if driven else 1), where
    assert reports[("andrews_squeezer", None)]["rank"] == 6
    assert reports[("bricard", None)]["rank"] == 4


def test_slider_crank_gas_force_is_the_table():
    assert check.gas_force_error() < 1e-8
