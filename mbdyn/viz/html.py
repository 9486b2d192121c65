"""A self-contained HTML view of a run: orbit, zoom and pan, play/pause, a time slider;
bodies as shaded solids, springs, dampers, ground planes, actuators, centres of mass and
their trails.

The page carries plotly.js, the bundle the plotly package ships (never the "cdn" mode): it
opens without network access and without a server.  plotly is an optional extra:
``pip install "mbdyn[viz]"``.  The run is sent as each solid's mesh once and every
frame's poses (``viz.view_data``); the page's script (``view.js``) rebuilds each frame.
The page fills its window: the plot takes what the controls bar (play, slider, ticks that
never overlap, the time) leaves.  It exposes ``window.mbdynView`` for scripts and tests:
``frames`` (count), ``times``, ``names`` (bodies with a marker), ``goto(i)`` (a promise:
show frame i) and ``positions()`` (the drawn centres of mass).
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from ..errors import ModelError
from ..escape import script_json
from .view_data import view_data

STYLE = """
html, body { margin: 0; height: 100%; overflow: hidden; font: 13px sans-serif; }
body { display: flex; flex-direction: column; }
#mbdyn-plot { flex: 1 1 auto; min-height: 0; }
#mbdyn-bar { flex: 0 0 auto; display: flex; align-items: flex-start; gap: 14px;
             padding: 6px 18px 10px; border-top: 1px solid #ddd; }
#mbdyn-play { width: 64px; padding: 4px 0; }
#mbdyn-track { flex: 1 1 auto; position: relative; min-width: 0; }
#mbdyn-slider { width: 100%; margin: 4px 0 0; }
#mbdyn-ticks { position: relative; height: 16px; color: #555; font-size: 11px; }
.mbdyn-tick { position: absolute; transform: translateX(-50%); white-space: nowrap; }
#mbdyn-time { width: 96px; padding-top: 4px; font-variant-numeric: tabular-nums; }
"""

BODY = """<div id="mbdyn-plot"></div>
<div id="mbdyn-bar"><button id="mbdyn-play" type="button">play</button>
<div id="mbdyn-track"><input id="mbdyn-slider" type="range" min="0" max="0" step="1" value="0"
 aria-label="time"><div id="mbdyn-ticks"></div></div><span id="mbdyn-time"></span></div>
"""


def _eye(up):
    """A camera position off the vertical plane that planar models move in: from z when
    "up" is not z (a model in the x-y plane, gravity along -y), else the usual corner."""
    if abs(up[2]) > 0.9:
        return np.array([1.4, -1.4, 0.9])
    eye = 1.7 * np.array([0.0, 0.0, 1.0]) + 0.5 * up + np.array([0.5, 0.0, 0.0])
    return 2.2 * eye / np.linalg.norm(eye)      # far enough that the cube is not clipped


def _layout(model, data, centre, half):
    from .geometry import up_rotation
    up = up_rotation(model)[2]
    axis = lambda k: {"range": [centre[k] - half, centre[k] + half],  # noqa: E731
                      "title": {"text": "xyz"[k] + " [m]"}}
    return {"title": {"text": data["title"], "x": 0.02, "y": 0.98},
            "scene": {"xaxis": axis(0), "yaxis": axis(1), "zaxis": axis(2),
                      "aspectmode": "cube",
                      "camera": {"up": dict(zip("xyz", up.tolist())),
                                 "eye": dict(zip("xyz", _eye(up).tolist()))}},
            "margin": {"l": 0, "r": 0, "t": 36, "b": 0}, "autosize": True,
            "showlegend": False}


def plotly_js():
    """The plotly.js bundle the plotly package ships."""
    try:
        from plotly.offline import get_plotlyjs
    except ImportError:
        raise ModelError("the HTML view needs plotly (it ships plotly.js inside the file): "
                         "pip install \"mbdyn[viz]\"") from None
    return get_plotlyjs()


def write_html(run, path, fps=30.0, speed=1.0, title=None, trail=90):
    """Write the view of ``run`` (a ``viz.geometry.PosedRun``) to ``path``."""
    library = plotly_js()
    data = view_data(run, title or run.model.name, speed, fps, trail)
    layout = _layout(run.model, data, run.centre, run.half)
    script = (Path(__file__).with_name("view.js")).read_text()
    page = ("<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">\n"
            "<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n"
            "<title>mbdyn view</title>\n<style>" + STYLE + "</style>\n"
            "<script>" + library + "</script>\n</head><body>\n" + BODY
            # script_json: no text in the data can end or alter its <script> element
            + "<script type=\"application/json\" id=\"mbdyn-data\">" + script_json(data)
            + "</script>\n<script type=\"application/json\" id=\"mbdyn-layout\">"
            + script_json(layout) + "</script>\n<script>" + script
            + "</script>\n</body></html>\n")
    Path(path).write_text(page, encoding="utf-8")
