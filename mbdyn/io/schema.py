"""The structure of a model file: known keys and value shapes, cases and overrides.

This module checks the *shape* of a parsed TOML document (every key known, every value of
the right kind, every expression syntactically valid) and merges cases and ``--set``
overrides into it, remembering where each overridden value came from so that an error
points at the place the user wrote it (``cases.a.initial.theta``, ``--set ...``).  What the
values mean (names that must exist, numbers that must be positive) is checked when the
model is built (``mbdyn.io.loader``).

The parts, one job a module: the schema's tables (``keys``), the check of each kind of
value (``value_checks``) and of a document (``checker``), cases and overrides
(``cases``), the limits on any parsed value and ``--set`` values (``document``).  This
module keeps their names where they have always been imported from.
"""
from __future__ import annotations

from .cases import apply_case, apply_override, split_path  # noqa: F401
from .checker import Checker  # noqa: F401
from .document import parse_set_value, scan_document  # noqa: F401
from .keys import (ARRAY_ELEMENT, BODY_KEYS, DIRECTIONS, EFFECT_KEYS, EVENT_KEYS,  # noqa: F401
                   FORCE_KEYS, FORCE_KINDS, JOINT_KEYS, JOINT_KINDS, LOAD_KEYS, MODEL_KEYS,
                   OUTPUT_KEYS, POINT_KEYS, SECTIONS, SHAPE_KEYS, SIMULATION_KEYS)
from .wording import format_path  # noqa: F401
