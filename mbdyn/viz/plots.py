"""Time series and phase portraits of a ``Result``.

Series are named as the columns of ``mbdyn run --out``'s CSV: a coordinate or speed
(``theta1``, ``theta1_dot``), ``energy_kinetic`` ... ``energy_balance``,
``reaction_JOINT_Fx`` ... ``_Mz``, ``effort_JOINT``, ``point_NAME_x`` ...; a group's prefix
(``energy``, ``reaction_JOINT``, ``point_NAME``) stands for all its columns.  Each series
is labelled with its unit; series share an axis when they have one unit and peaks within
a factor of 20 of each other (``group_series``); event times are marked.
"""
from __future__ import annotations

import numpy as np

from .. import files
from ..errors import ModelError
from ..escape import legend_label, mathtext

FORMATS = (".png", ".pdf", ".svg")
SERIES_HELP = ("coordinates, speeds, energy_* (kinetic, potential, total, dissipated, work, "
               "balance), reaction_JOINT_Fx..Mz, effort_JOINT, point_NAME_x/_y/_z, or a "
               "group prefix: energy, reaction_JOINT, point_NAME")


def _units(model):
    """``{series name: unit}`` of the coordinates and speeds."""
    out = {}
    for j in model.elements[1]:
        if j.drive is not None or not j.nu:
            continue
        if j.kind == "prismatic":
            q_units, u_units = ["m"], ["m/s"]
        elif j.kind == "revolute" or j.kind == "euler":
            q_units, u_units = ["rad"] * j.nq, ["rad/s"] * j.nu
        elif j.kind == "spherical":
            q_units, u_units = ["-"] * 4, ["rad/s"] * 3
        else:   # free
            q_units, u_units = ["m"] * 3 + ["-"] * 4, ["m/s"] * 3 + ["rad/s"] * 3
        out.update(zip(j.coordinates, q_units))
        out.update(zip(j.speeds, u_units))
    return out


def series_table(result):
    """``{name: (values (n,), unit, label)}`` of everything a result holds."""
    model = result.model
    units = _units(model)
    table = {}
    for k, n in enumerate(model.coordinates):
        table[n] = (result.q[:, k], units.get(n, "-"), n)
    for k, n in enumerate(model.speeds):
        table[n] = (result.u[:, k], units.get(n, "-"), n)
    if result.energy is not None:
        for key, arr in result.energy.items():
            table[f"energy_{key}"] = (np.asarray(arr), "J", f"energy {key}")
    if result.reactions is not None:
        for j, arr in result.reactions.items():
            for c, comp in enumerate(("Fx", "Fy", "Fz", "Mx", "My", "Mz")):
                table[f"reaction_{j}_{comp}"] = (np.asarray(arr)[:, c],
                                                 "N" if comp[0] == "F" else "N m",
                                                 f"reaction {j} {comp}")
    if result.drive_efforts:
        for j, arr in result.drive_efforts.items():
            kind = model.joint(j).kind
            table[f"effort_{j}"] = (np.asarray(arr), "N m" if kind == "revolute" else "N",
                                    f"drive effort {j}")
    if result.points:
        for p, arr in result.points.items():
            for c, axis in enumerate("xyz"):
                table[f"point_{p}_{axis}"] = (np.asarray(arr)[:, c], "m", f"{p} {axis}")
    return table


#: signals of one unit whose largest magnitudes differ more than this share no axis
SCALE_RATIO = 20.0


def group_series(table, names, ratio=SCALE_RATIO):
    """The axes of a time plot: ``[(unit, [names])]``, one group per unit (in the order the
    units first appear), each split by magnitude so that within a group the largest peak
    ``max |x|`` is at most ``ratio`` times the smallest (signals that stay zero join the
    first group of their unit)."""
    by_unit = {}
    for n in names:
        by_unit.setdefault(table[n][1], []).append(n)
    out = []
    for unit, group in by_unit.items():
        peak = {n: float(np.nanmax(np.abs(table[n][0]))) if len(table[n][0]) else 0.0
                for n in group}
        peak = {n: (p if np.isfinite(p) else 0.0) for n, p in peak.items()}
        zero = [n for n in group if peak[n] == 0.0]
        split = []
        for n in sorted((n for n in group if peak[n] > 0.0), key=lambda n: -peak[n]):
            if split and peak[split[-1][0]] <= ratio * peak[n]:
                split[-1].append(n)
            else:
                split.append([n])
        split = split or [[]]
        split[0] += zero
        order = {n: k for k, n in enumerate(group)}           # the order asked for
        out += [(unit, sorted(g, key=order.get)) for g in split]
    return out


def _names(value, what):
    """Series names from ``"a,b"`` or a list of names; anything else is refused."""
    if isinstance(value, str):
        return [s.strip() for s in value.split(",") if s.strip()]
    if isinstance(value, (list, tuple)) and all(isinstance(s, str) for s in value):
        return [s.strip() for s in value]
    raise ModelError(f"{what} must be series names, \"a,b\" or a list of names (e.g. "
                     f"theta1,theta1_dot), got {value!r}")


def _expand(names, table):
    out = []
    for name in names:
        if name in table:
            out.append(name)
            continue
        group = [k for k in table if k.startswith(name + "_")]
        if not group:
            raise ModelError(f"unknown series {name!r}; this result has: "
                             f"{', '.join(table)} (or a group: energy, reaction_JOINT, "
                             "point_NAME)")
        out.extend(group)
    return out


def _check_path(path, formats=FORMATS, what="picture"):
    """The extension of an output path, checked before any work: a known format, an
    existing, writable directory, not a folder itself (``files.check_target``)."""
    return files.check_target(path, formats, what)


def _save(fig, path):
    """Write via a temporary file in the same directory and rename: no partial file, and
    a symbolic link at ``path`` replaced, never written through (``files.replacing``)."""
    with files.replacing(path) as tmp:
        fig.savefig(tmp, dpi=110)


def plot_result(result, series=None, phase=None, out=None, title=None):
    """Plot ``series`` (names or group prefixes; default: the coordinates, and the energy
    balance when the result has one) against time, one axis per unit and scale
    (``group_series``), event times marked;
    or, with ``phase=(X, Y)``, a phase portrait of two series.  Saves to ``out`` (.png, .pdf,
    .svg) when given; returns the matplotlib figure."""
    if out is not None:
        _check_path(out)
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        raise ModelError("pictures need matplotlib: pip install \"mbdyn[plot]\"") from None
    table = series_table(result)
    title = title or result.model.name
    if phase is not None:
        phase = _names(phase, "phase")
        if len(phase) != 2:
            raise ModelError(f"phase {phase!r}: give two series, e.g. theta1,theta1_dot")
        for p in phase:
            if p not in table:
                raise ModelError(f"unknown series {p!r}; this result has: {', '.join(table)}")
        (x, ux, lx), (y, uy, ly) = table[phase[0]], table[phase[1]]
        fig, ax = plt.subplots(figsize=(5.5, 5))
        ax.plot(x, y, lw=1)
        ax.plot(x[0], y[0], "o", color="tab:green", label=f"t = {result.t[0]:g} s")
        ax.plot(x[-1], y[-1], "s", color="tab:red", label=f"t = {result.t[-1]:g} s")
        ax.set_xlabel(mathtext(f"{lx} [{ux}]"))
        ax.set_ylabel(mathtext(f"{ly} [{uy}]"))
        ax.set_title(mathtext(f"{title}: phase portrait"), fontsize=10)
        ax.legend(fontsize=8)
    else:
        if series is None:
            series = list(result.model.coordinates)
            if result.energy is not None:
                series += ["energy_kinetic", "energy_potential", "energy_balance"]
        else:
            series = _names(series, "series")
        names = _expand(series, table)
        if not names:
            raise ModelError("nothing to plot: give series names")
        groups = group_series(table, names)
        fig, axes = plt.subplots(len(groups), 1, sharex=True,
                                 figsize=(7.5, 2.2 + 1.6 * len(groups)), squeeze=False)
        for ax, (unit, group) in zip(axes[:, 0], groups):
            for n in group:
                ax.plot(result.t, table[n][0], lw=1.2, label=legend_label(table[n][2]))
            ax.set_ylabel(f"[{unit}]")
            ax.legend(fontsize=8, loc="best")
            ax.grid(alpha=0.3)
            for name, t in result.events:
                ax.axvline(t, color="tab:red", lw=0.8, ls="--")
        for name, t in result.events:
            axes[0, 0].annotate(mathtext(name), (t, 1.0), xycoords=("data", "axes fraction"),
                                fontsize=8, color="tab:red", ha="right", va="bottom",
                                rotation=90)
        axes[-1, 0].set_xlabel("time t [s]")
        axes[0, 0].set_title(mathtext(title), fontsize=10)
    fig.tight_layout()
    if out is not None:
        _save(fig, out)
        plt.close(fig)
    return fig
