#!/usr/bin/env python
"""What a flexible body costs per evaluation (issue 26), against the number of modes and
of beam elements, and against the same body rigid.

    python benchmarks/flexible.py            # a table (about half a minute)

A steel shaft (1 m, 20 mm) on a revolute joint of the ground, its frame at the root,
spinning: medians (us) of ``Model.forward_dynamics`` at a random state.  The flexible
terms are evaluated in Python (numpy) on top of the compiled tree by default, or by the
compiled function (``model.compiled_terms = True``, opt-in; docs/flexible.md, "Routes
and cost"); the rigid body is the compiled route.  The number of beam elements
changes only the reduction (done once, at compile), not an evaluation: the table shows
it.  Exudyn's ``ObjectFFRFreducedOrder`` is not compared here (see the issue's note).

The second table: the flexible rotor models/jeffcott_flexible.toml (16 modes) with and
without its bearings and unbalance load at nodes (Python, ``algorithms.flexible_forces``),
against the rigid models/jeffcott_rotor.toml (compiled): CPU time of blocks of 200
evaluations, interleaved, medians.

The third table: joints at nodes and closed loops through a flexible body (Python): a
beam on a pin (3 modes) with and without a pendulum hanging from its tip (a node frame
in the tree), and the flexible slider-crank models/flexible_slider_crank.toml (4 modes,
the loop at the rod's tip: the constrained solve in Python) against the same with its
rod rigid (``-flexibility_rod``: the compiled closed-loop route); with a run of its
0.1 s at the file's tolerance, numpy's terms and scipy against the compiled terms and
loops (the same run to the tolerance).

    python benchmarks/flexible.py --cold     # also: the compiled function's first use

``--cold``: the CPU seconds numba takes for each kind of compiled function (plain, with
force elements, with loops) in a fresh process on an empty numba cache (after the tree's
kernels, which every model compiles); a few minutes.
"""
import os

for _var in ("OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "OMP_NUM_THREADS"):
    os.environ[_var] = "1"

import sys  # noqa: E402
import warnings  # noqa: E402
from pathlib import Path  # noqa: E402
from time import perf_counter  # noqa: E402

import numpy as np  # noqa: E402

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))
import mbdyn as mb  # noqa: E402
from timing import interleaved_cpu, per_call  # noqa: E402  (this folder)

ROOT = Path(__file__).resolve().parent.parent


def shaft(modes, elements):
    s = mb.System("shaft", gravity=(0, 0, -9.81))
    beam = {"length": 1.0, "elements": elements, "E": 2.1e11, "rho": 7850.0, "nu": 0.3,
            "section": {"circle": 0.02}}
    s.add_body("shaft", flexible={"beam": beam, "modes": modes})
    s.add_joint("spin", "revolute", parent="ground", child="shaft", axis="z")
    return s


def main():
    warnings.simplefilter("ignore")
    rng = np.random.default_rng(0)
    rigid = shaft(2, 10).compile(effects="-flexibility_shaft")
    q, u = rng.normal(size=rigid.nq), rng.normal(size=rigid.nu)
    base = per_call(lambda: rigid.forward_dynamics(q, u), rounds=11, most=1 << 18)
    t0 = perf_counter()
    print("| modes | elements | us per forward_dynamics, numpy | compiled terms | "
          "numpy / compiled | compiled / rigid | compile (s) |")
    print("|---|---|---|---|---|---|---|")
    print(f"| rigid | - | - | {base:.2f} | - | 1.0 | - |")
    for modes, elements in ((2, 10), (4, 10), (8, 10), (4, 5), (4, 20), (4, 40)):
        t0 = perf_counter()
        m = shaft(modes, elements).compile()
        build = perf_counter() - t0
        q, u = rng.normal(size=m.nq) * 1e-3, rng.normal(size=m.nu) * 1e-3
        c = per_call(lambda m=m, q=q, u=u: m.forward_dynamics(q, u), rounds=11,
                     most=1 << 18)
        m.compiled_terms = True
        k = per_call(lambda m=m, q=q, u=u: m.forward_dynamics(q, u), rounds=11,
                     most=1 << 18)
        print(f"| {modes} | {elements} | {c:.1f} | {k:.1f} | {c / k:.0f} | {k / base:.1f} "
              f"| {build:.2f} |")



def node_elements(rounds=9, calls=200):
    """Cost of loads and force elements at a flexible rotor's nodes."""
    import statistics
    models = {
        "flexible rotor, 2 bearings + load at nodes": mb.load_model(
            ROOT / "models" / "jeffcott_flexible.toml").model,
        "the same, compiled terms": _compiled(mb.load_model(
            ROOT / "models" / "jeffcott_flexible.toml").model),
        "flexible rotor, elements off": mb.load_model(
            ROOT / "models" / "jeffcott_flexible.toml",
            effects="-left_bearing,-right_bearing,-unbalance").model,
        "rigid jeffcott_rotor.toml (compiled)": mb.load_model(
            ROOT / "models" / "jeffcott_rotor.toml").model}

    def block(m):
        q, u = m.default_coordinates(), np.full(m.nu, 1e-3)
        return lambda: [m.forward_dynamics(q, u, 0.1) for _ in range(calls)]
    cpu = interleaved_cpu({k: block(m) for k, m in models.items()}, rounds)
    med = {k: statistics.median(v) / calls * 1e6 for k, v in cpu.items()}
    base = med["rigid jeffcott_rotor.toml (compiled)"]
    print("\n| model | us CPU per forward_dynamics | ratio to the rigid rotor |")
    print("|---|---|---|")
    for k, v in med.items():
        print(f"| {k} | {v:.1f} | {v / base:.0f} |")


def at_nodes(rounds=9, calls=100):
    """Cost of a joint at a node and of a loop through a flexible body."""
    import statistics

    def pinned(pendulum):
        s = mb.System("pinned beam", gravity=(0, -9.81, 0))
        beam = {"length": 1.0, "elements": 8, "E": 7e10, "rho": 2700.0, "rect": [0.03, 0.02]}
        s.add_body("beam", flexible={"beam": beam, "modes": 3})
        s.add_joint("pin", "revolute", "ground", "beam", axis="z")
        if pendulum:
            s.add_body("bob", mass=0.5, com=(0, -0.2, 0), inertia=[1e-3] * 3)
            s.add_joint("hang", "revolute", "beam", "bob", axis="z", position="tip")
        return s.compile()
    crank = ROOT / "models" / "flexible_slider_crank.toml"
    models = {"beam on a pin, 3 modes": pinned(False),
              "the same, a pendulum at its tip (node frame)": pinned(True),
              "slider-crank, rod rigid (compiled closed loop)":
                  mb.load_model(crank, effects="-flexibility_rod").model,
              "flexible slider-crank, 4 modes (loop at the rod's tip)":
                  mb.load_model(crank).model,
              "the same, numpy's terms": mb.load_model(crank).model,
              "the same, compiled terms": _compiled(mb.load_model(crank).model)}

    def block(m):
        q, u = m.default_coordinates(), np.full(m.nu, 1e-3)
        if m.has_loops:
            q, u = m.project(q + 0.3, u)
        return lambda: [m.forward_dynamics(q, u, 0.01) for _ in range(calls)]
    cpu = interleaved_cpu({k: block(m) for k, m in models.items()}, rounds)
    med = {k: statistics.median(v) / calls * 1e6 for k, v in cpu.items()}
    print("\n| model | us CPU per forward_dynamics | ratio to the line above |")
    print("|---|---|---|")
    for k, (name, v) in enumerate(med.items()):
        ratio = f"{v / list(med.values())[k - 1]:.2f}" if k % 2 else "-"
        print(f"| {name} | {v:.1f} | {ratio} |")
    from time import process_time
    runs = []
    for compiled in (False, True):
        scene = mb.load_model(crank)
        scene.model.compiled_terms = compiled
        t0 = process_time()
        res = scene.simulate()
        runs.append(res)
        print(f"\nflexible slider-crank, 0.1 s at rtol {scene.settings['rtol']:g}, "
              f"{'compiled terms and loop' if compiled else 'numpy terms, scipy'}: "
              f"{res.stats['rhs_evaluations']} evaluations, {process_time() - t0:.2f} s CPU")
    print("largest difference of the two runs' final coordinates: "
          f"{np.abs(runs[0].q[-1] - runs[1].q[-1]).max():.1e}")


def _compiled(model):
    model.compiled_terms = True
    return model


COLD = """
import os, sys, tempfile, time, warnings
os.environ["NUMBA_CACHE_DIR"] = tempfile.mkdtemp()
sys.path.insert(0, sys.argv[1])
warnings.simplefilter("ignore")
import numpy as np
import mbdyn as mb
crank = mb.load_model(sys.argv[1] + "/models/flexible_slider_crank.toml").model
rotor = mb.load_model(sys.argv[1] + "/models/jeffcott_flexible.toml").model
free = mb.System("free", gravity=(0, 0, 0))
free.add_body("b", flexible={"beam": {"length": 1.0, "elements": 8, "E": 2.1e11,
              "rho": 7850.0, "section": {"circle": 0.02}}, "modes": 4})
free.add_joint("float", "free", "ground", "b")
free = free.compile()
for m in (free, rotor, crank):
    m.mass_matrix(m.default_coordinates())          # the tree's kernels
t0 = time.process_time()
for name, m in (("plain (free-floating beam)", free), ("force elements (flexible rotor)",
                rotor), ("loops (flexible slider-crank)", crank)):
    m.compiled_terms = True
    t1 = time.process_time()
    m.mass_matrix(m.default_coordinates())
    print(f"| {name} | {time.process_time() - t1:.1f} |", flush=True)
"""


def cold():
    """The compiled function's first use per kind, fresh process, empty numba cache."""
    import subprocess
    print("\n| compiled function, cold numba cache | CPU s |")
    print("|---|---|")
    subprocess.run([sys.executable, "-c", COLD, str(ROOT)], check=True)


if __name__ == "__main__":
    main()
    node_elements()
    at_nodes()
    if "--cold" in sys.argv:
        cold()
