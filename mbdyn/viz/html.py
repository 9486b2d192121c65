"""A self-contained HTML view of a run: orbit, zoom and pan, play/pause, a time slider;
bodies as shaded solids, springs, dampers, ground planes, actuators, centres of mass and
their trails, world axes.

The page is the run's data and a small viewer of our own in plain JavaScript (no library:
``view_gl.js`` draws with WebGL, ``view_2d.js`` on a 2D canvas when the browser has no
WebGL, ``view.js`` builds each frame and runs the camera and the controls); it opens
without network access and without a server.  The run is sent as each solid's mesh once
and every frame's poses (``viz.view_data``).  The page fills its window: the view takes
what the controls bar (play, the slider with ticks that never overlap, the time, "reset
view") leaves.  It exposes ``window.mbdynView`` for scripts and tests: ``frames``
(count), ``times``, ``names`` (bodies with a marker), ``goto(i)`` (a promise: show frame
i), ``positions()`` (the drawn centres of mass), ``project(p)`` (a world point's CSS pixels
in the canvas) and ``renderer`` (``"webgl"`` or ``"2d"``).
"""
from __future__ import annotations

from pathlib import Path

from ..escape import script_json
from .view_data import view_data

#: the viewer's scripts, in the order the page runs them (view.js last: it starts the view)
SCRIPTS = ("view_gl.js", "view_2d.js", "view.js")

STYLE = """
html, body { margin: 0; height: 100%; overflow: hidden; font: 13px sans-serif; }
body { display: flex; flex-direction: column; }
#mbdyn-plot { flex: 1 1 auto; min-height: 0; position: relative; overflow: hidden; }
#mbdyn-canvas { position: absolute; left: 0; top: 0; width: 100%; height: 100%;
                display: block; touch-action: none; cursor: grab; }
#mbdyn-labels { position: absolute; left: 0; top: 0; width: 100%; height: 100%;
                pointer-events: none; }
.mbdyn-label, .mbdyn-axis, #mbdyn-tip { position: absolute; left: 0; top: 0;
                white-space: pre; }
.mbdyn-label { font-size: 12px; color: #333; background: rgba(255, 255, 255, 0.6); }
.mbdyn-axis { font-weight: bold; }
#mbdyn-tip { visibility: hidden; background: #ffffe8; border: 1px solid #999;
             padding: 1px 4px; }
#mbdyn-title { position: absolute; left: 18px; top: 8px; font-size: 16px; color: #222;
               pointer-events: none; white-space: pre; }
#mbdyn-scale, #mbdyn-hint { position: absolute; bottom: 6px; font-size: 11px; color: #777;
                            pointer-events: none; }
#mbdyn-scale { left: 18px; }
#mbdyn-hint { right: 18px; }
#mbdyn-bar { flex: 0 0 auto; display: flex; align-items: flex-start; gap: 14px;
             padding: 6px 18px 10px; border-top: 1px solid #ddd; }
#mbdyn-play { width: 64px; padding: 4px 0; }
#mbdyn-reset { padding: 4px 8px; }
#mbdyn-track { flex: 1 1 auto; position: relative; min-width: 0; }
#mbdyn-slider { width: 100%; margin: 4px 0 0; }
#mbdyn-ticks { position: relative; height: 16px; color: #555; font-size: 11px; }
.mbdyn-tick { position: absolute; transform: translateX(-50%); white-space: nowrap; }
#mbdyn-time { width: 96px; padding-top: 4px; font-variant-numeric: tabular-nums; }
"""

BODY = """<div id="mbdyn-plot"><canvas id="mbdyn-canvas"></canvas><div id="mbdyn-labels">
<span id="mbdyn-tip"></span></div><div id="mbdyn-title"></div><div id="mbdyn-scale"></div>
<div id="mbdyn-hint">drag: orbit &middot; shift-drag or right-drag: pan &middot; wheel: zoom
&middot; double-click: reset</div></div>
<div id="mbdyn-bar"><button id="mbdyn-play" type="button">play</button>
<div id="mbdyn-track"><input id="mbdyn-slider" type="range" min="0" max="0" step="1" value="0"
 aria-label="time"><div id="mbdyn-ticks"></div></div><span id="mbdyn-time"></span>
<button id="mbdyn-reset" type="button">reset view</button></div>
"""


def viewer_script():
    """The viewer: its scripts in one function scope (nothing global but ``mbdynView``)."""
    here = Path(__file__).parent
    return ("(function () {\n\"use strict\";\n"
            + "".join((here / name).read_text(encoding="utf-8") for name in SCRIPTS)
            + "})();\n")


def write_html(run, path, fps=30.0, speed=1.0, title=None, trail=90):
    """Write the view of ``run`` (a ``viz.geometry.PosedRun``) to ``path``."""
    data = view_data(run, title or run.model.name, speed, fps, trail)
    page = ("<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">\n"
            "<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n"
            "<title>mbdyn view</title>\n<style>" + STYLE + "</style>\n</head><body>\n" + BODY
            # script_json: no text in the data can end or alter its <script> element
            + "<script type=\"application/json\" id=\"mbdyn-data\">" + script_json(data)
            + "</script>\n<script>" + viewer_script() + "</script>\n</body></html>\n")
    Path(path).write_text(page, encoding="utf-8")
