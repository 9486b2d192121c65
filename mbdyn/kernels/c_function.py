"""C-callable functions (``numba.cfunc``) that say when they compile, as numba's jitted
functions do.

numba sends a ``numba:compile`` event whenever a jitted function compiles (never when it
loads from the cache), and the compile notice's progress line and closing count
(``cli.compiling.Watch``) and ``benchmarks/compile_events.py`` listen to it; a ``cfunc``
sends none.  A route's function (``route_entry``), a flexible model's (``flexible_entry``)
and the force elements' (``force_function``) compiled in silence: "compiled 10 kernels in
41 s" after a four-bar's first run that spent 57 s compiling, and the functions they call
were counted as kernels of their own.  ``c_function`` makes the ``cfunc`` with that event
around its compile; a cache hit sends none.
"""
from numba.core import event, sigutils
from numba.core.ccallback import CFunc


class _ReportedCFunc(CFunc):
    """A ``CFunc`` whose compile (not its load from the cache) is a ``numba:compile``
    event, with itself as the event's dispatcher."""

    @property
    def py_func(self):
        """The Python function compiled (what listeners read of a dispatcher)."""
        return self._pyfunc

    @property
    def shown_name(self):
        """``shown_name`` of the Python function compiled."""
        return shown_name(self._pyfunc)

    def _compile_uncached(self):
        data = {"dispatcher": self, "args": self._sig.args,
                "return_type": self._sig.return_type}
        with event.trigger_event("numba:compile", data=data):
            return super()._compile_uncached()


def shown_name(function):
    """``module.function`` for the progress line (its functions' names are short) and the
    compile notice's estimate (``cli.compiling.SECONDS``)."""
    return f"{function.__module__.rsplit('.', 1)[-1]}.{function.__qualname__}"


def c_function(signature, function, cache=False, **options):
    """``numba.cfunc(signature, cache=cache, **options)(function)``, compiled (or loaded
    from numba's cache) now, its compile reported as a ``numba:compile`` event."""
    made = _ReportedCFunc(function, sigutils.normalize_signature(signature), locals={},
                          options=options)
    if cache:
        made.enable_caching()
    made.compile()
    return made
