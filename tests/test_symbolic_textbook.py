"""The textbook reproduced in closed form (EXAMPLES.md): the derived equations are
symbolically equal to the text's.

* 1.4.2 double pendulum: theta1'', theta2'', Tr1, Tr2 exactly as printed by the Pascal
  listing ``pend2`` (copied below verbatim, ``Power(x,2)`` = ``x**2``), by Newton-Euler with
  the rod forces as reaction unknowns;
* 1.4.3 heavy top: the three equations of the listing ``top`` and the contact force
  ``B2 R = m B2 a_G - B2 P``;
* 1.4.1 rotating pendulum: the equation of motion and the reactions ``R`` and ``T``.
"""
import re
import warnings

import sympy as sp

import mbdyn as mb
from mbdyn.symbolic import compare_methods, derive, same_expression

from textbook_systems import (DOUBLE_PENDULUM_DATA, double_pendulum_system,
                              rotating_pendulum_system, with_symbols)

# ----------------------------------------------------------------------------- 1.4.2
LISTING = {
    "ddt1": """(g*l2*m1*m2*Sin(t1) - Power(dt1,2)*Power(l2,2)*Power(m2,2)*Sin(t2) - 2*dt1*dt2*Power(l2,2)*Power(m2,2)*Sin(t2) -Power(dt2,2)*Power(l2,2)*Power(m2,2)*Sin(t2) -Power(dt1,2)*l1*l2*Power(m2,2)*Cos(t2)*Sin(t2) -g*l2*Power(m2,2)*Cos(t1 + t2)*Sin(t2))/(-(l1*l2*m1*m2) - l1*l2*Power(m2,2)*Power(Sin(t2),2))""",
    "ddt2": """(-(g*l2*m1*m2*Sin(t1)) - g*l1*m1*m2*Cos(t2)*Sin(t1) +Power(dt1,2)*Power(l1,2)*m1*m2*Sin(t2) +Power(dt1,2)*Power(l2,2)*Power(m2,2)*Sin(t2) +2*dt1*dt2*Power(l2,2)*Power(m2,2)*Sin(t2) +Power(dt2,2)*Power(l2,2)*Power(m2,2)*Sin(t2) +2*Power(dt1,2)*l1*l2*Power(m2,2)*Cos(t2)*Sin(t2) + 2*dt1*dt2*l1*l2*Power(m2,2)*Cos(t2)*Sin(t2) +Power(dt2,2)*l1*l2*Power(m2,2)*Cos(t2)*Sin(t2) +Power(dt1,2)*Power(l1,2)*Power(m2,2)*Power(Cos(t2),2)*Sin(t2) +g*l2*Power(m2,2)*Cos(t1 + t2)*Sin(t2) +g*l1*Power(m2,2)*Cos(t2)*Cos(t1 + t2)*Sin(t2) +Power(dt1,2)*Power(l1,2)*Power(m2,2)*Power(Sin(t2),3) +g*l1*m1*m2*Sin(t1 + t2) +g*l1*Power(m2,2)*Power(Sin(t2),2)*Sin(t1 + t2))/(-(l1*l2*m1*m2) - l1*l2*Power(m2,2)*Power(Sin(t2),2))""",
    "Tr1": """(-(Power(dt1,2)*Power(l1,2)*l2*Power(m1,2)*m2) - g*l1*l2*Power(m1,2)*m2*Cos(t1) -Power(dt1,2)*l1*Power(l2,2)*m1*Power(m2,2)*Cos(t2) -2*dt1*dt2*l1*Power(l2,2)*m1*Power(m2,2)*Cos(t2) -Power(dt2,2)*l1*Power(l2,2)*m1*Power(m2,2)*Cos(t2) -Power(dt1,2)*Power(l1,2)*l2*m1*Power(m2,2)*Power(Cos(t2),2) -g*l1*l2*m1*Power(m2,2)*Cos(t2)*Cos(t1 + t2) -g*l1*l2*m1*Power(m2,2)*Cos(t2)*Sin(t1)*Sin(t2) -Power(dt1,2)*Power(l1,2)*l2*m1*Power(m2,2)*Power(Sin(t2),2) -g*l1*l2*m1*Power(m2,2)*Cos(t1)*Power(Sin(t2),2))/(-(l1*l2*m1*m2) - l1*l2*Power(m2,2)*Power(Sin(t2),2))""",
    "Tr2": """(-(Power(dt1,2)*l1*Power(l2,2)*m1*Power(m2,2)) - 2*dt1*dt2*l1*Power(l2,2)*m1*Power(m2,2) -Power(dt2,2)*l1*Power(l2,2)*m1*Power(m2,2) -Power(dt1,2)*Power(l1,2)*l2*m1*Power(m2,2)*Cos(t2) -g*l1*l2*m1*Power(m2,2)*Cos(t1 + t2) -g*l1*l2*m1*Power(m2,2)*Sin(t1)*Sin(t2))/(-(l1*l2*m1*m2) - l1*l2*Power(m2,2)*Power(Sin(t2),2))""",
}


def pascal(text, names):
    """A Mathematica-style expression of the listing as sympy, in the model's names."""
    text = text.replace("Power", "pow").replace("Sin", "sin").replace("Cos", "cos")
    for old, new in (("dt1", "theta1_dot"), ("dt2", "theta2_dot"), ("t1", "theta1"),
                     ("t2", "theta2")):
        text = re.sub(rf"\b{old}\b", new, text)
    return sp.sympify(text, locals=dict(names, pow=sp.Pow))


def double_pendulum():
    return with_symbols(double_pendulum_system, dict(DOUBLE_PENDULUM_DATA, g=9.81))


def test_double_pendulum_listing():
    d = derive(double_pendulum(), "newton-euler", solve=True)
    names = d.names()
    listing = {k: pascal(v, names) for k, v in LISTING.items()}
    assert same_expression(d.accelerations["theta1_dot"], listing["ddt1"])
    assert same_expression(d.accelerations["theta2_dot"], listing["ddt2"])
    # rod forces, tension positive: +y of each joint's reaction in the child frame
    Fx1, Tr1, Fz1, *M1 = d.reactions["theta1"]
    Fx2, Tr2, Fz2, *M2 = d.reactions["theta2"]
    assert same_expression(Tr1, listing["Tr1"])
    assert same_expression(Tr2, listing["Tr2"])
    # massless rods carry no transverse force and no moment
    assert all(e == 0 or same_expression(e, 0) for e in [Fx1, Fz1, Fx2, Fz2] + M1 + M2)


def test_double_pendulum_all_methods_same_equations():
    ds = [derive(double_pendulum(), m) for m in ("newton-euler", "jourdain", "lagrange")]
    assert all(compare_methods(ds).values())


# ----------------------------------------------------------------------------- 1.4.3
def top_system():
    s = mb.System("top", parameters={"m": 0.582, "h": 0.0558, "A": 0.00209393,
                                     "C": 0.0022058, "Mz": -0.025, "g": 9.81},
                  gravity=(0, 0, -sp.Symbol("g", real=True)))
    m, h, A, C, Mz = s.symbols("m h A C Mz")
    # the text gives A = Ixx = Iyy and C = Izz about the contact point O
    s.add_body("top", mass=m, com=(0, 0, h), inertia=(A - m * h**2, A - m * h**2, C))
    s.add_joint("contact", "euler", parent="ground", child="top", sequence="ZXZ",
                coordinates=("psi", "theta", "phi"))
    s.add_load("Mz", "top", moment=(0, 0, Mz), frame="body")
    return s


def test_top_three_equations_and_contact_force():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")      # the listing's data break the triangle rule
        model = top_system().compile()
    d = derive(model, "newton-euler", solve=True)
    n = d.names()
    m, h, A, C, Mz, g = (n[k] for k in ("m", "h", "A", "C", "Mz", "g"))
    th, phi = n["theta"], n["phi"]
    dpsi, dth, dphi = n["psi_dot"], n["theta_dot"], n["phi_dot"]
    acc = d.accelerations
    theta_dd = (m * g * h * sp.sin(th) + dpsi**2 * (A - C) * sp.sin(th) * sp.cos(th)
                - C * dphi * dpsi * sp.sin(th)) / A
    psi_dd = (C * dpsi * dth * sp.cos(th) - 2 * A * dpsi * dth * sp.cos(th)
              + C * dphi * dth) / (A * sp.sin(th))
    phi_dd = -psi_dd * sp.cos(th) + dpsi * dth * sp.sin(th) + Mz / C
    assert same_expression(acc["theta_dot"], theta_dd)
    assert same_expression(acc["psi_dot"], psi_dd)
    assert same_expression(acc["phi_dot"], phi_dd)
    # contact force: B2 R = m B2 a_G - B2 P, B2 the nutation frame (the body turned back
    # by the spin phi); our reaction is in the body frame B3 = T_z(phi) B2
    aG = h * sp.Matrix([2 * dpsi * dth * sp.cos(th) + psi_dd * sp.sin(th),
                        dpsi**2 * sp.sin(th) * sp.cos(th) - theta_dd,
                        -dpsi**2 * sp.sin(th)**2 - dth**2])
    P = sp.Matrix([0, -m * g * sp.sin(th), -m * g * sp.cos(th)])
    R_B2 = m * aG - P
    Rz = sp.Matrix([[sp.cos(phi), -sp.sin(phi), 0], [sp.sin(phi), sp.cos(phi), 0], [0, 0, 1]])
    ours_B2 = Rz * sp.Matrix(d.reactions["contact"][:3])
    for a, b in zip(ours_B2, R_B2):
        assert same_expression(a, b)
    assert d.reactions["contact"][3:] == [0, 0, 0]      # a ball joint: no moment


# ----------------------------------------------------------------------------- 1.4.1
def rotating_pendulum(Omega, omega):
    values = {"a": 0.5, "b": 0.4, "c": 0.1, "r": 0.15, "h": 0.2, "l": 0.25, "m": 0.1, "g": 9.81}
    return with_symbols(rotating_pendulum_system, values, Omega=Omega, omega=omega)


def test_rotating_pendulum_equation_and_reactions():
    Omega, omega = sp.pi / 4, sp.pi / 3          # different rates, so that none is mixed up
    d = derive(rotating_pendulum(Omega, omega), "newton-euler", solve=True)
    n = d.names()
    g, b, r, l, m, t = (n[k] for k in ("g", "b", "r", "l", "m", "t"))
    beta, dbeta = n["beta"], n["beta_dot"]
    W = Omega + omega
    beta_dd = (-(g / l) * sp.sin(beta)
               + (b * Omega**2 * sp.cos(omega * t) + r * W**2) / l * sp.cos(beta)
               + W**2 * sp.sin(beta) * sp.cos(beta))
    R = -m * (b * Omega**2 * sp.sin(omega * t) + 2 * l * W * dbeta * sp.cos(beta))
    T = m * (g * sp.cos(beta) + (b * Omega**2 * sp.cos(omega * t) + r * W**2) * sp.sin(beta)
             + l * (dbeta**2 + W**2 * sp.sin(beta)**2))
    assert same_expression(d.accelerations["beta_dot"], beta_dd)
    Fx, Fy, Fz = d.reactions["beta"][:3]        # B3 components: the text's [R, 0, T]
    assert same_expression(Fx, R)
    assert Fy == 0 or same_expression(Fy, 0)
    assert same_expression(Fz, T)
    # and the three methods give the same equation
    ds = [d] + [derive(rotating_pendulum(Omega, omega), mm) for mm in ("jourdain", "lagrange")]
    assert all(compare_methods(ds).values())


def test_solution_satisfies_every_newton_euler_equation():
    """The text solves the double pendulum's Newton equations, a linear system in
    [T1, T2, theta1'', theta2''], by Cramer's rule; here: the solved accelerations and all
    reaction components satisfy every body's Newton and Euler equations identically."""
    from mbdyn.symbolic.steps import newton_euler_equations
    d = derive(double_pendulum(), "newton-euler", solve=True)
    unknowns, equations = newton_euler_equations(d)
    values = dict(zip(d.rates, [d.accelerations[s] for s in d.speeds]))
    for joint, (R, M) in unknowns.items():
        sol = d.reactions[joint]
        for sym, val in zip(list(R) + list(M), sol):
            if isinstance(sym, sp.Symbol):
                values[sym] = val
    assert len(equations) == 4
    for label, lhs, rhs in equations:
        for a, b in zip(lhs, rhs):
            assert same_expression(a.xreplace(values), b.xreplace(values)), label
