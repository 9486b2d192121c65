"""The routes the compiled loops reach by address (``kernels.route_entry``): a closed
mechanism's accelerations and projection and the articulated-body algorithm, called
through their hook, against the per-call entries of the same model (other code: the
packed entries build ``M`` by the motion subspaces), and the hooks of a batch's members."""
import numpy as np
import pytest

from numba import cfunc, njit

import mbdyn as mb
from ball_chain import ball_chain
from loop_mechanisms import four_bar
from mbdyn.kernels import flexible_entry as kfe
from mbdyn.kernels import route_entry as kre
from mbdyn.kernels import routes


def _state_on_the_loop(model, seed):
    rng = np.random.default_rng(seed)
    return model.project(np.array([0.4, 1.0, 1.6]) + 0.1 * rng.normal(size=3),
                         rng.normal(size=3))


@pytest.fixture(scope="module")
def closed():
    return four_bar(g=9.81)


def test_a_tree_by_the_mass_matrix_passes_its_own_switches(closed):
    s = mb.System("pendulum")
    s.add_body("bob", mass=1.0, com=(0.5, 0, 0), inertia=(0.01, 0.01, 0.01))
    s.add_joint("th", "revolute", "ground", "bob", axis="z")
    args = s.compile().loop_arguments("jourdain")
    assert args[9][7].shape == (1,) and len(args[10]) == 18
    assert len(closed.loop_arguments("jourdain")[10]) == 18    # the same layout
    hook = closed.loop_arguments("jourdain")[9][7]
    assert hook.shape == (kre.HOOK,) and hook[-1] == 1 and hook[kre.FUNCTION] != 0


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_closed_accelerations_by_address_match_the_per_call_entry(closed, seed):
    q, u = _state_on_the_loop(closed, seed)
    ud = closed.forward_dynamics(q, u, method="jourdain")   # the packed per-call entry:
    lam = closed._con[6].copy()                   # M by the motion subspaces, other code
    hook = closed.loop_arguments("jourdain")[9][7]
    out = np.full(closed.nu, np.nan)
    assert kfe.call(hook, out, kre.ACCEL) == -1
    np.testing.assert_allclose(out, ud, rtol=1e-10, atol=1e-10 * np.abs(ud).max())
    np.testing.assert_allclose(closed._con[6], lam, rtol=1e-9,
                               atol=1e-10 * np.abs(lam).max())
    ud2, lam2 = closed.multipliers(q, u)          # Python's multipliers: the same function
    assert np.array_equal(ud2, out) and np.array_equal(lam2, closed._con[6])


def test_projection_by_address_closes_the_loop(closed):
    q, u = _state_on_the_loop(closed, 3)
    hook = closed.loop_arguments("jourdain")[9][7]
    y = np.concatenate([q + np.array([0.0, 0.02, -0.01]), u + 0.1])
    assert closed.constraint_residuals(y[:3], y[3:])[0].__abs__().max() > 1e-3
    assert kfe.call(hook, y, kre.PROJECT) >= 0
    phi, psi = closed.constraint_residuals(y[:3], y[3:])
    assert np.abs(phi).max() < 1e-10 and np.abs(psi).max() < 1e-9
    assert y[0] == pytest.approx(q[0], abs=0.03)    # the crank barely moved


def test_articulated_accelerations_by_address_match_the_per_call_entry():
    model, q, u, _ = ball_chain(7)                  # 21 speeds: the articulated bodies
    ud = model.forward_dynamics(q, u, method="articulated")
    hook = model.loop_arguments("articulated")[9][7]
    assert hook.shape == (kre.HOOK,) and hook[-1] == 0
    out = np.full(model.nu, np.nan)
    assert kfe.call(hook, out, kre.ACCEL) == -1
    np.testing.assert_allclose(out, ud, rtol=1e-11, atol=1e-11 * np.abs(ud).max())


def test_a_members_hook_writes_only_its_own_arrays(closed):
    hook = closed.loop_arguments("jourdain")[9][7]
    mine, kept = kre.private_hook(hook, {})
    for k, (name, _, ndim, written) in enumerate(kre.ARRAYS):
        at = kre.HEAD + 4 * k
        assert (mine[at + 1:at + 4] == hook[at + 1:at + 4]).all(), name
        if written and np.prod(hook[at + 1:at + 1 + ndim]) > 0:
            assert mine[at] != hook[at], name
        elif not written:
            assert mine[at] == hook[at], name
    assert kept and all(a.flags.owndata for a in kept)


def test_a_hook_refuses_an_array_of_another_type(closed):
    from mbdyn.algorithms.route_hook import route_arrays
    arrays = route_arrays(closed, closed._tree)
    arrays["mass"] = arrays["mass"].astype(np.float32)
    with pytest.raises(TypeError, match="mass"):
        kre.hook(arrays, 1, 0, closed.nq, closed.nu, closed=True)


def _failing(hook, io, mode):
    return kre.FAILED


@njit
def _loop_accelerations(tree, body, loads, ws, ud):
    return routes.accelerations(tree, body, loads, ws, ud)


def test_a_function_that_failed_raises_in_its_callers(closed):
    """A C function cannot raise (numba's wrapper prints the exception and returns 0): a
    route's function returns ``FAILED`` where its kernels raised, and its callers -- Python
    (``flexible_entry.call``) and the loops (``routes.accelerations``) -- raise
    ``ZeroDivisionError`` again, which the evaluations report as before."""
    failing = cfunc(kre.SIGNATURE)(_failing)
    closed.forward_dynamics(*_state_on_the_loop(closed, 5))    # a state in its arrays
    tree, body, loads, ws = closed.loop_arguments("jourdain")[7:11]
    hook = loads[7].copy()
    hook[kre.FUNCTION] = failing.address
    out = np.zeros(closed.nu)
    with pytest.raises(ZeroDivisionError):
        kfe.call(hook, out, kre.ACCEL)
    with pytest.raises(ZeroDivisionError):
        _loop_accelerations(tree, body, loads[:7] + (hook,), ws, out)
    assert _loop_accelerations(tree, body, loads, ws, out) == -1      # the route's own


def test_projection_of_a_quaternion_mechanism_after_a_run_keeps_its_arrays():
    """The hooks point to arrays the model keeps (its quaternions' starts among them): a
    run, then projections of states off the constraints of a mechanism with a free
    joint (a rod pendulum), then another run, all on the constraints."""
    L = 0.8
    s = mb.System("rod pendulum")
    s.add_body("bob", mass=2.0, inertia=(0.01, 0.02, 0.03))
    s.add_joint("float", "free", "ground", "bob")
    s.add_joint("rod", "distance", "ground", "bob", position=(0, 0, 0),
                child_position=(0, 0, 0), length=L)
    m = s.compile()
    q, u = m.assemble({"float_x": L * np.sin(0.4), "float_y": 0.0,
                       "float_z": -L * np.cos(0.4)}, {"float_vy": 1.2})
    mb.simulate(m, 0.2, q, u, t_eval=np.linspace(0, 0.2, 7))
    for k in range(5):
        off = q + 0.01 * np.random.default_rng(k).normal(size=q.size)
        qp, up = m.project(off, u)
        assert abs(np.linalg.norm(qp[:3]) - L) < 1e-10
        assert abs(np.linalg.norm(qp[3:7]) - 1.0) < 1e-12
        m.multipliers(qp, up)
    res = mb.simulate(m, 0.2, qp, up, t_eval=np.linspace(0, 0.2, 7))
    assert res.stats["constraint_drift"] <= 1e-10
