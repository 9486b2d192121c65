"""Seeded random trees of frames, bodies and joints for the engine's property tests.

``random_tree(seed)`` builds a tree of 1..12 frames that mixes every joint kind
(revolute and prismatic about random axes, euler with random valid sequences, spherical,
fixed, free), random joint placements (positions and orientations, given in every form the
API accepts), driven joints (sympy expressions of ``mb.t``), massless frames (always with a
massive descendant, so that every degree of freedom still carries inertia), bodies with
random full SPD inertia tensors about offset centres of mass, a random gravity vector and a
few loads (constant, world or body components, and callables of ``(t, q, u)``).  It returns a
``RandomTree``: the compiled model, a random state ``q`` (unit quaternions, Euler angles
away from their singular middle angle), ``u``, ``t``, and what the tests need to compute
expectations independently of the engine: the load functions bound to the model, the mass
properties, and ``freed()`` -- the same tree with every drive replaced by a free joint of
the same kind.

Nothing here calls the engine's dynamics; only ``System`` building, ``compile`` and
``Model.kinematics`` (for velocities and positions, which the kinematic tests check by
finite differences) are used by the helpers below.
"""
from __future__ import annotations

import functools
from dataclasses import dataclass, field

import numpy as np
import sympy

import mbdyn as mb

KINDS = ("revolute", "prismatic", "euler", "spherical", "fixed", "free")
#: every valid Euler sequence: 6 proper (first == last) and 6 Tait-Bryan
SEQUENCES = tuple(a + b + c for a in "XYZ" for b in "XYZ" for c in "XYZ" if a != b and b != c)
#: keep the middle Euler angle this far (rad) from its singular value
EULER_MARGIN = 0.35


# ----------------------------------------------------------------------------- math helpers
def cross(a, b):
    """Row-wise cross product of (n, 3) arrays (np.cross is slow on small arrays)."""
    out = np.empty(np.broadcast_shapes(a.shape, b.shape))
    out[..., 0] = a[..., 1] * b[..., 2] - a[..., 2] * b[..., 1]
    out[..., 1] = a[..., 2] * b[..., 0] - a[..., 0] * b[..., 2]
    out[..., 2] = a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]
    return out


def skew(v):
    return np.array([[0.0, -v[2], v[1]], [v[2], 0.0, -v[0]], [-v[1], v[0], 0.0]])


def quat_to_matrix(q):
    """Rotation matrix of a unit quaternion (w, x, y, z) (active; maps rotated to fixed)."""
    w, x, y, z = np.asarray(q, float) / np.linalg.norm(q)
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
                     [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
                     [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]])


def matrix_to_quat(R):
    """Unit quaternion (w, x, y, z) of a rotation matrix (Shepperd's method)."""
    tr = np.trace(R)
    cands = np.array([tr, R[0, 0], R[1, 1], R[2, 2]])
    k = int(np.argmax(cands))
    if k == 0:
        w = 0.5 * np.sqrt(1 + tr)
        q = np.array([w, (R[2, 1] - R[1, 2]) / (4 * w), (R[0, 2] - R[2, 0]) / (4 * w),
                      (R[1, 0] - R[0, 1]) / (4 * w)])
    else:
        i = k - 1
        j, m = (i + 1) % 3, (i + 2) % 3
        s = 0.5 * np.sqrt(1 + R[i, i] - R[j, j] - R[m, m])
        v = np.zeros(3)
        v[i] = s
        v[j] = (R[j, i] + R[i, j]) / (4 * s)
        v[m] = (R[m, i] + R[i, m]) / (4 * s)
        w = (R[m, j] - R[j, m]) / (4 * s)
        q = np.array([w, *v])
    return q / np.linalg.norm(q)


def quat_mul(a, b):
    """Hamilton product a (x) b of quaternions (w, x, y, z)."""
    w1, x1, y1, z1 = a
    w2, x2, y2, z2 = b
    return np.array([w1 * w2 - x1 * x2 - y1 * y2 - z1 * z2,
                     w1 * x2 + x1 * w2 + y1 * z2 - z1 * y2,
                     w1 * y2 - x1 * z2 + y1 * w2 + z1 * x2,
                     w1 * z2 + x1 * y2 - y1 * x2 + z1 * w2])


def quat_exp(theta):
    """Quaternion of the rotation vector ``theta`` (angle |theta| about theta/|theta|)."""
    phi = np.linalg.norm(theta)
    if phi < 1e-12:
        return np.array([1.0, 0.5 * theta[0], 0.5 * theta[1], 0.5 * theta[2]]) / \
            np.sqrt(1 + 0.25 * phi * phi)
    return np.concatenate([[np.cos(phi / 2)], np.sin(phi / 2) * np.asarray(theta) / phi])


def right_jacobian(theta):
    """``J_r(theta)``: body angular velocity of ``R0 Exp(theta)`` is ``J_r theta'``."""
    phi = np.linalg.norm(theta)
    K = skew(theta)
    if phi < 1e-6:
        return np.eye(3) - 0.5 * K + K @ K / 6.0
    return (np.eye(3) - (1 - np.cos(phi)) / phi**2 * K + (phi - np.sin(phi)) / phi**3 * K @ K)


def axis_rotation(k, angle):
    """Rotation by ``angle`` about coordinate axis k (active): the textbook's T_k(angle)^T."""
    c, s = np.cos(angle), np.sin(angle)
    i, j = (k + 1) % 3, (k + 2) % 3
    R = np.eye(3)
    R[i, i] = R[j, j] = c
    R[i, j] = -s
    R[j, i] = s
    return R


def random_rotation(rng):
    q = rng.normal(size=4)
    return q / np.linalg.norm(q)


def random_unit(rng):
    v = rng.normal(size=3)
    return v / np.linalg.norm(v)


def random_inertia(rng, mass):
    """A full SPD inertia tensor about the centre of mass of a solid ellipsoid of ``mass``
    (so it satisfies the triangle inequality) in randomly rotated axes."""
    a, b, c = rng.uniform(0.15, 0.6, 3)
    principal = mass / 5.0 * np.array([b * b + c * c, a * a + c * c, a * a + b * b])
    Q = quat_to_matrix(random_rotation(rng))
    I = Q @ np.diag(principal) @ Q.T
    return 0.5 * (I + I.T)


# ----------------------------------------------------------------------------- the spec
@dataclass
class Spec:
    """A plain description of a random tree, from which ``System``s are built."""
    seed: int
    gravity: np.ndarray
    frames: list = field(default_factory=list)      # dicts: name, mass, com, inertia
    joints: list = field(default_factory=list)      # dicts: add_joint kwargs + 'name','kind'
    loads: list = field(default_factory=list)       # dicts: name, body, frame, point, force, moment


class StateLoad:
    """``value(t, q, u) = a0 + a1 sin(w t) + cq * q[qname] + cu * u[uname]`` (three numbers).

    The indices of ``qname``/``uname`` are looked up in the model the load is bound to, so
    that one description serves a model and its drive-freed twin."""

    def __init__(self, a0, a1, w, qname, cq, uname, cu):
        self.a0, self.a1, self.w = np.asarray(a0), np.asarray(a1), float(w)
        self.qname, self.cq = qname, np.asarray(cq)
        self.uname, self.cu = uname, np.asarray(cu)
        self.qi = self.ui = None

    def bound(self):
        return StateLoad(self.a0, self.a1, self.w, self.qname, self.cq, self.uname, self.cu)

    def bind(self, model):
        self.qi = None if self.qname is None else model.coordinate_index(self.qname)
        self.ui = None if self.uname is None else model.speed_index(self.uname)

    def __call__(self, t, q, u):
        val = self.a0 + self.a1 * np.sin(self.w * t)
        if self.qi is not None:
            val = val + self.cq * q[self.qi]
        if self.ui is not None:
            val = val + self.cu * u[self.ui]
        return val


def _free_names(joint):
    """Coordinate / speed names the joint will get (defaults of the engine's API)."""
    name, kind = joint["name"], joint["kind"]
    if joint.get("drive") is not None or kind == "fixed":
        return (), ()
    if kind in ("revolute", "prismatic"):
        return (name,), (name + "_dot",)
    if kind == "euler":
        qn = tuple(f"{name}_{k}" for k in (1, 2, 3))
        return qn, tuple(c + "_dot" for c in qn)
    if kind == "spherical":
        return (), tuple(f"{name}_{k}" for k in ("wx", "wy", "wz"))
    qn = tuple(f"{name}_{k}" for k in "xyz")     # free: position coordinates only
    return qn, tuple(f"{name}_{k}" for k in ("vx", "vy", "vz", "wx", "wy", "wz"))


def random_spec(seed, n_frames=None, *, kinds=KINDS, drives=True, loads=True, massless=True,
                gravity=True, loads_on_massless=False):
    rng = np.random.default_rng(seed)
    n = int(rng.integers(1, 13)) if n_frames is None else int(n_frames)
    g = random_unit(rng) * rng.uniform(5.0, 12.0) if gravity else np.zeros(3)
    spec = Spec(seed, g)
    parents = ["ground"]
    # joint kinds: every kind at least once when there is room, the rest random
    pool = list(kinds)
    rng.shuffle(pool)
    kind_list = (pool + list(rng.choice(kinds, size=max(0, n - len(pool)))))[:n]
    rng.shuffle(kind_list)
    parent_of = []
    for k in range(n):
        # mostly chains, sometimes branches
        if k == 0 or rng.random() < 0.35:
            parent_of.append(int(rng.integers(0, k + 1)))     # 0 = ground, m = frame m-1
        else:
            parent_of.append(k)                               # the previous frame
    has_child = [False] * n
    for k, p in enumerate(parent_of):
        if p > 0:
            has_child[p - 1] = True
    for k in range(n):
        kind = str(kind_list[k])
        # massless frames: inner frames, or leaves hung by a fixed joint (markers)
        is_massless = massless and ((has_child[k] and rng.random() < 0.35)
                                    or (not has_child[k] and kind == "fixed"
                                        and rng.random() < 0.3))
        name = f"f{k}" if is_massless else f"b{k}"
        if is_massless:
            spec.frames.append(dict(name=name, mass=0.0, com=None, inertia=None))
        else:
            mass = rng.uniform(0.5, 2.0)
            inertia = random_inertia(rng, mass)
            form = rng.integers(0, 2)
            spec.frames.append(dict(name=name, mass=mass, com=rng.uniform(-0.4, 0.4, 3),
                                    inertia=inertia if form == 0 else inertia.tolist()))
        parent = parents[parent_of[k]]
        parents.append(name)
        joint = dict(name=f"j{k}", kind=kind, parent=parent, child=name,
                     position=tuple(rng.uniform(-0.5, 0.5, 3)))
        # orientation in every accepted form
        form = rng.integers(0, 4)
        if form == 1:
            joint["orientation"] = tuple(random_rotation(rng))
        elif form == 2:
            joint["orientation"] = quat_to_matrix(random_rotation(rng))
        elif form == 3:
            joint["orientation"] = (tuple(random_unit(rng)), float(rng.uniform(-np.pi, np.pi)))
        if kind in ("revolute", "prismatic"):
            joint["axis"] = (str(rng.choice(["x", "y", "z", "-y"])) if rng.random() < 0.25
                             else tuple(random_unit(rng) * rng.uniform(0.5, 2.0)))
            if drives and rng.random() < 0.35:
                a, w, b, c = rng.uniform(-1, 1), rng.uniform(0.5, 3), rng.uniform(-1, 1), \
                    rng.uniform(-0.5, 0.5)
                joint["drive"] = float(a) * sympy.sin(float(w) * mb.t) + float(b) * mb.t + float(c)
        if kind == "euler":
            joint["sequence"] = str(rng.choice(SEQUENCES))
        spec.joints.append(joint)
    if loads:
        bodies = [f["name"] for f in spec.frames if f["mass"] > 0]
        if loads_on_massless:           # put the loads on massless frames where there are any
            bodies = [f["name"] for f in spec.frames if f["mass"] == 0] or bodies
        free_q = [c for j in spec.joints for c in _free_names(j)[0]]
        free_u = [c for j in spec.joints for c in _free_names(j)[1]]
        for m in range(int(rng.integers(1, 4))):
            body = str(rng.choice(bodies))
            frame = str(rng.choice(["world", "body"]))
            point = tuple(rng.uniform(-0.5, 0.5, 3))
            kind = m % 3
            if kind == 0:                       # constant force (and moment)
                force = tuple(rng.normal(size=3) * 3)
                moment = tuple(rng.normal(size=3)) if rng.random() < 0.5 else None
            elif kind == 1:                     # constant moment
                force, moment = None, tuple(rng.normal(size=3))
            else:                               # callables of (t, q, u)
                def state_load():
                    return StateLoad(rng.normal(size=3), rng.normal(size=3), rng.uniform(0.5, 3),
                                     str(rng.choice(free_q)) if free_q else None,
                                     rng.normal(size=3),
                                     str(rng.choice(free_u)) if free_u else None,
                                     rng.normal(size=3) * 0.5)
                force = state_load()
                moment = state_load() if rng.random() < 0.5 else None
            spec.loads.append(dict(name=f"load{m}", body=body, frame=frame, point=point,
                                   force=force, moment=moment))
    return spec


def build_system(spec, free_drives=False):
    """A ``System`` from the spec; ``free_drives`` leaves the driven joints free.  Returns
    the system and the bound load callables ``[(load dict, force fn, moment fn)]``."""
    s = mb.System(f"random tree {spec.seed}", gravity=tuple(spec.gravity))
    frames = {f["name"]: f for f in spec.frames}
    for j in spec.joints:
        f = frames[j["child"]]
        if f["mass"] > 0:
            s.add_body(f["name"], mass=f["mass"], com=f["com"], inertia=f["inertia"])
        else:
            s.add_frame(f["name"])
        kw = {k: v for k, v in j.items() if k not in ("name", "kind", "parent", "child")}
        if free_drives:
            kw.pop("drive", None)
        s.add_joint(j["name"], j["kind"], j["parent"], j["child"], **kw)
    bound = []
    for ld in spec.loads:
        fns = []
        for val in (ld["force"], ld["moment"]):
            if isinstance(val, StateLoad):
                fns.append(val.bound())
            elif val is None:
                fns.append(None)
            else:
                fns.append(np.asarray(val, float))
        s.add_load(ld["name"], ld["body"], force=fns[0], moment=fns[1], point=ld["point"],
                   frame=ld["frame"])
        bound.append((ld, fns[0], fns[1]))
    return s, bound


# ----------------------------------------------------------------------------- the tree
@dataclass
class RandomTree:
    spec: Spec
    model: object
    loads: list          # [(load dict, force, moment)], force/moment: array, callable or None
    q: np.ndarray
    u: np.ndarray
    t: float

    @property
    def kinds(self):
        return {j["kind"] for j in self.spec.joints}

    @property
    def driven(self):
        return [j["name"] for j in self.spec.joints if j.get("drive") is not None]

    def load_value(self, val, t, q, u):
        if val is None:
            return np.zeros(3)
        if callable(val):
            return np.asarray(val(t, q, u), float)
        return np.asarray(val, float)

    def external_wrenches(self, kin, t, q, u):
        """Gravity and loads on every frame, reduced to its centre of mass (world
        components): arrays ``F (n, 3)``, ``N (n, 3)`` -- computed here, not by the engine."""
        model = self.model
        n = model.n_frames
        F = np.zeros((n, 3))
        N = np.zeros((n, 3))
        for i, name in enumerate(model.frames):
            F[i] = model.body(name).mass * model.gravity
        for ld, fv, mv in self.loads:
            i = model.frame_index(ld["body"])
            R = kin.R[i]
            f = self.load_value(fv, t, q, u)
            m = self.load_value(mv, t, q, u)
            if ld["frame"] == "body":
                f, m = R @ f, R @ m
            com = model.body(ld["body"]).com
            lever = R @ (np.asarray(ld["point"]) - com)
            F[i] += f
            N[i] += m + np.cross(lever, f)
        return F, N

    def load_power(self, kin, t, q, u, kin_velocity=None):
        """Power of the (non-gravity) loads evaluated at the state ``(t, q, u)`` on the
        velocity field of ``kin_velocity`` (default ``kin``)."""
        kv = kin if kin_velocity is None else kin_velocity
        model = self.model
        P = 0.0
        for ld, fv, mv in self.loads:
            i = model.frame_index(ld["body"])
            R = kin.R[i]
            f = self.load_value(fv, t, q, u)
            m = self.load_value(mv, t, q, u)
            if ld["frame"] == "body":
                f, m = R @ f, R @ m
            vp = kv.v[i] + np.cross(kv.w[i], R @ np.asarray(ld["point"]))
            P += f @ vp + m @ kv.w[i]
        return P

    def energy(self, q, u, t):
        """(T, V) computed here from the kinematics and the mass properties."""
        return energy_of(self.model, q, u, t)

    def freed(self):
        """The same tree with every driven joint free, and the matching state (the freed
        coordinates and speeds take the drive's values at ``t``)."""
        s, loads = build_system(self.spec, free_drives=True)
        model = s.compile(check_inertia=False)
        for _, fv, mv in loads:
            for fn in (fv, mv):
                if isinstance(fn, StateLoad):
                    fn.bind(model)
        q = model.default_coordinates()
        u = np.zeros(model.nu)
        for k, name in enumerate(self.model.coordinates):
            q[model.coordinate_index(name)] = self.q[k]
        for k, name in enumerate(self.model.speeds):
            u[model.speed_index(name)] = self.u[k]
        for name in self.driven:
            d = self.model.joint(name).drive
            q[model.coordinate_index(name)] = d.position(self.t)
            u[model.speed_index(name + "_dot")] = d.velocity(self.t)
        return RandomTree(self.spec, model, loads, q, u, self.t)

    def drive_state(self):
        """``{joint: (q, q', q'')}`` of the driven joints at ``t``, from the sympy
        expressions of the spec (not the engine's lambdified copies)."""
        out = {}
        for j in self.spec.joints:
            e = j.get("drive")
            if e is not None:
                out[j["name"]] = tuple(float(x.subs(mb.t, self.t))
                                       for x in (e, e.diff(mb.t), e.diff(mb.t, 2)))
        return out


_MASS_PROPERTIES = {}


def mass_properties(model):
    """``(mass (n,), com (n, 3), inertia about the centre of mass (n, 3, 3))`` from the
    body records, in ``model.frames`` order."""
    key = id(model)
    if key not in _MASS_PROPERTIES or _MASS_PROPERTIES[key][0] is not model:
        bodies = [model.body(nm) for nm in model.frames]
        _MASS_PROPERTIES[key] = (model, np.array([b.mass for b in bodies]),
                                 np.array([b.com for b in bodies]).reshape(-1, 3),
                                 np.array([b.inertia for b in bodies]).reshape(-1, 3, 3))
    return _MASS_PROPERTIES[key][1:]


def energy_of(model, q, u, t):
    """Kinetic and potential energy from ``Model.kinematics`` (frame origins, rotation,
    angular velocity) and the body records -- not from ``Model.energy``."""
    kin = model.kinematics(q, u, t=t)
    m, com, inertia = mass_properties(model)
    c = np.einsum("nij,nj->ni", kin.R, com)
    vG = kin.v + cross(kin.w, c)
    wb = np.einsum("nji,nj->ni", kin.R, kin.w)                 # w in body components
    T = 0.5 * np.einsum("n,ni,ni->", m, vG, vG) + 0.5 * np.einsum("ni,nij,nj->", wb, inertia, wb)
    V = -np.einsum("n,i,ni->", m, model.gravity, kin.r + c)
    return float(T), float(V)


def random_state(model, spec, rng):
    """Random ``q`` (unit quaternions, Euler middle angles away from singularity), ``u``
    and ``t``."""
    q = np.zeros(model.nq)
    for j in spec.joints:
        if j.get("drive") is not None or j["kind"] == "fixed":
            continue
        name, kind = j["name"], j["kind"]
        jt = model.joint(name)
        idx = [model.coordinate_index(c) for c in jt.coordinates]
        if kind == "revolute":
            q[idx] = rng.uniform(-np.pi, np.pi)
        elif kind == "prismatic":
            q[idx] = rng.uniform(-0.5, 0.5)
        elif kind == "euler":
            seq = j["sequence"]
            a, c = rng.uniform(-np.pi, np.pi, 2)
            if seq[0] == seq[2]:        # proper Euler: singular at sin(b) = 0
                b = rng.uniform(EULER_MARGIN, np.pi - EULER_MARGIN) * rng.choice([-1, 1])
            else:                       # Tait-Bryan: singular at cos(b) = 0
                b = rng.uniform(-np.pi / 2 + EULER_MARGIN, np.pi / 2 - EULER_MARGIN)
            q[idx] = (a, b, c)
        elif kind == "spherical":
            q[idx] = random_rotation(rng)
        elif kind == "free":
            q[idx[:3]] = rng.uniform(-0.5, 0.5, 3)
            q[idx[3:]] = random_rotation(rng)
    u = rng.normal(size=model.nu)
    t = float(rng.uniform(0.0, 2.0))
    return q, u, t


def random_tree(seed, n_frames=None, *, max_condition=1e7, **options):
    """A ``RandomTree`` for ``seed`` (deterministic).  Trees whose compile refuses a
    degree of freedom without inertia, or whose mass matrix at the random state is worse
    conditioned than ``max_condition``, are regenerated with the next sub-seed."""
    for attempt in range(200):
        sub = seed * 1000 + attempt
        spec = random_spec(sub, n_frames, **options)
        s, loads = build_system(spec)
        try:
            model = s.compile()
        except mb.ModelError:           # the only whole-tree check that can fail here:
            continue                    # a degree of freedom without inertia
        for _, fv, mv in loads:
            for fn in (fv, mv):
                if isinstance(fn, StateLoad):
                    fn.bind(model)
        rng = np.random.default_rng(sub + 7)
        q, u, t = random_state(model, spec, rng)
        if model.nu and np.linalg.cond(model.mass_matrix(q, t)) > max_condition:
            continue
        return RandomTree(spec, model, loads, q, u, t)
    raise RuntimeError(f"no acceptable random tree for seed {seed}")


@functools.lru_cache(maxsize=None)
def cached_tree(seed, n_frames=None, **options):
    """``random_tree`` memoised, so that the test modules share the compiled models.
    Callers must not modify the returned arrays."""
    return random_tree(seed, n_frames, **options)
