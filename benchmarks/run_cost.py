"""Cost of whole runs, this tree against a baseline checkout, measured in one session.

    python benchmarks/run_cost.py [--baseline DIR] [--repeats N]

Each tree runs in its own subprocess (``PYTHONPATH=tree``), alternating, after one
untimed warm-up each (numba compiles into each tree's own cache); in each process a short
untimed run comes first, so that imports and the first call's dispatch are not counted
(``benchmarks/first_start.py`` measures those).  Measures: the
textbook double pendulum over 4 s with DOP853 at rtol 1e-9 (compiled stretches of
adaptive steps since kernels/adaptive.py; scipy's solver stepped from Python before) and
with rk4 at dt = 4/48000 (the compiled fixed-step loop); medians of wall time and the ratio HEAD / baseline.  Prints a
markdown table.  With no ``--baseline`` only this tree is measured.
"""
from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys

HERE = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))

SNIPPET = r"""
import json, os, sys, time
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
import numpy as np
import mbdyn as mb
s = mb.System("double pendulum", gravity=(0, -9.81, 0))
s.add_body("link1", mass=0.00046, com=(0, -0.07, 0))
s.add_body("link2", mass=0.0046, com=(0, -0.07, 0))
s.add_joint("theta1", "revolute", "ground", "link1", axis="-z")
s.add_joint("theta2", "revolute", "link1", "link2", axis="-z", position=(0, -0.07, 0))
m = s.compile()
q0 = {"theta1": -np.pi / 4, "theta2": np.pi / 4}
simulate = mb.simulate        # resolved (and imported) before any timing
out = {}
for name, kw in (("DOP853 rtol 1e-9", dict(integrator="DOP853", rtol=1e-9, atol=1e-12)),
                 ("rk4, 48000 steps", dict(integrator="rk4", dt=4 / 48000))):
    simulate(m, 0.01, q0, **kw)      # first call in the process: dispatch, cache loading
    start = time.perf_counter()
    simulate(m, 4.0, q0, **kw)
    out[name] = time.perf_counter() - start
print(json.dumps(out))
"""


def measure(tree):
    env = dict(os.environ, PYTHONPATH=tree, OPENBLAS_NUM_THREADS="1")
    proc = subprocess.run([sys.executable, "-c", SNIPPET], env=env, capture_output=True,
                          text=True, cwd=tree, check=True)
    return json.loads(proc.stdout.strip().splitlines()[-1])


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--baseline", help="a checkout of the baseline commit")
    ap.add_argument("--repeats", type=int, default=5)
    args = ap.parse_args()
    trees = [("HEAD", HERE)] + ([("baseline", os.path.abspath(args.baseline))]
                                if args.baseline else [])
    for _, tree in trees:                      # warm-up: compile into each tree's cache
        measure(tree)
    times = {label: {} for label, _ in trees}
    for _ in range(args.repeats):
        for label, tree in trees:
            for case, wall in measure(tree).items():
                times[label].setdefault(case, []).append(wall)
    cases = list(times["HEAD"])
    head = "| case | HEAD median (s) |" + (" baseline median (s) | ratio |" if args.baseline
                                           else "")
    print(head)
    print("|---|---|" + ("---|---|" if args.baseline else ""))
    for case in cases:
        h = statistics.median(times["HEAD"][case])
        row = f"| {case} | {h:.3f} |"
        if args.baseline:
            b = statistics.median(times["baseline"][case])
            row += f" {b:.3f} | {h / b:.2f} |"
        print(row)


if __name__ == "__main__":
    main()
