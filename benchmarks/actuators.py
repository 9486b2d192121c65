#!/usr/bin/env python
"""What actuators, controllers and stops cost, against the ways they had to be written
before (issue 28).

    python benchmarks/actuators.py          # tables (about a minute, warm cache)

Tables (medians over interleaved rounds; ratios against a baseline measured in the same
run):

1. A 3-DoF arm held by three PD controllers with gravity compensation
   (``models/pd_arm.toml``, 3 s): compiled actuators, against the same PD laws written
   as Python-function loads (two loads per joint, +tau on the child and -tau on the
   parent, the only way before; they send the run to scipy's DOP853).
2. Cost per ``state_derivative`` call: the bare arm, the arm with the three PD
   actuators, with joint stops, with a friction law (compiled program).
3. A sampled-data controller on the arm (a Python PD at the control rate) against the
   compiled PD: the cost of a sample.
"""
import os

for _var in ("OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "OMP_NUM_THREADS"):
    os.environ[_var] = "1"

import statistics  # noqa: E402
import sys  # noqa: E402
import warnings  # noqa: E402
from pathlib import Path  # noqa: E402
from time import perf_counter  # noqa: E402

import numpy as np  # noqa: E402
import sympy  # noqa: E402

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

import mbdyn as mb  # noqa: E402
from timing import per_call  # noqa: E402  (this folder)

ARM = ROOT / "models" / "pd_arm.toml"
POSE = np.array([0.5, -0.6, 1.2])
KP, KD = 400.0, 40.0


def timed(fn, rounds=7):
    """Median wall time of ``fn()`` (s) and its last value."""
    fn()
    times, value = [], None
    for _ in range(rounds):
        t0 = perf_counter()
        value = fn()
        times.append(perf_counter() - t0)
    return statistics.median(times), value


def python_loads_arm():
    """The PD laws as Python-function loads (the way before actuators), gravity
    compensated by the bare arm's inverse dynamics at rest: the same equations."""
    scene = mb.load_model(ARM)
    system = mb.load_model(ARM, effects="-drive_pan,-drive_shoulder,-drive_elbow").system
    bare = system.compile(effects="-drive_pan,-drive_shoulder,-drive_elbow")
    s = mb.System("arm with loads", gravity=(0, 0, -9.81))
    for b in ("base", "upper_arm", "forearm"):
        rec = system.bodies[b]
        s.add_body(b, mass=rec.mass, com=rec.com, inertia=rec.inertia)
    for name, j in system.joints.items():
        s.add_joint(name, "revolute", parent=j.parent, child=j.child, axis=j.axis,
                    position=j.position)
    model_axes = {"pan": 0, "shoulder": 1, "elbow": 2}

    def effort(k):
        def tau(t, q, u):
            g = bare.inverse_dynamics(q, np.zeros(3), np.zeros(3))[0]
            return KP * (POSE[k] - q[k]) + KD * (-u[k]) + g[bare.speeds[k]]
        return tau
    for name, k in model_axes.items():
        j = system.joints[name]
        tau = effort(k)
        axis = np.asarray(j.axis, float)
        # +tau about the axis on the child, -tau on the parent, both in body axes: a
        # revolute joint's axis has the same components in the parent's and the child's
        # axes (the joints here have no orientation)
        s.add_load(f"{name}_child", j.child, frame="body",
                   moment=lambda t, q, u, tau=tau, a=axis: tau(t, q, u) * a)
        if j.parent != "ground":
            s.add_load(f"{name}_parent", j.parent, frame="body",
                       moment=lambda t, q, u, tau=tau, a=axis: -tau(t, q, u) * a)
    return scene, s.compile()


def main():
    warnings.simplefilter("ignore")
    scene = mb.load_model(ARM)
    model = scene.model
    t_run, res = timed(lambda: scene.simulate())
    print("## 1. PD arm, 3 s: compiled actuators against Python-function loads\n")
    print("| route | wall time (s) | final pose error (rad) |")
    print("|---|---|---|")
    print(f"| compiled PD actuators (DOP853, compiled) | {t_run:.3g} | "
          f"{np.abs(res.q[-1] - POSE).max():.1e} |")
    try:
        _, loads_model = python_loads_arm()
        t_py, res_py = timed(lambda: mb.simulate(loads_model, 3.0, q0=scene.q0, u0=scene.u0,
                                                 t_eval=res.t), rounds=3)
        print(f"| PD as Python loads (scipy DOP853) | {t_py:.3g} ({t_py / t_run:.0f}x) | "
              f"{np.abs(res_py.q[-1] - POSE).max():.1e} |")
        print(f"\nlargest difference between the two motions: "
              f"{np.abs(res_py.q - res.q).max():.1e} rad")
    except Exception as exc:          # the baseline is a benchmark's, not a product's
        print(f"| PD as Python loads | failed: {exc} | |")

    print("\n## 2. us per state_derivative call (Jourdain, compiled)\n")
    y = np.concatenate([scene.q0, scene.u0])
    bare = scene.system.compile(effects="-drive_pan,-drive_shoulder,-drive_elbow")
    base = per_call(lambda: bare.state_derivative(0.0, y))
    print("| model | us/call | ratio to the bare arm |")
    print("|---|---|---|")
    print(f"| bare arm | {base:.2f} | 1.0 |")
    variants = {"3 PD actuators with gravity compensation": model}
    s = scene.system
    for name in ("pan", "shoulder", "elbow"):
        s.add_force(f"stop_{name}", "joint-stop", joint=name, lower=-3, upper=3,
                    stiffness=1e5, damping=100)
    variants["+ 3 joint stops"] = s.compile()
    x, v = sympy.symbols("x v")
    for name in ("pan", "shoulder", "elbow"):
        s.add_force(f"friction_{name}", "joint-spring-damper", joint=name,
                    law=2.0 * sympy.tanh(v / 0.01))
    variants["+ 3 friction laws (compiled programs)"] = s.compile()
    for label, m in variants.items():
        c = per_call(lambda m=m: m.state_derivative(0.0, y))
        print(f"| {label} | {c:.2f} | {c / base:.2f} |")

    print("\n## 3. A controller in Python at its rate, against the compiled PD (3 s)\n")
    print("| controller | wall time (s) | ratio | sampling instants |")
    print("|---|---|---|---|")
    print(f"| compiled PD actuators | {t_run:.3g} | 1.0 | 0 |")
    for rate in (500.0, 2000.0):
        sys_ = mb.load_model(ARM, effects="-drive_pan,-drive_shoulder,-drive_elbow").system
        g_model = sys_.compile()

        def control(t, q, u, g_model=g_model):
            g = g_model.inverse_dynamics(q, np.zeros(3), np.zeros(3))[0]
            return KP * (POSE - q) - KD * u + np.array([g[s] for s in g_model.speeds])
        sys_.add_controller("ctl", control, rate=rate, joints=["pan", "shoulder", "elbow"])
        cm = sys_.compile(effects="-drive_pan,-drive_shoulder,-drive_elbow")
        t_c, r = timed(lambda cm=cm: mb.simulate(cm, 3.0, q0=scene.q0, u0=scene.u0),
                       rounds=3)
        print(f"| Python PD at {rate:g} Hz | {t_c:.3g} | {t_c / t_run:.0f}x | "
              f"{r.stats['sampling_instants']} |")


if __name__ == "__main__":
    main()
