#!/usr/bin/env python
"""The two formulations of a model with flexible bodies (issue 26, item 5): the cost of
``forward_dynamics`` by the Jourdain route (``M u' = f``, the flexible terms projected
on the speeds) and by the Newton-Euler system with reaction unknowns (one LU solve of
``6 n + modal (+ loop rows)`` unknowns, docs/flexible.md, "Two formulations"), and of
``reactions`` by each (inverse dynamics after the Jourdain accelerations, or the same
solve).

    python benchmarks/flexible_newton_euler.py        # a table (about half a minute)

CPU time of blocks of 100 calls, interleaved, medians; the ratio is to the Jourdain
route's in the same run.
"""
import os

for _var in ("OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "OMP_NUM_THREADS"):
    os.environ[_var] = "1"

import statistics  # noqa: E402
import sys  # noqa: E402
import warnings  # noqa: E402
from pathlib import Path  # noqa: E402

import numpy as np  # noqa: E402

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))
import mbdyn as mb  # noqa: E402
from timing import interleaved_cpu  # noqa: E402  (this folder)

ROOT = Path(__file__).resolve().parent.parent


def pinned(pendulum):
    s = mb.System("pinned beam", gravity=(0, -9.81, 0))
    beam = {"length": 1.0, "elements": 8, "E": 7e10, "rho": 2700.0, "rect": [0.03, 0.02]}
    s.add_body("beam", flexible={"beam": beam, "modes": 3})
    s.add_joint("pin", "revolute", "ground", "beam", axis="z")
    if pendulum:
        s.add_body("bob", mass=0.5, com=(0, -0.2, 0), inertia=[1e-3] * 3)
        s.add_joint("hang", "revolute", "beam", "bob", axis="z", position="tip")
    return s.compile()


def main(rounds=9, calls=100):
    warnings.simplefilter("ignore")
    models = {"beam on a pin, 3 modes": pinned(False),
              "the same, a pendulum at its tip (node frame)": pinned(True),
              "flexible slider-crank, 4 modes (loop)":
                  mb.load_model(ROOT / "models" / "flexible_slider_crank.toml").model,
              "flexible rotor, 16 modes, bearings at nodes":
                  mb.load_model(ROOT / "models" / "jeffcott_flexible.toml").model}
    print("| model | route | us CPU per forward_dynamics | ratio | us CPU per reactions "
          "| ratio |")
    print("|---|---|---|---|---|---|")
    for name, m in models.items():
        q, u = m.default_coordinates(), np.full(m.nu, 1e-3)
        if m.has_loops:
            q, u = m.project(q + 0.3, u)
        runs = {}
        for route, method in (("jourdain", "jourdain"), ("newton-euler", "newton-euler")):
            runs[("fd", route)] = (lambda m=m, q=q, u=u, method=method:
                                   [m.forward_dynamics(q, u, 0.01, method) for _ in
                                    range(calls)])
            how = "auto" if route == "jourdain" else method
            runs[("r", route)] = (lambda m=m, q=q, u=u, how=how:
                                  [m.reactions(q, u, 0.01, how) for _ in range(calls)])
        cpu = interleaved_cpu(runs, rounds)
        med = {k: statistics.median(v) / calls * 1e6 for k, v in cpu.items()}
        for route in ("jourdain", "newton-euler"):
            fd, r = med[("fd", route)], med[("r", route)]
            print(f"| {name} | {route} | {fd:.0f} | {fd / med[('fd', 'jourdain')]:.2f} | "
                  f"{r:.0f} | {r / med[('r', 'jourdain')]:.2f} |")


if __name__ == "__main__":
    main()
