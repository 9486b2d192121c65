"""``Model.newton_euler`` (and so ``Model.reactions`` along a run) takes the kernels a run
compiles anyway and LAPACK's ``dgesv`` from Python instead of the fused, compiled
Newton-Euler solution (docs/performance.md, "Cold and warm start"); the numbers must be
the fused route's, bit for bit."""
import numpy as np
import pytest

from random_trees import cached_tree

SEEDS = range(8)


@pytest.mark.parametrize("seed", SEEDS)
def test_newton_euler_route_is_bit_identical_to_the_fused_kernel(seed):
    tr = cached_tree(seed)
    m, q, u, t = tr.model, tr.q, tr.u, tr.t
    fused = m._newton_euler(q, u, t, packed=True).copy()     # numba's np.linalg.solve
    ud, reactions = m.newton_euler(q, u, t)
    assert np.array_equal(ud, fused[:m.nu])
    assert np.array_equal(m._newton_euler(q, u, t, packed=False), fused)


def test_non_finite_state_is_named():
    import mbdyn as mb
    tr = cached_tree(0)
    m, q, u, t = tr.model, tr.q.copy(), tr.u.copy(), tr.t
    u[0] = np.nan
    with pytest.raises(mb.errors.NonFiniteError, match=m.speeds[0]):
        m.newton_euler(q, u, t)
