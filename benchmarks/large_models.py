"""Memory and time of large models: a chain and a star of revolute links, compiled and
one step taken, each in a fresh process.

    python benchmarks/large_models.py [--sizes 1000,2000] [--kinds chain,star] [--tree DIR]

The issue's goal (29): a 10,000-body chain and a 5,000-body star compile and take a step
in well under 1 GB and a few seconds.  Prints a markdown table: the times of building the
``System``, compiling it and the first step (``simulate`` of one rk4 step); the peak
resident memory of the process (``ru_maxrss``), and its growth over the peak before the
model was built (the interpreter, numpy, numba and the kernels, loaded by an 8-body model
first: about 215 MB); the model's own arrays (the packed buffers and the arrays of the
Jourdain route beside them, if allocated).  ``--tree`` measures another checkout (a
baseline) with the same script.
"""
from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys

HERE = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))

SNIPPET = r"""
import json, resource, sys, time
import numpy as np
import mbdyn as mb
kind, n = sys.argv[1], int(sys.argv[2])

def system(n):
    s = mb.System(f"{kind} {n}", gravity=(0, -9.81, 0))
    parent = "ground"
    for i in range(n):
        s.add_body(f"b{i}", mass=1.0, com=(0.1, 0, 0), inertia=(1e-3, 1e-3, 1e-3))
        s.add_joint(f"j{i}", "revolute", parent=parent, child=f"b{i}", axis="z",
                    position=(0.1, 0, 0) if (kind == "chain" and i) else (0, 0, 0.01 * i))
        if kind == "chain":
            parent = f"b{i}"
    return s

def peak_mb():
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024

mb.simulate(system(8).compile(), 1e-3, integrator="rk4", dt=1e-3)    # the kernels loaded
floor = peak_mb()
t0 = time.perf_counter()
s = system(n)
t1 = time.perf_counter()
m = s.compile()
t2 = time.perf_counter()
res = mb.simulate(m, 1e-3, integrator="rk4", dt=1e-3)
t3 = time.perf_counter()
held = sum(b.nbytes for b in m._packed[:2])
held += sum(a.nbytes for a in (m._JR, m._JT, m._M, m._L, m._anc_idx) if a.base is None)
print(json.dumps({"build": t1 - t0, "compile": t2 - t1, "step": t3 - t2, "peak_MB": peak_mb(),
                  "growth_MB": peak_mb() - floor, "held_MB": held / 2**20,
                  "method": res.stats["method"], "finite": bool(np.isfinite(res.u).all())}))
"""


def measure(kind, n, tree):
    env = dict(os.environ, PYTHONPATH=tree, OPENBLAS_NUM_THREADS="1")
    proc = subprocess.run([sys.executable, "-c", SNIPPET, kind, str(n)], env=env,
                          capture_output=True, text=True, cwd=tree, timeout=1800)
    if proc.returncode:
        last = (proc.stderr.strip().splitlines() or ["?"])[-1]
        return {"error": last[:120]}
    return json.loads(proc.stdout.strip().splitlines()[-1])


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--sizes", default="1000,2000,5000,10000")
    ap.add_argument("--kinds", default="chain,star")
    ap.add_argument("--tree", default=HERE, help="checkout to measure (default this one)")
    args = ap.parse_args()
    print("| model | build s | compile s | first step s | peak MB | growth MB | model arrays MB "
          "| route |")
    print("|---|---:|---:|---:|---:|---:|---:|---|")
    for kind in args.kinds.split(","):
        for n in map(int, args.sizes.split(",")):
            r = measure(kind, n, args.tree)
            if "error" in r:
                print(f"| {kind} {n} | | | | | | | failed: {r['error']} |")
            else:
                print(f"| {kind} {n} | {r['build']:.2f} | {r['compile']:.2f} | "
                      f"{r['step']:.2f} | {r['peak_MB']:.0f} | {r['growth_MB']:.0f} | "
                      f"{r['held_MB']:.1f} | {r['method']} |", flush=True)


if __name__ == "__main__":
    main()
