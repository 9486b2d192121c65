"""Model files (TOML), results export.

``load_model(path, case=None, overrides=None)`` -> ``Scene`` (``.model``, ``.q0``, ``.u0``,
``.simulate()``); the format is documented in ``docs/model-files.md``.
"""
from .errors import ModelFileError
from .expressions import ExpressionError, parse as parse_expression
from .loader import METHODS, Scene, load_model, read_document
from .results import summary, write_results

__all__ = ["load_model", "Scene", "ModelFileError", "ExpressionError", "parse_expression",
           "METHODS", "read_document", "summary", "write_results"]
