"""Numeric kernels on the compiled model's flat arrays (numba, ``@njit(cache=True)``).

Plain loops over arrays, no Python objects, joint kinds dispatched by integer code so one
compiled kernel serves every model.  ``NUMBA_DISABLE_JIT=1`` runs them as plain Python.
"""
import warnings

from .cache import install as _install_cache

#: before any kernel module is imported: numba's cache entries stamped with every
#: kernel module's source, not only their own (``cache``)
_install_cache()

#: numba's SSA pass reports variables of functions inlined into a loop
#: (``inline="always"``) as "not in scope" when it compiles the loop: an internal
#: "pedantic check" of its own IR (``NumbaIRAssumptionWarning``), not about the numbers,
#: which the tests check against independent routes.  A user would read it as an error.
#: It is raised from numba's module or, in a parallel loop, from the kernel's source line,
#: so it is matched by its text alone (after numba's terminal highlighting codes).
PEDANTIC_NUMBA = {"message": r"(\x1b\[\d+m)*variable '[^']*' is not in scope"}


def ignore_pedantic_numba():
    """Silence numba's pedantic scope warning (only that one) in the current filters."""
    warnings.filterwarnings("ignore", **PEDANTIC_NUMBA)


ignore_pedantic_numba()
