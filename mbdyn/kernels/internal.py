"""Kernels that only compiled code calls: compiled without an entry from Python.

numba gives every compiled function two wrappers besides its code: one that Python calls
(it unboxes each argument from a Python object and boxes the result) and one that C calls.
A helper of the kinematics or of the composite inertias is only ever called from other
compiled functions, which call its code directly; its wrappers are compiled, optimised,
machine-coded and cached for nothing (for a function of twenty arrays the Python wrapper
is a quarter of its compile; ``docs/performance.md``, "Fourth round": 0.45 s of the
README's first command for its eleven helpers).

``internal`` compiles a function without either wrapper.  A helper moved out of its
callers' numba inlining (``inline="always"`` compiles it at every call site) takes
``forceinline=True``: compiled once by numba, its code inlined by LLVM into each caller, so
that runs pay no call.  Called from Python, such a
function would run a null entry (numba crashes the process), so its dispatcher never
registers an entry for Python calls: a call from Python reaches ``_compile_for_args``,
which raises ``TypeError`` naming the kernel.  A compiled caller's constant arguments are
typed as their types, not as literal values, so that a kernel compiles once per argument
types (four copies of the constraint rows, 13 s, in a closed loop's first run before),
unless it asks for its constants (``constants=True``).  ``tests/test_internal_kernels.py``
checks that no Python code of the package, its tests or benchmarks calls one.
"""
from numba.core import config, types
from numba.core.registry import CPUDispatcher


class InternalDispatcher(CPUDispatcher):
    """A dispatcher whose specializations compiled callers link, with no Python entry."""

    def add_overload(self, cres):
        # the specialization for compiled callers (type inference, linking), without
        # the entry in the table Python calls go through
        self.overloads[tuple(cres.signature.args)] = cres

    #: compiled once per constant value of its arguments (``internal(constants=True)``)
    by_constant = False

    def get_call_template(self, args, kws):
        # one specialization per argument types: a constant argument (``-1``, ``False``)
        # would otherwise compile its own copy per value, each as costly as the first
        if not self.by_constant:
            args = tuple(types.unliteral(a) for a in args)
            kws = {k: types.unliteral(a) for k, a in kws.items()}
        return super().get_call_template(args, kws)

    def _compile_for_args(self, *args, **kws):
        name = f"{self.py_func.__module__}.{self.py_func.__qualname__}"
        raise TypeError(f"{name} is an internal kernel (mbdyn.kernels.internal): it has no "
                        "entry from Python; call it from compiled code, or call "
                        f"{name}.py_func for the pure-Python original")


def internal(cache=False, constants=False, **options):
    """Decorator like ``numba.njit(cache=..., **options)`` for a function only compiled
    code calls (module docstring).  With ``constants``, a caller's constant arguments
    select a specialization of their own (a flag that removes a branch's work where the
    kernel is hot: ``motion``'s ``rates``)."""
    targetoptions = dict(options, nopython=True, no_cpython_wrapper=True,
                         no_cfunc_wrapper=True)

    def decorate(function):
        if config.DISABLE_JIT:
            return function
        dispatcher = InternalDispatcher(py_func=function, locals={},
                                        targetoptions=targetoptions)
        dispatcher.by_constant = constants
        if cache:
            dispatcher.enable_caching()
        return dispatcher
    return decorate
