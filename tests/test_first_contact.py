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
