#!/usr/bin/env python
"""Closed kinematic loops (issue 24): what the constraints cost per call, and whole runs of
two closed mechanisms at equal accuracy against scipy and Exudyn.

    python benchmarks/constraints.py              # full run (about 10-15 minutes)
    python benchmarks/constraints.py --quick      # fewer rounds, the 1e-6 target only
    python benchmarks/constraints.py --json       # machine-readable output on stdout
    python benchmarks/constraints.py --only calls # or "runs": one part only
    python benchmarks/constraints.py --help

Exudyn is a peer for benchmarking only, never a dependency of mbdyn: install it into the
virtual environment by hand (``pip install exudyn``).  When it is not installed its rows
say "skipped" and the rest runs.

Part 1: one constrained evaluation against the same bodies as a tree
--------------------------------------------------------------------
Each mechanism twice: closed (the loop joints), and as a tree (the same model without the
loop joints: for the model files, the same file with the ``cut = true`` joints and the
assembly guesses removed), both evaluated at the same state (the closed mechanism's
assembled ``q``, ``u``).  Mechanisms: the four-bar (``models/four_bar.toml``, case
"free": a free crank), a slider-crank (built here as in ``tests/loop_mechanisms.py``: no
loads but gravity), Andrews' squeezer (``models/andrews_squeezer.toml``, 7 bodies, three
loop joints) and planar chains of n = 20 and 100 revolute links hanging in a half circle
from the ground and closed back to the ground by one revolute loop joint.  Columns:

* "Python entry": ``model.forward_dynamics(q, u)`` (method "auto", the route a user
  gets: for the closed mechanism ``M u' = f + G^T lam``, ``G u' = gamma`` by the mass
  matrix below 16 free speeds, by the articulated bodies from 16 on; for the tree ``M u'
  = f`` below 6, the articulated-body algorithm from 6 on), timed with
  ``benchmarks/forward_dynamics.py``'s ``measure`` (blocks sized to a time budget, rounds
  interleaved, garbage collector off; medians; the ratio is the median of the per-round
  ratios).
* "RK4 run, per evaluation": a fixed-step RK4 run (``mb.simulate(..., integrator="rk4",
  dt=...)``, the compiled loop, the "auto" route of each as above) of each,
  ``stats["wall_time_s"] / stats["rhs_evaluations"]``: the compiled cost of one
  right-hand side in a run, the closed mechanism's including its share of the projection
  onto the constraints after every step (one projection per 4 evaluations).  The two runs
  follow different motions (the tree's links are free) with the same number of
  evaluations.
* "kernel alone": the compiled kernel called in a loop from compiled code (no dispatch,
  no Python, no projection): ``kernels.constrained.constrained_accelerations`` for the
  closed mechanism, ``kernels.packed.jourdain_accelerations_packed`` for the tree.  These
  call the engine's internals the way ``Model.forward_dynamics`` does; if they move,
  the columns are left out with a note.

Issue 24's goal: a constrained evaluation at most 2x the tree's.

Part 2: whole runs at equal accuracy
------------------------------------
The four-bar's free crank over 2 s, and Andrews' squeezer over 0.03 s (its published
problem), each at targets of 1e-6 and 1e-8 rad on the positions at the end time (the
largest error over the coordinates).  References: for Andrews the published solution at
0.03 s (``tests/loop_references.py`` ``ANDREWS_Q_REF``, 16 digits); for the four-bar an
mbdyn DOP853 run at rtol 1e-13, atol 1e-15 (checked below against the scipy DAE run at
its tightest tolerance).  Every solver's setting is the loosest of a grid that meets the
target:

* mbdyn: ``mb.simulate(model, t_end, q0, u0, integrator="DOP853", rtol=rtol,
  atol=rtol/1000, t_eval=[t_end])`` (projection onto the constraints after every step);
  the loosest rtol of ``RTOLS`` at which it and the next tighter one both meet the target
  (so that a lucky cancellation does not choose it).  Its drift figures are
  ``stats["constraint_drift"]`` (largest position residual over the samples, after the
  projection), ``"constraint_drift_unprojected"`` (before it) and
  ``"constraint_drift_velocity"``.
* scipy: ``solve_ivp(method="Radau")`` on the index-1 form of the equations written in
  minimal coordinates from the publication (Andrews: ``andrews_mass_matrix``,
  ``andrews_forces``, ``andrews_constraint_jacobian`` of ``tests/loop_references.py``, the
  Hairer-Wanner formulation; the four-bar: absolute link angles, derived in this file):
  ``M q'' = f + G^T lam``, ``G q'' = -(G' q')`` solved as an ODE in ``(q, q')`` by
  eliminating ``lam`` at every call (one dense solve of the augmented system); no
  projection, so it drifts off the position and velocity constraints.  Jacobian by
  scipy's finite differences; same rtol grid and rule, atol = rtol/1000.
* Exudyn (``pip install exudyn``): the same tree as an ``ObjectKinematicTree``
  (minimal coordinates, the same joint coordinates) closed by ``GenericJoint``s that
  constrain the planar position (x, y) of the loop joints' points; Andrews' spring as an
  ``ObjectConnectorSpringDamper`` and its motor as the tree's joint force.  Exudyn's
  explicit solvers do not handle such constraints (its documentation, "Explicit
  solvers"), so its implicit index-3 generalized-alpha solver (default settings:
  spectral radius 0.9, modified Newton; Newton's tolerances tightened to 1e-12 relative,
  1e-14 absolute: with the defaults its error stops falling near 3e-7 rad on Andrews) at
  a fixed step; the step count is the smallest
  of the grid ``1000 * 2^(k/2)`` that meets the target (its error falls smoothly with the
  step: second order).

The drift columns are the constraint residuals at the end state of each run, position
(largest |phi|) and velocity (largest |psi|), all evaluated by mbdyn's
``Model.constraint_residuals`` (the peers' end states mapped to mbdyn's coordinates).

Timing: CPU time of this process (``time.process_time``), one call per round, the rounds
interleaved (rotated), garbage collector off; medians.  mbdyn is timed over the whole
``mb.simulate`` call, Exudyn over ``SolveDynamic`` (its system built once beforehand),
scipy over ``solve_ivp``.  Exudyn runs longer than 10 s are timed over two rounds.
Issue 24's goal: mbdyn at most half of Exudyn's time.

The machine may be shared and noisy: compare the ratios, measured in the same run.
"""
import os

for _var in ("OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "OMP_NUM_THREADS",
             "NUMEXPR_NUM_THREADS", "VECLIB_MAXIMUM_THREADS", "BLIS_NUM_THREADS"):
    os.environ[_var] = "1"

import argparse  # noqa: E402
import importlib  # noqa: E402
import json  # noqa: E402
import math  # noqa: E402
import platform  # noqa: E402
import re  # noqa: E402
import statistics  # noqa: E402
import sys  # noqa: E402
import time  # noqa: E402
import warnings  # noqa: E402
from pathlib import Path  # noqa: E402

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
sys.path.insert(0, str(HERE))                  # forward_dynamics: the per-call timer
sys.path.insert(0, str(ROOT / "tests"))        # loop_references: published data

import numpy as np  # noqa: E402

import forward_dynamics as fdb  # noqa: E402
from timing import interleaved_cpu  # noqa: E402
import loop_references as lr  # noqa: E402

NOTES = []
#: rtol grid of the adaptive solvers (atol = rtol / 1000)
RTOLS = (1e-5, 3e-6, 1e-6, 3e-7, 1e-7, 3e-8, 1e-8, 3e-9, 1e-9, 3e-10, 1e-10, 3e-11, 1e-11,
         3e-12, 1e-12)
TARGETS = (1e-6, 1e-8)
#: Exudyn's fixed step counts: STEP_BASE * 2^(k/2)
STEP_BASE = 1000
#: Exudyn runs longer than this (CPU seconds) are timed over two rounds only
LONG_RUN = 10.0
#: Exudyn's Newton tolerances (relative, absolute): see ``exudyn_tree``
NEWTON_TOLERANCES = (1e-12, 1e-14)


def log(*args):
    print(*args, file=sys.stderr, flush=True)


def peer(module):
    """The imported module, or None (with a note) when it is not installed."""
    try:
        return importlib.import_module(module)
    except ImportError as exc:
        NOTES.append(f"{module} is not installed ({exc}): its rows are skipped "
                     "(pip install exudyn into the environment that runs this script; it "
                     "is never a dependency of mbdyn).")
        return None


# =========================================================================== models
def tree_text(text):
    """A model file's text without its loop joints: every ``[[...joints]]`` table that
    says ``cut = true`` dropped, and the assembly guesses (``[guess]``, ``guess = {...}``),
    which a model without loops refuses."""
    chunks = re.split(r"(?m)^(?=\[)", text)
    kept = []
    for chunk in chunks:
        head = chunk.split("\n", 1)[0]
        if head.startswith("[[") and "joints]]" in head and re.search(
                r"(?m)^cut\s*=\s*true", chunk):
            continue
        if head.startswith("[guess]"):
            continue
        kept.append(chunk)
    return re.sub(r"(?m)^guess\s*=.*$", "", "".join(kept))


def file_pair(mb, name, case=None):
    """``(closed model, tree model, q, u, scene)`` of ``models/NAME``: the state is the
    file's own (assembled) initial state."""
    path = ROOT / "models" / name
    scene = mb.load_model(path, case=case)
    tree = mb.load_model(path, case=case, text=tree_text(path.read_text())).model
    if tree.has_loops or not scene.model.has_loops:
        raise RuntimeError(f"{name}: removing the loop joints did not leave a tree")
    return scene.model, tree, scene.q0.copy(), scene.u0.copy(), scene


def _rod(s, name, length, mass, w=0.02):
    s.add_body(name, mass=mass, com=(length / 2, 0, 0),
               inertia=(mass * 2 * w * w / 12, mass * (length ** 2 + w * w) / 12,
                        mass * (length ** 2 + w * w) / 12))


def slider_crank(mb, close, r=0.05, l=0.2, e=0.01):
    """Crank, connecting rod and piston (prismatic along x at height ``e``), as in
    ``tests/loop_mechanisms.py``: gravity, no other load."""
    s = mb.System("slider-crank", gravity=(0, -9.81, 0))
    _rod(s, "crank", r, 0.5)
    _rod(s, "rod", l, 0.8)
    s.add_body("piston", mass=0.6, inertia=(1e-4, 1e-4, 1e-4))
    s.add_joint("th", "revolute", "ground", "crank", axis="z")
    s.add_joint("phi", "revolute", "crank", "rod", axis="z", position=(r, 0, 0))
    s.add_joint("x", "prismatic", "ground", "piston", axis="x", position=(0, e, 0))
    if close:
        s.add_joint("pin", "revolute", "rod", "piston", axis="z", position=(l, 0, 0),
                    child_position=(0, 0, 0))
    return s.compile()


def slider_pair(mb):
    loop, tree = slider_crank(mb, True), slider_crank(mb, False)
    th = 0.4
    rod_abs = math.asin((0.01 - 0.05 * math.sin(th)) / 0.2)
    x = 0.05 * math.cos(th) + 0.2 * math.cos(rod_abs)
    q, u = loop.assemble(initial={"th": th}, initial_speeds={"th": 20.0},
                         guess={"phi": rod_abs - th, "x": x})
    return loop, tree, q, u


def chain(mb, n, close, total=2.0):
    """``n`` revolute links (axes z, planar, gravity -y) hanging from the origin in a half
    circle (link i at the absolute angle ``-pi/2 + pi (i + 1/2)/n``), the last link's end
    pinned back to the ground where it lies by a revolute loop joint (5 equations of rank
    2; mobility n - 2).  Links of length ``total/n``, mass ``2/n`` kg."""
    length, mass = total / n, 2.0 / n
    angles = -math.pi / 2 + math.pi * (np.arange(n) + 0.5) / n
    s = mb.System(f"closed chain of {n}", gravity=(0, -9.81, 0))
    parent = "ground"
    for i in range(n):
        _rod(s, f"link{i}", length, mass)
        s.add_joint(f"q{i}", "revolute", parent, f"link{i}", axis="z",
                    position=(0 if i == 0 else length, 0, 0))
        parent = f"link{i}"
    end = length * np.array([np.cos(angles).sum(), np.sin(angles).sum()])
    if close:
        s.add_joint("close", "revolute", "ground", parent, axis="z",
                    position=(end[0], end[1], 0.0), child_position=(length, 0, 0))
    return s.compile(), np.concatenate([[angles[0]], np.diff(angles)])


def chain_pair(mb, n):
    loop, q = chain(mb, n, True)
    tree, _ = chain(mb, n, False)
    rng = np.random.default_rng([24, n])
    q, u = loop.project(q, rng.uniform(-0.5, 0.5, n))
    return loop, tree, q, u


# =========================================================================== part 1
RK4 = {  # (t_end, dt) of the fixed-step runs: 2000-4000 steps
    "four-bar": (2.0, 1e-3), "slider-crank": (0.5, 2.5e-4), "Andrews (7 bodies)": (0.03, 1e-5),
    "chain n=20": (1.0, 5e-4), "chain n=100": (0.5, 2.5e-4)}


def kernel_loops():
    """``(tree_loop, loop_loop)``: the two kernels called ``count`` times from compiled
    code, or ``(None, None)`` with a note when the internals moved."""
    try:
        from numba import njit
        from mbdyn.kernels import constrained as kc
        from mbdyn.kernels import packed as kp
        tree_loop = fdb.packed_helpers(kp.jourdain_accelerations_packed)[1]

        @njit
        def loop_loop(count, tree, body, state, loads, motion, jourdain, con, scratch):
            s = 0
            for _ in range(count):
                s += kc.constrained_accelerations(tree, body, state, loads, motion,
                                                  jourdain, con, scratch)
            return s
        return tree_loop, loop_loop
    except Exception as exc:            # noqa: BLE001 -- report and carry on
        NOTES.append(f"kernel-alone columns left out: {type(exc).__name__}: {exc}")
        return None, None


def kernel_cases(loop, tree, q, u, loops, count=200):
    """Measure cases of the two kernels (``count`` calls per invocation), after checking
    that each reproduces its model's ``forward_dynamics``."""
    tree_loop, loop_loop = loops
    if tree_loop is None:
        return {}
    try:
        from mbdyn.algorithms.constrained import groups
        ref_tree = tree.forward_dynamics(q, u)
        ref_loop = loop.forward_dynamics(q, u)
        targs = (*tree._dynamics_full, np.array(q, float), np.array(u, float))
        tree_loop(1, *targs)
        loop._fill(q, u, 0.0)
        largs = (*groups(loop), loop._con, loop._scratch)
        status = loop_loop(1, *largs)
        scale = max(1.0, float(np.abs(ref_loop).max()))
        if (np.abs(tree._ud - ref_tree).max() > 1e-9 * max(1.0, np.abs(ref_tree).max())
                or np.abs(loop._ud - ref_loop).max() > 1e-9 * scale or status != -1):
            raise RuntimeError("the kernels do not reproduce Model.forward_dynamics")
        return {"tree kernel": (tree_loop, (count, *targs), {}, count),
                "loop kernel": (loop_loop, (count, *largs), {}, count)}
    except Exception as exc:            # noqa: BLE001
        NOTES.append(f"kernel-alone columns left out ({type(exc).__name__}: {exc})")
        return {}


def rk4_per_eval(mb, pairs, repeats):
    """``{name: {"tree": us, "loop": us, "ratio": r, "steps": n}}``: medians over
    interleaved runs of the per-evaluation cost ``wall_time_s / rhs_evaluations``."""
    out = {}
    for name, (loop, tree, q, u) in pairs.items():
        t_end, dt = RK4[name]
        steps = int(round(t_end / dt))

        def run(model):
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                r = mb.simulate(model, t_end, q, u, integrator="rk4", dt=dt,
                                decimate=max(1, steps // 4))
            return r.stats["wall_time_s"] / r.stats["rhs_evaluations"], r
        _, rl = run(loop)                 # warm-up (compiles the loop on a cold cache)
        run(tree)
        samples = {"tree": [], "loop": []}
        for k in range(repeats):
            order = ("tree", "loop") if k % 2 == 0 else ("loop", "tree")
            for which in order:
                samples[which].append(run(tree if which == "tree" else loop)[0])
        ratios = [a / b for a, b in zip(samples["loop"], samples["tree"])]
        out[name] = {"tree_us": statistics.median(samples["tree"]) * 1e6,
                     "loop_us": statistics.median(samples["loop"]) * 1e6,
                     "ratio": statistics.median(ratios), "steps": steps, "dt": dt,
                     "evaluations": int(rl.stats["rhs_evaluations"]),
                     "drift": float(rl.stats.get("constraint_drift", float("nan")))}
        log(f"  rk4 {name}: tree {out[name]['tree_us']:.2f} us, loop "
            f"{out[name]['loop_us']:.2f} us per evaluation")
    return out


def part_calls(mb, args):
    log("part 1: building the mechanisms")
    pairs = {}
    loop, tree, q, u, _ = file_pair(mb, "four_bar.toml", "free")
    pairs["four-bar"] = (loop, tree, q, u)
    pairs["slider-crank"] = slider_pair(mb)
    loop, tree, q, u, _ = file_pair(mb, "andrews_squeezer.toml")
    pairs["Andrews (7 bodies)"] = (loop, tree, q, u)
    for n in (20, 100):
        pairs[f"chain n={n}"] = chain_pair(mb, n)
    loops = kernel_loops()
    rows = {}
    for name, (loop, tree, q, u) in pairs.items():
        log(f"  per call: {name}")
        cases = {"tree": (tree.forward_dynamics, (q, u), {}, 1),
                 "loop": (loop.forward_dynamics, (q, u), {}, 1)}
        ll, out = tree.lowlevel("jourdain"), np.empty(tree.nu)
        cases["tree lowlevel"] = (ll.forward_dynamics, (q, u, 0.0, out), {}, 1)
        cases.update(kernel_cases(loop, tree, q, u, loops))
        res, rat = fdb.measure(cases, args.budget, args.repeats,
                               ratios=[("loop", "tree"), ("loop kernel", "tree kernel")])
        rank = loop.constraint_rank(q)[0]
        row = {"nu": loop.nu, "rows": len(loop.constraint_rows), "rank": rank,
               "python_tree_us": res["tree"]["median_us"],
               "python_loop_us": res["loop"]["median_us"],
               "python_ratio": rat[("loop", "tree")]["median"],
               "lowlevel_tree_us": res["tree lowlevel"]["median_us"]}
        if "loop kernel" in res:
            row.update(kernel_tree_us=res["tree kernel"]["median_us"],
                       kernel_loop_us=res["loop kernel"]["median_us"],
                       kernel_ratio=rat[("loop kernel", "tree kernel")]["median"])
        rows[name] = row
    log("  RK4 runs (tree against loop)")
    rk4 = rk4_per_eval(mb, pairs, max(3, args.repeats // 2))
    for name in rows:
        rows[name]["rk4"] = rk4[name]
    return rows


def table_calls(rows):
    def f(x, nd=2):
        return "—" if x is None else f"{x:.{nd}f}"
    out = ["| mechanism | nu | loop rows (rank) | Python entry: tree (µs) | loop (µs) | "
           "ratio | RK4 run, per evaluation: tree (µs) | loop (µs) | ratio | "
           "kernel alone: tree (µs) | loop (µs) | ratio |",
           "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|"]
    for name, r in rows.items():
        k = r.get
        out.append(f"| {name} | {r['nu']} | {r['rows']} ({r['rank']}) | "
                   f"{f(r['python_tree_us'])} | {f(r['python_loop_us'])} | "
                   f"**{f(r['python_ratio'], 1)}** | {f(r['rk4']['tree_us'])} | "
                   f"{f(r['rk4']['loop_us'])} | **{f(r['rk4']['ratio'], 1)}** | "
                   f"{f(k('kernel_tree_us'))} | {f(k('kernel_loop_us'))} | "
                   f"**{f(k('kernel_ratio'), 1)}** |")
    return "\n".join(out)


# =========================================================================== part 2
# ---------------------------------------------------------------- scipy: index-1 DAEs
def andrews_gamma(q, qd, p=lr.ANDREWS_PARAMETERS):
    """``-(G' q')``: the right-hand side of ``G q'' = gamma``, the velocity-product part of
    the second derivative of ``lr.andrews_constraints`` (each term ``c cos(x)`` or
    ``c sin(x)`` of ``g`` contributes ``-c cos(x) x'^2`` or ``-c sin(x) x'^2``; derived
    here, checked against finite differences of ``G`` in ``check_andrews_dae``)."""
    be, th, ga, ph, de, om, ep = q
    bp, tp, gp, pp, dp, op, ep_ = qd
    rr, d, ss, e, zt, zf, u = (p[k] for k in ("rr", "d", "ss", "e", "zt", "zf", "u"))
    bt = bp + tp
    hx = -rr * math.cos(be) * bp ** 2 + d * math.cos(be + th) * bt ** 2
    hy = -rr * math.sin(be) * bp ** 2 + d * math.sin(be + th) * bt ** 2
    pd, oe = pp + dp, op + ep_
    h = np.array([
        hx + ss * math.sin(ga) * gp ** 2,
        hy - ss * math.cos(ga) * gp ** 2,
        hx + e * math.sin(ph + de) * pd ** 2 + zt * math.cos(de) * dp ** 2,
        hy - e * math.cos(ph + de) * pd ** 2 + zt * math.sin(de) * dp ** 2,
        hx + zf * math.cos(om + ep) * oe ** 2 + u * math.sin(ep) * ep_ ** 2,
        hy + zf * math.sin(om + ep) * oe ** 2 - u * math.cos(ep) * ep_ ** 2,
    ])
    return -h


def index1_rhs(mass, forces, jacobian, gamma, n):
    """``y' = (q', q'')`` of ``M q'' = f + G^T lam``, ``G q'' = gamma``: the augmented
    system solved for ``q''`` and ``lam`` at every call."""
    def rhs(t, y):
        q, qd = y[:n], y[n:]
        G = jacobian(q)
        m = G.shape[0]
        A = np.zeros((n + m, n + m))
        A[:n, :n] = mass(q)
        A[:n, n:] = G.T
        A[n:, :n] = G
        b = np.concatenate([forces(q, qd), gamma(q, qd)])
        return np.concatenate([qd, np.linalg.solve(A, b)[:n]])
    return rhs


def andrews_dae():
    return index1_rhs(lr.andrews_mass_matrix, lr.andrews_forces,
                      lr.andrews_constraint_jacobian, andrews_gamma, 7)


def check_andrews_dae():
    """The index-1 form against the published initial accelerations and ``gamma``
    against central differences of ``G`` along ``q'``."""
    rhs = andrews_dae()
    w0 = rhs(0.0, np.concatenate([lr.ANDREWS_Q0, lr.ANDREWS_U0]))[7:]
    acc = float(np.abs(w0 - lr.ANDREWS_W0).max() / np.abs(lr.ANDREWS_W0).max())
    rng = np.random.default_rng(7)
    q, qd = lr.ANDREWS_Q0 + rng.normal(0, 0.1, 7), rng.normal(0, 50, 7)
    h = 1e-6
    Gdot = (lr.andrews_constraint_jacobian(q + h * qd)
            - lr.andrews_constraint_jacobian(q - h * qd)) / (2 * h)
    gam = float(np.abs(andrews_gamma(q, qd) + Gdot @ qd).max() / np.abs(Gdot @ qd).max())
    NOTES.append(f"scipy's Andrews DAE checked: accelerations at t = 0 against the "
                 f"published ones, relative difference {acc:.1e}; G' q' against central "
                 f"differences of G, {gam:.1e}.")
    return acc < 1e-8 and gam < 1e-6


FB = None          # the four-bar's parameters (read from the model file by part_runs)


def fourbar_terms(P):
    """The four-bar in absolute link angles ``(t2, t3, t4)`` (crank, coupler, rocker; all
    from +x), derived here by Lagrange's equations: crank and rocker turn about fixed
    pivots (inertia about the pivot ``I + m |c|^2``); the coupler's centre is
    ``a e(t2) + |c3| e(t3 + alpha)``, ``alpha = atan2(q3, b/2)``, so ``M12 = m3 a |c3|
    cos(delta)``, ``delta = t3 - t2 + alpha``, and the velocity products are
    ``k sin(delta) w3^2`` (crank) and ``-k sin(delta) w2^2`` (coupler), ``k = m3 a |c3|``;
    gravity along -y.  Loop ``a e(t2) + b e(t3) - c e(t4) = (d, 0)``."""
    a, b, c, d, w, g = (P[k] for k in ("a", "b", "c", "d", "w", "g"))
    m2, m3, m4, q3 = P["m2"], P["m3"], P["m4"], P["q3"]

    def izz(m, L):
        return m * (L * L + w * w) / 12

    c3, alpha = math.hypot(b / 2, q3), math.atan2(q3, b / 2)
    J2 = izz(m2, a) + m2 * (a / 2) ** 2 + m3 * a * a
    J3 = izz(m3, b) + m3 * c3 * c3
    J4 = izz(m4, c) + m4 * (c / 2) ** 2
    k = m3 * a * c3

    def mass(q):
        m12 = k * math.cos(q[1] - q[0] + alpha)
        return np.array([[J2, m12, 0.0], [m12, J3, 0.0], [0.0, 0.0, J4]])

    def forces(q, qd):
        t2, t3, t4 = q
        s = k * math.sin(t3 - t2 + alpha)
        return np.array([s * qd[1] ** 2 - (m2 * a / 2 + m3 * a) * g * math.cos(t2),
                         -s * qd[0] ** 2 - m3 * g * c3 * math.cos(t3 + alpha),
                         -m4 * g * (c / 2) * math.cos(t4)])

    def jacobian(q):
        t2, t3, t4 = q
        return np.array([[-a * math.sin(t2), -b * math.sin(t3), c * math.sin(t4)],
                         [a * math.cos(t2), b * math.cos(t3), -c * math.cos(t4)]])

    def gamma(q, qd):
        t2, t3, t4 = q
        w2, w3, w4 = qd
        return -np.array([-a * math.cos(t2) * w2 ** 2 - b * math.cos(t3) * w3 ** 2
                          + c * math.cos(t4) * w4 ** 2,
                          -a * math.sin(t2) * w2 ** 2 - b * math.sin(t3) * w3 ** 2
                          + c * math.sin(t4) * w4 ** 2])
    return index1_rhs(mass, forces, jacobian, gamma, 3)


def fourbar_to_absolute(model, q, u):
    """mbdyn's four-bar state (crank, coupler relative to the crank, rocker) as absolute
    angles and rates ``(t2, t3, t4)``."""
    i = [model.coordinates.index(n) for n in ("crank", "coupler", "rocker")]
    j = [model.speeds.index(n + "_dot") for n in ("crank", "coupler", "rocker")]
    qa, ua = np.asarray(q)[i], np.asarray(u)[j]
    return (np.array([qa[0], qa[0] + qa[1], qa[2]]), np.array([ua[0], ua[0] + ua[1], ua[2]]))


def fourbar_from_absolute(model, qa, ua):
    q, u = np.empty(3), np.empty(3)
    for k, (name, x, v) in enumerate(zip(("crank", "coupler", "rocker"),
                                         (qa[0], qa[1] - qa[0], qa[2]),
                                         (ua[0], ua[1] - ua[0], ua[2]))):
        q[model.coordinates.index(name)] = x
        u[model.speeds.index(name + "_dot")] = v
    return q, u


# ---------------------------------------------------------------- Exudyn
def exudyn_tree(exu, links, q0, u0, closures, gravity, t_end, steps, springs=(),
                joint_forces=None):
    """An Exudyn ``ObjectKinematicTree`` of planar links (``links``: ``(parent index,
    offset (x, y), com (x, y), mass, Izz)``, revolute about z, identity joint
    transformations: mbdyn's layout), closed by ``GenericJoint``s constraining x and y of
    the point pairs ``closures`` (``((link, (x, y)), (link, (x, y)))``), with linear
    springs ``((link, (x, y)), ground (x, y), stiffness, free length)``; and a function
    that runs generalized-alpha with ``steps`` fixed steps to ``t_end`` and returns the
    final ``(q, q')`` in link order."""
    from exudyn.itemInterface import (GenericJoint, MarkerBodyPosition,
                                      MarkerKinematicTreeRigid, NodeGenericODE2,
                                      ObjectConnectorSpringDamper, ObjectGround,
                                      ObjectKinematicTree)
    n = len(links)
    SC = exu.SystemContainer()
    mbs = SC.AddSystem()
    node = mbs.AddNode(NodeGenericODE2(referenceCoordinates=[0.0] * n,
                                       initialCoordinates=[float(x) for x in q0],
                                       initialCoordinates_t=[float(x) for x in u0],
                                       numberOfODE2Coordinates=n))
    extra = {} if joint_forces is None else {"jointForceVector": list(joint_forces)}
    kt = mbs.AddObject(ObjectKinematicTree(
        nodeNumber=node, jointTypes=[exu.JointType.RevoluteZ] * n,
        linkParents=[lk[0] for lk in links],
        jointTransformations=exu.Matrix3DList([np.eye(3)] * n),
        jointOffsets=exu.Vector3DList([[lk[1][0], lk[1][1], 0.0] for lk in links]),
        linkInertiasCOM=exu.Matrix3DList([np.diag([lk[4] / 2, lk[4] / 2, lk[4]])
                                          for lk in links]),
        linkCOMs=exu.Vector3DList([[lk[2][0], lk[2][1], 0.0] for lk in links]),
        linkMasses=[lk[3] for lk in links], gravity=list(gravity), **extra))

    def marker(link, xy):
        return mbs.AddMarker(MarkerKinematicTreeRigid(objectNumber=kt, linkNumber=link,
                                                      localPosition=[xy[0], xy[1], 0.0]))
    for (la, pa), (lb, pb) in closures:
        mbs.AddObject(GenericJoint(markerNumbers=[marker(la, pa), marker(lb, pb)],
                                   constrainedAxes=[1, 1, 0, 0, 0, 0]))
    if springs:
        ground = mbs.AddObject(ObjectGround())
        for (link, xy), gxy, stiffness, length in springs:
            mg = mbs.AddMarker(MarkerBodyPosition(bodyNumber=ground,
                                                  localPosition=[gxy[0], gxy[1], 0.0]))
            mbs.AddObject(ObjectConnectorSpringDamper(
                markerNumbers=[marker(link, xy), mg], stiffness=stiffness, damping=0.0,
                referenceLength=length))
    mbs.Assemble()
    ss = exu.SimulationSettings()
    ti = ss.timeIntegration
    ti.endTime = t_end
    ti.numberOfSteps = int(steps)
    ti.automaticStepSize = False
    ti.verboseMode = 0
    # Newton's tolerances tightened (defaults 1e-8 relative, 1e-10 absolute): with the
    # defaults the error on Andrews stops falling at about 3e-7 rad (3.1e-7 at 362 039
    # steps), short of the 1e-8 target; these cost no measurable time at 30 000 steps
    ti.newton.relativeTolerance = NEWTON_TOLERANCES[0]
    ti.newton.absoluteTolerance = NEWTON_TOLERANCES[1]
    ss.solution.file.write = False
    ss.solution.sensors.writePeriod = t_end
    ss.show.computationTime = False
    ss.show.statistics = False

    def run():
        exu.SolveDynamic(mbs, ss, showHints=False)
        return (np.array(mbs.systemData.GetODE2Coordinates()),
                np.array(mbs.systemData.GetODE2Coordinates_t()))
    return run


def exudyn_andrews(exu, steps):
    """Andrews' squeezer in Exudyn from the published data (``lr.ANDREWS_PARAMETERS``;
    the bodies as ``lr.ANDREWS_BODIES`` lays them out).  Returns ``run() -> (q, q')`` in
    the publication's order."""
    p = lr.ANDREWS_PARAMETERS
    order = ("K1", "K2", "K3", "K5", "K4", "K7", "K6")     # parents first
    names = ("beta", "Theta", "gamma", "delta", "Phi", "epsilon", "Omega")
    links = [(-1, (0, 0), (p["ra"], 0), p["m1"], p["I1"]),
             (0, (p["rr"], 0), (-p["da"], 0), p["m2"], p["I2"]),
             (-1, (p["xb"], p["yb"]), (p["sb"], -p["sa"]), p["m3"], p["I3"]),
             (-1, (p["xa"], p["ya"]), (p["ta"], p["tb"]), p["m5"], p["I5"]),
             (3, (p["zt"], 0), (0, -(p["e"] - p["ea"])), p["m4"], p["I4"]),
             (-1, (p["xa"], p["ya"]), (-p["ub"], -p["ua"]), p["m7"], p["I7"]),
             (5, (0, -p["u"]), (p["zf"] - p["fa"], 0), p["m6"], p["I6"])]
    k = {b: i for i, b in enumerate(order)}
    E = (k["K2"], (-p["d"], 0))
    closures = [(E, (k["K3"], (0, -p["ss"]))), (E, (k["K4"], (0, -p["e"]))),
                (E, (k["K6"], (p["zf"], 0)))]
    springs = [((k["K3"], (p["sd"], -p["sc"])), (p["xc"], p["yc"]), p["c0"], p["l0"])]
    pub = [lr.ANDREWS_NAMES.index(n) for n in names]
    run = exudyn_tree(exu, links, lr.ANDREWS_Q0[pub], lr.ANDREWS_U0[pub], closures,
                      (0, 0, 0), lr.ANDREWS_T_REF, steps, springs,
                      [p["mom"]] + [0.0] * 6)
    back = [names.index(n) for n in lr.ANDREWS_NAMES]

    def published():
        q, qd = run()
        return q[back], qd[back]
    return published


def exudyn_fourbar(exu, P, q0, u0, t_end, steps):
    """The four-bar (links crank, coupler on the crank, rocker: mbdyn's joint
    coordinates) closed at B; ``q0``, ``u0`` in that order."""
    a, b, c, d, w = (P[k] for k in ("a", "b", "c", "d", "w"))

    def izz(m, L):
        return m * (L * L + w * w) / 12
    links = [(-1, (0, 0), (a / 2, 0), P["m2"], izz(P["m2"], a)),
             (0, (a, 0), (b / 2, P["q3"]), P["m3"], izz(P["m3"], b)),
             (-1, (d, 0), (c / 2, 0), P["m4"], izz(P["m4"], c))]
    return exudyn_tree(exu, links, q0, u0, [((1, (b, 0)), (2, (c, 0)))],
                       (0, -P["g"], 0), t_end, steps)


# ---------------------------------------------------------------- runs
def loosest(rtols, error_of, target):
    """The loosest rtol at which ``error_of`` and the next tighter one both meet
    ``target`` (``(rtol, error)``), or ``(None, errors)``."""
    errs = {}
    for i, rtol in enumerate(rtols):
        errs[rtol] = error_of(rtol)
        if errs[rtol] <= target:
            if i + 1 == len(rtols):
                return rtol, errs[rtol]
            nxt = rtols[i + 1]
            errs[nxt] = error_of(nxt)
            if errs[nxt] <= target:
                return rtol, errs[rtol]
    return None, errs


def fewest_steps(error_of, target, first, cap=1_500_000):
    """The smallest ``STEP_BASE * 2^(k/2)`` meeting ``target``: predicted from a run at
    ``first`` steps by second order, then walked down or up the grid.  ``error_of(steps)``
    returns ``(error, end state)``.  Returns ``(steps, error, cpu seconds of that run, its
    end state)`` or ``(None, smallest error, None, None)``."""
    def steps(k):
        return int(round(STEP_BASE * 2 ** (k / 2)))
    cache = {}

    def err(k):
        if k not in cache:
            c0 = time.process_time()
            try:
                e, state = error_of(steps(k))
            except Exception as exc:   # noqa: BLE001 -- a failed run misses the target
                log(f"    exudyn {steps(k)} steps failed: {type(exc).__name__}")
                e, state = float("inf"), None
            cache[k] = (e, time.process_time() - c0, state)
            log(f"    exudyn {steps(k)} steps: error {e:.2e} ({cache[k][1]:.1f} s)")
        return cache[k][0]
    k0 = max(0, round(2 * math.log2(first / STEP_BASE)))
    e0 = err(k0)
    if not math.isfinite(e0):
        return None, e0, None, None
    k = max(0, math.ceil(2 * math.log2(max(first * math.sqrt(e0 / target), 1) / STEP_BASE)))
    if err(k) <= target:
        while k > 0 and err(k - 1) <= target:
            k -= 1
    else:
        while err(k) > target:
            k += 1
            if steps(k) > cap or err(k) > 0.8 * err(k - 1):     # too long, or a floor
                return None, min(v[0] for v in cache.values()), None, None
    return steps(k), cache[k][0], cache[k][1], cache[k][2]


def residuals(model, q, u, t):
    phi, psi = model.constraint_residuals(q, u, t)
    return float(np.abs(phi).max()), float(np.abs(psi).max())


def mechanism_runs(mb, exu, name, model, q0, u0, t_end, error_of_q, scipy_setup, exudyn_setup,
                   targets, rounds):
    """The rows of one mechanism: for each target, mbdyn, scipy, Exudyn."""
    from scipy.integrate import solve_ivp

    def mbdyn_run(rtol):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            return mb.simulate(model, t_end, q0, u0, integrator="DOP853", rtol=rtol,
                               atol=rtol * 1e-3, t_eval=[t_end])
    mbdyn_cache = {}

    def mbdyn_error(rtol):
        if rtol not in mbdyn_cache:
            mbdyn_cache[rtol] = mbdyn_run(rtol)
        r = mbdyn_cache[rtol]
        return error_of_q(r.q[-1])

    rhs, y0, to_mbdyn = scipy_setup
    scipy_cache = {}

    def scipy_run(rtol):
        return solve_ivp(rhs, (0.0, t_end), y0, method="Radau", rtol=rtol, atol=rtol * 1e-3)

    def scipy_error(rtol):
        if rtol not in scipy_cache:
            scipy_cache[rtol] = scipy_run(rtol)
        sol = scipy_cache[rtol]
        if sol.status != 0:
            return float("inf")
        q, u = to_mbdyn(sol.y[:, -1])
        return error_of_q(q)

    rows = []
    for target in targets:
        log(f"  {name}, target {target:g}")
        runs, info = {}, {}
        rtol, err = loosest(RTOLS, mbdyn_error, target)
        if rtol is None:
            NOTES.append(f"{name}: mbdyn DOP853 met {target:g} at none of the rtols "
                         f"(errors {', '.join(f'{k:g}: {v:.1e}' for k, v in err.items())})")
        else:
            r = mbdyn_cache[rtol]
            with warnings.catch_warnings():         # the drift over the run: 201 samples
                warnings.simplefilter("ignore")
                dense = mb.simulate(model, t_end, q0, u0, integrator="DOP853", rtol=rtol,
                                    atol=rtol * 1e-3, t_eval=np.linspace(0.0, t_end, 201))
            s = dense.stats
            info["mbdyn"] = {"solver": "mbdyn DOP853", "setting": f"rtol {rtol:g}",
                             "error": err, "work": f"{r.stats['rhs_evaluations']} evaluations",
                             "drift": residuals(model, r.q[-1], r.u[-1], t_end),
                             "run_drift": {k: s[k] for k in (
                                 "constraint_drift", "constraint_drift_unprojected",
                                 "constraint_drift_velocity")}}
            runs["mbdyn"] = lambda rtol=rtol: mbdyn_run(rtol)
        rtol, err = loosest(RTOLS, scipy_error, target)
        if rtol is None:
            NOTES.append(f"{name}: scipy Radau (index-1 DAE) met {target:g} at none of the "
                         f"rtols (errors {', '.join(f'{k:g}: {v:.1e}' for k, v in err.items())})")
        else:
            sol = scipy_cache[rtol]
            q, u = to_mbdyn(sol.y[:, -1])
            over = np.array([residuals(model, *to_mbdyn(y), t)
                             for t, y in zip(sol.t, sol.y.T)])
            info["scipy"] = {"solver": "scipy Radau, index-1 DAE", "setting": f"rtol {rtol:g}",
                             "error": err, "work": f"{sol.nfev} evaluations, {sol.njev} "
                             "Jacobians", "drift": residuals(model, q, u, t_end),
                             "run_drift": {"position": float(over[:, 0].max()),
                                           "velocity": float(over[:, 1].max()),
                                           "steps": int(sol.t.size - 1)}}
            runs["scipy"] = lambda rtol=rtol: scipy_run(rtol)
        if exu is not None:
            make, first = exudyn_setup

            def exudyn_error(steps):
                q, u = make(steps)()
                return error_of_q(q), (q, u)
            steps, err, cpu, state = fewest_steps(exudyn_error, target, first)
            if steps is None:
                NOTES.append(f"{name}: Exudyn met {target:g} with none of its step counts "
                             f"(smallest error {err:.1e})")
            else:
                run = make(steps)
                q, u = state
                info["exudyn"] = {"solver": "Exudyn generalized-alpha (index 3)",
                                  "setting": f"{steps} fixed steps", "error": err,
                                  "work": f"{steps} steps",
                                  "drift": residuals(model, q, u, t_end), "long": cpu,
                                  "first_cpu": cpu}
                runs["exudyn"] = run
        heavy = "exudyn" in info and info["exudyn"]["long"] > LONG_RUN
        cpu = interleaved_cpu(runs, 1 if heavy else rounds)
        if heavy:                       # one more round of the light ones; Exudyn's
            more = interleaved_cpu({k: v for k, v in runs.items() if k != "exudyn"},
                               max(1, rounds - 1))
            for k, v in more.items():
                cpu[k].extend(v)
            cpu["exudyn"].append(info["exudyn"]["first_cpu"])   # its search run, same n
        med = {k: statistics.median(v) for k, v in cpu.items()}
        for k in ("mbdyn", "scipy", "exudyn"):
            if k in info:
                info[k]["time"] = med[k]
                info[k]["rounds"] = len(cpu[k])
                info[k]["ratio"] = (med["mbdyn"] / med[k]) if "mbdyn" in med else None
        if exu is None:
            info["exudyn"] = {"solver": "Exudyn", "skipped": True}
        rows.append({"mechanism": name, "target": target, "solvers": info})
    return rows


def part_runs(mb, args):
    exu = None if args.no_exudyn else peer("exudyn")
    targets = TARGETS[:1] if args.quick else TARGETS
    rounds = args.rounds
    out = []

    # ---- Andrews' squeezer
    scene = mb.load_model(ROOT / "models" / "andrews_squeezer.toml")
    model = scene.model
    idx = [model.coordinates.index(n) for n in lr.ANDREWS_NAMES]
    jdx = [model.speeds.index(n + "_dot") for n in lr.ANDREWS_NAMES]
    if not check_andrews_dae():
        NOTES.append("WARNING: the scipy Andrews DAE does not reproduce the published "
                     "initial accelerations")

    def andrews_error(q):
        return float(np.abs(np.asarray(q)[idx] - lr.ANDREWS_Q_REF).max())

    def andrews_to_mbdyn(y):
        q, u = np.empty(7), np.empty(7)
        q[idx], u[jdx] = y[:7], y[7:]
        return q, u
    scipy_setup = (andrews_dae(), np.concatenate([lr.ANDREWS_Q0, lr.ANDREWS_U0]),
                   andrews_to_mbdyn)

    def andrews_exudyn(steps):
        run = exudyn_andrews(exu, steps)

        def mapped():
            qp, up = run()
            q, u = andrews_to_mbdyn(np.concatenate([qp, up]))
            return q, u
        return mapped
    log("part 2: Andrews' squeezer")
    out += mechanism_runs(mb, exu, "Andrews' squeezer, 0.03 s", model, scene.q0, scene.u0,
                          lr.ANDREWS_T_REF, andrews_error, scipy_setup,
                          (andrews_exudyn, 8000), targets, rounds)

    # ---- four-bar, free crank
    log("part 2: four-bar (free crank), reference run")
    scene = mb.load_model(ROOT / "models" / "four_bar.toml", case="free")
    model, P, t_end = scene.model, scene.parameters, 2.0
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        ref = mb.simulate(model, t_end, scene.q0, scene.u0, integrator="DOP853", rtol=1e-13,
                          atol=1e-15, t_eval=[t_end])
    q_ref = ref.q[-1].copy()

    def fourbar_error(q):
        return float(np.abs(np.asarray(q) - q_ref).max())
    qa, ua = fourbar_to_absolute(model, scene.q0, scene.u0)

    def fourbar_to_mbdyn(y):
        return fourbar_from_absolute(model, y[:3], y[3:])
    rhs = fourbar_terms(P)
    # the hand-derived equations against mbdyn's at the initial state
    ud = model.forward_dynamics(scene.q0, scene.u0)
    _, uda = fourbar_to_absolute(model, scene.q0, ud)
    mine = rhs(0.0, np.concatenate([qa, ua]))[3:]
    NOTES.append(f"scipy's four-bar DAE (absolute angles, derived here) checked: its "
                 f"accelerations at t = 0 against mbdyn's, relative difference "
                 f"{np.abs(mine - uda).max() / np.abs(uda).max():.1e}.")
    chk = solve_check(rhs, qa, ua, t_end, fourbar_to_mbdyn, q_ref)
    NOTES.append(f"four-bar reference (mbdyn DOP853 rtol 1e-13, atol 1e-15, "
                 f"{ref.stats['rhs_evaluations']} evaluations) against scipy Radau on the "
                 f"independent DAE at rtol 1e-12: largest difference {chk:.1e} rad.")
    names = ("crank", "coupler", "rocker")
    ci = [model.coordinates.index(n) for n in names]
    si = [model.speeds.index(n + "_dot") for n in names]

    def fourbar_exudyn(steps):
        run = exudyn_fourbar(exu, P, scene.q0[ci], scene.u0[si], t_end, steps)

        def mapped():
            qe, ue = run()
            q, u = np.empty(3), np.empty(3)
            q[ci], u[si] = qe, ue
            return q, u
        return mapped
    log("part 2: four-bar (free crank)")
    out += mechanism_runs(mb, exu, "four-bar (free crank), 2 s", model, scene.q0, scene.u0,
                          t_end, fourbar_error,
                          (rhs, np.concatenate([qa, ua]), fourbar_to_mbdyn),
                          (fourbar_exudyn, 8000), targets, rounds)
    return out


def solve_check(rhs, qa, ua, t_end, to_mbdyn, q_ref):
    from scipy.integrate import solve_ivp
    sol = solve_ivp(rhs, (0.0, t_end), np.concatenate([qa, ua]), method="Radau",
                    rtol=1e-12, atol=1e-15)
    q, _ = to_mbdyn(sol.y[:, -1])
    return float(np.abs(q - q_ref).max())


def table_runs(rows):
    out = ["| mechanism | target (rad) | solver | setting | error (rad) | work | CPU time (s) "
           "| mbdyn / this | drift: position | velocity |",
           "|---|---:|---|---|---:|---|---:|---:|---:|---:|"]
    for r in rows:
        for key in ("mbdyn", "scipy", "exudyn"):
            s = r["solvers"].get(key)
            if s is None:
                continue
            if s.get("skipped"):
                out.append(f"| {r['mechanism']} | {r['target']:g} | Exudyn | skipped "
                           "(not installed, or --no-exudyn) | | | | | | |")
                continue
            ratio = "" if key == "mbdyn" or s.get("ratio") is None else f"**{s['ratio']:.2g}**"
            dp, dv = s["drift"]
            out.append(f"| {r['mechanism']} | {r['target']:g} | {s['solver']} | "
                       f"{s['setting']} | {s['error']:.1e} | {s['work']} | "
                       f"{s['time']:.4g} | {ratio} | {dp:.1e} | {dv:.1e} |")
    return "\n".join(out)


# =========================================================================== main
def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--quick", action="store_true",
                    help="fewer rounds; whole runs at the 1e-6 target only")
    ap.add_argument("--json", action="store_true", help="machine-readable output on stdout")
    ap.add_argument("--only", choices=("calls", "runs"), help="one part only")
    ap.add_argument("--budget", type=float, default=None,
                    help="seconds per per-call measurement (default 2, quick 0.6)")
    ap.add_argument("--repeats", type=int, default=None,
                    help="rounds of the per-call measurements (default 11, quick 5)")
    ap.add_argument("--rounds", type=int, default=None,
                    help="rounds of the whole runs (default 3, quick 1)")
    ap.add_argument("--no-exudyn", action="store_true", help="skip Exudyn")
    args = ap.parse_args()
    args.budget = args.budget or (0.6 if args.quick else 2.0)
    args.repeats = args.repeats or (5 if args.quick else 11)
    args.rounds = args.rounds or (1 if args.quick else 3)
    import mbdyn as mb
    started = time.perf_counter()
    versions = {"python": platform.python_version(), "numpy": np.__version__}
    for mod in ("numba", "scipy", "exudyn"):
        try:
            versions[mod] = importlib.import_module(mod).__version__
        except ImportError:
            versions[mod] = "not installed"
    result = {"versions": versions, "machine": platform.machine(), "notes": NOTES}
    if args.only in (None, "calls"):
        result["calls"] = part_calls(mb, args)
    if args.only in (None, "runs"):
        result["runs"] = part_runs(mb, args)
    result["seconds"] = time.perf_counter() - started
    if args.json:
        print(json.dumps(result, indent=1, default=str))
        return
    print(f"mbdyn closed loops, {time.strftime('%Y-%m-%d')}: " + ", ".join(
        f"{k} {v}" for k, v in versions.items()) + f"; {os.cpu_count()} CPUs\n")
    if "calls" in result:
        print("### One evaluation: closed mechanism against the same bodies as a tree\n")
        print(table_calls(result["calls"]))
        print("\nratio = loop / tree (goal: <= 2).  RK4 runs: "
              + "; ".join(f"{k} {v['rk4']['steps']} steps of {v['rk4']['dt']:g} s, drift "
                          f"{v['rk4']['drift']:.1e}" for k, v in result["calls"].items()))
        print("\nThe tree's low-level entry, `model.lowlevel().forward_dynamics(q, u, t, out)`"
              ": " + ", ".join(f"{k} {v['lowlevel_tree_us']:.2f} µs"
                               for k, v in result["calls"].items())
              + ".  A closed mechanism has no low-level entry of its own (its `lowlevel()` "
              "evaluates the tree without the constraints).")
        print()
    if "runs" in result:
        print("### Whole runs at equal accuracy\n")
        print(table_runs(result["runs"]))
        print("\nmbdyn / this = mbdyn's CPU time over this solver's (goal against Exudyn: "
              "<= 0.5).  Drift: largest constraint residual at the end state (positions, "
              "velocities), by mbdyn's `constraint_residuals`.  Over the runs (mbdyn: the "
              "same run with 201 output times, its `stats`; scipy: every step):\n")
        for r in result["runs"]:
            s = r["solvers"].get("mbdyn")
            if s:
                d = s["run_drift"]
                print(f"* {r['mechanism']}, mbdyn {s['setting']}: constraint_drift "
                      f"{d['constraint_drift']:.1e}, constraint_drift_unprojected "
                      f"{d['constraint_drift_unprojected']:.1e}, constraint_drift_velocity "
                      f"{d['constraint_drift_velocity']:.1e}")
            s = r["solvers"].get("scipy")
            if s:
                d = s["run_drift"]
                print(f"* {r['mechanism']}, scipy {s['setting']}: largest |phi| "
                      f"{d['position']:.1e}, |psi| {d['velocity']:.1e} over its "
                      f"{d['steps']} steps")
        print()
    if NOTES:
        print("Notes:\n")
        for n in NOTES:
            print(f"* {n}")
    print(f"\n({result['seconds']:.0f} s)")


if __name__ == "__main__":
    main()
