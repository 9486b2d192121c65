"""Numeric kernels on the compiled model's flat arrays (numba, ``@njit(cache=True)``).

Plain loops over arrays, no Python objects, joint kinds dispatched by integer code so one
compiled kernel serves every model.  ``NUMBA_DISABLE_JIT=1`` runs them as plain Python.
"""
import warnings

#: numba's SSA pass reports variables of functions inlined into a loop
#: (``inline="always"``) as "not in scope" when it compiles the loop: an internal
#: "pedantic check" of its own IR (``NumbaIRAssumptionWarning``), not about the numbers,
#: which the tests check against independent routes.  A user would read it as an error.
PEDANTIC_NUMBA = {"message": r".*is not in scope", "module": r"numba\.core\.ssa"}


def ignore_pedantic_numba():
    """Silence numba's pedantic scope warning (only that one) in the current filters."""
    warnings.filterwarnings("ignore", **PEDANTIC_NUMBA)


ignore_pedantic_numba()
