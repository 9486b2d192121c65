"""Pictures users can trust: the HTML view's layout at common window sizes and its size,
solid meshes facing outward, force elements and actuators drawn, GIF/MP4 in world axes,
and plots grouping signals by unit and scale."""
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
    monkeypatch.setattr(drawing, "extra_primitives", lambda model, kin: [box])
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
    pytest.importorskip("plotly")
    res = _load("double_pendulum.toml", **{"simulation.t_end": 10.0}).simulate()
    out = tmp_path_factory.mktemp("view") / "dp.html"
    n = res.animate(out)
    return out, n


def test_a_ten_second_page_is_plotly_plus_little(ten_second_page):
    from mbdyn.viz.html import plotly_js
    out, n = ten_second_page
    assert n == 301
    data = out.stat().st_size - len(plotly_js())
    assert data < 150e3, data          # the 301 frames: poses only (it was 2.8 MB)


LAYOUT = """() => {
  const box = e => { const r = e.getBoundingClientRect();
                     return [r.left, r.top, r.right, r.bottom]; };
  const q = s => Array.from(document.querySelectorAll(s));
  return {w: innerWidth, h: innerHeight,
          scroll: [document.documentElement.scrollWidth, document.documentElement.scrollHeight],
          plot: box(document.querySelector('#mbdyn-plot .svg-container') ||
                    document.getElementById('mbdyn-plot')),
          bar: box(document.getElementById('mbdyn-bar')),
          parts: q('#mbdyn-play, #mbdyn-slider, #mbdyn-time, .gtitle').map(box),
          ticks: q('.mbdyn-tick').map(box)};
}"""


@pytest.mark.parametrize("size", [(1280, 800), (1920, 1080)])
def test_html_view_lays_out_without_clipping(ten_second_page, size, tmp_path):
    out, n = ten_second_page
    with browser.page(size) as (page, log):
        page.goto(out.as_uri())
        page.wait_for_function("window.mbdynView !== undefined", timeout=60000)
        got = page.evaluate(LAYOUT)
        page.screenshot(path=str(tmp_path / f"view_{size[0]}x{size[1]}.png"))
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
    from PIL import Image
    with Image.open(tmp_path / f"view_{w}x{h}.png") as im:
        colours = im.convert("RGB").getcolors(maxcolors=1 << 20)
    assert colours is not None and len(colours) > 20              # not a blank page


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
