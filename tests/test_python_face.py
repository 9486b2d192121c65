"""The Python interface agrees with model files (issue 14's first points)."""
import numpy as np
import pytest

import mbdyn as mb
from mbdyn.io.loader import DEFAULT_SIMULATION


def pendulum():
    s = mb.System("pendulum", gravity=(0, 0, -9.81))
    s.add_body("bob", mass=1.0, com=(0, 0, -1.0))
    s.add_joint("theta", "revolute", parent="ground", child="bob", axis="y")
    return s.compile()


def test_one_set_of_defaults_for_python_and_files():
    assert mb.simulate.__kwdefaults__["integrator"] == DEFAULT_SIMULATION["integrator"] == \
        "DOP853"
    assert mb.simulate.__kwdefaults__["rtol"] == DEFAULT_SIMULATION["rtol"] == 1e-9
    assert mb.simulate.__kwdefaults__["atol"] == DEFAULT_SIMULATION["atol"] == 1e-12
    # the pendulum's small-amplitude period through Python defaults is good to ~1e-9
    model = pendulum()
    res = mb.simulate(model, 2.0, {"theta": 1e-3}, t_eval=np.linspace(0, 2, 4001))
    assert res.stats["integrator"] == "DOP853"
    w = np.sqrt(9.81)
    assert np.abs(res["theta"] - 1e-3 * np.cos(w * res.t)).max() < 1e-9


def test_u0_accepts_a_coordinate_name_for_its_rate_as_files_do():
    model = pendulum()
    assert model.u_vector({"theta": 1.5}) == pytest.approx([1.5])
    res = mb.simulate(model, 0.1, u0={"theta": 1.5})
    assert res["theta_dot"][0] == 1.5
    with pytest.raises(mb.ModelError, match="given twice"):
        model.u_vector({"theta": 1.0, "theta_dot": 2.0})
    with pytest.raises(mb.ModelError, match="unknown speed 'phi'"):
        model.u_vector({"phi": 1.0})


def test_a_particle_on_a_spherical_joint_is_refused_with_the_remedy():
    s = mb.System("conical pendulum")
    s.add_body("bob", mass=1.0, com=(0, 0, -1.0))
    s.add_joint("ball", "spherical", parent="ground", child="bob")
    with pytest.raises(mb.ModelError, match=r"two revolute joints.*small isotropic inertia"):
        s.compile()
