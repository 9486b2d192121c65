"""The derivation trace's steps that differ by method: Newton-Euler's equations with the
reaction unknowns, Jourdain's projection by the Jacobians, Lagrange's energies and their
derivatives (steps 11-12 of the textbook).
"""
from __future__ import annotations

import sympy

from .step_record import LATEX_NAMES, Step, _nonzero
from .symbols import cross


def reaction_symbols(walk, m):
    """Unknown reaction components of a joint (force, moment), basis components, with
    zeros where a coordinate-aligned direction is free."""
    from .methods import _projectors
    PF, PM = _projectors(walk, m)
    name = m.joint.name
    F = sympy.Matrix([sympy.Symbol(f"R_{name}_{c}", real=True) for c in "xyz"])
    M = sympy.Matrix([sympy.Symbol(f"M_{name}_{c}", real=True) for c in "xyz"])
    joint_tex = sympy.latex(sympy.Symbol(name))
    for vec, letter in ((F, "R"), (M, "M")):
        for sym, c in zip(vec, "xyz"):
            LATEX_NAMES[sym] = f"{letter}^{{{joint_tex}}}_{{{c}}}"
    for k in range(3):
        if PF[:, k].is_zero_matrix:
            F[k] = 0
        if PM[:, k].is_zero_matrix:
            M[k] = 0
    return F, M


def newton_euler_equations(d):
    """The per-body Newton and Euler equations of a newton-euler derivation with the
    reaction components as unknown symbols: ``(unknowns, equations)``, ``unknowns``
    ``{joint: (R, M)}`` (symbol vectors, basis components), ``equations`` a list of
    ``(label, lhs, rhs)`` vectors."""
    walk = d.walk
    react = {m.name: reaction_symbols(walk, m) for m in walk.motions}
    out = []
    for body in d.equations.details["bodies"]:
        m = walk.by_name[body["body"]]
        F, M = react[m.name]
        lhsF = F + m.force
        lhsM = M + m.moment + cross(body["com"], m.force)
        for (jname, X, rho) in body["children"]:
            ch = walk.by_name[walk.model.joint(jname).child]
            Fc, Mc = react[ch.name]
            lhsF = lhsF - X * Fc
            lhsM = lhsM - X * Mc - cross(rho, X * Fc)
        rhsM = walk.s(body["euler_G"] + cross(body["com"], body["m_aG"]))
        out.append((f"Newton {m.name}", walk.s(lhsF), body["m_aG"]))
        out.append((f"Euler {m.name}", walk.s(lhsM), rhsM))
    return {walk.by_name[n].joint.name: v for n, v in react.items()}, out


def _newton_euler_steps(d, fl, basis):
    walk = d.walk
    eq = d.equations
    unknowns, equations = newton_euler_equations(d)
    out = []
    st = Step("11", "Reaction forces and moments (free-body diagram)",
              "Unknowns: the force R and moment M each parent exerts on its child at the "
              "child frame's origin; none along a joint's free directions.")
    for m in walk.motions:
        F, M = unknowns[m.joint.name]
        b = basis(m)
        st.add(f"{b[0]} R_{m.joint.name}", f"{{}}^{{{b[1]}}}R_{{\\text{{{m.joint.name}}}}}", F)
        if _nonzero(M):
            st.add(f"{b[0]} M_{m.joint.name}", f"{{}}^{{{b[1]}}}M_{{\\text{{{m.joint.name}}}}}", M)
    out.append(st)
    st = Step("12", "Newton-Euler equations",
              "Newton sum F = m a_G and Euler about the frame origin sum M_O = I_G alpha + "
              "w x I_G w + r_OG x m a_G, for every body, with the reactions of its own joint "
              "(+) and of its children's joints (-).")
    for (label, lhs, rhs), body in zip(equations, [b for b in eq.details["bodies"]
                                                   for _ in (0, 1)]):
        m = walk.by_name[body["body"]]
        k = m.index + 1
        what = "Newton" if label.startswith("Newton") else f"Euler about O{k}"
        st.add(f"{what}, body {k} ({m.name}), {basis(m)[0]}",
               f"\\text{{{what.split()[0]}, body {k}}}", (lhs, rhs))
    out.append(st)
    st = Step("12", "Reactions in terms of the accelerations",
              "Each body's equations solved for its joint's reaction, leaves first.")
    for m in walk.motions:
        F, M = eq.details["reactions"][m.joint.name]
        b = basis(m)
        st.add(f"{b[0]} R_{m.joint.name}", f"{{}}^{{{b[1]}}}R_{{\\text{{{m.joint.name}}}}}", F)
        if _nonzero(M):
            st.add(f"{b[0]} M_{m.joint.name}", f"{{}}^{{{b[1]}}}M_{{\\text{{{m.joint.name}}}}}", M)
    out.append(st)
    return out


def _jourdain_steps(d, fl, basis):
    walk = d.walk
    st = Step("13", "Jacobians of translation and rotation",
              "J_T,i = d v_Gi / d u and J_R,i = d w_i / d u; then "
              "sum J_T^T (F - m a_G) + J_R^T (M_G - I alpha - w x I w) = 0.")
    for m in walk.motions:
        if not m.has_inertia:
            continue
        b = basis(m)
        k = m.index + 1
        st.add(f"{b[0]} J_T{k}", f"{{}}^{{{b[1]}}}J_{{T,{k}}}", m.JT)
        if _nonzero(m.inertia):
            st.add(f"{b[0]} J_R{k}", f"{{}}^{{{b[1]}}}J_{{R,{k}}}", m.JR)
    return [st]


def _lagrange_steps(d, fl, basis):
    det = d.equations.details
    st = Step("13", "Energies and generalized forces",
              "T = sum 1/2 m v_G . v_G + 1/2 w . I_G w, V = -sum m g . r_G, "
              "Q = sum J_T^T F + J_R^T M over the loads; then "
              "d/dt dT/du - dT/dq + dV/dq = Q with u = q'.")
    for name, Tm, Vm in det["bodies"]:
        m = d.walk.by_name[name]
        k = m.index + 1
        st.add(f"T_{k} ({name})", f"T_{{{k}}}", Tm)
        if Vm != 0:
            st.add(f"V_{k} ({name})", f"V_{{{k}}}", Vm)
    st.add("T", "T", det["kinetic"])
    st.add("V", "V", det["potential"])
    if _nonzero(det["generalized_forces"]):
        st.add("Q", "Q", det["generalized_forces"])
    st.add("dT/du", r"\partial T / \partial u", sympy.Matrix(det["momenta"]).applyfunc(d.walk.s))
    return [st]
