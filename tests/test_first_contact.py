"""The small things of a first hour (issue 27, items 5 and 8): the Campbell colour scale,
file modes, messages, column names, the sweep table and its progress, shared run flags."""
from __future__ import annotations

import json
import math
import shlex
import warnings
from pathlib import Path

import numpy as np
import pytest

from mbdyn.analysis.campbell import ZETA_RANGE, Campbell
from mbdyn.cli import main


def _campbell(zetas):
    values = np.linspace(0, 1, len(zetas))
    freq = np.ones((len(zetas), 1)) * 10.0
    zeta = np.asarray(zetas, dtype=float)[:, None]
    return Campbell("Omega", values, freq, -zeta * 10, zeta, [("forward",)] * len(zetas),
                    np.ones(len(zetas)), spin_is_parameter=False)


def test_the_campbell_colour_scale_is_neutral_at_zero_damping():
    """White at zeta = 0; a healthy 0.15 is plainly blue, an unstable -0.05 plainly red
    (the old linear scale from -0.2 to 0.5 put its white at 0.15)."""
    pytest.importorskip("matplotlib")
    import matplotlib.pyplot as plt
    fig = _campbell([-0.05, 0.0, 0.15]).plot()
    (points,) = [c for c in fig.axes[0].collections if c.get_array() is not None]
    assert points.norm(0.0) == pytest.approx(0.5)
    assert points.norm(ZETA_RANGE[0]) == pytest.approx(0.0)
    assert points.norm(ZETA_RANGE[1]) == pytest.approx(1.0)
    red, white, blue = points.cmap(points.norm(np.array([-0.05, 0.0, 0.15])))[:, :3]
    assert red[0] > red[2] + 0.1 and blue[2] > blue[0] + 0.2
    assert min(white) > 0.8                                   # the neutral colour
    plt.close(fig)


ROOT = Path(__file__).resolve().parent.parent


def test_the_docs_top_equilibrium_is_away_from_the_euler_singularity(capsys):
    """docs/vibration.md's command finds the steady precession of the closed form, not
    the upright top at the ZXZ singularity (theta = 0)."""
    line = next(ln for ln in (ROOT / "docs" / "vibration.md").read_text().splitlines()
                if ln.startswith("mbdyn equilibrium models/top.toml"))
    argv = shlex.split(line)[1:]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        assert main(argv + ["--json"]) == 0
    out, err = capsys.readouterr()
    theta = json.loads(out)["equilibrium"]["q"]["theta"]
    A, C, mgh = 0.00209393, 0.00220580, 0.582 * 9.81 * 0.0558
    psid, phid = 30.0, 3.5
    assert "initial_speeds.psi=30" in line and "initial_speeds.phi=3.5" in line
    exact = math.acos((C * phid * psid - mgh) / ((A - C) * psid ** 2))
    assert theta == pytest.approx(exact, abs=1e-9) and theta > 0.3
    assert "singular" not in err


@pytest.mark.parametrize("umask", [0o022, 0o002, 0o077])
def test_output_files_get_the_modes_the_umask_gives(tmp_path, umask):
    """Every output goes through ``mbdyn.files``, whose temporaries (mkstemp: 0600) get
    ``0666 & ~umask`` before they are renamed into place, as ``open()`` would give."""
    import os
    import stat

    import mbdyn as mb
    from mbdyn import files
    from mbdyn.io.results import write_results
    old = os.umask(umask)
    try:
        assert files.current_umask() == umask
        scene = mb.load_model(ROOT / "models" / "double_pendulum.toml")
        res = scene.simulate(t_end=0.01)
        paths = list(write_results(tmp_path / "out", scene, res))
        paths.append(res.to_csv(tmp_path / "r.csv"))
        files.atomic_write(tmp_path / "t.txt", "text")
        with files.replacing(tmp_path / "p.png") as tmp:
            Path(tmp).write_bytes(b"png")
        paths += [tmp_path / "t.txt", tmp_path / "p.png"]
    finally:
        os.umask(old)
    for p in paths:
        assert stat.S_IMODE(os.stat(p).st_mode) == 0o666 & ~umask, p


@pytest.mark.parametrize("spec, problem", [
    ("-nonexistent", "unknown effect 'nonexistent'"),
    ("-damper,+damper", "effect 'damper' is switched both on (+damper) and off"),
])
def test_a_bad_effects_option_is_named_once(capsys, spec, problem):
    code = main(["run", str(ROOT / "models" / "mass_spring_damper.toml"), f"--effects={spec}"])
    _, err = capsys.readouterr()
    assert code == 1
    assert err.startswith(f"mbdyn: error: --effects: {problem}")
    assert err.count("--effects:") == 1


# -- sweeps (issue 27, item 5)

DOUBLE = str(ROOT / "models" / "double_pendulum.toml")
SHORT = ["--t-end", "0.05", "--integrator", "rk4", "--dt", "1e-3"]


def test_a_quantity_as_q_spells_it_is_a_plot_column(tmp_path, capsys):
    """``-q absmax:theta1`` makes the column ``absmax.theta1``; ``--plot`` takes either."""
    pytest.importorskip("matplotlib")
    for spelled in ("absmax:theta1", "absmax.theta1"):
        out = tmp_path / f"{spelled.replace(':', '_')}.csv"
        code = main(["sweep", DOUBLE, "--grid", "parameters.m1=0.0004:0.0005:3",
                     "-q", "absmax:theta1", *SHORT, "--out", str(out), "--plot", spelled])
        _, err = capsys.readouterr()
        assert code == 0, err
        assert (tmp_path / f"{out.stem}_absmax.theta1.png").stat().st_size > 1000
    from mbdyn.analysis.sweeps.quantities import column_of
    assert column_of("max:energy") == "max.energy" and column_of("final.x") == "final.x"
    assert column_of("t_final") == "t_final" and column_of("foo:x") == "foo:x"


def test_the_sweep_table_is_a_plain_csv_with_a_sidecar(tmp_path, capsys):
    """The CSV starts with its header (no comment line): any CSV reader takes it as it
    is; what describes it is in NAME.json beside it."""
    import csv
    out = tmp_path / "s.csv"
    assert main(["sweep", DOUBLE, "--grid", "parameters.m1=0.0004:0.0005:3", "-q", "final",
                 *SHORT, "--out", str(out)]) == 0
    capsys.readouterr()
    rows = list(csv.reader(out.read_text().splitlines()))
    assert rows[0][:3] == ["member", "parameters.m1", "status"] and len(rows) == 4
    assert {len(r) for r in rows} == {len(rows[0])}
    data = np.genfromtxt(out, delimiter=",", names=True, dtype=None, encoding="utf-8")
    assert list(data["member"]) == [0, 1, 2]
    np.testing.assert_allclose(data["parametersm1"], [0.0004, 0.00045, 0.0005])
    meta = json.loads((tmp_path / "s.json").read_text())
    assert meta["format"] == "mbdyn sweep table" and meta["status"] == "complete"
    assert meta["columns"] == rows[0] and meta["rows"] == 3 and meta["csv"] == "s.csv"
    assert meta["fixed"] == {"simulation.t_end": 0.05, "simulation.integrator": "rk4",
                             "simulation.dt": 0.001}


def test_pandas_reads_the_sweep_table_as_it_is(tmp_path, capsys):
    pd = pytest.importorskip("pandas")
    out = tmp_path / "s.csv"
    assert main(["sweep", DOUBLE, "--grid", "parameters.m1=0.0004:0.0005:3", *SHORT,
                 "--out", str(out)]) == 0
    frame = pd.read_csv(out)
    assert list(frame["member"]) == [0, 1, 2] and frame["status"].tolist() == ["ok"] * 3


def _members(progress):
    from mbdyn.analysis.sweep import sweep
    return sweep(DOUBLE, {"parameters.m1": [0.0004, 0.0005, 0.0006]},
                 fixed={"simulation.t_end": 0.02}, progress=progress)


def test_sweep_progress_true_is_a_bar_without_tqdm(capsys, monkeypatch):
    import builtins
    real_import = builtins.__import__

    def no_tqdm(name, *args, **kwargs):
        if name.startswith("tqdm"):
            raise ImportError(name)
        return real_import(name, *args, **kwargs)
    monkeypatch.setattr(builtins, "__import__", no_tqdm)
    assert len(_members(True)) == 3
    err = capsys.readouterr().err
    assert "mbdyn sweep: 3/3 members" in err


def test_sweep_progress_true_uses_tqdm_when_installed(monkeypatch):
    import sys
    import types
    made = []

    class FakeTqdm:
        def __init__(self, total, initial, **kw):
            self.n, self.total, self.closed = initial, total, False
            made.append(self)

        def update(self, k):
            self.n += k

        def close(self):
            self.closed = True
    auto = types.ModuleType("tqdm.auto")
    auto.tqdm = FakeTqdm
    monkeypatch.setitem(sys.modules, "tqdm", types.ModuleType("tqdm"))
    monkeypatch.setitem(sys.modules, "tqdm.auto", auto)
    _members(True)
    assert len(made) == 1 and made[0].n == made[0].total == 3 and made[0].closed


def test_sweep_progress_may_be_a_function_and_nothing_else():
    import mbdyn as mb
    seen = []
    _members(lambda done, total: seen.append((done, total)))
    assert seen == [(1, 3), (2, 3), (3, 3)]
    with pytest.raises(mb.ModelError, match=r"progress='yes': give True"):
        _members("yes")


@pytest.mark.parametrize("command", ["run", "plot", "animate", "sweep", "accuracy"])
def test_every_command_that_runs_a_model_takes_the_same_simulation_flags(command):
    """--t-end --integrator --rtol --atol --dt, defined once (common.SIMULATION_FLAGS)."""
    from mbdyn.cli import build_parser
    from mbdyn.cli.common import SIMULATION_FLAGS
    parser = build_parser(command)
    sub = next(a for a in parser._actions if a.dest == "command").choices[command]
    options = {o: a for a in sub._actions for o in a.option_strings}
    for _, flag, metavar, _ in SIMULATION_FLAGS:
        assert flag in options and options[flag].metavar == metavar, (command, flag)
        assert options[flag].type is None                 # read as --set values


def test_the_simulation_flags_reach_the_runs(tmp_path, capsys):
    pytest.importorskip("matplotlib")
    png = tmp_path / "p.png"
    assert main(["plot", DOUBLE, *SHORT, "--out", str(png)]) == 0
    out = tmp_path / "s.csv"
    assert main(["sweep", DOUBLE, "--grid", "parameters.m1=0.0004:0.0005:2", "-q", "steps",
                 "-q", "t_final", *SHORT, "--out", str(out)]) == 0
    capsys.readouterr()
    rows = list(json.loads((tmp_path / "s.json").read_text())["columns"])
    assert rows[-2:] == ["steps", "t_final"]
    assert out.read_text().splitlines()[1].endswith(",50.0,0.05")      # 50 steps to 0.05 s
    code = main(["accuracy", str(ROOT / "models" / "rotating_pendulum.toml"), "--t-end",
                 "0.1", "--integrator", "rk4", "--dt", "5e-4", "--repeats", "1"])
    text = capsys.readouterr().out
    assert code == 0 and "t = 0 .. 0.1 s" in text
    assert [ln.split()[:2] for ln in text.splitlines()[2:]] == [["rk4", "5.00e-04"]]
    code = main(["accuracy", DOUBLE, "--integrator", "rk4", "--integrators", "rk4"])
    assert code == 1 and "--integrator and --integrators: give one" in capsys.readouterr().err
