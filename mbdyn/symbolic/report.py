"""Render a ``Derivation``: plain text, LaTeX (a complete document), Markdown, JSON.

JSON (``mbdyn eom --format json``) is one object::

    {"method": str, "coordinates": [str], "speeds": [str], "mass_matrix": [[str]],
     "forcing": [str], "accelerations": {speed: str} | null,
     "reactions": {joint: [Fx, Fy, Fz, Mx, My, Mz]} | null,
     "constraints": {"rows": [str], "joints": [str], "multipliers": [str], "phi": [str],
                     "jacobian": [[str]], "G": [[str]], "phi_t": [str], "gamma": [str],
                     "constraint_forces": [str], "equations": str} | null,
     "stats": {"derive_s": float, "operations": int, "operations_after_cse": int}}

(``constraints``: a closed mechanism's loops, ``mbdyn.symbolic.loop_report``;
and, only for a model with flexible bodies, ``"flexible"``: ``{body: {"modal_coordinates",
"equations", "first_moment", "inertia", "coupling", "matrices", "values": {name:
value}}}``, their invariants as named symbols, ``mbdyn.symbolic.flexible_report``.)

(plus ``"steps"`` when asked for).  Every expression string is ``str()`` of a sympy
expression: ``sympy.sympify(s, locals={name: Symbol(name) for name in names})`` reads it back,
with ``names`` the model's parameters, coordinates, speeds, speed rates and ``t``.
"""
from __future__ import annotations

import sympy

from . import flexible_report, loop_report
from .steps import Step


# ---------------------------------------------------------------------------- helpers
def _str(value):
    if isinstance(value, str):
        return value
    return sympy.sstr(value)


def _text_value(value, indent="    "):
    if isinstance(value, str):
        return value
    if isinstance(value, tuple) and len(value) == 2:
        lhs, rhs = value
        if isinstance(lhs, sympy.MatrixBase):
            rows = [f"{indent}{_str(a)} = {_str(b)}" for a, b in zip(lhs, rhs)]
            return "\n" + "\n".join(rows)
        return f"{_str(lhs)} = {_str(rhs)}"
    if isinstance(value, sympy.MatrixBase):
        if value.cols == 1:
            return "[" + ", ".join(_str(e) for e in value) + "]"
        rows = ["[" + ", ".join(_str(e) for e in value.row(r)) + "]" for r in range(value.rows)]
        return "\n" + "\n".join(indent + r for r in rows)
    return _str(value)


def latex_names(d):
    """``{Symbol: LaTeX}``: speeds ``x_dot`` as ``\\dot{x}``, rates as ``\\ddot{x}``."""
    from .steps import LATEX_NAMES
    names = dict(LATEX_NAMES)
    for s in d.walk.sym.table.values():
        n = s.name
        for suffix, acc in (("_ddot", r"\ddot"), ("_dot", r"\dot")):
            if n.endswith(suffix) and len(n) > len(suffix):
                names[s] = acc + "{" + sympy.latex(sympy.Symbol(n[:-len(suffix)])) + "}"
                break
    names.update(flexible_report.latex_names(d))
    return names


def _latex(value, names):
    if isinstance(value, str):
        return r"\text{" + value.replace("_", r"\_").replace("'", "") + "}"
    if isinstance(value, tuple) and len(value) == 2:
        return _latex(value[0], names) + " = " + _latex(value[1], names)
    return sympy.latex(value, symbol_names=names, mat_delim="[")


def _header(d):
    where = "each body's own frame" if d.frames == "own" else "the inertial frame"
    return f"Equations of motion of {d.model.name!r} by {d.method} (vectors in {where})"


# ---------------------------------------------------------------------------- text
def as_text(d, steps=False):
    out = [_header(d), "=" * len(_header(d)), ""]
    out.append("coordinates q: " + ", ".join(d.coordinates))
    out.append("speeds u:      " + ", ".join(d.speeds))
    out.append("rates u':      " + ", ".join(s.name for s in d.rates))
    out.append("")
    if steps:
        for st in d.steps():
            title = f"({st.number}) {st.title}"
            out.append(title)
            out.append("-" * len(title))
            if st.text:
                out.append(st.text)
            for e in st.entries:
                note = f"   [{e.note}]" if e.note else ""
                out.append(f"  {e.label} = {_text_value(e.value)}{note}")
            out.append("")
    else:
        out.append(loop_report.equations_title(d))
        out.append("")
        for r in range(d.mass_matrix.rows):
            for c in range(d.mass_matrix.cols):
                if c >= r:
                    out.append(f"  M[{d.speeds[r]}, {d.speeds[c]}] = {_str(d.mass_matrix[r, c])}")
        out.append("")
        for r, s in enumerate(d.speeds):
            out.append(f"  f[{s}] = {_str(d.forcing[r])}")
        out.append("")
        out.extend(loop_report.text_lines(d, _str))
        out.extend(flexible_report.text_lines(d, _str))
        if d.accelerations is not None:
            if d.constraints is not None:
                out.append("Accelerations in terms of the multipliers (u' = M^-1 (f + G^T "
                           "lambda))")
            for s, e in d.accelerations.items():
                rate = d.walk.sym.ud[d.model.speed_index(s)]
                out.append(f"  {rate.name} = {_str(e)}")
            out.append("")
        if d.reactions:
            out.append("Reactions (force, moment; parent on child at the child frame's origin, "
                       + ("child-frame" if d.frames == "own" else "inertial") + " components)")
            for j, comps in d.reactions.items():
                for lab, e in zip(("Fx", "Fy", "Fz", "Mx", "My", "Mz"), comps):
                    if e != 0:
                        out.append(f"  {j}.{lab} = {_str(e)}")
            out.append("")
    st = d.stats
    out.append(f"derived in {st.get('derive_s', 0):.3f} s; M and f: {st.get('operations', '?')} "
               f"operations, {st.get('operations_after_cse', '?')} after cse")
    return "\n".join(out) + "\n"


# ---------------------------------------------------------------------------- latex
def _latex_body(d, steps, heading, math_open, math_close, para):
    built = d.steps() if steps else []      # first: the steps introduce symbols
    names = latex_names(d)
    out = []
    if steps:
        for st in built:
            out.append(heading(f"({st.number}) {st.title}"))
            if st.text:
                out.append(para(st.text))
            for e in st.entries:
                if isinstance(e.value, str):
                    out.append(para(f"{e.label}: {e.value}"))
                else:
                    note = r"\quad\text{(" + e.note + ")}" if e.note else ""
                    out.append(math_open + e.latex + " = " + _latex(e.value, names) + note
                               + math_close)
    else:
        out.append(heading("Equations of motion"))
        out.append(math_open + "M = " + _latex(d.mass_matrix, names) + math_close)
        out.append(math_open + "f = " + _latex(d.forcing, names) + math_close)
        out.extend(loop_report.latex_parts(d, names, _latex, heading, math_open, math_close,
                                           para))
        out.extend(flexible_report.latex_parts(d, names, _latex, heading, math_open,
                                               math_close, para))
        if d.accelerations is not None:
            out.append(heading("Accelerations"))
            for s, e in d.accelerations.items():
                sym = d.walk.sym.table[s]
                out.append(math_open + r"\dot{" + _latex(sym, names) + "} = " + _latex(e, names)
                           + math_close)
        if d.reactions:
            out.append(heading("Reactions"))
            for j, comps in d.reactions.items():
                jt = j.replace("_", r"\_")
                out.append(math_open + r"R_{\text{" + jt + "}} = "
                           + _latex(sympy.Matrix(comps[:3]), names) + r",\quad M_{\text{"
                           + jt + "}} = " + _latex(sympy.Matrix(comps[3:]), names)
                           + math_close)
    st = d.stats
    out.append(para(f"Derived in {st.get('derive_s', 0):.3f} s; M and f have "
                    f"{st.get('operations', '?')} operations, "
                    f"{st.get('operations_after_cse', '?')} after common subexpression "
                    "elimination."))
    return out


def _tex_escape(s):
    for a, b in (("\\", r"\textbackslash{}"), ("_", r"\_"), ("&", r"\&"), ("%", r"\%"),
                 ("#", r"\#"), ("{", r"\{"), ("}", r"\}"), ("^", r"\^{}"), ("~", r"\~{}"),
                 ("$", r"\$")):
        s = s.replace(a, b)
    return s


def as_latex(d, steps=False):
    body = _latex_body(d, steps,
                       heading=lambda t: r"\section*{" + _tex_escape(t) + "}",
                       math_open="\\[\n", math_close="\n\\]",
                       para=lambda t: _tex_escape(t) + "\n")
    head = [r"\documentclass[a4paper,10pt]{article}",
            r"\usepackage[margin=2cm]{geometry}",
            r"\usepackage{amsmath}",
            r"\allowdisplaybreaks",
            r"\begin{document}",
            r"\section*{" + _tex_escape(_header(d)) + "}",
            _tex_escape("Coordinates: " + ", ".join(d.coordinates) + "; speeds: "
                        + ", ".join(d.speeds) + ".") + "\n"]
    return "\n".join(head + body + [r"\end{document}"]) + "\n"


def as_markdown(d, steps=False):
    body = _latex_body(d, steps, heading=lambda t: "\n## " + t + "\n",
                       math_open="$$", math_close="$$",
                       para=lambda t: t + "\n")
    head = ["# " + _header(d), "",
            "Coordinates: " + ", ".join(f"`{c}`" for c in d.coordinates) + "; speeds: "
            + ", ".join(f"`{s}`" for s in d.speeds) + ".", ""]
    return "\n".join(head + body) + "\n"


# ---------------------------------------------------------------------------- json
def as_dict(d, steps=False):
    M, f = d.mass_matrix, d.forcing
    out = {
        "method": d.method,
        "coordinates": list(d.coordinates),
        "speeds": list(d.speeds),
        "mass_matrix": [[_str(M[r, c]) for c in range(M.cols)] for r in range(M.rows)],
        "forcing": [_str(e) for e in f],
        "accelerations": (None if d.accelerations is None
                          else {s: _str(e) for s, e in d.accelerations.items()}),
        "reactions": (None if d.reactions is None
                      else {j: [_str(e) for e in comps] for j, comps in d.reactions.items()}),
        "constraints": loop_report.as_dict(d, _str),
        "stats": {"derive_s": float(d.stats.get("derive_s", 0.0)),
                  "operations": int(d.stats.get("operations", -1)),
                  "operations_after_cse": int(d.stats.get("operations_after_cse", -1))},
    }
    if d.walk.flexible:                 # a model with flexible bodies: their invariants
        out["flexible"] = flexible_report.as_dict(d, _str)
    if steps:
        out["steps"] = [_step_dict(st) for st in d.steps()]
    return out


def _json_value(value):
    if isinstance(value, str):
        return value
    if isinstance(value, tuple) and len(value) == 2:
        return {"lhs": _json_value(value[0]), "rhs": _json_value(value[1])}
    if isinstance(value, sympy.MatrixBase):
        return [[_str(value[r, c]) for c in range(value.cols)] for r in range(value.rows)]
    return _str(value)


def _kind(value):
    if isinstance(value, str):
        return "text"
    if isinstance(value, tuple):
        return "equation"
    if isinstance(value, sympy.MatrixBase):
        return "matrix"
    return "expression"


def _step_dict(st: Step):
    """A step as JSON: entries of kind ``text`` (a sentence), ``expression`` (a string),
    ``matrix`` (rows of strings) or ``equation`` (``{"lhs", "rhs"}``)."""
    return {"number": st.number, "title": st.title, "text": st.text,
            "entries": [{"label": e.label, "kind": _kind(e.value),
                         "value": _json_value(e.value), "note": e.note}
                        for e in st.entries]}
