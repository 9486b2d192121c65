"""A model's flexible bodies in ``mbdyn eom``'s output (``report``) and in its steps: the
floating frame's terms in closed form -- the body's speeds ``w``, its first moment
``S(eta)``, inertia ``J(eta)`` and coupling ``Cr(eta)`` -- and the value of every named
invariant (``symbolic.flexible``), in text, LaTeX/Markdown and JSON.
"""
from __future__ import annotations

import sympy

from .step_record import Step

#: the matrices listed, their meaning (the labels of ``flexible._Names.matrices``)
MEANING = {"m": "mass", "S0": "first moment at eta = 0", "S1": "modal first moment (C_t)",
           "J0": "inertia about the frame origin at eta = 0",
           "J1": "inertia, linear in eta_k", "J2": "inertia, coefficient of eta_k eta_l",
           "Cr0": "rotation-elastic coupling at eta = 0 (C_r)",
           "Cr1": "coupling, linear in eta_k", "Mee": "modal mass", "Kee": "modal stiffness",
           "Dee": "modal damping", "Kc": "geometric stiffness per omega_y^2 + omega_z^2",
           "Ka": "geometric stiffness per a_x - g_x", "Omega": "spin",
           "Gee": "gyroscopic matrix per unit spin"}

EQUATIONS = ("w = (v, omega, eta') (frame origin's velocity, angular velocity: body "
             "components; modal rates);  M_b(eta) = [[m I, -S~, S1], [S~, J, Cr], [S1^T, "
             "Cr^T, Mee]];  Q = Q_v + (m g, S x g, S1^T g) - (0, 0, Kee eta + Dee eta'"
             "{extra})")


def _extra(body):
    out = ""
    if body.Omega is not None:
        out += " + Omega Gee eta'"
    if body.stiffening:
        out += " + ((omega_y^2 + omega_z^2) Kc + (a_x - g_x) Ka) eta"
    return out


def _kind(label):
    return label.split("_")[0]


#: LaTeX of each kind of invariant: its letter and the first part of its subscript
LATEX = {"m": ("m", ""), "S0": ("S", "0"), "S1": ("S", "1"), "J0": ("J", "0"),
         "J1": ("J", "1"), "J2": ("J", "2"), "Cr0": ("C", "r0"), "Cr1": ("C", "r1"),
         "Mee": ("M", "ee"), "Kee": ("K", "ee"), "Dee": ("D", "ee"), "Kc": ("K", "c"),
         "Ka": ("K", "a"), "Gee": ("G", "ee"), "Omega": (r"\Omega", "")}


def latex_names(d):
    """``{Symbol: LaTeX}`` of the invariants: ``beam_J2_1_2_yz`` as ``J^{beam}_{2,1,2,yz}``."""
    out = {}
    for body in d.walk.flexible:
        top = r"\mathrm{" + body.name.replace("_", r"\_") + "}"
        for s in body.names.constants:
            kind, *rest = s.name[len(body.name) + 1:].split("_")
            if kind not in LATEX:             # a mode shape at a node: its own name
                continue
            letter, first = LATEX[kind]
            sub = ",".join(p for p in [first, *rest] if p)
            out[s] = f"{letter}^{{{top}}}" + (f"_{{{sub}}}" if sub else "")
    return out


def _values(body):
    """``[(label, meaning, [(name, value)])]`` of the body's named invariants."""
    out = []
    for label, M in body.names.matrices.items():
        named = [(e.name, body.names.constants[e]) for e in dict.fromkeys(
            e for e in M if e.is_Symbol)]
        out.append((label, body.names.meanings.get(label) or MEANING.get(_kind(label), ""),
                    named))
    if body.Omega is not None:
        out.append(("Omega", MEANING["Omega"], [(body.Omega.name,
                                                 body.names.constants[body.Omega])]))
    return out


def _closed_forms(body):
    return [("S(eta)", r"S(\eta)", body.S), ("J(eta)", r"J(\eta)", body.J),
            ("Cr(eta)", r"C_r(\eta)", body.Cr)]


def text_lines(d, show):
    """The text section (``show``: the report's expression printer)."""
    out = []
    for body in d.walk.flexible:
        out += [f"Flexible body {body.name!r}: floating frame, modal coordinates "
                + ", ".join(e.name for e in body.eta), "",
                "  " + EQUATIONS.format(extra=_extra(body)), ""]
        for label, _, value in _closed_forms(body):
            out.append(f"  {label} = {_show_matrix(value, show)}")
        out += ["", "  Invariants (named symbols; entries below 1e-11 of the largest of "
                "their matrix are 0)", ""]
        for label, meaning, named in _values(body):
            out.append(f"  {label}: {meaning}" if meaning else f"  {label}")
            out += [f"    {name} = {value:.17g}" for name, value in named]
        out.append("")
    return out


def _show_matrix(M, show):
    if M.cols == 1:
        return "[" + ", ".join(show(e) for e in M) + "]"
    return "[" + ", ".join("[" + ", ".join(show(e) for e in M.row(r)) + "]"
                           for r in range(M.rows)) + "]"


def latex_parts(d, names, latex, heading, math_open, math_close, para):
    """The LaTeX/Markdown section (``latex``: the report's expression printer)."""
    out = []
    for body in d.walk.flexible:
        out.append(heading(f"Flexible body {body.name}"))
        out.append(para("Floating frame; " + EQUATIONS.format(extra=_extra(body))))
        for _, tex, value in _closed_forms(body):
            out.append(math_open + tex + " = " + latex(value, names) + math_close)
        out.append(para("Invariants (named symbols; entries below 1e-11 of the largest of "
                        "their matrix are 0):"))
        for label, meaning, named in _values(body):
            out.append(para(f"{label} ({meaning}): " + ", ".join(
                f"{name} = {value:.17g}" for name, value in named)))
    return out


def as_dict(d, show):
    """The JSON object's ``"flexible"`` (a model with flexible bodies): per body its
    modal coordinates, ``S``, ``J``, ``Cr`` as expression strings and ``values``
    ``{name: value}`` of every named invariant."""
    out = {}
    for body in d.walk.flexible:
        def rows(M):
            return [[show(M[r, c]) for c in range(M.cols)] for r in range(M.rows)]
        out[body.name] = {
            "modal_coordinates": [e.name for e in body.eta],
            "equations": EQUATIONS.format(extra=_extra(body)),
            "first_moment": [show(e) for e in body.S], "inertia": rows(body.J),
            "coupling": rows(body.Cr),
            "matrices": {label: rows(M) for label, M in body.names.matrices.items()},
            "values": {s.name: v for s, v in body.names.constants.items()}}
    return out


def flexible_step(d):
    """The derivation's step for the flexible bodies (``None`` without them)."""
    if not d.walk.flexible:
        return None
    st = Step("F", "Flexible bodies (floating frame of reference)",
              "Each flexible body's frame moves with the tree (a massless frame there); "
              "its modal coordinates eta add to its kinetic energy 1/2 w^T M_b(eta) w "
              "and its forces Q (inertia invariants as named symbols: values below).")
    for body in d.walk.flexible:
        b = body.name
        st.add(f"{b}: w", "w", body.w)
        st.add(f"{b}: B = dw/du", "B", body.B)
        for label, tex, value in _closed_forms(body):
            st.add(f"{b}: {label}", tex, value)
        st.add(f"{b}: M_b(eta)", r"M_b(\eta)", body.mass_matrix())
        st.add(f"{b}: Q", "Q", body.forces())
        for label, meaning, named in _values(body):
            for name, value in named:
                st.add(name, sympy.latex(sympy.Symbol(name)), sympy.Float(value, 17),
                       meaning)
    return st
