#!/usr/bin/env python
"""Cost of one forward-dynamics evaluation, and of compiling the kernels.

    python benchmarks/forward_dynamics.py            # full run (about 2-3 minutes)
    python benchmarks/forward_dynamics.py --quick    # fewer sizes and repeats
    python benchmarks/forward_dynamics.py --json     # machine-readable output on stdout
    python benchmarks/forward_dynamics.py --steps    # also time each compiled step
    python benchmarks/forward_dynamics.py --help     # sizes, budget, repeats, skips

Most of a run is the cold compile probe (half a minute to a minute and a half); add
``--no-compile`` to skip it.

What it measures
----------------
* ``Model.forward_dynamics(q, u, t, method=...)`` for ``"jourdain"`` and ``"newton-euler"``
  on chains of n = 2, 5, 10, 20, 50 bodies joined by (a) revolute joints with alternating
  x / y axes (a 3D chain) and (b) spherical joints; the ratio newton-euler / jourdain taken
  round by round in the same run; ``Model.mass_matrix(q)``.
* The raw compiled kernels (``mbdyn.kernels.packed.jourdain_accelerations_packed`` and
  ``newton_euler_solution_packed``) called with the model's own packed arrays, so that
  ``method - raw`` is the Python overhead of the ``Model`` layer; and a do-nothing numba
  function taking the same arguments, which is the cost of numba's dispatch (type matching
  and unboxing of every argument) inside the raw call.
* For small models, a breakdown of one Jourdain call: the kernel's own compute time (the
  kernel called in a loop from inside compiled code, no dispatch), numba's dispatch, and
  the Python layer -- ``Model.forward_dynamics`` timed with the kernel swapped (during
  those blocks only) for the do-nothing function -- split into the ``Model`` helpers one
  call actually runs (``HELPERS``: found by wrapping them for one call)
  and the rest.
* With ``--steps``: the compute time of each compiled step (kinematics and loads; ``M``
  and ``f``; Cholesky; the Newton-Euler assembly; its LU solve) for every size.
* The kernels' numba compile time, "cold" (a subprocess with ``NUMBA_CACHE_DIR`` set to a
  fresh temporary directory imports mbdyn, compiles a small model and calls both
  formulations once) and "cached" (a second subprocess with the same directory).

How it measures
---------------
``time.perf_counter`` around blocks of calls; each block is sized so that a measurement
(all its repeats) takes about ``--budget`` seconds; the quantities of one model are
measured interleaved, round by round (so that a burst of load from another process hits
them all alike), after warm-up calls, with the garbage collector off.  Reported: the
median over the rounds and the interquartile range (the JSON also has min, max and the
thread CPU time, whose ratio to the wall time shows whether the process was kept waiting
for a CPU).  The BLAS and OpenMP thread pools are pinned to one thread before numpy is
imported.

The raw-kernel and breakdown columns call private attributes of ``Model`` in the same way
``Model.forward_dynamics`` does; if the engine's internals change so that this no longer
works, those columns are left out (with a note) and the rest still runs.
"""
import os

for _var in ("OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "OMP_NUM_THREADS",
             "NUMEXPR_NUM_THREADS", "VECLIB_MAXIMUM_THREADS", "BLIS_NUM_THREADS"):
    os.environ[_var] = "1"

import argparse  # noqa: E402
import contextlib  # noqa: E402
import gc  # noqa: E402
import json  # noqa: E402
import platform  # noqa: E402
import subprocess  # noqa: E402
import sys  # noqa: E402
import tempfile  # noqa: E402
import textwrap  # noqa: E402
import time  # noqa: E402
from time import perf_counter, thread_time  # noqa: E402

import numpy as np  # noqa: E402

SIZES = (2, 5, 10, 20, 50)
QUICK_SIZES = (2, 10, 50)
JOINTS = ("revolute", "spherical")
METHODS = ("jourdain", "newton-euler")
NOTE = ("The machine may be shared and noisy (other processes running): every figure is the "
        "median over interleaved rounds; the spread is the interquartile range (iqr).  "
        "Compare ratios measured in the same run rather than absolute times across runs.")


def log(*args):
    print(*args, file=sys.stderr, flush=True)


# ----------------------------------------------------------------------------- models
def random_rotation(rng):
    """A seeded random proper rotation (QR of a Gaussian matrix)."""
    Q, R = np.linalg.qr(rng.normal(size=(3, 3)))
    Q = Q * np.sign(np.diag(R))
    if np.linalg.det(Q) < 0:
        Q[:, 0] = -Q[:, 0]
    return Q


def build_chain(mb, n, joint, seed=2024):
    """A chain of ``n`` links hanging from the ground: links of length ~0.3 along the body
    ``-z`` axis, seeded random masses, centres of mass and (full, rotated box) inertia
    tensors; revolute axes alternate x and y."""
    rng = np.random.default_rng([seed, n, JOINTS.index(joint)])
    s = mb.System(f"{joint} chain of {n}")
    parent, offset = "ground", 0.0
    for i in range(n):
        length = rng.uniform(0.25, 0.35)
        mass = rng.uniform(0.5, 2.0)
        box = mb.inertia.box(mass, rng.uniform(0.02, 0.06), rng.uniform(0.02, 0.06), length)
        Q = random_rotation(rng) if i % 2 else np.eye(3)
        inertia = Q @ box @ Q.T
        inertia = 0.5 * (inertia + inertia.T)
        com = (rng.uniform(-0.01, 0.01), rng.uniform(-0.01, 0.01),
               -0.5 * length + rng.uniform(-0.02, 0.02))
        body = f"link{i}"
        s.add_body(body, mass=mass, com=com, inertia=inertia)
        extra = {"axis": "xy"[i % 2]} if joint == "revolute" else {}
        s.add_joint(f"j{i}", joint, parent, body, position=(0.0, 0.0, -offset), **extra)
        parent, offset = body, length
    model = s.compile()
    q = model.default_coordinates()
    if joint == "revolute":
        q = rng.uniform(-1.0, 1.0, model.nq)
    else:
        for k in range(0, model.nq, 4):
            quat = rng.normal(size=4)
            q[k:k + 4] = quat / np.linalg.norm(quat)
    u = rng.uniform(-1.0, 1.0, model.nu)
    return model, q, u


# ----------------------------------------------------------------------------- timing
def _block(fn, args, kwargs, number):
    """Wall (perf_counter) and thread CPU time of ``number`` calls."""
    c0 = thread_time()
    t0 = perf_counter()
    for _ in range(number):
        fn(*args, **kwargs)
    t1 = perf_counter()
    return t1 - t0, thread_time() - c0


def calibrate(fn, args, kwargs, block_target):
    """Warm up, then the number of calls per block so that a block lasts ``block_target``."""
    for _ in range(3):
        fn(*args, **kwargs)
    number = 1
    while True:
        dt, _ = _block(fn, args, kwargs, number)
        if dt >= 0.005 or number >= 1 << 20:
            break
        number *= 4
    per_call = dt / number
    return max(1, int(round(block_target / per_call))), per_call


def stats(samples, cpu):
    a = np.asarray(samples) * 1e6
    q1, med, q3 = np.percentile(a, [25, 50, 75])
    return {"median_us": float(med), "q1_us": float(q1), "q3_us": float(q3),
            "iqr_us": float(q3 - q1), "min_us": float(a.min()), "max_us": float(a.max()),
            "cpu_median_us": float(np.median(cpu) * 1e6), "rounds": int(a.size)}


def measure(cases, budget, repeats, ratios=()):
    """Time every case of ``cases`` ``{key: (fn, args, kwargs, calls_per_invocation[,
    context])}`` interleaved over ``repeats`` rounds (``context()``, a context manager, is
    entered around each block of the case).  Each measurement takes about ``budget`` seconds.

    Returns ``{key: stats}`` (seconds per call -> microseconds) and ``{(a, b): ratio stats}``
    of the per-round ratios ``a / b``.
    """
    block_target = budget / repeats
    plan = {}
    for key, (fn, args, kwargs, per, *ctx) in cases.items():
        ctx = ctx[0] if ctx else contextlib.nullcontext
        with ctx():
            number, _ = calibrate(fn, args, kwargs, block_target)
        plan[key] = (fn, args, kwargs, number, per, ctx)
    samples = {key: [] for key in plan}
    cpu = {key: [] for key in plan}
    keys = list(plan)
    gc.collect()
    gc.disable()
    try:
        for r in range(repeats):
            order = keys[r % len(keys):] + keys[:r % len(keys)]   # rotate: no position bias
            for key in order:
                fn, args, kwargs, number, per, ctx = plan[key]
                with ctx():
                    wall, cput = _block(fn, args, kwargs, number)
                samples[key].append(wall / (number * per))
                cpu[key].append(cput / (number * per))
    finally:
        gc.enable()
    out = {key: dict(stats(samples[key], cpu[key]), calls_per_round=plan[key][3] * plan[key][4])
           for key in plan}
    ratio_out = {}
    for a, b in ratios:
        if a in samples and b in samples:
            rr = np.asarray(samples[a]) / np.asarray(samples[b])
            q1, med, q3 = np.percentile(rr, [25, 50, 75])
            ratio_out[(a, b)] = {"median": float(med), "q1": float(q1), "q3": float(q3)}
    return out, ratio_out


# ----------------------------------------------------------------------------- raw kernels
def packed_args(model, q, u):
    """The arguments ``Model.forward_dynamics`` passes to the packed Jourdain kernel: the
    float buffer, the integer buffer (its head the offset table), the force table or None
    (``mbdyn.kernels.packed``), q, u."""
    return (*model._dynamics_full, np.asarray(q, float), np.asarray(u, float))


_PACKED = {}


def packed_helpers(kernel):
    """``nop(fb, ib, forces, q, u)``: zeroes the packed ``ud`` and returns -1 at once (its
    call cost is numba's dispatch for the five arguments); ``loop(count, fb, ib, forces,
    q, u)``:
    calls ``kernel`` ``count`` times from compiled code (its compute time without
    dispatch)."""
    if kernel not in _PACKED:
        from numba import njit
        from mbdyn.kernels import packed as kp
        UD = kp.UD

        @njit
        def nop(fb, ib, forces, q, u):
            fb[ib[UD]:ib[UD] + ib[1]] = 0.0
            return -1

        loop = None
        if kernel is not None:
            @njit
            def loop(count, fb, ib, forces, q, u):
                for _ in range(count):
                    kernel(fb, ib, forces, q, u)      # writes its outputs: not elided
                return count
        _PACKED[kernel] = (nop, loop)
    return _PACKED[kernel]


_GENERATED = {}


def generated_kernels(nargs, kernel):
    """Two compiled helpers with ``nargs`` arguments: ``nop`` (zeroes its last argument,
    the output ``ud`` of the Jourdain kernel, and returns -1 at once: its call cost is
    numba's dispatch) and ``loop(count, *args)`` (calls ``kernel`` ``count`` times from
    compiled code: the kernel's compute time without dispatch)."""
    key = (nargs, kernel)
    if key not in _GENERATED:
        from numba import njit
        names = ", ".join(f"a{k}" for k in range(nargs))
        src = textwrap.dedent(f"""
            def nop({names}):
                a{nargs - 1}[:] = 0.0
                return -1

            def loop(count, {names}):
                for _ in range(count):
                    kernel({names})    # writes its outputs: the call cannot be elided
                return count
            """)
        ns = {"kernel": kernel}
        exec(src, ns)  # noqa: S102 -- generated from an integer only
        _GENERATED[key] = (njit(ns["nop"]), njit(ns["loop"]) if kernel is not None else None)
    return _GENERATED[key]


def subkernel_cases(model, q, u, ke):
    """``{name: (kernel, args)}`` of the compiled steps inside the two fused kernels
    (mirrors mbdyn/kernels/evaluate.py), each to be called from compiled code."""
    from numba import njit
    from mbdyn.kernels import dynamics as kd
    m = model
    global _SOLVE
    if _SOLVE is None:
        @njit
        def solve(A, b):
            return np.linalg.solve(A, b)
        _SOLVE = solve
    m._dense_system()                   # (allocates the full Jacobians and M too)
    m._fill(q, u, 0.0)
    ud = np.empty(m.nu)
    kin = (*m._tree, m._mass, m._com, m.gravity, m._qfull, m._ufull, m._udfull,
           *m._loads_arrays, *m._kin_out, m._scratch)
    jd = (m._mass, m._com, m._inertia, m._has_inertia, m._R, m._r, m._w, m._alpha, m._a,
          m._JR, m._JT, m._anc_ptr, m._anc_idx, m._parent, m._F, m._N, m._M, m._f)
    ch = (m._M, m._f, m._L, ud)
    nes = (m._mass, m._com, m._inertia, m._parent, m._R, m._r, m._w, m._alpha, m._a, m._JR,
           m._JT, m._anc_ptr, m._anc_idx, m._F, m._N, m._react_joint, m._react_force,
           m._react_moment, m._A, m._b, m._scratch)
    ke.kinematics_and_loads(*kin)       # leave every workspace as one evaluation does
    kd.jourdain(*jd)
    kd.cholesky_solve(*ch)
    kd.newton_euler_system(*nes)
    return {"kinematics_and_loads": (ke.kinematics_and_loads, kin),
            "jourdain (M, f)": (kd.jourdain, jd),
            "cholesky_solve": (kd.cholesky_solve, ch),
            "newton_euler_system (A, b)": (kd.newton_euler_system, nes),
            "np.linalg.solve(A, b)": (_SOLVE, (m._A, m._b))}


_SOLVE = None


class Raw:
    """Raw-kernel access to a model; ``ok`` False (with ``why``) if the internals moved."""

    def __init__(self, model, q, u, kp):
        self.ok, self.why = False, ""
        try:
            model._fill(q, u, 0.0)
            self.jargs = packed_args(model, q, u)
            self.ud = model._ud
            self.prebuilt = True
            self.neargs = (*model._packed, *self.jargs[-2:]) + tuple(model._dense_system())
            self.jk = kp.jourdain_accelerations_packed
            self.nek = kp.newton_euler_solution_packed
            ref = model.forward_dynamics(q, u, 0.0, method="jourdain")
            model._fill(q, u, 0.0)
            pivot = self.jk(*self.jargs)
            x, _ = self.nek(*self.neargs)
            scale = max(np.abs(ref).max(), 1.0)
            if pivot >= 0 or np.abs(self.ud - ref).max() > 1e-9 * scale \
                    or np.abs(x[:model.nu] - ref).max() > 1e-6 * scale:
                raise RuntimeError("the raw kernels do not reproduce Model.forward_dynamics")
            self.ok = True
        except Exception as exc:            # noqa: BLE001 -- report and carry on
            self.why = f"{type(exc).__name__}: {exc}"


# ----------------------------------------------------------------------------- compile time
COMPILE_PROBE = r"""
import os, sys, json, time
t0 = time.perf_counter()
import numpy as np, numba
t1 = time.perf_counter()
import mbdyn as mb
t2 = time.perf_counter()
s = mb.System("probe")
s.add_body("a", mass=1.0, com=(0, 0, -0.15), inertia=(0.01, 0.01, 0.002))
s.add_joint("j0", "revolute", "ground", "a", axis="x")
s.add_body("b", mass=1.0, com=(0, 0, -0.15), inertia=(0.01, 0.012, 0.003))
s.add_joint("j1", "spherical", "a", "b", position=(0, 0, -0.3))
model = s.compile()          # checks the inertia of every dof: mass_matrix + jourdain
t3 = time.perf_counter()
q = model.default_coordinates() + 0.1
model.normalize_quaternions(q)
u = np.full(model.nu, 0.2)
model.forward_dynamics(q, u, 0.0, method="jourdain")
t4 = time.perf_counter()
model.forward_dynamics(q, u, 0.0, method="newton-euler")
t5 = time.perf_counter()
model.coordinate_rates(q, u)
t6 = time.perf_counter()
from numba.core.registry import CPUDispatcher
seen, hits, misses = set(), 0, 0
for name, mod in list(sys.modules.items()):
    if name.startswith("mbdyn"):
        for obj in list(vars(mod).values()):
            if isinstance(obj, CPUDispatcher) and id(obj) not in seen:
                seen.add(id(obj))
                hits += sum(obj.stats.cache_hits.values())
                misses += sum(obj.stats.cache_misses.values())
print(json.dumps({"numba_cache_hits": hits, "numba_cache_misses": misses,"import_numpy_numba_s": t1 - t0, "import_mbdyn_s": t2 - t1,
                  "build_and_compile_model_s": t3 - t2, "first_jourdain_s": t4 - t3,
                  "first_newton_euler_s": t5 - t4, "first_coordinate_rates_s": t6 - t5,
                  "in_process_total_s": t6 - t0}))
"""


def kernel_sources_digest():
    """A digest of the compiled-kernel sources, to notice edits made during the probes."""
    import hashlib
    import mbdyn.kernels
    h = hashlib.sha256()
    folder = os.path.dirname(mbdyn.kernels.__file__)
    for name in sorted(os.listdir(folder)):
        if name.endswith(".py"):
            with open(os.path.join(folder, name), "rb") as fh:
                h.update(name.encode() + fh.read())
    return h.hexdigest()[:12]


def compile_times():
    """Run the probe twice in subprocesses sharing a fresh NUMBA_CACHE_DIR."""
    out = {"kernel_sources_before": kernel_sources_digest()}
    with tempfile.TemporaryDirectory(prefix="mbdyn-numba-cache-") as cache:
        env = dict(os.environ, NUMBA_CACHE_DIR=cache)
        env.pop("NUMBA_DISABLE_JIT", None)
        for label in ("cold", "cached"):
            log(f"  compile probe: {label} ...")
            t0 = perf_counter()
            proc = subprocess.run([sys.executable, "-c", COMPILE_PROBE], env=env,
                                  capture_output=True, text=True, timeout=900)
            wall = perf_counter() - t0
            if proc.returncode != 0:
                out[label] = {"error": proc.stderr.strip().splitlines()[-1:]}
                continue
            rec = json.loads(proc.stdout.strip().splitlines()[-1])
            rec["subprocess_wall_s"] = wall
            rec["cache_index_files"] = sum(f.endswith(".nbi") for _, _, fs in os.walk(cache)
                                           for f in fs)
            out[label] = rec
    out["kernel_sources_after"] = kernel_sources_digest()
    out["sources_changed_during_probe"] = (out["kernel_sources_before"]
                                           != out["kernel_sources_after"])
    return out


# ----------------------------------------------------------------------------- machine
def source_info(mbdyn):
    """Commit of the mbdyn sources and whether they differ from it (read-only git calls)."""
    root = os.path.dirname(os.path.dirname(os.path.abspath(mbdyn.__file__)))
    try:
        head = subprocess.run(["git", "rev-parse", "--short", "HEAD"], cwd=root, text=True,
                              capture_output=True, timeout=10).stdout.strip()
        dirty = subprocess.run(["git", "status", "--porcelain", "--", "mbdyn"], cwd=root,
                               text=True, capture_output=True, timeout=10).stdout.strip()
    except (OSError, subprocess.SubprocessError):
        return {"path": root, "commit": None, "modified": None}
    return {"path": root, "commit": head or None,
            "modified": bool(dirty) if head else None}


def machine_info():
    import numba
    import scipy
    import mbdyn
    cpu = platform.processor() or ""
    try:
        with open("/proc/cpuinfo") as fh:
            for line in fh:
                if line.startswith("model name"):
                    cpu = line.split(":", 1)[1].strip()
                    break
    except OSError:
        pass
    try:
        usable = len(os.sched_getaffinity(0))
    except AttributeError:
        usable = os.cpu_count()
    try:
        load = [round(x, 2) for x in os.getloadavg()]
    except OSError:
        load = None
    return {"source": source_info(mbdyn),
            "python": platform.python_version(), "implementation": platform.python_implementation(),
            "numpy": np.__version__, "numba": numba.__version__, "scipy": scipy.__version__,
            "mbdyn": getattr(mbdyn, "__version__", "?"), "platform": platform.platform(),
            "cpu": cpu, "cpu_count": os.cpu_count(), "cpus_usable": usable,
            "load_average_start": load,
            "threads": {v: os.environ.get(v) for v in ("OPENBLAS_NUM_THREADS",
                                                         "MKL_NUM_THREADS", "OMP_NUM_THREADS")},
            "date": time.strftime("%Y-%m-%d %H:%M:%S")}


# ----------------------------------------------------------------------------- main runs
def run_table(mb, kp, sizes, budget, repeats):
    rows = []
    for joint in JOINTS:
        for n in sizes:
            log(f"  {joint} chain, n={n} ...")
            model, q, u = build_chain(mb, n, joint)
            raw = Raw(model, q, u, kp)
            fd = model.forward_dynamics
            cases = {"jourdain": (fd, (q, u, 0.0), {"method": "jourdain"}, 1),
                     "newton-euler": (fd, (q, u, 0.0), {"method": "newton-euler"}, 1),
                     "mass_matrix": (model.mass_matrix, (q,), {}, 1)}
            if raw.ok:
                nop, _ = packed_helpers(None)
                cases["jourdain_raw"] = (raw.jk, raw.jargs, {}, 1)
                cases["newton-euler_raw"] = (raw.nek, raw.neargs, {}, 1)
                cases["dispatch"] = (nop, raw.jargs, {}, 1)
            res, ratios = measure(cases, budget, repeats,
                                  ratios=[("newton-euler", "jourdain"),
                                          ("jourdain_raw", "jourdain"),
                                          ("newton-euler_raw", "newton-euler")])
            a = fd(q, u, 0.0, method="jourdain")
            b = fd(q, u, 0.0, method="newton-euler")
            agree = float(np.abs(a - b).max() / max(np.abs(a).max(), 1e-300))
            row = {"joint": joint, "n": n, "nu": model.nu, "times": res,
                   "ratio_ne_over_j": ratios[("newton-euler", "jourdain")],
                   "max_rel_difference": agree, "raw_available": raw.ok}
            if not raw.ok:
                row["raw_unavailable_because"] = raw.why
            rows.append(row)
    return rows


def run_subkernels(mb, ke, sizes, budget, repeats):
    """Compute time of each compiled step, called from compiled code (no dispatch)."""
    rows = []
    for joint in JOINTS:
        for n in sizes:
            log(f"  steps: {joint} chain, n={n} ...")
            model, q, u = build_chain(mb, n, joint)
            try:
                steps = subkernel_cases(model, q, u, ke)
                cases = {}
                for name, (kernel, args) in steps.items():
                    _, loop = generated_kernels(len(args), kernel)
                    loop(1, *args)
                    inner = max(1, min(200, 20000 // (n * n)))
                    cases[name] = (loop, (inner, *args), {}, inner)
            except Exception as exc:        # noqa: BLE001 -- the engine's internals moved
                return {"unavailable": f"{type(exc).__name__}: {str(exc)[:200]}"}
            res, _ = measure(cases, budget, repeats)
            rows.append({"joint": joint, "n": n, "nu": model.nu,
                         "times": {k: v["median_us"] for k, v in res.items()}})
    return rows


HELPERS = ("_fill", "_state", "_fill_inputs", "_check_finite")


def helpers_called(model, q, u):
    """How many times one ``forward_dynamics`` call runs each of the ``Model`` helpers
    in ``HELPERS`` (found by wrapping them on the instance for one call)."""
    called = {}
    wrapped = []
    for name in HELPERS:
        orig = getattr(model, name, None)
        if orig is None or name in vars(model):
            continue

        def wrapper(*args, _orig=orig, _name=name, **kwargs):
            called[_name] = called.get(_name, 0) + 1
            return _orig(*args, **kwargs)
        setattr(model, name, wrapper)
        wrapped.append(name)
    try:
        model.forward_dynamics(q, u, 0.0)
    finally:
        for name in wrapped:
            delattr(model, name)
    return called


def run_breakdown(mb, kp, budget, repeats, with_compute, specs=(("revolute", 2),
                                                                  ("revolute", 5),
                                                                  ("spherical", 2))):
    """Where the time of one small Jourdain call goes.

    ``Model.forward_dynamics`` is also timed with ``kp.jourdain_accelerations_packed`` swapped
    (for the duration of those blocks only) for the do-nothing numba function taking the
    same arguments: that is the engine's Python layer plus numba's dispatch, with no
    compute.  The helpers of ``HELPERS`` that one call runs are timed on their own.
    """
    out = []
    for joint, n in specs:
        log(f"  breakdown: {joint} chain, n={n} ...")
        model, q, u = build_chain(mb, n, joint)
        raw = Raw(model, q, u, kp)
        if not raw.ok:
            return {"unavailable": raw.why}
        nop, loop = packed_helpers(raw.jk if with_compute else None)
        inner = 200
        ud = model.forward_dynamics(q, u, 0.0)
        m = model
        real = kp.jourdain_accelerations_packed

        @contextlib.contextmanager
        def no_kernel():
            kp.jourdain_accelerations_packed = nop
            try:
                yield
            finally:
                kp.jourdain_accelerations_packed = real

        with no_kernel():
            swapped = m.forward_dynamics(q, u, 0.0)
        if np.any(swapped != 0.0) or np.any(m.forward_dynamics(q, u, 0.0) != ud):
            return {"unavailable": "Model.forward_dynamics no longer calls "
                                   "mbdyn.kernels.packed.jourdain_accelerations_packed by "
                                   "its module attribute"}
        called = helpers_called(m, q, u)

        cases = {"method": (m.forward_dynamics, (q, u, 0.0), {}, 1),
                 "method_no_kernel": (m.forward_dynamics, (q, u, 0.0), {}, 1, no_kernel),
                 "raw": (raw.jk, raw.jargs, {}, 1),
                 "dispatch": (nop, raw.jargs, {}, 1)}
        for name, args in (("_fill", (q, u, 0.0)), ("_state", (q, u)),
                           ("_fill_inputs", (q, u, 0.0))):
            if name in called:
                cases[name] = (getattr(m, name), args, {}, 1)
        if "_check_finite" in called:
            cases["_check_finite"] = (m._check_finite, (q, u, 0.0, ud, "x"), {}, 1)
        if with_compute:
            if not out:
                log("    (compiling an in-loop wrapper of the kernel; takes a few seconds)")
            try:
                loop(1, *raw.jargs)
                cases["compute"] = (loop, (inner, *raw.jargs), {}, inner)
            except Exception as exc:        # noqa: BLE001 -- fall back to raw - dispatch
                log(f"    in-loop wrapper failed ({type(exc).__name__}); using raw - dispatch")
        res, _ = measure(cases, budget, repeats)
        model.forward_dynamics(q, u, 0.0)          # leave the workspace as it was
        out.append({"joint": joint, "n": n, "nu": model.nu, "helpers_called": called,
                    "nargs": len(raw.jargs),
                    "prebuilt_args": raw.prebuilt,
                    "times": {k: v["median_us"] for k, v in res.items()},
                    "min": {k: v["min_us"] for k, v in res.items()},
                    "iqr": {k: v["iqr_us"] for k, v in res.items()}})
    return out


# ----------------------------------------------------------------------------- printing
def fmt(stat, width=7):
    if stat is None:
        return " " * (width + 7)
    return f"{stat['median_us']:{width}.1f} ({stat['iqr_us']:4.1f})"


def print_report(report):
    mi = report["machine"]
    print("mbdyn forward-dynamics benchmark")
    print("=" * 32)
    print(f"python {mi['python']} ({mi['implementation']}), numpy {mi['numpy']}, "
          f"numba {mi['numba']}, scipy {mi['scipy']}, mbdyn {mi['mbdyn']}")
    src = mi["source"]
    print(f"mbdyn at {src['path']}: commit {src['commit']}"
          f"{' + uncommitted changes under mbdyn/' if src['modified'] else ''}")
    print(f"cpu: {mi['cpu']}; cpu_count {mi['cpu_count']} ({mi['cpus_usable']} usable); "
          f"{mi['platform']}")
    print(f"load average at start {mi['load_average_start']}, at end "
          f"{report.get('load_average_end')}; BLAS/OpenMP threads pinned to 1; "
          f"{mi['date']}")
    print(f"settings: {report['settings']}")
    print()
    print(textwrap.fill("NOTE: " + NOTE, 96))
    print()

    rows = report["table"]
    print("Microseconds per call: median (iqr).  NE/J = newton-euler / jourdain, median of "
          "per-round ratios.")
    hdr = (f"{'joint':9} {'n':>3} {'nu':>4} | {'jourdain':>14} | {'newton-euler':>14} | "
           f"{'NE/J':>5} | {'mass_matrix':>14}")
    print(hdr)
    print("-" * len(hdr))
    for r in rows:
        t = r["times"]
        print(f"{r['joint']:9} {r['n']:3d} {r['nu']:4d} | {fmt(t['jourdain'])} | "
              f"{fmt(t['newton-euler'])} | {r['ratio_ne_over_j']['median']:5.2f} | "
              f"{fmt(t['mass_matrix'])}")
    worst = max(r["max_rel_difference"] for r in rows)
    print(f"(the two formulations agree to {worst:.1e}, max relative difference over all "
          "models)")
    share = [v["cpu_median_us"] / v["median_us"] for r in rows for v in r["times"].values()]
    print(f"(thread CPU time / wall time, median over the measurements: {np.median(share):.2f};"
          " below 1 means this process was waiting for a CPU)")
    print(f"(first use in this process: "
          f"{report.get('first_use_in_this_process_s', float('nan')):.2f} s -- loading the "
          "cached kernels, or compiling them if the on-disk cache was stale)")
    print()

    if any(r["raw_available"] for r in rows):
        print("Python overhead: Model method vs raw compiled kernel (microseconds per call, "
              "medians).")
        print("  dispatch = a do-nothing numba function taking the same arguments as the "
              "Jourdain kernel (numba's type matching + unboxing).")
        hdr = (f"{'joint':9} {'n':>3} | {'J method':>9} {'J raw':>8} {'dispatch':>8} "
               f"{'J ovh':>7} {'ovh%':>5} | {'NE method':>9} {'NE raw':>8} {'NE ovh':>7} "
               f"{'ovh%':>5}")
        print(hdr)
        print("-" * len(hdr))
        for r in rows:
            if not r["raw_available"]:
                continue
            t = {k: v["median_us"] for k, v in r["times"].items()}
            jo = t["jourdain"] - t["jourdain_raw"]
            no = t["newton-euler"] - t["newton-euler_raw"]
            print(f"{r['joint']:9} {r['n']:3d} | {t['jourdain']:9.1f} {t['jourdain_raw']:8.1f} "
                  f"{t['dispatch']:8.1f} {jo:7.1f} {100 * jo / t['jourdain']:5.0f} | "
                  f"{t['newton-euler']:9.1f} {t['newton-euler_raw']:8.1f} {no:7.1f} "
                  f"{100 * no / t['newton-euler']:5.0f}")
        print()
    else:
        why = rows[0].get("raw_unavailable_because", "?")
        print(f"(raw-kernel columns unavailable: {why})\n")

    bd = report.get("breakdown")
    if isinstance(bd, dict):
        print(f"(breakdown unavailable: {bd.get('unavailable')})\n")
    elif bd:
        print("Where one small Jourdain call goes (microseconds; the minimum is the figure "
              "least disturbed by other processes):")
        for b in bd:
            print(f"  {b['joint']} chain, n={b['n']} (nu={b['nu']})"
                  f"{'':>{max(0, 39 - len(b['joint']) - len(str(b['n'])) - len(str(b['nu'])))}}"
                  f"{'median':>9} {'%':>4} {'min':>8} {'%':>4}")
            cols = []
            for stat in ("times", "min"):
                t = b[stat]
                total = t["method"]
                compute = t["compute"] if "compute" in t else t["raw"] - t["dispatch"]
                clabel = ("kernel compute (called from compiled code)" if "compute" in t
                          else "kernel compute (raw call - do-nothing call)")
                python = t["method_no_kernel"] - t["dispatch"]
                parts = [(f"Model.{h}" + (f" (x{k})" if k > 1 else ""), k * t[h])
                         for h, k in b["helpers_called"].items() if h in t]
                rest = python - sum(v for _, v in parts)
                lines = [("Model.forward_dynamics(q, u, t)", total),
                         ("  " + clabel, compute),
                         (f"  numba dispatch: do-nothing call, same {b.get('nargs', 3)} "
                          "args", t["dispatch"]),
                         ("  Python layer (method with do-nothing kernel", None),
                         ("                - do-nothing call)", python)]
                lines += [("    " + label, val) for label, val in parts]
                lines += [("    the rest (call, branches, copies, lookups)", rest),
                          ("  interplay (total - compute - method with do-nothing", None),
                          ("     kernel): caches, predictors, noise",
                           total - compute - t["method_no_kernel"]),
                          ("for reference: raw kernel call, packed args", t["raw"])]
                cols.append([(label, val, None if val is None else 100 * val / total)
                             for label, val in lines])
            for (label, med, pm), (_, mn, pn) in zip(*cols):
                if med is None:
                    print(f"    {label}")
                else:
                    print(f"    {label:50} {med:8.1f} {pm:4.0f} {mn:8.1f} {pn:4.0f}")
        print()

    sk = report.get("steps")
    if isinstance(sk, dict):
        print(f"(per-step split unavailable: {sk.get('unavailable')})\n")
    elif sk:
        names = list(sk[0]["times"])
        print("Compute time of each compiled step, called from compiled code (no dispatch); "
              "microseconds, medians:")
        short = {"kinematics_and_loads": "kinematics", "jourdain (M, f)": "J: M,f",
                 "cholesky_solve": "J: chol", "newton_euler_system (A, b)": "NE: A,b",
                 "np.linalg.solve(A, b)": "NE: solve"}
        hdr = f"{'joint':9} {'n':>3} {'nu':>4} | " + " ".join(
            f"{short.get(k, k):>10}" for k in names)
        print(hdr)
        print("-" * len(hdr))
        for r in sk:
            print(f"{r['joint']:9} {r['n']:3d} {r['nu']:4d} | " + " ".join(
                f"{r['times'][k]:10.1f}" for k in names))
        print("(Jourdain = kinematics + J: M,f + J: chol;  "
              "Newton-Euler = kinematics + NE: A,b + NE: solve)")
        print()

    ct = report.get("compile")
    if ct:
        print("Kernel compile time (subprocesses sharing a fresh NUMBA_CACHE_DIR; seconds):")
        keys = ("import_numpy_numba_s", "import_mbdyn_s", "build_and_compile_model_s",
                "first_jourdain_s", "first_newton_euler_s", "first_coordinate_rates_s",
                "in_process_total_s", "subprocess_wall_s", "cache_index_files",
                "numba_cache_hits", "numba_cache_misses")
        print(f"  {'':34} {'cold':>9} {'cached':>9}")
        for k in keys:
            vals = []
            for label in ("cold", "cached"):
                rec = ct.get(label, {})
                v = rec.get(k)
                vals.append(f"{v:9.2f}" if isinstance(v, float) else f"{v!s:>9}")
            print(f"  {k:34} {vals[0]} {vals[1]}")
        for label in ("cold", "cached"):
            if "error" in ct.get(label, {}):
                print(f"  {label} probe failed: {ct[label]['error']}")
        cold, cached = ct.get("cold", {}), ct.get("cached", {})
        if ct.get("sources_changed_during_probe"):
            print("  WARNING: the kernel sources changed while the probes ran (someone edited "
                  "mbdyn/kernels); the 'cached' run had to recompile.  Run again.")
        elif cached.get("numba_cache_misses"):
            print("  WARNING: the 'cached' run still compiled some kernels (cache misses); "
                  "some kernel is not cacheable.")
        if "in_process_total_s" in cold and "in_process_total_s" in cached:
            print(f"  => compiling the kernels costs about "
                  f"{cold['in_process_total_s'] - cached['in_process_total_s']:.1f} s once "
                  f"per machine; a cached start costs {cached['subprocess_wall_s']:.1f} s "
                  "of wall time (mostly imports).")
        print("  (build_and_compile_model includes System.compile's inertia check, which "
              "already calls mass_matrix and the Jourdain kernel; cache hits/misses count "
              "the top-level kernels called from Python)")
        print()
    print(textwrap.fill("Reminder: " + NOTE, 96))


# ----------------------------------------------------------------------------- entry point
def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--quick", action="store_true",
                   help=f"sizes {QUICK_SIZES}, fewer repeats, no in-loop compute column")
    p.add_argument("--json", action="store_true", help="print JSON on stdout instead of tables")
    p.add_argument("--sizes", type=lambda s: tuple(int(x) for x in s.split(",")),
                   help="comma-separated chain sizes (default 2,5,10,20,50)")
    p.add_argument("--budget", type=float,
                   help="seconds per measurement (default 0.3, quick 0.08)")
    p.add_argument("--repeats", type=int, help="rounds per measurement (default 15, quick 7)")
    p.add_argument("--no-compile", action="store_true", help="skip the compile-time probes")
    p.add_argument("--no-breakdown", action="store_true", help="skip the small-model breakdown")
    p.add_argument("--steps", action="store_true",
                   help="also time each compiled step (kinematics, M and f, Cholesky, "
                        "Newton-Euler assembly, LU) for every size; compiles wrappers, "
                        "adds about a minute")
    args = p.parse_args(argv)

    sizes = args.sizes or (QUICK_SIZES if args.quick else SIZES)
    budget = args.budget or (0.08 if args.quick else 0.3)
    repeats = args.repeats or (7 if args.quick else 15)
    t_start = perf_counter()

    log("importing mbdyn ...")
    import mbdyn as mb
    from mbdyn.kernels import evaluate as ke
    from mbdyn.kernels import packed as kp
    report = {"machine": machine_info(),
              "settings": {"sizes": list(sizes), "budget_s": budget, "repeats": repeats,
                           "quick": args.quick, "steps": args.steps},
              "note": NOTE}
    t0 = perf_counter()
    warm_model, wq, wu = build_chain(mb, 2, "spherical")   # loads (or compiles) the kernels
    for method in METHODS:
        warm_model.forward_dynamics(wq, wu, 0.0, method=method)
    report["first_use_in_this_process_s"] = perf_counter() - t0

    log("timing the forward dynamics ...")
    report["table"] = run_table(mb, kp, sizes, budget, repeats)
    if not args.no_breakdown:
        report["breakdown"] = run_breakdown(mb, kp, budget, repeats, with_compute=not args.quick)
    if args.steps:
        report["steps"] = run_subkernels(mb, ke, sizes, budget, repeats)
    if not args.no_compile:
        log("timing the kernels' compilation ...")
        report["compile"] = compile_times()
    try:
        report["load_average_end"] = [round(x, 2) for x in os.getloadavg()]
    except OSError:
        report["load_average_end"] = None
    report["benchmark_wall_s"] = perf_counter() - t_start

    if args.json:
        print(json.dumps(report, indent=1))
    else:
        print_report(report)
        print(f"(benchmark wall time {report['benchmark_wall_s']:.0f} s)")


if __name__ == "__main__":
    main()
