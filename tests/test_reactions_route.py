"""``Model.newton_euler(dense=True)`` (and so ``Model.reactions`` along a run of a small
model) takes the kernels a run
compiles anyway and LAPACK's ``dgesv`` from Python instead of the fused, compiled
Newton-Euler solution (docs/performance.md, "Cold and warm start"); the numbers must be
the fused route's, bit for bit."""
import numpy as np
import pytest

from mbdyn.kernels import packed as kp
from random_trees import cached_tree

SEEDS = range(8)


@pytest.mark.parametrize("seed", SEEDS)
def test_newton_euler_route_is_bit_identical_to_the_fused_kernel(seed):
    tr = cached_tree(seed)
    m, q, u, t = tr.model, tr.q, tr.u, tr.t
    if m._python_inputs:
        m._fill_inputs(q, u, t)
    fused, _ = kp.newton_euler_solution_packed(*m._packed, q, u, *m._dense_system())   # numba's np.linalg.solve
    ud, reactions = m.newton_euler(q, u, t, dense=True)
    assert np.array_equal(ud, fused[:m.nu])
    assert np.array_equal(m._newton_euler(q, u, t, dense=True), fused)


def test_non_finite_state_is_named():
    import mbdyn as mb
    tr = cached_tree(0)
    m, q, u, t = tr.model, tr.q.copy(), tr.u.copy(), tr.t
    u[0] = np.nan
    with pytest.raises(mb.errors.NonFiniteError, match=m.speeds[0]):
        m.newton_euler(q, u, t, dense=True)
