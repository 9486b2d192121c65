"""Random closed mechanisms: seeded random trees (``random_trees``) closed by random loop
joints of every kind, placed so that the loops close at the tree's random state.  On each:
the constraint Jacobian and ``gamma`` against finite differences of the residuals, the
constrained accelerations against the equations they must satisfy, and Jourdain with
multipliers against Newton-Euler with reaction unknowns (accelerations and the reaction
components the motion determines, to 1e-10) and against the articulated-body route
(accelerations)."""
from __future__ import annotations

import numpy as np
import pytest

import mbdyn as mb
from random_trees import (StateLoad, build_system, quat_to_matrix, random_rotation, random_tree,
                          random_unit)

LOOP_KINDS = ("revolute", "prismatic", "spherical", "fixed", "universal", "cylindrical",
              "distance", "coupling")
SEEDS = range(12)


def _perpendicular(axis, rng):
    v = np.cross(axis, random_unit(rng))
    return v / np.linalg.norm(v)


def random_closed(seed):
    """``(model, q, u, t)``: a random tree closed by 1-3 loop joints, on its manifold (a
    draw whose drives move a loop joint against its constraint is drawn again)."""
    for attempt in range(50):
        try:
            return _random_closed(seed, 10_000 + 100 * seed + attempt)
        except mb.SimulationError:
            continue
    raise RuntimeError(f"no consistent closed mechanism for seed {seed}")


def _random_closed(seed, sub):
    rt = random_tree(seed, int(np.random.default_rng(seed).integers(3, 9)))
    rng = np.random.default_rng(sub)
    system, loads = build_system(rt.spec)
    kin = rt.model.kinematics(rt.q, rt.u, t=rt.t)
    frames = list(rt.model.frames)
    free_1dof = [j.name for j in rt.model.elements[1]
                 if j.kind in ("revolute", "prismatic") and j.drive is None]
    kinds = [LOOP_KINDS[(seed + k) % len(LOOP_KINDS)] for k in range(int(rng.integers(1, 4)))]
    for k, kind in enumerate(kinds):
        name = f"loop{k}"
        if kind == "coupling":
            if len(free_1dof) < 2:
                continue
            a, b = rng.choice(free_1dof, size=2, replace=False)
            ratio = float(rng.uniform(-2, 2))
            qa = rt.q[rt.model.coordinate_index(a)]
            qb = rt.q[rt.model.coordinate_index(b)]
            system.add_joint(name, "coupling", follower=str(a), leader=str(b), ratio=ratio,
                             offset=float(qa - ratio * qb))
            continue
        child = frames[int(rng.integers(len(frames)))]
        parent = rng.choice(["ground"] + [f for f in frames if f != child])
        ip = None if parent == "ground" else frames.index(parent)
        ic = frames.index(child)
        Rp = np.eye(3) if ip is None else kin.R[ip]
        rp = np.zeros(3) if ip is None else kin.r[ip]
        Rc, rc = kin.R[ic], kin.r[ic]
        sp = rng.normal(scale=0.3, size=3)
        Cp = quat_to_matrix(random_rotation(rng))
        P = rp + Rp @ sp
        keys = {"position": sp}
        if kind == "distance":
            sc = rng.normal(scale=0.3, size=3)
            keys.update(child_position=sc, length=float(np.linalg.norm(rc + Rc @ sc - P)))
        else:
            keys.update(orientation=Cp, child_position=Rc.T @ (P - rc),
                        child_orientation=Rc.T @ Rp @ Cp)
        if kind in ("revolute", "prismatic", "cylindrical", "universal"):
            keys["axis"] = random_unit(rng)
        if kind == "universal":
            keys["axis2"] = _perpendicular(keys["axis"], rng)
        system.add_joint(name, kind, str(parent), child, **keys)
    model = system.compile()
    for _, fv, mv in loads:
        for fn in (fv, mv):
            if isinstance(fn, StateLoad):
                fn.bind(model)
    q, u = model.project(rt.q, rt.u, rt.t)
    np.testing.assert_allclose(q, rt.q, atol=1e-9)      # the loops close at the tree's q
    return model, q, u, rt.t


@pytest.mark.parametrize("seed", SEEDS)
def test_random_closed_mechanism(seed):
    m, q, u, t = random_closed(seed)
    rng = np.random.default_rng(seed)
    G = m.constraint_jacobian(q, t)
    phi, psi = m.constraint_residuals(q, u, t)
    assert np.abs(phi).max() < 1e-10 and np.abs(psi).max() < 1e-10 * (1 + np.abs(u).max())
    # G: the residuals' change along q' = N(q) u at fixed time
    h = 1e-6
    qd = m.coordinate_rates(q, u)
    fd = (m.constraint_residuals(q + h * qd, None, t)[0]
          - m.constraint_residuals(q - h * qd, None, t)[0]) / (2 * h)
    drives = m.constraint_residuals(q, np.zeros(m.nu), t)[1]
    np.testing.assert_allclose(fd, G @ u, atol=1e-6 * (1 + np.abs(u).max()))
    np.testing.assert_allclose(psi - drives, G @ u, atol=1e-12 * (1 + np.abs(u).max()))
    # gamma: d psi/dt along (q', u' = ud, t) equals G ud - gamma
    ud_any = rng.normal(size=m.nu)
    m.constraint_residuals(q, u, t)
    gamma = m._con[5].copy()
    fd = (m.constraint_residuals(q + h * qd, u + h * ud_any, t + h)[1]
          - m.constraint_residuals(q - h * qd, u - h * ud_any, t - h)[1]) / (2 * h)
    np.testing.assert_allclose(fd, G @ ud_any - gamma, atol=1e-5 * (1 + np.abs(u).max()) ** 2)
    # the constrained accelerations satisfy both equations
    ud, lam = m.multipliers(q, u, t)
    M, f = m.mass_matrix(q, t), m.forcing(q, u, t)
    scale = 1 + np.abs(f).max() + np.abs(M @ ud).max()
    np.testing.assert_allclose(M @ ud - f, G.T @ lam, atol=1e-9 * scale)
    m.constraint_residuals(q, u, t)
    np.testing.assert_allclose(G @ ud, m._con[5], atol=1e-9 * (1 + np.abs(ud).max()))
    # Newton-Euler with reaction unknowns: the same accelerations, the same determinate
    # reaction components
    ne = m.forward_dynamics(q, u, t, method="newton-euler")
    assert np.abs(ud - ne).max() <= 1e-10 * (1 + np.abs(ud).max())
    # the articulated-body route (kernels.loop_articulated): no mass matrix at all
    art = m.forward_dynamics(q, u, t, method="articulated")
    assert np.abs(ud - art).max() <= 1e-10 * (1 + np.abs(ud).max())
    r1 = m.reactions(q, u, t)
    r2 = m.reactions(q, u, t, method="newton-euler")
    unique = m.reaction_uniqueness(q, t)
    for joint in m.reaction_joints:
        a, b = np.concatenate(r1[joint]), np.concatenate(r2[joint])
        d = np.abs(a - b)[unique[joint]]
        assert d.size == 0 or d.max() <= 1e-10 * (1 + np.abs(a).max()), joint


@pytest.mark.parametrize("path, case", [("models/four_bar.toml", "free"),
                                        ("models/andrews_squeezer.toml", None),
                                        ("models/bricard.toml", None), (None, 0), (None, 5)])
def test_rows_left_out_are_zero_at_every_state(path, case):
    """The primitives the per-call entries leave out (``con_int[:, 5] == 0``,
    ``constraint_packing.moves``) have rows of ``G`` and ``gamma`` that are exactly zero
    at random states (off the mechanism too, every coordinate moved), and the planar
    mechanisms do have such rows (Andrews' squeezer: 6 of its 9 primitives)."""
    if path is None:
        model = random_closed(case)[0]
    else:
        model = mb.load_model(path, case).model
    con_int = model._con[0]
    rows = np.repeat(np.arange(con_int.shape[0]), [3 if k == 0 else 1 for k in con_int[:, 0]])
    out = np.flatnonzero(con_int[rows, 5] == 0)
    if path and "bricard" not in path:
        assert out.size >= 2
    rng = np.random.default_rng(5)
    for _ in range(5):
        q, u = rng.normal(size=model.nq), rng.normal(size=model.nu)
        if hasattr(model, "_quaternions"):
            for s in model._quaternions:
                q[s] /= np.linalg.norm(q[s])
        G = model.constraint_jacobian(q)
        model.constraint_residuals(q, u)
        assert (G[out] == 0).all() and (model._con[5][out] == 0).all()
