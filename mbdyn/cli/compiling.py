"""Saying so when a command compiles the numeric kernels (issue 27, item 1).

A command's first use of a kernel on a machine compiles it with numba (seconds to a
minute); later uses load it from numba's on-disk cache.  A command says so once, on
stderr, before the silent wait::

    mbdyn: compiling the numeric kernels for this machine, once: ~20 s (later runs load them
    from the cache; `mbdyn warmup` compiles them all ahead of time)

and, on a terminal, shows which kernel it is compiling and for how long, then how long it
took in all.  Two parts: the notice must come within a second of the command's start, and
the first compile begins after the imports and the model's reading (1.5 s on 2 busy cores):

* ``announce_if_cold(command, argv)``, before anything heavy is imported: looks for the
  cache index files (``*.nbi``) of the kernels the command always calls (``CORE``) where
  numba keeps them (``cache_dir``), without importing numba, and checks that each index
  is of the installed numba and of the current source (its SHA-256, which numba stores in
  the index, and the hash of every kernel module the entry is stamped with besides,
  ``kernels.cache``); for a command that simulates, also those of the integrator it will use
  (``--integrator``, or the model file's, read with ``tomllib``).  One missing: the
  notice, with an estimate from ``SECONDS``.
* ``Watch``, a listener on numba's ``numba:compile`` events for the rest of the command:
  exact (sent on a compile, never on a cache hit; also by ``kernels.c_function``): a kernel
  outside ``CORE`` or of a new argument type still gets the notice when its compile begins.

``MBDYN_COMPILE_NOTICE=0`` turns both off (the test suite does, except in the tests of the
notice itself).
"""
from __future__ import annotations

import hashlib
import os
import sys
import threading
import time
from pathlib import Path

PACKAGE = Path(__file__).resolve().parent.parent

#: the entry points (compiled from Python) every command that reads a model calls, as
#: ``(kernels module, qualname)``: the check of the model's inertia and the mass matrix's
#: condition (measured with numba's compile events)
CORE = (("evaluate", "kinematics_and_loads"), ("dynamics", "jourdain_terms"),
        ("dynamics", "cholesky_solve"))
#: the commands that call ``CORE``, and those of them that simulate (their integrator's
#: kernels are checked too, ``INTEGRATOR_KERNELS``)
COMPILING = ("run", "info", "accuracy", "equilibrium", "modes", "campbell", "plot",
             "animate", "sweep")
SIMULATING = ("run", "accuracy", "plot", "animate", "sweep")
_ADAPTIVE = (("adaptive", "stage"), ("adaptive", "rk_stretch"))
#: the entry points an integrator adds (a model's first run with it)
INTEGRATOR_KERNELS = {
    "DOP853": _ADAPTIVE, "RK45": _ADAPTIVE,
    "semi-implicit-euler": (("integrators", "semi_implicit_euler_loop"),),
    "euler": (("integrators", "euler_loop"),), "rk4": (("integrators", "rk4_loop"),),
    "implicit-midpoint": (("integrators", "implicit_midpoint_loop"),),
}
#: the entry points a model's features add, when its file shows them (``features_of``): a
#: closed loop (a joint with ``cut = true``), force elements (``[[forces]]``)
FEATURE_KERNELS = {
    "closed loop": (("constrained", "constraint_state"), ("constrained", "project_state_call")),
    "force elements": (("forces", "force_elements"),),
}
#: cold compile of each entry point with everything below it, CPU seconds on a 2-core
#: machine (numba 0.68; ``benchmarks/compile_events.py``, docs/performance.md): the
#: estimate's source.  Others count ``OTHER`` seconds.  A closed loop's two count its
#: route's function too (``kernels.route_entry``: the loops and stages are the tree's, its
#: multipliers for the reactions go through the function), a four-bar's first run after a
#: tree's: 27 s; only kernels every closed loop's run compiles are looked for, or a warm
#: run would be told it compiles; force elements count their function.  The C functions
#: (``kernels.c_function``) by shown name, with all they call, for when one comes first
SECONDS = {"kinematics_and_loads": 2.6, "jourdain_terms": 1.3, "cholesky_solve": 0.8,
           "stage": 2.7, "rk_stretch": 3.2, "implicit_midpoint_loop": 6.6,
           "semi_implicit_euler_loop": 3.1, "euler_loop": 3.0, "rk4_loop": 3.9,
           "constraint_state": 7.0, "project_state_call": 20.0, "force_elements": 5.0,
           "route_entry._articulated": 17.0, "route_entry._closed": 27.0,
           "route_entry._articulated_closed": 27.0, "force_function._plain": 13.0,
           "force_function._shapes": 13.0}
OTHER = 5.0
#: what a simulation compiles besides its integrator (the reactions' Newton-Euler system,
#: the energies, the drives' programs)
RUN_EXTRA = 1.0

_STATE = {"announced": False, "estimate": None}
_LOCK = threading.Lock()


def enabled():
    return os.environ.get("MBDYN_COMPILE_NOTICE", "1").strip() not in ("0", "no", "off",
                                                                        "false")


def cache_dir(source):
    """Where numba keeps the cache of the functions of the file ``source``, by numba's
    own rules (``numba.core.caching``): ``NUMBA_CACHE_DIR/<dir>_<sha1 of the dir>`` when
    that variable is set, else ``__pycache__`` beside the file when it can be written,
    else the user's cache folder.  ``None`` when numba's locators are replaced
    (``NUMBA_CACHE_LOCATOR_CLASSES``) or caching is off (``NUMBA_DISABLE_JIT``)."""
    if os.environ.get("NUMBA_CACHE_LOCATOR_CLASSES") or os.environ.get("NUMBA_DISABLE_JIT",
                                                                       "0") != "0":
        return None
    folder = os.path.dirname(os.path.abspath(source))
    sub = os.path.basename(folder) + "_" + hashlib.sha1(folder.encode()).hexdigest()
    if os.environ.get("NUMBA_CACHE_DIR"):
        return os.path.join(os.environ["NUMBA_CACHE_DIR"], sub)
    in_tree = os.path.join(folder, "__pycache__")
    if os.access(in_tree if os.path.isdir(in_tree) else folder, os.W_OK):
        return in_tree
    if sys.platform == "darwin":
        base = os.path.expanduser("~/Library/Caches")
    else:
        base = os.environ.get("XDG_CACHE_HOME") or os.path.expanduser("~/.cache")
    return os.path.join(base, "numba", sub)


def _numba_version():
    from importlib.metadata import PackageNotFoundError, version
    try:
        return version("numba")
    except PackageNotFoundError:
        return None


def kernels_fingerprint():
    """``kernels.cache.fingerprint()``, which every kernel's cache entry is stamped with
    besides its own file's hash, computed here without importing the kernels (whose
    package imports numba): the same hash of every module of ``mbdyn/kernels``
    (tests/test_kernel_cache.py holds the two equal)."""
    if "fingerprint" not in _STATE:
        digest = hashlib.sha256()
        folder = PACKAGE / "kernels"
        for name in sorted(os.listdir(folder)):
            if name.endswith(".py"):
                digest.update(name.encode() + b"\0" + (folder / name).read_bytes() + b"\0")
        _STATE["fingerprint"] = digest.hexdigest()
    return _STATE["fingerprint"]


def is_cached(module, qualname, numba_version=None):
    """Whether numba's cache holds ``mbdyn.kernels.<module>.<qualname>`` compiled from
    the current source by the installed numba (for some argument types)."""
    import pickle
    source = PACKAGE / "kernels" / f"{module}.py"
    folder = cache_dir(source)
    if folder is None or not os.path.isdir(folder):
        return False
    digest = hashlib.sha256(source.read_bytes()).digest()
    sources = kernels_fingerprint().encode()
    numba_version = numba_version or _numba_version()
    tag = f"py{sys.version_info.major}{sys.version_info.minor}"
    for name in os.listdir(folder):
        if not (name.startswith(f"{module}.{qualname}-") and name.endswith(".nbi")
                and tag in name):
            continue
        try:
            with open(os.path.join(folder, name), "rb") as f:
                if pickle.load(f) != numba_version:
                    continue
                stamp = f.read()
                if digest in stamp and sources in stamp:
                    return True
        except (OSError, pickle.UnpicklingError, EOFError, ValueError):
            continue
    return False


def missing(entries=CORE):
    """The entry points of ``entries`` (``(module, qualname)`` pairs) not in the cache."""
    version = _numba_version()
    return [q for m, q in entries if not is_cached(m, q, version)]


def announce(seconds, stream=None):
    """The notice, once per process; returns whether it was written now."""
    with _LOCK:
        if _STATE["announced"]:
            return False
        _STATE["announced"] = True
        _STATE["estimate"] = max(1, round(seconds))
    stream = stream or sys.stderr
    stream.write(f"mbdyn: compiling the numeric kernels for this machine, once: "
                 f"~{max(1, round(seconds))} s (later runs load them from the cache; "
                 "`mbdyn warmup` compiles them all ahead of time)\n")
    stream.flush()
    return True


def _option(words, flag):
    for k, w in enumerate(words):
        if w == flag and k + 1 < len(words):
            return words[k + 1]
        if w.startswith(flag + "="):
            return w.split("=", 1)[1]
    return None


def _read_toml(model):
    """The model file as TOML data, or ``None`` (not TOML, unreadable, over 1 MB)."""
    import tomllib
    try:
        if os.path.getsize(model) > 1_000_000:
            return None
        with open(model, "rb") as f:
            return tomllib.load(f)
    except (OSError, ValueError):
        return None


def _case_table(data, words):
    """The table of the case the command line runs (``--case``, else the file's default),
    or ``{}``: read as the loader would, without its checks (a malformed file is its to
    refuse, with a message)."""
    model, cases = data.get("model", {}), data.get("cases", {})
    case = _option(words, "--case") or (model.get("default_case")
                                        if isinstance(model, dict) else None)
    if isinstance(case, str) and isinstance(cases, dict) and isinstance(cases.get(case), dict):
        return cases[case]
    return {}


def integrator_of(model, words, data=None):
    """The integrator a command line runs ``model`` with, read without the model's
    loader: ``--integrator``, else the case's or the file's ``[simulation] integrator``,
    else the default DOP853; ``None`` if the file cannot be read as TOML here."""
    chosen = _option(words, "--integrator")
    if chosen:
        return chosen
    data = _read_toml(model) if data is None else data
    if not isinstance(data, dict):
        return None
    for table in (_case_table(data, words), data):
        simulation = table.get("simulation", {})
        value = simulation.get("integrator") if isinstance(simulation, dict) else None
        if isinstance(value, str):
            return value
    return "DOP853"


def _elements(data, case, key):
    """The array ``key`` (joints, forces) of the model a case makes: the case's list
    replaces the file's, its table of elements by name amends or extends it, as
    ``io.cases.apply_case`` merges them (not called: importing ``mbdyn.io`` takes a second,
    which the notice cannot wait, and it records where each value came from)."""
    base = data.get(key, [])
    out = [dict(e) for e in base if isinstance(e, dict)] if isinstance(base, list) else []
    value = case.get(key)
    if isinstance(value, list):
        return [e for e in value if isinstance(e, dict)]
    if isinstance(value, dict):
        for name, partial in value.items():
            if not isinstance(partial, dict):
                continue
            for element in out:
                if element.get("name") == name:
                    element.update(partial)
                    break
            else:
                out.append(dict(partial, name=name))
    return out


def features_of(data, words=()):
    """The features of ``FEATURE_KERNELS`` the model a command line runs surely has, read
    from its file's TOML data and the case run: a joint with ``cut = true`` (a closed loop);
    force elements, unless effects are switched (``--effects``, an ``[effects]`` table:
    they may switch the elements off, and a kernel counted but never compiled would give
    the notice on every run)."""
    found = set()
    if not isinstance(data, dict):
        return found
    case = _case_table(data, words)
    if any(j.get("cut") is True for j in _elements(data, case, "joints")):
        found.add("closed loop")
    switched = (_option(words, "--effects") is not None or "effects" in data
                or "effects" in case)
    if _elements(data, case, "forces") and not switched:
        found.add("force elements")
    return found


def announce_if_cold(command, argv):
    """Before a command that compiles (``COMPILING``) is even parsed (the parser imports
    its layers, a second): the notice if one of the ``CORE`` kernels, or of the kernels of
    the integrator a simulating command will use, is not cached.  Nothing for help, nor
    when the word after the command (the model file) is not a file (a mistyped path fails
    at once; a model named after options is left to ``Watch``)."""
    if command not in COMPILING or not enabled() or _STATE["announced"]:
        return False
    words = list(argv)
    rest = words[words.index(command) + 1:]
    if any(w in ("-h", "--help", "--version") for w in words) or not rest or not \
            os.path.isfile(rest[0]):
        return False
    entries = CORE
    data = _read_toml(rest[0])
    if command in SIMULATING:
        entries += INTEGRATOR_KERNELS.get(integrator_of(rest[0], rest, data), ())
        for feature in sorted(features_of(data, rest)):
            entries += FEATURE_KERNELS[feature]
    cold = missing(entries)
    if not cold:
        return False
    extra = RUN_EXTRA if command in SIMULATING else 0.0
    return announce(sum(SECONDS.get(q, OTHER) for q in cold) + extra)


class Watch:
    """A listener on numba's compile events for one command: the notice when a compile
    begins (if not given yet), on a terminal a line that shows the kernel and the time
    spent, rewritten in place; ``close()`` says what it compiled and how long it took.
    ``compiled``: ``[(entry point, seconds)]`` of the kernels compiled from Python."""

    def __init__(self, stream=None, notice=True, live=None):
        self.stream = stream or sys.stderr
        self.notice = notice
        isatty = getattr(self.stream, "isatty", lambda: False)
        self.live = isatty() if live is None else live
        self.depth, self.current, self.began = 0, None, None
        self.compiled = []
        self._ticker = None
        self._shown = False
        self._listener = None

    def __enter__(self):
        from numba.core import event

        watch = self

        class Listener(event.Listener):
            def on_start(self, ev):
                made = ev.data["dispatcher"]    # c_function's: named with its module
                watch._start(getattr(made, "shown_name", None) or made.py_func.__qualname__)

            def on_end(self, ev):
                watch._end()
        self._listener = Listener()
        event.register("numba:compile", self._listener)
        return self

    def __exit__(self, *exc):
        from numba.core import event
        event.unregister("numba:compile", self._listener)
        self._clear()

    def _start(self, name):
        self.depth += 1
        if self.depth > 1:
            return
        if self.notice and enabled():
            announce(SECONDS.get(name, OTHER) + RUN_EXTRA, self.stream)
        with _LOCK:
            self.current, self.began = name, time.perf_counter()
        if self.live and self.notice and enabled() and self._ticker is None:
            self._ticker = threading.Thread(target=self._tick, daemon=True)
            self._ticker.start()

    def _end(self):
        self.depth -= 1
        if self.depth:
            return
        with _LOCK:
            self.compiled.append((self.current, time.perf_counter() - self.began))
            self.current = None
            self._clear_locked()

    def _tick(self):
        while True:
            time.sleep(0.25)
            with _LOCK:
                if self._ticker is None:
                    return
                if self.current is None:
                    continue
                spent = sum(s for _, s in self.compiled) + time.perf_counter() - self.began
                of = f" of ~{_STATE['estimate']} s" if (_STATE["estimate"] or 0) > spent \
                    else ""
                self.stream.write(f"\rmbdyn: compiling {self.current}: {spent:.0f} s so "
                                  f"far{of} ({len(self.compiled)} kernels done)\x1b[K")
                self.stream.flush()
                self._shown = True

    def _clear_locked(self):
        if self._shown:
            self.stream.write("\r\x1b[K")
            self.stream.flush()
            self._shown = False

    def _clear(self):
        with _LOCK:
            self._ticker = None
            self._clear_locked()

    def close(self):
        """The closing line after a command that compiled (nothing otherwise)."""
        if not self.compiled or not (self.notice and enabled()):
            return
        total = sum(s for _, s in self.compiled)
        self.stream.write(f"mbdyn: compiled {len(self.compiled)} kernels in {total:.0f} s; "
                          "they are cached for the next runs\n")
        self.stream.flush()
