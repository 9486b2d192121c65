"""C functions that say when they compile (``mbdyn.kernels.c_function``): numba's compile
event around a compile, none on a load from the cache, and the compile notice's count
(``cli.compiling.Watch``) includes them."""
from __future__ import annotations

import ctypes
import io
import os
import subprocess
import sys
import textwrap

from numba.core import event

from mbdyn.cli import compiling
from mbdyn.kernels import force_function, route_entry
from mbdyn.kernels.c_function import c_function, shown_name


class Events(event.Listener):
    """The names of the dispatchers of the ``numba:compile`` events received."""

    def __init__(self):
        self.names = []

    def on_start(self, ev):
        self.names.append(ev.data["dispatcher"].py_func.__qualname__)

    def on_end(self, ev):
        pass


def _twice(x):
    return 2.0 * x


def test_a_compile_is_an_event_and_the_function_works():
    events = Events()
    with event.install_listener("numba:compile", events):
        made = c_function("float64(float64)", _twice)
    assert events.names == ["_twice"]
    assert made.shown_name == "test_c_function._twice"
    call = ctypes.CFUNCTYPE(ctypes.c_double, ctypes.c_double)(made.address)
    assert call(1.25) == 2.5


def test_the_notice_counts_a_c_function(monkeypatch):
    monkeypatch.setenv("MBDYN_COMPILE_NOTICE", "1")
    monkeypatch.setitem(compiling._STATE, "announced", True)   # the closing line only
    stream = io.StringIO()
    with compiling.Watch(stream=stream) as watch:
        c_function("float64(float64)", _twice)
    watch.close()
    assert [name for name, _ in watch.compiled] == ["test_c_function._twice"]
    assert stream.getvalue().startswith("mbdyn: compiled 1 kernels in ")


SCRIPT = textwrap.dedent("""
    import sys
    from numba.core import event
    sys.path.insert(0, sys.argv[1])
    from cached_twice import twice
    from mbdyn.kernels.c_function import c_function
    seen = []

    class Events(event.Listener):
        def on_start(self, ev):
            seen.append(ev.data["dispatcher"].py_func.__qualname__)

        def on_end(self, ev):
            pass
    with event.install_listener("numba:compile", Events()):
        made = c_function("float64(float64)", twice, cache=True)
    print(len(seen), made.cache_hits)
""")


def test_a_load_from_the_cache_is_no_event(tmp_path):
    """The first process compiles (one event) and saves; the second loads (no event)."""
    (tmp_path / "cached_twice.py").write_text("def twice(x):\n    return 2.0 * x\n")
    env = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path / "cache"))
    runs = [subprocess.run([sys.executable, "-c", SCRIPT, str(tmp_path)], env=env,
                           capture_output=True, text=True, check=True).stdout.split()
            for _ in range(2)]
    assert runs == [["1", "0"], ["0", "1"]]


def test_the_notice_estimates_each_c_function_of_the_package():
    """A C function that compiles before any other kernel (the closed route after
    ``mbdyn info`` of the same mechanism cached the rest) is announced with its own
    estimate, not the default ``OTHER``."""
    functions = (*route_entry._KINDS.values(), *force_function._PYTHON.values())
    for function in functions:
        assert shown_name(function) in compiling.SECONDS, shown_name(function)
    assert shown_name(route_entry._closed) == "route_entry._closed"
