#!/usr/bin/env python
"""Cost of one forward-dynamics call by each route, against the size of the model.

    python benchmarks/formulations.py            # chains of 1 .. 100 links (about a minute)
    python benchmarks/formulations.py --quick    # fewer sizes and rounds
    python benchmarks/formulations.py --json     # machine-readable output on stdout

Chains of n links joined by revolute joints (axes alternating x / y, a 3D chain) and by
spherical joints, real inertia on every link.  Per call, in microseconds (medians over
interleaved rounds, each round a block of calls, gc off, BLAS pinned to one thread):

* ``lowlevel jourdain`` / ``lowlevel articulated``: ``Model.lowlevel(method)`` -- one
  compiled call on preallocated buffers, the cheapest way to call the engine;
* ``checked jourdain``, ``checked articulated``, ``checked NE tree``, ``checked NE
  dense``: ``Model.forward_dynamics(q, u, method=...)`` (input checks, a copy of the
  result); NE is the Newton-Euler system with reactions, solved in tree order or dense.

The ratio columns divide by ``lowlevel jourdain`` of the same round.  The ``auto`` column
says which route ``Model.formulation()`` picks at that size.
"""
from __future__ import annotations

import os

for _var in ("OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "OMP_NUM_THREADS"):
    os.environ[_var] = "1"

import argparse  # noqa: E402
import gc  # noqa: E402
import json  # noqa: E402
import statistics  # noqa: E402
import time  # noqa: E402

import numpy as np  # noqa: E402

import mbdyn as mb  # noqa: E402


def chain(n, kind):
    """``n`` cylinders (1 kg, 0.1 m) hanging from ``kind`` joints, and a random state."""
    s = mb.System(f"{kind} chain {n}", gravity=(0, 0, -9.81))
    inertia = mb.inertia.cylinder(1.0, 0.01, 0.1)
    parent = "ground"
    for i in range(n):
        s.add_body(f"link{i}", mass=1.0, com=(0, 0, -0.05), inertia=inertia)
        extra = {"axis": "x" if i % 2 == 0 else "y"} if kind == "revolute" else {}
        s.add_joint(f"j{i}", kind, parent, f"link{i}",
                    position=(0, 0, -0.1) if i else (0, 0, 0), **extra)
        parent = f"link{i}"
    m = s.compile()
    rng = np.random.default_rng(n)
    q = m.default_coordinates()
    if kind == "revolute":
        q = rng.uniform(-1, 1, m.nq)
    else:
        for k in range(n):
            v = rng.normal(size=3) * 0.3
            a = np.linalg.norm(v)
            q[4 * k:4 * k + 4] = [np.cos(a / 2), *(np.sin(a / 2) * v / a)]
    return m, q, rng.normal(size=m.nu)


def routes(m, q, u):
    """The callables timed, by column name."""
    lj, la = m.lowlevel("jourdain"), m.lowlevel("articulated")
    return {
        "lowlevel jourdain": lambda: lj.forward_dynamics(q, u),
        "lowlevel articulated": lambda: la.forward_dynamics(q, u),
        "checked jourdain": lambda: m.forward_dynamics(q, u, method="jourdain"),
        "checked articulated": lambda: m.forward_dynamics(q, u, method="articulated"),
        "checked NE tree": lambda: m.forward_dynamics(q, u, method="newton-euler"),
        "checked NE dense": lambda: m.forward_dynamics(q, u, method="newton-euler-dense"),
    }


def measure(fns, rounds, budget):
    """Median microseconds per call of each callable, measured round by round."""
    for fn in fns.values():              # warm-up (and compile)
        fn()
    block = {}
    for name, fn in fns.items():         # calls per block: about budget / rounds seconds
        t0 = time.perf_counter()
        k = 0
        while time.perf_counter() - t0 < 0.01:
            fn()
            k += 1
        block[name] = max(1, int(k * budget / rounds / 0.01 / len(fns)))
    samples = {name: [] for name in fns}
    gc.disable()
    try:
        for _ in range(rounds):
            for name, fn in fns.items():
                k = block[name]
                t0 = time.perf_counter()
                for _ in range(k):
                    fn()
                samples[name].append((time.perf_counter() - t0) / k * 1e6)
    finally:
        gc.enable()
    return {name: statistics.median(v) for name, v in samples.items()}


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--quick", action="store_true", help="sizes 2, 20, 100; fewer rounds")
    ap.add_argument("--json", action="store_true", help="JSON on stdout instead of a table")
    ap.add_argument("--budget", type=float, default=1.0, help="seconds per size (default 1)")
    args = ap.parse_args(argv)
    sizes = (2, 20, 100) if args.quick else (1, 2, 3, 5, 8, 10, 20, 50, 100)
    rounds = 5 if args.quick else 9
    rows = []
    for kind in ("revolute", "spherical"):
        for n in sizes:
            m, q, u = chain(n, kind)
            times = measure(routes(m, q, u), rounds, args.budget)
            rows.append({"kind": kind, "n": n, "nu": m.nu, "auto": m.formulation(),
                         **times})
    if args.json:
        json.dump(rows, __import__("sys").stdout, indent=1)
        return
    cols = list(routes(*chain(1, "revolute")).keys())
    print("| chain | n | nu | auto | " + " | ".join(c + " (us)" for c in cols)
          + " | articulated / jourdain (lowlevel) | NE tree / jourdain (checked) |")
    print("|---" * (4 + len(cols) + 2) + "|")
    for r in rows:
        print(f"| {r['kind']} | {r['n']} | {r['nu']} | {r['auto']} | "
              + " | ".join(f"{r[c]:.2f}" for c in cols)
              + f" | {r['lowlevel articulated'] / r['lowlevel jourdain']:.2f}"
              + f" | {r['checked NE tree'] / r['checked jourdain']:.2f} |")


if __name__ == "__main__":
    main()
