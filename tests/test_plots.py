"""Plots of results: axes and units, events, phase portraits, and bad requests."""
import os
import subprocess
import sys
import warnings
from pathlib import Path

import numpy as np
import pytest

import mbdyn as mb

pytest.importorskip("matplotlib", reason="pictures need matplotlib: pip install '.[plot]'")

ROOT = Path(__file__).resolve().parent.parent


@pytest.fixture(scope="module")
def top_result():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", mb.ModelWarning)
        scene = mb.load_model(ROOT / "models/top.toml", case="a")
    return scene.simulate(integrator="DOP853", t_end=3.0)


def test_time_series_name_their_axes_and_units_and_mark_events(top_result, tmp_path):
    out = tmp_path / "top.png"
    fig = top_result.plot(series="theta,psi_dot,energy", out=out)
    assert out.stat().st_size > 5000
    labels = [ax.get_ylabel() for ax in fig.axes]
    assert labels == ["[rad]", "[rad/s]", "[J]"]
    assert fig.axes[-1].get_xlabel() == "time t [s]"
    t_floor = dict(top_result.events)["floor"]
    lines = [ln for ln in fig.axes[0].lines if ln.get_linestyle() == "--"]
    assert any(np.allclose(ln.get_xdata(), t_floor) for ln in lines)
    legend = [t.get_text() for t in fig.axes[2].get_legend().get_texts()]
    assert "energy balance" in legend and "energy dissipated" in legend


def test_phase_portrait(top_result, tmp_path):
    fig = top_result.plot(phase="theta,theta_dot", out=tmp_path / "phase.svg")
    ax = fig.axes[0]
    assert ax.get_xlabel() == "theta [rad]" and ax.get_ylabel() == "theta_dot [rad/s]"
    x, y = ax.lines[0].get_data()
    assert np.array_equal(x, top_result["theta"]) and np.array_equal(y, top_result["theta_dot"])


@pytest.mark.parametrize("kwargs, message", [
    ({"series": "thetaa"}, "unknown series 'thetaa'"),
    ({"phase": "theta"}, "give two series"),
    ({"out": "picture.bmp"}, "unknown picture format '.bmp'"),
    ({"out": "no/such/dir/p.png"}, "does not exist"),
])
def test_bad_requests_are_clear_and_leave_no_file(top_result, tmp_path, kwargs, message):
    if "out" in kwargs:
        kwargs = {"out": str(tmp_path / kwargs["out"])}
    else:
        kwargs["out"] = str(tmp_path / "p.png")
    before = set(os.listdir(tmp_path))
    with pytest.raises(mb.ModelError, match=message):
        top_result.plot(**kwargs)
    assert set(os.listdir(tmp_path)) == before


def test_plot_and_run_plot_commands(tmp_path):
    def cli(*args):
        return subprocess.run([sys.executable, "-m", "mbdyn", *args], capture_output=True,
                              text=True, cwd=ROOT, timeout=600)
    out = tmp_path / "msd.png"
    r = cli("plot", "models/mass_spring_damper.toml", "--series", "x,energy",
            "--out", str(out))
    assert r.returncode == 0, r.stderr
    assert out.stat().st_size > 5000
    out2 = tmp_path / "run.pdf"
    r = cli("run", "models/mass_spring_damper.toml", "--plot", str(out2))
    assert r.returncode == 0, r.stderr
    assert out2.read_bytes()[:4] == b"%PDF"
    r = cli("plot", "models/mass_spring_damper.toml", "--out", str(tmp_path / "x.gif"))
    assert r.returncode == 1 and "unknown picture format" in r.stderr
