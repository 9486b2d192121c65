"""Every command that takes a model file takes a URDF robot (and a TOML wrapper of one),
through the one loader: info, run, plot, animate, modes, equilibrium, eom, sweep."""
import json
import pathlib

import pytest

from mbdyn.cli import main

DATA = pathlib.Path(__file__).resolve().parent / "data"
ARM = str(DATA / "planar_arm.urdf")
HANGING = ["--set", "initial.shoulder=1.5"]        # near the arm's hanging equilibrium


def run_json(capsys, *args):
    assert main([*args, "--json"]) == 0, capsys.readouterr().err
    return json.loads(capsys.readouterr().out)


def test_info_json(capsys):
    d = run_json(capsys, "info", ARM)
    assert d["model"] == "planar_arm" and d["coordinates"] == ["shoulder", "elbow"]
    assert [b["name"] for b in d["bodies"]] == ["base_link", "upper_arm", "forearm", "tool"]
    assert d["urdf"]["base"] == "fixed" and d["urdf"]["massless"] == ["tool"]
    assert set(d["urdf"]["stops"]) == {"limit_shoulder", "limit_elbow"}
    assert d["urdf"]["joints"][0]["limit"] == {"lower": -2.5, "upper": 2.5, "effort": 40.0,
                                               "velocity": 3.0}
    floating = run_json(capsys, "info", ARM, "--floating")
    assert floating["dof"] == 8 and floating["urdf"]["base"] == "floating"


def test_info_text(capsys):
    assert main(["info", ARM]) == 0
    out = capsys.readouterr().out
    assert "urdf         " in out and "base fixed to the ground (joint 'root')" in out
    assert "stop limit_elbow: elbow in [-2.8, 2.8]" in out
    assert "damping: damping_shoulder, damping_elbow" in out


def test_run_needs_t_end_and_takes_it(capsys):
    assert main(["run", ARM]) == 1
    assert "t_end" in capsys.readouterr().err
    d = run_json(capsys, "run", ARM, "--t-end", "0.2", "--floating", *HANGING)
    assert d["t_final"] == pytest.approx(0.2)
    assert d["q"]["root_z"] == pytest.approx(-9.81 * 0.2 ** 2 / 2, rel=1e-6)


def test_run_the_wrapper(capsys):
    d = run_json(capsys, "run", str(DATA / "planar_arm.toml"), "--case", "light")
    assert d["events"][0]["name"] == "elbow_straight"


def test_plot(tmp_path, capsys):
    pytest.importorskip("matplotlib")
    out = tmp_path / "arm.png"
    assert main(["plot", ARM, "--t-end", "0.2", "--series", "shoulder,elbow",
                 "--out", str(out)]) == 0
    assert out.stat().st_size > 1000


def test_animate(tmp_path, capsys):
    out = tmp_path / "arm.html"
    assert main(["animate", str(DATA / "arm6.urdf"), "--t-end", "0.1", "--out",
                 str(out)]) == 0
    assert "<html" in out.read_text()[:2000].lower()


def test_modes_and_equilibrium(capsys):
    d = run_json(capsys, "modes", ARM, *HANGING)
    assert len(d["modes"]) == 2
    assert all(m["frequency_hz"] > 0 for m in d["modes"])
    e = run_json(capsys, "equilibrium", ARM, *HANGING)
    assert e["equilibrium"]["q"]["shoulder"] == pytest.approx(1.5707963267948966, abs=1e-6)


def test_eom(capsys):
    assert main(["eom", ARM]) == 0
    out = capsys.readouterr().out
    assert "M[shoulder_dot, shoulder_dot]" in out and "Piecewise" in out


def test_sweep(capsys):
    d = run_json(capsys, "sweep", ARM, "--grid", "initial.shoulder=[0.5, 1.0]",
                 "--t-end", "0.05", "--floating")
    assert d["status"] == ["ok", "ok"]
    assert "final.root_z" in d
