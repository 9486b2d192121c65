"""The derivation trace of a closed mechanism: step 3's constraint equations (the loop
joints' points and ``phi(q, t) = 0``), and the equations of motion with the multipliers
(``Phi_q``, ``G``, ``gamma``, ``M u' = f + G^T lambda``); ``mbdyn.symbolic.loops`` derives
them.
"""
from __future__ import annotations

import sympy

from .step_record import Step


def _tex(label):
    return label.replace("_", r"\_")


def constraint_entries(st, d):
    """Step 3's part for the loops: each loop joint's two points in world components and
    its rows of ``phi(q, t) = 0``."""
    c = d.constraints
    if c is None:
        return
    st.title = "Position vectors and constraint equations"
    st.text += (" Each loop joint is cut: its points, P on the parent and P' on the child "
                "(world components), give the constraint equations phi(q, t) = 0 "
                "(points coincide, axes stay perpendicular, a point stays in a plane, a "
                "rod keeps its length, coordinates stay geared).")
    seen = set()
    for p in c.primitives:
        if p.kind != "COUPLE" and p.joint not in seen:
            seen.add(p.joint)
            st.add(f"I r_P ({p.joint}, on {p.parent})", rf"{{}}^{{I}}r_{{P,\text{{{_tex(p.joint)}}}}}",
                   p.world[0])
            st.add(f"I r_P' ({p.joint}, on {p.child})",
                   rf"{{}}^{{I}}r_{{P',\text{{{_tex(p.joint)}}}}}", p.world[1])
        for r in p.rows:
            label = c.rows[r]
            st.add(f"phi[{label}] ({p.kind.lower()})", rf"\phi_{{\text{{{_tex(label)}}}}}",
                   (c.phi[r], sympy.Integer(0)), "identically" if c.phi[r] == 0 else "")


def multiplier_step(d):
    """The constraints' Jacobian, ``gamma`` and the equations with the multipliers."""
    c = d.constraints
    lagrange = d.method == "lagrange"
    text = ("Phi_q = d phi / d q; the speeds enter by G = Phi_q N(q) (q' = N(q) u), so "
            "d phi/dt = G u + phi_t and the accelerations satisfy G u' = gamma; one "
            "multiplier a row: M u' = f + G^T lambda.")
    if lagrange:
        text += (" By Lagrange (u = q', G = Phi_q): d/dt dL/dq' - dL/dq = Q + Phi_q^T "
                 "lambda with L = T - V.")
    elif d.method == "newton-euler":
        text += (" By Newton-Euler the multipliers are forces and moments on the bodies "
                 "(in the loads and the reactions above); projected on the speeds they "
                 "are G^T lambda.")
    st = Step("13" if d.method != "newton-euler" else "12",
              "Constraint Jacobian and multipliers", text)
    st.add("lambda", r"\lambda", sympy.Matrix(c.multipliers))
    st.add("Phi_q", r"\Phi_q", c.jacobian)
    if c.speed_form:
        st.add("G = Phi_q N", "G", c.G)
    if any(e != 0 for e in c.phi_t):
        st.add("phi_t", r"\phi_t", c.phi_t, "the drives' part of d phi/dt")
    st.add("gamma", r"\gamma", c.gamma)
    st.add("G^T lambda", r"G^T \lambda", c.constraint_forces())
    return st
