"""The derivation trace: the textbook's steps 1-13 for one model, as data.

``build_steps(derivation)`` returns a list of ``Step``: each has the textbook's step number,
a title, a sentence of explanation and ``Entry`` items -- a label (plain text and LaTeX) and
a value (a sympy expression or matrix, an equation ``(lhs, rhs)``, or text).  The formats
in ``mbdyn.symbolic.report`` render it.
"""
from __future__ import annotations

import sympy

from .flexible_report import flexible_step
from .loop_steps import constraint_entries, multiplier_step
from .method_steps import _jourdain_steps, _lagrange_steps, _newton_euler_steps
from .method_steps import newton_euler_equations, reaction_symbols  # noqa: F401 (their home)
from .step_record import LATEX_NAMES, Entry, Step  # noqa: F401 (report.py reads them here)
from .step_record import _latex_name, _nonzero


def _frame_labels(walk):
    """``{frame name: (text label, latex label)}`` of the bases: B1..Bn, or I."""
    out = {"ground": ("I", "I")}
    for m in walk.motions:
        out[m.name] = (f"B{m.index + 1}", f"B_{{{m.index + 1}}}")
    return out


class _Labels:
    """What every step's function reads: the walk, the frames' labels, and the basis each
    frame's vectors are written in."""

    def __init__(self, d):
        self.walk = d.walk
        self.sym = d.walk.sym
        self.fl = _frame_labels(d.walk)
        self.own = d.walk.frames == "own"

    def basis(self, m):
        return self.fl[m.name] if self.own else ("I", "I")


def build_steps(d):
    """The textbook's steps of the derivation ``d``: steps 1-10 (frames to applied loads),
    the method's own steps, the equations of motion and, when solved, the solution."""
    c = _Labels(d)
    steps = [step(c) for step in KINEMATIC_STEPS]
    constraint_entries(steps[2], d)         # step 3: a closed mechanism's constraints
    flexible = flexible_step(d)             # a floating frame's terms, its invariants
    if flexible is not None:
        steps.append(flexible)
    if d.method == "newton-euler":
        steps.extend(_newton_euler_steps(d, c.fl, c.basis))
    elif d.method == "jourdain":
        steps.extend(_jourdain_steps(d, c.fl, c.basis))
    else:
        steps.extend(_lagrange_steps(d, c.fl, c.basis))
    if d.constraints is not None:
        steps.append(multiplier_step(d))
    steps.append(_equations_step(d, c))
    if d.accelerations is not None:
        steps.append(_solution_step(d, c))
    return steps


def _frames_step(c):
    """Step 1: the inertial frame and a frame on each body, each hung from its joint."""
    walk, fl = c.walk, c.fl
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
    return st


def _transformations_step(c):
    """Step 2: the transformation matrices from each parent frame."""
    walk, fl = c.walk, c.fl
    st = Step("2", "Transformation matrices",
              "B s = T . P s maps a vector's components in the parent frame P to the moving "
              "frame B; P s = T^T . B s.")
    for m in walk.motions:
        p = fl[m.parent]
        st.add(f"T_{m.index + 1} ({p[0]} -> {fl[m.name][0]})",
               f"T_{{{m.index + 1}}}", m.T)
    return st


def _positions_step(c):
    """Step 3: the position vectors of the joints and the centres of mass."""
    walk, fl = c.walk, c.fl
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
    return st


def _rotations_step(c):
    """Steps 4-5: the angular velocities and accelerations."""
    walk, own, basis = c.walk, c.own, c.basis
    st = Step("4-5", "Angular velocities and accelerations",
              "Absolute angular velocity and acceleration of each frame (and body), in "
              + ("its own frame: w_i = T_i w_p + w_rel, alpha_i = T_i alpha_p + (T_i w_p) x "
                 "w_rel + d/dt w_rel." if own else "inertial components."))
    for m in walk.motions:
        b = basis(m)
        k = m.index + 1
        st.add(f"{b[0]} omega_{k}", f"{{}}^{{{b[1]}}}\\omega_{{{k}}}", m.omega)
        st.add(f"{b[0]} alpha_{k}", f"{{}}^{{{b[1]}}}\\alpha_{{{k}}}", m.alpha)
    return st


def _velocities_step(c):
    """Step 6: the velocities and accelerations of the origins and centres of mass."""
    walk, basis = c.walk, c.basis
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
    return st


def _inertia_step(c):
    """Step 7: mass and inertia about the centre of mass."""
    walk, fl = c.walk, c.fl
    st = Step("7", "Mass and inertia", "Mass and inertia tensor about the centre of mass, "
              "in the body's own axes (constant there).")
    for m in walk.motions:
        if m.has_inertia:
            k = m.index + 1
            st.add(f"m_{k} ({m.name})", f"m_{{{k}}}", m.mass)
            if _nonzero(m.inertia):
                st.add(f"{fl[m.name][0]} I_G{k}", f"{{}}^{{{fl[m.name][1]}}}I_{{G_{{{k}}}}}",
                       m.inertia)
    return st


def _momentum_step(c):
    """Steps 8-9: linear and angular momentum."""
    walk, basis = c.walk, c.basis
    st = Step("8-9", "Linear and angular momentum", "p = m v_G and H_G = I_G w.")
    for m in walk.motions:
        if m.has_inertia:
            b = basis(m)
            k = m.index + 1
            st.add(f"{b[0]} p_{k}", f"{{}}^{{{b[1]}}}p_{{{k}}}", walk.s(m.mass * m.v_G))
            if _nonzero(m.inertia):
                st.add(f"{b[0]} H_G{k}", f"{{}}^{{{b[1]}}}H_{{G_{{{k}}}}}",
                       walk.s(m.inertia_basis * m.omega))
    return st


def _loads_step(c):
    """Step 10: the applied forces and moments, reduced to the centres of mass."""
    walk, basis = c.walk, c.basis
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
    return st


#: steps 1-10, the same for every method
KINEMATIC_STEPS = (_frames_step, _transformations_step, _positions_step, _rotations_step,
                   _velocities_step, _inertia_step, _momentum_step, _loads_step)


def _equations_step(d, c):
    """The equations of motion ``M(q) u' = f`` and the kinematic equations."""
    walk = c.walk
    loops = d.constraints is not None
    st = Step("13" if d.method != "newton-euler" else "12",
              "Equations of motion M(q) u' = f(q, u, t)" + (" + G^T lambda, G u' = gamma"
                                                             if loops else ""),
              f"By {d.method}; speeds u = ({', '.join(d.speeds)}), rates u' = "
              f"({', '.join(s.name for s in d.rates)}).")
    st.add("M", "M", d.mass_matrix)
    st.add("f", "f", d.forcing)
    if loops:
        _multiplier_rows(st, d)
    nontrivial = {q: r for q, r in walk.qdot.items()
                  if not (isinstance(r, sympy.Symbol) and r.name.startswith(q.name))}
    if nontrivial:
        for q, r in nontrivial.items():
            st.add(f"{q.name}'", f"\\dot{{{sympy.latex(q)}}}", r, "kinematic equation")
    return st


def _solution_step(d, c):
    """The equations solved for the accelerations (and the reactions)."""
    walk, own, basis = c.walk, c.own, c.basis
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
        if any(x != 0 for x in comps[3:]):
            st.add(f"{b[0]} M ({joint}, moment)", f"{{}}^{{{b[1]}}}M_{{\\text{{{joint}}}}}",
                   sympy.Matrix(comps[3:]))
    return st


def _multiplier_rows(st, d):
    """The equations with the multipliers, in two blocks: one row a speed, then the
    acceleration constraints (rows identically ``0 = 0`` named, not written)."""
    eqs = d.constrained_equations()
    n, rows = len(d.speeds), d.constraints.rows
    if d.method == "lagrange":
        st.add("d/dt dL/dq' - dL/dq = Q + Phi_q^T lambda",
               r"\frac{d}{dt}\frac{\partial L}{\partial \dot q} - \frac{\partial L}"
               r"{\partial q} = Q + \Phi_q^T \lambda", _block(eqs[:n]))
    else:
        st.add("M u' = f + G^T lambda", r"M \dot u = f + G^T \lambda", _block(eqs[:n]))
    kept = [e for e in eqs[n:] if not (e.lhs == 0 and e.rhs == 0)]
    zero = [rows[k] for k, e in enumerate(eqs[n:]) if e.lhs == 0 and e.rhs == 0]
    if kept:
        st.add("G u' = gamma", r"G \dot u = \gamma", _block(kept))
    if zero:
        st.add("G u' = gamma", r"G \dot u = \gamma", "0 = 0 in rows " + ", ".join(zero)
               + " (identically satisfied here)")


def _block(eqs):
    return (sympy.Matrix([e.lhs for e in eqs]), sympy.Matrix([e.rhs for e in eqs]))
