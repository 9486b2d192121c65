"""Numeric kernels on the compiled model's flat arrays (numba, ``@njit(cache=True)``).

Plain loops over arrays, no Python objects, joint kinds dispatched by integer code so one
compiled kernel serves every model.  ``NUMBA_DISABLE_JIT=1`` runs them as plain Python.
"""
