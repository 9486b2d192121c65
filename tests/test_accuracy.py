"""``mbdyn accuracy`` and ``mbdyn.analysis.accuracy``: the work-precision study, fast.

Short runs only (t_end 0.1 s for the double pendulum: the Radau cross-check of the
reference at 1e-13 costs a few seconds; the rotating pendulum's is cheap).  The long studies
behind docs/accuracy.md are not run here.
"""
import contextlib
import io
import json
import math
import pathlib

import numpy as np
import pytest

import mbdyn as mb
from mbdyn.analysis.accuracy import Study, accuracy_study
from mbdyn.cli import main

ROOT = pathlib.Path(__file__).resolve().parents[1]
DOUBLE = str(ROOT / "models" / "double_pendulum.toml")
ROTATING = str(ROOT / "models" / "rotating_pendulum.toml")

T_END = 0.1
SPACING = T_END / 200                       # the study's 201 error samples
STEPS = (SPACING, SPACING / 2, SPACING / 4)  # aligned with the samples: no interpolation
TOLERANCES = (1e-4, 1e-6, 1e-8, 1e-10)

REFERENCE_TYPES = {"integrator": str, "tolerance": float, "error_estimate": float}
RUN_TYPES = {"integrator": str, "setting": float, "error": float,
             "energy_drift": (float, type(None)), "wall_time_s": float,
             "rhs_evaluations": int}


def strict_json(text):
    """``json.loads`` that refuses NaN/Infinity (not JSON, though Python writes them)."""
    def refuse(name):
        raise ValueError(f"{name} is not valid JSON")
    return json.loads(text, parse_constant=refuse)


def check_schema(d):
    """Exactly issue 5's object: keys and types, nothing more, nothing less."""
    assert set(d) == {"reference", "runs"}
    assert set(d["reference"]) == set(REFERENCE_TYPES)
    for k, typ in REFERENCE_TYPES.items():
        assert isinstance(d["reference"][k], typ), k
    assert isinstance(d["runs"], list) and d["runs"]
    for run in d["runs"]:
        assert set(run) == set(RUN_TYPES)
        for k, typ in RUN_TYPES.items():
            assert isinstance(run[k], typ) and not isinstance(run[k], bool), (k, run)


def cli(capsys, *args):
    code = main(["accuracy", *args])
    out, err = capsys.readouterr()
    return code, out, err


@pytest.fixture(scope="module")
def double_json(tmp_path_factory):
    """One CLI study of the double pendulum (45_45): JSON on stdout and a plot."""
    png = tmp_path_factory.mktemp("accuracy") / "wp.png"
    args = ["accuracy", DOUBLE, "--case", "45_45", "--t-end", str(T_END),
            "--integrators", "DOP853,rk4,semi-implicit-euler",
            "--tolerances", ",".join(map(str, TOLERANCES)),
            "--steps", ",".join(map(repr, STEPS)), "--repeats", "1", "--json"]
    has_mpl = True
    try:
        import matplotlib  # noqa: F401
    except ImportError:
        has_mpl = False
    if has_mpl:
        args += ["--plot", str(png)]
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        code = main(args)
    return {"code": code, "stdout": out.getvalue(), "stderr": err.getvalue(),
            "png": png if has_mpl else None}


def runs_of(d, integrator):
    return [r for r in d["runs"] if r["integrator"] == integrator]


# ----------------------------------------------------------------------------- --json
def test_json_is_one_object_with_exactly_the_schema_of_issue_5(double_json):
    assert double_json["code"] == 0, double_json["stderr"]
    text = double_json["stdout"]
    assert text.strip().count("\n") == 0             # one line, nothing else on stdout
    d = strict_json(text)
    check_schema(d)
    assert d["reference"]["integrator"] == "DOP853" and d["reference"]["tolerance"] == 1e-13
    assert [r["integrator"] for r in d["runs"]] == ["DOP853"] * 4 + ["rk4"] * 3 + \
        ["semi-implicit-euler"] * 3
    assert [r["setting"] for r in runs_of(d, "DOP853")] == list(TOLERANCES)
    assert [r["setting"] for r in runs_of(d, "rk4")] == pytest.approx(STEPS)
    for r in d["runs"]:
        assert r["rhs_evaluations"] > 0 and r["wall_time_s"] > 0


def test_the_references_error_estimate_is_small_and_finite(double_json):
    est = strict_json(double_json["stdout"])["reference"]["error_estimate"]
    assert math.isfinite(est) and 0 <= est < 1e-9


def test_dop853_error_falls_as_the_tolerance_tightens(double_json):
    errors = [r["error"] for r in runs_of(strict_json(double_json["stdout"]), "DOP853")]
    assert all(math.isfinite(e) and e > 0 for e in errors)
    # roughly monotone (a factor 2 of slack between neighbours), and six decades of
    # tolerance buy at least four decades of error
    assert all(b < 2 * a for a, b in zip(errors, errors[1:])), errors
    assert errors[-1] < 1e-4 * errors[0], errors
    assert errors[0] < 1e-3 and errors[-1] < 1e-8, errors


def test_rk4_error_falls_with_the_fourth_power_of_the_step(double_json):
    errors = [r["error"] for r in runs_of(strict_json(double_json["stdout"]), "rk4")]
    orders = np.log2(np.array(errors[:-1]) / np.array(errors[1:]))
    assert np.all((orders > 3.5) & (orders < 4.5)), (errors, orders)


def test_semi_implicit_euler_is_first_order(double_json):
    errors = [r["error"] for r in runs_of(strict_json(double_json["stdout"]),
                                          "semi-implicit-euler")]
    orders = np.log2(np.array(errors[:-1]) / np.array(errors[1:]))
    assert np.all((orders > 0.8) & (orders < 1.3)), (errors, orders)


def test_energy_drift_is_a_number_for_the_conservative_double_pendulum(double_json):
    for r in strict_json(double_json["stdout"])["runs"]:
        assert isinstance(r["energy_drift"], float) and 0 <= r["energy_drift"] < 0.1, r
    # and it shrinks with the error
    drifts = [r["energy_drift"] for r in runs_of(strict_json(double_json["stdout"]), "rk4")]
    assert drifts[-1] < drifts[0] / 50


def test_plot_writes_a_png(double_json):
    if double_json["png"] is None:
        pytest.skip("matplotlib is not installed: --plot needs it (pip install matplotlib)")
    png = double_json["png"]
    data = png.read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n" and len(data) > 5000


# ----------------------------------------------------------------------------- drives
def test_energy_drift_is_null_for_a_model_with_drives():
    scene = mb.load_model(ROTATING)
    assert scene.model.driven_joints                 # the arm and the disk are driven
    study = accuracy_study(scene.model, scene.q0, scene.u0, 0.2,
                           integrators=("DOP853", "rk4"), tolerances=(1e-6,),
                           steps=(0.2 / 200,), repeats=1)
    assert isinstance(study, Study) and not study.conservative
    d = strict_json(json.dumps(study.as_dict()))
    check_schema(d)
    assert [r["energy_drift"] for r in d["runs"]] == [None, None]
    assert all(r["error"] < 1e-5 for r in d["runs"])


# ----------------------------------------------------------------------------- table
def test_table_names_every_integrator_run(capsys):
    integrators = ["RK45", "DOP853", "LSODA", "rk4", "semi-implicit-euler",
                   "implicit-midpoint"]
    code, out, err = cli(capsys, ROTATING, "--t-end", "0.2", "--integrators",
                         ",".join(integrators), "--tolerances", "1e-4,1e-6",
                         "--steps", "0.001,0.0005", "--repeats", "1")
    assert code == 0, err
    lines = out.strip().splitlines()
    assert "reference DOP853 at 1e-13" in lines[0] and "error estimate" in lines[0]
    assert lines[1].split()[:2] == ["integrator", "setting"]
    rows = [line.split()[0] for line in lines[2:]]
    assert rows == [i for i in integrators for _ in range(2)]
    assert "energy drift" in lines[1]
    for line in lines[2:]:
        assert line.split()[3] == "-"                # no energy drift with drives


# ----------------------------------------------------------------------------- errors
def test_bad_integrator_name_fails_with_one_line_naming_it(capsys):
    code, out, err = cli(capsys, DOUBLE, "--t-end", "0.1",
                         "--integrators", "DOP853,DOP835")
    assert code != 0
    assert out == ""
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("mbdyn: error:"), err
    assert "DOP835" in lines[0] and "--integrators" in lines[0]
    assert "DOP853" in lines[0]                      # the valid choices are listed


def test_bad_integrator_name_in_python_is_a_model_error():
    scene = mb.load_model(ROTATING)
    with pytest.raises(mb.ModelError, match="rk5"):
        accuracy_study(scene.model, scene.q0, scene.u0, 0.1, integrators=("rk5",))


def test_bad_tolerance_list_fails_with_one_line(capsys):
    code, out, err = cli(capsys, ROTATING, "--t-end", "0.1", "--tolerances", "1e-6,abc")
    assert code != 0 and out == "" and len(err.strip().splitlines()) == 1
    assert "--tolerances" in err


# ----------------------------------------------------------------------------- honesty
def test_steps_that_miss_the_error_samples_cost_no_accuracy(recwarn):
    """A step that does not divide the samples' spacing is sampled by the cubic Hermite
    output: RK4's error still falls with the step (linear interpolation's h^2 error did
    not: 0.7 of the aligned step was then the less accurate)."""
    scene = mb.load_model(ROTATING)
    study = accuracy_study(scene.model, scene.q0, scene.u0, 0.2, integrators=("rk4",),
                           steps=(0.2 / 200, 0.2 / 200 * 0.7), repeats=1)
    aligned, off = (r.error for r in study.runs)
    assert off < 0.5 * aligned
    assert not [w for w in recwarn if "divide" in str(w.message)]


def test_aligned_steps_raise_no_warning(recwarn):
    scene = mb.load_model(ROTATING)
    accuracy_study(scene.model, scene.q0, scene.u0, 0.2, integrators=("rk4",),
                   steps=(0.2 / 200, 0.2 / 600), repeats=1)
    assert not [w for w in recwarn if "divide" in str(w.message)]
    assert not [w for w in recwarn if "cross-check" in str(w.message)]


def test_a_poor_reference_is_warned_about(monkeypatch):
    """A reference that its cross-check does not confirm (as on a chaotic run) is said so;
    here the threshold is lowered below the rotating pendulum's genuine estimate."""
    import mbdyn.analysis.accuracy as acc
    monkeypatch.setattr(acc, "REFERENCE_WARNING", 0.0)
    scene = mb.load_model(ROTATING)
    with pytest.warns(UserWarning, match=r"cross-check differ by .*shorter --t-end"):
        acc.accuracy_study(scene.model, scene.q0, scene.u0, 0.2, integrators=("rk4",),
                           steps=(0.2 / 200,), repeats=1)


def _trajectory(t, q):
    from types import SimpleNamespace
    return SimpleNamespace(t=np.asarray(t, float), q=np.asarray(q, float).reshape(len(t), -1))


def test_error_compares_only_rows_at_the_same_time():
    """A run stopped by a terminal event ends with a row at its own event time; it must not
    be compared with the reference's row at a sample time."""
    from mbdyn.analysis.accuracy import _max_error
    ref = _trajectory([0.0, 0.1, 0.2, 0.3], [0.0, 1.0, 2.0, 3.0])
    early = _trajectory([0.0, 0.1, 0.15], [0.0, 1.001, 9.0])      # event at 0.15
    assert _max_error(early, ref) == pytest.approx(0.001)
    late = _trajectory([0.0, 0.1, 0.2, 0.3], [0.0, 1.0, 2.002, 3.0])
    ref_event = _trajectory([0.0, 0.1, 0.2, 0.25], [0.0, 1.0, 2.0, 7.0])
    assert _max_error(late, ref_event) == pytest.approx(0.002)
    assert _max_error(_trajectory([0.0, 0.05], [0.0, 0.0]),
                      _trajectory([0.1, 0.2], [0.0, 0.0])) == math.inf


def test_a_failed_run_has_a_null_error_in_json_and_is_named_on_stderr(capsys, monkeypatch):
    from mbdyn.analysis.accuracy import Run
    import mbdyn.cli.accuracy as cli_accuracy
    ok = Run("rk4", 0.001, 1e-6, None, 0.01, 800)
    bad = Run("euler", 0.01, 0.5, None, 0.01, 20, failed="failed: non-finite state at t=0.2")
    assert ok.as_dict()["error"] == 1e-6 and bad.as_dict()["error"] is None
    study = Study("stub", 0.2, [], 1e-12, 0.1, [ok, bad], False)
    monkeypatch.setattr(cli_accuracy, "accuracy_study", lambda *a, **k: study)
    code, out, err = cli(capsys, ROTATING, "--t-end", "0.2", "--json")
    assert code == 0
    d = strict_json(out)
    assert [r["error"] for r in d["runs"]] == [1e-6, None]
    assert "euler at 0.01 failed: non-finite state at t=0.2" in err
    code, out, err = cli(capsys, ROTATING, "--t-end", "0.2")
    assert "failed: non-finite state" in out.splitlines()[-1]    # the table says it too
