"""Tree joints of two degrees of freedom made of two 1-DoF joints through a massless frame:
``universal`` (a turn about ``axis``, then about ``axis2``) and ``cylindrical`` (a slide
along ``axis`` and a turn about it).

A universal joint is a revolute from the parent to a massless cross (``NAME.cross``)
and a revolute from the cross to the child; a cylindrical joint a prismatic and a
revolute.  The two joints are named ``NAME_1``, ``NAME_2`` (universal) or
``NAME_slide``, ``NAME_turn`` (cylindrical), and so are their coordinates, unless
``coordinates`` names them; the second joint's reaction is the composite joint's
(parent's side on the child: the cross carries no mass).
"""
from __future__ import annotations

import numpy as np

from ..elements.values import parse_axis
from ..errors import ModelError

#: the two joints each composite kind is made of, and their names' suffixes
PARTS = {"universal": (("revolute", "_1"), ("revolute", "_2")),
         "cylindrical": (("prismatic", "_slide"), ("revolute", "_turn"))}


def add_composite_joint(system, name, kind, parent, child, *, axis=None, axis2=None,
                        position=(0, 0, 0), orientation=None, coordinates=None, drive=None,
                        **other):
    """``System.add_joint`` for a tree ``universal`` or ``cylindrical`` joint."""
    element = f"joint {name!r}"
    unknown = sorted(k for k, v in other.items() if v is not None)
    if unknown:
        raise ModelError(f"{element}: a {kind} tree joint takes axis, position, "
                         f"orientation, coordinates{', axis2' if kind == 'universal' else ''}"
                         f"; not {', '.join(unknown)}")
    if drive is not None:
        raise ModelError(f"{element}: a {kind} joint cannot be driven (only 1-DoF joints); "
                         "drive its parts as two joints instead")
    if axis is None:
        raise ModelError(f"{element}: a {kind} joint needs an axis, e.g. axis = 'z'")
    if kind == "universal":
        if axis2 is None:
            raise ModelError(f"{element}: a universal joint needs axis2, its second axis (in "
                             "the child's frame), perpendicular to axis")
        a1 = parse_axis(axis, element) if isinstance(axis, str) else np.asarray(axis, float)
        a2 = parse_axis(axis2, element) if isinstance(axis2, str) else np.asarray(axis2, float)
        if abs(float(a1 @ a2)) > 1e-9 * np.linalg.norm(a1) * np.linalg.norm(a2):
            raise ModelError(f"{element}: axis2 {a2.tolist()} is not perpendicular to axis "
                             f"{a1.tolist()}")
        second_axis = axis2
    elif axis2 is not None:
        raise ModelError(f"{element}: only a universal joint takes axis2")
    else:
        second_axis = axis
    names = [name + suffix for _, suffix in PARTS[kind]]
    if coordinates is not None:
        coordinates = [coordinates] if isinstance(coordinates, str) else list(coordinates)
        if len(coordinates) != 2:
            raise ModelError(f"{element}: a {kind} joint has 2 coordinates, got names "
                             f"{coordinates}")
    cross = f"{name}.cross"
    system.add_frame(cross)
    (k1, _), (k2, _) = PARTS[kind]
    system.add_joint(names[0], k1, parent, cross, axis=axis, position=position,
                     orientation=orientation,
                     coordinates=None if coordinates is None else coordinates[0])
    system.add_joint(names[1], k2, cross, child, axis=second_axis,
                     coordinates=None if coordinates is None else coordinates[1])
    return name
