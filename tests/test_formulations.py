"""The two formulations against each other and against independent routes.

On 50 seeded random trees (``random_trees.py``: every joint kind, drives, massless frames,
full inertia tensors, gravity and loads):

* Jourdain ``M u' = f`` and the Newton-Euler system with reaction unknowns give the same
  accelerations (1e-10 relative);
* ``M`` is symmetric positive definite and is the Hessian of the kinetic energy computed
  here from the frame velocities (``T = 1/2 u^T M u`` and its polarisation);
* ``M u'`` equals Lagrange's equations evaluated by finite differences of energies computed
  here (local rotation-vector coordinates for the quaternion joints);
* reactions by Newton-Euler equal the inverse-dynamics route and the momentum balance of
  every subtree computed here; they respect what each joint kind cannot transmit;
* drive efforts equal the generalized force the freed joint needs, and the power balance
  ``dE/dt = P(loads) + sum(effort * q'_drive)`` holds.
"""
import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import mbdyn as mb
from random_trees import (KINDS, cached_tree, energy_of, mass_properties, quat_exp, quat_mul,
                          random_tree, right_jacobian)

SEEDS = range(50)
TINY = 1e-300


def rel(a, b):
    a, b = np.asarray(a, float), np.asarray(b, float)
    return np.linalg.norm(a - b) / max(np.linalg.norm(a), np.linalg.norm(b), TINY)


def tree(seed):
    return cached_tree(seed)


# ----------------------------------------------------------------------------- the sample
def test_random_trees_mix_every_kind_drives_massless_frames_and_loads():
    trees = [tree(s) for s in SEEDS]
    kinds = set().union(*(t.kinds for t in trees))
    assert kinds == set(KINDS)
    sizes = [t.model.n_frames for t in trees]
    assert min(sizes) == 1 and max(sizes) == 12
    assert sum(len(t.kinds) == len(KINDS) for t in trees) >= 15, "few trees mix all kinds"
    assert sum(bool(t.driven) for t in trees) >= 15
    assert sum(any(t.model.body(f).mass == 0 for f in t.model.frames) for t in trees) >= 10
    assert sum(any(callable(fv) or callable(mv) for _, fv, mv in t.loads) for t in trees) >= 15
    seqs = {j["sequence"] for t in trees for j in t.spec.joints if j["kind"] == "euler"}
    assert len(seqs) >= 8
    assert sum(t.model.nu > 0 for t in trees) >= 45


def test_random_trees_are_deterministic_and_states_valid():
    a, b = random_tree(3), random_tree(3)
    assert np.array_equal(a.q, b.q) and np.array_equal(a.u, b.u) and a.t == b.t
    for seed in SEEDS:
        t = tree(seed)
        for sl in t.model._quaternions:
            assert abs(np.linalg.norm(t.q[sl]) - 1) < 1e-14
        for j in t.spec.joints:
            if j["kind"] == "euler":
                mid = t.q[t.model.coordinate_index(j["name"] + "_2")]
                proper = j["sequence"][0] == j["sequence"][2]
                assert (abs(np.sin(mid)) if proper else abs(np.cos(mid))) > 0.3


# ----------------------------------------------------------------------------- formulations
@pytest.mark.parametrize("seed", SEEDS)
def test_jourdain_and_newton_euler_agree(seed):
    t = tree(seed)
    m = t.model
    a = m.forward_dynamics(t.q, t.u, t.t, method="jourdain")
    b = m.forward_dynamics(t.q, t.u, t.t, method="newton-euler")
    assert rel(a, b) < 1e-10, f"seed {seed}: formulations differ by {rel(a, b):.2e}"
    ud, _ = m.newton_euler(t.q, t.u, t.t)
    assert rel(ud, b) < 1e-14
    # M u' = f, and M symmetric positive definite
    M = m.mass_matrix(t.q, t.t)
    f = m.forcing(t.q, t.u, t.t)
    assert rel(M @ a, f) < 1e-10
    assert a.shape == b.shape == f.shape == (m.nu,) and M.shape == (m.nu, m.nu)
    if m.nu:
        assert np.abs(M - M.T).max() <= 1e-14 * np.abs(M).max()
        assert np.linalg.eigvalsh(M)[0] > 0


@pytest.mark.parametrize("seed", SEEDS)
def test_state_derivative_is_coordinate_rates_and_accelerations(seed):
    """The fused compiled call against its two parts -- after another evaluation has left
    different values in the shared workspace (the kinematics with nonzero speed rates)."""
    t = tree(seed)
    m = t.model
    y = np.concatenate([t.q, t.u])
    rng = np.random.default_rng(seed)
    m.kinematics(t.q, -t.u, rng.uniform(-5, 5, m.nu), t.t + 0.3)
    ydot = m.state_derivative(t.t, y)
    rates = m.coordinate_rates(t.q, t.u)
    m.kinematics(t.q, -t.u, rng.uniform(-5, 5, m.nu), t.t + 0.3)
    ud = m.forward_dynamics(t.q, t.u, t.t)
    b = m.forward_dynamics(t.q, t.u, t.t, method="newton-euler")
    assert ydot.shape == (m.nq + m.nu,)
    assert np.array_equal(ydot[:m.nq], rates)
    assert np.array_equal(ydot[m.nq:], ud)
    assert m.nu == 0 or rel(ud, b) < 1e-10
    assert m.state_derivative(t.t, y) is not ydot             # a new array every call


def test_state_derivative_refuses_a_wrong_state_and_names_a_non_finite_one():
    t = tree(SEEDS[0])
    m = t.model
    with pytest.raises(mb.ModelError, match=r"state of length \d+ \(q then u\)"):
        m.state_derivative(0.0, np.zeros(m.nq + m.nu + 1))
    y = np.concatenate([t.q, t.u])
    y[m.nq] = np.nan
    with pytest.raises(mb.NonFiniteError, match=m.speeds[0]):
        m.state_derivative(t.t, y)


@settings(max_examples=12, deadline=None, derandomize=True,
          suppress_health_check=[HealthCheck.too_slow])
@given(seed=st.integers(1000, 10**6))
def test_jourdain_and_newton_euler_agree_on_more_trees(seed):
    t = random_tree(seed)
    m = t.model
    a = m.forward_dynamics(t.q, t.u, t.t, method="jourdain")
    b = m.forward_dynamics(t.q, t.u, t.t, method="newton-euler")
    assert m.nu == 0 or rel(a, b) < 1e-10, f"seed {seed}: formulations differ by {rel(a, b):.2e}"


@pytest.mark.parametrize("seed", SEEDS)
def test_mass_matrix_is_the_hessian_of_the_kinetic_energy(seed):
    """On the drive-freed tree, T(u) computed here from the frame velocities is
    1/2 u^T M u, for the state's u and for random pairs (polarisation)."""
    t = tree(seed).freed()
    m = t.model
    if m.nu == 0:
        return
    M = m.mass_matrix(t.q, t.t)
    T, V = energy_of(m, t.q, t.u, t.t)
    assert abs(T - 0.5 * t.u @ M @ t.u) <= 1e-12 * max(T, 1e-300)
    Te, Ve = m.energy(t.q, t.u, t.t)
    assert abs(Te - T) <= 1e-12 * T and abs(Ve - V) <= 1e-12 * (abs(V) + T)
    rng = np.random.default_rng(seed)
    scale = np.abs(M).max()
    for _ in range(4):
        x, y = rng.normal(size=(2, m.nu))
        E = [energy_of(m, t.q, v, t.t)[0] for v in (x + y, x, y)]
        assert abs((E[0] - E[1] - E[2]) - x @ M @ y) <= 1e-11 * scale * (x @ x + y @ y)


# ----------------------------------------------------------------------------- Lagrange
class LocalCoordinates:
    """Local coordinates theta around ``q0`` with ``theta = 0`` at ``q0``: angles and
    displacements shift; quaternions become ``q0 (x) exp(theta/2)``, whose angular velocity
    in the child frame is ``J_r(theta) theta'``.  At theta = 0, theta' = u and
    theta'' = u'."""

    def __init__(self, model, q0):
        self.model, self.q0 = model, q0
        self.blocks = []
        for name in model.joints:
            j = model.joint(name)
            if j.drive is not None or j.kind == "fixed":
                continue
            qi = [model.coordinate_index(c) for c in j.coordinates]
            ui = [model.speed_index(s) for s in j.speeds]
            self.blocks.append((j.kind, qi, ui))

    def state(self, theta, thetad):
        q, u = self.q0.copy(), np.array(thetad, float)
        for kind, qi, ui in self.blocks:
            if kind in ("revolute", "prismatic", "euler"):
                q[qi] += theta[ui]
            else:
                rot_q, rot_u = (qi, ui) if kind == "spherical" else (qi[3:], ui[3:])
                if kind == "free":
                    q[qi[:3]] += theta[ui[:3]]
                q[rot_q] = quat_mul(self.q0[rot_q], quat_exp(theta[rot_u]))
                u[rot_u] = right_jacobian(theta[rot_u]) @ thetad[rot_u]
        return q, u


def lagrange_rhs(tr, h=1e-4):
    """``M theta''`` from Lagrange's equations by finite differences of energies computed
    here: ``Q - dV/dtheta + dT/dtheta - dp/dt`` with ``p = dT/dtheta'`` (exact by central
    differences of step 1: T is quadratic in theta') and ``dp/dt`` its change along
    ``(theta, t) -> (theta + h theta', t + h)`` at fixed theta'."""
    m, t = tr.model, tr.t
    loc = LocalCoordinates(m, tr.q)
    n = m.nu
    zero = np.zeros(n)
    E = np.eye(n)

    def energies(theta, thetad, time):
        return energy_of(m, *loc.state(theta, thetad), time)

    def momentum(theta, thetad, time):
        return np.array([0.5 * (energies(theta, thetad + E[k], time)[0]
                                - energies(theta, thetad - E[k], time)[0]) for k in range(n)])

    u = tr.u
    dT = np.empty(n)
    dV = np.empty(n)
    for k in range(n):
        Tp, Vp = energies(h * E[k], u, t)
        Tm, Vm = energies(-h * E[k], u, t)
        dT[k] = (Tp - Tm) / (2 * h)
        dV[k] = (Vp - Vm) / (2 * h)
    dp = (momentum(h * u, u, t + h) - momentum(-h * u, u, t - h)) / (2 * h)
    # generalized forces of the loads by virtual power: Q_k = P(e_k) - P(0)
    kin = m.kinematics(tr.q, tr.u, t=t)
    k0 = m.kinematics(tr.q, zero, t=t)
    P0 = tr.load_power(kin, t, tr.q, tr.u, k0)
    Q = np.array([tr.load_power(kin, t, tr.q, tr.u, m.kinematics(tr.q, E[k], t=t)) - P0
                  for k in range(n)])
    terms = (Q, dV, dT, dp)
    return Q - dV + dT - dp, max(np.abs(x).max() for x in terms)


@pytest.mark.parametrize("seed", SEEDS)
def test_jourdain_equals_lagrange_by_finite_differences(seed):
    tr = tree(seed)
    m = tr.model
    if m.nu == 0:
        return
    rhs, scale = lagrange_rhs(tr)
    M = m.mass_matrix(tr.q, tr.t)
    ud = m.forward_dynamics(tr.q, tr.u, tr.t)
    err = np.abs(M @ ud - rhs).max() / scale
    assert err < 1e-6, f"seed {seed}: M u' differs from Lagrange's equations by {err:.2e}"


# ----------------------------------------------------------------------------- reactions
def subtree(model, joint):
    """Frame indices of the joint's child and its descendants."""
    child = model.joint(joint).child
    out = {model.frame_index(child)}
    for name in model.joints:                         # topological order: parents first
        j = model.joint(name)
        if j.parent in {model.frames[i] for i in out}:
            out.add(model.frame_index(j.child))
    return sorted(out)


def momentum_balance_reactions(tr, ud):
    """Reaction of every joint from the momentum balance of the subtree it carries,
    computed here from the kinematics (with the accelerations ``ud``) and the loads."""
    m, q, u, t = tr.model, tr.q, tr.u, tr.t
    kin = m.kinematics(q, u, ud, t=t)
    F, N = tr.external_wrenches(kin, t, q, u)
    mass, com, inertia = mass_properties(m)
    c = np.einsum("nij,nj->ni", kin.R, com)
    rG = kin.r + c
    aG = kin.a + np.cross(kin.alpha, c) + np.cross(kin.w, np.cross(kin.w, c))
    Iw = np.einsum("nij,njk,nlk->nil", kin.R, inertia, kin.R)
    Iw_w = np.einsum("nij,nj->ni", Iw, kin.w)
    dH = np.einsum("nij,nj->ni", Iw, kin.alpha) + np.cross(kin.w, Iw_w)
    need = mass[:, None] * aG - F                  # force the body needs beyond its loads
    out = {}
    for name in m.joints:
        idx = subtree(m, name)
        origin = kin.r[m.frame_index(m.joint(name).child)]
        f = need[idx].sum(axis=0)
        mo = (dH[idx] - N[idx] + np.cross(rG[idx] - origin, need[idx])).sum(axis=0)
        out[name] = (f, mo)
    return out


@pytest.mark.parametrize("seed", SEEDS)
def test_reactions_by_both_routes_and_momentum_balance(seed):
    tr = tree(seed)
    m = tr.model
    ne = m.reactions(tr.q, tr.u, tr.t, method="newton-euler")
    jo = m.reactions(tr.q, tr.u, tr.t, method="jourdain")
    ud = m.forward_dynamics(tr.q, tr.u, tr.t)
    mb_ = momentum_balance_reactions(tr, ud)
    assert set(ne) == set(jo) == set(m.joints)
    scale = 1.0 + max(max(np.abs(f).max(), np.abs(mo).max()) for f, mo in mb_.values())
    kin = m.kinematics(tr.q, tr.u, t=tr.t)
    for name in m.joints:
        for k, what in enumerate(("force", "moment")):
            d1 = np.abs(ne[name][k] - jo[name][k]).max() / scale
            d2 = np.abs(ne[name][k] - mb_[name][k]).max() / scale
            assert d1 < 1e-9, f"seed {seed}, joint {name}: {what} NE vs inverse dynamics {d1:.2e}"
            assert d2 < 1e-9, f"seed {seed}, joint {name}: {what} NE vs momentum balance {d2:.2e}"
        # what the joint cannot transmit (checked on the inverse-dynamics route, which does
        # not build these constraints in)
        j = m.joint(name)
        f, mo = jo[name]
        axis = kin.R[m.frame_index(j.child)] @ j.axis
        if j.kind == "free":
            assert np.abs(np.concatenate([f, mo])).max() < 1e-9 * scale
        elif j.kind in ("spherical", "euler"):
            assert np.abs(mo).max() < 1e-9 * scale
        elif j.kind == "revolute" and j.drive is None:
            assert abs(mo @ axis) < 1e-9 * scale
        elif j.kind == "prismatic" and j.drive is None:
            assert abs(f @ axis) < 1e-9 * scale


@pytest.mark.parametrize("seed", [s for s in SEEDS if cached_tree(s).driven])
def test_drive_efforts_are_the_generalized_forces_of_the_freed_joints(seed):
    """With the drive replaced by a free joint, ``M u' - f`` of the freed model at the
    driven accelerations is the generalized force the drive must supply."""
    tr = tree(seed)
    m = tr.model
    efforts = m.drive_efforts(tr.q, tr.u, tr.t)
    assert set(efforts) == set(tr.driven)
    fr = tr.freed()
    mf = fr.model
    ud = m.forward_dynamics(tr.q, tr.u, tr.t)
    udf = np.zeros(mf.nu)
    for k, s in enumerate(m.speeds):
        udf[mf.speed_index(s)] = ud[k]
    drives = tr.drive_state()
    for name, (_, _, qdd) in drives.items():
        udf[mf.speed_index(name + "_dot")] = qdd
    tau = mf.mass_matrix(fr.q, fr.t) @ udf - mf.forcing(fr.q, fr.u, fr.t)
    scale = 1.0 + np.abs(tau).max()
    for name in tr.driven:
        expected = tau[mf.speed_index(name + "_dot")]
        assert abs(efforts[name] - expected) < 1e-9 * scale, (name, efforts[name], expected)
    # every other generalized force of the freed model vanishes
    others = [mf.speed_index(s) for s in m.speeds]
    assert np.abs(tau[others]).max(initial=0) < 1e-9 * scale
    # the drive's own speeds follow the sympy expression
    kin = m.kinematics(tr.q, tr.u, t=tr.t)
    kinf = mf.kinematics(fr.q, fr.u, t=fr.t)
    assert np.abs(kin.v - kinf.v).max() < 1e-12 * (1 + np.abs(kin.v).max())


@pytest.mark.parametrize("seed", SEEDS)
def test_power_balance(seed):
    """dE/dt along the motion (central differences of the energy computed here) equals
    the power of the loads plus the drives' power ``effort * q'_drive``."""
    tr = tree(seed)
    m, q, u, t = tr.model, tr.q, tr.u, tr.t
    if m.nu == 0 and not tr.driven:
        return
    qd = m.coordinate_rates(q, u)
    ud = m.forward_dynamics(q, u, t)
    h = 1e-5
    Ep = sum(energy_of(m, q + h * qd, u + h * ud, t + h))
    Em = sum(energy_of(m, q - h * qd, u - h * ud, t - h))
    dE = (Ep - Em) / (2 * h)
    kin = m.kinematics(q, u, t=t)
    P = tr.load_power(kin, t, q, u)
    efforts = m.drive_efforts(q, u, t)
    Pd = sum(efforts[n] * v for n, (_, v, _) in tr.drive_state().items())
    T, V = energy_of(m, q, u, t)
    scale = 1.0 + abs(P) + abs(Pd) + abs(T) + abs(V)
    assert abs(dE - P - Pd) < 1e-7 * scale, (dE, P, Pd)


@pytest.mark.parametrize("seed", range(100, 110))
def test_conservative_tree_has_no_power(seed):
    tr = cached_tree(seed, drives=False, loads=False)
    m, q, u, t = tr.model, tr.q, tr.u, tr.t
    qd = m.coordinate_rates(q, u)
    ud = m.forward_dynamics(q, u, t, method="newton-euler")
    h = 1e-5
    dE = (sum(energy_of(m, q + h * qd, u + h * ud, t)) -
          sum(energy_of(m, q - h * qd, u - h * ud, t))) / (2 * h)
    T, V = energy_of(m, q, u, t)
    assert abs(dE) < 1e-7 * (1 + abs(T) + abs(V))


# ----------------------------------------------------------------------------- massless loads
def _moving_massless_load(tr):
    """Does some load act on a massless frame that moves with a degree of freedom?"""
    m = tr.model
    return any(m.body(ld["body"]).mass == 0 and np.abs(
        m.jacobian_translation(tr.q, ld["body"], ld["point"], tr.t)).max(initial=0) > 0
        for ld, _, _ in tr.loads)


MASSLESS_LOAD_SEEDS = [s for s in range(200, 260) if _moving_massless_load(
    cached_tree(s, n_frames=8, loads_on_massless=True))][:6]


@pytest.mark.parametrize("seed", MASSLESS_LOAD_SEEDS)
def test_loads_on_massless_frames_count_in_both_formulations(seed):
    """A load on a massless frame (e.g. a force on an intermediate joint frame) is part of
    the motion: both formulations must see it."""
    tr = cached_tree(seed, n_frames=8, loads_on_massless=True)
    m = tr.model
    a = m.forward_dynamics(tr.q, tr.u, tr.t, method="jourdain")
    b = m.forward_dynamics(tr.q, tr.u, tr.t, method="newton-euler")
    rhs, scale = lagrange_rhs(tr)
    M = m.mass_matrix(tr.q, tr.t)
    on_massless = [ld["name"] for ld, _, _ in tr.loads if m.body(ld["body"]).mass == 0]
    assert on_massless, "the generator put no load on a massless frame"
    assert np.abs(M @ b - rhs).max() / scale < 1e-6, "Newton-Euler differs from Lagrange"
    assert rel(a, b) < 1e-10, (
        f"Jourdain ignores the loads {on_massless} on massless frames (differs from "
        f"Newton-Euler and Lagrange by {rel(a, b):.2e}); kernels.dynamics.jourdain skips "
        "frames without inertia")


def test_load_on_massless_frame_minimal():
    """Minimal reproducer: a force on a massless intermediate frame ``f``, applied at the
    origin of joint ``j2`` -- a point fixed in both ``f`` and ``b``.  Applying the same
    force to ``b`` at that point must give the same motion."""
    def pendulum(load_on):
        s = mb.System("massless load")
        s.add_frame("f")
        s.add_joint("j1", "revolute", "ground", "f", axis="x")
        s.add_body("b", mass=1.0, com=(0, 0, -1), inertia=(0.1, 0.2, 0.3))
        s.add_joint("j2", "revolute", "f", "b", axis="y", position=(0, 0, -0.5))
        if load_on == "f":
            s.add_load("push", "f", force=(0, 5, 0), point=(0, 0, -0.5))
        elif load_on == "b":
            s.add_load("push", "b", force=(0, 5, 0), point=(0, 0, 0))
        return s.compile()

    q, u = np.array([0.3, 0.2]), np.array([0.1, -0.4])
    ref = pendulum("b").forward_dynamics(q, u)
    assert rel(pendulum(None).forward_dynamics(q, u), ref) > 0.1     # the push matters
    m = pendulum("f")
    assert rel(m.forward_dynamics(q, u, method="newton-euler"), ref) < 1e-12
    assert rel(m.forward_dynamics(q, u, method="jourdain"), ref) < 1e-12, (
        "Jourdain ignores a load on a massless frame: kernels.dynamics.jourdain skips "
        "frames without inertia (`if not has_inertia[i]: continue`), dropping their loads")
