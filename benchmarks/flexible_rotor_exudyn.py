#!/usr/bin/env python
"""mbdyn against Exudyn's ``ObjectFFRFreducedOrder`` on a flexible rotor's run-up through
its first critical speed (models/flexible_rotor_runup.toml), at equal accuracy.

    PYTHONPATH=. python benchmarks/flexible_rotor_exudyn.py --quick   # a few minutes
    PYTHONPATH=. python benchmarks/flexible_rotor_exudyn.py           # more repeats and settings

Exudyn is imported from another environment as in benchmarks/flexible_exudyn.py (whose
helpers this script reuses: the point mesh, the solver settings, the tables); without it
the script says so and runs mbdyn's rows only.

The rotor: a cantilevered steel shaft (0.5 m, d = 20 mm, 5 Euler-Bernoulli elements, 4
Craig-Bampton modes: the first and second bending pairs) spinning in its floating frame:
the frame is the shaft's root on a revolute joint about x whose angle is prescribed,
``phi = ALPHA t^2 / 2`` (a run-up at constant angular acceleration, 0 to 150 rad/s in
2.5 s); a 5 kg disk (a point mass) on the tip node, a 10 g unbalance mass 10 mm off the
axis at the tip node, and a damper from the tip to the ground (20 N s/m in y and z, world
axes: external damping; the shaft has no internal damping, which would destabilise it
above the critical speed).  Compared: the tip's lateral deflection in the spinning frame,
``(y, z) = Phi_tip eta`` (m), every 2 ms.

How the two models are made the same:

* **Shaft and disk.**  As in benchmarks/flexible_exudyn.py: the beam as the mass points
  mbdyn's invariants are built from (each element's Gauss points with interpolated mode
  shapes; the disk's point on the tip node), mbdyn's Craig-Bampton basis, its reduced
  stiffness ``K_ee``; the twist inertia ``rho Ip`` in the rigid part (the spin axis: it
  only changes the drive's torque).
* **Unbalance.**  mbdyn: a rigid body of mass ``M_U`` (no inertia) on a fixed joint at the
  node ``tip``, its centre of mass at ``(0, EPS, 0)`` in the node's frame.  Exudyn: one
  more mass point at ``(L, EPS, 0)`` whose mode shapes are the tip node's carried to it,
  ``Phi_tip - s~ Psi_tip`` with ``s = (0, EPS, 0)``.  The same to first order in the tip's
  rotation; mbdyn turns the node frame by the rotation exactly (``Rx Ry Rz``), which
  gives terms of order ``M_U EPS^2 Omega^2 theta`` the linear point lacks: the tools'
  references differ by 2.7e-9 m (1.2e-5 of the peak), in proportion to EPS at the same
  unbalance ``M_U EPS`` (2.0e-10 m at EPS = 1 mm, 2.8e-8 m at 100 mm).
* **Spin.**  mbdyn: the joint's drive ``0.5*ALPHA*t**2``.  Exudyn: a ``GenericJoint``
  from the ground to the frame's node (rotation parameters Rxyz) holding all but the
  rotation about x, and a ``CoordinateConstraint`` on that rotation coordinate whose
  offset is ``ALPHA t^2 / 2`` (and its rate ``ALPHA t`` for the index-2 solver), given as
  Exudyn's symbolic user functions (evaluated in C++, no Python call per evaluation).
* **Damper.**  mbdyn: a ``bearing`` at the node ``tip`` with ``kxx = kyy = 0``,
  ``cxx = cyy = C`` (world y and z).  Exudyn: a ``CartesianSpringDamper`` from the ground
  to the tip's mesh node, damping ``(0, C, C)`` in world axes.
* **Geometric stiffening.**  Off in mbdyn (``-geometric_stiffening``), as in Exudyn's
  linear body; a spin about the shaft's own axis gives no axial force (``omega_y =
  omega_z = 0``, ``a_x = 0``), so the effect is zero here -- printed.

The solvers, the error measure (largest distance to mbdyn's DOP853 at rtol 1e-12, Exudyn's
also to its own finest run), CPU time (process time of the solve, median of interleaved
repeats, one thread) and the equal-accuracy table are those of
benchmarks/flexible_exudyn.py.  mbdyn's settings, all with ``compiled_terms = True``: the
compiled explicit loops (DOP853, RK45; rtol, atol = 1e-3 rtol), the compiled fixed-step
implicit midpoint rule (dt; its iteration matrix kept over steps), and scipy's
implicit Radau, BDF, LSODA (rtol; the compiled state derivative called from Python, the
Jacobian by scipy's finite differences).  mbdyn's compiled code is warmed up first (the
first use of the "force elements" kind compiles for about 35 s on an empty numba cache,
the implicit midpoint's loop about 30 s more; not counted).
"""
import os

for _var in ("OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "OMP_NUM_THREADS"):
    os.environ[_var] = "1"

import argparse  # noqa: E402
import sys  # noqa: E402
import tomllib  # noqa: E402
import warnings  # noqa: E402
from pathlib import Path  # noqa: E402
from time import process_time  # noqa: E402

import numpy as np  # noqa: E402

sys.path.insert(0, str(Path(__file__).resolve().parent))
from flexible_exudyn import (EXUDYN, ROOT, _PointMesh, _Points, all_runs,  # noqa: E402
                             equal_accuracy, error, exu, exudyn_settings, ground_joint,
                             reference_spline, timed_solve)

import mbdyn as mb  # noqa: E402
from mbdyn.flexible import beam_from_spec  # noqa: E402

if exu is not None:
    import exudyn.itemInterface as eii  # noqa: E402
    from exudyn.advancedUtilities import CreateSymbolicUserFunction  # noqa: E402
    from exudyn.FEM import ObjectFFRFreducedOrderInterface  # noqa: E402

ROTOR = ROOT / "models" / "flexible_rotor_runup.toml"
SAMPLE = 0.002                          # s, where both tools' outputs are compared


def tilde(s):
    return np.array([[0.0, -s[2], s[1]], [s[2], 0.0, -s[0]], [-s[1], s[0], 0.0]])


class Rotor:
    """The rotor's data shared by both tools."""

    def __init__(self, t_end=None, effects="-geometric_stiffening"):
        self.scene = scene = mb.load_model(ROTOR, effects=effects)
        self.model = scene.model
        self.t_end = float(t_end or scene.settings["t_end"])
        self.t_out = np.linspace(0.0, self.t_end, int(round(self.t_end / SAMPLE)) + 1)
        self.par = {k: float(v) for k, v in
                    tomllib.load(open(ROTOR, "rb"))["parameters"].items()}
        fb = self.model.flexible["shaft"]
        self.reduced = red = fb.reduced
        self.beam = beam_from_spec(fb.spec["beam"])
        n = red.n_modes
        beam_pts = self.beam.mass_points(red.modes.reshape(-1, n))
        tip = red.node("tip")
        self.tip_phi = red.modes[tip, :3, :]
        # the unbalance: one more point, the tip node's shapes carried to (0, EPS, 0)
        s = np.array([0.0, self.par["EPS"], 0.0])
        u_shape = red.modes[tip, :3, :] - tilde(s) @ red.modes[tip, 3:, :]
        self.points = _Points(
            np.append(beam_pts.mass, self.par["M_U"]),
            np.vstack([beam_pts.position, red.nodes[tip] + s]),
            np.concatenate([beam_pts.inertia, np.zeros((1, 3, 3))]),
            np.concatenate([beam_pts.translation, u_shape[None]]),
            np.concatenate([beam_pts.rotation, np.zeros((1, 3, n))]))
        # the disk's point: the attachment on the tip node (the beam's last mass point)
        self.disk_point = len(beam_pts.mass) - 1
        assert np.allclose(beam_pts.position[self.disk_point], red.nodes[tip])
        self.modal = [self.model.coordinates.index(f"shaft_m{k + 1}") for k in range(n)]

    def deflection(self, eta):
        """The tip's lateral deflection (y, z) in the spinning frame (k, 2), from (k, n)."""
        return eta @ self.tip_phi[1:].T

    def spin_speed(self, t):
        return self.par["ALPHA"] * np.asarray(t)


FIXED = ("implicit-midpoint",)          # mbdyn's fixed-step integrators used here: x is dt


def mbdyn_run(r, integrator, x, compiled, t_eval=None):
    """One mbdyn solve; ``x`` is rtol (atol = 1e-3 rtol), or the step for a fixed-step
    integrator.  Returns (result, CPU of the solve)."""
    m = r.model
    m.compiled_terms = compiled
    step = dict(dt=x) if integrator in FIXED else dict(rtol=x, atol=x * 1e-3)
    t0 = process_time()
    res = mb.simulate(m, r.t_end, r.scene.q0, r.scene.u0, integrator=integrator,
                      t_eval=r.t_out if t_eval is None else t_eval, **step)
    cpu = process_time() - t0
    return res, cpu


def mbdyn_label(integrator, x):
    """The (solver, setting, work) of a run's row."""
    if integrator in FIXED:         # the compiled fixed-step loop
        return f"{integrator} compiled", f"dt {x:g}", "{steps} steps, {evals} evals"
    if integrator in ("RK45", "DOP853"):     # the compiled adaptive loops
        return f"{integrator} compiled", f"rtol {x:g}", "{evals} evals"
    # scipy's solver stepping the compiled state derivative from Python; its Jacobian by
    # scipy's finite differences
    return f"{integrator} (scipy)", f"rtol {x:g}", "{steps} steps, {evals} evals, {njev} jac"


def mbdyn_deflection(r, res):
    return res.t, r.deflection(res.q[:, r.modal])


# ---------------------------------------------------------------- Exudyn side
def exudyn_build(r):
    """An Exudyn system of the rotor; returns (mbs, modal sensor, interface, keep-alive)."""
    P = r.par
    SC = exu.SystemContainer()
    mbs = SC.AddSystem()
    cms = ObjectFFRFreducedOrderInterface(_PointMesh(r.points),
                                          rigidBodyNodeType="NodeType.RotationRxyz")
    cms.stiffnessMatrixReduced = np.array(r.reduced.stiffness_matrix)
    cms.inertiaLocal = cms.inertiaLocal + np.sum(r.points.inertia, axis=0)   # the twist
    obj = cms.AddObjectFFRFreducedOrder(mbs, positionRef=[0, 0, 0])
    n_rigid, n_modal = obj["nRigidBody"], obj["nGenericODE2"]
    o_ground = ground_joint(mbs, n_rigid, [1, 1, 1, 0, 1, 1])
    # the spin: the frame's rotation about x (Rxyz's first angle) prescribed
    n_g = mbs.AddNode(eii.NodePointGround())
    m_gc = mbs.AddMarker(eii.MarkerNodeCoordinate(nodeNumber=n_g, coordinate=0))
    m_rx = mbs.AddMarker(eii.MarkerNodeCoordinate(nodeNumber=n_rigid, coordinate=3))
    alpha = P["ALPHA"]

    def angle(mbs, t, itemNumber, lOffset):
        return 0.5 * alpha * t * t

    def rate(mbs, t, itemNumber, lOffset):
        return alpha * t
    keep = [CreateSymbolicUserFunction(mbs, angle, "offsetUserFunction",
                                       itemTypeName="ObjectConnectorCoordinate"),
            CreateSymbolicUserFunction(mbs, rate, "offsetUserFunction_t",
                                       itemTypeName="ObjectConnectorCoordinate")]
    mbs.AddObject(eii.CoordinateConstraint(markerNumbers=[m_gc, m_rx],
                                           offsetUserFunction=keep[0],
                                           offsetUserFunction_t=keep[1]))
    # the damper: tip to ground, world y and z
    m_tip = mbs.AddMarker(eii.MarkerSuperElementPosition(
        bodyNumber=obj["oFFRFreducedOrder"], meshNodeNumbers=[r.disk_point],
        weightingFactors=[1.0]))
    m_fix = mbs.AddMarker(eii.MarkerBodyPosition(bodyNumber=o_ground,
                                                 localPosition=[P["L"], 0, 0]))
    mbs.AddObject(eii.CartesianSpringDamper(markerNumbers=[m_fix, m_tip],
                                            stiffness=[0, 0, 0], damping=[0, P["C"], P["C"]]))
    s_modal = mbs.AddSensor(eii.SensorNode(nodeNumber=n_modal, storeInternal=True,
                                           outputVariableType=exu.OutputVariableType.Coordinates))
    mbs.Assemble()
    return mbs, s_modal, cms, keep


def exudyn_run(r, solver, steps):
    """One Exudyn solve of a freshly built system; returns (t, deflection, cpu)."""
    mbs, s_modal, _, keep = exudyn_build(r)
    cpu = timed_solve(mbs, exudyn_settings(r, solver, steps, write=SAMPLE), solver)
    modal = mbs.GetSensorStoredData(s_modal)
    return modal[:, 0], r.deflection(modal[:, 1:]), cpu


# ---------------------------------------------------------------- the run-up
def peak(r, t, y):
    """The largest radial deflection, when, and the spin speed then."""
    rad = np.hypot(y[:, 0], y[:, 1])
    k = int(np.argmax(rad))
    return rad[k], t[k], float(r.spin_speed(t[k]))


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--quick", action="store_true", help="fewer repeats and settings")
    args = ap.parse_args()
    warnings.simplefilter("ignore")
    repeats = 3 if args.quick else 7
    r = Rotor()
    red = r.reduced
    w = 2 * np.pi * red.frequencies
    print(f"# mbdyn vs Exudyn ObjectFFRFreducedOrder: {ROTOR.name}, {r.t_end:g} s\n")
    print(f"- shaft: {r.beam.n_elements} elements, {red.n_modes} Craig-Bampton modes (root "
          f"held), {w.round(3)} rad/s; {len(r.points.mass)} mass points (the last: the "
          f"unbalance), mass {r.points.mass.sum():.6f} kg; run-up 0 to "
          f"{r.spin_speed(r.t_end):g} rad/s, the first critical speed {w[0]:.3f} rad/s "
          f"crossed at t = {w[0] / r.par['ALPHA']:.3f} s")
    if exu is None:
        print(f"- {EXUDYN}")
    else:
        print(f"- Exudyn {exu.__version__}")
        _, _, cms, _ = exudyn_build(r)
        inv = red.invariants
        dK = np.abs(cms.stiffnessMatrixReduced - red.stiffness_matrix).max()
        dM = np.abs(cms.massMatrixReduced - red.mass_matrix).max()
        print(f"- reduced matrices, Exudyn's from the mass points (with the unbalance) vs "
              f"mbdyn's shaft (without): |dM_ee| {dM:.1e} (of 1; the unbalance's "
              f"{r.par['M_U']:g} kg), |dK_ee| {dK:.1e}; mass {cms.totalMass:.6f} vs "
              f"{inv.mass:.6f} + {r.par['M_U']:g} kg")

    # mbdyn's reference (DOP853 at rtol 1e-12, compiled terms) on a fine grid
    t_ref = np.linspace(0, r.t_end, int(round(r.t_end / 2e-4)) + 1)
    res, _ = mbdyn_run(r, "DOP853", 1e-12, True, t_eval=t_ref)
    t_r, y_r = mbdyn_deflection(r, res)
    ref = reference_spline(t_r, y_r)
    res_n, cpu_n = mbdyn_run(r, "DOP853", 1e-8, False, t_eval=t_ref)
    stiff = Rotor(effects=None)
    stiff.model.compiled_terms = True
    res_s = mb.simulate(stiff.model, r.t_end, stiff.scene.q0, stiff.scene.u0,
                        integrator="DOP853", rtol=1e-12, atol=1e-15, t_eval=t_ref)
    a_max, t_max, w_max = peak(r, t_r, y_r)
    print(f"- mbdyn reference: DOP853 rtol 1e-12 (compiled terms), "
          f"{res.stats['rhs_evaluations']} evaluations; numpy terms (scipy) at rtol 1e-8 differ by "
          f"{error(*mbdyn_deflection(r, res_n), ref):.1e} m ({cpu_n:.1f} s CPU); the tip's "
          f"largest lateral deflection {a_max * 1e3:.4f} mm at t = {t_max:.4f} s, spin "
          f"{w_max:.2f} rad/s ({w_max / w[0]:.3f} x the first critical speed); geometric "
          f"stiffening (mbdyn's default, not in Exudyn, off here) would move it by "
          f"{error(*mbdyn_deflection(stiff, res_s), ref):.1e} m")

    mb_settings = [("DOP853", x, True) for x in
                   ((1e-4, 1e-6, 1e-8, 1e-10) if args.quick else (
                       1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10))]
    mb_settings += [("RK45", x, True) for x in ((1e-4, 1e-6, 1e-8) if args.quick
                                                else (1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8))]
    # the implicit integrators: the compiled fixed-step implicit midpoint rule (dt), scipy's
    # Radau, BDF, LSODA (compiled terms, from Python)
    mb_settings += [("implicit-midpoint", x, True) for x in (
        (8e-3, 4e-3, 2e-3, 1e-3) if args.quick else (8e-3, 5e-3, 4e-3, 2e-3, 1e-3, 5e-4))]
    mb_settings += [(integ, x, True) for integ, xs in (
        ("Radau", (1e-2, 1e-3, 1e-4) if args.quick else (1e-2, 1e-3, 1e-4, 1e-5, 1e-6)),
        ("BDF", (1e-2, 1e-3) if args.quick else (1e-2, 1e-3, 1e-4, 1e-5)),
        ("LSODA", (1e-2, 1e-3) if args.quick else (1e-2, 1e-3, 1e-4, 1e-5))) for x in xs]
    ex_settings = []
    if exu is not None:
        steps = (312, 625, 1250, 2500, 5000, 10000, 40000) if args.quick else (
            312, 625, 1250, 2500, 5000, 10000, 20000, 40000, 80000, 160000)
        ex_settings = [(solver, n) for solver in ("GeneralizedAlpha", "TrapezoidalIndex2")
                       for n in steps]
        fine = 320000 if args.quick else 640000
        t_x, y_x, cpu_x = exudyn_run(r, "GeneralizedAlpha", fine)
        ex_ref = reference_spline(t_x, y_x)
        t_h, y_h, _ = exudyn_run(r, "GeneralizedAlpha", fine // 2)
        b_max, tb, wb = peak(r, t_x, y_x)
        print(f"- Exudyn reference: GeneralizedAlpha, {fine} steps ({cpu_x:.1f} s CPU); vs "
              f"{fine // 2} steps: {error(t_h, y_h, ex_ref):.1e} m; vs mbdyn's reference: "
              f"largest distance {error(t_x, y_x, ref):.1e} m over the run; its largest "
              f"deflection {b_max * 1e3:.4f} mm at t = {tb:.4f} s (mbdyn's: "
              f"{a_max * 1e3:.4f} mm at {t_max:.4f} s)")
        t_t, y_t, _ = exudyn_run(r, "TrapezoidalIndex2", fine)
        print(f"- Exudyn TrapezoidalIndex2, {fine} steps, vs mbdyn's reference: "
              f"{error(t_t, y_t, ref):.1e} m")

    for integ, x, c in mb_settings:                 # warm up the compiled code
        mbdyn_run(r, integ, x, c)
    runs = {}
    for _ in range(repeats):
        for integ, x, c in mb_settings:
            res, cpu = mbdyn_run(r, integ, x, c)
            solver, setting, work = mbdyn_label(integ, x)
            st = res.stats
            key = ("mbdyn", solver, setting)
            runs.setdefault(key, {"cpu": [], "err": error(*mbdyn_deflection(r, res), ref),
                                  "work": work.format(evals=st["rhs_evaluations"],
                                                      steps=st.get("steps", "?"),
                                                      njev=st.get("njev", "?"))})
            runs[key]["cpu"].append(cpu)
        for solver, n in ex_settings:
            t, y, cpu = exudyn_run(r, solver, n)
            key = ("Exudyn", solver, f"{n} steps")
            runs.setdefault(key, {"cpu": [], "err": error(t, y, ref),
                                  "err_own": error(t, y, ex_ref), "work": f"{n} steps"})
            runs[key]["cpu"].append(cpu)
    rows = all_runs("flexible rotor run-up", runs, repeats,
                    "largest distance of the tip's lateral deflection (m)",
                    (1e-5, 1e-6, 1e-7, 1e-8))
    equal_accuracy(rows)


if __name__ == "__main__":
    main()
