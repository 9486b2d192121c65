"""Animations (GIF, MP4, HTML) and body shapes; the HTML view in a real headless Chromium.

The browser test uses Debian's chromium (never a downloaded browser) driven by Playwright's
Python package, with every request that is not file:// blocked.  Without chromium or
playwright it skips with the install hint -- except in CI (CI set), where it fails.
"""
import os
import shutil
import sys
import warnings
from pathlib import Path

import numpy as np
import pytest

import mbdyn as mb
from mbdyn.viz.geometry import model_geometry, state_at

import browser

pytest.importorskip("matplotlib")
ROOT = Path(__file__).resolve().parent.parent


@pytest.fixture(scope="module")
def pendulum_result():
    scene = mb.load_model(ROOT / "models/double_pendulum.toml",
                          overrides={"simulation.t_end": 1.0})
    return scene.simulate()


def test_gif_has_the_frames_and_duration_of_real_time_playback(pendulum_result, tmp_path):
    from PIL import Image
    out = tmp_path / "dp.gif"
    n = pendulum_result.animate(out, speed=0.5, fps=25)
    duration = pendulum_result.t[-1] - pendulum_result.t[0]
    assert n == int(duration / 0.5 * 25) + 1
    with Image.open(out) as im:
        assert im.n_frames == n
        total = 0
        for k in range(im.n_frames):
            im.seek(k)
            total += im.info["duration"]
    assert total / 1000 == pytest.approx(n / 25, rel=1e-9)      # 0.5x: twice the run


def test_mp4_without_the_extra_is_a_clear_error_and_writes_nothing(pendulum_result, tmp_path,
                                                                     monkeypatch):
    monkeypatch.setitem(sys.modules, "imageio_ffmpeg", None)
    with pytest.raises(mb.ModelError, match=r"mbdyn\[video\]"):
        pendulum_result.animate(tmp_path / "dp.mp4")
    assert os.listdir(tmp_path) == []


def test_mp4_has_the_frame_count(pendulum_result, tmp_path):
    imageio_ffmpeg = pytest.importorskip("imageio_ffmpeg")
    out = tmp_path / "dp.mp4"
    n = pendulum_result.animate(out, fps=20)
    reader = imageio_ffmpeg.read_frames(str(out))
    meta = next(reader)
    frames = sum(1 for _ in reader)
    assert frames == n and meta["fps"] == pytest.approx(20)


@pytest.mark.parametrize("name, message", [("dp.avi", "unknown animation format"),
                                           ("missing/dp.gif", "does not exist")])
def test_bad_animation_requests(pendulum_result, tmp_path, name, message):
    with pytest.raises(mb.ModelError, match=message):
        pendulum_result.animate(tmp_path / name)
    assert [f for f in os.listdir(tmp_path) if not os.path.isdir(tmp_path / f)] == []


def test_shapes_are_validated_and_read_from_files():
    s = mb.System("shapes")
    with pytest.raises(mb.ModelError, match="shape type 'cone'"):
        s.add_body("b", mass=1.0, shape={"type": "cone"})
    with pytest.raises(mb.ModelError, match="a cylinder shape needs length"):
        s.add_body("b", mass=1.0, shape={"type": "cylinder", "radius": 0.1})
    with pytest.raises(mb.ModelError, match="must be positive"):
        s.add_body("b", mass=1.0, shape={"type": "sphere", "radius": -1})
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", mb.ModelWarning)
        top = mb.load_model(ROOT / "models/top.toml").model
    shape = top.body("top").shape
    assert shape["type"] == "disk" and shape["radius"] == 0.05
    assert shape["center"] == pytest.approx([0, 0, 0.0558])
    bad = (ROOT / "models/mass_spring_damper.toml").read_text().replace(
        'mass = "m"', 'mass = "m"\nshape = { type = "box" }')
    path = Path(os.environ.get("TMPDIR", "/tmp")) / "mbdyn_bad_shape.toml"
    path.write_text(bad)
    with pytest.raises(mb.ModelFileError, match=r"bodies\[0\].*box shape needs size"):
        mb.load_model(path)


def test_html_view_in_headless_chromium(pendulum_result, tmp_path):
    import re

    from view_pixels import check_markers
    out = tmp_path / "view.html"
    n = pendulum_result.animate(out)
    assert out.stat().st_size < 120e3           # the viewer (tens of KB) and the poses
    text = out.read_text()
    assert not re.search(r"<script[^>]+src=|<link|https?://", text)   # self-contained
    model = pendulum_result.model
    geometry = [g for g in model_geometry(model) if g["mass"] > 0]
    names = [g["name"] for g in geometry]
    times = np.arange(n) / 30.0
    from mbdyn.viz.geometry import prepare
    half = prepare(pendulum_result, times).half
    with browser.page((900, 700)) as (page, log):
        page.goto(out.as_uri())
        page.wait_for_function("window.mbdynView !== undefined", timeout=30000)
        assert page.evaluate("window.mbdynView.frames") == n
        assert page.evaluate("window.mbdynView.names") == names
        for i in (0, n // 2, n - 1):
            page.evaluate(f"window.mbdynView.goto({i})")
            # drawn where the kinematics put them, and on the screen where a pinhole
            # camera computed here sees them
            drawn = check_markers(page, [g["color"] for g in geometry])
            q, u = state_at(pendulum_result, times[i])
            kin = model.kinematics(q, u, t=times[i])
            expected = np.array([kin.r_com[model.frame_index(nm)] for nm in names])
            # rounded to what a screen shows: 1e-4 of the scene's half-width
            assert np.abs(drawn - expected).max() < 2e-4 * half, i
        with pytest.raises(Exception, match="not in 0"):
            page.evaluate(f"window.mbdynView.goto({n})")
        # the controls: play runs the frames on, pause holds one, the slider picks one
        page.evaluate("window.mbdynView.goto(0)")
        page.click("#mbdyn-play")
        page.wait_for_timeout(400)
        assert page.inner_text("#mbdyn-play") == "pause"
        page.click("#mbdyn-play")
        held = int(page.eval_on_selector("#mbdyn-slider", "e => e.value"))
        assert 0 < held < n and page.inner_text("#mbdyn-play") == "play"
        assert page.inner_text("#mbdyn-time") == f"t = {times[held]:.3f} s"
        page.wait_for_timeout(200)
        assert int(page.eval_on_selector("#mbdyn-slider", "e => e.value")) == held
        page.eval_on_selector("#mbdyn-slider", "e => { e.value = '7'; "
                              "e.dispatchEvent(new Event('input')); }")
        assert page.inner_text("#mbdyn-time") == f"t = {times[7]:.3f} s"
        shot = tmp_path / "view.png"
        page.screenshot(path=str(shot))
        assert log["errors"] == [] and log["outside"] == []
    from PIL import Image
    with Image.open(shot) as im:
        colours = im.convert("RGB").getcolors(maxcolors=1 << 20)
    assert colours is not None and len(colours) > 20          # not a blank page


def test_animate_command(tmp_path):
    import subprocess
    out = tmp_path / "top.gif"
    r = subprocess.run([sys.executable, "-m", "mbdyn", "animate", "models/top.toml", "--case",
                        "a", "--set", "simulation.t_end=0.3", "--out", str(out)],
                       capture_output=True, text=True, cwd=ROOT, timeout=600)
    assert r.returncode == 0, r.stderr
    assert "frames" in r.stdout and out.stat().st_size > 10000


def test_mode_shape_animation(tmp_path):
    from mbdyn.viz.modeshape import animate_mode, mode_motion
    scene = mb.load_model(ROOT / "models/double_pendulum.toml")
    lin = mb.linearize(scene.model)
    mode = mb.modes(lin)[1]
    res = mode_motion(lin, mode, amplitude=0.05)
    # the motion is the mode: the two angles keep the shape's ratio, at its frequency
    k = np.argmax(np.abs(res["theta1"]) > 1e-3)
    assert res["theta2"][k] / res["theta1"][k] == pytest.approx(
        (mode.shape[1] / mode.shape[0]).real, rel=1e-9)
    n = animate_mode(lin, mode, tmp_path / "mode.gif", period_seconds=1.0, fps=25)
    assert n == int(2 * 25) + 1


def test_output_points_leave_trails():
    from mbdyn.viz.geometry import frames
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", mb.ModelWarning)
        res = mb.load_model(ROOT / "models/top.toml", case="a").simulate(t_end=0.5)
    scenes = frames(res, np.linspace(0, 0.5, 11))
    trail = scenes[-1].trails["point G"]
    assert len(trail) == 11 and trail[-1] == pytest.approx(res.points["G"][-1], abs=1e-12)
