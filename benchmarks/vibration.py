#!/usr/bin/env python
"""What vibration analysis costs.

    python benchmarks/vibration.py           # about a minute

Tables (medians of repeated runs, seconds):

1. Linearisation and modes against the degrees of freedom: chains of n revolute links
   (alternating x/y axes, n = 2 ... 100) and spherical links (3 DoF each), numeric route
   (central differences of the compiled model: 4 evaluations per coordinate and speed) and
   eigen-analysis of the 2n x 2n state matrix.
2. The symbolic route (closed-form equations, exact derivatives) for small chains, with
   the derivation's own time shown apart.
3. Time per point of a Campbell sweep: the Jeffcott rotor model (6 DoF, tabulated
   bearings): rebuild from the file, equilibrium, linearisation, modes, tracking.
"""
import os

for _var in ("OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "OMP_NUM_THREADS"):
    os.environ[_var] = "1"

import sys  # noqa: E402
import time  # noqa: E402
import warnings  # noqa: E402
from pathlib import Path  # noqa: E402

import numpy as np  # noqa: E402

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))
import mbdyn as mb  # noqa: E402
from mbdyn.symbolic import derive  # noqa: E402


def chain(n, kind):
    s = mb.System(f"{kind} chain", gravity=(0, 0, -9.81))
    parent = "ground"
    for i in range(n):
        s.add_body(f"b{i}", mass=1.0, com=(0, 0, -0.1), inertia=[0.01, 0.012, 0.002])
        kw = {"axis": "x" if i % 2 else "y"} if kind == "revolute" else {}
        s.add_joint(f"j{i}", kind, parent=parent, child=f"b{i}",
                    position=(0, 0, -0.2 if i else 0), **kw)
        parent = f"b{i}"
    return s.compile()


def median_time(fn, repeats=5, budget=4.0):
    out = []
    t_start = time.perf_counter()
    for _ in range(repeats):
        t0 = time.perf_counter()
        fn()
        out.append(time.perf_counter() - t0)
        if time.perf_counter() - t_start > budget:
            break
    return float(np.median(out))


def main():
    warnings.simplefilter("ignore")
    print("1. Numeric linearisation and modes (s, medians)")
    print(f"{'joint':<10} {'n':>4} {'dof':>5} {'linearize':>11} {'modes':>9} {'per dof':>10}")
    for kind, sizes in (("revolute", (2, 5, 10, 20, 50, 100)), ("spherical", (2, 5, 10, 20))):
        for n in sizes:
            model = chain(n, kind)
            q = model.default_coordinates()
            rng = np.random.default_rng(0)
            if kind == "revolute":
                q = q + rng.uniform(-0.2, 0.2, model.nq)
            lin_holder = {}

            def lin():
                lin_holder["lin"] = mb.linearize(model, q)
            t_lin = median_time(lin, repeats=3 if n >= 50 else 5)
            t_modes = median_time(lambda: mb.modes(lin_holder["lin"]))
            print(f"{kind:<10} {n:>4} {model.nu:>5} {t_lin:>11.4f} {t_modes:>9.4f} "
                  f"{t_lin / model.nu:>10.2e}")
    print("\n2. Symbolic route (derivation + exact derivatives) vs numeric (s)")
    print("(derive: the first derivation; symbolic: linearize(route=\"symbolic\"), which derives again\n with sympy's caches warm, then differentiates exactly)")
    print(f"{'joint':<10} {'n':>4} {'derive':>9} {'symbolic':>10} {'numeric':>9} "
          f"{'max |A_sym - A_num| / |A|':>26}")
    for kind, n in (("revolute", 2), ("revolute", 4), ("revolute", 6), ("spherical", 2),
                    ("spherical", 3)):
        model = chain(n, kind)
        q = model.default_coordinates()
        if kind == "revolute":
            q = q + np.random.default_rng(1).uniform(-0.2, 0.2, model.nq)
        t0 = time.perf_counter()
        derive(model, "jourdain", measure=False)
        t_der = time.perf_counter() - t0
        t0 = time.perf_counter()
        a = mb.linearize(model, q, route="symbolic")
        t_sym = time.perf_counter() - t0
        t0 = time.perf_counter()
        b = mb.linearize(model, q)
        t_num = time.perf_counter() - t0
        diff = np.abs(a.A - b.A).max() / np.abs(a.A).max()
        print(f"{kind:<10} {n:>4} {t_der:>9.3f} {t_sym:>10.3f} {t_num:>9.4f} {diff:>26.2e}")
    print("\n3. Campbell sweep of models/jeffcott_rotor.toml (6 DoF)")
    sc = mb.load_model(ROOT / "models/jeffcott_rotor.toml")
    for points in (6, 16):
        t = median_time(lambda: mb.campbell(sc, "Omega", np.linspace(50, 800, points),
                                            whirl=[("y", "z")]), repeats=3)
        print(f"{points:>3} points: {t:.3f} s, {t / points * 1e3:.1f} ms per point")


if __name__ == "__main__":
    main()
