"""What a cold ``mbdyn`` command compiles: numba's compile events, CPU seconds.

    python benchmarks/compile_events.py [COMMAND ...]     (default: run models/top.toml --case a)

Runs the command in this process with an empty numba cache (``NUMBA_CACHE_DIR`` set to a
new temporary directory, so the checkout's own cache is neither used nor touched) and
records numba's ``numba:compile`` events.  Prints two markdown tables: the *entry points*
(functions compiled from Python, each with everything it compiles below it: each one is
optimised and machine-coded with its whole call tree) and every compiled function's *own*
CPU time (its time minus its callees' compiles), largest first.  Read with
docs/performance.md, "Cold and warm start".
"""
from __future__ import annotations

import os
import sys
import tempfile
import time

os.environ["NUMBA_CACHE_DIR"] = tempfile.mkdtemp(prefix="mbdyn-compile-events-")
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
HERE = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, HERE)

import numba.core.event as event  # noqa: E402  (after NUMBA_CACHE_DIR is set)


class CompileTimes(event.Listener):
    """Own and inclusive CPU time of every compile, and which ones came from Python."""

    def __init__(self):
        self.stack, self.own, self.count, self.entries = [], {}, {}, []

    def on_start(self, ev):
        fn = ev.data["dispatcher"].py_func
        self.stack.append([f"{fn.__module__}.{fn.__qualname__}", time.process_time(), 0.0])

    def on_end(self, ev):
        name, start, children = self.stack.pop()
        spent = time.process_time() - start
        self.own[name] = self.own.get(name, 0.0) + spent - children
        self.count[name] = self.count.get(name, 0) + 1
        if self.stack:
            self.stack[-1][2] += spent
        else:
            self.entries.append((name, spent))


def main(argv):
    args = argv or ["run", "models/top.toml", "--case", "a", "--json"]
    times = CompileTimes()
    event.register("numba:compile", times)
    os.chdir(HERE)
    start = time.process_time()
    from mbdyn.cli import main as mbdyn_main
    with open(os.devnull, "w") as devnull:
        stdout, sys.stdout = sys.stdout, devnull
        try:
            code = mbdyn_main(args)
        finally:
            sys.stdout = stdout
    total = time.process_time() - start
    compiled = sum(t for _, t in times.entries)
    print(f"`mbdyn {' '.join(args)}`: exit code {code}, {total:.1f} s CPU in all, "
          f"{compiled:.1f} s of it compiling\n")
    print("| entry point (compiled from Python) | CPU (s), with its callees |")
    print("|---|---:|")
    for name, spent in times.entries:
        print(f"| `{name}` | {spent:.2f} |")
    print("\n| compiled function | own CPU (s) | compiles |")
    print("|---|---:|---:|")
    for name, spent in sorted(times.own.items(), key=lambda kv: -kv[1]):
        if spent >= 0.1:
            print(f"| `{name}` | {spent:.2f} | {times.count[name]} |")


if __name__ == "__main__":
    main(sys.argv[1:])
