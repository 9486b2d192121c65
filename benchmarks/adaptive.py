"""Cost of an accurate adaptive run: the textbook double pendulum over 4 s to an error of at
most 1e-8 rad, by mbdyn's compiled DOP853, scipy's DOP853 on the same right-hand side, the
symbolic right-hand side (``method="symbolic"``, scipy's DOP853) and, when available,
Exudyn's DOPRI5 on the same model (an ``ObjectKinematicTree`` in minimal coordinates).

    python benchmarks/adaptive.py [--repeats N] [--exudyn-python PYTHON]

The error is the largest of ``|theta1(4) - ref|``, ``|theta2(4) - ref|``; the reference is
scipy's DOP853 at rtol 1e-13, atol 1e-15.  Each solver runs at the loosest tolerance of
``TOLERANCES`` (rtol = atol) that meets the target, in its own subprocess
(OPENBLAS_NUM_THREADS=1) after an untimed warm-up run, ``--repeats`` times; the table gives
the median CPU time of the solve (``time.process_time``: the machine is shared) and its
ratio to the compiled DOP853.  Exudyn runs in the interpreter ``--exudyn-python`` (default:
this one, if it imports ``exudyn``); Exudyn is never a dependency of mbdyn.
"""
from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys

HERE = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
TARGET = 1e-8
TOLERANCES = (1e-7, 3e-8, 1e-8, 3e-9, 1e-9, 3e-10, 1e-10, 3e-11, 1e-11, 3e-12, 1e-12, 3e-13)

MBDYN = r"""
import json, sys, time
import numpy as np
import mbdyn as mb
cfg = json.loads(sys.argv[1])
s = mb.System("double pendulum", gravity=(0, -9.81, 0))
s.add_body("link1", mass=0.00046, com=(0, -0.07, 0))
s.add_body("link2", mass=0.0046, com=(0, -0.07, 0))
s.add_joint("theta1", "revolute", "ground", "link1", axis="-z")
s.add_joint("theta2", "revolute", "link1", "link2", axis="-z", position=(0, -0.07, 0))
m = s.compile()
q0 = {"theta1": -np.pi / 4, "theta2": np.pi / 4}
kw = dict(integrator=cfg["integrator"], method=cfg["method"])
if cfg.get("reference"):
    r = mb.simulate(m, 4.0, q0, integrator="scipy-DOP853", rtol=1e-13, atol=1e-15)
    print(json.dumps({"q": r.q[-1].tolist()}))
    sys.exit()
mb.simulate(m, 0.01, q0, **kw)                # warm-up: compiles, loads caches
def run(tol):
    c = time.process_time()
    r = mb.simulate(m, 4.0, q0, rtol=tol, atol=tol, **kw)
    return time.process_time() - c, r.q[-1], r.stats["steps"]
for tol in cfg["tolerances"]:
    _, q, steps = run(tol)
    err = float(np.abs(q - np.array(cfg["ref"])).max())
    if err <= cfg["target"]:
        break
times = [run(tol)[0] for _ in range(cfg["repeats"])]
print(json.dumps({"tol": tol, "error": err, "steps": steps, "times": times}))
"""

EXUDYN = r"""
import json, sys, time
import numpy as np
import exudyn as exu
from exudyn.utilities import (ObjectGround, NodeGenericODE2, ObjectKinematicTree)
cfg = json.loads(sys.argv[1])
def run(tol):
    SC = exu.SystemContainer()
    mbs = SC.AddSystem()
    mbs.AddObject(ObjectGround(referencePosition=[0, 0, 0]))
    # Exudyn's RevoluteZ turns about +z; mbdyn's model about -z: the angles change sign
    node = mbs.AddNode(NodeGenericODE2(referenceCoordinates=[0.0, 0.0],
                                       initialCoordinates=[np.pi / 4, -np.pi / 4],
                                       initialCoordinates_t=[0.0, 0.0],
                                       numberOfODE2Coordinates=2))
    mbs.AddObject(ObjectKinematicTree(
        nodeNumber=node, jointTypes=[exu.JointType.RevoluteZ] * 2, linkParents=[-1, 0],
        jointTransformations=exu.Matrix3DList([np.eye(3)] * 2),
        jointOffsets=exu.Vector3DList([[0, 0, 0], [0, -0.07, 0]]),
        linkInertiasCOM=exu.Matrix3DList([np.zeros((3, 3))] * 2),
        linkCOMs=exu.Vector3DList([[0, -0.07, 0]] * 2), linkMasses=[0.00046, 0.0046],
        baseOffset=[0.0, 0.0, 0.0], gravity=[0.0, -9.81, 0.0]))
    mbs.Assemble()
    st = exu.SimulationSettings()
    st.timeIntegration.endTime = 4.0
    st.timeIntegration.numberOfSteps = 1000
    st.timeIntegration.automaticStepSize = True
    st.timeIntegration.absoluteTolerance = tol
    st.timeIntegration.relativeTolerance = tol
    st.timeIntegration.verboseMode = 0
    st.solutionSettings.writeSolutionToFile = False
    st.displayComputationTime = False
    c = time.process_time()
    mbs.SolveDynamic(st, solverType=exu.DynamicSolverType.DOPRI5)
    c = time.process_time() - c
    return c, -np.array(mbs.GetNodeOutput(node, exu.OutputVariableType.Coordinates))
run(1e-6)                                       # warm-up
for tol in cfg["tolerances"]:
    _, q = run(tol)
    err = float(np.abs(q - np.array(cfg["ref"])).max())
    if err <= cfg["target"]:
        break
times = [run(tol)[0] for _ in range(cfg["repeats"])]
print(json.dumps({"tol": tol, "error": err, "steps": None, "times": times}))
"""


def child(python, code, cfg):
    env = dict(os.environ, PYTHONPATH=HERE, OPENBLAS_NUM_THREADS="1")
    proc = subprocess.run([python, "-c", code, json.dumps(cfg)], env=env, capture_output=True,
                          text=True, cwd=HERE)
    if proc.returncode:
        raise RuntimeError(proc.stderr.strip().splitlines()[-1] if proc.stderr else "failed")
    return json.loads(proc.stdout.strip().splitlines()[-1])


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument("--exudyn-python", default=sys.executable,
                    help="a Python interpreter with exudyn installed (default: this one)")
    args = ap.parse_args()
    ref = child(sys.executable, MBDYN, {"reference": True, "integrator": "scipy-DOP853",
                                        "method": "jourdain"})["q"]
    base = {"ref": ref, "target": TARGET, "tolerances": list(TOLERANCES),
            "repeats": args.repeats}
    rows = [("mbdyn DOP853 (compiled)", sys.executable, MBDYN,
             {"integrator": "DOP853", "method": "jourdain"}),
            ("mbdyn scipy-DOP853", sys.executable, MBDYN,
             {"integrator": "scipy-DOP853", "method": "jourdain"}),
            ("mbdyn symbolic RHS, scipy DOP853", sys.executable, MBDYN,
             {"integrator": "DOP853", "method": "symbolic"}),
            ("Exudyn DOPRI5 (ObjectKinematicTree)", args.exudyn_python, EXUDYN, {})]
    results = []
    for name, python, code, cfg in rows:
        try:
            out = child(python, code, dict(base, **cfg))
        except (RuntimeError, OSError) as exc:
            print(f"{name}: not measured ({exc})", file=sys.stderr)
            continue
        results.append((name, out, statistics.median(out["times"])))
    first = results[0][2]
    exudyn = next((t for n, _, t in results if n.startswith("Exudyn")), None)
    print(f"Double pendulum, 4 s, error <= {TARGET:g} rad; median CPU s of {args.repeats}\n")
    print("| solver | rtol = atol | error (rad) | steps | CPU s | / compiled DOP853 |"
          + (" / Exudyn |" if exudyn else ""))
    print("|---|---|---|---|---|---|" + ("---|" if exudyn else ""))
    for name, out, t in results:
        steps = "" if out["steps"] is None else str(out["steps"])
        line = (f"| {name} | {out['tol']:g} | {out['error']:.2g} | {steps} | {t:.4f} | "
                f"{t / first:.2f} |")
        if exudyn:
            line += f" {t / exudyn:.2f} |"
        print(line)


if __name__ == "__main__":
    main()
