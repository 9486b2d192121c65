"""The safe reader of model-file expressions lives in ``mbdyn.expressions`` (the element
layer, so that Python events can use it too); this module keeps its old import path."""
from ..expressions import *  # noqa: F401,F403
from ..expressions import (FUNCTIONS, RESERVED, ExpressionError, parse,  # noqa: F401
                           parse_condition, symbol, to_float)
