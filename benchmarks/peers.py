#!/usr/bin/env python
"""mbdyn's speed goals (issue 12) as ratios against peer libraries, measured side by side
in one process.

    python benchmarks/peers.py              # full run (several minutes)
    python benchmarks/peers.py --quick      # fewer rounds, no cold/warm start
    python benchmarks/peers.py --json       # machine-readable output on stdout
    python benchmarks/peers.py --only 1,3   # only these rows (1-5; the accuracy table is
                                            # "acc")

The peers are for benchmarking only, never dependencies of mbdyn.  Install them into a
virtual environment that still sees the system's packages (mbdyn installed there):

    python -m venv --system-site-packages /work/peers-venv
    /work/peers-venv/bin/pip install pin mujoco exudyn mpmath
    PYTHONPATH=. /work/peers-venv/bin/python benchmarks/peers.py

A peer that is not installed is skipped with a note; its rows show "skipped".

The rows (each the median over interleaved rounds, CPU time of this process; the ratio is
mbdyn / peer; "met" says whether the goal holds):

1. The textbook double pendulum over 4 s (point masses 0.00046 and 0.0046 kg on massless
   rods of 0.07 m, revolute joints about -z, theta1 = -pi/4, theta2 = pi/4), accurate to
   1e-8 rad: the largest angle error at the output times against a reference (mbdyn's
   DOP853 at rtol 1e-13, atol 1e-14).  mbdyn: ``mb.simulate(..., integrator="DOP853")``
   (and ``method="symbolic"``) at the loosest rtol of a list that meets 1e-8 (atol =
   rtol / 1000, 41 output times); Exudyn: an ``ObjectKinematicTree`` (minimal
   coordinates, angles about +z, so phi = -theta) with its DOPRI5 at the loosest
   tolerance (absolute = relative) of a list that meets 1e-8 at its sensor times.  Goal:
   mbdyn <= 0.5 x Exudyn.
2. Fixed-step RK4, 48 000 steps over 4 s, per step: ``integrator="rk4"`` (the compiled
   loop) against MuJoCo's RK4 on the same model (MJCF built here: inertial elements with
   the point masses and an inertia of 1e-15 kg m^2), both ``mujoco.rollout`` (the loop in
   C) and ``mj_step`` called from Python.  Checked: MuJoCo's ``qacc`` at the initial state
   against mbdyn's accelerations.  Goal: mbdyn <= 1.0 x MuJoCo (rollout).
3. Forward dynamics per Python call on the chains of ``benchmarks/forward_dynamics.py``
   (``build_chain``: revolute with alternating x / y axes, and spherical; seeded random
   inertias), n = 2, 20, 100: ``model.lowlevel().forward_dynamics(q, u, 0.0, out)`` (or
   ``model.forward_dynamics(q, u)`` where there is no ``lowlevel``) against
   ``pinocchio.aba`` on the same chain translated to pinocchio (``to_pinocchio``;
   quaternions reordered (w, x, y, z) -> (x, y, z, w); the speeds of a spherical joint are
   the child-frame angular velocity in both).  Checked: the accelerations agree at a
   random state.  Goal: <= 1.5 x pinocchio at n = 2, <= 1.0 x from n = 20.
4. The Newton-Euler equations with reactions against our own Jourdain form, per call,
   same chains: ``forward_dynamics(q, u, method="newton-euler")`` /
   ``method="jourdain"`` (also shown: ``"articulated"``).  Goal: <= 2 x.
5. Cold and warm start of ``mbdyn run models/top.toml --case a``
   (``benchmarks/first_start.py``, CPU of the child).  No peer; goals cold <= 20 s,
   warm <= 1.5 s.  Skipped with ``--quick``.

Accuracy (what makes the speed honest): a 50-link spherical chain made ill-conditioned
(alternating heavy and very light links; cond(M) from ``model.mass_matrix_condition``
printed), the relative error (2-norm) of pinocchio's ``aba`` and of mbdyn's routes
against the exact solution of ``M x = f`` with ``M, f`` as mbdyn computes them, and as
pinocchio computes them (``crba``, ``-nle``), each found by iterative refinement with
residuals in 50-digit arithmetic (mpmath): both references are exact for their rounded
``M, f``; their difference is what the rounding of ``M, f`` alone allows.

How it measures: BLAS and OpenMP pools pinned to one thread before numpy is imported;
per-call rows use ``forward_dynamics.measure`` (blocks sized to a time budget, rounds
interleaved, garbage collector off; thread CPU time); whole runs (rows 1, 2) are timed
one call per round, interleaved, with ``time.process_time``.  The machine may be shared:
compare the ratios, measured in the same run.
"""
import os

for _var in ("OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "OMP_NUM_THREADS",
             "NUMEXPR_NUM_THREADS", "VECLIB_MAXIMUM_THREADS", "BLIS_NUM_THREADS"):
    os.environ[_var] = "1"

import argparse  # noqa: E402
import importlib  # noqa: E402
import json  # noqa: E402
import statistics  # noqa: E402
import sys  # noqa: E402
import time  # noqa: E402
import warnings  # noqa: E402

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import forward_dynamics as fdb  # noqa: E402  (this folder: chains and the per-call timer)
from timing import interleaved_cpu  # noqa: E402
import numpy as np  # noqa: E402

ROWS = ("1", "2", "3", "4", "5", "acc")
SIZES = (2, 20, 100)
NOTES = []


def log(*args):
    print(*args, file=sys.stderr, flush=True)


def peer(module):
    """The imported peer module, or None (with a note) when it is not installed."""
    try:
        return importlib.import_module(module)
    except ImportError as exc:
        NOTES.append(f"{module} not installed ({exc}): its rows are skipped.")
        return None


def interleaved(runs, rounds):
    """``{name: median CPU seconds}`` of whole calls ``runs = {name: fn}``, timed
    round-robin (``timing.interleaved_cpu``)."""
    return {k: statistics.median(v) for k, v in interleaved_cpu(runs, rounds).items()}


def row(measure, mbdyn, peer_value, goal, unit="s", peer_name=""):
    """One table row; ``goal`` is the largest ratio mbdyn / peer that meets it."""
    ratio = mbdyn / peer_value if peer_value else None
    return {"measure": measure, "mbdyn": mbdyn, "peer": peer_value, "peer_name": peer_name,
            "unit": unit, "ratio": ratio, "goal": goal,
            "met": None if ratio is None or goal is None else bool(ratio <= goal)}


# ------------------------------------------------------------------ 1: double pendulum
L1, M1, M2 = 0.07, 0.00046, 0.0046
THETA0 = (-np.pi / 4, np.pi / 4)
TOLERANCES = (1e-8, 3e-9, 1e-9, 3e-10, 1e-10, 3e-11, 1e-11, 3e-12, 1e-12, 3e-13)
ANGLE_GOAL = 1e-8


def double_pendulum(mb):
    """The textbook double pendulum (as ``benchmarks/run_cost.py``)."""
    s = mb.System("double pendulum", gravity=(0, -9.81, 0))
    s.add_body("link1", mass=M1, com=(0, -L1, 0))
    s.add_body("link2", mass=M2, com=(0, -L1, 0))
    s.add_joint("theta1", "revolute", "ground", "link1", axis="-z")
    s.add_joint("theta2", "revolute", "link1", "link2", axis="-z", position=(0, -L1, 0))
    return s.compile()


def exudyn_pendulum(exu, tol):
    """Exudyn's double pendulum as a kinematic tree (revolute joints about +z, so its
    angles are -theta) and a function that runs DOPRI5 over 4 s at tolerance ``tol``
    (absolute and relative) and returns the sensor's ``[t, phi1, phi2]`` rows."""
    from exudyn.itemInterface import NodeGenericODE2, ObjectKinematicTree, SensorNode
    SC = exu.SystemContainer()
    mbs = SC.AddSystem()
    node = mbs.AddNode(NodeGenericODE2(referenceCoordinates=[0.0, 0.0],
                                       initialCoordinates=[-THETA0[0], -THETA0[1]],
                                       initialCoordinates_t=[0.0, 0.0],
                                       numberOfODE2Coordinates=2))
    zero = np.zeros((3, 3))
    mbs.AddObject(ObjectKinematicTree(
        nodeNumber=node, jointTypes=[exu.JointType.RevoluteZ] * 2, linkParents=[-1, 0],
        jointTransformations=exu.Matrix3DList([np.eye(3)] * 2),
        jointOffsets=exu.Vector3DList([[0, 0, 0], [0, -L1, 0]]),
        linkInertiasCOM=exu.Matrix3DList([zero, zero]),
        linkCOMs=exu.Vector3DList([[0, -L1, 0], [0, -L1, 0]]),
        linkMasses=[M1, M2], gravity=[0, -9.81, 0]))
    sensor = mbs.AddSensor(SensorNode(nodeNumber=node, storeInternal=True, writeToFile=False,
                                      outputVariableType=exu.OutputVariableType.Coordinates))
    mbs.Assemble()
    ss = exu.SimulationSettings()
    ti = ss.timeIntegration
    ti.endTime = 4.0
    ti.numberOfSteps = 100        # largest step 0.04 s (10 diverged, 400 was slower)
    ti.verboseMode = 0
    ti.automaticStepSize = True
    ti.absoluteTolerance = ti.relativeTolerance = tol
    ti.explicitIntegration.computeEndOfStepAccelerations = False   # not needed: faster
    ss.solution.file.write = False
    ss.solution.sensors.writePeriod = 0.1
    ss.show.computationTime = False
    ss.show.statistics = False

    def run():
        exu.SolveDynamic(mbs, ss, solverType=exu.DynamicSolverType.DOPRI5)
        return mbs.GetSensorStoredData(sensor)
    return run


def row_pendulum(mb, rounds):
    exu = peer("exudyn")
    model = double_pendulum(mb)
    q0 = {"theta1": THETA0[0], "theta2": THETA0[1]}
    grid = np.linspace(0.0, 4.0, 41)
    exu_runs = {}
    times = [grid]
    if exu is not None:
        log("  exudyn: one run per tolerance (sensor times)")
        for tol in TOLERANCES:
            run = exudyn_pendulum(exu, tol)
            data = run()
            exu_runs[tol] = (run, data)
            times.append(data[:, 0])
    t_all = np.unique(np.concatenate(times))
    log(f"  reference: DOP853 rtol 1e-13 at {t_all.size} times (about 15 s)")
    ref = mb.simulate(model, 4.0, q0, integrator="DOP853", rtol=1e-13, atol=1e-14,
                      t_eval=t_all)
    ref_at = {t: q for t, q in zip(ref.t, ref.q)}

    def mbdyn_run(rtol, method):
        return lambda: mb.simulate(model, 4.0, q0, integrator="DOP853", rtol=rtol,
                                   atol=rtol * 1e-3, t_eval=grid, method=method)

    chosen, errors = {}, {}
    for method in ("jourdain", "symbolic"):
        for rtol in TOLERANCES:
            res = mbdyn_run(rtol, method)()
            err = float(np.abs(res.q - np.array([ref_at[t] for t in res.t])).max())
            if err <= ANGLE_GOAL:
                chosen[method], errors[method] = rtol, err
                break
    if exu is not None:
        for tol, (run, data) in exu_runs.items():
            err = float(np.abs(-data[:, 1:] - np.array([ref_at[t] for t in data[:, 0]])).max())
            if err <= ANGLE_GOAL:
                chosen["exudyn"], errors["exudyn"] = tol, err
                break
    runs = {m: mbdyn_run(chosen[m], m) for m in ("jourdain", "symbolic") if m in chosen}
    if "exudyn" in chosen:
        runs["exudyn"] = exu_runs[chosen["exudyn"]][0]
    t = interleaved(runs, rounds)
    exu_t = t.get("exudyn")
    rows = []
    for m, label in (("jourdain", "double pendulum 4 s, DOP853, 1e-8 rad"),
                     ("symbolic", "double pendulum 4 s, DOP853 symbolic RHS, 1e-8 rad")):
        if m in t:
            rows.append(row(f"{label} (rtol {chosen[m]:g}; error {errors[m]:.1e})", t[m],
                            exu_t, 0.5, "s", "Exudyn DOPRI5" + (
                                f" (tol {chosen['exudyn']:g}; error {errors['exudyn']:.1e})"
                                if exu_t else "")))
        else:
            NOTES.append(f"row 1: mbdyn {m} met 1e-8 rad at none of {TOLERANCES}")
    if exu is not None and "exudyn" not in chosen:
        NOTES.append(f"row 1: Exudyn DOPRI5 met 1e-8 rad at none of {TOLERANCES}")
    NOTES.append("row 1 verified: every run's largest angle error at its output times "
                 "(mbdyn: 41 times; Exudyn: its sensor times, every 0.1 s of its steps) "
                 "against one reference run (mbdyn DOP853, rtol 1e-13, atol 1e-14) at the "
                 "union of those times; Exudyn's angles are about +z (phi = -theta).  "
                 "Errors: " + ", ".join(f"{k} {v:.2e}" for k, v in errors.items()))
    return rows


# ------------------------------------------------------------------ 2: fixed-step RK4
STEPS = 48000


def pendulum_mjcf(dt):
    """The double pendulum in MJCF: inertial elements with the point masses (an inertia
    of 1e-15 kg m^2, MuJoCo needs one), hinges about -z, no contacts."""
    tiny = "1e-15 1e-15 1e-15"
    return f"""
<mujoco model="double pendulum">
  <compiler inertiafromgeom="false" angle="radian"/>
  <option timestep="{dt!r}" integrator="RK4" gravity="0 -9.81 0">
    <flag contact="disable"/>
  </option>
  <worldbody>
    <body name="link1">
      <joint name="theta1" type="hinge" axis="0 0 -1"/>
      <inertial pos="0 {-L1!r} 0" mass="{M1!r}" diaginertia="{tiny}"/>
      <body name="link2" pos="0 {-L1!r} 0">
        <joint name="theta2" type="hinge" axis="0 0 -1"/>
        <inertial pos="0 {-L1!r} 0" mass="{M2!r}" diaginertia="{tiny}"/>
      </body>
    </body>
  </worldbody>
</mujoco>"""


def row_rk4(mb, rounds):
    mujoco = peer("mujoco")
    model = double_pendulum(mb)
    q0 = {"theta1": THETA0[0], "theta2": THETA0[1]}
    dt = 4.0 / STEPS

    def mbdyn_run():
        return mb.simulate(model, 4.0, q0, integrator="rk4", dt=dt)
    runs = {"mbdyn": mbdyn_run}
    final = mbdyn_run().q[-1]
    if mujoco is not None:
        mm = mujoco.MjModel.from_xml_string(pendulum_mjcf(dt))
        md = mujoco.MjData(mm)
        md.qpos[:] = THETA0
        mujoco.mj_forward(mm, md)
        ud = model.forward_dynamics(np.array(THETA0), np.zeros(2))
        acc_err = float(np.abs(md.qacc - ud).max() / np.abs(ud).max())
        spec = mujoco.mjtState.mjSTATE_FULLPHYSICS
        state0 = np.empty(mujoco.mj_stateSize(mm, spec))
        mujoco.mj_getState(mm, md, state0, spec)
        from mujoco import rollout
        out = np.empty((1, STEPS, state0.size))
        control = np.zeros((1, STEPS, mm.nu))

        def mujoco_rollout():
            rollout.rollout(mm, md, state0[None, :], control, state=out)

        def mujoco_python():
            mujoco.mj_setState(mm, md, state0, spec)
            step = mujoco.mj_step
            for _ in range(STEPS):
                step(mm, md)
        mujoco_rollout()
        q_mj = out[0, -1, 1:3]                      # state: time, qpos, qvel, ...
        runs["mujoco rollout"] = mujoco_rollout
        runs["mujoco mj_step loop"] = mujoco_python
        NOTES.append(f"row 2 verified: MuJoCo's qacc at the initial state against mbdyn's "
                     f"accelerations: relative difference {acc_err:.1e}; angles after "
                     f"48 000 RK4 steps differ by {np.abs(q_mj - final).max():.1e} rad "
                     "(a chaotic motion amplifies the 1e-15 inertia and the rounding)")
    t = interleaved(runs, rounds)
    per = {k: v / STEPS * 1e6 for k, v in t.items()}
    rows = [row("RK4 48 000 steps, per step (compiled loop vs rollout)", per["mbdyn"],
                per.get("mujoco rollout"), 1.0, "us", "MuJoCo RK4, mujoco.rollout")]
    if "mujoco mj_step loop" in per:
        rows.append(row("RK4 48 000 steps, per step (compiled loop vs mj_step from Python)",
                        per["mbdyn"], per["mujoco mj_step loop"], None, "us",
                        "MuJoCo RK4, mj_step loop"))
    return rows


# ------------------------------------------------------------------ 3, 4: per call
def to_pinocchio(pin, model):
    """The same tree in pinocchio, built from mbdyn's public records (revolute and
    spherical joints), and a function mapping mbdyn's ``q`` to pinocchio's (quaternion
    ``(w, x, y, z)`` -> ``(x, y, z, w)``; speeds are the same vector)."""
    pm = pin.Model()
    pm.gravity.linear = np.array(model.gravity, dtype=float)
    joint_of = {model.joint(j).child: model.joint(j) for j in model.joints}
    pin_id = {"ground": 0}
    qmap = []
    for frame in model.frames:
        if frame not in joint_of:
            continue
        j = joint_of[frame]
        placement = pin.SE3(np.array(j.orientation, float), np.array(j.position, float))
        if j.kind == "revolute":
            axis = np.array(j.axis, float)
            jm = pin.JointModelRevoluteUnaligned(axis / np.linalg.norm(axis))
        elif j.kind == "spherical":
            jm = pin.JointModelSpherical()
        else:
            raise ValueError(f"to_pinocchio: joint kind {j.kind!r} not translated")
        jid = pm.addJoint(pin_id[j.parent], jm, placement, j.name)
        body = model.body(frame)
        pm.appendBodyToJoint(jid, pin.Inertia(float(body.mass), np.array(body.com, float),
                                              np.array(body.inertia, float)),
                             pin.SE3.Identity())
        pin_id[frame] = jid
        k = model.coordinate_index(j.coordinates[0])
        qmap.append((j.kind, k, pm.idx_qs[jid], model.speed_index(j.speeds[0]),
                     pm.idx_vs[jid]))
    for kind, _, _, um, up in qmap:
        if um != up:
            raise ValueError("to_pinocchio: speeds in another order than mbdyn's")

    def q_pin(q):
        out = np.empty(pm.nq)
        for kind, k, kp, _, _ in qmap:
            if kind == "revolute":
                out[kp] = q[k]
            else:
                out[kp:kp + 3] = q[k + 1:k + 4]
                out[kp + 3] = q[k]
        return out
    return pm, q_pin


def row_per_call(mb, sizes, budget, repeats, which):
    pin = peer("pinocchio")
    rows3, rows4 = [], []
    checks = []
    for joint in fdb.JOINTS:
        for n in sizes:
            log(f"  {joint} chain n={n}")
            model, q, u = fdb.build_chain(mb, n, joint)
            q, u = np.asarray(q, float), np.asarray(u, float)
            out = np.empty(model.nu)
            if hasattr(model, "lowlevel"):
                ll = model.lowlevel()
                entry = f"lowlevel ({ll.method})"
                # positional, as pinocchio's arguments: through the harness's
                # fn(*args, **kwargs) a keyword argument costs a Python function 0.2 us
                # that a direct call (ll.forward_dynamics(q, u, out=out)) does not
                cases = {"mbdyn": (ll.forward_dynamics, (q, u, 0.0, out), {}, 1)}
            else:
                entry = "Model.forward_dynamics"
                cases = {"mbdyn": (model.forward_dynamics, (q, u), {}, 1)}
            ud = model.forward_dynamics(q, u, method="jourdain")
            if pin is not None and "3" in which:
                pm, q_pin = to_pinocchio(pin, model)
                pd = pm.createData()
                qp, tau = q_pin(q), np.zeros(pm.nv)
                Mp = pin.crba(pm, pd, qp).copy()
                Mp = np.triu(Mp) + np.triu(Mp, 1).T
                fp = -pin.nonLinearEffects(pm, pd, qp, u)
                M, f = model.mass_matrix(q), model.forcing(q, u)
                same = max(float(np.abs(Mp - M).max() / np.abs(M).max()),
                           float(np.abs(fp - f).max() / np.abs(f).max()))
                a = pin.aba(pm, pd, qp, u, tau)
                err = float(np.abs(a - ud).max() / np.abs(ud).max())
                checks.append(f"{joint} n={n}: M, f {same:.0e}, aba {err:.0e}")
                if same > 1e-12:
                    NOTES.append(f"row 3: {joint} n={n}: pinocchio's M, f differ from "
                                 f"mbdyn's by {same:.1e} (relative): not the same model")
                if err > 1e-9:
                    NOTES.append(f"row 3: {joint} n={n}: pinocchio.aba's accelerations "
                                 f"differ from mbdyn's by {err:.1e} (relative) although "
                                 f"M and f agree to {same:.0e}: see the accuracy table")
                cases["pin"] = (pin.aba, (pm, pd, qp, u, tau), {}, 1)
            if "4" in which:
                for m in ("jourdain", "newton-euler", "articulated"):
                    cases[m] = (model.forward_dynamics, (q, u), {"method": m}, 1)
                    got = model.forward_dynamics(q, u, method=m)
                    if np.abs(got - ud).max() > 1e-8 * np.abs(ud).max():
                        NOTES.append(f"row 4: {joint} n={n}: {m} differs from jourdain")
            res, _ = fdb.measure(cases, budget, repeats)
            cpu = {k: v["cpu_median_us"] for k, v in res.items()}
            if "3" in which:
                goal = 1.5 if n <= 2 else 1.0
                rows3.append(row(f"forward dynamics, {joint} n={n}: mbdyn {entry} vs "
                                 "pinocchio.aba", cpu["mbdyn"], cpu.get("pin"), goal, "us",
                                 "pinocchio.aba"))
            if "4" in which:
                rows4.append(row(f"{joint} n={n}: method='newton-euler' vs 'jourdain'",
                                 cpu["newton-euler"], cpu["jourdain"], 2.0, "us",
                                 "mbdyn jourdain"))
                rows4.append(row(f"{joint} n={n}: method='articulated' vs 'jourdain' (no "
                                 "goal)", cpu["articulated"], cpu["jourdain"], None, "us",
                                 "mbdyn jourdain"))
                rows4.append(row(f"{joint} n={n}: {entry} vs Model.forward_dynamics "
                                 "'jourdain' (no goal)", cpu["mbdyn"], cpu["jourdain"],
                                 None, "us", "mbdyn jourdain"))
    if checks:
        NOTES.append("row 3 verified: the translated model's crba M and -nle f against "
                     "mbdyn's mass_matrix and forcing, and pinocchio.aba against mbdyn's "
                     "Jourdain accelerations, at the random state of each chain (largest "
                     "difference over the largest entry): " + "; ".join(checks))
    return rows3 + rows4


# ------------------------------------------------------------------ 5: first start
def row_first_start(mb):
    """``benchmarks/first_start.py`` on the checkout whose mbdyn this process imported
    (a copy of its ``mbdyn/`` and ``models/top.toml``)."""
    import first_start
    source = os.path.dirname(os.path.dirname(os.path.abspath(mb.__file__)))
    log(f"  cold and warm runs of {source} in subprocesses (a minute or so)")
    res = first_start.measure(source, n_warm=3, n_cold=1, n_import=3)
    rows = []
    for label, (n, wall, cpu) in res.items():
        goal = 20.0 if label.startswith("cold") else 1.5 if label.startswith("warm") else None
        rows.append({"measure": f"{label} ({n} runs; wall {wall:.2f} s)", "mbdyn": cpu,
                     "peer": None, "peer_name": "(no peer: absolute goal)", "unit": "s CPU",
                     "ratio": None, "goal": goal,
                     "met": None if goal is None else bool(cpu <= goal)})
    return rows


# ------------------------------------------------------------------ accuracy
def ill_conditioned_chain(mb, n=50, light=0.05, seed=7):
    """A chain of ``n`` spherical joints, links alternately heavy (about 1 kg) and very
    light (``light`` times that), with rotated box inertias and gravity; at its random
    state cond(M) is about 1e8 (a 50-link chain of equal links is at about 5e7)."""
    rng = np.random.default_rng(seed)
    s = mb.System(f"ill-conditioned ball chain of {n}")
    parent, offset = "ground", 0.0
    for i in range(n):
        scale = 1.0 if i % 2 == 0 else light
        length = rng.uniform(0.25, 0.35)
        mass = scale * rng.uniform(0.5, 2.0)
        box = mb.inertia.box(mass, rng.uniform(0.02, 0.06), rng.uniform(0.02, 0.06), length)
        Q = fdb.random_rotation(rng)
        inertia = Q @ box @ Q.T
        com = (rng.uniform(-0.01, 0.01), rng.uniform(-0.01, 0.01), -0.5 * length)
        s.add_body(f"link{i}", mass=mass, com=com, inertia=0.5 * (inertia + inertia.T))
        s.add_joint(f"j{i}", "spherical", parent, f"link{i}", position=(0.0, 0.0, -offset))
        parent, offset = f"link{i}", length
    model = s.compile()
    q = model.default_coordinates()
    for k in range(0, model.nq, 4):
        quat = rng.normal(size=4)
        q[k:k + 4] = quat / np.linalg.norm(quat)
    return model, q, rng.uniform(-1.0, 1.0, model.nu)


def refined_solve(M, f, digits=50):
    """The solution of ``M x = f`` for these double matrices, exact to double precision:
    iterative refinement, LU in double, residuals ``f - M x`` in ``digits`` digits
    (mpmath), ``x`` kept as a sum of doubles."""
    import mpmath
    from scipy.linalg import lu_factor, lu_solve
    mpmath.mp.dps = digits
    Mm = [[mpmath.mpf(float(v)) for v in r] for r in M]
    fm = [mpmath.mpf(float(v)) for v in f]
    lu = lu_factor(M)
    x = [mpmath.mpf(0)] * len(f)
    for _ in range(30):
        r = np.array([float(fm[i] - mpmath.fsum(a * b for a, b in zip(Mm[i], x)))
                      for i in range(len(f))])
        dx = lu_solve(lu, r)
        x = [xi + mpmath.mpf(float(d)) for xi, d in zip(x, dx)]
        if np.linalg.norm(dx) <= 1e-20 * np.linalg.norm(np.array([float(v) for v in x])):
            break
    return np.array([float(v) for v in x])


def accuracy(mb):
    pin = peer("pinocchio")
    if peer("mpmath") is None:
        return None
    model, q, u = ill_conditioned_chain(mb)
    cond, _ = model.mass_matrix_condition(q)
    M, f = model.mass_matrix(q), model.forcing(q, u)
    refs = {"mbdyn's M, f": refined_solve(M, f)}
    got = {f"mbdyn {m}": model.forward_dynamics(q, u, method=m)
           for m in ("jourdain", "articulated", "newton-euler")}
    if hasattr(model, "lowlevel"):
        got["mbdyn lowlevel (auto)"] = model.lowlevel().forward_dynamics(q, u).copy()
    if pin is not None:
        pm, q_pin = to_pinocchio(pin, model)
        pd = pm.createData()
        qp = q_pin(q)
        Mp = pin.crba(pm, pd, qp).copy()
        Mp = np.triu(Mp) + np.triu(Mp, 1).T
        fp = -pin.nonLinearEffects(pm, pd, qp, u).copy()
        refs["pinocchio's M, f (crba, -nle)"] = refined_solve(Mp, fp)
        got["pinocchio.aba"] = pin.aba(pm, pd, qp, u, np.zeros(pm.nv)).copy()
    table = []
    for name, a in got.items():
        table.append({"route": name, "errors": {
            r: float(np.linalg.norm(a - x) / np.linalg.norm(x)) for r, x in refs.items()}})
    between = None
    if len(refs) == 2:
        x1, x2 = refs.values()
        between = float(np.linalg.norm(x1 - x2) / np.linalg.norm(x1))
    return {"n": 50, "nu": model.nu, "cond": cond, "table": table, "refs": list(refs),
            "between_refs": between}


# ------------------------------------------------------------------ output
def fmt(v, unit):
    if v is None:
        return "skipped"
    return f"{v:.4g} {unit}"


def print_report(report):
    print(f"mbdyn at {report['source']} (commit {report['commit']}); peers: "
          + ", ".join(f"{k} {v}" for k, v in report["peers"].items()))
    print(f"{os.cpu_count()} cores; CPU time of this process, medians; "
          f"{report['settings']}\n")
    print("| measure | mbdyn | peer | ratio | goal | met |")
    print("|---|---:|---|---:|---:|---|")
    for r in report["rows"]:
        if r["peer_name"].startswith("(no peer"):
            peer_txt = r["peer_name"]
        else:
            peer_txt = f"{r['peer_name']}: {fmt(r['peer'], r['unit'])}"
        ratio = "" if r["ratio"] is None else f"{r['ratio']:.2f}"
        if r["goal"] is None:
            goal = ""
        elif r["peer_name"].startswith("(no peer"):         # an absolute goal
            goal = f"<= {r['goal']:g} {r['unit']}"
        else:
            goal = f"<= {r['goal']:g}x"
        met = "" if r["met"] is None else ("yes" if r["met"] else "no")
        print(f"| {r['measure']} | {fmt(r['mbdyn'], r['unit'])} | {peer_txt} | {ratio} | "
              f"{goal} | {met} |")
    acc = report.get("accuracy")
    if acc:
        print(f"\nAccuracy: 50-link spherical chain, alternating heavy and light links "
              f"(nu = {acc['nu']}), cond(M) = {acc['cond']:.2e}.  Relative error "
              "|a - x| / |x| against the exact solution x of M x = f for:\n")
        print("| route | " + " | ".join(acc["refs"]) + " |")
        print("|---|" + "---:|" * len(acc["refs"]))
        for t in acc["table"]:
            print(f"| {t['route']} | " + " | ".join(f"{t['errors'][r]:.2e}"
                                                    for r in acc["refs"]) + " |")
        if acc["between_refs"] is not None:
            print(f"\n(the two references differ by {acc['between_refs']:.2e}: what the "
                  "rounding of M and f alone allows; errors below it are not meaningful)")
    if report["notes"]:
        print("\nNotes:")
        for note in report["notes"]:
            print(f"* {note}")
    print(f"\n(benchmark wall time {report['wall_s']:.0f} s)")


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--quick", action="store_true",
                   help="fewer rounds, shorter budgets, no cold/warm start (row 5)")
    p.add_argument("--json", action="store_true", help="print JSON instead of tables")
    p.add_argument("--only", default=",".join(ROWS),
                   help=f"comma-separated rows to run, of {','.join(ROWS)} (default all)")
    args = p.parse_args(argv)
    which = set(args.only.split(","))
    unknown = which - set(ROWS)
    if unknown:
        p.error(f"--only: unknown rows {sorted(unknown)}; use some of {','.join(ROWS)}")
    rounds = 5 if args.quick else 11
    budget, repeats = (0.1, 7) if args.quick else (0.4, 15)
    t_start = time.perf_counter()
    warnings.simplefilter("ignore", DeprecationWarning)

    import mbdyn as mb
    rows = []
    if "1" in which:
        log("row 1: double pendulum, DOP853 to 1e-8 rad vs Exudyn DOPRI5")
        rows += row_pendulum(mb, rounds)
    if "2" in which:
        log("row 2: RK4 48 000 steps vs MuJoCo")
        rows += row_rk4(mb, rounds)
    if which & {"3", "4"}:
        log("rows 3, 4: forward dynamics per call")
        rows += row_per_call(mb, SIZES, budget, repeats, which)
    if "5" in which:
        if args.quick:
            NOTES.append("row 5 (cold/warm start) skipped with --quick: run "
                         "benchmarks/first_start.py or this script without --quick")
        else:
            log("row 5: cold and warm start")
            rows += row_first_start(mb)
    acc = None
    if "acc" in which:
        log("accuracy: ill-conditioned 50-link ball chain")
        acc = accuracy(mb)
    versions = {}
    for name in ("pinocchio", "mujoco", "exudyn", "mpmath"):
        mod = sys.modules.get(name)
        versions[name] = getattr(mod, "__version__", "?") if mod else "not loaded"
    src = fdb.source_info(mb)
    report = {"source": src["path"],
              "commit": (f"{src['commit']}{' + uncommitted changes' if src['modified'] else ''}"
                         if src["commit"] else "not a git checkout"),
              "peers": versions,
              "settings": {"quick": args.quick, "rounds": rounds, "budget_s": budget,
                           "repeats": repeats, "only": sorted(which)},
              "rows": rows, "accuracy": acc, "notes": list(dict.fromkeys(NOTES)),
              "wall_s": time.perf_counter() - t_start}
    if args.json:
        print(json.dumps(report, indent=1))
    else:
        print_report(report)


if __name__ == "__main__":
    main()
