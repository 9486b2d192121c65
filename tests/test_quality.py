"""Every run reports what it is worth (issue 27, item 2): the energy balance drift, the
quaternion drift and, on request, an error estimate, in the printed report and in
``--json``; a figure above the threshold is a warning that names it and the remedy."""
from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

import mbdyn as mb
from mbdyn import limits
from mbdyn.cli import main

ROOT = Path(__file__).resolve().parent.parent
DOUBLE = str(ROOT / "models" / "double_pendulum.toml")
SPHERICAL = str(ROOT / "models" / "spherical_pendulum.toml")


def _run(capsys, *args):
    code = main(["run", *args])
    out, err = capsys.readouterr()
    return code, out, err


def test_the_textbook_scheme_on_90_90_warns_of_its_energy_drift_and_the_remedy(capsys):
    """The README's example: semi-implicit Euler, the listing's scheme, drifts by 62 %."""
    code, out, err = _run(capsys, DOUBLE, "--case", "90_90")
    assert code == 0
    warning = [ln for ln in err.splitlines() if "energy balance drifted" in ln]
    assert len(warning) == 1
    assert "62.4 %" in warning[0] and "use DOP853 with rtol 1e-10" in warning[0]
    assert "smaller dt" in warning[0]
    assert "energy balance drift: 0.624 (62.4 % of the energy scale)" in out
    assert "above the warning threshold" in out


def test_the_same_run_with_dop853_does_not_warn(capsys):
    code, out, err = _run(capsys, DOUBLE, "--case", "90_90", "--integrator", "DOP853")
    assert code == 0 and "drifted" not in err and "above the warning" not in out
    assert "energy balance drift: 6." in out                 # 6.5e-9


def test_json_carries_the_figures_and_the_warnings(capsys):
    code, out, _ = _run(capsys, DOUBLE, "--case", "90_90", "--json")
    q = json.loads(out)["quality"]
    assert code == 0 and q["energy_drift"] == pytest.approx(0.624, abs=1e-3)
    assert q["threshold"] == limits.WARN_THRESHOLD and len(q["warnings"]) == 1
    assert q["quaternion_drift"] is None and q["error_estimate"] is None   # no quaternion
    code, out, _ = _run(capsys, DOUBLE, "--case", "90_90", "--json", "--integrator", "DOP853")
    q = json.loads(out)["quality"]
    assert q["energy_drift"] < 1e-7 and q["warnings"] == []


def test_the_threshold_is_settable(capsys):
    code, out, err = _run(capsys, DOUBLE, "--case", "90_90", "--warn-threshold", "0.7")
    assert code == 0 and "drifted" not in err
    code, out, err = _run(capsys, DOUBLE, "--case", "45_45", "--warn-threshold", "0.01",
                          "--json")
    assert "drifted by 0.0379" in err and json.loads(out)["quality"]["threshold"] == 0.01


def test_error_estimate_on_the_command_line(capsys):
    code, out, err = _run(capsys, DOUBLE, "--case", "90_90", "--error-estimate", "--json")
    est = json.loads(out)["quality"]["error_estimate"]
    assert code == 0 and est["against"] == "dt = 8e-05"
    assert set(est["difference"]) == {"theta1", "theta2", "theta1_dot", "theta2_dot"}
    assert est["difference"]["theta1"] > 1                    # 4.66 rad: worthless
    assert "the error estimate of" in err
    code, out, err = _run(capsys, DOUBLE, "--case", "45_45", "--error-estimate",
                          "--integrator", "DOP853", "--rtol", "1e-10", "--atol", "1e-12")
    assert "error estimate (difference from the same run at rtol = 1e-12, atol = 1e-14)" in out
    assert "theta2_dot" in out and "error estimate of" not in err


@pytest.fixture(scope="module")
def pendulum():
    return mb.load_model(DOUBLE, case="45_45")


def test_a_fixed_step_estimate_is_the_error_it_estimates(pendulum):
    """RK4: the difference from the run at half the step is 15/16 of the run's error."""
    kw = {"t_eval": np.linspace(0, 1, 11)}
    ref = mb.simulate(pendulum.model, 1.0, pendulum.q0, pendulum.u0, integrator="DOP853",
                      rtol=1e-13, atol=1e-15, **kw)
    res = mb.simulate(pendulum.model, 1.0, pendulum.q0, pendulum.u0, integrator="rk4",
                      dt=1e-3, error_estimate=True, **kw)
    est = res.stats["error_estimate"]
    err = np.abs(res.q - ref.q).max(axis=0)
    for k, name in enumerate(pendulum.model.coordinates):
        assert 0.8 * err[k] < est["difference"][name] < 1.1 * err[k]
    assert est["against"] == "dt = 0.0005" and 0 < est["relative"] < 1e-4


def test_an_adaptive_estimate_bounds_the_error(pendulum):
    kw = {"t_eval": np.linspace(0, 1, 11)}
    ref = mb.simulate(pendulum.model, 1.0, pendulum.q0, pendulum.u0, integrator="DOP853",
                      rtol=1e-13, atol=1e-15, **kw)
    res = mb.simulate(pendulum.model, 1.0, pendulum.q0, pendulum.u0, integrator="RK45",
                      rtol=1e-6, atol=1e-9, error_estimate=True, **kw)
    est = res.stats["error_estimate"]
    err = np.abs(res.q - ref.q).max()
    assert est["against"] == "rtol = 1e-08, atol = 1e-11"
    assert 0.5 * err < max(est["difference"][n] for n in pendulum.model.coordinates) < 2 * err
    tight = mb.simulate(pendulum.model, 0.1, pendulum.q0, pendulum.u0, rtol=1e-13,
                        atol=1e-15, error_estimate=True)
    assert "already the tightest" in tight.stats["error_estimate"]["failed"]


def test_result_quality_in_python(pendulum):
    res = mb.simulate(pendulum.model, 1.0, pendulum.q0, pendulum.u0,
                      integrator="semi-implicit-euler", dt=1e-3)
    assert "energy_drift" not in res.stats                    # not asked for ...
    q = res.quality()                                         # ... but conservative
    full = mb.simulate(pendulum.model, 1.0, pendulum.q0, pendulum.u0,
                       integrator="semi-implicit-euler", dt=1e-3, outputs=("energy",))
    assert q["energy_drift"] == pytest.approx(full.stats["energy_drift"], rel=1e-9)
    assert q["warnings"] and "energy balance drifted" in q["warnings"][0]
    assert res.quality(threshold=1.0)["warnings"] == []


def test_quaternion_drift_is_reported_and_warned_about():
    scene = mb.load_model(SPHERICAL, case="swirl")
    res = scene.simulate(integrator="RK45", rtol=1e-3, atol=1e-3)
    q = res.quality(threshold=1e-12)
    assert q["quaternion_drift"] == res.stats["quaternion_drift"] > 1e-12
    assert any("quaternions drifted off unit length" in w for w in q["warnings"])


def test_a_model_with_loads_and_no_energy_output_has_no_drift():
    s = mb.System("pushed", gravity=(0, 0, 0))
    s.add_body("b", mass=1.0, com=(0, 0, 0))
    s.add_joint("x", "prismatic", parent="ground", child="b", axis="x")
    s.add_load("push", "b", force=(1.0, 0, 0))
    res = mb.simulate(s, 1.0)
    assert res.quality()["energy_drift"] is None
    assert mb.simulate(s, 1.0, outputs=("energy",)).quality()["energy_drift"] < 1e-9
