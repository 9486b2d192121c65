"""A self-contained HTML view of a run: orbit, zoom and pan, play/pause, a time slider;
bodies (their shapes), centres of mass and their trails.

Written with plotly, with its bundled plotly.js inside the file (never the "cdn" mode): the
page opens without network access and without a server.  plotly is an optional extra:
``pip install "mbdyn[viz]"``.  The page exposes ``window.mbdynView`` for scripts and tests:
``frames`` (count), ``times``, ``names`` (bodies with a marker), ``goto(i)`` (a promise:
show frame i) and ``positions()`` (the drawn centres of mass).
"""
from __future__ import annotations

import numpy as np

from ..errors import ModelError
from ..escape import markup, script_json

LINK = "#444444"


def _polyline_trace(go, segments, colour, width, name, decimals=6):
    xs, ys, zs = [], [], []
    for pts in segments:
        pts = np.round(pts, decimals)
        xs += list(pts[:, 0]) + [None]
        ys += list(pts[:, 1]) + [None]
        zs += list(pts[:, 2]) + [None]
    return go.Scatter3d(x=xs, y=ys, z=zs, mode="lines", name=name, hoverinfo="skip",
                        line={"color": colour, "width": width * 2}, showlegend=False)


def _traces(go, scene, colours, marker_names, decimals=6):
    """The traces of one frame: a polyline trace per colour, the trails, the centres of
    mass (exact: the tests compare them with the results); lines rounded to ``decimals``
    (a ten-thousandth of the scene's size) to keep the file small."""
    out = []
    for colour in colours:
        segs = [pts for pts, c, _ in scene.lines if c == colour]
        width = max([w for _, c, w in scene.lines if c == colour], default=2.0)
        out.append(_polyline_trace(go, segs, colour, width,
                                   "links" if colour == LINK else colour, decimals))
    trails = [tr for tr in scene.trails.values() if len(tr) > 1]
    out.append(_polyline_trace(go, trails, "#aaaaaa", 0.6, "trails", decimals))
    pos = {name: p for name, p, _, _ in scene.markers}
    col = {name: c for name, _, c, _ in scene.markers}
    size = {name: s for name, _, _, s in scene.markers}
    out.append(go.Scatter3d(
        x=[pos[n][0] for n in marker_names], y=[pos[n][1] for n in marker_names],
        z=[pos[n][2] for n in marker_names], mode="markers", name="centres of mass",
        text=[markup(n) for n in marker_names], hovertemplate="%{text}<extra></extra>", showlegend=False,
        marker={"color": [col[n] for n in marker_names],
                "size": [max(size[n] * 0.6, 3) for n in marker_names]}))
    return out


def _eye(up):
    """A camera position off the vertical plane that planar models move in: from z when
    "up" is not z (a model in the x-y plane, gravity along -y), else the usual corner."""
    if abs(up[2]) > 0.9:
        return np.array([1.4, -1.4, 0.9])
    return 1.7 * np.array([0.0, 0.0, 1.0]) + 0.5 * up + np.array([0.5, 0.0, 0.0])


def write_html(model, scenes, path, fps=30.0, speed=1.0, title=None):
    """Write the view of ``scenes`` (``viz.geometry.frames``) to ``path``."""
    try:
        import plotly.graph_objects as go
    except ImportError:
        raise ModelError("the HTML view needs plotly (it ships plotly.js inside the file): "
                         "pip install \"mbdyn[viz]\"") from None
    from .geometry import bounds, up_rotation
    colours = list(dict.fromkeys(c for sc in scenes for _, c, _ in sc.lines))
    marker_names = [name for name, _, _, _ in scenes[0].markers]
    centre, half = bounds(scenes)
    decimals = max(0, int(np.ceil(-np.log10(half))) + 4)
    frames = [go.Frame(data=_traces(go, sc, colours, marker_names, decimals), name=str(k))
              for k, sc in enumerate(scenes)]
    fig = go.Figure(data=_traces(go, scenes[0], colours, marker_names, decimals),
                    frames=frames)
    duration = 1000.0 / fps
    play = {"frame": {"duration": duration, "redraw": True}, "fromcurrent": True,
            "transition": {"duration": 0}, "mode": "immediate"}
    still = {"frame": {"duration": 0, "redraw": True}, "mode": "immediate",
             "transition": {"duration": 0}}
    up = up_rotation(model)[2]
    axis = lambda k: {"range": [centre[k] - half, centre[k] + half],  # noqa: E731
                      "title": "xyz"[k] + " [m]"}
    fig.update_layout(
        title={"text": markup(title or model.name) + (f"  ({speed:g}x)" if speed != 1 else ""),
               "x": 0.02},
        scene={"xaxis": axis(0), "yaxis": axis(1), "zaxis": axis(2), "aspectmode": "cube",
               "camera": {"up": {"x": up[0], "y": up[1], "z": up[2]},
                          "eye": dict(zip("xyz", _eye(up).tolist()))}},
        margin={"l": 0, "r": 0, "t": 40, "b": 0}, height=640,
        updatemenus=[{"type": "buttons", "x": 0.02, "y": 0.02, "xanchor": "left",
                      "buttons": [{"label": "play", "method": "animate",
                                   "args": [None, play]},
                                  {"label": "pause", "method": "animate",
                                   "args": [[None], still]}]}],
        sliders=[{"x": 0.15, "len": 0.8, "y": 0.02, "currentvalue": {"prefix": "t = "},
                  "steps": [{"label": f"{sc.t:.3f} s", "method": "animate",
                             "args": [[str(k)], still]} for k, sc in enumerate(scenes)]}])
    marker_trace = len(colours) + 1
    meta = {"frames": len(scenes), "times": [sc.t for sc in scenes], "names": marker_names,
            "markerTrace": marker_trace}
    post = ("(function(){var gd=document.getElementById('{plot_id}');"
            "var meta=" + script_json(meta).replace("{plot_id}", "\\u007bplot_id}") + ";"
            "window.mbdynView={frames:meta.frames,times:meta.times,names:meta.names,"
            "goto:function(i){return Plotly.animate(gd,[String(i)],{mode:'immediate',"
            "frame:{duration:0,redraw:true},transition:{duration:0}});},"
            "positions:function(){var t=gd.data[meta.markerTrace];"
            "return t.x.map(function(x,k){return [x,t.y[k],t.z[k]];});}};})();")
    # plotly writes the page's texts as escaped JSON; ``post`` is ours: its data go through
    # script_json, and a name holding plotly's own placeholder "{plot_id}" (only ever inside
    # a JSON string there) is written with its brace escaped so plotly leaves it alone
    fig.write_html(path, include_plotlyjs=True, full_html=True, auto_play=False,
                   post_script=post)
