"""Pictures users can trust: the HTML view's layout at common window sizes and its size,
solid meshes facing outward, force elements and actuators drawn, GIF/MP4 in world axes,
and plots grouping signals by unit and scale."""
import sys
import warnings
from pathlib import Path

import numpy as np
import pytest

import mbdyn as mb
from mbdyn.viz import meshes
from mbdyn.viz.geometry import frames, prepare

import browser

pytest.importorskip("matplotlib")
ROOT = Path(__file__).resolve().parent.parent


def _load(name, case=None, **overrides):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", mb.ModelWarning)
        return mb.load_model(ROOT / "models" / name, case=case,
                             overrides=overrides or None)


@pytest.mark.parametrize("mesh", [
    meshes.sphere([0.1, 0.2, 0.3], 0.5), meshes.box([1, 0, 0], [0.2, 0.4, 0.8]),
    meshes.tube([0, 0, 0], [0.3, -0.2, 0.5], 0.05),
    meshes.shape_mesh({"type": "disk", "radius": 0.05, "length": 0.02,
                       "center": np.array([0, 0, 0.05]), "axis": np.array([0, 1.0, 0])}),
    meshes.shape_mesh({"type": "rod", "start": np.zeros(3), "end": np.array([0, -0.07, 0])}),
    meshes.primitive_mesh("cylinder", (np.eye(3)[[1, 2, 0]], np.ones(3)), (0.1, 0.3)),
], ids=["sphere", "box", "tube", "disk", "rod", "primitive"])
def test_mesh_faces_point_outward_and_close_the_solid(mesh):
    v, f = mesh
    n = meshes.normals(v, f)
    centroid = v[f].mean(axis=1)
    inside = v.mean(axis=0)                    # every shape is convex
    assert np.all(np.einsum("ij,ij->i", n, centroid - inside) > 0)
    # closed: every edge is shared by exactly two faces, in opposite directions
    edges = {}
    for a, b, c in f:
        for e in ((a, b), (b, c), (c, a)):
            edges[e] = edges.get(e, 0) + 1
    assert all(count == 1 and edges.get((b, a)) == 1 for (a, b), count in edges.items())


def test_shading_is_lambert_by_face_normal():
    v, f = meshes.box([0, 0, 0], [1, 1, 1])
    shades = meshes.shade((1.0, 0.5, 0.0), v, f, np.array([0, 0, 1.0]), ambient=0.3)
    up = meshes.normals(v, f)[:, 2] > 0.5
    assert np.allclose(shades[up], [1.0, 0.5, 0.0])          # facing the light: full colour
    assert np.allclose(shades[~up], [0.3, 0.15, 0.0])        # the rest: ambient only


def test_springs_dampers_planes_and_actuators_are_drawn():
    msd = _load("mass_spring_damper.toml").simulate(t_end=0.2)
    run = prepare(msd, [0.0, 0.1])
    assert [s[0] for s in run.drawing.springs] == ["spring"]
    assert [s[0] for s in run.drawing.dampers] == ["damper"]
    sc = frames(msd, [0.1])[0]
    coil = max((pts for pts, c, _ in sc.lines if c == "#3d5a80"), key=len)
    x = np.interp(0.1, msd.t, msd["x"])
    assert coil[0] == pytest.approx(msd.model.force_element("spring").params["point_a"])
    assert coil[-1] == pytest.approx([x, 0, 0], abs=1e-9)   # the coil ends on the block
    ball = _load("bouncing_ball.toml").simulate(t_end=0.1)
    sc = frames(ball, [0.0])[0]
    assert len(sc.planes) == 1
    name, corners, faces = sc.planes[0]
    assert np.ptp(corners[:, 2]) == 0 and corners[0, 2] == pytest.approx(0.0)
    arm = _load("pd_arm.toml").simulate(t_end=0.05)
    sc = frames(arm, [0.0])[0]
    rings = [pts for pts, c, _ in sc.lines if c == "#ff7f0e"]
    actuators = [n for n in arm.model.forces if arm.model.force_element(n).kind == "actuator"]
    assert len(rings) == len(actuators) > 0
    assert sc.solids and all(len(v) and len(f) for v, f, _ in sc.solids)


def test_extra_primitives_hook_adds_solids(monkeypatch):
    from mbdyn.viz import drawing
    box = ("box", (np.eye(3), np.array([0.0, 0.0, -0.5])), (0.1, 0.2, 0.3))
    monkeypatch.setattr(drawing, "extra_primitives", lambda model, kin, q=None, scale=1.0: [box])
    res = _load("double_pendulum.toml").simulate(t_end=0.1)
    sc = frames(res, [0.0])[0]
    v = sc.solids[-1][0]
    assert v.min(axis=0) == pytest.approx([-0.05, -0.1, -0.65])


def test_gif_axes_are_the_worlds():
    from mbdyn.viz.animate import _figure
    res = _load("double_pendulum.toml").simulate(t_end=0.2)
    scenes = frames(res, [0.0, 0.1])
    fig, draw = _figure(res.model, scenes, "dp", 1.0)
    draw(1)
    ax = fig.axes[0]
    assert (ax.get_xlabel(), ax.get_ylabel(), ax.get_zlabel()) == ("x [m]", "y [m]", "z [m]")
    spans = [np.ptp(lim) for lim in (ax.get_xlim(), ax.get_ylim(), ax.get_zlim())]
    assert spans == pytest.approx([spans[0]] * 3)              # one scale on every axis
    # world coordinates: the lower particle's line ends where the kinematics put it
    x, y = scenes[1].markers[-1][1][:2]
    drawn = [ln.get_data_3d() for ln in ax.lines]
    assert any(np.isclose(d[0][-1], x) and np.isclose(d[1][-1], y) for d in drawn)


# ---------------------------------------------------------------- the HTML view
@pytest.fixture(scope="module")
def ten_second_page(tmp_path_factory):
    res = _load("double_pendulum.toml", **{"simulation.t_end": 10.0}).simulate()
    out = tmp_path_factory.mktemp("view") / "dp.html"
    n = res.animate(out)
    return out, n, res


def test_a_ten_second_page_is_its_data_and_a_small_viewer(ten_second_page):
    import json
    import re

    from mbdyn.viz.html import viewer_script
    out, n, _ = ten_second_page
    assert n == 301
    page = out.read_text()
    script = viewer_script()
    assert script in page and len(script) < 50e3      # our own viewer: no library inside
    data = re.search(r'id="mbdyn-data">(.*?)</script>', page, re.DOTALL).group(1)
    assert len(data) < 150e3, len(data)     # the 301 frames: poses only (it was 2.8 MB)
    assert len(json.loads(data)["poses"]) == 301 * 2 * 7
    assert out.stat().st_size < len(data) + len(script) + 5e3     # and nothing else
    # self-contained: nothing the page would fetch
    assert not re.search(r"<script[^>]+src=|<link|<img|https?://|//cdn", page)


def test_the_html_view_needs_no_plotting_library(tmp_path, monkeypatch):
    res = _load("double_pendulum.toml").simulate(t_end=0.2)
    for name in ("matplotlib", "plotly"):          # any import of them now fails
        monkeypatch.setitem(sys.modules, name, None)
    assert res.animate(tmp_path / "v.html") == 7
    assert "mbdyn-data" in (tmp_path / "v.html").read_text()


def test_the_viewer_scripts_are_installed_with_the_package():
    import tomllib

    from mbdyn.viz.html import SCRIPTS
    with open(ROOT / "pyproject.toml", "rb") as f:
        data = tomllib.load(f)["tool"]["setuptools"]["package-data"]["mbdyn.viz"]
    assert sorted(data) == sorted(SCRIPTS)


LAYOUT = """() => {
  const box = e => { const r = e.getBoundingClientRect();
                     return [r.left, r.top, r.right, r.bottom]; };
  const q = s => Array.from(document.querySelectorAll(s));
  return {w: innerWidth, h: innerHeight,
          scroll: [document.documentElement.scrollWidth, document.documentElement.scrollHeight],
          plot: box(document.getElementById('mbdyn-canvas')),
          bar: box(document.getElementById('mbdyn-bar')),
          parts: q('#mbdyn-play, #mbdyn-slider, #mbdyn-time, #mbdyn-reset, #mbdyn-title')
                 .map(box),
          ticks: q('.mbdyn-tick').map(box)};
}"""


def _inside_the_view(page, res, n):
    """At the first, middle and last frames: the mechanism's pixels clear of the canvas's
    edges, every centre of mass of the run inside it, the markers drawn where they are."""
    from view_pixels import canvas_pixels, check_markers, drawn_box, pinhole
    from mbdyn.viz.geometry import model_geometry
    colours = [g["color"] for g in model_geometry(res.model) if g["mass"] > 0]
    cam = page.evaluate("window.mbdynView.camera()")
    w, h = cam["width"], cam["height"]
    for i in (0, n // 2, n - 1):
        page.evaluate(f"window.mbdynView.goto({i})")
        check_markers(page, colours)
        box, count = drawn_box(canvas_pixels(page))
        assert count > 2000, count                       # the mechanism is drawn...
        left, top, right, bottom = box
        assert left >= 3 and top >= 3 and right <= w - 4 and bottom <= h - 4, (box, w, h)
        width, height = right - left, bottom - top       # ... and not lost in a corner
        assert max(width / w, height / h) > 0.4, (box, w, h)
    model = res.model
    bodies = [model.frame_index(nm) for nm in page.evaluate("window.mbdynView.names")]
    coms = np.vstack([model.kinematics(q, u, t=t).r_com[bodies]
                      for t, q, u in zip(res.t, res.q, res.u)])
    at = pinhole(cam, coms)                              # every sample of the run
    assert at.min() > 0 and (at[:, 0] < w).all() and (at[:, 1] < h).all()


@pytest.mark.parametrize("size", [(1280, 800), (1920, 1080)])
def test_html_view_lays_out_without_clipping(ten_second_page, size, tmp_path):
    out, n, res = ten_second_page
    with browser.page(size) as (page, log):
        page.goto(out.as_uri())
        page.wait_for_function("window.mbdynView !== undefined", timeout=60000)
        got = page.evaluate(LAYOUT)
        page.screenshot(path=str(tmp_path / f"view_{size[0]}x{size[1]}.png"))
        _inside_the_view(page, res, n)
        # what the tests here exercise is what headless Chromium gives: WebGL
        assert page.evaluate("window.mbdynView.renderer") == "webgl"
        assert log["errors"] == [] and log["outside"] == []
    w, h = size
    assert got["scroll"][0] <= w and got["scroll"][1] <= h        # nothing past the window
    for left, top, right, bottom in got["parts"] + got["ticks"] + [got["bar"]]:
        assert 0 <= left and right <= w and 0 <= top and bottom <= h
    assert got["plot"][3] <= got["bar"][1] + 1                    # the plot ends above the bar
    assert got["plot"][3] - got["plot"][1] > 0.75 * h             # and takes most of the page
    ticks = sorted(got["ticks"])
    assert len(ticks) >= 5
    assert all(a[2] + 4 <= b[0] for a, b in zip(ticks, ticks[1:]))   # labels never overlap


def test_html_view_without_webgl_draws_on_a_2d_canvas(ten_second_page):
    out, n, res = ten_second_page
    with browser.page((1280, 800), browser.NO_WEBGL) as (page, log):
        page.goto(out.as_uri())
        page.wait_for_function("window.mbdynView !== undefined", timeout=60000)
        assert page.evaluate("window.mbdynView.renderer") == "2d"
        _inside_the_view(page, res, n)
        assert log["errors"] == [] and log["outside"] == []


@pytest.mark.parametrize("flags", [(), browser.NO_WEBGL], ids=["webgl", "2d"])
def test_html_view_draws_springs_dampers_planes_and_contact_forces(tmp_path, flags):
    """Each piece in its colour: a spring's coil and a damper (quarter car), a translucent
    ground plane and the contact forces' arrows (box on an incline)."""
    from view_pixels import canvas_pixels, hex_rgb
    from mbdyn.viz import drawing as dr
    car = _load("quarter_car.toml").simulate(t_end=0.5)
    box = _load("box_incline.toml").simulate(t_end=0.3)
    for k, (res, options, colours) in enumerate([(car, {}, [dr.SPRING, dr.DAMPER]),
                                                  (box, {"contact_forces": True}, [dr.FORCE])]):
        out = tmp_path / f"page{k}.html"
        n = res.animate(out, **options)
        with browser.page((900, 700), flags) as (page, log):
            page.goto(out.as_uri())
            page.wait_for_function("window.mbdynView !== undefined", timeout=60000)
            page.evaluate(f"window.mbdynView.goto({n // 2})")
            pixels = canvas_pixels(page).astype(int)
            assert log["errors"] == []
        for colour in colours:
            near = (np.abs(pixels - hex_rgb(colour)).max(axis=2) <= 6).sum()
            assert near > 30, (colour, near)
        if options:        # the plane: its grey at 30 % over the white background
            grey = (np.ptp(pixels, axis=2) <= 2) & (pixels[..., 0] >= 195) \
                & (pixels[..., 0] <= 235)
            assert grey.mean() > 0.05, grey.mean()


def test_world_axes_are_a_round_length_at_the_origin_or_the_mechanism():
    from mbdyn.viz.view_data import world_axes
    for half in (0.0123, 0.1, 0.37, 2.0, 55.0):
        origin, length = world_axes(np.zeros(3), half, (np.ones(3), 2 * np.ones(3)))
        assert origin.tolist() == [0, 0, 0]
        assert 0.2 * half < length <= 0.5 * half
        mantissa = length / 10 ** np.floor(np.log10(length))
        assert min(abs(mantissa - m) for m in (1, 2, 5)) < 1e-9
    origin, _ = world_axes(np.array([5.0, 0, 0]), 1.0, (np.array([4.0, -1, 0]), np.ones(3)))
    assert origin.tolist() == [4, -1, 0]          # the origin is off the scene's cube


def test_html_view_camera_orbits_pans_zooms_and_resets(ten_second_page):
    """Drag orbits about "up" (kept vertical on the screen), shift-drag pans (the point
    under the pointer follows it), the wheel zooms, double-click fits the run again."""
    from view_pixels import pinhole
    out, n, res = ten_second_page
    with browser.page((1280, 800)) as (page, log):
        page.goto(out.as_uri())
        page.wait_for_function("window.mbdynView !== undefined", timeout=60000)
        box = page.locator("#mbdyn-canvas").bounding_box()
        cx, cy = box["x"] + box["width"] / 2, box["y"] + box["height"] / 2
        first = page.evaluate("window.mbdynView.camera()")
        page.mouse.move(cx, cy)
        page.mouse.down()
        page.mouse.move(cx + 120, cy + 40, steps=4)
        page.mouse.up()
        cam = page.evaluate("window.mbdynView.camera()")
        assert cam["target"] == first["target"]
        assert np.linalg.norm(np.subtract(cam["eye"], cam["target"])) == \
            pytest.approx(np.linalg.norm(np.subtract(first["eye"], first["target"])))
        assert not np.allclose(cam["eye"], first["eye"])
        up = np.asarray(cam["target"]) + np.outer([-1, 1], cam["up"])
        assert np.ptp(pinhole(cam, up)[:, 0]) < 1e-6           # "up" stays vertical
        before = page.evaluate(f"window.mbdynView.project({cam['target']})")
        page.keyboard.down("Shift")
        page.mouse.move(cx, cy)
        page.mouse.down()
        page.mouse.move(cx + 50, cy + 30, steps=3)
        page.mouse.up()
        page.keyboard.up("Shift")
        after = page.evaluate(f"window.mbdynView.project({cam['target']})")
        assert np.subtract(after, before) == pytest.approx([50, 30], abs=0.01)
        d0 = np.linalg.norm(np.subtract(*[page.evaluate("window.mbdynView.camera()")[k]
                                          for k in ("eye", "target")]))
        page.mouse.wheel(0, -200)
        page.wait_for_timeout(100)
        cam = page.evaluate("window.mbdynView.camera()")
        assert np.linalg.norm(np.subtract(cam["eye"], cam["target"])) < 0.9 * d0
        page.mouse.dblclick(cx, cy)
        page.wait_for_timeout(100)
        cam = page.evaluate("window.mbdynView.camera()")
        for key in ("eye", "target"):
            assert cam[key] == pytest.approx(first[key], rel=1e-12, abs=1e-12)
        assert log["errors"] == []


# ---------------------------------------------------------------- plots by unit and scale
def test_group_series_splits_units_and_scales():
    from mbdyn.viz.plots import group_series
    t = np.linspace(0, 1, 50)
    table = {"a": (np.sin(t), "rad", ""), "x": (0.01 * t, "m", ""), "b": (3 * t, "rad", ""),
             "y": (2.0 * t, "m", ""), "z": (np.zeros(50), "m", ""),
             "v": (t, "m/s", ""), "w": (0.1 * t, "m", "")}
    groups = group_series(table, ["a", "x", "b", "y", "z", "v", "w"])
    assert groups == [("rad", ["a", "b"]), ("m", ["y", "z", "w"]), ("m", ["x"]),
                      ("m/s", ["v"])]
    # the chain of a group never spans more than the ratio
    groups = group_series({k: (np.array([10.0 ** (k / 2)]), "J", "") for k in range(6)},
                          list(range(6)), ratio=20)
    assert [g for _, g in groups] == [[3, 4, 5], [0, 1, 2]]      # 316..31.6 and 10..1


def test_plot_puts_signals_of_one_unit_but_other_scales_on_separate_axes(tmp_path):
    res = _load("quarter_car.toml").simulate(t_end=1.0)   # potential ~2000 J, kinetic ~10 J
    fig = res.plot(series="zw,zb,energy", out=tmp_path / "qc.png")
    assert [ax.get_ylabel() for ax in fig.axes] == ["[m]", "[J]", "[J]"]
    for ax in fig.axes:
        peaks = [np.abs(ln.get_ydata()).max() for ln in ax.lines if ln.get_linestyle() == "-"]
        assert max(peaks) <= 20 * min(peaks)
    legend = [t.get_text() for t in fig.axes[1].get_legend().get_texts()]
    assert "energy potential" in legend and "energy kinetic" not in legend
