"""URDF robots read into a ``System`` (docs/urdf.md): a reader of the io layer that builds
through ``System``'s public API, as the TOML loader does.

``add_urdf(system, path)`` adds a URDF file's links, joints, dampers, friction, stops and
mimic couplings to ``system`` and returns the ``RobotBuilder`` (``report``: what was read
and made, for ``mbdyn info``; ``warnings``); ``mb.load_model("robot.urdf")`` and a model
file's ``[model] urdf = "robot.urdf"`` go through it.  One job a module: the hardened XML
reading (``parse``), the tree and the URDF's conventions (``tree``), the bodies and
joints (``build``), the effects and couplings (``effects``).
"""
from __future__ import annotations

import warnings

from ...errors import ModelWarning
from ..document import read_bytes
from .build import RobotBuilder, add_robot
from .parse import JOINT_TYPES, Reader, parse_urdf
from .tree import rpy_matrix


def is_urdf(path):
    """Whether ``path`` names a URDF file (by its suffix ``.urdf``)."""
    return str(path).lower().endswith(".urdf")


def read_urdf(path, text=None):
    """The ``Robot`` records of the URDF file ``path`` (or of ``text``, named ``path``)."""
    data = read_bytes(path) if text is None else text
    return parse_urdf(data, str(path))


def add_urdf(system, path, *, floating=False, accept_inertia=False, text=None,
             warn=True, mesh_path=()):
    """Add the URDF file ``path`` to ``system`` (a ``mb.System``); returns the
    ``RobotBuilder``: ``report`` (what was read and made), ``warnings``, ``bodies`` and
    ``joints`` (the names added).  ``floating``: the base hangs from the ground by a free
    joint ``root`` (else a fixed one).  ``accept_inertia``: take inertias no body can have
    (a negative principal moment set to zero, a broken triangle inequality), with a
    warning, instead of refusing them.  ``warn``: emit the warnings (``ModelWarning``).
    ``mesh_path``: folders ``package://`` meshes of ``<visual>`` are looked for in (before
    the URDF's own folder and its parents; docs/urdf.md)."""
    robot = read_urdf(path, text)
    builder = add_robot(system, Reader(path), robot, floating=floating,
                        accept_inertia=accept_inertia, mesh_path=mesh_path)
    if warn:
        for message in builder.warnings:
            warnings.warn(message, ModelWarning, stacklevel=2)
    return builder


__all__ = ["add_urdf", "read_urdf", "is_urdf", "rpy_matrix", "RobotBuilder", "JOINT_TYPES"]
