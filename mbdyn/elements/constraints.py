"""Loop joints and constraints: the records of what closes a kinematic loop, each
validated on creation (``System.add_joint`` with a ``child_position``, or a ``distance`` or
``coupling``).

A loop joint joins a point and frame of its parent body (``position``, ``orientation``,
as a tree joint's) to a point and frame of its child body (``child_position``,
``child_orientation``, in the child's body axes) which already hangs from the tree.  Its
``axis`` is given in the parent's joint frame and is the same vector in the child's joint
frame; a ``universal`` joint's second axis ``axis2`` is in the child's joint frame.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..errors import ModelError
from .values import _vector3, has_symbols, numeric, parse_axis, parse_orientation

#: kinds that can close a loop, with the number of equations each writes
LOOP_KINDS = {"revolute": 5, "prismatic": 5, "spherical": 3, "fixed": 6, "universal": 4,
              "cylindrical": 4, "distance": 1, "coupling": 1}
#: kinds that need an axis
AXIAL = ("revolute", "prismatic", "universal", "cylindrical")


@dataclass(frozen=True)
class LoopJoint:
    """A constraint closing a loop; see ``System.add_joint``.  ``follower``, ``leader``,
    ``ratio``, ``offset`` are a coupling's (``q_follower = ratio q_leader + offset``);
    ``length`` a distance's.  ``symbolic`` keeps the values given as sympy expressions of
    the parameters (for ``mbdyn.symbolic``), by keyword."""
    name: str
    kind: str
    parent: str | None
    child: str | None
    position: np.ndarray
    orientation: np.ndarray
    child_position: np.ndarray
    child_orientation: np.ndarray
    axis: np.ndarray
    axis2: np.ndarray
    length: float = 0.0
    follower: str | None = None
    leader: str | None = None
    ratio: float = 1.0
    offset: float = 0.0
    symbolic: dict = field(default_factory=dict, compare=False, repr=False)

    @property
    def equations(self):
        return LOOP_KINDS[self.kind]


def make_loop_joint(name, kind, parent, child, *, position=(0, 0, 0), orientation=None,
                    child_position=None, child_orientation=None, axis=None, axis2=None,
                    length=None, follower=None, leader=None, ratio=1.0, offset=0.0,
                    parameters=None):
    """Validate and build a ``LoopJoint``."""
    element = f"joint {name!r}"
    parameters = parameters or {}
    raw = {"position": position, "orientation": orientation, "child_position": child_position,
           "child_orientation": child_orientation, "axis": axis, "axis2": axis2,
           "length": length, "ratio": ratio, "offset": offset}
    symbolic = {k: v for k, v in raw.items() if not isinstance(v, str) and has_symbols(v)}
    if kind not in LOOP_KINDS:
        raise ModelError(f"{element}: a {kind!r} joint cannot close a loop; use one of "
                         + ", ".join(repr(k) for k in LOOP_KINDS))
    num = lambda value, what: numeric(value, parameters, element, what)  # noqa: E731
    if kind == "coupling":
        return _make_coupling(name, follower, leader, num(ratio, "ratio"),
                              num(offset, "offset"), symbolic)
    if child == parent:
        raise ModelError(f"{element}: parent and child are both {child!r}; a loop joint "
                         "joins two different bodies")
    if kind != "distance" and child_position is None:
        raise ModelError(f"{element}: a loop joint needs child_position (the joint's point "
                         f"in {child!r}'s body frame)")
    position = _vector3(num(position, "position"), "position", element)
    child_position = _vector3(num(child_position if child_position is not None else (0, 0, 0),
                                  "child_position"), "child_position", element)
    C = parse_orientation(_orientation(orientation, num), element)
    Cc = parse_orientation(_orientation(child_orientation, num), element)
    if kind in AXIAL:
        if axis is None:
            raise ModelError(f"{element}: a {kind} joint needs an axis, e.g. axis = 'z'")
        axis = parse_axis(axis if isinstance(axis, str) else num(axis, "axis"), element)
    elif axis is not None:
        raise ModelError(f"{element}: a {kind} joint takes no axis (remove axis)")
    else:
        axis = np.array([0.0, 0.0, 1.0])
    if kind == "universal":
        if axis2 is None:
            raise ModelError(f"{element}: a universal joint needs axis2, its second axis "
                             "(in the child's joint frame), perpendicular to axis")
        axis2 = parse_axis(axis2 if isinstance(axis2, str) else num(axis2, "axis2"), element)
        if abs(float(axis @ axis2)) > 1e-9:
            raise ModelError(f"{element}: axis2 {axis2.tolist()} is not perpendicular to "
                             f"axis {axis.tolist()}; a universal joint's axes cross at a "
                             "right angle")
    elif axis2 is not None:
        raise ModelError(f"{element}: only a universal joint takes axis2")
    else:
        axis2 = np.zeros(3)
    if kind == "distance":
        if length is None:
            raise ModelError(f"{element}: a distance constraint needs length (m), the rod's "
                             "length between position and child_position")
        length = _scalar(num(length, "length"), element, "length")
        if not length > 0:
            raise ModelError(f"{element}: length must be positive, got {length}")
    elif length is not None:
        raise ModelError(f"{element}: only a distance constraint takes length")
    return LoopJoint(name, kind, parent, child, position, C, child_position, Cc, axis, axis2,
                     length=float(length or 0.0), symbolic=symbolic)


def _make_coupling(name, follower, leader, ratio, offset, symbolic=None):
    """A coupling ``q_follower = ratio q_leader + offset`` between two tree joints."""
    element = f"joint {name!r}"
    for key, value in (("follower", follower), ("leader", leader)):
        if not isinstance(value, str) or not value:
            raise ModelError(f"{element}: a coupling needs {key} = the name of a revolute or "
                             "prismatic joint (q_follower = ratio * q_leader + offset)")
    if follower == leader:
        raise ModelError(f"{element}: follower and leader are both {follower!r}; couple two "
                         "different joints")
    eye = np.eye(3)
    return LoopJoint(name, "coupling", None, None, np.zeros(3), eye, np.zeros(3), eye,
                     np.zeros(3), np.zeros(3), follower=follower, leader=leader,
                     ratio=_scalar(ratio, element, "ratio"),
                     offset=_scalar(offset, element, "offset"), symbolic=dict(symbolic or {}))


def _orientation(value, num):
    if isinstance(value, (tuple, list)) and len(value) == 2 and isinstance(value[0], str):
        return (value[0], num(value[1], "orientation"))
    return num(value, "orientation") if value is not None else None


def _scalar(value, element, what):
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise ModelError(f"{element}: {what} must be a number, got {value!r}") from None
    if not np.isfinite(v):
        raise ModelError(f"{element}: {what} must be finite, got {v}")
    return v
