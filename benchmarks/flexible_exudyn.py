#!/usr/bin/env python
"""mbdyn's modally reduced flexible body against Exudyn's ``ObjectFFRFreducedOrder`` (the
floating frame of reference, reduced order) on the same flexible mechanism, at equal
accuracy.

    PYTHONPATH=. python benchmarks/flexible_exudyn.py --quick   # about 2-3 minutes
    PYTHONPATH=. python benchmarks/flexible_exudyn.py           # more repeats and settings
    PYTHONPATH=. python benchmarks/flexible_exudyn.py --no-crank   # the pendulum only

Exudyn is imported from another environment (``EXUDYN_SITE`` below); it is no dependency
of mbdyn.  Without it the script says so and runs nothing of Exudyn's.

The mechanism: models/flexible_pendulum.toml, a slender aluminium arm (0.8 m, 10 x 30 mm,
8 Euler-Bernoulli elements) on a pin about z, released level under gravity (-y), two
cantilever modes (Craig-Bampton with the root as the only interface node: the frame is the
root's tangent frame), 1 % modal damping, 1 s.

How the two models are made the same:

* **FE matrices and modes.**  Exudyn's FFRF body takes nodes with three translations each
  (solid meshes); mbdyn's beam has six DoFs per node.  So Exudyn is given the beam as the
  mass points mbdyn's invariants are built from (``Beam.mass_points``: each element's 4
  Gauss points, weight times rho A, carrying the element's interpolated mode shapes): a
  diagonal 3-per-point mass matrix, whose projections are exactly the consistent beam
  mass matrix's (Euler-Bernoulli without rotary inertia).  The twist inertia rho Ip
  about the beam's own axis, which points cannot carry, is added to the body's rigid
  inertia (the modes do not twist, so it couples with nothing).  The
  mode basis is mbdyn's (the same Craig-Bampton vectors of the same K and M), so the
  reduced mass is ``Phi^T M Phi`` in both and the reduced stiffness is mbdyn's
  ``K_ee = Phi^T K Phi``, handed to Exudyn directly (the beam's K has rotations, which a
  point mesh cannot hold).  The script prints the differences of the reduced matrices.
* **Damping.**  1 % in both modes: mbdyn's modal damping, Exudyn's Rayleigh damping
  ``alpha M + beta K`` fitted to the two modes, which is the same matrix with two modes
  (the script prints the difference).
* **Joint.**  mbdyn: a revolute joint about z at the frame origin (the root).  Exudyn: a
  ``GenericJoint`` from the ground to the frame's rigid node (Rxyz rotation parameters),
  holding x, y, z and the rotations about x and y.
* **Gravity.**  Both -9.81 along y.  Exudyn: the force m g at the mass points' weighted
  mean (a ``MarkerSuperElementPosition`` over all points, weights m_p / m: the centre of
  mass, moved by the modes), whose Jacobian gives the full generalized gravity force.
  (Exudyn's usual ``LoadMassProportional`` puts the tip 6.8e-5 m away from both
  references, as if gravity's modal part were missing -- not investigated; the script
  prints it.)
* **Geometric stiffening.**  mbdyn adds the beam's geometric stiffness under the motion's
  axial force by default; Exudyn's linear FFRF does not.  The comparison runs mbdyn with
  ``-geometric_stiffening`` (the same equations); the size of the effect is printed.

The solvers.  mbdyn: DOP853 and RK45 (adaptive, explicit) with its compiled
floating-frame terms and loop (``model.compiled_terms = True``), and DOP853 on the default
route (numpy terms, scipy's solver).  Exudyn: its implicit index-3 generalized-alpha
(spectral radius 0.9, Exudyn's default) and index-2 trapezoidal rule at fixed steps,
Newton tolerance 1e-10, which is Exudyn's route for constrained FFRF bodies.  Exudyn's
explicit solvers (DOPRI5, RK67, ...) are not usable here: they take no joints, only
``CoordinateConstraint``s to the ground, which they eliminate; with the frame's
coordinates held that way the body did not move at all in Exudyn 1.13.6 (gravity's
generalized force is lost with the eliminated rows), and RK67 returned NaN.

The flexible slider-crank (models/flexible_slider_crank.toml, Simeon's problem of the
IVP test set, 0.1 s): the rod is reduced data (two lateral sine shapes, two axial ones;
the test set's M_ee and K_ee, no damping; 20 Gauss points carrying its mass and section
rotary inertia, plus mass-less nodes root, mid, tip).  Exudyn gets the same points with
their translational mode shapes, M_ee and K_ee overridden by the data's, and the points'
rotary inertia added to the rigid inertia and to the angular-modal coupling
(``mXRefTildePsi``), so that every invariant equals mbdyn's (printed).  The crank: a rigid
body on a joint, its rate held at 150 rad/s by a velocity-level ``CoordinateConstraint``
(mbdyn: a revolute joint with the drive ``OMEGA*t``); the rod's frame pinned to the crank
at (L1, 0, 0) (``GenericJoint``), its node ``tip`` to the slider (a ``SphericalJoint`` on
x and y); the slider a point mass held on the x axis.  Initial state: mbdyn's (the
test set's, projected on the loop).  Compared: rod_m1 (the midpoint's deflection) and
the slider's x3, every 0.5 ms, the largest difference (m); mbdyn's atol is rtol / 1000
here (the modal coordinates are 1e-5 to 1e-4 m), rtol / 100 for the pendulum.

The quantity compared for the pendulum: the tip's position in the world, ``R(theta) (x_tip + Phi_tip
eta)``, over the run (every sample of the coarser output).  The error of a run is the
largest distance to a reference: for mbdyn DOP853 at rtol 1e-12, for Exudyn its own
finest generalized-alpha run, and the two references are compared with each other.  CPU time (process
time of the solve only, models built beforehand, compiled code warmed up) is the median
of interleaved repeats; for each tool and target error the cheapest setting reaching it
is listed, with the ratio of mbdyn's cheapest to it.  Exudyn runs with one thread.  mbdyn's
compiled terms are warmed up first (their first use compiles: about a minute of CPU for
the slider-crank's "loops" kind on an empty numba cache, not counted); the numpy route of
the slider-crank runs once (13 s).
"""
import os

for _var in ("OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "OMP_NUM_THREADS"):
    os.environ[_var] = "1"

import argparse  # noqa: E402
import statistics  # noqa: E402
import sys  # noqa: E402
import warnings  # noqa: E402
from pathlib import Path  # noqa: E402
from time import process_time  # noqa: E402

import numpy as np  # noqa: E402
import scipy.sparse  # noqa: E402
from scipy.interpolate import CubicSpline  # noqa: E402

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))
import mbdyn as mb  # noqa: E402
from mbdyn.flexible import beam_from_spec  # noqa: E402

EXUDYN_SITE = "/tmp/exuvenv/lib/python3.11/site-packages"
try:
    import site
    site.addsitedir(EXUDYN_SITE)
    import exudyn as exu  # noqa: E402
    import exudyn.itemInterface as eii  # noqa: E402
    from exudyn.FEM import ObjectFFRFreducedOrderInterface  # noqa: E402
    from exudyn.rigidBodyUtilities import GetRigidBodyNode  # noqa: E402
    EXUDYN = None
except Exception as exc:  # pragma: no cover - only without Exudyn
    exu = None
    EXUDYN = f"Exudyn not importable ({exc!r}); its rows are skipped"

PENDULUM = ROOT / "models" / "flexible_pendulum.toml"
G = np.array([0.0, -9.81, 0.0])


# ---------------------------------------------------------------- mbdyn side
class Pendulum:
    """The pendulum's data shared by both tools."""

    def __init__(self, t_end):
        self.t_end = t_end
        self.t_out = np.linspace(0.0, t_end, int(round(t_end / 0.002)) + 1)
        scene = mb.load_model(PENDULUM, effects="-geometric_stiffening")
        self.scene = scene
        self.model = scene.model
        fb = self.model.flexible["arm"]
        self.reduced = red = fb.reduced
        self.beam = beam_from_spec(fb.spec["beam"])
        n = red.n_modes
        basis = red.modes.reshape(-1, n)
        pts = self.beam.mass_points(basis)
        self.points = pts
        self.tip_x = red.nodes[red.node("tip")]
        self.tip_phi = red.modes[red.node("tip"), :3, :]
        self.n = n

    def tip(self, angle, eta):
        """World tip positions (k, 3) from the pin angle (k,) and modal coordinates (k, n)."""
        local = self.tip_x[None, :] + eta @ self.tip_phi.T
        c, s = np.cos(angle), np.sin(angle)
        return np.stack([c * local[:, 0] - s * local[:, 1],
                         s * local[:, 0] + c * local[:, 1], local[:, 2]], axis=1)


def mbdyn_run(p, integrator, rtol, compiled):
    """One run sampled where Exudyn's sensors write (every 2 ms)."""
    m = p.model
    m.compiled_terms = compiled
    t0 = process_time()
    res = mb.simulate(m, p.t_end, p.scene.q0, p.scene.u0, integrator=integrator, rtol=rtol,
                      atol=rtol * 1e-2, t_eval=p.t_out)
    cpu = process_time() - t0
    return res, cpu


def mbdyn_tip(p, res):
    i = [p.model.coordinates.index(c) for c in ("pin", "arm_m1", "arm_m2")]
    return res.t, p.tip(res.q[:, i[0]], res.q[:, i[1:]])


# ---------------------------------------------------------------- Exudyn side
class _PointMesh:
    """What ObjectFFRFreducedOrderInterface reads from an FEMinterface: the beam as mass
    points (3 translations each), their mass matrix and the mode basis."""

    def __init__(self, pts):
        self.positions = np.asarray(pts.position, dtype=float)
        n_pts = len(self.positions)
        self.modeBasis = {"matrix": np.asarray(pts.translation).reshape(3 * n_pts, -1),
                          "type": "NormalModes"}
        self.postProcessingModes = {}
        self._M = scipy.sparse.diags(np.repeat(pts.mass, 3)).tocsr()
        self._K = scipy.sparse.csr_matrix((3 * n_pts, 3 * n_pts))   # replaced below

    def GetNodePositionsAsArray(self):
        return self.positions

    def GetSurfaceTriangles6(self):
        return []

    def GetSurfaceTriangles(self):
        return []

    def GetMassMatrix(self, sparse=True):
        return self._M

    def GetStiffnessMatrix(self, sparse=True):
        return self._K


def rayleigh(red):
    """alpha, beta of alpha M + beta K matching mbdyn's modal damping on two modes."""
    w = 2 * np.pi * red.frequencies[:2]
    zeta = np.diag(red.damping_matrix)[:2] / (2 * w)      # M_ee = I, K_ee diagonal
    A = np.array([[1.0, w[0] ** 2], [1.0, w[1] ** 2]])
    return np.linalg.solve(A, 2 * zeta * w)


def ground_joint(mbs, node, constrained_axes):
    """The ground, and a ``GenericJoint`` from it (at the origin) to the rigid ``node``
    holding ``constrained_axes``; returns the ground object's number."""
    o_ground = mbs.AddObject(eii.ObjectGround())
    m_ground = mbs.AddMarker(eii.MarkerBodyRigid(bodyNumber=o_ground, localPosition=[0, 0, 0]))
    m_node = mbs.AddMarker(eii.MarkerNodeRigid(nodeNumber=node))
    mbs.AddObject(eii.GenericJoint(markerNumbers=[m_ground, m_node],
                                   constrainedAxes=list(constrained_axes)))
    return o_ground


def timed_solve(mbs, settings, solver):
    """``SolveDynamic`` with Exudyn's ``solver``; returns its CPU seconds (raises if it
    failed)."""
    t0 = process_time()
    ok = mbs.SolveDynamic(settings, solverType=getattr(exu.DynamicSolverType, solver))
    cpu = process_time() - t0
    if not ok:
        raise RuntimeError(f"Exudyn {solver} failed")
    return cpu


def exudyn_build(p, mass_load=False):
    """An Exudyn system of the pendulum; returns (SC, mbs, sensor numbers, reduced data)."""
    SC = exu.SystemContainer()
    mbs = SC.AddSystem()
    cms = ObjectFFRFreducedOrderInterface(_PointMesh(p.points),
                                          rigidBodyNodeType="NodeType.RotationRxyz")
    cms.stiffnessMatrixReduced = np.array(p.reduced.stiffness_matrix)
    # the points' own rotary inertia (the twist, rho Ip, about the beam's axis): points on
    # the axis have none, and the free rotation about x would leave M singular
    cms.inertiaLocal = cms.inertiaLocal + np.sum(p.points.inertia, axis=0)
    alpha, beta = rayleigh(p.reduced)
    obj = cms.AddObjectFFRFreducedOrder(mbs, positionRef=[0, 0, 0],
                                        massProportionalDamping=alpha,
                                        stiffnessProportionalDamping=beta,
                                        gravity=list(G) if mass_load else [0, 0, 0])
    n_rigid, n_modal = obj["nRigidBody"], obj["nGenericODE2"]
    if not mass_load:
        # gravity as m g at the mass points' weighted mean, the centre of mass with its
        # modal part, so its Jacobian gives the whole generalized force (m g, c x g, C^T g)
        m = np.asarray(p.points.mass)
        marker = mbs.AddMarker(eii.MarkerSuperElementPosition(
            bodyNumber=obj["oFFRFreducedOrder"], meshNodeNumbers=list(range(len(m))),
            weightingFactors=list(m / m.sum())))
        mbs.AddLoad(eii.LoadForceVector(markerNumber=marker, loadVector=list(m.sum() * G)))
    ground_joint(mbs, n_rigid, [1, 1, 1, 1, 1, 0])
    s_rigid = mbs.AddSensor(eii.SensorNode(nodeNumber=n_rigid, storeInternal=True,
                                           outputVariableType=exu.OutputVariableType.Coordinates))
    s_modal = mbs.AddSensor(eii.SensorNode(nodeNumber=n_modal, storeInternal=True,
                                           outputVariableType=exu.OutputVariableType.Coordinates))
    mbs.Assemble()
    return SC, mbs, (s_rigid, s_modal), cms


def exudyn_settings(p, solver, steps, write=0.002):
    s = exu.SimulationSettings()
    s.timeIntegration.endTime = p.t_end
    s.timeIntegration.numberOfSteps = int(steps)
    s.timeIntegration.verboseMode = 0
    s.displayComputationTime = False
    s.displayStatistics = False
    s.parallel.numberOfThreads = 1
    s.solutionSettings.writeSolutionToFile = False
    s.solutionSettings.sensorsWritePeriod = write
    s.timeIntegration.generalizedAlpha.spectralRadius = 0.9
    s.timeIntegration.newton.relativeTolerance = 1e-10
    s.timeIntegration.newton.absoluteTolerance = 1e-12
    s.timeIntegration.adaptiveStep = False
    return s


def exudyn_run(p, solver, steps, mass_load=False):
    """One Exudyn solve of a freshly built system; returns (t, tip, cpu, steps)."""
    SC, mbs, sensors, _ = exudyn_build(p, mass_load)
    cpu = timed_solve(mbs, exudyn_settings(p, solver, steps), solver)
    rigid = mbs.GetSensorStoredData(sensors[0])
    modal = mbs.GetSensorStoredData(sensors[1])
    return rigid[:, 0], p.tip(rigid[:, 6], modal[:, 1:]), cpu, int(steps)


# ---------------------------------------------------------------- slider-crank
CRANK = ROOT / "models" / "flexible_slider_crank.toml"


class _Points:
    def __init__(self, mass, position, inertia, translation, rotation):
        self.mass, self.position, self.inertia = mass, position, inertia
        self.translation, self.rotation = translation, rotation


class SliderCrank:
    """models/flexible_slider_crank.toml (Simeon's, the IVP test set's): data shared."""

    def __init__(self):
        import tomllib
        self.scene = scene = mb.load_model(CRANK)
        self.model = scene.model
        self.t_end = float(scene.settings["t_end"])
        self.t_out = np.linspace(0.0, self.t_end, int(round(self.t_end / 0.0005)) + 1)
        self.reduced = red = self.model.flexible["rod"].reduced
        self.par = {k: float(v) for k, v in tomllib.load(open(CRANK, "rb"))["parameters"].items()}
        data = tomllib.load(open(ROOT / "models" / "data" / "flexible_slider_crank_rod.toml", "rb"))
        nm = np.array(data["node_mass"], dtype=float)
        self.points = _Points(nm[:, 0, 0], red.nodes, nm[:, 3:, 3:], red.modes[:, :3, :],
                              red.modes[:, 3:, :])
        self.tip = red.node("tip")
        self.idx = [self.model.coordinates.index(c) for c in
                    ("x3", "rod_m1", "rod_m2", "rod_m3", "rod_m4")]

    def series(self, x3, eta):
        """What is compared: the midpoint deflection rod_m1 (m) and the slider's x3."""
        return np.column_stack([eta[:, 0], x3])


def crank_mbdyn_run(c, integrator, rtol, compiled):
    c.model.compiled_terms = compiled
    t0 = process_time()
    res = mb.simulate(c.model, c.t_end, c.scene.q0, c.scene.u0, integrator=integrator,
                      rtol=rtol, atol=rtol * 1e-3, t_eval=c.t_out)
    cpu = process_time() - t0
    q = res.q[:, c.idx]
    return res.t, c.series(q[:, 0], q[:, 1:]), cpu, res


def crank_exudyn_build(c):
    """Exudyn's slider-crank: the driven crank (a rigid body on a joint, its rotation rate
    held at OMEGA by a velocity-level coordinate constraint), the rod as an FFRF body from
    the same data (its mass points, modes, and the test set's M_ee, K_ee), the slider a
    point mass on x; the rod's frame pinned to the crank, its node "tip" to the slider."""
    P = c.par
    L1, OMEGA = P["L1"], P["OMEGA"]
    q0, u0 = c.scene.q0, c.scene.u0
    co = c.model.coordinates
    x3, x3d = q0[co.index("x3")], u0[co.index("x3")]
    w_rod = OMEGA + u0[co.index("phi2")]                        # absolute, about z
    eta0 = q0[c.idx[1:]]
    eta0_t = u0[c.idx[1:]]
    SC = exu.SystemContainer()
    mbs = SC.AddSystem()
    # crank
    Jyy = P["J1"] - P["M1"] * L1 ** 2 / 4
    n_crank = mbs.AddNode(GetRigidBodyNode(exu.NodeType.RotationRxyz,
                                           angularVelocity=[0, 0, OMEGA]))
    o_crank = mbs.AddObject(eii.ObjectRigidBody(nodeNumber=n_crank, physicsMass=P["M1"],
                                      physicsInertia=[1e-9, Jyy + P["M1"] * L1 ** 2 / 4,
                                                      Jyy + P["M1"] * L1 ** 2 / 4, 0, 0, 0],
                                      physicsCenterOfMass=[L1 / 2, 0, 0]))
    ground_joint(mbs, n_crank, [1, 1, 1, 1, 1, 0])
    n_g = mbs.AddNode(eii.NodePointGround())
    m_gc = mbs.AddMarker(eii.MarkerNodeCoordinate(nodeNumber=n_g, coordinate=0))
    m_rz = mbs.AddMarker(eii.MarkerNodeCoordinate(nodeNumber=n_crank, coordinate=5))
    mbs.AddObject(eii.CoordinateConstraint(markerNumbers=[m_gc, m_rz], offset=OMEGA,
                                           velocityLevel=True))
    # rod
    cms = ObjectFFRFreducedOrderInterface(_PointMesh(c.points),
                                          rigidBodyNodeType="NodeType.RotationRxyz")
    red = c.reduced
    cms.massMatrixReduced = np.array(red.mass_matrix)            # the test set's
    cms.stiffnessMatrixReduced = np.array(red.stiffness_matrix)
    J = c.points.inertia
    cms.inertiaLocal = cms.inertiaLocal + J.sum(axis=0)
    cms.mXRefTildePsi = cms.mXRefTildePsi - np.einsum("pij,pjn->in", J, c.points.rotation)
    rod = cms.AddObjectFFRFreducedOrder(mbs, positionRef=[L1, 0, 0],
                                        initialVelocity=[0, OMEGA * L1, 0],
                                        initialAngularVelocity=[0, 0, w_rod])
    n_modal = rod["nGenericODE2"]
    mbs.SetNodeParameter(n_modal, "initialCoordinates", list(eta0))
    mbs.SetNodeParameter(n_modal, "initialCoordinates_t", list(eta0_t))
    m_pin = mbs.AddMarker(eii.MarkerBodyRigid(bodyNumber=o_crank, localPosition=[L1, 0, 0]))
    m_rod0 = mbs.AddMarker(eii.MarkerNodeRigid(nodeNumber=rod["nRigidBody"]))
    mbs.AddObject(eii.GenericJoint(markerNumbers=[m_pin, m_rod0],
                                   constrainedAxes=[1, 1, 1, 1, 1, 0]))
    # slider
    n_sl = mbs.AddNode(eii.NodePoint(referenceCoordinates=[x3, 0, 0],
                                     initialVelocities=[x3d, 0, 0]))
    mbs.AddObject(eii.MassPoint(nodeNumber=n_sl, physicsMass=P["M3"]))
    for k in (1, 2):
        mk = mbs.AddMarker(eii.MarkerNodeCoordinate(nodeNumber=n_sl, coordinate=k))
        mbs.AddObject(eii.CoordinateConstraint(markerNumbers=[m_gc, mk]))
    m_tip = mbs.AddMarker(eii.MarkerSuperElementPosition(
        bodyNumber=rod["oFFRFreducedOrder"], meshNodeNumbers=[c.tip], weightingFactors=[1.0]))
    m_sl = mbs.AddMarker(eii.MarkerNodePosition(nodeNumber=n_sl))
    mbs.AddObject(eii.SphericalJoint(markerNumbers=[m_tip, m_sl], constrainedAxes=[1, 1, 0]))
    s_modal = mbs.AddSensor(eii.SensorNode(nodeNumber=n_modal, storeInternal=True,
                                           outputVariableType=exu.OutputVariableType.Coordinates))
    s_sl = mbs.AddSensor(eii.SensorNode(nodeNumber=n_sl, storeInternal=True,
                                        outputVariableType=exu.OutputVariableType.Position))
    mbs.Assemble()
    return mbs, (s_modal, s_sl), cms


def crank_exudyn_run(c, solver, steps):
    mbs, (s_modal, s_sl), _ = crank_exudyn_build(c)
    p = type("P", (), {"t_end": c.t_end})
    cpu = timed_solve(mbs, exudyn_settings(p, solver, steps, write=0.0005), solver)
    modal = mbs.GetSensorStoredData(s_modal)
    sl = mbs.GetSensorStoredData(s_sl)
    return modal[:, 0], c.series(sl[:, 1], modal[:, 1:]), cpu


# ---------------------------------------------------------------- comparison
def error(t, tip, ref):
    return float(np.max(np.linalg.norm(tip - ref(t), axis=1)))


def reference_spline(t, tip):
    return CubicSpline(t, tip, axis=0)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--quick", action="store_true", help="fewer repeats and settings")
    ap.add_argument("--t-end", type=float, default=1.0, help="pendulum's run (s)")
    ap.add_argument("--no-crank", action="store_true", help="the pendulum only")
    args = ap.parse_args()
    warnings.simplefilter("ignore")
    repeats = 3 if args.quick else 7
    p = Pendulum(args.t_end)
    red = p.reduced
    print(f"# mbdyn vs Exudyn ObjectFFRFreducedOrder: {PENDULUM.name}, {args.t_end:g} s\n")
    print(f"- beam: {p.beam.n_elements} elements, {red.n_modes} Craig-Bampton modes (root "
          f"held), {red.frequencies.round(3)} Hz; {len(p.points.mass)} mass points, "
          f"mass {p.points.mass.sum():.6f} kg")
    if exu is None:
        print(f"- {EXUDYN}")
    else:
        print(f"- Exudyn {exu.__version__}")
        _, _, _, cms = exudyn_build(p)
        dM = np.abs(cms.massMatrixReduced - red.mass_matrix).max()
        dK = np.abs(cms.stiffnessMatrixReduced - red.stiffness_matrix).max()
        a, b = rayleigh(red)
        dC = np.abs(a * red.mass_matrix + b * red.stiffness_matrix - red.damping_matrix).max()
        inv = red.invariants
        print(f"- reduced matrices, Exudyn's from the mass points vs mbdyn's: |dM_ee| "
              f"{dM:.1e} (of 1), |dK_ee| {dK:.1e}, Rayleigh vs modal damping |dC_ee| "
              f"{dC:.1e} (of {np.abs(red.damping_matrix).max():.2f}); mass {cms.totalMass:.6f}"
              f" vs {inv.mass:.6f} kg, centre of mass x {cms.chiU[0]:.6f} vs "
              f"{inv.first_moment[0] / inv.mass:.6f} m, inertia about z "
              f"{cms.inertiaLocal[2, 2]:.6e} vs {inv.inertia[2, 2]:.6e} kg m^2")

    # mbdyn reference (DOP853 at rtol 1e-12, compiled terms), the tip on a fine grid
    t_ref = np.linspace(0, args.t_end, int(round(args.t_end / 2e-4)) + 1)
    p.model.compiled_terms = True
    res = mb.simulate(p.model, args.t_end, p.scene.q0, p.scene.u0, integrator="DOP853",
                      rtol=1e-12, atol=1e-14, t_eval=t_ref)
    ref = reference_spline(*mbdyn_tip(p, res))
    p.model.compiled_terms = False
    res_n = mb.simulate(p.model, args.t_end, p.scene.q0, p.scene.u0, integrator="DOP853",
                        rtol=1e-11, atol=1e-13, t_eval=t_ref)
    stiff = mb.load_model(PENDULUM)
    stiff.model.compiled_terms = True
    res_s = mb.simulate(stiff.model, args.t_end, stiff.q0, stiff.u0, integrator="DOP853",
                        rtol=1e-12, atol=1e-14, t_eval=t_ref)
    i = [stiff.model.coordinates.index(c) for c in ("pin", "arm_m1", "arm_m2")]
    tip_s = p.tip(res_s.q[:, i[0]], res_s.q[:, i[1:]])
    defl = np.abs(res.q[:, p.model.coordinates.index("arm_m1")] * p.tip_phi[1, 0]).max()
    print(f"- mbdyn reference: DOP853 rtol 1e-12 (compiled terms); numpy terms at rtol 1e-11 "
          f"differ by {error(*mbdyn_tip(p, res_n), ref):.1e} m; largest in-plane tip "
          f"deflection {defl * 1e3:.3f} mm; tip at t = {args.t_end:g} s "
          f"{ref(args.t_end).round(6)} m; geometric stiffening (mbdyn's default, not in "
          f"Exudyn, off here) would move the tip by up to "
          f"{np.linalg.norm(tip_s - ref(t_ref), axis=1).max():.1e} m")

    # the settings
    mb_settings = [("DOP853", r, True) for r in
                   ((1e-3, 1e-4, 1e-6, 1e-8, 1e-10) if args.quick else (
                       1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10))]
    mb_settings += [("RK45", r, True) for r in ((1e-3, 1e-4, 1e-6, 1e-8) if args.quick
                                                else (1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8))]
    mb_settings += [("DOP853", r, False) for r in ((1e-4, 1e-6) if args.quick
                                                   else (1e-4, 1e-6, 1e-8))]
    ex_settings = []
    if exu is not None:
        steps = (250, 500, 1000, 2000, 8000, 32000) if args.quick else (
            250, 500, 1000, 2000, 4000, 8000, 16000, 32000, 64000)
        ex_settings = [(solver, n) for solver in ("GeneralizedAlpha", "TrapezoidalIndex2")
                       for n in steps]
        # Exudyn's own reference: its finest run; the next coarser shows its convergence
        fine = 128000 if args.quick else 256000
        t_x, tip_x, cpu_x, _ = exudyn_run(p, "GeneralizedAlpha", fine)
        ex_ref = reference_spline(t_x, tip_x)
        t_h, tip_h, _, _ = exudyn_run(p, "GeneralizedAlpha", fine // 2)
        print(f"- Exudyn reference: GeneralizedAlpha, {fine} steps ({cpu_x:.1f} s CPU); vs "
              f"{fine // 2} steps: {error(t_h, tip_h, ex_ref):.1e} m (second order: its own "
              f"error about a third of that); vs mbdyn's reference: largest tip distance "
              f"{error(t_x, tip_x, ref):.1e} m over the run, "
              f"{np.linalg.norm(tip_x[-1] - ref(t_x[-1])):.1e} m at t = {args.t_end:g} s")
        t_t, tip_t, _, _ = exudyn_run(p, "TrapezoidalIndex2", fine)
        t_m, tip_m, _, _ = exudyn_run(p, "GeneralizedAlpha", fine, mass_load=True)
        print(f"- Exudyn TrapezoidalIndex2, {fine} steps, vs mbdyn's reference: "
              f"{error(t_t, tip_t, ref):.1e} m; GeneralizedAlpha with gravity as Exudyn's "
              f"LoadMassProportional instead, {fine} steps: {error(t_m, tip_m, ref):.1e} m")

    # warm up mbdyn's compiled code (numba cache), then interleave the repeats
    for integ, r, c in mb_settings:
        mbdyn_run(p, integ, r, c)
    runs = {}
    for _ in range(repeats):
        for integ, r, c in mb_settings:
            res, cpu = mbdyn_run(p, integ, r, c)
            key = ("mbdyn", f"{integ}{' compiled' if c else ' numpy+scipy'}", f"rtol {r:g}")
            e = error(*mbdyn_tip(p, res), ref)
            runs.setdefault(key, {"cpu": [], "err": e,
                                  "work": f"{res.stats['rhs_evaluations']} evals"})
            runs[key]["cpu"].append(cpu)
        for solver, n in ex_settings:
            t, tip, cpu, n_steps = exudyn_run(p, solver, n)
            key = ("Exudyn", solver, f"{n} steps")
            runs.setdefault(key, {"cpu": [], "err": error(t, tip, ref),
                                  "err_own": error(t, tip, ex_ref),
                                  "work": f"{n_steps} steps"})
            runs[key]["cpu"].append(cpu)
    rows = all_runs("flexible pendulum", runs, repeats, "largest tip distance (m)",
                    (1e-4, 1e-6, 1e-8))
    if exu is not None and not args.no_crank:
        rows += slider_crank(args, repeats)
    equal_accuracy(rows)


def all_runs(name, runs, repeats, what, targets):
    """Prints every run of a mechanism; returns the equal-accuracy rows."""
    for v in runs.values():
        v["med"] = statistics.median(v["cpu"])
    print(f"\n{name}, all runs (median CPU s of {repeats} interleaved repeats unless noted; "
          f"error: {what} to mbdyn's reference, Exudyn's also to its own):\n")
    print("| tool | solver | setting | error | error vs own ref | work | CPU (s) |")
    print("|---|---|---|---|---|---|---|")
    for (tool, solver, setting), v in runs.items():
        own = f"{v['err_own']:.1e}" if "err_own" in v else "-"
        print(f"| {tool} | {solver} | {setting} | {v['err']:.1e} | {own} | {v['work']} | "
              f"{v['med']:.4f} |")
    rows = []
    for target in targets:
        best = {}
        for key, v in runs.items():
            if v["err"] <= target and (key[:2] not in best or v["med"] < best[key[:2]][1]["med"]):
                best[key[:2]] = (key, v)
        mb_best = min((v["med"] for (k, v) in best.values() if k[0] == "mbdyn"), default=None)
        ex_best = min((v["med"] for (k, v) in best.values() if k[0] == "Exudyn"), default=None)
        for (tool, solver), (key, v) in sorted(best.items(), key=lambda kv: kv[1][1]["med"]):
            ratio = f"{mb_best / v['med']:.2f}" if mb_best is not None else "-"
            vs_ex = f"{v['med'] / ex_best:.2f}" if ex_best is not None else "-"
            rows.append(f"| {name} | {target:.0e} | {tool} | {solver} | {key[2]} | "
                        f"{v['err']:.1e} | {v['work']} | {v['med']:.4f} | {ratio} | {vs_ex} |")
        for tool, solver in sorted({k[:2] for k in runs} - set(best)):
            rows.append(f"| {name} | {target:.0e} | {tool} | {solver} | none reached | "
                        "- | - | - | - | - |")
    return rows


def equal_accuracy(rows):
    print("\nAt equal accuracy: per target, the cheapest run of each solver whose error "
          "(vs mbdyn's reference, on the same samples) is below it; mbdyn / this = the CPU "
          "of mbdyn's cheapest run reaching the target over this one's (below 1: mbdyn "
          "faster); this / Exudyn = this run's CPU over Exudyn's cheapest.\n")
    print("| mechanism | target (m) | tool | solver | setting | error (m) | work | "
          "CPU (s) | mbdyn / this | this / Exudyn |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    for row in rows:
        print(row)


def slider_crank(args, repeats):
    """The flexible slider-crank: runs, all-runs table; returns equal-accuracy rows."""
    c = SliderCrank()
    print(f"\n## {CRANK.name}, {c.t_end:g} s\n")
    red = c.reduced
    _, _, cms = crank_exudyn_build(c)
    inv = red.invariants
    print(f"- rod: reduced data, {red.n_modes} coordinates, {len(c.points.mass)} points "
          f"(20 Gauss points with mass, root, mid, tip); Exudyn's invariants from them vs "
          f"mbdyn's: mass {abs(cms.totalMass - inv.mass):.1e}, first moment "
          f"{np.abs(cms.totalMass * cms.chiU - inv.first_moment).max():.1e}, modal first "
          f"moment {np.abs(cms.mPhitTPsi - inv.modal_first_moment).max():.1e}, Cr0 "
          f"{np.abs(-cms.mXRefTildePsi - inv.coupling).max():.1e}, inertia "
          f"{np.abs(cms.inertiaLocal - inv.inertia).max():.1e}; M_ee and K_ee the data's "
          "(the test set's) in both")
    c.model.compiled_terms = True
    res = mb.simulate(c.model, c.t_end, c.scene.q0, c.scene.u0, integrator="DOP853",
                      rtol=1e-12, atol=1e-15, t_eval=c.t_out)
    q = res.q[:, c.idx]
    y_ref = c.series(q[:, 0], q[:, 1:])
    print(f"- mbdyn reference: DOP853 rtol 1e-12 (compiled terms), "
          f"{res.stats['rhs_evaluations']} evaluations; rod_m1(0.1 s) = {y_ref[-1, 0]:.12e} m "
          "(the test set's: 1.893192899613509e-04)")
    fine = 128000 if args.quick else 256000
    t_x, y_x, cpu_x = crank_exudyn_run(c, "GeneralizedAlpha", fine)
    t_h, y_h, _ = crank_exudyn_run(c, "GeneralizedAlpha", fine // 2)

    def err(t, y, yr):
        k = np.searchsorted(c.t_out, t - 1e-12)
        return float(np.abs(y - yr[k]).max())
    ex_ref = y_x
    print(f"- Exudyn reference: GeneralizedAlpha, {fine} steps ({cpu_x:.1f} s CPU); vs "
          f"{fine // 2} steps: {err(t_h, y_h, y_x):.1e} m; vs mbdyn's reference: "
          f"{err(t_x, y_x, y_ref):.1e} m (largest over rod_m1 and x3 and the samples); "
          f"rod_m1(0.1 s) = {y_x[-1, 0]:.12e} m")
    mb_settings = [("DOP853", r, True) for r in ((1e-3, 1e-4, 1e-6, 1e-8) if args.quick else
                                                 (1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-10))]
    mb_settings += [("RK45", r, True) for r in ((1e-3, 1e-4, 1e-6) if args.quick else
                                                (1e-3, 1e-4, 1e-5, 1e-6, 1e-7))]
    numpy_settings = [("DOP853", 1e-6, False)]
    steps = (1000, 2000, 4000, 8000, 32000) if args.quick else (500, 1000, 2000, 4000, 8000, 16000,
                                                          32000, 64000)
    ex_settings = [(s, n) for s in ("GeneralizedAlpha", "TrapezoidalIndex2") for n in steps]
    for integ, r, comp in mb_settings:
        crank_mbdyn_run(c, integ, r, comp)
    runs = {}

    def mb_one(integ, r, comp):
        t, y, cpu, res = crank_mbdyn_run(c, integ, r, comp)
        key = ("mbdyn", f"{integ}{' compiled' if comp else ' numpy+scipy'}", f"rtol {r:g}")
        runs.setdefault(key, {"cpu": [], "err": err(t, y, y_ref),
                              "work": f"{res.stats['rhs_evaluations']} evals"})
        runs[key]["cpu"].append(cpu)
    for _ in range(repeats):
        for s in mb_settings:
            mb_one(*s)
        for solver, n in ex_settings:
            t, y, cpu = crank_exudyn_run(c, solver, n)
            key = ("Exudyn", solver, f"{n} steps")
            runs.setdefault(key, {"cpu": [], "err": err(t, y, y_ref),
                                  "err_own": err(t, y, ex_ref), "work": f"{n} steps"})
            runs[key]["cpu"].append(cpu)
    for s in numpy_settings:            # slow: once
        mb_one(*s)
        key = ("mbdyn", "DOP853 numpy+scipy", f"rtol {s[1]:g}")
        runs[key]["work"] += " (1 run)"
    return all_runs("flexible slider-crank", runs, repeats,
                    "largest |difference| of rod_m1 and x3 (m)", (1e-6, 1e-8))


if __name__ == "__main__":
    main()
