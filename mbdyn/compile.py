"""The compiled, frozen ``Model``: flat arrays in topological order and the numeric API.

``System.compile()`` (in ``mbdyn.model``) validates the tree and hands its elements here in
topological order; this layer knows nothing of the tree, only of the element records.
A changed parameter means a new compile, which is cheap (the kernels are compiled once per
machine and cached by numba).

State conventions: ``q`` (coordinates) and ``u`` (speeds) are the *free* ones, in the order
``Model.coordinates`` / ``Model.speeds``; driven joints have no entry, their motion comes
from their drives.  Vectors are in inertial (world) components unless stated.
"""
from __future__ import annotations

from dataclasses import dataclass

import math

import numpy as np

from .errors import ModelError, NonFiniteError, SingularMassMatrixError
from .force_packing import pack_forces
from .kernels import dynamics as kd
from .kernels import evaluate as ke
from .kernels import forces as kf
from .kernels import joints as kj
from .kernels import packed as kp
from .kernels.kinematics import point_jacobian

#: formulations of the forward dynamics: ``M(q) u' = f`` (Jourdain, composite-rigid-body
#: mass matrix and Cholesky), the articulated-body algorithm (O(n)), the Newton-Euler
#: system with reaction unknowns eliminated in tree order (O(n)) and the same system as the
#: textbook writes it, assembled dense and solved by LU
METHODS = ("jourdain", "articulated", "newton-euler", "newton-euler-dense")
#: "auto" takes the articulated-body route from this many free speeds on (below it the
#: mass matrix and its Cholesky factor are as cheap or cheaper: at 4 speeds the two cost
#: the same, at 6 the articulated bodies 7-11 % less; docs/performance.md)
ARTICULATED_FROM = 6


def _perpendicular_pair(a):
    """Two unit vectors completing ``a`` to a right-handed orthonormal basis."""
    helper = np.eye(3)[np.argmin(np.abs(a))]
    n1 = np.cross(a, helper)
    n1 /= np.linalg.norm(n1)
    return n1, np.cross(a, n1)


def reaction_basis(joint):
    """Directions (child-frame components) of the reaction components a joint transmits:
    ``[(force, moment), ...]`` -- six minus its degrees of freedom, plus the drive's."""
    e = np.eye(3)
    z = np.zeros(3)
    kind = joint.kind
    forces = [(e[k], z) for k in range(3)]
    moments = [(z, e[k]) for k in range(3)]
    if kind == "fixed":
        basis = forces + moments
    elif kind in ("spherical", "euler"):
        basis = forces
    elif kind == "free":
        basis = []
    elif kind == "revolute":
        n1, n2 = _perpendicular_pair(joint.axis)
        basis = forces + [(z, n1), (z, n2)]
        if joint.drive is not None:
            basis.append((z, joint.axis.copy()))
    else:  # prismatic
        n1, n2 = _perpendicular_pair(joint.axis)
        basis = [(n1, z), (n2, z)] + moments
        if joint.drive is not None:
            basis.append((joint.axis.copy(), z))
    return basis


def _lu_solve(A, b):
    """``x`` of ``A x = b`` as numba's compiled ``np.linalg.solve`` gives it, bit for bit:
    LAPACK's ``dgesv`` from scipy (the library numba calls); NaN or Inf in ``A`` or ``b``
    and a singular ``A`` raise ``numpy.linalg.LinAlgError``, as there."""
    if not (np.all(np.isfinite(A)) and np.all(np.isfinite(b))):
        raise np.linalg.LinAlgError("Array must not contain infs or NaNs.")
    if not b.shape[0]:
        return b.copy()
    from scipy.linalg.lapack import dgesv
    _, _, x, info = dgesv(A, b)
    if info > 0:
        raise np.linalg.LinAlgError("Matrix is singular to machine precision.")
    return x


@dataclass(frozen=True)
class Kinematics:
    """Motion of every frame (rows in ``Model.frames`` order).

    World components: ``R`` (``I s = R . B s``), ``r, v, a`` of frame origins, ``w, alpha``
    angular velocity and acceleration, ``r_com, v_com, a_com`` of centres of mass.
    Own-frame components (as the textbook writes them): ``w_body``, ``alpha_body``.
    """
    frames: tuple
    R: np.ndarray
    r: np.ndarray
    v: np.ndarray
    a: np.ndarray
    w: np.ndarray
    alpha: np.ndarray
    r_com: np.ndarray
    v_com: np.ndarray
    a_com: np.ndarray

    @property
    def T(self):
        """The textbook's transformation matrices ``B s = T . I s`` (``R`` transposed)."""
        return np.transpose(self.R, (0, 2, 1))

    @property
    def w_body(self):
        return np.einsum("nji,nj->ni", self.R, self.w)

    @property
    def alpha_body(self):
        return np.einsum("nji,nj->ni", self.R, self.alpha)

    def frame(self, name):
        """Index of a frame by name."""
        return self.frames.index(name)


class Model:
    """A compiled multibody model (frozen).  Build it with ``System.compile()``.

    Not thread-safe: evaluations share one preallocated workspace; every method returns
    fresh arrays.
    """

    def __init__(self, name, bodies, joints, loads, gravity, warnings=(), parameters=None,
                 gravity_symbolic=None, forces=(), effects=None):
        self.name = name
        self.warnings = tuple(warnings)
        self.gravity = np.array(gravity, dtype=float)
        #: the element records in topological order (for the symbolic layer and reports)
        self.elements = (tuple(bodies), tuple(joints), tuple(loads))
        self.parameters = dict(parameters or {})
        self.gravity_symbolic = gravity_symbolic
        self.frames = tuple(b.name for b in bodies)
        self.bodies = tuple(b.name for b in bodies if b.has_inertia)
        self.joints = tuple(j.name for j in joints)
        self._joint = {j.name: j for j in joints}
        self._body = {b.name: b for b in bodies}
        self._frame_index = {nm: i for i, nm in enumerate(self.frames)}
        n = len(bodies)
        self.n_frames = n
        # -- tree arrays
        self._parent = np.array([self._frame_index.get(j.parent, -1) for j in joints], np.int64)
        self._kind = np.array([j.code for j in joints], np.int64)
        self._axis = np.array([j.axis for j in joints], float).reshape(n, 3)
        self._seq = np.array([j.sequence for j in joints], np.int64).reshape(n, 3)
        self._pos = np.array([j.position for j in joints], float).reshape(n, 3)
        self._C = np.array([j.orientation for j in joints], float).reshape(n, 3, 3)
        qoff = np.zeros(n, np.int64)
        uoff = np.zeros(n, np.int64)
        ucol = -np.ones(n, np.int64)
        free_q, free_u, coords, speeds = [], [], [], []
        self._driven = []                 # (joint, qfull index, ufull index, drive)
        self._quaternions = []            # slices of q holding a quaternion
        nqf = nuf = 0
        for i, j in enumerate(joints):
            qoff[i], uoff[i] = nqf, nuf
            if j.drive is not None:
                self._driven.append((j.name, nqf, nuf, j.drive))
            elif j.nu:
                ucol[i] = len(free_u)
                start = len(free_q)
                if j.kind == "spherical":
                    self._quaternions.append(slice(start, start + 4))
                elif j.kind == "free":
                    self._quaternions.append(slice(start + 3, start + 7))
                free_q.extend(range(nqf, nqf + j.nq))
                free_u.extend(range(nuf, nuf + j.nu))
                coords.extend(j.coordinates)
                speeds.extend(j.speeds)
            nqf += j.nq
            nuf += j.nu
        self._qoff, self._uoff, self._ucol = qoff, uoff, ucol
        self._free_q = np.array(free_q, np.int64)
        self._free_u = np.array(free_u, np.int64)
        self.coordinates = tuple(coords)
        self.speeds = tuple(speeds)
        self.nq, self.nu = len(coords), len(speeds)
        self._coordinate_index = {c: k for k, c in enumerate(coords)}
        self._speed_index = {c: k for k, c in enumerate(speeds)}
        self._speed_joint = []            # joint name of each speed
        self._free_joint_slots = []       # (kind code, q start, nq, u start, nu)
        self._euler_middle = []           # (joint, q index of middle angle, proper sequence?)
        qi = ui = 0
        for j in joints:
            if j.drive is None and j.nu:
                self._free_joint_slots.append((j.code, qi, j.nq, ui, j.nu))
                if j.kind == "euler":
                    self._euler_middle.append((j.name, qi + 1, j.sequence[0] == j.sequence[2]))
                self._speed_joint.extend([j.name] * j.nu)
                qi += j.nq
                ui += j.nu
        # columns each frame depends on: its own joint's and its ancestors'
        cols = []
        for i, j in enumerate(joints):
            own = list(range(ucol[i], ucol[i] + j.nu)) if ucol[i] >= 0 else []
            inherited = cols[self._parent[i]] if self._parent[i] >= 0 else []
            cols.append(sorted(inherited + own))
        self._anc_ptr = np.cumsum([0] + [len(c) for c in cols]).astype(np.int64)
        self._anc_idx = np.array([c for cs in cols for c in cs], np.int64)
        # and each frame's own columns only (the articulated-body route reads no others)
        own = [list(range(ucol[i], ucol[i] + j.nu)) if ucol[i] >= 0 else []
               for i, j in enumerate(joints)]
        self._own_ptr = np.cumsum([0] + [len(c) for c in own]).astype(np.int64)
        self._own_idx = np.array([c for cs in own for c in cs], np.int64)
        # -- body arrays
        self._mass = np.array([b.mass for b in bodies], float)
        self._com = np.array([b.com for b in bodies], float).reshape(n, 3)
        self._inertia = np.array([b.inertia for b in bodies], float).reshape(n, 3, 3)
        self._has_inertia = np.array([b.has_inertia for b in bodies], np.bool_)
        # -- reactions
        rj, rf, rm, self._reaction_slices = [], [], [], {}
        for i, j in enumerate(joints):
            basis = reaction_basis(j)
            self._reaction_slices[j.name] = slice(len(rj), len(rj) + len(basis))
            for fo, mo in basis:
                rj.append(i)
                rf.append(fo)
                rm.append(mo)
        self._react_joint = np.array(rj, np.int64)
        self._react_force = np.array(rf, float).reshape(-1, 3)
        self._react_moment = np.array(rm, float).reshape(-1, 3)
        # -- loads
        self.loads = tuple(ld.name for ld in loads)
        nl = len(loads)
        self._load_body = np.array([self._frame_index[ld.body] for ld in loads], np.int64)
        self._load_point = np.array([ld.point for ld in loads], float).reshape(nl, 3)
        self._load_in_body = np.array([ld.in_body for ld in loads], np.bool_)
        self._load_force = np.zeros((nl, 3))
        self._load_moment = np.zeros((nl, 3))
        load_functions = []               # (load name, array, row, callable)
        for k, ld in enumerate(loads):
            for target, val in (("_load_force", ld.force), ("_load_moment", ld.moment)):
                if isinstance(val, tuple):
                    val = self._lambdify_load(ld.name, val)
                if callable(val):
                    load_functions.append((ld.name, target, k, val))
                else:
                    getattr(self, target)[k] = val
        # -- force elements and the effects the scene chose (only what is on is here)
        self._force_elements = tuple(forces)
        self.forces = tuple(el.name for el in forces)
        #: ``{effect: on}`` as the scene chose them (see ``mbdyn.effects``)
        self.effects = dict(effects) if effects is not None else dict.fromkeys(
            ("gravity", "gyroscopic") + self.loads + self.forces, True)
        self.gyroscopic = bool(self.effects.get("gyroscopic", True))
        self._force_int, self._force_data, laws = pack_forces(self, forces)
        self._switches = np.array([1 if self.gyroscopic else 0], np.int64)
        # -- workspace
        self._qfull = np.zeros(nqf)
        self._ufull = np.zeros(nuf)
        self._udfull = np.zeros(nuf)
        for i, j in enumerate(joints):    # identity quaternions where nothing else is set
            if j.kind == "spherical":
                self._qfull[qoff[i]] = 1.0
            elif j.kind == "free":
                self._qfull[qoff[i] + 3] = 1.0
        self._R = np.zeros((n, 3, 3))
        self._r, self._w, self._v = np.zeros((n, 3)), np.zeros((n, 3)), np.zeros((n, 3))
        self._alpha, self._a = np.zeros((n, 3)), np.zeros((n, 3))
        self._JR = np.zeros((n, 3, self.nu))
        self._JT = np.zeros((n, 3, self.nu))
        self._F, self._N = np.zeros((n, 3)), np.zeros((n, 3))
        self._M = np.zeros((self.nu, self.nu))
        self._f = np.zeros(self.nu)
        self._L = np.zeros((self.nu, self.nu))
        self._A = np.zeros((6 * n, 6 * n))
        self._b = np.zeros(6 * n)
        self._ud = np.zeros(self.nu)
        # articulated bodies (kernels.articulated): per frame 6x6 inertias, biases, the
        # joint's U = IA S and Cholesky factor of D, accelerations, joint wrenches
        self._IA, self._U = np.zeros((n, 6, 6)), np.zeros((n, 6, 6))
        self._pA, self._cb, self._acc = np.zeros((n, 6)), np.zeros((n, 6)), np.zeros((n, 6))
        self._Dl, self._W = np.zeros((n, 6, 7)), np.zeros((n, 6))
        self._lam = np.zeros(len(rj))
        #: every temporary of an evaluation (``kernels.evaluate.scratch_size``)
        self._scratch = np.zeros(ke.scratch_size(n, self.nu, nuf))
        self._slots = np.array(self._free_joint_slots, np.int64).reshape(-1, 5)
        self._pack()
        #: (load name, the row of the load array its function fills, the function)
        self._load_functions = [(name, getattr(self, target)[k], fn)
                                for name, target, k, fn in load_functions]
        #: force laws evaluated in Python: (element, its force slot in the packed data, law)
        self._laws = laws
        #: drives, function loads or force laws: values Python writes before each compiled
        #: evaluation
        self._python_inputs = bool(self._driven or self._load_functions or self._laws)
        self._tree = (self._parent, self._kind, self._axis, self._seq, self._pos, self._C,
                      self._qoff, self._uoff, self._ucol, self._anc_ptr, self._anc_idx)
        # no force elements: None instead of the empty table, so that the compiled
        # kernels are specialised without them (kernels/evaluate.kinematics_and_loads)
        self._loads_arrays = (self._load_body, self._load_point, self._load_force,
                              self._load_moment, self._load_in_body,
                              self._force_int if self._force_int.shape[0] else None,
                              self._force_data, self._switches)
        self._kin_out = (self._R, self._r, self._w, self._v, self._alpha, self._a,
                         self._JR, self._JT, self._F, self._N)

    def _pack(self):
        """Move every array the fused kernels use into two flat buffers
        (``kernels.packed``): the attributes become views of them, and a kernel call
        passes three arrays instead of 38."""
        attr = {name: "gravity" if name == "gravity" else "_" + name
                for name in kp.FLOATS + kp.INTS}
        fbuf, ibuf, table, views = kp.pack(
            {k: getattr(self, attr[k]) for k in kp.FLOATS},
            {k: getattr(self, attr[k]) for k in kp.INTS})
        for name, view in views.items():
            setattr(self, attr[name], view)
        self._packed = (fbuf, ibuf, table)

    def _lambdify_load(self, name, exprs):
        """A callable ``(t, q, u) -> 3 values`` from sympy expressions of ``t`` and the
        coordinate and speed names."""
        import sympy
        names = ("t",) + self.coordinates + self.speeds
        used = {s.name for e in exprs for s in e.free_symbols}
        unknown = sorted(used - set(names))
        if unknown:
            raise ModelError(f"load {name!r}: its expression uses {', '.join(unknown)}, which "
                             "are neither t nor coordinates or speeds of the model "
                             f"({', '.join(names[1:])})")
        args = [sympy.Symbol(n) for n in names]
        renamed = [e.subs({s: sympy.Symbol(s.name) for s in e.free_symbols}) for e in exprs]
        fn = sympy.lambdify(args, sympy.Matrix(renamed).T, "numpy")

        def load(t, q, u):
            return np.asarray(fn(t, *q, *u), dtype=float).reshape(3)
        return load

    # ------------------------------------------------------------------ state helpers
    def __repr__(self):
        return (f"<Model {self.name!r}: {self.n_frames} frames, {len(self.joints)} joints, "
                f"nq={self.nq}, nu={self.nu}>")

    def joint(self, name):
        """The joint record (kind, axis, parent, child, coordinates, drive...)."""
        return self._joint[name]

    def body(self, name):
        """The body record (mass, com, inertia about the centre of mass)."""
        return self._body[name]

    def coordinate_index(self, name):
        return self._coordinate_index[name]

    def speed_index(self, name):
        return self._speed_index[name]

    def frame_index(self, name):
        try:
            return self._frame_index[name]
        except KeyError:
            raise ModelError(f"unknown frame {name!r}; the model's frames are "
                             f"{', '.join(self.frames)}") from None

    @property
    def driven_joints(self):
        return tuple(d[0] for d in self._driven)

    def default_coordinates(self):
        """Zero coordinates with identity quaternions."""
        q = np.zeros(self.nq)
        for s in self._quaternions:
            q[s.start] = 1.0
        return q

    def q_vector(self, values=None):
        """Coordinates as an array from an array, or a mapping ``{name: value}`` over the
        defaults (unknown names are refused)."""
        return self._vector(values, self.default_coordinates(), self._coordinate_index,
                            "coordinate")

    def u_vector(self, values=None):
        """Speeds as an array from an array, or a mapping ``{name: value}`` over zeros; as
        in model files, a revolute, prismatic or Euler-angle coordinate's name stands for
        its rate (``{"theta": 1}`` sets ``theta_dot``)."""
        if isinstance(values, dict):
            rates = {}
            for j in self.elements[1]:
                if j.drive is None and j.kind in ("revolute", "prismatic", "euler"):
                    rates.update(zip(j.coordinates, j.speeds))
            mapped = {}
            for k, v in values.items():
                target = k if k in self._speed_index else rates.get(k, k)
                if target in mapped:
                    raise ModelError(f"speed {target!r} is given twice ({k!r} stands for it); "
                                     "keep one of the two")
                mapped[target] = v
            values = mapped
        return self._vector(values, np.zeros(self.nu), self._speed_index, "speed")

    def _vector(self, values, default, index, what):
        try:
            return self._vector_of(values, default, index, what)
        except ModelError:
            raise
        except (TypeError, ValueError):
            raise ModelError(f"the {what}s must be numbers, given as an array or as "
                             f"{{name: value}}; got {values!r}") from None

    def _vector_of(self, values, default, index, what):
        if values is None:
            return default
        if isinstance(values, dict):
            for k, val in values.items():
                if k not in index and k in self._joint and np.ndim(val) == 1:
                    # a joint's name: all its coordinates (or speeds) at once, e.g. a
                    # spherical joint's quaternion from mbdyn.rotations
                    joint = self._joint[k]
                    names = joint.coordinates if what == "coordinate" else joint.speeds
                    if len(val) != len(names) or any(n not in index for n in names):
                        raise ModelError(f"joint {k!r}: give its {len(names)} {what}s "
                                         f"({', '.join(names)}), got {len(val)} values")
                    for n, v in zip(names, val):
                        default[index[n]] = float(v)
                    continue
                if k not in index:
                    raise ModelError(f"unknown {what} {k!r}; the model's {what}s are "
                                     f"{', '.join(index) or '(none)'}")
                default[index[k]] = float(val)
            return default
        arr = np.array(values, dtype=float).reshape(-1)
        if arr.shape != default.shape:
            raise ModelError(f"expected {default.size} {what}s ({', '.join(index)}), "
                             f"got {arr.size} values")
        return arr

    def normalize_quaternions(self, q):
        """Project every joint quaternion in ``q`` back onto the unit sphere (in place);
        returns the largest ``| |quat| - 1 |`` found before projection."""
        drift = 0.0
        for s in self._quaternions:
            n = np.linalg.norm(q[s])
            if not (np.isfinite(n) and n > 0):
                raise NonFiniteError(f"model {self.name!r}: the quaternion "
                                     f"{', '.join(self.coordinates[s])} is {q[s].tolist()}, "
                                     "which has no direction; give a finite, non-zero one")
            drift = max(drift, abs(n - 1.0))
            q[s] /= n
        return drift

    def quaternion_drift(self, q):
        """Largest ``| |quat| - 1 |`` over the joint quaternions in ``q`` (0 if none); ``q``
        one state or an array of states (one per row)."""
        q = np.asarray(q, dtype=float)
        if not self._quaternions or not q.size:
            return 0.0
        return float(max(np.abs(np.linalg.norm(q[..., s], axis=-1) - 1.0).max()
                         for s in self._quaternions))

    # ------------------------------------------------------------------ evaluation core
    def _fill(self, q, u, t):
        """Scatter the free state and the drives into joint-space vectors; evaluate the
        loads that are functions of ``(t, q, u)``."""
        q, u = self._as_arrays(q, u)
        if q.shape != (self.nq,) or u.shape != (self.nu,):
            raise ModelError(f"model {self.name!r} expects q of length {self.nq} and u of "
                             f"length {self.nu}, got {q.shape} and {u.shape}")
        if self._driven:
            self._qfull[self._free_q] = q
            self._ufull[self._free_u] = u
        else:                             # every joint is free: the layouts coincide
            self._qfull[:] = q
            self._ufull[:] = u
        self._udfull[:] = 0.0
        self._fill_inputs(q, u, t)
        return q, u

    def _as_arrays(self, q, u):
        try:
            return np.asarray(q, dtype=float), np.asarray(u, dtype=float)
        except (TypeError, ValueError):
            raise ModelError(f"model {self.name!r}: q and u must be arrays of numbers "
                             f"(q: {self.nq} coordinates, u: {self.nu} speeds)") from None

    def _require_finite(self, q, u, t=0.0):
        """``NonFiniteError`` naming the coordinates and speeds that are NaN or Inf."""
        bad = [n for n, x in zip(self.coordinates + self.speeds,
                                 np.concatenate([np.ravel(q), np.ravel(u)]))
               if not np.isfinite(x)]
        if bad:
            raise NonFiniteError(f"model {self.name!r}, t={t:.6g}: the state holds non-finite "
                                 f"values in {', '.join(bad)}; give finite coordinates and "
                                 "speeds")

    def _state(self, q, u):
        q, u = self._as_arrays(q, u)
        if q.shape != (self.nq,) or u.shape != (self.nu,):
            raise ModelError(f"model {self.name!r} expects q of length {self.nq} and u of "
                             f"length {self.nu}, got {q.shape} and {u.shape}")
        return q, u

    def _fill_inputs(self, q, u, t):
        """The drives' values and the loads given as Python functions, at ``t``."""
        for name, kq, ku, drive in self._driven:
            self._qfull[kq] = drive.position(t)
            self._ufull[ku] = drive.velocity(t)
            self._udfull[ku] = drive.acceleration(t)
        if self._laws:
            self._fill_laws(q, u, t)
        for name, row, fn in self._load_functions:
            try:
                val = np.asarray(fn(t, q, u), dtype=float).reshape(-1)
            except (ModelError, NonFiniteError, SingularMassMatrixError):
                raise
            except Exception as exc:
                raise ModelError(f"load {name!r}: its function raised {type(exc).__name__}: "
                                 f"{exc} (at t={t:.6g})") from exc
            if val.shape != (3,):
                raise ModelError(f"load {name!r}: its function returned {val.size} values at "
                                 f"t={t}; it must return three")
            row[:] = val

    def _fill_laws(self, q, u, t):
        """Each force law's value at the state: ``law(x, x')`` of a spring-damper's
        elongation or a joint's coordinate offset, written where the kernel reads it."""
        self._qfull[self._free_q] = q
        self._ufull[self._free_u] = u
        kinematics_done = False
        fd = self._force_data
        for el, slot, law in self._laws:
            p = el.params
            if el.kind == "joint-spring-damper":
                j = self._joint[p["joint"]]
                i = self._frame_index[j.child]
                x = self._qfull[self._qoff[i]] - p["rest"]
                v = self._ufull[self._uoff[i]]
            else:
                if not kinematics_done:
                    from .kernels.kinematics import forward_kinematics
                    forward_kinematics(*self._tree, self._qfull, self._ufull, self._udfull,
                                       *self._kin_out[:8])
                    kinematics_done = True
                ends = []
                for frame, point in zip(el.frames, (p["point_a"], p["point_b"])):
                    if frame == "ground":
                        ends.append((point, np.zeros(3)))
                    else:
                        i = self._frame_index[frame]
                        lever = self._R[i] @ point
                        ends.append((self._r[i] + lever, self._v[i] + np.cross(self._w[i], lever)))
                d = ends[1][0] - ends[0][0]
                L = float(np.sqrt(d @ d))
                e = d / np.sqrt(L * L + p["min_length"] ** 2)
                x = L - p["free_length"]
                v = float(e @ (ends[1][1] - ends[0][1]))
            try:
                value = float(law(x, v))
            except Exception as exc:
                raise ModelError(f"force {el.name!r}: its law failed at x={x:.6g}, v={v:.6g} "
                                 f"(t={t:.6g}): {type(exc).__name__}: {exc}") from None
            if not np.isfinite(value):
                raise NonFiniteError(f"model {self.name!r}, t={t:.6g}: the law of force "
                                     f"{el.name!r} gave {value} at x={x:.6g}, v={v:.6g}")
            fd[slot] = value

    def _check_finite(self, q, u, t, out, what, names=None):
        if np.all(np.isfinite(out)):
            return
        if not np.all(np.isfinite(q)) or not np.all(np.isfinite(u)):
            bad = [n for n, x in zip(self.coordinates + self.speeds, np.concatenate([q, u]))
                   if not np.isfinite(x)]
            raise NonFiniteError(f"model {self.name!r}, t={t:.6g}: the state holds non-finite "
                                 f"values in {', '.join(bad)}")
        for name, row, _ in self._load_functions:
            if not np.all(np.isfinite(row)):
                raise NonFiniteError(f"model {self.name!r}, t={t:.6g}: load {name!r} returned "
                                     f"non-finite values {row.tolist()}")
        for name, kq, ku, _ in self._driven:
            if not (np.isfinite(self._qfull[kq]) and np.isfinite(self._ufull[ku])
                    and np.isfinite(self._udfull[ku])):
                raise NonFiniteError(f"model {self.name!r}, t={t:.6g}: the drive of joint "
                                     f"{name!r} gave a non-finite value")
        bad = [n for n, x in zip(names or self.speeds, out) if not np.isfinite(x)]
        raise NonFiniteError(f"model {self.name!r}, t={t:.6g}: {what} came out non-finite "
                             f"for {', '.join(bad) or 'some entries'}")

    def _kinematics_kernel(self, q, u, t, ud=None):
        q, u = self._fill(q, u, t)
        if ud is not None:
            self._udfull[self._free_u] = ud
        ke.kinematics_and_loads(*self._tree, self._mass, self._com, self.gravity,
                                self._qfull, self._ufull, self._udfull, *self._loads_arrays,
                                *self._kin_out, self._scratch)
        return q, u

    def _drop_velocity_products(self):
        """With the gyroscopic effect off: bias accelerations without velocity products."""
        if not self.gyroscopic:
            ke.drop_velocity_products(*self._tree, self._qfull, self._ufull, self._udfull,
                                      *self._kin_out[:8], self._scratch)

    def _jourdain_terms(self, q, u, t):
        q, u = self._kinematics_kernel(q, u, t)
        self._drop_velocity_products()
        kd.jourdain_terms(self._mass, self._com, self._inertia, self._has_inertia, self._R,
                          self._r, self._w, self._alpha, self._a, self._JR, self._JT,
                          self._anc_ptr, self._anc_idx, self._parent, self._F, self._N,
                          self._M, self._f, self._scratch)
        return q, u

    # ------------------------------------------------------------------ public numerics
    def kinematics(self, q, u=None, ud=None, t=0.0):
        """Positions, velocities and accelerations of every frame and centre of mass.

        With ``ud=None`` the accelerations are those at zero free speed rates (the
        velocity-product part); pass ``ud`` for the full accelerations.
        """
        u = np.zeros(self.nu) if u is None else u
        self._kinematics_kernel(q, u, t, ud)
        R = self._R.copy()
        c = np.einsum("nij,nj->ni", R, self._com)
        w, al = self._w.copy(), self._alpha.copy()
        return Kinematics(self.frames, R, self._r.copy(), self._v.copy(), self._a.copy(), w, al,
                          self._r + c, self._v + np.cross(w, c),
                          self._a + np.cross(al, c) + np.cross(w, np.cross(w, c)))

    def jacobian_rotation(self, q, frame, t=0.0):
        """``dw/du`` of a frame (3 x nu, world components)."""
        i = self.frame_index(frame)
        self._kinematics_kernel(q, np.zeros(self.nu), t)
        return self._JR[i].copy()

    def jacobian_translation(self, q, frame, point=None, t=0.0):
        """``dv/du`` of a point fixed on a frame (3 x nu, world components).

        ``point`` is in the frame's own components from its origin; default the centre of
        mass of a body (the origin of a massless frame).
        """
        i = self.frame_index(frame)
        self._kinematics_kernel(q, np.zeros(self.nu), t)
        p = self._com[i] if point is None else np.asarray(point, dtype=float)
        out = np.empty((3, self.nu))
        point_jacobian(self._JT[i], self._JR[i], self._R[i] @ p, out)
        return out

    def mass_matrix(self, q, t=0.0):
        """The Jourdain mass matrix ``M(q)`` (nu x nu, symmetric)."""
        return self._mass_matrix(q, t, self._jourdain_packed)

    def _mass_matrix(self, q, t, terms):
        """``mass_matrix`` with the Jourdain terms computed by ``terms``: the packed,
        one-call route (``_jourdain_packed``) or the kernels a run compiles anyway
        (``_jourdain_terms``; for the checks of a run, whose first start must not compile
        the packed entry point).  The same kernels either way: the same numbers."""
        terms(q, np.zeros(self.nu), t)
        # the sum is finite exactly when every entry is (short of overflow, which the
        # exact test below then clears): a third of the cost of isfinite().all()
        if not math.isfinite(self._M.sum()) and not np.all(np.isfinite(self._M)):
            self._require_finite(q, np.zeros(self.nu), t)
            raise NonFiniteError(f"model {self.name!r}, t={t:.6g}: the mass matrix came out "
                                 "non-finite (check masses, inertias and drives)")
        return self._M.copy()

    def forcing(self, q, u, t=0.0):
        """The right-hand side ``f(q, u, t)`` of ``M u' = f``: applied, gyroscopic and
        velocity-product terms projected by the Jacobians."""
        self._jourdain_packed(q, u, t)
        return self._f.copy()

    def _jourdain_packed(self, q, u, t):
        """``M`` and ``f`` into the workspace by one compiled call on the packed buffers
        (``kernels.packed.jourdain_accelerations_packed``, which solves for ``u'`` too: a
        small part of its cost, and no extra compiled entry point)."""
        q, u = self._state(q, u)
        if self._python_inputs:
            self._fill_inputs(q, u, t)
        kp.jourdain_accelerations_packed(*self._packed, q, u)
        return q, u

    def forward_dynamics(self, q, u, t=0.0, method="jourdain"):
        """Speed rates ``u'``: from ``M(q) u' = f(q, u, t)`` (``method="jourdain"``), by the
        articulated-body algorithm (``"articulated"``), or from the Newton-Euler system with
        reactions, eliminated in tree order (``"newton-euler"``) or assembled dense and
        solved by LU (``"newton-euler-dense"``).  All four solve the same equations;
        ``docs/performance.md`` says which is fastest at which size."""
        if method in ("jourdain", "articulated"):
            q, u = self._state(q, u)
            if self._python_inputs:
                self._fill_inputs(q, u, t)
            kernel = (kp.jourdain_accelerations_packed if method == "jourdain"
                      else kp.articulated_accelerations_packed)
            pivot = kernel(*self._packed, q, u)
            if pivot >= 0:
                self._raise_singular(q, t, pivot)
            if pivot == -2:
                self._check_finite(q, u, t, self._ud, "the accelerations")
            return self._ud.copy()
        if method in ("newton-euler", "newton-euler-dense"):
            return self._newton_euler(q, u, t, dense=method == "newton-euler-dense")[:self.nu]
        raise ModelError(f"unknown method {method!r}; use one of {', '.join(METHODS)}")

    def formulation(self, method="auto"):
        """The per-call route ``method`` stands for: ``"auto"`` is ``"jourdain"`` for fewer
        than ``ARTICULATED_FROM`` free speeds, else ``"articulated"`` (measured crossover,
        docs/performance.md); any other name is checked and returned."""
        if method == "auto":
            return "jourdain" if self.nu < ARTICULATED_FROM else "articulated"
        if method not in METHODS:
            raise ModelError(f"unknown method {method!r}; use 'auto' or one of "
                             f"{', '.join(METHODS)}")
        return method

    def lowlevel(self, method="auto"):
        """The low-level entry (``mbdyn.lowlevel.LowLevel``): ``forward_dynamics(q, u)``
        and ``state_derivative(y)`` as single compiled calls on preallocated buffers, for
        loops of your own; ``method``: ``"auto"``, ``"jourdain"`` or ``"articulated"``."""
        from .lowlevel import LowLevel
        return LowLevel(self, self.formulation(method))

    def _check_at_rest(self, q, t=0.0):
        """Raise what ``forward_dynamics(q, 0, t)`` raises -- ``SingularMassMatrixError``
        or ``NonFiniteError`` -- by the same Cholesky solve of ``M u' = f``, called on the
        terms ``mass_matrix`` computes; returns nothing.  Used when a system is compiled:
        this way the check needs no compiled entry point of its own (a first run compiles
        less)."""
        q, u = self._state(q, np.zeros(self.nu))
        self._jourdain_terms(q, u, t)
        pivot = kd.cholesky_solve(self._M, self._f, self._L, self._ud)
        if pivot >= 0:
            self._raise_singular(q, t, pivot)
        self._check_finite(q, u, t, self._ud, "the accelerations")

    def state_derivative(self, t, y, method="jourdain"):
        """``[q', u']`` for the state ``y = [q, u]`` in one compiled call: ``q' = N(q) u``
        (``coordinate_rates``) and ``u'`` as ``forward_dynamics`` gives it (``method``:
        ``"jourdain"`` or ``"articulated"``).  Returns a new array."""
        y = np.asarray(y, dtype=float)
        if y.shape != (self.nq + self.nu,):
            raise ModelError(f"model {self.name!r} expects a state of length "
                             f"{self.nq + self.nu} (q then u), got shape {y.shape}")
        if method == "jourdain":
            kernel = kp.state_derivative_packed
        elif method == "articulated":
            kernel = kp.state_derivative_articulated_packed
        else:
            raise ModelError(f"state_derivative: unknown method {method!r}; use 'jourdain' "
                             "or 'articulated'")
        if self._python_inputs:
            self._fill_inputs(y[:self.nq], y[self.nq:], t)
        ydot = np.empty(self.nq + self.nu)
        status = kernel(*self._packed, y, ydot)
        if status >= 0:
            self._raise_singular(y[:self.nq], t, status)
        if status == -2:
            rates = [c + "'" for c in self.coordinates] + [s + "'" for s in self.speeds]
            self._check_finite(y[:self.nq], y[self.nq:], t, ydot, "the state derivative",
                               rates)
        return ydot

    def _newton_euler(self, q, u, t, dense=False):
        """The Newton-Euler unknowns ``[u', reactions]`` (a new array): eliminated in tree
        order (``kernels.articulated``), or, with ``dense``, the system of
        ``kernels.dynamics.newton_euler_system`` solved by LU (from Python: it needs no
        compiled entry point beyond the kinematics a run has compiled anyway)."""
        q, u = self._state(q, u)
        if not dense:
            if self._python_inputs:
                self._fill_inputs(q, u, t)
            status = kp.newton_euler_tree_packed(*self._packed, q, u)
            if status >= 0:
                self._raise_singular(q, t, status)
            x = np.concatenate([self._ud, self._lam])
            if status == -2:
                self._check_finite(q, u, t, x, "the Newton-Euler solution")
            return x
        try:
            # the steps of newton_euler_solution with kernels a run compiles anyway, and
            # the LU solve from Python: no fused entry point of its own to compile
            self._kinematics_kernel(q, u, t)
            self._drop_velocity_products()
            kd.newton_euler_system(self._mass, self._com, self._inertia, self._parent,
                                   self._R, self._r, self._w, self._alpha, self._a,
                                   self._JR, self._JT, self._anc_ptr, self._anc_idx,
                                   self._F, self._N, self._react_joint,
                                   self._react_force, self._react_moment, self._A, self._b)
            x = _lu_solve(self._A, self._b)
            finite = bool(np.all(np.isfinite(x)))
        except np.linalg.LinAlgError:     # singular, or fed NaN/Inf: tell which
            self._jourdain_terms(q, u, t)
            for out in (self._f, np.diag(self._M)):
                if not np.all(np.isfinite(out)):
                    self._check_finite(q, u, t, out, "the Newton-Euler equations")
            self._raise_singular(q, t, None)
        if not finite:                    # NaN or Inf somewhere: find and report it
            self._check_finite(q, u, t, x, "the Newton-Euler solution")
        return x

    def _raise_singular(self, q, t, pivot):
        self._jourdain_terms(q, np.zeros(self.nu), t)   # M at q (whatever route failed)
        M = self._M
        if not np.all(np.isfinite(M)):   # a NaN pivot: the input, not the inertia
            self._require_finite(q, self._ufull[self._free_u] if self._driven else
                                 self._ufull, t)
            self._check_finite(q, np.zeros(self.nu), t, M.reshape(-1), "the mass matrix",
                               names=[f"M[{i},{j}]" for i in range(self.nu)
                                      for j in range(self.nu)])
        eigval, eigvec = np.linalg.eigh(0.5 * (M + M.T))
        scale = max(abs(eigval).max(), 1e-300)
        null = eigvec[:, eigval <= 1e-12 * scale]
        if null.size:
            weight = np.abs(null).max(axis=1)
            names = [s for s, wgt in zip(self.speeds, weight) if wgt > 0.1]
        else:
            names = [self.speeds[pivot]] if pivot is not None else []
        raise SingularMassMatrixError(
            f"model {self.name!r}, t={t:.6g}: the mass matrix is not positive definite; "
            f"the degrees of freedom {self.describe_speeds(names)} carry no inertia here "
            "(smallest eigenvalue {:.3g}, largest {:.3g}).  Give the bodies they move mass "
            "or inertia, or, for a configuration singularity such as Euler angles at "
            "sin(theta)=0, use a spherical (quaternion) joint.".format(eigval[0], eigval[-1]),
            names)

    def newton_euler(self, q, u, t=0.0, dense=False):
        """Solve the Newton-Euler equations with reaction unknowns, eliminated in tree
        order (O(n)) or, with ``dense=True``, assembled as one 6n system and solved by LU
        (the textbook's literal form).

        Returns ``(ud, reactions)``; ``reactions`` as in ``Model.reactions``.
        """
        x = self._newton_euler(q, u, t, dense=dense)
        return x[:self.nu].copy(), self._reactions_from(x[self.nu:])

    def _reactions_from(self, lam):
        out = {}
        for i, name in enumerate(self.joints):
            s = self._reaction_slices[name]
            R = self._R[i]
            force = R @ (self._react_force[s].T @ lam[s])
            moment = R @ (self._react_moment[s].T @ lam[s])
            out[name] = (force, moment)
        return out

    def reactions(self, q, u, t=0.0, method="auto", frame="world"):
        """Force and moment each joint's parent exerts on its child, reduced to the joint
        origin (the child frame's origin): ``{joint: (F[3], M[3])}``, in world components
        (``frame="world"``) or in the child frame's own components (``frame="child"``, as
        the textbook writes reactions).

        ``method="newton-euler"`` solves the system with reaction unknowns in tree order
        (``"newton-euler-dense"``: the dense 6n system); ``"jourdain"`` and
        ``"articulated"`` compute the accelerations by that route and then the joint
        wrenches by inverse dynamics from the leaves to the root.  ``"auto"``: the dense
        system below ``ARTICULATED_FROM`` speeds (it needs no compiled kernel beyond those
        a run has, so a first run compiles less), tree order from there on.
        """
        if frame not in ("world", "child"):
            raise ModelError(f"unknown frame {frame!r} for reactions; use 'world' or 'child'")
        if method == "auto":
            method = "newton-euler-dense" if self.nu < ARTICULATED_FROM else "newton-euler"
        if method in ("newton-euler", "newton-euler-dense"):
            out = self.newton_euler(q, u, t, dense=method == "newton-euler-dense")[1]
        elif method in ("jourdain", "articulated"):
            ud = self.forward_dynamics(q, u, t, method=method)
            self._kinematics_kernel(q, u, t, ud)
            self._drop_velocity_products()
            w = np.empty((self.n_frames, 6))
            kd.joint_wrenches(self._mass, self._com, self._inertia, self._parent, self._R,
                              self._r, self._w, self._alpha, self._a, self._F, self._N, w)
            out = {name: (w[i, :3].copy(), w[i, 3:].copy()) for i, name in enumerate(self.joints)}
        else:
            raise ModelError(f"unknown method {method!r}; use one of {', '.join(METHODS)}")
        if frame == "child":
            out = {name: (self._R[i].T @ f, self._R[i].T @ m)
                   for i, (name, (f, m)) in enumerate(out.items())}
        return out

    def inverse_dynamics(self, q, u, u_dot, t=0.0, frame="world"):
        """The efforts and reactions that make the motion ``(q, u, u')``: returns
        ``(efforts, reactions)`` -- ``efforts`` ``{speed name: generalized force}`` the
        actuators must add on each free speed, ``Q = M u' - f`` (a torque on a revolute
        joint's speed, a force on a prismatic one), and ``reactions`` ``{joint: (F, M)}``
        as ``Model.reactions`` gives them, the joints transmitting those efforts too."""
        q, u = self._state(q, u)
        ud = np.asarray(u_dot, dtype=float)
        if ud.shape != (self.nu,):
            raise ModelError(f"model {self.name!r}: u_dot needs {self.nu} values, got "
                             f"{ud.size}")
        M = self.mass_matrix(q, t)
        f = self.forcing(q, u, t)
        Q = M @ ud - f
        self._kinematics_kernel(q, u, t, ud)
        self._drop_velocity_products()
        w = np.empty((self.n_frames, 6))
        kd.joint_wrenches(self._mass, self._com, self._inertia, self._parent, self._R,
                          self._r, self._w, self._alpha, self._a, self._F, self._N, w)
        reactions = {name: (w[i, :3].copy(), w[i, 3:].copy())
                     for i, name in enumerate(self.joints)}
        if frame == "child":
            reactions = {name: (self._R[i].T @ fo, self._R[i].T @ mo)
                         for i, (name, (fo, mo)) in enumerate(reactions.items())}
        elif frame != "world":
            raise ModelError(f"unknown frame {frame!r} for reactions; use 'world' or 'child'")
        return dict(zip(self.speeds, Q.tolist())), reactions

    def inverse_dynamics_along(self, t, q, u, u_dot=None, frame="world"):
        """``inverse_dynamics`` along a trajectory: ``t`` (n,), ``q`` (n, nq), ``u``
        (n, nu) and ``u_dot`` (n, nu; default the time derivative of ``u`` by second-order
        finite differences, ``numpy.gradient``).  Returns ``(efforts (n, nu), {joint:
        (n, 6)})`` -- force then moment, as ``reactions``."""
        t = np.asarray(t, dtype=float)
        q = np.asarray(q, dtype=float).reshape(len(t), self.nq)
        u = np.asarray(u, dtype=float).reshape(len(t), self.nu)
        if u_dot is None:
            if len(t) < 3:
                raise ModelError("inverse_dynamics_along: give u_dot, or at least three "
                                 "samples to differentiate u")
            u_dot = np.gradient(u, t, axis=0, edge_order=2)
        u_dot = np.asarray(u_dot, dtype=float).reshape(len(t), self.nu)
        efforts = np.empty((len(t), self.nu))
        reactions = {j: np.empty((len(t), 6)) for j in self.joints}
        for k in range(len(t)):
            e, r = self.inverse_dynamics(q[k], u[k], u_dot[k], t[k], frame)
            efforts[k] = list(e.values())
            for j, (fo, mo) in r.items():
                reactions[j][k, :3], reactions[j][k, 3:] = fo, mo
        return efforts, reactions

    def drive_efforts(self, q, u, t=0.0):
        """Force or torque each driven joint needs to impose its motion: ``{joint: value}``
        (the reaction component along the joint axis, in the axis' sense)."""
        reac = self.reactions(q, u, t)
        out = {}
        for name, *_ in self._driven:
            j = self._joint[name]
            i = self._frame_index[j.child]
            axis_world = self._R[i] @ j.axis
            f, m = reac[name]
            out[name] = float(axis_world @ (m if j.kind == "revolute" else f))
        return out

    def coordinate_rates(self, q, u):
        """Kinematic equations ``q' = N(q) u``; quaternion rates use the normalised
        quaternion, so that ``|q|`` is an invariant of the exact flow."""
        u = np.asarray(u, dtype=float)
        if not self._quaternions:
            return u.copy()
        qd = np.empty(self.nq)
        kj.coordinate_rates(np.asarray(q, dtype=float), u, self._slots, qd)
        return qd

    def energy(self, q, u, t=0.0):
        """Kinetic and gravitational potential energy ``(T, V)``; ``V = -sum m g . r_G``."""
        self._kinematics_kernel(q, u, t)
        T, V = kd.energies(self._mass, self._com, self._inertia, self.gravity, self._R,
                           self._r, self._w, self._v)
        return float(T), float(V)

    def momentum(self, q, u, t=0.0):
        """Linear momentum ``sum m v_G`` and angular momentum about the world origin
        ``sum (r_G x m v_G + I_G w)`` of all bodies, world components: ``(p, L)``."""
        kin = self.kinematics(q, u, t=t)
        p = np.zeros(3)
        L = np.zeros(3)
        for i in range(self.n_frames):
            m = self._mass[i]
            R = kin.R[i]
            IG = R @ self._inertia[i] @ R.T
            p += m * kin.v_com[i]
            L += np.cross(kin.r_com[i], m * kin.v_com[i]) + IG @ kin.w[i]
        return p, L

    def element_energy(self, q, u, t=0.0):
        """Force elements' ``(potential energy, non-conservative power)``: the energy stored
        in springs and contacts, and the power dampers, friction, bushings and bearings
        deliver to the system (negative when they take energy out)."""
        if not self.forces:
            return 0.0, 0.0
        self._kinematics_kernel(q, u, t)
        acc = np.zeros(2)
        kf.force_elements(self._force_int, self._force_data, self._parent, self._axis,
                          self._com, self._qfull, self._ufull, self._R, self._r, self._w,
                          self._v, self._F, self._N, acc, self._scratch)
        return float(acc[0]), float(acc[1])

    def load_power(self, q, u, t=0.0):
        """Power of the loads (``add_load``) on the system: force times the velocity of its
        point plus moment times the body's angular velocity."""
        if not self.loads:
            return 0.0
        self._kinematics_kernel(q, u, t)
        P = 0.0
        for k in range(len(self.loads)):
            i = self._load_body[k]
            f, m = self._load_force[k], self._load_moment[k]
            if self._load_in_body[k]:
                f, m = self._R[i] @ f, self._R[i] @ m
            lever = self._R[i] @ self._load_point[k]
            P += f @ (self._v[i] + np.cross(self._w[i], lever)) + m @ self._w[i]
        return float(P)

    def force_element(self, name):
        """The force-element record (kind, frames, parameters) by name."""
        for el in self._force_elements:
            if el.name == name:
                return el
        raise ModelError(f"unknown force element {name!r}; the model's force elements are "
                         f"{', '.join(self.forces) or '(none)'}")

    def point_positions(self, q, points, t=0.0):
        """World positions of points fixed on frames: ``points`` is a list of
        ``(frame, offset in the frame's components)``; returns an array (len(points), 3)."""
        self._kinematics_kernel(q, np.zeros(self.nu), t)
        out = np.empty((len(points), 3))
        for k, (frame, offset) in enumerate(points):
            i = self.frame_index(frame)
            out[k] = self._r[i] + self._R[i] @ np.asarray(offset, dtype=float)
        return out

    # ------------------------------------------------------------------ compiled loops
    @property
    def has_callable_loads(self):
        """True when some load is a Python function (compiled loops cannot call it)."""
        return bool(self._load_functions or self._laws)

    def drive_values(self, times):
        """``(len(times), n_drives, 3)``: each drive's ``q, q', q''`` at ``times``."""
        out = np.empty((len(times), len(self._driven), 3))
        for d, (_, _, _, drive) in enumerate(self._driven):
            for k, tk in enumerate(times):
                out[k, d] = drive.position(tk), drive.velocity(tk), drive.acceleration(tk)
        return out

    def loop_arguments(self, method="jourdain"):
        """The arrays ``kernels.integrators.fixed_step_loop`` needs after its drive table:
        ``(nq, slots, quats, free_q, free_u, drive_q, drive_u, tree, body, loads, ws)``;
        laid out for ``method`` ``"jourdain"`` or ``"articulated"`` (the compiled loops
        choose their route by the workspace's layout, ``integrators.accelerations``)."""
        slots = self._slots
        quats = np.array([s.start for s in self._quaternions], np.int64)
        drive_q = np.array([d[1] for d in self._driven], np.int64)
        drive_u = np.array([d[2] for d in self._driven], np.int64)
        body = (self._mass, self._com, self._inertia, self._has_inertia, self.gravity)
        ws = (self._qfull, self._ufull, self._udfull, self._R, self._r, self._w, self._v,
              self._alpha, self._a, self._JR, self._JT, self._F, self._N)
        tree = self._tree
        if method == "jourdain":
            ws += (self._M, self._f, self._L, self._scratch)
        elif method == "articulated":
            ws += (self._IA, self._pA, self._cb, self._U, self._Dl, self._acc, self._scratch)
            tree = tree[:9] + (self._own_ptr, self._own_idx)
        else:
            raise ModelError(f"loop_arguments: no compiled loop for method {method!r}")
        return (self.nq, slots, quats, self._free_q, self._free_u, drive_q, drive_u,
                tree, body, self._loads_arrays, ws)

    def describe_speeds(self, speeds):
        """``"theta2 (joint 'theta2')"``: the coordinates and joints behind some speeds
        (for a joint whose speeds are not coordinate rates, the speeds are named too)."""
        parts = []
        for j in dict.fromkeys(self._speed_joint[self._speed_index[s]] for s in speeds):
            joint = self._joint[j]
            mine = [x for x in speeds if self._speed_joint[self._speed_index[x]] == j]
            if joint.kind in ("spherical", "free"):
                parts.append(f"{', '.join(mine)} (joint {j!r})")
            else:
                coords = [joint.coordinates[joint.speeds.index(x)] for x in mine]
                parts.append(f"{', '.join(coords)} (joint {j!r})")
        return "; ".join(parts) or "some coordinates"

    def euler_singularity(self, q):
        """Distance of every Euler-angle joint from its singular configuration:
        ``{joint: |sin(q1)|}`` for proper sequences (``ZXZ``...), ``|cos(q1)|`` for
        Tait-Bryan ones (``XYZ``...).  At 0 the angle rates are undefined."""
        out = {}
        for name, k, proper in self._euler_middle:
            out[name] = abs(np.sin(q[k])) if proper else abs(np.cos(q[k]))
        return out

    def mass_matrix_condition(self, q, t=0.0):
        """2-norm condition number of ``M(q)`` (inf when singular) and the speeds that
        dominate its weakest direction: ``(condition, [speed names])``."""
        if self.nu == 0:
            return 1.0, []
        try:
            M = self._mass_matrix(q, t, self._jourdain_terms)
        except NonFiniteError:
            return float("inf"), []
        ev, vec = np.linalg.eigh(M)
        weak = [s for s, x in zip(self.speeds, np.abs(vec[:, 0])) if x > 0.3]
        cond = float(ev[-1] / ev[0]) if ev[0] > 0 else float("inf")
        return cond, weak
