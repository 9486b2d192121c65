#!/usr/bin/env python
"""What force elements and effects cost per evaluation.

    python benchmarks/forces.py                   # tables (about a minute, warm cache)
    python benchmarks/forces.py --baseline REV    # also the no-element cost at git REV

Tables (medians over interleaved rounds, us per ``Model.forward_dynamics`` call, Jourdain):

1. Cost of each element kind: a three-body model (revolute, spherical, prismatic joints)
   compiled with only that element on, minus the same model with every element off.
2. A scene with every effect on, with each one switched off, and with none: an effect off
   must cost what deleting it costs, i.e. the element's share disappears.
3. With ``--baseline REV``: the textbook double pendulum and a 20-link revolute chain
   without force elements, at this tree and at git revision REV (checked out in a
   temporary worktree and timed in a subprocess, alternating with this tree's), so
   "paying nothing for what is off" is measured against the code before force elements.
"""
import os

for _var in ("OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "OMP_NUM_THREADS"):
    os.environ[_var] = "1"

import argparse  # noqa: E402
import json  # noqa: E402
import subprocess  # noqa: E402
import sys  # noqa: E402
import tempfile  # noqa: E402
import warnings  # noqa: E402
from pathlib import Path  # noqa: E402

import numpy as np  # noqa: E402

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "tests"))

from timing import per_call  # noqa: E402  (this folder)


def interleaved(calls, rounds=15):
    """``{name: median us}`` measured round-robin, so that load bursts hit all alike."""
    samples = {k: [] for k in calls}
    for _ in range(rounds):
        for k, fn in calls.items():
            samples[k].append(per_call(fn, rounds=1))
    return {k: float(np.median(v)) for k, v in samples.items()}


NO_ELEMENT_SCRIPT = r"""
import os, sys, json
for v in ("OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "OMP_NUM_THREADS"):
    os.environ[v] = "1"
sys.path.insert(0, sys.argv[1])
sys.path.insert(0, sys.argv[2])
import numpy as np
import mbdyn as mb
from time import perf_counter
import gc

def chain(n):
    s = mb.System("chain", gravity=(0, 0, -9.81))
    parent = "ground"
    for i in range(n):
        s.add_body(f"b{i}", mass=1.0, com=(0, 0, -0.1), inertia=[0.01, 0.01, 0.002])
        s.add_joint(f"j{i}", "revolute", parent=parent, child=f"b{i}",
                    axis="x" if i % 2 else "y", position=(0, 0, -0.2 if i else 0))
        parent = f"b{i}"
    return s.compile()

def pendulum():
    s = mb.System("double pendulum", gravity=(0, -9.81, 0))
    s.add_body("mass1", mass=0.00046, com=(0, -0.07, 0))
    s.add_joint("theta1", "revolute", parent="ground", child="mass1", axis="z")
    s.add_body("mass2", mass=0.0046, com=(0, -0.07, 0))
    s.add_joint("theta2", "revolute", parent="mass1", child="mass2", axis="z",
                position=(0, -0.07, 0))
    return s.compile()

out = {}
for name, model in (("double pendulum", pendulum()), ("revolute chain n=20", chain(20))):
    q, u = np.full(model.nq, 0.3), np.full(model.nu, 0.1)
    model.forward_dynamics(q, u)
    n = 20000 if model.nu < 10 else 4000
    best = []
    gc.disable()
    for _ in range(7):
        t0 = perf_counter()
        for _ in range(n):
            model.forward_dynamics(q, u)
        best.append((perf_counter() - t0) / n * 1e6)
    gc.enable()
    out[name] = sorted(best)[3]
print(json.dumps(out))
"""


def baseline_table(rev, rounds=5):
    tmp = Path(tempfile.mkdtemp(prefix="mbdyn-baseline-"))
    tree = tmp / "tree"
    subprocess.run(["git", "-C", str(ROOT), "worktree", "add", "--detach", str(tree), rev],
                   check=True, capture_output=True)
    script = tmp / "time_no_elements.py"
    script.write_text(NO_ELEMENT_SCRIPT)
    try:
        runs = {"this tree": [], f"at {rev}": []}
        for _ in range(rounds):                 # alternate, so noise hits both alike
            for label, path in (("this tree", ROOT), (f"at {rev}", tree)):
                out = subprocess.run([sys.executable, str(script), str(path), str(tmp)],
                                     check=True, capture_output=True, text=True)
                runs[label].append(json.loads(out.stdout))
    finally:
        subprocess.run(["git", "-C", str(ROOT), "worktree", "remove", "--force", str(tree)],
                       capture_output=True)
    names = list(runs["this tree"][0])
    print(f"\n3. Models without force elements: this tree vs {rev} (us per call, median of "
          f"{rounds} alternating subprocess runs)")
    print(f"{'model':<22} {'this tree':>10} {rev:>10} {'ratio':>7}")
    for n in names:
        a = float(np.median([r[n] for r in runs["this tree"]]))
        b = float(np.median([r[n] for r in runs[f"at {rev}"]]))
        print(f"{n:<22} {a:>10.2f} {b:>10.2f} {a / b:>7.3f}")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--baseline", metavar="REV", help="git revision to compare the "
                    "no-element cost with (e.g. the commit before force elements)")
    ap.add_argument("--rounds", type=int, default=15)
    args = ap.parse_args()
    warnings.simplefilter("ignore")
    from test_forces import every_kind_system
    s = every_kind_system()
    elements = list(s.forces)
    loads_and_globals = [n for n in s.effect_names() if n not in elements]
    q_model = s.compile()
    rng = np.random.default_rng(1)
    q = q_model.default_coordinates() + rng.uniform(-0.3, 0.3, q_model.nq)
    q_model.normalize_quaternions(q)
    q[q_model.coordinate_index("c")] = -0.35       # the slider in contact with the floor
    u = rng.uniform(-1, 1, q_model.nu)

    def model_with(on):
        off = [f"-{n}" for n in elements if n not in on]
        m = s.compile(effects=off)
        return lambda: m.forward_dynamics(q, u)

    calls = {"none": model_with(())}
    for el in elements:
        calls[el] = model_with((el,))
    res = interleaved(calls, args.rounds)
    print("1. Cost of each element kind (us per forward_dynamics call, 3 bodies, "
          "Jourdain; element alone minus none)")
    print(f"{'element':<14} {'kind':<20} {'alone':>8} {'cost':>8}")
    print(f"{'(none)':<14} {'':<20} {res['none']:>8.2f} {0.0:>8.2f}")
    for el in elements:
        kind = s.forces[el].kind
        print(f"{el:<14} {kind:<20} {res[el]:>8.2f} {res[el] - res['none']:>8.2f}")

    calls = {"all on": model_with(elements)}
    for el in elements:
        calls[f"-{el}"] = model_with([e for e in elements if e != el])
    calls["-gravity"] = (lambda m: lambda: m.forward_dynamics(q, u))(
        s.compile(effects="-gravity"))
    calls["-gyroscopic"] = (lambda m: lambda: m.forward_dynamics(q, u))(
        s.compile(effects="-gyroscopic"))
    calls["none"] = model_with(())
    res2 = interleaved(calls, args.rounds)
    print("\n2. A scene with every effect on, each switched off, none (us per call)")
    print(f"{'scene':<18} {'us':>8} {'vs all on':>10}")
    for k, v in res2.items():
        print(f"{k:<18} {v:>8.2f} {v / res2['all on']:>10.3f}")
    print(f"(effects besides the elements: {', '.join(loads_and_globals)})")
    if args.baseline:
        baseline_table(args.baseline)


if __name__ == "__main__":
    main()
