"""The implicit midpoint rule's quasi-Newton iteration (``kernels.implicit_midpoint``): the
matrix kept over steps and corrected by Broyden's update must still give the rule's own
step -- ``yn = y + h F(t + h/2, (y + yn)/2)`` solved to the rounding of ``yn`` -- while
costing fewer evaluations than Newton's method with a fresh Jacobian every step."""
from __future__ import annotations

import numpy as np
import pytest

import mbdyn as mb
from mbdyn.kernels.implicit_midpoint import broyden_update, lu_apply, lu_factor

DOUBLE = "models/double_pendulum.toml"
BEAD = "models/bead_on_rod.toml"


def midpoint_residuals(model, res):
    """``|yn - y - h F(t + h/2, (y + yn)/2)|`` of every step of a run, relative to
    ``max(1, |yn|)`` (max norms)."""
    y = np.hstack([res.q, res.u])
    out = []
    for k in range(len(res.t) - 1):
        h = res.t[k + 1] - res.t[k]
        f = model.state_derivative(res.t[k] + h / 2, 0.5 * (y[k] + y[k + 1]))
        g = y[k + 1] - y[k] - h * f
        out.append(np.abs(g).max() / max(1.0, np.abs(y[k + 1]).max()))
    return np.array(out)


@pytest.mark.parametrize("path, dt, steps", [(DOUBLE, 1e-3, 600), (BEAD, 1e-2, 200)])
@pytest.mark.parametrize("compiled", [True, False])
def test_every_step_solves_the_midpoint_equation(path, dt, steps, compiled):
    """Each step's residual is at the level of the evaluation's rounding: measured at most
    5.4e-15 relative on the double pendulum (nonlinear) and 4.9e-16 on the bead (its rod
    driven: the drive's time is the midpoint's), as with Newton's method and a fresh
    Jacobian every step (5.3e-15, 4.9e-16)."""
    scene = mb.load_model(path)
    res = mb.simulate(scene.model, steps * dt, scene.q0, scene.u0,
                      integrator="implicit-midpoint", dt=dt, compiled_loop=compiled)
    assert len(res.t) == steps + 1
    r = midpoint_residuals(scene.model, res)
    assert r.max() < 1e-14, (r.max(), int(r.argmax()))


@pytest.mark.parametrize("compiled", [True, False])
def test_the_kept_matrix_saves_evaluations(compiled):
    """Newton's method with a fresh forward-difference Jacobian costs ``ny + 4``
    evaluations a step here (the step's start, the predictor, the Jacobian's ``ny``
    columns, two iterations); kept and updated it costs under 7 (measured 6.2)."""
    scene = mb.load_model(DOUBLE)
    steps, ny = 2000, 4
    res = mb.simulate(scene.model, 2.0, scene.q0, scene.u0, integrator="implicit-midpoint",
                      dt=1e-3, compiled_loop=compiled)
    per_step = res.stats["rhs_evaluations"] / steps
    assert per_step < 7.0 < ny + 4, per_step


def test_compiled_and_python_iterations_agree():
    """The compiled loop and the Python step run the same iteration: over 200 steps of
    the chaotic double pendulum they stay within what a relative change of 1e-14 in the
    initial angles alone makes of the Python run (measured: 1e-14 and 3e-13 at step 100,
    2e-12 and 9e-12 at step 500)."""
    scene = mb.load_model(DOUBLE)
    runs = [mb.simulate(scene.model, 0.2, scene.q0, scene.u0, integrator="implicit-midpoint",
                        dt=1e-3, compiled_loop=flag) for flag in (True, False)]
    a, b = (np.hstack([r.q, r.u]) for r in runs)
    assert np.abs(a - b).max() < 1e-12


def test_lu_factor_and_apply_solve_like_numpy():
    rng = np.random.default_rng(3)
    for n in (1, 2, 5, 12):
        A = rng.normal(size=(n, n))
        A[0, 0] = 0.0 if n > 1 else 2.0             # needs a row swap
        b = rng.normal(size=n)
        LU, piv = A.copy(), np.zeros(n, np.int64)
        assert lu_factor(LU, piv) == -1
        x = b.copy()
        lu_apply(LU, piv, x)
        np.testing.assert_allclose(x, np.linalg.solve(A, b), rtol=1e-10, atol=1e-12)
    S = np.array([[1.0, 2.0], [2.0, 4.0]])
    assert lu_factor(S.copy(), np.zeros(2, np.int64)) == 1    # the singular column


def test_broyden_update_meets_the_secant_condition():
    """After the update the inverse maps the residual's change onto the step taken
    (``H dg = s``), and it changes ``H`` only along ``H^T s`` (rank one)."""
    rng = np.random.default_rng(5)
    n = 6
    H = np.eye(n) + 0.1 * rng.normal(size=(n, n))
    s, dg = rng.normal(size=n), rng.normal(size=n)
    H1 = H.copy()
    broyden_update(H1, s, dg, np.empty(n), np.empty(n))
    np.testing.assert_allclose(H1 @ dg, s, rtol=1e-12, atol=1e-12)
    assert np.linalg.matrix_rank(H1 - H, tol=1e-12) == 1
    H2 = H.copy()
    broyden_update(H2, np.zeros(n), dg, np.empty(n), np.empty(n))    # no step: no update
    np.testing.assert_array_equal(H2, H)
