"""A beam from its description (a TOML table or a Python dict), every value checked and
every error naming its key.

    theory = "timoshenko"            # or "euler-bernoulli" (default "timoshenko")
    rotary_inertia = true            # default: true for Timoshenko, false for Euler-Bernoulli
    [[segments]]                     # from the root outwards, one or more
    length = 0.8                     # m
    elements = 8                     # equal elements in this segment (>= 1)
    circle = 0.05                    # or tube = [d_out, d_in], or rect = [b, h]
    E = 210e9                        # Pa
    rho = 7850                       # kg/m^3
    nu = 0.3                         # Poisson's ratio (default 0.3)
    [[masses]]                       # point masses and rigid disks on nodes
    at = "tip"                       # a node's name, or a position along x
    mass = 2.0                       # kg
    polar = 0.01                     # kg m^2 about x
    diametral = 0.005                # kg m^2 about y and z
    [nodes]                          # named nodes: position along x
    mid = 0.4

A single segment may be written in the beam's table itself (without ``segments``).  A
named position picks the nearest node (halfway between two, the one nearer the root);
the nodes ``root`` (x = 0) and ``tip`` (x = L) are named unless the table names them.
To put a node exactly at a position, end a segment there.
"""
from __future__ import annotations

import difflib
import math
import numbers
import warnings

import numpy as np

from ..errors import ModelError, ModelWarning
from ..limits import MAX_BEAM_ELEMENTS
from ..names import identifier_problem
from .beam import Attachment, Beam, nearest_node
from .sections import KINDS, make_section

THEORIES = ("timoshenko", "euler-bernoulli")
SEGMENT_KEYS = ("length", "elements", "circle", "tube", "rect", "section", "E", "rho", "nu")
BEAM_KEYS = ("theory", "rotary_inertia", "segments", "masses", "nodes")
MASS_KEYS = ("at", "mass", "polar", "diametral")


def _unknown(table, known, key):
    for name in table:
        if name not in known:
            near = difflib.get_close_matches(str(name), known, n=1)
            hint = f" (did you mean {near[0]!r}?)" if near else ""
            raise ModelError(f"{key}.{name}: unknown key{hint}; known: {', '.join(known)}")


def _number(table, name, key, *, default=None, low=None, strict=True):
    """``table[name]`` as a finite float, above ``low`` (strictly if ``strict``)."""
    if name not in table:
        if default is None:
            raise ModelError(f"{key}.{name}: missing; give a number")
        return default
    value = table[name]
    if isinstance(value, bool) or not isinstance(value, numbers.Real) \
            or not math.isfinite(value):
        raise ModelError(f"{key}.{name}: must be a finite number, got {value!r}")
    if low is not None and (value <= low if strict else value < low):
        raise ModelError(f"{key}.{name}: must be {'>' if strict else '>='} {low:g}, "
                         f"got {value!r}")
    return float(value)


def _segment(table, key):
    if not isinstance(table, dict):
        raise ModelError(f"{key}: must be a table of length, elements, a section, E, rho, nu")
    _unknown(table, SEGMENT_KEYS, key)
    table = _with_section(table, key)
    length = _number(table, "length", key, low=0.0)
    elements = table.get("elements", 1)
    if isinstance(elements, bool) or not isinstance(elements, numbers.Integral) or elements < 1:
        raise ModelError(f"{key}.elements: must be a whole number >= 1, got {elements!r}")
    kinds = [k for k in KINDS if k in table]
    if len(kinds) != 1:
        raise ModelError(f"{key}.section: give exactly one of circle = d, tube = [d_out, d_in]"
                         f", rect = [b, h] (found {', '.join(kinds) or 'none'})")
    E = _number(table, "E", key, low=0.0)
    rho = _number(table, "rho", key, low=0.0)
    nu = _number(table, "nu", key, default=0.3)
    if not -1.0 < nu < 0.5:
        raise ModelError(f"{key}.nu: Poisson's ratio must lie in (-1, 0.5), got {nu!r}")
    section = make_section(kinds[0], table[kinds[0]], nu, f"{key}.{kinds[0]}")
    return length, elements, section, E, rho, nu


def _with_section(table, key):
    """``section = { circle = d }`` (or ``tube``, ``rect``) written as the segment's own
    ``circle = d``: the two spellings are the same beam."""
    if "section" not in table:
        return table
    section = table["section"]
    if not isinstance(section, dict) or len(section) != 1 or next(iter(section)) not in KINDS:
        raise ModelError(f"{key}.section: give exactly one of circle = d, tube = [d_out, "
                         f"d_in], rect = [b, h] in it, e.g. section = {{ circle = 0.02 }}; "
                         f"got {section!r}")
    if any(k in table for k in KINDS):
        raise ModelError(f"{key}.section: the section is also given as "
                         f"{', '.join(k for k in KINDS if k in table)}; keep one")
    out = {k: v for k, v in table.items() if k != "section"}
    out.update(section)
    return out


def _segments(spec, key):
    if "segments" in spec:
        segs = spec["segments"]
        if any(k in spec for k in SEGMENT_KEYS):
            raise ModelError(f"{key}: give either segments or one segment's keys "
                             f"({', '.join(SEGMENT_KEYS)}) in the beam's table, not both")
        if not isinstance(segs, list) or not segs:
            raise ModelError(f"{key}.segments: must be a non-empty array of tables")
        return [_segment(s, f"{key}.segments[{i}]") for i, s in enumerate(segs)]
    return [_segment({k: v for k, v in spec.items() if k in SEGMENT_KEYS}, key)]


def _named_nodes(table, x, key):
    names = {"root": 0, "tip": len(x) - 1}
    if not isinstance(table, dict):
        raise ModelError(f"{key}.nodes: must be a table of name = position along x")
    for name, pos in table.items():
        problem = identifier_problem(name)
        if problem:
            raise ModelError(f"{key}.nodes: the name {name!r} {problem}")
        where = _number(table, name, f"{key}.nodes", low=None)
        if not -1e-9 * x[-1] <= where <= x[-1] * (1 + 1e-9):
            raise ModelError(f"{key}.nodes.{name}: {where:g} is off the beam (0 .. {x[-1]:g})")
        names[name] = nearest_node(x, where)
    return names


def _attachment(table, x, names, key):
    if not isinstance(table, dict):
        raise ModelError(f"{key}: must be a table of at, mass, polar, diametral")
    _unknown(table, MASS_KEYS, key)
    if "at" not in table:
        raise ModelError(f"{key}.at: missing; give a node's name or a position along x")
    at = table["at"]
    if isinstance(at, str):
        if at not in names:
            raise ModelError(f"{key}.at: no node named {at!r}; named: {', '.join(names)}")
        node = names[at]
    else:
        where = _number(table, "at", key)
        if not -1e-9 * x[-1] <= where <= x[-1] * (1 + 1e-9):
            raise ModelError(f"{key}.at: {where:g} is off the beam (0 .. {x[-1]:g})")
        node = nearest_node(x, where)
    m = _number(table, "mass", key, default=0.0, low=0.0, strict=False)
    polar = _number(table, "polar", key, default=0.0, low=0.0, strict=False)
    diam = _number(table, "diametral", key, default=0.0, low=0.0, strict=False)
    if m == polar == diam == 0.0:
        raise ModelError(f"{key}: give a mass, polar or diametral inertia above zero")
    if polar > 2.0 * diam * (1 + 1e-12) and diam > 0.0:
        warnings.warn(f"{key}: polar inertia {polar:g} exceeds twice the diametral {diam:g} "
                      "(no rigid body has that; a thin disk has polar = 2 diametral)",
                      ModelWarning, stacklevel=4)
    return Attachment(node, m, polar, diam)


def beam_from_spec(spec, key="flexible.beam"):
    """The :class:`Beam` described by the table ``spec`` (see this module's docstring);
    ``key`` is the table's path, used in error messages."""
    if not isinstance(spec, dict):
        raise ModelError(f"{key}: must be a table")
    _unknown(spec, BEAM_KEYS + SEGMENT_KEYS, key)
    theory = spec.get("theory", "timoshenko")
    if theory not in THEORIES:
        raise ModelError(f"{key}.theory: {theory!r} is not one of {', '.join(THEORIES)}")
    rotary = spec.get("rotary_inertia", theory == "timoshenko")
    if not isinstance(rotary, bool):
        raise ModelError(f"{key}.rotary_inertia: must be true or false, got {rotary!r}")
    segments = _segments(spec, key)
    total = sum(s[1] for s in segments)
    if total > MAX_BEAM_ELEMENTS:
        raise ModelError(f"{key}: {total} elements (at most {MAX_BEAM_ELEMENTS}); a reduced "
                         "model rarely needs more than a few dozen")
    x, E, G, rho, sections = [0.0], [], [], [], []
    for length, n, section, e, r, nu in segments:
        n = int(n)
        x.extend(x[-1] + length * np.arange(1, n + 1) / n)
        E += [e] * n
        G += [e / (2.0 * (1.0 + nu))] * n
        rho += [r] * n
        sections += [section] * n
    x = np.array(x)
    names = _named_nodes(spec.get("nodes", {}), x, key)
    masses = spec.get("masses", [])
    if not isinstance(masses, list):
        raise ModelError(f"{key}.masses: must be an array of tables")
    attachments = tuple(_attachment(m, x, names, f"{key}.masses[{i}]")
                        for i, m in enumerate(masses))
    return Beam(x=x, E=np.array(E), G=np.array(G), rho=np.array(rho),
                sections=tuple(sections), theory=theory, rotary_inertia=rotary,
                attachments=attachments, node_names=names)
