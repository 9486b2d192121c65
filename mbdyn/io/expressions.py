"""The safe reader of model-file expressions lives in ``mbdyn.elements.expressions`` (the element
layer, so that Python events can use it too); this module keeps its old import path."""
from ..elements.expressions import *  # noqa: F401,F403
from ..elements.expressions import (FUNCTIONS, RESERVED, ExpressionError, parse,
                                    parse_condition, symbol, to_float)
