"""Pictures of a sweep's table: a line over one grid axis, a heat map over two
(matplotlib, Agg: no display)."""
from __future__ import annotations

import numpy as np

from .. import files
from ..errors import ModelError
from ..escape import mathtext

FORMATS = (".png", ".pdf", ".svg")


def _axis(values):
    """Numeric positions and tick labels of one grid axis (its distinct values in order)."""
    distinct = list(dict.fromkeys(values))
    try:
        distinct.sort(key=float)
        pos = np.array([float(v) for v in distinct])
        return distinct, pos, None
    except (TypeError, ValueError):
        return distinct, np.arange(len(distinct), dtype=float), [mathtext(v) for v in distinct]


def plot_sweep(result, quantity, path, axes=None, title=None, ax=None):
    """Plot column ``quantity`` of a ``SweepResult`` over its grid ``axes`` (the override
    paths; default all): one axis a line, two a heat map (NaN cells -- no event, a failed
    member -- left blank).  Writes ``path`` (.png, .pdf, .svg; checked first) unless ``ax``
    is given; returns the matplotlib figure.  ``quantity`` is a column name or a quantity
    as ``sweep`` takes it (``"absmax:theta"`` for the column ``absmax.theta``)."""
    from ..analysis.sweeps.quantities import column_of
    if ax is None:
        files.check_target(path, FORMATS, "picture")
    if quantity not in result.columns:
        quantity = column_of(quantity)
    if quantity not in result.columns:
        raise ModelError(f"--plot {quantity}: not a column of the table; the columns are: "
                         + ", ".join(result.columns))
    axes = list(axes or [c for c in result.columns if "." in c and c.split(".")[0] in (
        "parameters", "initial", "initial_speeds", "simulation", "bodies", "joints", "loads")])
    if len(axes) not in (1, 2):
        raise ModelError(f"--plot: the sweep has {len(axes)} grid axes; a plot shows one "
                         "(a line) or two (a heat map)")
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    rows = result.rows
    z = np.array([r[quantity] if isinstance(r[quantity], float) else np.nan for r in rows])
    fig = None
    if ax is None:
        fig, ax = plt.subplots(figsize=(6.4, 4.8), dpi=100)
    if len(axes) == 1:
        xs, pos, labels = _axis([r[axes[0]] for r in rows])
        index = {v: k for k, v in enumerate(xs)}
        x = np.array([pos[index[r[axes[0]]]] for r in rows])
        order = np.argsort(x, kind="stable")
        ax.plot(x[order], z[order], "o-")
        ax.set_xlabel(mathtext(axes[0]))
        ax.set_ylabel(mathtext(quantity))
        if labels:
            ax.set_xticks(pos, labels)
        ax.grid(True, alpha=0.3)
    else:
        xs, xpos, xl = _axis([r[axes[0]] for r in rows])
        ys, ypos, yl = _axis([r[axes[1]] for r in rows])
        grid = np.full((len(ys), len(xs)), np.nan)
        xi = {v: k for k, v in enumerate(xs)}
        yi = {v: k for k, v in enumerate(ys)}
        for r, val in zip(rows, z):
            grid[yi[r[axes[1]]], xi[r[axes[0]]]] = val
        mesh = ax.pcolormesh(_edges(xpos), _edges(ypos), np.ma.masked_invalid(grid),
                             shading="flat", cmap="viridis")
        (ax.figure.colorbar(mesh, ax=ax)).set_label(mathtext(quantity))
        ax.set_xlabel(mathtext(axes[0]))
        ax.set_ylabel(mathtext(axes[1]))
        if xl:
            ax.set_xticks(xpos, xl)
        if yl:
            ax.set_yticks(ypos, yl)
    ax.set_title(mathtext(title or quantity))
    if fig is not None:
        fig.tight_layout()
        with files.replacing(path) as tmp:      # a link at ``path`` is replaced
            fig.savefig(tmp)
        plt.close(fig)
    return ax.figure


def _edges(centres):
    """Cell edges around increasing centres (halfway between neighbours)."""
    s = np.asarray(centres, float)
    if len(s) == 1:
        return np.array([s[0] - 0.5, s[0] + 0.5])
    mid = 0.5 * (s[1:] + s[:-1])
    return np.concatenate([[s[0] - (mid[0] - s[0])], mid, [s[-1] + (s[-1] - mid[-1])]])
