"""The loads of the loop multipliers (``kernels.constraints.constraint_wrenches``) against
routes that do not use them: the virtual power of every primitive's wrench against its
multiplier times its residual's rate (``Model.constraint_residuals``, the constraint rows'
own code), and the pin forces of a driven four-bar against a hand-written Newton-Euler
solve of its three links (planar, from Freudenstein's closed form)."""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import mbdyn as mb
from loop_mechanisms import FOUR_BAR, MASSES, four_bar, four_bar_rates, freudenstein
from mbdyn.kernels import constraints as kcon
from test_loops_random import random_closed

MODELS = Path(__file__).resolve().parent.parent / "models"


def _geared():
    """Two wheels and a slider geared together: ``COUPLE`` rows with a revolute and a
    prismatic follower (a torque and a force), off-axis centres of mass."""
    s = mb.System("gears", gravity=(0, -9.81, 0))
    for name, com in (("w1", (0.1, 0.2, 0)), ("w2", (0, 0.1, 0.3)), ("sl", (0.2, 0, 0.1))):
        s.add_body(name, mass=1.0, inertia=(0.1, 0.1, 0.05), com=com)
    s.add_joint("a", "revolute", "ground", "w1", axis=(0, 0.6, 0.8))
    s.add_joint("b", "revolute", "ground", "w2", axis="z", position=(1, 0, 0))
    s.add_joint("c", "prismatic", "w1", "sl", axis=(1, 2, 3), position=(0, 1, 0))
    s.add_joint("mesh", "coupling", follower="b", leader="a", ratio=-2.0, offset=0.0)
    s.add_joint("rack", "coupling", follower="c", leader="b", ratio=0.3, offset=0.0)
    m = s.compile()
    q, u = m.assemble({"a": 0.4}, {"a": 1.3})
    return m, q, u, 0.0


def _point_velocity(kin, i, P):
    """World velocity of the material point of frame ``i`` (-1: the ground) at ``P``."""
    return np.zeros(3) if i < 0 else kin.v[i] + np.cross(kin.w[i], P - kin.r[i])


def _check_power(m, q, u, t, rng):
    """The loads of random multipliers: their power on the motion ``(q, u)`` (``q`` on
    the mechanism, any ``u``) is ``lam . psi``, in all (``F``, ``N``) and primitive by
    primitive (``out``)."""
    con_int, con_data = m._con[0], m._con[1]
    rows = kcon.ROWS[con_int[:, 0]]
    _, psi = m.constraint_residuals(q, u, t)
    if np.abs(m.constraint_jacobian(q, t)).max() > 0:     # a loop some speed moves
        assert np.abs(psi).max() > 1e-3
    kin = m.kinematics(q, u, t=t)
    lam = rng.normal(size=rows.sum())
    n = m.n_frames
    F, N, out = np.zeros((n, 3)), np.zeros((n, 3)), np.full((con_int.shape[0], 6), np.nan)
    kcon.constraint_wrenches(con_int, con_data, m._parent, m._kind, m._axis, kin.R, kin.r,
                             lam, F, N, m._com, out)
    power = np.sum(F * kin.v_com) + np.sum(N * kin.w)
    scale = 1.0 + np.abs(lam).sum() * (1.0 + np.abs(kin.v_com).max() + np.abs(kin.w).max())
    assert abs(power - lam @ psi) <= 1e-12 * scale
    row = 0
    for k, (kind, ip, ic) in enumerate(con_int[:, :3]):
        mine = slice(row, row + rows[k])
        row += rows[k]
        if kind == kcon.COUPLE:
            assert (out[k] == 0).all()
            continue
        sc = con_data[k, 3:6]
        P = sc if ic < 0 else kin.r[ic] + kin.R[ic] @ sc
        w_c = np.zeros(3) if ic < 0 else kin.w[ic]
        w_p = np.zeros(3) if ip < 0 else kin.w[ip]
        rel = _point_velocity(kin, ic, P) - _point_velocity(kin, ip, P)
        got = out[k, :3] @ rel + out[k, 3:] @ (w_c - w_p)
        assert abs(got - lam[mine] @ psi[mine]) <= 1e-12 * scale, (k, kind)


@pytest.mark.parametrize("case", [*range(12), "gears", "four_bar", "slider_crank",
                                  "andrews_squeezer", "bricard"])
def test_multiplier_loads_do_the_multipliers_power(case):
    """Every kind of primitive (points, perpendicular vectors, planes, rods, gears with a
    torque and with a force), parents on the ground and on bodies."""
    if isinstance(case, int):
        m, q, u, t = random_closed(case)
    elif case == "gears":
        m, q, u, t = _geared()
    else:
        scene = mb.load_model(MODELS / f"{case}.toml")
        m, t = scene.model, 0.0
        q, u = m.project(scene.q0, scene.u0 + 0.7, t)
    assert np.abs(m.constraint_residuals(q, u, t)[0]).max() < 1e-9
    rng = np.random.default_rng(7)
    for _ in range(3):      # speeds off the constraints: every residual's rate non-zero
        _check_power(m, q, rng.normal(size=m.nu), t, rng)


def _e(x):
    return np.array([np.cos(x), np.sin(x)])


def _p(x):
    return np.array([-np.sin(x), np.cos(x)])


def _cross2(a, b):
    return a[0] * b[1] - a[1] * b[0]


def _hand_four_bar(th2, w2, al2, g=9.81):
    """The four-bar's pin forces by Newton-Euler on each link, planar, by hand: the forces
    on the crank at A (ground), on the coupler at B (crank), on the rocker at O4 (ground)
    and at D (coupler), and the drive torque; ``(F_A, F_B, F_O, F_D, tau)``."""
    a, b, c, d = (FOUR_BAR[k] for k in "abcd")
    th4, th3 = freudenstein(th2, +1)
    w3, w4, al3, al4 = four_bar_rates(th2, w2, al2, th3, th4)
    A, O4 = np.zeros(2), np.array([d, 0.0])
    B, D = a * _e(th2), O4 + c * _e(th4)
    links = []                        # (mass, Izz, centre, its acceleration, alpha)
    for L, name, O, aO, th, w, al in ((a, "crank", A, np.zeros(2), th2, w2, al2),
                                      (b, "coupler", B, a * (al2 * _p(th2) - w2 ** 2 * _e(th2)),
                                       th3, w3, al3),
                                      (c, "rocker", O4, np.zeros(2), th4, w4, al4)):
        mass = MASSES[name]
        links.append((mass, mass * L * L / 12 + 1e-4, O + L / 2 * _e(th),
                      aO + L / 2 * (al * _p(th) - w * w * _e(th)), al))
    # unknowns x = (F_A, F_B, F_O, F_D, tau); per link: force balance (2), moment about G
    M, rhs = np.zeros((9, 9)), np.zeros(9)
    acting = ((((0, A, 1.0), (1, B, -1.0)), True), (((1, B, 1.0), (3, D, -1.0)), False),
              (((2, O4, 1.0), (3, D, 1.0)), False))
    for k, ((mass, Izz, G, aG, al), (forces, driven)) in enumerate(zip(links, acting)):
        for j, P, sign in forces:
            M[3 * k:3 * k + 2, 2 * j:2 * j + 2] += sign * np.eye(2)
            M[3 * k + 2, 2 * j:2 * j + 2] += sign * np.array([-(P - G)[1], (P - G)[0]])
        M[3 * k + 2, 8] = 1.0 if driven else 0.0
        rhs[3 * k:3 * k + 2] = mass * (aG - np.array([0.0, -g]))
        rhs[3 * k + 2] = Izz * al
    x = np.linalg.solve(M, rhs)
    return x[0:2], x[2:4], x[4:6], x[6:8], x[8], (th3 - th2, th4)


@pytest.mark.parametrize("t", [0.0, 0.4, 1.1, 2.5])
def test_four_bar_pin_forces_against_a_hand_newton_euler(t):
    """In-plane forces at the four pins (the loop joint D's on the rocker at its point)
    and the crank's drive torque, with the crank turning at 2 rad/s."""
    m = four_bar(drive=2.0 * mb.t + 0.3)
    th2 = 2.0 * t + 0.3
    F_A, F_B, F_O, F_D, tau, (th3, th4) = _hand_four_bar(th2, 2.0, 0.0)
    q, u = m.assemble(guess={"th3": (th3 + np.pi) % (2 * np.pi) - np.pi, "th4": th4}, t=t)
    assert abs(q[m.coordinate_index("th4")] - th4) < 1e-9
    r = m.reactions(q, u, t)
    scale = 1.0 + max(np.abs(v).max() for v in (F_A, F_B, F_O, F_D))
    for joint, want in (("th2", F_A), ("th3", F_B), ("th4", F_O), ("D", F_D)):
        np.testing.assert_allclose(r[joint][0][:2], want, rtol=0, atol=1e-9 * scale)
        assert abs(r[joint][1][2] - (tau if joint == "th2" else 0.0)) < 1e-9 * scale
