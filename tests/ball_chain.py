"""A chain of links on spherical (ball) joints, and its Jourdain terms computed
independently of the engine in extended precision (``numpy.longdouble``).

The reference takes the same inputs (masses, lengths, quaternions, speeds) and evaluates
``M = sum JT^T m JT + JR^T I JR`` and ``f`` from the Jacobians of each centre of mass and
each body's rotation, written out for this chain only, then solves ``M u' = f`` by
Cholesky in the same precision.  With an ill-conditioned chain (cond(M) about 1e8) it tells
how many digits each of the engine's routes keeps.
"""
from __future__ import annotations

import numpy as np

import mbdyn as mb

LD = np.longdouble


def ball_chain(n, *, length=0.1, mass=1.0, radius=0.002, seed=0, gravity=9.81):
    """``(model, q, u, spec)``: ``n`` uniform cylinders of ``length`` and ``radius``
    hanging from spherical joints at their tops (the first at the world origin), gravity
    along -z, a random state (rotations up to about 0.5 rad per joint)."""
    s = mb.System("ball chain", gravity=(0, 0, -gravity))
    inertia = mb.inertia.cylinder(mass, radius, length, axis="z")
    parent = "ground"
    for i in range(n):
        s.add_body(f"link{i}", mass=mass, com=(0, 0, -length / 2), inertia=inertia)
        s.add_joint(f"ball{i}", "spherical", parent, f"link{i}",
                    position=(0, 0, -length) if i else (0, 0, 0))
        parent = f"link{i}"
    model = s.compile()
    rng = np.random.default_rng(seed)
    q = np.empty(4 * n)
    for k in range(n):
        v = rng.normal(size=3) * 0.3
        a = np.linalg.norm(v)
        q[4 * k:4 * k + 4] = [np.cos(a / 2), *(np.sin(a / 2) * v / a)]
    u = rng.normal(size=3 * n)
    spec = {"n": n, "length": length, "mass": mass, "inertia": np.asarray(inertia),
            "gravity": gravity}
    return model, q, u, spec


def _quat_matrix(q):
    w, x, y, z = q / np.sqrt(q @ q)
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
                     [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
                     [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]])


def _skew(v):
    return np.array([[0, -v[2], v[1]], [v[2], 0, -v[0]], [-v[1], v[0], 0]], dtype=v.dtype)


def reference_terms(spec, q, u):
    """``M`` and ``f`` of the chain in ``longdouble`` (world components)."""
    n, L, m = spec["n"], LD(spec["length"]), LD(spec["mass"])
    Ib = spec["inertia"].astype(LD)
    g = np.array([0, 0, -spec["gravity"]], dtype=LD)
    q, u = np.asarray(q, LD), np.asarray(u, LD)
    R = np.eye(3, dtype=LD)
    o = np.zeros(3, LD)                   # joint (frame) origin
    w = np.zeros(3, LD)
    a_o = np.zeros(3, LD)                 # bias accelerations (u' = 0) of the origin
    alpha = np.zeros(3, LD)
    joint_R, joint_o = [], []
    M = np.zeros((3 * n, 3 * n), LD)
    f = np.zeros(3 * n, LD)
    down = np.array([0, 0, -1], LD) * L
    for k in range(n):
        if k:                             # origin moves with the parent's rotation
            d = R @ down
            a_o = a_o + np.cross(alpha, d) + np.cross(w, np.cross(w, d))
            o = o + d
        R = R @ _quat_matrix(q[4 * k:4 * k + 4])
        w_rel = R @ u[3 * k:3 * k + 3]
        alpha = alpha + np.cross(w, w_rel)        # d/dt (R u_k) at u' = 0
        w = w + w_rel
        joint_R.append(R)
        joint_o.append(o)
        c = R @ (down / 2)                        # centre of mass from the origin
        G = o + c
        aG = a_o + np.cross(alpha, c) + np.cross(w, np.cross(w, c))
        Iw = R @ Ib @ R.T
        JR = np.zeros((3, 3 * n), LD)
        JT = np.zeros((3, 3 * n), LD)
        for j in range(k + 1):                    # joint j turns body k about o_j
            JR[:, 3 * j:3 * j + 3] = joint_R[j]
            JT[:, 3 * j:3 * j + 3] = -_skew(G - joint_o[j]) @ joint_R[j]
        M += m * JT.T @ JT + JR.T @ Iw @ JR
        f += JT.T @ (m * g - m * aG) + JR.T @ (-Iw @ alpha - np.cross(w, Iw @ w))
    return M, f


def reference_accelerations(spec, q, u):
    """``u'`` from the reference ``M`` and ``f``, by Cholesky in ``longdouble``."""
    M, f = reference_terms(spec, q, u)
    nu = M.shape[0]
    Lc = np.zeros_like(M)
    for j in range(nu):
        Lc[j, j] = np.sqrt(M[j, j] - Lc[j, :j] @ Lc[j, :j])
        Lc[j + 1:, j] = (M[j + 1:, j] - Lc[j + 1:, :j] @ Lc[j, :j]) / Lc[j, j]
    y = np.zeros(nu, LD)
    for i in range(nu):
        y[i] = (f[i] - Lc[i, :i] @ y[:i]) / Lc[i, i]
    x = np.zeros(nu, LD)
    for i in range(nu - 1, -1, -1):
        x[i] = (y[i] - Lc[i + 1:, i] @ x[i + 1:]) / Lc[i, i]
    return x, M
