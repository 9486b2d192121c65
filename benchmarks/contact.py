#!/usr/bin/env python
"""What contact between shapes costs, and how it compares with MuJoCo at equal accuracy.

    OPENBLAS_NUM_THREADS=1 python benchmarks/contact.py            # both parts (~2 min)
    python benchmarks/contact.py --sizes 10 100 --no-mujoco

1. Per evaluation against the number of shapes: N spheres (radius 1 cm) of N free bodies
   on a cubic grid 1.96 cm apart (each overlaps its neighbours by 0.4 mm) above a floor,
   one contact element of the whole group, its pairs found by the sweep and prune or all
   N (N-1) / 2 tested (``broad_phase = false``).  Medians (us) of the force kernel alone
   (``kernels.forces.force_elements`` on the model's arrays: the contacts) and of a whole
   ``Model.forward_dynamics`` (the articulated-body route, 6 N speeds), and their ratios.
2. MuJoCo (``pip install mujoco``; never a dependency of mbdyn, skipped with a message
   when missing) and mbdyn on two problems with closed forms, each run at a sequence of
   accuracies (mbdyn: DOP853's rtol; MuJoCo: its time step, RK4): wall time and error.
   * the cradle: five balls on a frictionless line, 2 mm apart, the first at 0.5 m/s,
     elastic impacts: the speeds after 0.05 s must be (0, 0, 0, 0, 0.5); the error is the
     largest speed error (m/s) over 0.5 m/s;
   * the box on the incline (models/box_incline.toml: mu = 0.3, tan theta = 1.1 mu):
     its acceleration along the slope, fitted over 0.3..1 s, against g (sin - mu cos).
   The contact laws differ (mbdyn: Hertz k d^1.5, Hunt-Crossley; MuJoCo: its soft
   constraint, here a direct stiffness ``solref = "-k 0"`` for the elastic cradle and its
   default for the box): the comparison is of cost at an equal error in the closed-form
   observable, not of identical models.
"""
import os

for _var in ("OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "OMP_NUM_THREADS"):
    os.environ[_var] = "1"

import argparse  # noqa: E402
import math  # noqa: E402
import sys  # noqa: E402
from pathlib import Path  # noqa: E402
from time import perf_counter  # noqa: E402

import numpy as np  # noqa: E402

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

import mbdyn as mb  # noqa: E402
from mbdyn.kernels import forces as kf  # noqa: E402
from timing import per_call  # noqa: E402  (this folder)


# ----------------------------------------------------------------------------- part 1
def grid_of_spheres(n, broad_phase):
    r, spacing = 0.01, 0.0196
    side = math.ceil(n ** (1 / 3))
    s = mb.System(f"{n} spheres")
    names = []
    for k in range(n):
        i, j, l = k % side, (k // side) % side, k // (side * side)
        s.add_body(f"b{k}", mass=0.03, inertia=[1.2e-6] * 3)
        s.add_joint(f"j{k}", "free", parent="ground", child=f"b{k}",
                    position=(i * spacing, j * spacing, r + l * spacing))
        s.add_shape(f"s{k}", "sphere", f"b{k}", radius=r)
        names.append(f"s{k}")
    s.add_shape("floor", "plane", "ground")
    s.add_contact("c", group=names + ["floor"], stiffness=1e7, restitution=0.5,
                  friction=0.3, broad_phase=broad_phase)
    return s.compile(check_inertia=False)


def force_kernel(model):
    """The force elements alone, on the kinematics of the current state."""
    args = (model._force_int, model._force_data, model._parent, model._axis, model._com,
            model._qfull, model._ufull, model._R, model._r, model._w, model._v, model._F,
            model._N, np.zeros(0), model._scratch)

    def call():
        kf.force_elements(*args)
    return call


def scaling(sizes):
    print("1. per evaluation against the number of spheres (us, medians)")
    print(f"{'N':>5} {'pairs':>7} | {'kernel SAP':>10} {'kernel all':>10} {'ratio':>6} | "
          f"{'f.dyn SAP':>10} {'f.dyn all':>10} {'ratio':>6}")
    rng = np.random.default_rng(1)
    for n in sizes:
        row = []
        for broad in (True, False):
            model = grid_of_spheres(n, broad)
            q = model.default_coordinates()
            u = 0.01 * rng.normal(size=model.nu)
            model.forward_dynamics(q, u)            # the kinematics in the workspace
            kernel = per_call(force_kernel(model), rounds=9)
            whole = per_call(lambda: model.forward_dynamics(q, u), rounds=9)
            row.append((kernel, whole))
        (ks, ws), (ka, wa) = row
        print(f"{n:>5} {n * (n + 1) // 2:>7} | {ks:>10.1f} {ka:>10.1f} {ka / ks:>6.1f} | "
              f"{ws:>10.1f} {wa:>10.1f} {wa / ws:>6.1f}")


# ----------------------------------------------------------------------------- part 2
def mbdyn_cradle(rtol):
    s = mb.System("row", gravity=(0, 0, 0))
    for i in range(5):
        s.add_body(f"b{i}", mass=0.03, inertia=[1.2e-6] * 3)
        s.add_joint(f"x{i}", "prismatic", parent="ground", child=f"b{i}", axis="x",
                    position=(i * 0.022, 0, 0))
        s.add_shape(f"s{i}", "sphere", f"b{i}", radius=0.01)
    s.add_contact("c", group=[f"s{i}" for i in range(5)], stiffness=1e7, impact_speed=0.5)
    model = s.compile()
    t0 = perf_counter()
    res = mb.simulate(model, 0.05, u0={"x0_dot": 0.5}, rtol=rtol, atol=rtol * 1e-3,
                      max_step=1e-4)
    wall = perf_counter() - t0
    v = res.u[-1]
    return wall, np.abs(v - [0, 0, 0, 0, 0.5]).max() / 0.5


def mujoco_cradle(mujoco, h):
    bodies = "".join(
        f'<body pos="{i * 0.022} 0 0"><joint type="slide" axis="1 0 0"/>'
        f'<geom type="sphere" size="0.01" mass="0.03" solref="-1e6 0" '
        f'solimp="0.9999 0.9999 0.001 0.5 2"/></body>' for i in range(5))
    xml = (f'<mujoco><option timestep="{h}" gravity="0 0 0" integrator="RK4"/>'
           f"<worldbody>{bodies}</worldbody></mujoco>")
    m = mujoco.MjModel.from_xml_string(xml)
    d = mujoco.MjData(m)
    d.qvel[0] = 0.5
    t0 = perf_counter()
    for _ in range(int(round(0.05 / h))):
        mujoco.mj_step(m, d)
    wall = perf_counter() - t0
    return wall, np.abs(d.qvel - [0, 0, 0, 0, 0.5]).max() / 0.5


def closed_form_box():
    mu = 0.3
    theta = math.atan(1.1 * mu)
    return mu, theta, 9.81 * (math.sin(theta) - mu * math.cos(theta))


def mbdyn_box(rtol):
    scene = mb.load_model(ROOT / "models" / "box_incline.toml")
    t0 = perf_counter()
    res = scene.simulate(rtol=rtol, atol=rtol * 1e-2)
    wall = perf_counter() - t0
    late = res.t > 0.3
    a = np.polyfit(res.t[late], res["x_dot"][late], 1)[0]
    return wall, abs(a / closed_form_box()[2] - 1)


def mujoco_box(mujoco, h):
    mu, theta, _ = closed_form_box()
    xml = f"""<mujoco><option timestep="{h}" integrator="RK4" cone="elliptic"/>
<worldbody>
  <geom type="plane" size="5 5 0.1" friction="{mu} 0 0" euler="0 {math.degrees(theta)} 0"/>
  <body pos="{0.05 * math.sin(theta)} 0 {0.05 * math.cos(theta)}"
        euler="0 {math.degrees(theta)} 0"><freejoint/>
    <geom type="box" size="0.2 0.05 0.05" mass="1" friction="{mu} 0 0"/></body>
</worldbody></mujoco>"""
    m = mujoco.MjModel.from_xml_string(xml)
    d = mujoco.MjData(m)
    down = np.array([math.cos(theta), 0, -math.sin(theta)])
    ts, vs = [], []
    t0 = perf_counter()
    for k in range(int(round(1.0 / h))):
        mujoco.mj_step(m, d)
        if k % max(1, int(round(2e-3 / h))) == 0:
            ts.append(d.time)
            vs.append(d.qvel[:3] @ down)
    wall = perf_counter() - t0
    ts, vs = np.array(ts), np.array(vs)
    late = ts > 0.3
    a = np.polyfit(ts[late], vs[late], 1)[0]
    return wall, abs(a / closed_form_box()[2] - 1)


def peers():
    print("\n2. against MuJoCo at equal accuracy (wall time s; error relative to the "
          "closed form)")
    try:
        import mujoco
    except ImportError:
        print("   MuJoCo is not installed (pip install mujoco): skipped")
        return
    print(f"   MuJoCo {mujoco.__version__}")
    mbdyn_cradle(1e-6), mbdyn_box(1e-6)            # warm: first calls set up the runs
    rows = [("cradle", "mbdyn", f"rtol {r:g}", *mbdyn_cradle(r)) for r in (1e-6, 1e-8, 1e-10)]
    rows += [("cradle", "MuJoCo", f"h {h:g}", *mujoco_cradle(mujoco, h))
             for h in (1e-4, 3e-5, 1e-5)]
    rows += [("box", "mbdyn", f"rtol {r:g}", *mbdyn_box(r)) for r in (1e-6, 1e-8)]
    rows += [("box", "MuJoCo", f"h {h:g}", *mujoco_box(mujoco, h)) for h in (1e-3, 1e-4)]
    print(f"   {'problem':<7} {'engine':<7} {'setting':<11} {'wall (s)':>9} {'error':>9}")
    for problem, engine, setting, wall, err in rows:
        print(f"   {problem:<7} {engine:<7} {setting:<11} {wall:>9.4f} {err:>9.2e}")
    for problem in ("cradle", "box"):
        best = {}
        for p, engine, setting, wall, err in rows:
            if p == problem and err < 1e-3 and wall < best.get(engine, (np.inf,))[0]:
                best[engine] = (wall, setting)
        text = ", ".join(f"{e} {w:.4f} s ({s})" for e, (w, s) in best.items()) or "neither"
        print(f"   {problem}: fastest within 1e-3: {text}")


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--sizes", type=int, nargs="+", default=[10, 30, 100, 300, 500])
    parser.add_argument("--no-mujoco", action="store_true")
    args = parser.parse_args()
    scaling(args.sizes)
    if not args.no_mujoco:
        peers()


if __name__ == "__main__":
    main()
