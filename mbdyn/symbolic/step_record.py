"""The records of the derivation trace: a ``Step`` (the textbook's number, a title, a
sentence) holds ``Entry`` items (a label in text and LaTeX, and a value); the LaTeX names
of the symbols the steps introduce.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import sympy


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


def _latex_name(name):
    for suffix, acc in (("_ddot", r"\ddot"), ("_dot", r"\dot")):
        if name.endswith(suffix) and len(name) > len(suffix):
            return acc + "{" + sympy.latex(sympy.Symbol(name[:-len(suffix)])) + "}"
    return sympy.latex(sympy.Symbol(name))
