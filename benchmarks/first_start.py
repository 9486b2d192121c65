"""First start: the cost of ``import mbdyn``, of a cold and a warm ``mbdyn run``, and of
each feature's first use.

    python benchmarks/first_start.py [--warm 3] [--cold 1] [--source DIR]
    python benchmarks/first_start.py --features [NAME ...] [--shared] [--source DIR]

Copies the package (``mbdyn/`` of ``--source``, default this checkout) and the model into a
temporary directory, so that the cold runs start from an empty numba cache without
touching the checkout's own cache, and times, as separate processes:

* ``python -c "import mbdyn"`` (and ``python -c pass`` for reference);
* the cold ``python -m mbdyn run models/top.toml --case a``: every ``__pycache__`` of the
  copy deleted first, so every kernel the run needs is compiled;
* the warm run: the same command again, the kernels loaded from the cache.

The children run with Python's default bytecode cache (``PYTHONDONTWRITEBYTECODE`` is
taken out of their environment): a user's second run finds the ``.pyc`` files its first run
wrote.  Where that variable is set, every run compiles the package's Python source anew,
about 0.1 s that a user does not pay.

Prints a markdown table of the medians (wall time and CPU time: user + system of the
child) over the runs.

``--features`` instead times the cold first use of each feature (``FEATURES``: the
README's command, an adaptive run, force elements, the articulated route, a closed loop,
a batched sweep, modes, an HTML animation), each in a fresh process with an empty numba
cache of its own (``NUMBA_CACHE_DIR`` set to a new folder: numba's cache locator takes it
before the package's ``__pycache__``, and the benchmark checks that the copy's folders
received no cache file), then the same command again warm, from that cache.  Cold minus
warm is about what compiling costs; "kernels" counts the compiled entry points numba
wrote to the cache (its index files).  The machine's load shows in the wall times; compare CPU times, and
compare against a baseline measured in the same session (``--source`` of another
checkout, e.g. a ``git worktree`` of an older commit).  ``--features --shared`` runs the
features in order on one cache instead, as a newcomer meets them: each one's cold figure
is what its first use adds to the ones before.
"""
from __future__ import annotations

import argparse
import os
import resource
import shutil
import statistics
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
COMMAND = ["-m", "mbdyn", "run", "models/top.toml", "--case", "a"]
#: the children's environment: this one without PYTHONDONTWRITEBYTECODE (see above)
CHILD_ENV = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}


#: ``(name, command line)`` of each feature's first use, on the shipped models (run in a copy
#: of the checkout's ``models/``) and ``mbdyn warmup``'s six-link chain (no shipped model is
#: a tree of 6 or more speeds without force elements); ``{tmp}`` is a scratch folder that
#: holds ``chain.toml``
FEATURES = (
    ("README command (`run models/top.toml --case a`)", COMMAND[2:]),
    ("adaptive run (DOP853), small tree", ["run", "models/double_pendulum.toml",
                                           "--integrator", "DOP853"]),
    ("force elements (DOP853)", ["run", "models/mass_spring_damper.toml"]),
    ("articulated route (6+ speeds, DOP853)", ["run", "{tmp}/chain.toml"]),
    ("URDF arm (6 speeds, joint stops, DOP853)", ["run", "models/arm6.urdf", "--t-end",
                                                  "1"]),
    ("closed loop (four-bar, DOP853)", ["run", "models/four_bar.toml"]),
    ("batched sweep (rk4)", ["sweep", "models/double_pendulum.toml", "--grid",
                             "initial.theta1=0.1:0.5:4", "--integrator", "rk4", "--batched",
                             "--json"]),
    ("modes", ["modes", "models/double_pendulum.toml"]),
    ("animate (HTML)", ["animate", "models/double_pendulum.toml", "--out",
                        "{tmp}/pendulum.html"]),
)


def timed(args, cwd, env=None):
    """Run ``python ARGS`` in ``cwd``; returns ``(wall s, cpu s)`` of the child."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    start = time.perf_counter()
    subprocess.run([sys.executable, *args], cwd=cwd, check=True, stdout=subprocess.DEVNULL,
                   stderr=subprocess.DEVNULL, env=CHILD_ENV | {"PYTHONPATH": cwd} | (env or {}))
    wall = time.perf_counter() - start
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    return wall, cpu


def clear_cache(root):
    """Delete every ``__pycache__`` under ``root/mbdyn`` (numba caches its kernels there)."""
    for dirpath, dirnames, _ in os.walk(os.path.join(root, "mbdyn")):
        if "__pycache__" in dirnames:
            shutil.rmtree(os.path.join(dirpath, "__pycache__"))
            dirnames.remove("__pycache__")


def median(rows):
    return statistics.median(r[0] for r in rows), statistics.median(r[1] for r in rows)


def measure(source, n_warm, n_cold, n_import):
    """``{label: (n, wall, cpu)}`` for a copy of ``source``'s package."""
    with tempfile.TemporaryDirectory(prefix="mbdyn-first-start-") as tmp:
        shutil.copytree(os.path.join(source, "mbdyn"), os.path.join(tmp, "mbdyn"),
                        ignore=shutil.ignore_patterns("__pycache__"))
        os.makedirs(os.path.join(tmp, "models"))
        shutil.copy(os.path.join(source, "models", "top.toml"), os.path.join(tmp, "models"))
        out = {}
        cold = []
        for _ in range(n_cold):
            clear_cache(tmp)
            cold.append(timed(COMMAND, tmp))
        if not n_cold:                   # the warm runs need a filled cache
            clear_cache(tmp)
            timed(COMMAND, tmp)
        warm = [timed(COMMAND, tmp) for _ in range(n_warm)]
        python = [timed(["-c", "pass"], tmp) for _ in range(n_import)]
        imports = [timed(["-c", "import mbdyn"], tmp) for _ in range(n_import)]
        out["python -c pass (reference)"] = (n_import, *median(python))
        out["python -c 'import mbdyn'"] = (n_import, *median(imports))
        if cold:
            out["cold `mbdyn run models/top.toml --case a`"] = (n_cold, *median(cold))
        out["warm `mbdyn run models/top.toml --case a`"] = (n_warm, *median(warm))
        return out


def cache_files(root, suffix=".nbi"):
    """Paths of numba's cache index files under ``root``."""
    return [os.path.join(d, f) for d, _, files in os.walk(root) for f in files
            if f.endswith(suffix)]


def write_chain(tmp, folder):
    """``folder/chain.toml``: the six-link chain of ``mbdyn warmup`` (its model files are
    Python strings: read from the copy in ``tmp`` without importing the package)."""
    path = os.path.join(tmp, "mbdyn", "cli", "warmup_models.py")
    namespace = {}
    with open(path, encoding="utf-8") as f:
        exec(compile(f.read(), path, "exec"), namespace)
    with open(os.path.join(folder, "chain.toml"), "w", encoding="utf-8") as f:
        f.write(namespace["MODELS"]["chain"])


def measure_features(source, names=None, n_warm=1, shared=False):
    """``{feature: (kernels, cold wall, cold cpu, warm wall, warm cpu)}``: each feature
    cold in a fresh process with an empty numba cache of its own, then ``n_warm`` times
    warm from that cache (medians).  ``shared``: one cache for all, the features in
    ``FEATURES``' order (the README's command first), as a newcomer meets them: each
    cold figure is then what that feature's first use adds, and "kernels" counts the
    cache's index files so far."""
    out = {}
    cache = None
    with tempfile.TemporaryDirectory(prefix="mbdyn-first-use-") as tmp:
        shutil.copytree(os.path.join(source, "mbdyn"), os.path.join(tmp, "mbdyn"),
                        ignore=shutil.ignore_patterns("__pycache__"))
        shutil.copytree(os.path.join(source, "models"), os.path.join(tmp, "models"))
        # Python's own bytecode first, so that no feature pays for it
        subprocess.run([sys.executable, "-m", "compileall", "-q", "mbdyn"], cwd=tmp,
                       check=True, env=CHILD_ENV)
        for name, line in FEATURES:
            if names and not any(n.lower() in name.lower() for n in names):
                continue
            if cache is None or not shared:
                cache = tempfile.mkdtemp(prefix="cache-", dir=tmp)
            scratch = tempfile.mkdtemp(prefix="scratch-", dir=tmp)
            write_chain(tmp, scratch)
            args = ["-m", "mbdyn", *[w.format(tmp=scratch) for w in line]]
            env = {"NUMBA_CACHE_DIR": cache}
            cold = timed(args, tmp, env)
            warm = [timed(args, tmp, env) for _ in range(n_warm)]
            stray = cache_files(os.path.join(tmp, "mbdyn"))
            if stray:
                raise RuntimeError(f"numba wrote cache files beside the source, not in "
                                   f"NUMBA_CACHE_DIR: {stray[:3]}")
            out[name] = (len(cache_files(cache)), *cold, *median(warm))
            print(f"  {name}: cold {cold[1]:.1f} s CPU", file=sys.stderr, flush=True)
    return out


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--warm", type=int, default=3, help="warm runs (default 3)")
    parser.add_argument("--cold", type=int, default=1, help="cold runs (default 1)")
    parser.add_argument("--imports", type=int, default=5,
                        help="runs of python -c 'import mbdyn' (default 5)")
    parser.add_argument("--source", default=HERE,
                        help="checkout whose mbdyn/ and models/top.toml to measure "
                             "(default this one)")
    parser.add_argument("--features", nargs="*", metavar="NAME",
                        help="time each feature's cold first use instead (FEATURES; names "
                             "by any part, default all)")
    parser.add_argument("--shared", action="store_true",
                        help="with --features: one numba cache for all the features, in "
                             "order (what each one's first use adds after the ones before)")
    args = parser.parse_args(argv)
    if args.features is not None:
        rows = measure_features(os.path.abspath(args.source), args.features,
                                max(args.warm, 1), args.shared)
        print(f"{os.cpu_count()} cores, Python {sys.version.split()[0]}, "
              f"source {os.path.abspath(args.source)}\n")
        print("| feature (first use) | kernels | cold wall (s) | cold CPU (s) | warm CPU (s) |")
        print("|---|---:|---:|---:|---:|")
        for name, (k, cw, cc, ww, wc) in rows.items():
            print(f"| {name} | {k} | {cw:.1f} | {cc:.1f} | {wc:.1f} |")
        return
    rows = measure(os.path.abspath(args.source), args.warm, args.cold, args.imports)
    print(f"{os.cpu_count()} cores, Python {sys.version.split()[0]}, "
          f"source {os.path.abspath(args.source)}\n")
    print("| what | runs | wall (median, s) | CPU (median, s) |")
    print("|---|---:|---:|---:|")
    for label, (n, wall, cpu) in rows.items():
        print(f"| {label} | {n} | {wall:.2f} | {cpu:.2f} |")


if __name__ == "__main__":
    main()
