"""Model files (TOML) -> ``System`` -> compiled ``Model`` -> a ready-to-run ``Scene``.

``load_model(path, case=None, overrides=None)`` reads the file with ``tomllib``, checks its
shape (``mbdyn.io.schema``), merges the chosen case and the overrides, then builds the
``System``: parameters become ``System(parameters=...)`` and every value written as an
expression of parameters is handed to the engine as a sympy expression of the parameter
symbols (the symbolic layer reads them); numbers stay numbers.  Errors are
``ModelFileError``: file, key path, what is wrong, what to change.  The format is
documented in ``docs/model-files.md``.

The steps, one job a module: reading the file (``document``), the ``Scene`` and
``load_model`` (``scene``), the builder of the ``System`` and ``Model`` (``builder``), the
sections that make the system (``system_sections``), the initial state (``initial``),
``[simulation]`` and ``[outputs]`` (``settings``), ``[[events]]`` (``events``).  This module
keeps their names where they have always been imported from.
"""
from __future__ import annotations

from .cases import split_path
from .document import decode_text, parse_document, read_bytes, read_document  # noqa: F401
from .scene import Scene, load_model
from .settings import BUDGETS, DEFAULT_SIMULATION, METHODS, SIMULATE_KEYWORDS  # noqa: F401

__all__ = ["load_model", "read_document", "Scene", "METHODS", "DEFAULT_SIMULATION",
           "split_path"]
