"""The energy balance's running Simpson integral (``mbdyn.integrate.balance.cumulative_simpson``):
exact for parabolas on any grid, and the same numbers as scipy's, bit for bit (the run's
energy columns must not change with the route)."""
import numpy as np
import pytest
from scipy.integrate import cumulative_simpson as scipy_cumulative_simpson

from mbdyn.integrate.balance import cumulative_simpson


@pytest.mark.parametrize("n", [3, 4, 5, 8, 33])
def test_exact_for_a_parabola_on_an_uneven_grid(n):
    rng = np.random.default_rng(n)
    x = np.cumsum(0.1 + rng.random(n))
    y = 2.0 - 3.0 * x + 0.5 * x ** 2
    exact = (2.0 * x - 1.5 * x ** 2 + x ** 3 / 6) - (2.0 * x[0] - 1.5 * x[0] ** 2 + x[0] ** 3 / 6)
    assert cumulative_simpson(y, x) == pytest.approx(exact, rel=1e-12, abs=1e-12)


def test_bit_identical_to_scipy():
    rng = np.random.default_rng(7)
    for n in range(3, 60):
        for even in (False, True):
            x = np.linspace(0.0, 2.0, n) if even else np.cumsum(0.01 + rng.random(n))
            y = rng.standard_normal(n)
            ours = cumulative_simpson(y, x)
            theirs = scipy_cumulative_simpson(y, x=x, initial=0.0)
            assert np.array_equal(ours, theirs), n
