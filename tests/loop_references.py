"""Closed forms and published data of the closed-loop mechanisms in ``models/``.

Plain ``math``/``numpy`` only -- nothing here may call mbdyn (nor scipy: the self-tests in
``tests/test_loop_references.py`` check these formulas against scipy's solvers and finite
differences, so the two routes stay independent).  Each function's docstring names its
source.  Conventions: planar mechanisms in the x-y plane, angles counter-clockwise from
the +x axis (the "ground line"), ``e(a) = (cos a, sin a)``, ``n(a) = (-sin a, cos a)``.

Contents
    four-bar      Freudenstein's equation (rocker and coupler, both branches), angular
                  velocities and accelerations, Grashof's check, the drive torque by a power
                  balance (``fourbar_*``)
    slider-crank  exact piston position, velocity and acceleration; a gas-pressure table
                  (``slider_crank*``, ``GAS_*``)
    Andrews       the squeezing mechanism's published data, constraints, mass matrix and
                  reference solution (``ANDREWS_*``, ``andrews_*``)
    Bricard       a six-revolute loop of mobility 1 (Grubler: 0), its motion in closed form
                  and a 1-DoF reference motion (``BRICARD_*``, ``bricard_*``)
    governor      the flyball governor's steady state and small oscillations (``governor_*``)
"""
import math

import numpy as np

G = 9.81


def e_(a):
    """Unit vector ``(cos a, sin a)`` (vectorised: shape ``(2, ...)``)."""
    return np.array([np.cos(a), np.sin(a)])


def n_(a):
    """Unit normal ``(-sin a, cos a)``, ``e(a)`` turned by +90 degrees."""
    return np.array([-np.sin(a), np.cos(a)])


# =======================================================================================
# Four-bar linkage: ground d (pivots O2 = (0, 0) and O4 = (d, 0)), crank a (O2 -> A),
# coupler b (A -> B), rocker c (O4 -> B); theta2, theta3, theta4 absolute, from the ground
# line.  Loop: a e(t2) + b e(t3) - c e(t4) - d e(0) = 0.
# =======================================================================================
BRANCHES = {"open": -1.0, "crossed": +1.0}


def grashof(a, b, c, d):
    """Grashof's condition and the kind of four-bar (Grashof 1883, *Theoretische
    Maschinenlehre*; as stated in Norton, *Design of Machinery*, ch. 2).

    With ``s``, ``l`` the shortest and longest links and ``p``, ``q`` the others: Grashof if
    ``s + l <= p + q`` (some link turns fully).  Kind: ``"crank-rocker"`` if the shortest is
    the crank ``a`` (or the rocker ``c``: then the rocker is the one that turns),
    ``"double-crank"`` if it is the ground ``d``, ``"double-rocker"`` if it is the coupler
    ``b``; ``"change-point"`` if ``s + l == p + q`` (to 1e-12 relative); else
    ``"triple-rocker"`` (non-Grashof: no link turns fully).  Returns ``(is_grashof, kind)``.
    """
    links = {"a": a, "b": b, "c": c, "d": d}
    lengths = sorted(links.values())
    s, p, q, l = lengths
    if abs((s + l) - (p + q)) <= 1e-12 * (p + q):
        return True, "change-point"
    if s + l > p + q:
        return False, "triple-rocker"
    shortest = min(links, key=links.get)
    return True, {"a": "crank-rocker", "c": "crank-rocker", "d": "double-crank",
                  "b": "double-rocker"}[shortest]


def freudenstein_constants(a, b, c, d):
    """``K1..K5`` of Freudenstein's equations, in Norton's numbering (Norton, *Design of
    Machinery*, ch. 4, algebraic position analysis; Freudenstein, Trans. ASME 77 (1955)
    853-861):
    ``K1 = d/a, K2 = d/c, K3 = (a^2 - b^2 + c^2 + d^2)/(2ac), K4 = d/b,
    K5 = (c^2 - d^2 - a^2 - b^2)/(2ab)``."""
    return (d / a, d / c, (a * a - b * b + c * c + d * d) / (2 * a * c), d / b,
            (c * c - d * d - a * a - b * b) / (2 * a * b))


def _solve_pq(P, Q, R, sigma):
    """``x`` with ``P cos x + Q sin x + R = 0`` on branch ``sigma`` (+1 or -1):
    ``x = atan2(Q, P) + sigma acos(-R / sqrt(P^2 + Q^2))``.  NaN where no real solution."""
    rho = np.hypot(P, Q)
    with np.errstate(invalid="ignore", divide="ignore"):
        ratio = -R / rho
        x = np.arctan2(Q, P) + sigma * np.arccos(np.where(np.abs(ratio) <= 1.0, ratio, np.nan))
    return x


def fourbar_positions(theta2, a, b, c, d, branch="open"):
    """Rocker and coupler angles ``(theta3, theta4)`` for crank angle ``theta2`` by
    Freudenstein's equations (sources as ``freudenstein_constants``).

    Rocker:  ``K1 cos t4 - K2 cos t2 + K3 = cos(t2 - t4)``, i.e.
             ``(cos t2 - K1) cos t4 + sin t2 sin t4 + (K2 cos t2 - K3) = 0``;
    coupler: ``K1 cos t3 + K4 cos t2 + K5 = cos(t2 - t3)``, i.e.
             ``(cos t2 - K1) cos t3 + sin t2 sin t3 - (K4 cos t2 + K5) = 0``.
    Each is solved as ``x = atan2(Q, P) + sigma acos(-R/sqrt(P^2+Q^2))``; the same
    ``sigma`` on both picks one assembly: ``sigma = -1`` the "open" branch, ``+1`` the
    "crossed" one (``BRANCHES``).  Geometrically ``t4 = angle(A - O4) + sigma gamma`` with
    ``gamma`` the triangle A-B-O4's angle at O4, and ``t3 = angle(O4 - A) - sigma delta``
    with ``delta`` its angle at A.  On a branch the sign of ``sin(t4 - t3)`` (the
    transmission angle's orientation) is constant; it changes only where coupler and rocker
    are collinear, which a Grashof crank-rocker never reaches.  Vectorised in ``theta2``;
    NaN where the linkage cannot be assembled.  Angles are returned in (-pi, pi].
    """
    sigma = BRANCHES[branch] if isinstance(branch, str) else float(branch)
    K1, K2, K3, K4, K5 = freudenstein_constants(a, b, c, d)
    c2, s2 = np.cos(theta2), np.sin(theta2)
    theta4 = _solve_pq(c2 - K1, s2, K2 * c2 - K3, sigma)
    theta3 = _solve_pq(c2 - K1, s2, -(K4 * c2 + K5), sigma)
    return wrap(theta3), wrap(theta4)


def wrap(x):
    """``x`` wrapped to (-pi, pi]."""
    return np.pi - np.mod(np.pi - np.asarray(x, float), 2 * np.pi)


def fourbar_loop_residual(theta2, theta3, theta4, a, b, c, d):
    """The vector loop ``a e(t2) + b e(t3) - c e(t4) - d e(0)`` (2 components)."""
    return a * e_(theta2) + b * e_(theta3) - c * e_(theta4) - np.array([d, 0.0]).reshape(
        (2,) + (1,) * np.ndim(theta2))


def fourbar_velocities(theta2, theta3, theta4, omega2, a, b, c, d):
    """``(omega3, omega4)`` from the time derivative of the loop,
    ``a w2 n(t2) + b w3 n(t3) - c w4 n(t4) = 0``, dotted with ``e(t4)`` and ``e(t3)``
    (``n(x).e(y) = sin(y - x)``); derived here (the textbook route, as in Norton ch. 6):
    ``w3 = a w2 sin(t4 - t2) / (b sin(t3 - t4))``,
    ``w4 = a w2 sin(t2 - t3) / (c sin(t4 - t3))``."""
    omega3 = a * omega2 * np.sin(theta4 - theta2) / (b * np.sin(theta3 - theta4))
    omega4 = a * omega2 * np.sin(theta2 - theta3) / (c * np.sin(theta4 - theta3))
    return omega3, omega4


def fourbar_accelerations(theta2, theta3, theta4, omega2, omega3, omega4, alpha2,
                          a, b, c, d):
    """``(alpha3, alpha4)`` from the second derivative of the loop,
    ``a(al2 n2 - w2^2 e2) + b(al3 n3 - w3^2 e3) - c(al4 n4 - w4^2 e4) = 0``, dotted with
    ``e(t4)`` and ``e(t3)``; derived here (as in Norton ch. 7):
    ``al3 = [-a al2 sin(t4-t2) + a w2^2 cos(t4-t2) + b w3^2 cos(t4-t3) - c w4^2]
    / (b sin(t4-t3))``,
    ``al4 = [a al2 sin(t3-t2) - a w2^2 cos(t3-t2) - b w3^2 + c w4^2 cos(t4-t3)]
    / (c sin(t3-t4))``."""
    s43 = np.sin(theta4 - theta3)
    alpha3 = (-a * alpha2 * np.sin(theta4 - theta2) + a * omega2**2 * np.cos(theta4 - theta2)
              + b * omega3**2 * np.cos(theta4 - theta3) - c * omega4**2) / (b * s43)
    alpha4 = (a * alpha2 * np.sin(theta3 - theta2) - a * omega2**2 * np.cos(theta3 - theta2)
              - b * omega3**2 + c * omega4**2 * np.cos(theta4 - theta3)) / (-c * s43)
    return alpha3, alpha4


def fourbar_state(theta2, omega2, alpha2, a, b, c, d, branch="open"):
    """Angles, rates and accelerations of crank, coupler, rocker:
    ``((t2, t3, t4), (w2, w3, w4), (al2, al3, al4))`` -- the three functions above."""
    theta3, theta4 = fourbar_positions(theta2, a, b, c, d, branch)
    omega3, omega4 = fourbar_velocities(theta2, theta3, theta4, omega2, a, b, c, d)
    alpha3, alpha4 = fourbar_accelerations(theta2, theta3, theta4, omega2, omega3, omega4,
                                           alpha2, a, b, c, d)
    return (theta2, theta3, theta4), (omega2, omega3, omega4), (alpha2, alpha3, alpha4)


def fourbar_com_motion(angles, rates, accels, a, d, coms):
    """Positions, velocities and accelerations (each ``(3, 2, ...)``: link, x/y) of the
    links' centres of mass.  ``coms = ((p2, q2), (p3, q3), (p4, q4))``: each link's centre
    in its own axes (x along the link from its first pin: O2 for the crank, A for the
    coupler, O4 for the rocker; y turned +90 degrees).  A point ``p e(t) + q n(t)`` of a
    link turning at ``w``, ``al`` moves with ``w (p n - q e)`` and accelerates with
    ``al (p n - q e) - w^2 (p e + q n)``; the coupler adds pin A's motion."""
    bases = [np.zeros(2), None, np.array([d, 0.0])]
    r, v, acc = [], [], []
    for k, ((p, q), t, w, al) in enumerate(zip(coms, angles, rates, accels)):
        E, N = e_(t), n_(t)
        rk = p * E + q * N
        vk = w * (p * N - q * E)
        ak = al * (p * N - q * E) - w**2 * (p * E + q * N)
        if k == 1:                       # the coupler rides on the crank pin A
            t2, w2, al2 = angles[0], rates[0], accels[0]
            rk = rk + a * e_(t2)
            vk = vk + a * w2 * n_(t2)
            ak = ak + a * (al2 * n_(t2) - w2**2 * e_(t2))
        else:
            rk = rk + bases[k].reshape((2,) + (1,) * (rk.ndim - 1))
        r.append(rk), v.append(vk), acc.append(ak)
    return np.array(r), np.array(v), np.array(acc)


def fourbar_energy(theta2, omega2, a, b, c, d, masses, coms, inertias, gravity=(0.0, -G),
                   branch="open"):
    """Kinetic and potential energy ``(T, V)`` of the three links:
    ``T = sum(m v_G^2/2 + I_G w^2/2)``, ``V = -sum(m g . r_G)`` (``inertias`` about the
    centres of mass, normal to the plane)."""
    ang, rat, acc = fourbar_state(theta2, omega2, 0.0 * omega2, a, b, c, d, branch)
    r, v, _ = fourbar_com_motion(ang, rat, acc, a, d, coms)
    gv = np.asarray(gravity, float)
    T = sum(0.5 * m * (vk**2).sum(axis=0) + 0.5 * I * w**2
            for m, vk, I, w in zip(masses, v, inertias, rat))
    V = sum(-m * np.tensordot(gv, rk, axes=(0, 0)) for m, rk in zip(masses, r))
    return T, V


def fourbar_drive_torque(theta2, omega2, alpha2, a, b, c, d, masses, coms, inertias,
                         gravity=(0.0, -G), branch="open"):
    """The torque on the crank that makes it move with ``(theta2, omega2, alpha2)`` against
    the links' inertia and gravity, by a power balance: ``tau w2 = dE/dt`` with
    ``E = T + V`` of the links (no friction), so
    ``tau = sum(m v_G . (a_G - g) + I_G w al) / w2`` (derived here: the power, or
    energy, method of machine dynamics).  Needs
    ``omega2 != 0``.  At constant speed ``alpha2 = 0``.  Vectorised along ``theta2``."""
    ang, rat, acc = fourbar_state(theta2, omega2, alpha2, a, b, c, d, branch)
    _, v, ac = fourbar_com_motion(ang, rat, acc, a, d, coms)
    gv = np.asarray(gravity, float).reshape((2,) + (1,) * np.ndim(theta2))
    power = sum(m * (vk * (ak - gv)).sum(axis=0) + I * w * al
                for m, vk, ak, I, w, al in zip(masses, v, ac, inertias, rat, acc))
    return power / omega2


# =======================================================================================
# Slider-crank: crank r about O = (0, 0), connecting rod l, piston pin on the line y = e
# (the offset), at x > 0.  Crank angle theta from +x; rod angle phi (absolute) from the
# crank pin to the piston pin.
# =======================================================================================
def slider_crank(theta, omega, alpha, r, l, e=0.0):
    """Exact piston position, velocity and acceleration ``(x, x', x'')`` (no series in
    ``r/l``), derived from the loop ``r e(theta) + l e(phi) = (x, e)``:
    ``s = r sin(theta) - e``, ``D = sqrt(l^2 - s^2)``, ``x = r cos(theta) + D``,
    ``x_t = dx/dtheta = -r sin(theta) - s r cos(theta) / D``,
    ``x_tt = -r cos(theta) - (r^2 cos^2(theta) - s r sin(theta)) / D
    - s^2 r^2 cos^2(theta) / D^3``,
    ``x' = x_t omega``, ``x'' = x_t alpha + x_tt omega^2``.  (For ``e = 0`` the textbook
    form of engine-dynamics texts, e.g. Norton ch. 13, before its binomial series.)"""
    st, ct = np.sin(theta), np.cos(theta)
    s = r * st - e
    D = np.sqrt(l * l - s * s)
    x = r * ct + D
    x_t = -r * st - s * r * ct / D
    x_tt = -r * ct - (r * r * ct * ct - s * r * st) / D - s * s * r * r * ct * ct / D**3
    return x, x_t * omega, x_t * alpha + x_tt * omega**2


def slider_crank_rod(theta, omega, alpha, r, l, e=0.0):
    """Rod angle and its rates ``(phi, phi', phi'')``: ``l sin(phi) = e - r sin(theta)``,
    so ``phi = asin((e - r sin theta)/l)`` (|phi| < pi/2: the piston on the +x side),
    ``phi' = -r cos(theta) omega / (l cos phi)``,
    ``phi'' = (r sin(theta) omega^2 - r cos(theta) alpha + l sin(phi) phi'^2)/(l cos phi)``.
    """
    phi = np.arcsin((e - r * np.sin(theta)) / l)
    cp = np.cos(phi)
    phid = -r * np.cos(theta) * omega / (l * cp)
    phidd = (r * np.sin(theta) * omega**2 - r * np.cos(theta) * alpha
             + l * np.sin(phi) * phid**2) / (l * cp)
    return phi, phid, phidd


#: Cylinder gauge pressure of the four-stroke engine in models/slider_crank.toml, in bar,
#: against the cycle angle psi in degrees (psi in (-360, 360], 0 at the crank angle 0 where
#: the mixture burns; -360..-180 intake, -180..0 compression, 0..180 expansion, 180..360
#: exhaust).  Made up for the model (a plausible spark-ignition shape with a 52 bar peak
#: 15 degrees after firing); the model's force expression interpolates it linearly.
GAS_PSI_DEG = np.array([-360, -180, -135, -90, -45, -15, 0, 15, 30, 45, 90, 135, 180,
                        225, 360], float)
GAS_BAR = np.array([0, 0, 0.6, 2, 7, 20, 38, 52, 40, 28, 10, 5, 1, 0, 0], float)


def gas_cycle_angle(theta):
    """The cycle angle ``psi`` in degrees of crank angle ``theta`` (radians), wrapped to
    (-360, 360]: ``psi = (360/pi) atan2(sin(theta/2), cos(theta/2))`` -- the form the
    model file writes."""
    half = np.asarray(theta) / 2
    return (360.0 / math.pi) * np.arctan2(np.sin(half), np.cos(half))


def gas_pressure(theta):
    """Gauge pressure in Pa at crank angle ``theta``: ``GAS_BAR`` interpolated linearly in
    ``gas_cycle_angle(theta)``."""
    return 1e5 * np.interp(gas_cycle_angle(theta), GAS_PSI_DEG, GAS_BAR)


def mean_gas_torque(r, l, e, area, n=20001):
    """Mean over a cycle (4 pi of crank angle) of the gas force's torque on the crank,
    ``-p A dx/dtheta`` (the piston force ``-p A`` along +x), by the trapezoidal rule on
    ``n`` points (the integrand is continuous)."""
    theta = np.linspace(-2 * math.pi, 2 * math.pi, n)
    x_t = slider_crank(theta, 1.0, 0.0, r, l, e)[1]
    f = -gas_pressure(theta) * area * x_t
    return float(np.sum((f[1:] + f[:-1]) * np.diff(theta)) / 2 / (4 * math.pi))


def hinge_expression(x, y, variable, scale="1"):
    """The piecewise-linear interpolation of the table ``(x, y)`` as an expression of
    ``variable`` that model files accept (``max`` is one of their functions):
    ``y0 + s0 (v - x0) + sum_i (s_i - s_{i-1}) max(0, v - x_i)``, exact inside the table and
    continued along the end slopes outside.  Slopes are written as fractions of the table's
    numbers (``(dy/dx)``), so the text holds the table exactly.  ``scale`` multiplies the
    whole."""
    x, y = np.asarray(x, float), np.asarray(y, float)
    slopes = [(y[i + 1] - y[i], x[i + 1] - x[i]) for i in range(len(x) - 1)]

    def frac(dy, dx):
        return "0" if dy == 0 else f"({_num(dy)}/{_num(dx)})"

    def shifted(x0):
        if x0 == 0:
            return variable
        return f"{variable} + {_num(-x0)}" if x0 < 0 else f"{variable} - {_num(x0)}"

    terms = [_num(y[0])]
    if slopes[0][0] != 0:
        terms.append(f"{frac(*slopes[0])}*({shifted(x[0])})")
    for i in range(1, len(x) - 1):
        (dy1, dx1), (dy0, dx0) = slopes[i], slopes[i - 1]
        if dy1 / dx1 == dy0 / dx0:
            continue
        change = frac(dy1, dx1) if dy0 == 0 else (
            f"-{frac(dy0, dx0)}" if dy1 == 0 else f"{frac(dy1, dx1)} - {frac(dy0, dx0)}")
        terms.append(f"({change})*max(0, {shifted(x[i])})")
    return f"{scale}*(" + " + ".join(terms) + ")"


def _num(v):
    v = float(v)
    return str(int(v)) if v.is_integer() else repr(v)


# =======================================================================================
# Andrews' squeezing mechanism (seven bodies, planar, no gravity)
# =======================================================================================
#: Parameters, exactly as in the IVP test set's andrews.f (Mazzia, Magherini, Iavernaro,
#: "Test Set for IVP Solvers", Univ. of Bari, release 2.3 (2006)/2.4, problem "andrews";
#: first in the CWI test set of Lioen & de Swart, 1999) and in Hairer & Wanner, *Solving
#: ODEs II*, 2nd ed., section VII.7, after Schiehlen (ed.), *Multibody Systems Handbook*
#: (1990).  Lengths m, masses kg, inertias
#: kg m^2 about the centres of mass, c0 N/m, l0 m, mom N m.  Read from copies of andrews.f
#: (a MEBDFI driver of the test set, "02/04/2000"), Assimulo's and pySDC's squeezer
#: examples and the R package deTestSet's documentation, which agree digit for digit.
ANDREWS_PARAMETERS = {
    "m1": 0.04325, "m2": 0.00365, "m3": 0.02373, "m4": 0.00706, "m5": 0.07050, "m6": 0.00706,
    "m7": 0.05498,
    "I1": 2.194e-6, "I2": 4.410e-7, "I3": 5.255e-6, "I4": 5.667e-7, "I5": 1.169e-5, "I6": 5.667e-7,
    "I7": 1.912e-5,
    "xa": -0.06934, "ya": -0.00227, "xb": -0.03635, "yb": 0.03273, "xc": 0.014, "yc": 0.072,
    "c0": 4530.0, "l0": 0.07785, "mom": 0.033,
    "d": 28e-3, "da": 115e-4, "e": 2e-2, "ea": 1421e-5, "rr": 7e-3, "ra": 92e-5,
    "ss": 35e-3, "sa": 1874e-5, "sb": 1043e-5, "sc": 18e-3, "sd": 2e-2,
    "ta": 2308e-5, "tb": 916e-5, "u": 4e-2, "ua": 1228e-5, "ub": 449e-5,
    "zf": 2e-2, "zt": 4e-2, "fa": 1421e-5,
}
#: Coordinate names, in the publication's order (Hairer & Wanner's beta, Theta, gamma,
#: Phi, delta, Omega, epsilon): beta, gamma, delta, epsilon absolute; Theta relative to
#: beta, Phi relative to delta, Omega relative to epsilon.
ANDREWS_NAMES = ("beta", "Theta", "gamma", "Phi", "delta", "Omega", "epsilon")
#: Consistent initial values (andrews.f, subroutine init; Hairer & Wanner VII.7);
#: the speeds are zero.  The test set prints 30 digits; these are their doubles.
ANDREWS_Q0 = np.array([-0.0617138900142764496358948458001, 0.0,
                       0.455279819163070380255912382449, 0.222668390165885884674473185609,
                       0.487364979543842550225598953530, -0.222668390165885884674473185609,
                       1.23054744454982119249735015568])
ANDREWS_U0 = np.zeros(7)
#: The consistent initial accelerations (only beta'' and Theta'' are non-zero) and the two
#: non-zero Lagrange multipliers lambda1, lambda2 (the other four are zero) at t = 0.
ANDREWS_W0 = np.array([14222.4439199541138705911625887, -10666.8329399655854029433719415,
                       0.0, 0.0, 0.0, 0.0, 0.0])
ANDREWS_LAMBDA0 = np.array([98.5668703962410896057654982170, -6.12268834425566265503114393122,
                            0.0, 0.0, 0.0, 0.0])
#: Reference solution at t = 0.03 s (andrews.f, subroutine solut: RADAU5 at tight
#: tolerances; 16 digits printed): angles y(1..7) and speeds y(8..14).
ANDREWS_T_REF = 0.03
ANDREWS_Q_REF = np.array([0.1581077119629904e+2, -0.1575637105984298e+2,
                          0.4082224013073101e-1, -0.5347301163226948e+0,
                          0.5244099658805304e+0, 0.5347301163226948e+0,
                          0.1048080741042263e+1])
ANDREWS_U_REF = np.array([0.1139920302151208e+4, -0.1424379294994111e+4,
                          0.1103291221937134e+2, 0.1929337464421385e+2,
                          0.5735699284790808e+0, -0.1929337464421385e+2,
                          0.3231791658026955e+0])


def andrews_constraints(q, p=ANDREWS_PARAMETERS):
    """The six position constraints ``g(q) = 0`` of the published formulation (Hairer &
    Wanner VII.7, the equations the test-set codes cite as their (7.11); andrews.f,
    feval): point E reached through bodies 1-2 equals E reached through body 3 (g1, g2),
    through bodies 5-4 (g3, g4) and through 7-6 (g5, g6):
    ``g1 = rr cos(be) - d cos(be+th) - ss sin(ga) - xb``
    ``g2 = rr sin(be) - d sin(be+th) + ss cos(ga) - yb``
    ``g3 = rr cos(be) - d cos(be+th) - e sin(ph+de) - zt cos(de) - xa``
    ``g4 = rr sin(be) - d sin(be+th) + e cos(ph+de) - zt sin(de) - ya``
    ``g5 = rr cos(be) - d cos(be+th) - zf cos(om+ep) - u sin(ep) - xa``
    ``g6 = rr sin(be) - d sin(be+th) - zf sin(om+ep) + u cos(ep) - ya``."""
    be, th, ga, ph, de, om, ep = q
    P = p
    ex = P["rr"] * math.cos(be) - P["d"] * math.cos(be + th)
    ey = P["rr"] * math.sin(be) - P["d"] * math.sin(be + th)
    return np.array([
        ex - P["ss"] * math.sin(ga) - P["xb"],
        ey + P["ss"] * math.cos(ga) - P["yb"],
        ex - P["e"] * math.sin(ph + de) - P["zt"] * math.cos(de) - P["xa"],
        ey + P["e"] * math.cos(ph + de) - P["zt"] * math.sin(de) - P["ya"],
        ex - P["zf"] * math.cos(om + ep) - P["u"] * math.sin(ep) - P["xa"],
        ey - P["zf"] * math.sin(om + ep) + P["u"] * math.cos(ep) - P["ya"],
    ])


def andrews_constraint_jacobian(q, p=ANDREWS_PARAMETERS):
    """``G(q) = dg/dq`` (6 x 7) as published (andrews.f, ``gp``; Hairer & Wanner VII)."""
    be, th, ga, ph, de, om, ep = q
    P = p
    rr, d, ss, e, zt, zf, u = (P[k] for k in ("rr", "d", "ss", "e", "zt", "zf", "u"))
    sbt, cbt = math.sin(be + th), math.cos(be + th)
    spd, cpd = math.sin(ph + de), math.cos(ph + de)
    soe, coe = math.sin(om + ep), math.cos(om + ep)
    gx = (-rr * math.sin(be) + d * sbt, d * sbt)
    gy = (rr * math.cos(be) - d * cbt, -d * cbt)
    G = np.zeros((6, 7))
    for row in (0, 2, 4):
        G[row, 0:2] = gx
    for row in (1, 3, 5):
        G[row, 0:2] = gy
    G[0, 2] = -ss * math.cos(ga)
    G[1, 2] = -ss * math.sin(ga)
    G[2, 3], G[2, 4] = -e * cpd, -e * cpd + zt * math.sin(de)
    G[3, 3], G[3, 4] = -e * spd, -e * spd - zt * math.cos(de)
    G[4, 5], G[4, 6] = zf * soe, zf * soe - u * math.cos(ep)
    G[5, 5], G[5, 6] = -zf * coe, -zf * coe - u * math.sin(ep)
    return G


def andrews_mass_matrix(q, p=ANDREWS_PARAMETERS):
    """The 7 x 7 mass matrix ``M(q)`` as published (andrews.f; Hairer & Wanner VII)."""
    P = p
    th, ph, om = q[1], q[3], q[5]
    m1, m2, m3, m4, m5, m6, m7 = (P[f"m{k}"] for k in range(1, 8))
    i1, i2, i3, i4, i5, i6, i7 = (P[f"I{k}"] for k in range(1, 8))
    rr, ra, da, sa, sb, e, ea, zt, ta, tb, zf, fa, u, ua, ub = (P[k] for k in (
        "rr", "ra", "da", "sa", "sb", "e", "ea", "zt", "ta", "tb", "zf", "fa", "u", "ua", "ub"))
    M = np.zeros((7, 7))
    M[0, 0] = m1 * ra**2 + m2 * (rr**2 - 2 * da * rr * math.cos(th) + da**2) + i1 + i2
    M[1, 0] = M[0, 1] = m2 * (da**2 - da * rr * math.cos(th)) + i2
    M[1, 1] = m2 * da**2 + i2
    M[2, 2] = m3 * (sa**2 + sb**2) + i3
    M[3, 3] = m4 * (e - ea)**2 + i4
    M[4, 3] = M[3, 4] = m4 * ((e - ea)**2 + zt * (e - ea) * math.sin(ph)) + i4
    M[4, 4] = (m4 * (zt**2 + 2 * zt * (e - ea) * math.sin(ph) + (e - ea)**2)
               + m5 * (ta**2 + tb**2) + i4 + i5)
    M[5, 5] = m6 * (zf - fa)**2 + i6
    M[6, 5] = M[5, 6] = m6 * ((zf - fa)**2 - u * (zf - fa) * math.sin(om)) + i6
    M[6, 6] = (m6 * ((zf - fa)**2 - 2 * u * (zf - fa) * math.sin(om) + u**2)
               + m7 * (ua**2 + ub**2) + i6 + i7)
    return M


def andrews_forces(q, qd, p=ANDREWS_PARAMETERS):
    """The right-hand side ``f(q, q')`` as published (andrews.f, ``ff``): the motor moment
    ``mom`` on beta, the spring ``c0 (L - l0)`` between D on body 3 (``xd = sd cos(ga) +
    sc sin(ga) + xb``, ``yd = sd sin(ga) - sc cos(ga) + yb``) and C = (xc, yc), and the
    velocity-product terms."""
    P = p
    _be, th, ga, ph, _de, om, _ep = q
    bep, thp, _gap, php, dep, omp, epp = qd
    m2, m4, m6 = P["m2"], P["m4"], P["m6"]
    da, rr, zt, e, ea, u, zf, fa = (P[k] for k in ("da", "rr", "zt", "e", "ea", "u", "zf", "fa"))
    sd, sc = P["sd"], P["sc"]
    xd = sd * math.cos(ga) + sc * math.sin(ga) + P["xb"]
    yd = sd * math.sin(ga) - sc * math.cos(ga) + P["yb"]
    L = math.hypot(xd - P["xc"], yd - P["yc"])
    force = -P["c0"] * (L - P["l0"]) / L
    fx, fy = force * (xd - P["xc"]), force * (yd - P["yc"])
    return np.array([
        P["mom"] - m2 * da * rr * thp * (thp + 2 * bep) * math.sin(th),
        m2 * da * rr * bep**2 * math.sin(th),
        fx * (sc * math.cos(ga) - sd * math.sin(ga)) + fy * (sd * math.cos(ga) + sc * math.sin(ga)),
        m4 * zt * (e - ea) * dep**2 * math.cos(ph),
        -m4 * zt * (e - ea) * php * (php + 2 * dep) * math.cos(ph),
        -m6 * u * (zf - fa) * epp**2 * math.cos(om),
        m6 * u * (zf - fa) * omp * (omp + 2 * epp) * math.cos(om),
    ])


#: The bodies as models/andrews_squeezer.toml builds them (planar frames, x-y plane, all
#: joints about +z): ``name: (parent, joint position in the parent, coordinate index,
#: centre of mass in the body, mass key, inertia key)``.  Worked out here from the
#: published g, M and f (the figure of Hairer & Wanner VII.7): K1 turns about O at beta;
#: K2 on K1 at (rr, 0), Theta; K3 about B = (xb, yb) at gamma; K5 about A = (xa, ya) at
#: delta; K4 on K5 at (zt, 0), Phi; K7 about A at epsilon; K6 on K7 at (0, -u), Omega.
ANDREWS_BODIES = {
    "K1": ("ground", ("0", "0"), 0, ("ra", "0"), "m1", "I1"),
    "K2": ("K1", ("rr", "0"), 1, ("-da", "0"), "m2", "I2"),
    "K3": ("ground", ("xb", "yb"), 2, ("sb", "-sa"), "m3", "I3"),
    "K5": ("ground", ("xa", "ya"), 4, ("ta", "tb"), "m5", "I5"),
    "K4": ("K5", ("zt", "0"), 3, ("0", "-(e - ea)"), "m4", "I4"),
    "K7": ("ground", ("xa", "ya"), 6, ("-ub", "-ua"), "m7", "I7"),
    "K6": ("K7", ("0", "-u"), 5, ("zf - fa", "0"), "m6", "I6"),
}
#: Point E in each body meeting there (the three loop joints join K2 to K3, K4 and K6),
#: and the spring's end D on K3.
ANDREWS_POINTS = {"E_K2": ("K2", ("-d", "0")), "E_K3": ("K3", ("0", "-ss")),
                  "E_K4": ("K4", ("0", "-e")), "E_K6": ("K6", ("zf", "0")),
                  "D_K3": ("K3", ("sd", "-sc"))}


def _pval(text, p):
    """A parameter expression of ``ANDREWS_BODIES``: a name, a number or ``-(a - b)``,
    ``a - b``, ``-a``."""
    t = text.replace(" ", "")
    neg = t.startswith("-")
    t = t[1:] if neg else t
    if t.startswith("(") and t.endswith(")"):
        t = t[1:-1]
    parts = t.split("-")
    val = sum((-1 if i else 1) * (p[s] if s in p else float(s)) for i, s in enumerate(parts))
    return -val if neg else val


def andrews_frames(q, p=ANDREWS_PARAMETERS):
    """World angle and origin of every body frame of ``ANDREWS_BODIES`` at ``q``."""
    frames = {"ground": (0.0, np.zeros(2))}
    for name, (parent, pos, k, *_rest) in ANDREWS_BODIES.items():
        a0, r0 = frames[parent]
        r = r0 + _rot2(a0) @ np.array([_pval(pos[0], p), _pval(pos[1], p)])
        frames[name] = (a0 + q[k], r)
    return frames


def andrews_point(q, key, p=ANDREWS_PARAMETERS):
    """World position of a point of ``ANDREWS_POINTS`` at ``q``."""
    body, (x, y) = ANDREWS_POINTS[key]
    a, r = andrews_frames(q, p)[body]
    return r + _rot2(a) @ np.array([_pval(x, p), _pval(y, p)])


def andrews_kinetic_energy(q, qd, p=ANDREWS_PARAMETERS, h=1e-4):
    """Kinetic energy of the seven bodies of ``ANDREWS_BODIES`` at ``(q, q')``, their
    centres' velocities and angular rates by the fourth-order central difference along
    ``q'`` (step ``h`` in time)."""
    frames = {s: andrews_frames(q + s * h * qd, p) for s in (-2, -1, 1, 2)}
    T = 0.0
    for name, (_parent, _pos, _k, com, mk, ik) in ANDREWS_BODIES.items():
        c = np.array([_pval(com[0], p), _pval(com[1], p)])
        centre = {s: frames[s][name][1] + _rot2(frames[s][name][0]) @ c for s in frames}
        angle = {s: frames[s][name][0] for s in frames}
        v = (8 * (centre[1] - centre[-1]) - (centre[2] - centre[-2])) / (12 * h)
        w = (8 * (angle[1] - angle[-1]) - (angle[2] - angle[-2])) / (12 * h)
        T += 0.5 * p[mk] * v @ v + 0.5 * p[ik] * w * w
    return T


def _rot2(a):
    c, s = math.cos(a), math.sin(a)
    return np.array([[c, -s], [s, c]])


# =======================================================================================
# Bricard's linkage: six unit rods along the edges of a cube, six revolutes
# =======================================================================================
#: The geometry of the IFToMM multibody benchmark A04 "Bricard mechanism" (Gonzalez,
#: Dopico, Lugris, Cuadrado, "A benchmarking system for MBS simulation software", Multibody
#: System Dynamics 16 (2006) 179-190; library at lim.ii.udc.es/mbsbenchmark; geometry read
#: from the OpenSim implementation MBSbenchmarksInOpenSim, A04 createModel.cpp): rods of
#: 1 m and 1 kg (square section 0.1 m), gravity -y.  Corners O = (0,0,0), P1 = (1,0,0),
#: P2 = (1,-1,0), P3 = (1,-1,1), P4 = (0,-1,1), P5 = (0,0,1); the ground is the sixth
#: link P5 -> O.  Joint axes, each normal to both links it joins: y at O, z at P1, x at P2,
#: y at P3, z at P4, x at P5 (the loop joint).  Every link has length 1, twist 90 degrees
#: and no offset.  Tree: rod i's frame sits at its first corner, parallel to the world
#: axes when all angles are zero; ``(position in the parent, axis)``.
BRICARD_JOINTS = (((0.0, 0.0, 0.0), (0.0, 1.0, 0.0)),      # ground -> rod1 at O
                  ((1.0, 0.0, 0.0), (0.0, 0.0, 1.0)),      # rod1 -> rod2 at P1
                  ((0.0, -1.0, 0.0), (1.0, 0.0, 0.0)),     # rod2 -> rod3 at P2
                  ((0.0, 0.0, 1.0), (0.0, 1.0, 0.0)),      # rod3 -> rod4 at P3
                  ((-1.0, 0.0, 0.0), (0.0, 0.0, 1.0)))     # rod4 -> rod5 at P4
#: Loop joint: rod5's end (0, 1, 0) in its frame meets P5 = (0, 0, 1) of the ground, axis x.
BRICARD_LOOP = ((0.0, 0.0, 1.0), (0.0, 1.0, 0.0), (1.0, 0.0, 0.0))
#: Each rod's centre of mass in its frame (the rod's midpoint).
BRICARD_COMS = ((0.5, 0.0, 0.0), (0.0, -0.5, 0.0), (0.0, 0.0, 0.5), (-0.5, 0.0, 0.0),
                (0.0, 0.5, 0.0))
BRICARD_MASS = 1.0
BRICARD_SECTION = 0.1
#: Time from the cube position (at rest) to q1 = pi, from bricard_reduced_rhs (computed
#: here with scipy's DOP853 at rtol 1e-11, atol 1e-12; not a published number).
BRICARD_HALF_PERIOD = 2.49585576


def bricard_inertias(m=BRICARD_MASS, L=1.0, s=BRICARD_SECTION):
    """Each rod's principal inertia about its centre, body axes (a box ``L x s x s``
    along its own axis: ``m (s^2 + s^2)/12`` about it, ``m (L^2 + s^2)/12`` across)."""
    ax, tr = m * 2 * s * s / 12, m * (L * L + s * s) / 12
    along = (0, 1, 2, 0, 1)                    # x, y, z, x, y
    out = []
    for k in along:
        d = [tr, tr, tr]
        d[k] = ax
        out.append(np.diag(d))
    return out


def rotation(axis, angle):
    """Rodrigues: the rotation by ``angle`` about the unit ``axis`` (maps rotated components
    to fixed ones)."""
    k = np.asarray(axis, float) / np.linalg.norm(axis)
    K = np.array([[0, -k[2], k[1]], [k[2], 0, -k[0]], [-k[1], k[0], 0]])
    return np.eye(3) + math.sin(angle) * K + (1 - math.cos(angle)) * K @ K


def bricard_frames(q):
    """``[(R_i, r_i)]`` of rods 1..5 for the five tree angles ``q``."""
    R, r, out = np.eye(3), np.zeros(3), []
    for (pos, axis), qi in zip(BRICARD_JOINTS, q):
        r = r + R @ np.asarray(pos)
        R = R @ rotation(axis, qi)
        out.append((R, r))
    return out


def bricard_loop_residual(q):
    """The revolute loop joint's 5 equations: rod5's point on P5 (3) and rod5's x axis along
    the ground's x axis (its y and z components, 2)."""
    R5, r5 = bricard_frames(q)[-1]
    ground_point, child_point, axis = BRICARD_LOOP
    gap = r5 + R5 @ np.asarray(child_point) - np.asarray(ground_point)
    a = R5 @ np.asarray(axis)
    return np.concatenate([gap, [a[1], a[2]]])


def bricard_grubler(n_links=6, revolutes=6):
    """Grubler-Kutzbach's spatial count ``6 (n - 1 - j) + sum f`` (Kutzbach 1929): 0 here."""
    return 6 * (n_links - 1 - revolutes) + revolutes


def bricard_phi(theta):
    """The motion in closed form: the five tree angles are ``(t, f, t, f, t)`` and the loop
    joint turns by ``-f``, with ``sin f = -sin t / (1 + sin t)`` -- a threefold symmetry of
    this linkage (derived here, and checked in the tests against a numeric solve of the
    loop: not found in the benchmark's documents).  Real for ``sin t >= -1/2``, i.e.
    ``t`` in [-pi/6, 7 pi/6].  Released from rest in the cube position (t = 0) under
    gravity, the mechanism swings to t = pi (where V is again V(0), all rods turned over)
    and back: ``bricard_reduced_rhs`` integrated at rtol 1e-11 reaches t = pi at
    2.49586 s (``BRICARD_HALF_PERIOD``), a period of 4.99171 s.  Returns ``(f, df/dt)``:
    ``df/dt = -cos t / ((1 + sin t) sqrt(1 + 2 sin t))``."""
    s, c = np.sin(theta), np.cos(theta)
    phi = np.arcsin(-s / (1 + s))
    return phi, -c / ((1 + s) * np.sqrt(1 + 2 * s))


def bricard_q(theta):
    """The five tree angles at ``theta`` (``bricard_phi``)."""
    phi = bricard_phi(theta)[0]
    return np.array([theta, phi, theta, phi, theta])


def _bricard_energy_terms(theta, g=G):
    """``(J, V)``: ``T = J(theta) theta'^2 / 2`` and the potential ``V(theta)`` of the five
    rods (gravity -y), from the frames of ``bricard_q`` and the rates
    ``dq/dtheta = (1, f', 1, f', 1)``; each rod's angular velocity is the sum of the joint
    rates along its axis, its centre's velocity ``w x (r_G - r_joint)`` summed down the
    chain."""
    q = bricard_q(theta)
    dq = np.array([1.0, bricard_phi(theta)[1], 1.0, bricard_phi(theta)[1], 1.0])
    frames = bricard_frames(q)
    inertias = bricard_inertias()
    J = V = 0.0
    axes_w, points = [], []
    Rp = np.eye(3)
    for k, ((pos, axis), (R, r)) in enumerate(zip(BRICARD_JOINTS, frames)):
        axes_w.append(Rp @ np.asarray(axis) * dq[k])   # joint k's axis in world, times rate
        points.append(r)
        Rp = R
        rG = r + R @ np.asarray(BRICARD_COMS[k])
        w = sum(axes_w)
        v = sum(np.cross(aw, rG - pj) for aw, pj in zip(axes_w, points))
        J += BRICARD_MASS * v @ v + w @ (R @ inertias[k] @ R.T) @ w
        V += BRICARD_MASS * g * rG[1]
    return J, V


def bricard_reduced_rhs(t, y, g=G, h=1e-3):
    """The 1-DoF equation of motion on the closed-form path, ``y = (theta, theta')``:
    Lagrange's ``J theta'' + J'(theta) theta'^2 / 2 + V'(theta) = 0`` with ``J'``, ``V'``
    by the fourth-order central difference (step ``h``; error ~1e-12).  An independent
    reference of the whole mechanism's motion (``scipy.integrate.solve_ivp`` on this)."""
    th, thd = y
    J, _ = _bricard_energy_terms(th, g)
    (J1, V1), (J2, V2) = _bricard_energy_terms(th + h, g), _bricard_energy_terms(th + 2 * h, g)
    (Jm1, Vm1), (Jm2, Vm2) = _bricard_energy_terms(th - h, g), _bricard_energy_terms(th - 2 * h, g)
    dJ = (8 * (J1 - Jm1) - (J2 - Jm2)) / (12 * h)
    dV = (8 * (V1 - Vm1) - (V2 - Vm2)) / (12 * h)
    return [thd, -(dJ * thd**2 / 2 + dV) / J]


def bricard_energy(theta, theta_dot, g=G):
    """Total energy ``J theta'^2 / 2 + V`` on the closed-form path."""
    J, V = _bricard_energy_terms(theta, g)
    return 0.5 * J * theta_dot**2 + V


# =======================================================================================
# Flyball governor (models/watt_governor.toml): spindle turning at Omega about z; at
# radius h and height H two arms hinged, hanging at alpha from the downward vertical, each
# with a ball at distance L; a link of length l = a from each arm (at a from the hinge) to
# the sleeve (hinged at radius h), which slides on the spindle at z_s = H - 2 a cos(alpha);
# a spring between the collar at (0, 0, H) and the sleeve.
# =======================================================================================
GOVERNOR = {"h": 0.03, "H": 0.30, "L": 0.25, "a": 0.12, "m_arm": 0.2, "r_arm": 0.006,
            "m_ball": 1.0, "r_ball": 0.04, "m_link": 0.1, "r_link": 0.005, "m_sleeve": 0.5,
            "k": 600.0, "L0": 0.25, "g": G}


def governor_inertias(P=GOVERNOR):
    """Principal inertias about the centres: arm and link as solid rods (radius ``r_*``)
    along their own axis: ``(I_transverse, I_axial)``; the ball a solid sphere."""
    arm = (P["m_arm"] * (3 * P["r_arm"]**2 + P["L"]**2) / 12, P["m_arm"] * P["r_arm"]**2 / 2)
    link = (P["m_link"] * (3 * P["r_link"]**2 + P["a"]**2) / 12,
            P["m_link"] * P["r_link"]**2 / 2)
    ball = 0.4 * P["m_ball"] * P["r_ball"]**2
    return arm, link, ball


def governor_terms(alpha, P=GOVERNOR):
    """``(M, dM, Jz, dJz, ddJz, V, dV, ddV)`` of the symmetric governor at arm angle
    ``alpha`` (both arms), derived here by hand:

    * ``T = M(alpha) alpha'^2 / 2 + Omega^2 Jz(alpha) / 2`` (+ the spindle's and the
      sleeve's constant spin): the relative motion lies in the plane of each arm and the
      cross terms with the spin vanish (each rod's inertia is symmetric about its own axis,
      and the relative velocities are normal to ``Omega x r``);
    * ``M = 2 [I_arm_t + m_arm L^2/4 + m_ball L^2 + I_ball
      + m_link ((a/2)^2 cos^2 + (3a/2)^2 sin^2) + I_link_t] + 4 m_sleeve a^2 sin^2``;
    * ``Jz = 2 [m_arm (h + L s/2)^2 + I_arm_t s^2 + I_arm_a c^2 + m_ball (h + L s)^2
      + I_ball + m_link (h + a s/2)^2 + I_link_t s^2 + I_link_a c^2]`` (about the spindle
      axis; ``s, c = sin, cos alpha``);
    * ``V = g [2 m_arm (H - L c/2) + 2 m_ball (H - L c) + 2 m_link (H - 3 a c/2)
      + m_sleeve (H - 2 a c)] + k (2 a c - L0)^2 / 2``."""
    s, c = math.sin(alpha), math.cos(alpha)
    h, H, L, a, g, k, L0 = (P[x] for x in ("h", "H", "L", "a", "g", "k", "L0"))
    ma, mb, ml, ms = P["m_arm"], P["m_ball"], P["m_link"], P["m_sleeve"]
    (Iat, Iaa), (Ilt, Ila), Ib = governor_inertias(P)
    M = (2 * (Iat + ma * L * L / 4 + mb * L * L + Ib
              + ml * (a * a / 4 * c * c + 9 * a * a / 4 * s * s) + Ilt)
         + 4 * ms * a * a * s * s)
    dM = 2 * ml * (9 - 1) * a * a / 4 * 2 * s * c + 8 * ms * a * a * s * c
    # Jz and its derivatives: sum of m (h + k s)^2 + It s^2 + Ia c^2 terms
    Jz = dJz = ddJz = 0.0
    for m_, k_, It, Ia in ((ma, L / 2, Iat, Iaa), (mb, L, 0.0, 0.0), (ml, a / 2, Ilt, Ila)):
        Jz += 2 * (m_ * (h + k_ * s)**2 + It * s * s + Ia * c * c)
        dJz += 2 * (2 * m_ * (h + k_ * s) * k_ * c + 2 * (It - Ia) * s * c)
        ddJz += 2 * (2 * m_ * (k_ * c)**2 - 2 * m_ * (h + k_ * s) * k_ * s
                     + 2 * (It - Ia) * (c * c - s * s))
    Jz += 2 * Ib
    # V_gravity = g (const - lever cos(alpha))
    lever = 2 * ma * L / 2 + 2 * mb * L + 2 * ml * 3 * a / 2 + ms * 2 * a
    V = g * (2 * ma + 2 * mb + 2 * ml + ms) * H - g * lever * c + 0.5 * k * (2 * a * c - L0)**2
    dV = g * lever * s - k * (2 * a * c - L0) * 2 * a * s
    ddV = g * lever * c + k * (2 * a * s)**2 - k * (2 * a * c - L0) * 2 * a * c
    return M, dM, Jz, dJz, ddJz, V, dV, ddV


def governor_equilibrium_speed(alpha, P=GOVERNOR):
    """The spindle speed at which the arms stay at ``alpha``: the effective potential
    ``V - Omega^2 Jz / 2`` is stationary, ``Omega^2 = 2 V'(alpha) / Jz'(alpha)``
    (Lagrange in the turning frame, derived here: the classic Porter/Hartnell-governor
    balance of machine-theory texts, here with rods, balls, links, sleeve and spring)."""
    _, _, _, dJz, _, _, dV, _ = governor_terms(alpha, P)
    return math.sqrt(2 * dV / dJz)


def governor_frequency(alpha, P=GOVERNOR):
    """Angular frequency of small oscillations of the arms about the steady state at
    ``alpha`` (spindle at ``governor_equilibrium_speed(alpha)``):
    ``w^2 = (V'' - Omega^2 Jz'' / 2) / M``."""
    M, _, _, dJz, ddJz, _, dV, ddV = governor_terms(alpha, P)
    Om2 = 2 * dV / dJz
    return math.sqrt((ddV - 0.5 * Om2 * ddJz) / M)


def governor_rhs(t, y, Omega, P=GOVERNOR):
    """``(alpha', alpha'')`` of the reduced equation
    ``M alpha'' + M' alpha'^2 / 2 - Omega^2 Jz' / 2 + V' = 0`` (spindle driven at the
    constant ``Omega``)."""
    al, ald = y
    M, dM, _, dJz, _, _, dV, _ = governor_terms(al, P)
    return [ald, (0.5 * Omega**2 * dJz - dV - 0.5 * dM * ald**2) / M]
