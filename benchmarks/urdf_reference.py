#!/usr/bin/env python
"""Reference dynamics of the URDF robots in ``tests/data/`` computed by Pinocchio, written
to ``tests/data/urdf_reference.json`` (committed), which ``tests/test_urdf_pinocchio.py``
compares mbdyn against.  Pinocchio is never a dependency of mbdyn nor imported by the
tests: run this script in an environment of its own, and only when a robot or the states
change:

    python -m venv /tmp/pinvenv && /tmp/pinvenv/bin/pip install pin
    /tmp/pinvenv/bin/python benchmarks/urdf_reference.py

Pinocchio reads each URDF with its own parser (``buildModelFromUrdf``), fixed base, and
``arm6`` also with a free-flyer root.  At seeded random states it gives the mass matrix
(``crba``), the bias forces (``nonLinearEffects``: ``M ddq + nle = tau``), forward
dynamics (``aba``), inverse dynamics (``rnea``), every link's placement and its frame
Jacobian (``LOCAL_WORLD_ALIGNED``, at the link frame's origin).

Everything is written in mbdyn's coordinates, named as mbdyn names them (a joint's
coordinate after the joint, its speed ``NAME_dot``; the free base ``root_x .. root_qz``,
``root_vx .. root_wz``): a continuous joint's ``(cos q, sin q)`` becomes its angle ``q``;
the free flyer's ``(x, y, z, qx, qy, qz, qw)`` becomes ``(x, y, z, qw, qx, qy, qz)`` and
its speeds ``(v, w)`` in body axes become the velocity in world axes ``R v`` and ``w``.
With ``T = blkdiag(R, 1)`` on the base's speeds, ``u = T v``, ``u' = T (dv/dt) +
(R (w x v), 0)``, generalised forces ``T tau``, ``M_mbdyn = T M T^T`` and Jacobians
``J T^T``.
"""
from __future__ import annotations

import json
import os
import sys

import numpy as np

try:
    import pinocchio as pin
except ImportError:  # pragma: no cover - the generator's own environment
    sys.exit("this generator needs Pinocchio: pip install pin (in an environment of its own)")

HERE = os.path.dirname(os.path.abspath(__file__))
DATA = os.path.join(HERE, "..", "tests", "data")
ROBOTS = [("planar_arm", False), ("arm6", False), ("mixed", False), ("arm6", True)]
STATES = 3
SEED = 2025


def names_of(model, floating):
    """mbdyn's coordinate and speed names, in Pinocchio's joint order."""
    coords, speeds = [], []
    for jid in range(1, model.njoints):
        name = model.names[jid]
        if floating and jid == 1:
            coords += [f"root_{k}" for k in ("x", "y", "z", "qw", "qx", "qy", "qz")]
            speeds += [f"root_{k}" for k in ("vx", "vy", "vz", "wx", "wy", "wz")]
        else:
            coords.append(name)
            speeds.append(f"{name}_dot")
    return coords, speeds


def random_state(model, rng, floating):
    """``(q, v)`` in Pinocchio's form: angles within the limits (or +-pi), a unit
    quaternion for the free flyer, speeds of order one."""
    q = np.zeros(model.nq)
    for jid in range(1, model.njoints):
        j = model.joints[jid]
        if floating and jid == 1:
            q[j.idx_q:j.idx_q + 3] = rng.uniform(-0.5, 0.5, 3)
            quat = rng.normal(size=4)
            q[j.idx_q + 3:j.idx_q + 7] = quat / np.linalg.norm(quat)
        elif j.nq == 2:                        # continuous: (cos, sin)
            a = rng.uniform(-np.pi, np.pi)
            q[j.idx_q:j.idx_q + 2] = (np.cos(a), np.sin(a))
        else:
            lo = max(model.lowerPositionLimit[j.idx_q], -np.pi)
            hi = min(model.upperPositionLimit[j.idx_q], np.pi)
            q[j.idx_q] = rng.uniform(lo, hi)
    return q, rng.normal(size=model.nv)


def to_mbdyn(model, q, floating):
    """mbdyn's ``q`` (in Pinocchio's joint order) and ``T`` (``u = T v``)."""
    out, T = [], np.eye(model.nv)
    for jid in range(1, model.njoints):
        j = model.joints[jid]
        if floating and jid == 1:
            x, y, z, qx, qy, qz, qw = q[j.idx_q:j.idx_q + 7]
            out += [x, y, z, qw, qx, qy, qz]
            R = pin.Quaternion(qw, qx, qy, qz).toRotationMatrix()
            T[0:3, 0:3] = R
        elif j.nq == 2:
            out.append(float(np.arctan2(q[j.idx_q + 1], q[j.idx_q])))
        else:
            out.append(float(q[j.idx_q]))
    return np.array(out), T


def one_state(model, data, q, v, tau, a, floating):
    """The reference quantities at one state, in mbdyn's coordinates."""
    qm, T = to_mbdyn(model, q, floating)
    u = T @ v
    M = pin.crba(model, data, q)
    M = np.triu(M) + np.triu(M, 1).T
    nle = pin.nonLinearEffects(model, data, q, v).copy()
    ddq = pin.aba(model, data, q, v, tau).copy()
    c = np.zeros(model.nv)                     # u' = T ddq + c (the base's w x v term)
    if floating:
        c[0:3] = T[0:3, 0:3] @ np.cross(v[3:6], v[0:3])
    rnea = pin.rnea(model, data, q, v, a).copy()
    pin.computeJointJacobians(model, data, q)
    pin.framesForwardKinematics(model, data, q)
    frames = {}
    for f in model.frames:
        if f.type != pin.FrameType.BODY:
            continue
        fid = model.getFrameId(f.name)
        J = pin.getFrameJacobian(model, data, fid, pin.LOCAL_WORLD_ALIGNED)
        place = data.oMf[fid]
        frames[f.name] = {"R": place.rotation.tolist(), "p": place.translation.tolist(),
                          "J": (J @ T.T).tolist()}
    return {"q": qm.tolist(), "u": u.tolist(), "tau": (T @ tau).tolist(),
            "M": (T @ M @ T.T).tolist(), "nle": (T @ (nle - M @ T.T @ c)).tolist(),
            "ud": (T @ ddq + c).tolist(), "a": (T @ a + c).tolist(),
            "rnea": (T @ rnea).tolist(), "frames": frames}


def main():
    rng = np.random.default_rng(SEED)
    out = {"generator": "benchmarks/urdf_reference.py", "pinocchio": pin.__version__,
           "gravity": [0.0, 0.0, -9.81], "robots": []}
    for name, floating in ROBOTS:
        path = os.path.join(DATA, f"{name}.urdf")
        model = (pin.buildModelFromUrdf(path, pin.JointModelFreeFlyer()) if floating
                 else pin.buildModelFromUrdf(path))
        model.gravity.linear = np.array(out["gravity"])
        data = model.createData()
        coords, speeds = names_of(model, floating)
        states = []
        for _ in range(STATES):
            q, v = random_state(model, rng, floating)
            tau = rng.normal(size=model.nv)
            a = rng.normal(size=model.nv)
            states.append(one_state(model, data, q, v, tau, a, floating))
        out["robots"].append({"file": f"{name}.urdf", "floating": floating,
                              "coordinates": coords, "speeds": speeds, "states": states})
        print(f"{name}{' (floating)' if floating else ''}: nq {model.nq}, nv {model.nv}, "
              f"{len(states)} states")
    target = os.path.join(DATA, "urdf_reference.json")
    with open(target, "w") as fh:
        json.dump(out, fh, separators=(",", ":"))
        fh.write("\n")
    print(f"wrote {os.path.relpath(target)}")


if __name__ == "__main__":
    main()
