"""Units and angles (issue 27, item 3): ``deg(x)`` in model-file expressions and
``mb.deg`` in Python; a warning when an adaptive run needs over a million steps for a few
seconds of a small model (it looks stiff or mis-scaled)."""
from __future__ import annotations

import math
import warnings

import numpy as np
import pytest
import sympy

import mbdyn as mb
from mbdyn.elements.expressions import FUNCTIONS, RESERVED, parse
from mbdyn.integrate import budget as budgets

PENDULUM = """
[model]
name = "pendulum"
gravity = [0, -9.81, 0]
[parameters]
L = 0.5
tilt = "deg(30)"
[[bodies]]
name = "bob"
mass = 1
com = [0, "-L", 0]
[[joints]]
name = "theta"
kind = "revolute"
parent = "ground"
child = "bob"
axis = "z"
[initial]
theta = "deg(5)"
[simulation]
t_end = 0.1
"""


def test_deg_in_expressions_is_exact_radians():
    assert parse("deg(90)", {}) == sympy.pi / 2
    assert parse("deg(-45) + 1", {}) == 1 - sympy.pi / 4
    t = sympy.Symbol("t", real=True)
    assert parse("deg(30)*t", {"t": t}) == sympy.pi * t / 6
    assert "deg" in FUNCTIONS and "deg" in RESERVED


def test_deg_in_a_model_file(tmp_path):
    path = tmp_path / "pendulum.toml"
    path.write_text(PENDULUM)
    scene = mb.load_model(path)
    assert scene.q0[0] == pytest.approx(math.radians(5), abs=1e-15)
    assert scene.parameters["tilt"] == pytest.approx(math.pi / 6, abs=1e-15)
    over = mb.load_model(path, overrides={"initial.theta": "deg(10)"})
    assert over.q0[0] == pytest.approx(math.radians(10), abs=1e-15)


def test_deg_takes_one_argument_and_is_no_name(tmp_path):
    with pytest.raises(Exception, match=r"deg\(\) takes 1 argument"):
        parse("deg(1, 2)", {})
    path = tmp_path / "bad.toml"
    path.write_text(PENDULUM.replace("L = 0.5", "L = 0.5\ndeg = 2"))
    with pytest.raises(mb.ModelError, match="deg"):
        mb.load_model(path)


def test_mb_deg_in_python():
    assert mb.deg(180) == math.pi and isinstance(mb.deg(30), float)
    np.testing.assert_allclose(mb.deg([0, 90, 180]), [0, math.pi / 2, math.pi])
    assert mb.deg(sympy.Integer(90)) == sympy.pi / 2
    assert mb.deg(sympy.Integer(10)) * mb.t == sympy.pi * mb.t / 18    # an exact drive
    with pytest.raises(mb.ModelError, match="deg"):
        mb.deg("30")


def _stiff_system(k):
    """A 1 kg mass on a spring of stiffness ``k``: k = 1e12 N/m is k = 1 N/mm typed as
    if the lengths were in mm and the masses in tonnes -- nothing in SI is this stiff."""
    s = mb.System("mis-scaled", gravity=(0, 0, 0))
    s.add_body("b", mass=1.0, com=(0, 0, 0))
    s.add_joint("x", "prismatic", parent="ground", child="b", axis="x")
    s.add_force("spring", "joint-spring-damper", joint="x", stiffness=k)
    return s.compile()


def test_a_run_that_needs_millions_of_steps_for_seconds_is_warned_about():
    model = _stiff_system(1e12)
    stiff = r"looks stiff or mis-scaled -- .*Radau or BDF.*units"
    with pytest.warns(mb.ModelWarning, match=stiff), \
            pytest.raises(mb.SimulationError, match="max_wall_time"):
        mb.simulate(model, 2.0, {"x": 1e-3}, max_steps=10 ** 9, max_wall_time=1.0)


def test_a_run_the_step_budget_stops_says_so_once():
    """A run that cannot finish within max_steps stops with the same remedy in its
    message; no warning repeats it."""
    model = _stiff_system(1e12)
    with warnings.catch_warnings():
        warnings.simplefilter("error", mb.ModelWarning)
        with pytest.raises(mb.SimulationError, match="max_steps.*Radau or BDF"):
            mb.simulate(model, 2.0, {"x": 1e-3}, max_steps=3000)


def test_an_ordinary_run_is_not_warned_about():
    model = _stiff_system(100.0)
    with warnings.catch_warnings():
        warnings.simplefilter("error", mb.ModelWarning)
        mb.simulate(model, 2.0, {"x": 1e-3})


@pytest.mark.parametrize("speeds, span, projected, warned", [
    (1, 2.0, 2e6, True), (1, 2.0, 5e5, False),           # fewer than a million steps
    (1, 60.0, 2e7, False),                                # a long run may need them
    (40, 2.0, 2e6, False),                                # a large model may too
])
def test_the_stiffness_warning_rule(speeds, span, projected, warned):
    budget = {"speeds": speeds, "span": span, "integrator": "DOP853"}
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        budgets.warn_stiff(budget, projected, 1e-6)
        budgets.warn_stiff(budget, projected, 1e-6)               # once per run
    assert len(caught) == (1 if warned else 0)
