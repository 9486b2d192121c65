"""The derivation trace: the textbook's steps 1-13 for one model, as data.

``build_steps(derivation)`` returns a list of ``Step``: each has the textbook's step number,
a title, a sentence of explanation and ``Entry`` items -- a label (plain text and LaTeX) and
a value (a sympy expression or matrix, an equation ``(lhs, rhs)``, or text).  The formats
in ``mbdyn.symbolic.report`` render it.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import sympy

from .symbols import cross


#: LaTeX of the symbols the steps introduce (reaction unknowns)
LATEX_NAMES = {}


@dataclass
class Entry:
    label: str
    latex: str
    value: object
    note: str = ""


@dataclass
class Step:
    number: str
    title: str
    text: str = ""
    entries: list = field(default_factory=list)

    def add(self, label, latex, value, note=""):
        self.entries.append(Entry(label, latex, _tidy(value), note))


def _tidy(value):
    """Contract sums of angles in small displayed values (``finish``)."""
    from .simplify import finish
    if isinstance(value, sympy.MatrixBase):
        return value.applyfunc(lambda e: finish(e, limit=60))
    if isinstance(value, tuple):
        return tuple(_tidy(v) for v in value)
    if isinstance(value, sympy.Basic):
        return finish(value, limit=60)
    return value


def _nonzero(v):
    return any(e != 0 for e in v)


def _frame_labels(walk):
    """``{frame name: (text label, latex label)}`` of the bases: B1..Bn, or I."""
    out = {"ground": ("I", "I")}
    for m in walk.motions:
        out[m.name] = (f"B{m.index + 1}", f"B_{{{m.index + 1}}}")
    return out


def build_steps(d):
    walk = d.walk
    sym = walk.sym
    fl = _frame_labels(walk)
    own = walk.frames == "own"

    def basis(m):
        return fl[m.name] if own else ("I", "I")

    steps = []
    # 1 -------------------------------------------------------------- frames
    st = Step("1", "Reference frames",
              "An inertial frame I and one moving frame attached to each body; each frame "
              "hangs from its parent through a joint.")
    for m in walk.motions:
        j = m.joint
        qj, uj, udj, driven = walk.joint_values[j.name]
        what = f"{j.kind} joint {j.name!r} from {fl[j.parent][0]} ({j.parent})"
        if j.kind in ("revolute", "prismatic"):
            what += f", axis {list(walk._joint_geometry(j)[0])}"
        if j.kind == "euler":
            what += ", sequence " + "".join("XYZ"[k] for k in j.sequence)
        if driven:
            what += f", driven: {j.coordinates[0]} = {sympy.sstr(qj[0])}"
        elif j.coordinates:
            what += ", coordinates " + ", ".join(j.coordinates)
        st.add(f"{fl[m.name][0]} ({m.name})", fl[m.name][1], what)
    steps.append(st)
    # 2 -------------------------------------------------------------- transformation matrices
    st = Step("2", "Transformation matrices",
              "B s = T . P s maps a vector's components in the parent frame P to the moving "
              "frame B; P s = T^T . B s.")
    for m in walk.motions:
        p = fl[m.parent]
        st.add(f"T_{m.index + 1} ({p[0]} -> {fl[m.name][0]})",
               f"T_{{{m.index + 1}}}", m.T)
    steps.append(st)
    # 3 -------------------------------------------------------------- positions
    st = Step("3", "Position vectors",
              "Each written in the frame where it is shortest: the joint offset in the "
              "parent's frame, the centre of mass in the body's own frame.")
    for m in walk.motions:
        p = fl[m.parent]
        if _nonzero(m.rho_p):
            st.add(f"{p[0]} r_O{p[0][1:] or ''}O{m.index + 1}",
                   f"{{}}^{{{p[1]}}}r_{{O_{{{p[0][1:] or 'I'}}} O_{{{m.index + 1}}}}}", m.rho_p)
        if m.has_inertia and _nonzero(m.com):
            st.add(f"{fl[m.name][0]} r_O{m.index + 1}G{m.index + 1}",
                   f"{{}}^{{{fl[m.name][1]}}}r_{{O_{{{m.index + 1}}} G_{{{m.index + 1}}}}}", m.com)
    steps.append(st)
    # 4-5 ------------------------------------------------------------ angular velocity
    st = Step("4-5", "Angular velocities and accelerations",
              "Absolute angular velocity and acceleration of each frame (and body), in "
              + ("its own frame: w_i = T_i w_p + w_rel, alpha_i = T_i alpha_p + (T_i w_p) x "
                 "w_rel + d/dt w_rel." if own else "inertial components."))
    for m in walk.motions:
        b = basis(m)
        k = m.index + 1
        st.add(f"{b[0]} omega_{k}", f"{{}}^{{{b[1]}}}\\omega_{{{k}}}", m.omega)
        st.add(f"{b[0]} alpha_{k}", f"{{}}^{{{b[1]}}}\\alpha_{{{k}}}", m.alpha)
    steps.append(st)
    # 6 -------------------------------------------------------------- velocities
    st = Step("6", "Velocities and accelerations",
              "Of each frame's origin O_i and of each centre of mass G_i: v_G = v_O + w x r, "
              "a_G = a_O + alpha x r + w x (w x r) (+ 2 w x v_rel + a_rel across a sliding "
              "joint).")
    for m in walk.motions:
        b = basis(m)
        k = m.index + 1
        if _nonzero(m.v) or _nonzero(m.a):
            st.add(f"{b[0]} v_O{k}", f"{{}}^{{{b[1]}}}v_{{O_{{{k}}}}}", m.v)
            st.add(f"{b[0]} a_O{k}", f"{{}}^{{{b[1]}}}a_{{O_{{{k}}}}}", m.a)
        if m.has_inertia and _nonzero(m.com):
            st.add(f"{b[0]} v_G{k}", f"{{}}^{{{b[1]}}}v_{{G_{{{k}}}}}", m.v_G)
            st.add(f"{b[0]} a_G{k}", f"{{}}^{{{b[1]}}}a_{{G_{{{k}}}}}", m.a_G)
    steps.append(st)
    # 7 -------------------------------------------------------------- mass
    st = Step("7", "Mass and inertia", "Mass and inertia tensor about the centre of mass, "
              "in the body's own axes (constant there).")
    for m in walk.motions:
        if m.has_inertia:
            k = m.index + 1
            st.add(f"m_{k} ({m.name})", f"m_{{{k}}}", m.mass)
            if _nonzero(m.inertia):
                st.add(f"{fl[m.name][0]} I_G{k}", f"{{}}^{{{fl[m.name][1]}}}I_{{G_{{{k}}}}}",
                       m.inertia)
    steps.append(st)
    # 8-9 ------------------------------------------------------------ momenta
    st = Step("8-9", "Linear and angular momentum", "p = m v_G and H_G = I_G w.")
    for m in walk.motions:
        if m.has_inertia:
            b = basis(m)
            k = m.index + 1
            st.add(f"{b[0]} p_{k}", f"{{}}^{{{b[1]}}}p_{{{k}}}", walk.s(m.mass * m.v_G))
            if _nonzero(m.inertia):
                st.add(f"{b[0]} H_G{k}", f"{{}}^{{{b[1]}}}H_{{G_{{{k}}}}}",
                       walk.s(m.inertia_basis * m.omega))
    steps.append(st)
    # 10 ------------------------------------------------------------- applied loads
    st = Step("10", "Applied forces and moments",
              "Weight and loads (free-body diagram), reduced to the centre of mass.")
    for m in walk.motions:
        if not m.has_inertia and not m.loads:
            continue
        b = basis(m)
        k = m.index + 1
        if m.mass != 0:
            st.add(f"{b[0]} m_{k} g", f"{{}}^{{{b[1]}}}m_{{{k}}}g", walk.s(m.mass * m.gravity))
        for name, F, N, point in m.loads:
            if _nonzero(F):
                st.add(f"{b[0]} F ({name}, at {list(point)})",
                       f"{{}}^{{{b[1]}}}F_{{\\text{{{name}}}}}", F)
            if _nonzero(N):
                st.add(f"{b[0]} M ({name})", f"{{}}^{{{b[1]}}}M_{{\\text{{{name}}}}}", N)
        if _nonzero(m.force):
            st.add(f"{b[0]} F_{k} (total at G{k})", f"{{}}^{{{b[1]}}}F_{{{k}}}", m.force)
        if _nonzero(m.moment):
            st.add(f"{b[0]} M_G{k} (total about G{k})", f"{{}}^{{{b[1]}}}M_{{G_{{{k}}}}}", m.moment)
    steps.append(st)
    # method ------------------------------------------------------------------------------
    if d.method == "newton-euler":
        steps.extend(_newton_euler_steps(d, fl, basis))
    elif d.method == "jourdain":
        steps.extend(_jourdain_steps(d, fl, basis))
    else:
        steps.extend(_lagrange_steps(d, fl, basis))
    # equations ---------------------------------------------------------------------------
    st = Step("13" if d.method != "newton-euler" else "12",
              "Equations of motion M(q) u' = f(q, u, t)",
              f"By {d.method}; speeds u = ({', '.join(d.speeds)}), rates u' = "
              f"({', '.join(s.name for s in d.rates)}).")
    st.add("M", "M", d.mass_matrix)
    st.add("f", "f", d.forcing)
    nontrivial = {q: r for q, r in walk.qdot.items()
                  if not (isinstance(r, sympy.Symbol) and r.name.startswith(q.name))}
    if nontrivial:
        for q, r in nontrivial.items():
            st.add(f"{q.name}'", f"\\dot{{{sympy.latex(q)}}}", r, "kinematic equation")
    steps.append(st)
    if d.accelerations is not None:
        st = Step("14", "Solution", "The equations solved for the accelerations"
                  + (" and every reaction component (force then moment, parent on child at "
                     "the child frame's origin, " + ("own-frame" if own else "inertial")
                     + " components)." if d.reactions else "."))
        for s, e in d.accelerations.items():
            r = walk.sym.ud[walk.model.speed_index(s)]
            st.add(r.name, _latex_name(r.name), e)
        for joint, comps in (d.reactions or {}).items():
            m = walk.by_name[walk.model.joint(joint).child]
            b = basis(m)
            st.add(f"{b[0]} R ({joint}, force)", f"{{}}^{{{b[1]}}}R_{{\\text{{{joint}}}}}",
                   sympy.Matrix(comps[:3]))
            if any(c != 0 for c in comps[3:]):
                st.add(f"{b[0]} M ({joint}, moment)", f"{{}}^{{{b[1]}}}M_{{\\text{{{joint}}}}}",
                       sympy.Matrix(comps[3:]))
        steps.append(st)
    return steps


def _latex_name(name):
    for suffix, acc in (("_ddot", r"\ddot"), ("_dot", r"\dot")):
        if name.endswith(suffix) and len(name) > len(suffix):
            return acc + "{" + sympy.latex(sympy.Symbol(name[:-len(suffix)])) + "}"
    return sympy.latex(sympy.Symbol(name))


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
