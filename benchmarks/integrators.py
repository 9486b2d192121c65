#!/usr/bin/env python
"""Cost per step and per right-hand-side evaluation of each integrator.

    python benchmarks/integrators.py [--rounds 5]

Two models: the textbook double pendulum (2 speeds, ``M u' = f``) and a 20-link ball
chain (60 speeds, the articulated-body route that ``auto`` picks there), each run over a
fixed span with every integrator of ``mb.INTEGRATORS`` (the fixed-step ones at a step
that keeps them stable, the adaptive ones at rtol = atol = 1e-9).  Prints, per integrator,
the median CPU time of the run (a subprocess-free ``time.process_time`` after a warm-up
run that compiles), the steps, the right-hand-side evaluations and the cost per step and
per evaluation.  ``compiled`` says whether the run made no Python call per step.
"""
from __future__ import annotations

import os

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import argparse  # noqa: E402
import statistics  # noqa: E402
import sys  # noqa: E402
import time  # noqa: E402

import numpy as np  # noqa: E402

import mbdyn as mb  # noqa: E402

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
from formulations import chain  # noqa: E402


def double_pendulum():
    scene = mb.load_model(os.path.join(HERE, "..", "models", "double_pendulum.toml"))
    return "double pendulum (nu=2)", scene.model, scene.q0, scene.u0, 1.0, 1e-4


def ball_chain():
    m, q, u = chain(20, "spherical")
    return "ball chain n=20 (nu=60)", m, q, 0.1 * u, 0.2, 1e-4


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--rounds", type=int, default=5)
    args = ap.parse_args(argv)
    print("| model | integrator | route | compiled | steps | evaluations | CPU s "
          "| us / step | us / evaluation |")
    print("|---|---|---|---|---:|---:|---:|---:|---:|")
    for name, m, q, u, t_end, dt in (double_pendulum(), ball_chain()):
        for integ in mb.INTEGRATORS:
            if integ in ("Radau", "BDF", "LSODA", "RK23"):
                continue                   # scipy's own; their cost is scipy's
            kw = {"dt": dt} if integ in mb.FIXED_STEP else {"rtol": 1e-9,
                                                                     "atol": 1e-9}
            run = lambda: mb.simulate(m, t_end, q, u, integrator=integ, **kw)  # noqa: E731
            res = run()                    # compiles
            times = []
            for _ in range(args.rounds):
                t0 = time.process_time()
                res = run()
                times.append(time.process_time() - t0)
            cpu = statistics.median(times)
            st = res.stats
            steps = st.get("steps") or len(res.t) - 1
            nfev = st["rhs_evaluations"]
            compiled = bool(st.get("compiled", integ in mb.FIXED_STEP))
            print(f"| {name} | {integ} | {st['method']} | {'yes' if compiled else 'no'} "
                  f"| {steps} | {nfev} | {cpu:.3f} | {cpu / max(steps, 1) * 1e6:.1f} "
                  f"| {cpu / max(nfev, 1) * 1e6:.2f} |")


if __name__ == "__main__":
    main()
