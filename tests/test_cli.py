"""The ``mbdyn`` command end to end: ``run``, ``info``, ``--json``, ``--out``, exit codes."""
import json
import os
import pathlib
import subprocess
import sys

import numpy as np
import pytest

from mbdyn.cli import COMMANDS, main

ROOT = pathlib.Path(__file__).resolve().parents[1]
MODELS = ROOT / "models"
TOP = str(MODELS / "top.toml")
BEAD = str(MODELS / "bead_on_rod.toml")

SUMMARY_TYPES = {"model": str, "case": (str, type(None)), "t_final": float, "q": dict,
                 "reactions": (dict, type(None)), "drive_efforts": (dict, type(None)),
                 "points": (dict, type(None)),
                 "u": dict, "events": list, "energy": (dict, type(None)), "stats": dict,
                 "quality": dict}
STATS_TYPES = {"integrator": str, "method": str, "steps": int, "rhs_evaluations": int,
               "wall_time_s": float}


def check_run_json(d):
    """The schema of ``mbdyn run --json``, exactly."""
    assert set(d) == set(SUMMARY_TYPES)
    for k, typ in SUMMARY_TYPES.items():
        assert isinstance(d[k], typ), k
    assert set(d["stats"]) == set(STATS_TYPES)
    for k, typ in STATS_TYPES.items():
        assert isinstance(d["stats"][k], typ), k
    for name, v in list(d["q"].items()) + list(d["u"].items()):
        assert isinstance(name, str) and isinstance(v, float)
    for e in d["events"]:
        assert set(e) == {"name", "t"} and isinstance(e["name"], str) and isinstance(e["t"], float)
    if d["energy"] is not None:
        assert set(d["energy"]) == {"initial", "final"}
        assert all(isinstance(v, float) for v in d["energy"].values())
    assert set(d["quality"]) == {"energy_drift", "quaternion_drift", "error_estimate",
                                 "threshold", "warnings"}
    assert all(isinstance(w, str) for w in d["quality"]["warnings"])


def run_module(*args, timeout=300):
    env = dict(os.environ)
    env.pop("MBDYN_DEBUG", None)
    return subprocess.run([sys.executable, "-m", "mbdyn", *args], capture_output=True,
                          text=True, cwd=ROOT, timeout=timeout, env=env)


# ----------------------------------------------------------------------------- subprocess
def test_python_m_mbdyn_run_top_case_a_json():
    proc = run_module("run", "models/top.toml", "--case", "a", "--json")
    assert proc.returncode == 0, proc.stderr
    d = json.loads(proc.stdout)                      # exactly one JSON object ...
    assert proc.stdout.strip().count("\n") == 0      # ... on one line, nothing else
    check_run_json(d)
    assert d["model"] == "heavy top" and d["case"] == "a"
    (event,) = d["events"]
    assert event["name"] == "floor" and 2.3 < event["t"] < 2.7
    assert list(d["q"]) == ["psi", "theta", "phi"]
    assert d["stats"]["integrator"] == "semi-implicit-euler" and d["stats"]["method"] == "jourdain"
    assert "triangle inequality" in proc.stderr       # the warning: stderr, not stdout
    assert "Traceback" not in proc.stderr


def test_python_m_mbdyn_bad_input_one_line_no_traceback():
    proc = run_module("run", "tests/malformed/unknown_name.toml", "--json")
    assert proc.returncode == 1
    assert proc.stdout == ""
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("mbdyn: error: ")
    assert "bodies[0].mass" in lines[0] and "Traceback" not in proc.stderr


def test_console_script_is_declared():
    """``pip install .`` provides the ``mbdyn`` command (pyproject [project.scripts])."""
    import tomllib
    meta = tomllib.loads((ROOT / "pyproject.toml").read_text())
    assert meta["project"]["scripts"]["mbdyn"] == "mbdyn.cli:main"
    from importlib.metadata import entry_points
    eps = [ep for ep in entry_points(group="console_scripts") if ep.name == "mbdyn"]
    if eps:                                   # installed: the entry point is ours
        assert eps[0].value == "mbdyn.cli:main"


# ----------------------------------------------------------------------------- in process
def test_commands_registry():
    assert COMMANDS[:2] == ["run", "info"]
    for name in COMMANDS:
        module = __import__(f"mbdyn.cli.{name}", fromlist=["register"])
        assert callable(module.register)


def test_run_json_in_process(capsys):
    assert main(["run", BEAD, "--json"]) == 0
    out, err = capsys.readouterr()
    d = json.loads(out)
    check_run_json(d)
    assert d["case"] is None and d["events"][0]["name"] == "end_of_rod"
    assert d["q"]["x"] == pytest.approx(1.0, abs=1e-9)


def test_run_human_report(capsys):
    assert main(["run", BEAD, "--case", "pushed"]) == 0
    out, _ = capsys.readouterr()
    assert "bead on a rotating rod" in out and "case pushed" in out
    assert "event end_of_rod at t =" in out and "terminal" in out
    assert "x_dot" in out and "energy T + V" in out


def test_run_options_override_the_file(capsys):
    assert main(["run", BEAD, "--json", "--t-end", "0.5", "--integrator", "rk4", "--dt",
                 "1e-3", "--method", "newton-euler", "--set", "parameters.Omega=1",
                 "--set", "initial.x=0.2"]) == 0
    d = json.loads(capsys.readouterr().out)
    assert d["t_final"] == pytest.approx(0.5)
    assert d["stats"]["integrator"] == "rk4" and d["stats"]["method"] == "newton-euler"
    assert d["stats"]["steps"] == 500
    assert d["q"]["x"] == pytest.approx(0.2 * np.cosh(0.5), rel=1e-9)
    assert d["events"] == []


def test_run_out_writes_csv_and_json(tmp_path, capsys):
    out_dir = tmp_path / "results"
    assert main(["run", BEAD, "--out", str(out_dir), "--json"]) == 0
    d = json.loads(capsys.readouterr().out)
    assert sorted(os.listdir(out_dir)) == ["bead_on_rod.csv", "bead_on_rod.json"]
    meta = json.loads((out_dir / "bead_on_rod.json").read_text())
    assert {k: meta[k] for k in d if k != "stats"} == {k: d[k] for k in d if k != "stats"}
    header = (out_dir / "bead_on_rod.csv").read_text().splitlines()[0].split(",")
    assert header[:3] == ["t", "x", "x_dot"] and meta["columns"] == header
    data = np.loadtxt(out_dir / "bead_on_rod.csv", delimiter=",", skiprows=1)
    assert data[-1, 0] == pytest.approx(d["t_final"]) and data[-1, 1] == pytest.approx(1.0)


def test_run_case_names_the_output_files(tmp_path, capsys):
    assert main(["run", BEAD, "--case", "pushed", "--out", str(tmp_path)]) == 0
    assert sorted(os.listdir(tmp_path)) == ["bead_on_rod_pushed.csv", "bead_on_rod_pushed.json"]


def test_simulation_failure_exit_code_and_partial_results(tmp_path, capsys):
    """Case c of the top with the listing's scheme runs into the Euler singularity."""
    code = main(["run", TOP, "--case", "c", "--out", str(tmp_path), "--json"])
    out, err = capsys.readouterr()
    assert code == 3 and out == ""
    errors = [ln for ln in err.splitlines() if ln.startswith("mbdyn: error:")]
    assert len(errors) == 1 and "simulation failed" in errors[0] and "singular" in errors[0]
    meta = json.loads((tmp_path / "top_c.json").read_text())
    assert meta["status"] == "failed" and "singular" in meta["error"]


def test_info_text(capsys):
    assert main(["info", TOP, "--case", "a"]) == 0
    out, err = capsys.readouterr()
    for word in ("heavy top", "case         a", "bodies (1)", "joints (1)", "contact",
                 "euler ZXZ", "coordinates  psi, theta, phi",
                 "speeds       psi_dot, theta_dot, phi_dot", "degrees of freedom  3",
                 "drives       none", "loads (1)", "resisting_moment", "events (1)",
                 "floor          theta >= pi/2 - atan(r/0.0442)  (rising, terminal)",
                 "warnings (1)", "triangle inequality"):
        assert word in out, word
    assert err == ""                  # warnings are in the report, not repeated on stderr


def test_info_json_lists_drives_and_warnings(capsys):
    assert main(["info", str(MODELS / "rotating_pendulum.toml"), "--json"]) == 0
    d = json.loads(capsys.readouterr().out)
    assert d["dof"] == 1 and d["coordinates"] == ["beta"] and d["speeds"] == ["beta_dot"]
    assert [x["joint"] for x in d["drives"]] == ["arm_turn", "disk_turn"]
    assert d["drives"][0]["expression"] == "Omega*t"
    assert [b["name"] for b in d["bodies"]] == ["arm", "disk", "pendulum"]
    assert d["bodies"][0]["massless"] and not d["bodies"][2]["massless"]
    assert d["warnings"] == [] and d["cases"] == ["at_rest"] and d["case"] is None
    assert d["parameters"]["Omega"] == pytest.approx(np.pi / 4)
    assert d["route"]["route"] == "jourdain" and d["route"]["method"] == "auto"


def test_info_names_the_route_a_run_takes(capsys):
    """``mbdyn info`` says which formulation ``method = auto`` resolves to and what it
    solves: the mass matrix with multipliers for a small closed mechanism, the
    articulated bodies when asked."""
    andrews = str(MODELS / "andrews_squeezer.toml")
    assert main(["info", andrews]) == 0
    assert "route        jourdain (method auto): M u' = f + G^T lam" in capsys.readouterr().out
    assert main(["info", andrews, "--set", "simulation.method=articulated", "--json"]) == 0
    route = json.loads(capsys.readouterr().out)["route"]
    assert route["route"] == "articulated" and "independent constraint row" in route["solves"]


@pytest.mark.parametrize("argv, code, fragment", [
    (["run", "models/nope.toml"], 1, "no such file"),
    (["run", TOP, "--case", "z"], 1, "no case 'z'"),
    (["run", TOP, "--set", "parameters.MZ=1"], 1, "did you mean 'Mz'"),
    (["run", TOP, "--set", "nonsense"], 1, "expected PATH=VALUE"),
    (["run", TOP, "--t-end", "-1"], 1, "--t-end -1: must be > 0"),
    (["run", TOP, "--integrator", "foo"], 2, "invalid choice: 'foo'"),
    (["run", TOP, "--method", "lagrange"], 2, "invalid choice: 'lagrange'"),
    (["run"], 2, "MODEL"),
    (["frobnicate"], 2, "invalid choice"),
    ([], 2, "give a command"),
    (["info", "tests/malformed/toml_syntax.toml"], 1, "line 5: TOML syntax error"),
])
def test_bad_input_is_one_line_with_an_exit_code(argv, code, fragment, capsys):
    assert main(argv) == code
    out, err = capsys.readouterr()
    assert out == ""
    lines = [ln for ln in err.splitlines() if ln.strip() and not ln.startswith("usage:")
             and not ln.startswith("mbdyn: warning:") and not ln.startswith("  ")]
    assert len(lines) == 1, err
    assert fragment in lines[0] and "Traceback" not in err


def test_help_and_version(capsys):
    assert main(["--help"]) == 0
    assert "run" in capsys.readouterr().out
    assert main(["run", "--help"]) == 0
    out = capsys.readouterr().out
    for opt in ("--case", "--set", "--t-end", "--method", "--integrator", "--rtol", "--atol",
                "--dt", "--out", "--json", "jourdain", "newton-euler", "semi-implicit-euler"):
        assert opt in out
    assert main(["--version"]) == 0
    assert "mbdyn" in capsys.readouterr().out


def test_numbas_pedantic_scope_warning_is_not_shown_but_model_warnings_are(capsys):
    """numba's SSA pass warns "variable ... is not in scope" when it compiles a loop with
    inlined functions (an internal check of its IR); the command shows every other warning
    once but not that one."""
    import types
    import warnings

    from mbdyn.cli import _dispatch
    from mbdyn.errors import ModelError, ModelWarning, SimulationError

    class NumbaIRAssumptionWarning(UserWarning):
        pass

    def command(args):
        # raised from numba's module, or (a parallel loop) from the kernel's source line
        warnings.warn_explicit("\x1b[1mvariable 'x_v1.1' is not in scope.\n\nThis warning "
                               "came from an internal pedantic check.",
                               NumbaIRAssumptionWarning, "ssa.py", 304,
                               module="numba.core.ssa")
        warnings.warn_explicit("\x1b[1m\x1b[1m\x1b[1mvariable 'a_route_v127__v108call_45_3.1'"
                               " is not in scope.\nThis warning came from an internal "
                               "pedantic check.", NumbaIRAssumptionWarning,
                               "/x/mbdyn/kernels/batched.py", 58)
        warnings.warn("body 'b': check the data", ModelWarning)
        return 0

    assert _dispatch(types.SimpleNamespace(func=command), False, ModelError,
                     SimulationError) == 0
    err = capsys.readouterr().err
    assert "not in scope" not in err
    assert "mbdyn: warning: body 'b': check the data" in err
