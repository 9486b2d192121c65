"""Generated right-hand sides (mbdyn.symbolic.codegen), mb.simulate(method="symbolic"), and
the ``mbdyn eom`` / ``mbdyn run --method symbolic`` commands."""
import json
from pathlib import Path

import numpy as np
import pytest
import sympy as sp

import mbdyn as mb
from mbdyn.symbolic import compiled_rhs, random_states
from mbdyn.symbolic.codegen import model_signature

from textbook_systems import DOUBLE_PENDULUM_DATA, double_pendulum_system, with_symbols

MODELS = Path(__file__).resolve().parent.parent / "models"


@pytest.fixture(autouse=True)
def cache(tmp_path_factory, monkeypatch):
    monkeypatch.setenv("MBDYN_CACHE_DIR", str(tmp_path_factory.getbasetemp() / "eom-cache"))


def double_pendulum(m2=0.0046):
    return with_symbols(double_pendulum_system, dict(DOUBLE_PENDULUM_DATA, m2=m2, g=9.81))


def quaternion_model():
    """A spherical pendulum carrying a driven wheel and a damped, loaded slider: quaternion
    rates, explicit time and loads of q and u in the generated code."""
    s = mb.System("ball and wheel", parameters={"k": 3.0})
    k = s.symbols("k")
    s.add_body("bob", mass=1.0, com=(0, 0, -0.5), inertia=(0.01, 0.02, 0.03))
    s.add_joint("ball", "spherical", parent="ground", child="bob")
    s.add_body("wheel", mass=0.3, inertia=(0.002, 0.002, 0.004))
    s.add_joint("spin", "revolute", parent="bob", child="wheel", axis="z",
                position=(0, 0, -0.5), drive=5 * mb.t + sp.sin(mb.t))
    s.add_body("slider", mass=0.2, inertia=(0.001, 0.001, 0.001))
    s.add_joint("s", "prismatic", parent="bob", child="slider", axis="x")
    x, xd = sp.symbols("s s_dot")
    s.add_load("spring", "slider", force=(-k * x - 0.1 * xd, 0, 0), frame="body")
    return s


def test_generated_rhs_matches_the_engine_and_returns_fresh_arrays():
    model = double_pendulum().compile()
    rhs = compiled_rhs(model)
    assert compiled_rhs(model) is rhs                        # cached per model
    assert rhs.path.exists() and "def rhs(t, y, p):" in rhs.source
    for q, u, t in random_states(model, 5):
        y = np.concatenate([q, u])
        out = rhs(t, y)
        assert np.allclose(out[:2], u, rtol=0, atol=0)
        ud = model.forward_dynamics(q, u, t)
        assert np.abs(out[2:] - ud).max() <= 1e-10 * np.abs(ud).max()
    a = rhs(0.0, y)
    b = rhs(0.0, y)
    assert a is not b and not np.shares_memory(a, b)        # a new array every call
    a[:] = 7.0
    assert np.array_equal(rhs(0.0, y), b)
    raw = rhs.function(0.0, y, rhs.parameters)
    assert raw is not rhs.function(0.0, y, rhs.parameters)


def test_same_structure_shares_the_generated_code():
    m1 = double_pendulum().compile()
    m2 = double_pendulum(m2=0.01).compile()                  # other values, same equations
    assert model_signature(m1) == model_signature(m2)
    r1, r2 = compiled_rhs(m1), compiled_rhs(m2)
    assert r1.path == r2.path and not np.array_equal(r1.parameters, r2.parameters)
    q, u = np.array([0.3, -0.5]), np.array([0.2, 0.1])
    assert np.allclose(r2.accelerations(q, u), m2.forward_dynamics(q, u), rtol=1e-10)


def test_quaternions_time_and_loads_in_generated_code():
    model = quaternion_model().compile()
    rhs = compiled_rhs(model)
    for q, u, t in random_states(model, 4, seed=3):
        q[:4] *= 1.01                                       # drifted: normalised inside
        y = np.concatenate([q, u])
        out = rhs(t, y)
        qn = q.copy()
        model.normalize_quaternions(qn)
        assert np.allclose(out[:model.nq], model.coordinate_rates(qn, u), rtol=1e-12,
                           atol=1e-14)
        ud = model.forward_dynamics(qn, u, t)
        assert np.abs(out[model.nq:] - ud).max() <= 1e-10 * np.abs(ud).max()


def test_singular_mass_matrix_is_reported():
    s = mb.System("top")
    s.add_body("top", mass=1.0, com=(0, 0, 0.1), inertia=(0.01, 0.01, 0.02))
    s.add_joint("contact", "euler", parent="ground", child="top", sequence="ZXZ")
    model = s.compile()
    rhs = compiled_rhs(model)
    with pytest.raises(mb.SingularMassMatrixError):
        rhs(0.0, np.zeros(6))                               # theta = 0: psi and phi align


def test_simulate_with_the_symbolic_method():
    model = double_pendulum().compile()
    kw = dict(q0={"theta1": -np.pi / 4, "theta2": np.pi / 4}, integrator="DOP853",
              rtol=1e-10, atol=1e-12)
    a = mb.simulate(model, 1.0, method="symbolic", **kw)
    b = mb.simulate(model, 1.0, **kw)
    assert a.stats["method"] == "symbolic" and a.stats["status"] == "ok"
    assert np.abs(a.q[-1] - b.q[-1]).max() < 1e-8
    c = mb.simulate(model, 0.2, method="symbolic", integrator="semi-implicit-euler", dt=1e-3,
                    q0=kw["q0"])
    d = mb.simulate(model, 0.2, integrator="semi-implicit-euler", dt=1e-3, q0=kw["q0"],
                    compiled_loop=False)
    assert np.abs(c.q[-1] - d.q[-1]).max() < 1e-12


# ----------------------------------------------------------------------------- CLI
def _cli(argv, capsys):
    from mbdyn.cli import main
    code = main(argv)
    out = capsys.readouterr()
    return code, out.out, out.err


needs_models = pytest.mark.skipif(not (MODELS / "double_pendulum.toml").exists(),
                                  reason="model files not present")


@needs_models
def test_eom_json(capsys):
    code, out, err = _cli(["eom", str(MODELS / "double_pendulum.toml"), "--method",
                           "newton-euler", "--solve", "--format", "json"], capsys)
    assert code == 0, err
    obj = json.loads(out)
    assert obj["method"] == "newton-euler"
    names = {n: sp.Symbol(n) for n in obj["coordinates"] + obj["speeds"]
             + ["m1", "m2", "l1", "l2", "g", "t"]}
    for row in obj["mass_matrix"]:
        for e in row:
            assert not (sp.sympify(e, locals=names).free_symbols - set(names.values()))
    for e in obj["forcing"] + list(obj["accelerations"].values()):
        sp.sympify(e, locals=names)
    assert len(obj["reactions"]["theta1"]) == 6
    assert obj["stats"]["operations"] >= obj["stats"]["operations_after_cse"] > 0


@needs_models
def test_eom_steps_text_latex_markdown(capsys):
    path = str(MODELS / "double_pendulum.toml")
    code, out, _ = _cli(["eom", path, "--steps"], capsys)
    assert code == 0 and "(2) Transformation matrices" in out and "M(q) u' = f" in out
    code, out, _ = _cli(["eom", path, "--format", "latex", "--method", "lagrange"], capsys)
    assert code == 0 and out.startswith("\\documentclass")
    code, out, _ = _cli(["eom", path, "--format", "markdown", "--steps", "--solve"], capsys)
    assert code == 0 and "## (14) Solution" in out
    code, out, err = _cli(["eom", path, "--method", "kane"], capsys)
    assert code == 2


@needs_models
def test_run_with_the_symbolic_method(capsys):
    code, out, err = _cli(["run", str(MODELS / "double_pendulum.toml"), "--method",
                           "symbolic", "--t-end", "0.05"], capsys)
    assert code == 0, err
    assert "symbolic" in out
