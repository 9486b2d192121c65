"""A closed mechanism's part of ``mbdyn eom``'s output (``report``): the constraint
equations ``phi(q, t) = 0``, their Jacobian ``Phi_q`` (and ``G = Phi_q N`` where the speeds
are not the coordinates' rates), the drives' part ``phi_t``, ``gamma`` and the equations with
the multipliers -- in text, LaTeX/Markdown and JSON.
"""
from __future__ import annotations

import sympy


def equations_title(d):
    """The equations' one-line form."""
    if d.constraints is None:
        return "M(q) u' = f(q, u, t)"
    if d.method == "lagrange":
        return ("M(q) u' = f(q, u, t) + G^T lambda,  G u' = gamma  (Lagrange: d/dt dL/dq' - "
                "dL/dq = Q + Phi_q^T lambda, u = q', G = Phi_q)")
    return "M(q) u' = f(q, u, t) + G^T lambda,  G u' = gamma"


def _nonzero_entries(M, rows, cols):
    return [(rows[r], cols[c], M[r, c]) for r in range(M.rows) for c in range(M.cols)
            if M[r, c] != 0]


def text_lines(d, show):
    """The text section (``show``: the report's expression printer)."""
    c = d.constraints
    if c is None:
        return []
    out = [f"Loop joints: {', '.join(dict.fromkeys(c.joints))}; multipliers lambda: "
           + ", ".join(s.name for s in c.multipliers), "",
           "Constraint equations phi(q, t) = 0", ""]
    out += [f"  phi[{r}] = {show(e)}" for r, e in zip(c.rows, c.phi)]
    out += ["", "Jacobian Phi_q = d phi / d q (nonzero entries)", ""]
    out += [f"  Phi_q[{r}, {q}] = {show(e)}"
            for r, q, e in _nonzero_entries(c.jacobian, c.rows, d.coordinates)]
    if c.speed_form:
        out += ["", "Speed form G = Phi_q N(q): d phi/dt = G u + phi_t (nonzero entries)", ""]
        out += [f"  G[{r}, {u}] = {show(e)}"
                for r, u, e in _nonzero_entries(c.G, c.rows, d.speeds)]
    if any(e != 0 for e in c.phi_t):
        out += ["", "The drives' part phi_t = d phi / dt at fixed q", ""]
        out += [f"  phi_t[{r}] = {show(e)}" for r, e in zip(c.rows, c.phi_t) if e != 0]
    out += ["", "Accelerations: G u' = gamma", ""]
    out += [f"  gamma[{r}] = {show(e)}" for r, e in zip(c.rows, c.gamma)]
    out += ["", "Multipliers' generalized forces G^T lambda"
            + (" (= Phi_q^T lambda in Lagrange's equations)" if d.method == "lagrange" else ""),
            ""]
    out += [f"  (G^T lambda)[{s}] = {show(e)}"
            for s, e in zip(d.speeds, c.constraint_forces())]
    out.append("")
    return out


def latex_parts(d, names, latex, heading, math_open, math_close, para):
    """The LaTeX/Markdown section (``latex``: the report's expression printer)."""
    c = d.constraints
    if c is None:
        return []
    out = [heading("Constraint equations"),
           para("Loop joints: " + ", ".join(dict.fromkeys(c.joints)) + "; rows "
                + ", ".join(c.rows) + "."),
           math_open + r"\phi(q, t) = " + latex(c.phi, names) + " = 0" + math_close,
           math_open + r"\Phi_q = \frac{\partial \phi}{\partial q} = " + latex(c.jacobian, names)
           + math_close]
    if c.speed_form:
        out.append(math_open + r"G = \Phi_q N(q) = " + latex(c.G, names) + math_close)
    if any(e != 0 for e in c.phi_t):
        out.append(math_open + r"\phi_t = " + latex(c.phi_t, names) + math_close)
    out.append(math_open + r"G \dot u = \gamma, \quad \gamma = " + latex(c.gamma, names)
               + math_close)
    out.append(heading("Equations with multipliers"))
    lam = latex(sympy.Matrix(c.multipliers), names)
    if d.method == "lagrange":
        out.append(math_open + r"\frac{d}{dt}\frac{\partial L}{\partial \dot q} - "
                   r"\frac{\partial L}{\partial q} = Q + \Phi_q^T \lambda, \quad "
                   r"M \ddot q = f + \Phi_q^T \lambda, \quad \lambda = " + lam + math_close)
    else:
        out.append(math_open + r"M \dot u = f + G^T \lambda, \quad \lambda = " + lam
                   + math_close)
    out.append(math_open + r"G^T \lambda = " + latex(c.constraint_forces(), names)
               + math_close)
    return out


def as_dict(d, show):
    """The JSON object (``show``: the report's expression printer), or None for a tree."""
    c = d.constraints
    if c is None:
        return None

    def matrix(M):
        return [[show(M[r, k]) for k in range(M.cols)] for r in range(M.rows)]
    return {"rows": list(c.rows), "joints": list(c.joints),
            "multipliers": [s.name for s in c.multipliers],
            "phi": [show(e) for e in c.phi], "jacobian": matrix(c.jacobian),
            "G": matrix(c.G), "phi_t": [show(e) for e in c.phi_t],
            "gamma": [show(e) for e in c.gamma],
            "constraint_forces": [show(e) for e in c.constraint_forces()],
            "equations": equations_title(d)}
