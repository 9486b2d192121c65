"""The equations of motion in closed form: the textbook's walk done with sympy.

* ``derive(model_or_system, method="jourdain"|"newton-euler"|"lagrange", frames="own",
  simplify="compact", solve=False)`` -> ``Derivation`` (``mass_matrix``, ``forcing``,
  ``accelerations``, ``reactions``, ``steps()``, ``to_text/latex/markdown/json``);
* ``compare`` -- symbolic and numeric equivalence checks (against each other and against
  the numeric engine);
* ``compiled_rhs(model)`` -- generated, numba-compiled right-hand side, used by
  ``mb.simulate(..., method="symbolic")``.

Layers: ``symbols`` (names, exact numbers, rotations) -> ``walk`` (kinematics, loads) ->
``methods`` (Newton-Euler, Jourdain, Lagrange) -> ``derive`` / ``solve`` / ``steps`` /
``report``; ``codegen`` on top.
"""
from .codegen import CompiledRHS, compiled_rhs, generate_source
from .compare import (compare_methods, compare_numerically, random_states, same_expression,
                      same_matrix)
from .derive import Derivation, derive
from .methods import METHODS
from .simplify import MODES, operations, operations_after_cse
from .walk import FRAMES, Walk

__all__ = ["derive", "Derivation", "Walk", "METHODS", "FRAMES", "MODES", "compiled_rhs",
           "CompiledRHS", "generate_source", "compare_methods", "compare_numerically",
           "random_states", "same_expression", "same_matrix", "operations",
           "operations_after_cse"]
