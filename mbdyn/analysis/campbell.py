"""Campbell diagrams: modes against a parameter (a rotor's spin speed), tracked by shape.

At each value the equilibrium is found again (warm-started from the previous one), the
model linearised and its modes computed.  Modes are followed from one value to the next by
their shapes -- the modal assurance criterion ``MAC = |a^H b|^2 / (|a|^2 |b|^2)``, matched
by the assignment that maximises the total MAC -- not by sorting frequencies, which swaps
the labels of two modes where their frequencies cross.  Reported: each tracked mode's
frequency, damping and whirl against the parameter; the critical speeds, where a mode's
frequency meets an ``n x`` spin line (``n`` in ``orders``); and the onset of instability,
where a mode's real part crosses zero.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..errors import ModelError
from ..escape import mathtext
from . import arguments
from .equilibrium import EquilibriumError, equilibrium
from .linearize import linearize
from .modes import modes as compute_modes


def mac(a, b):
    """Modal assurance criterion of two complex shapes (1: the same shape)."""
    num = abs(np.vdot(a, b)) ** 2
    den = np.vdot(a, a).real * np.vdot(b, b).real
    return float(num / den) if den > 0 else 0.0


#: a crossing of a spin line by a mode damped above this ratio is no critical speed: its
#: amplification factor ``1 / (2 zeta)`` is below 2.5, API 684's "critically damped"
#: (such crossings are listed apart, ``Campbell.damped``)
CRITICALLY_DAMPED = 0.2
#: the damping ratios the Campbell diagram's colour scale spans (beyond: its end colours);
#: its neutral colour is at zeta = 0
ZETA_RANGE = (-0.2, 0.5)


@dataclass
class Campbell:
    """``values`` of ``parameter``; per tracked mode (columns) the damped frequency
    ``frequency`` (rad/s), ``real_part``, ``damping_ratio`` and ``whirl``; ``mac`` the
    shape correlation of each step; ``critical`` ``[(mode, order, value)]``; ``onset``
    ``[(mode, value)]``; ``damped`` ``[(mode, order, value, zeta)]``: crossings of modes
    damped above ``CRITICALLY_DAMPED``, which are not critical speeds."""
    parameter: str
    values: np.ndarray
    frequency: np.ndarray
    real_part: np.ndarray
    damping_ratio: np.ndarray
    whirl: list
    mac: np.ndarray
    critical: list = field(default_factory=list)
    onset: list = field(default_factory=list)
    spin_is_parameter: bool = True
    damped: list = field(default_factory=list)

    def to_dict(self):
        return {"parameter": self.parameter, "values": self.values.tolist(),
                "modes": [{"frequency": self.frequency[:, k].tolist(),
                           "real_part": self.real_part[:, k].tolist(),
                           "damping_ratio": self.damping_ratio[:, k].tolist(),
                           "whirl": [w[k] for w in self.whirl]}
                          for k in range(self.frequency.shape[1])],
                "tracking_mac_min": float(self.mac.min()) if self.mac.size else 1.0,
                "critical_speeds": [{"mode": m + 1, "order": o, "value": v}
                                    for m, o, v in self.critical],
                "instability_onset": [{"mode": m + 1, "value": v} for m, v in self.onset],
                "critically_damped_crossings": [{"mode": m + 1, "order": o, "value": v,
                                                 "damping_ratio": z}
                                                for m, o, v, z in self.damped]}

    def table(self):
        n = self.frequency.shape[1]
        head = f"{self.parameter:>12} " + " ".join(f"{'mode ' + str(k + 1):>14}"
                                                   for k in range(n))
        lines = [head + "   (damped frequency rad/s, whirl F/B, * unstable)"]
        for i, v in enumerate(self.values):
            cells = []
            for k in range(n):
                w = self.whirl[i][k]
                mark = ("F" if w == "forward" else "B" if w == "backward" else " ")
                star = "*" if self.real_part[i, k] > 0 else " "
                cells.append(f"{self.frequency[i, k]:>12.5g}{mark}{star}")
            lines.append(f"{v:>12.6g} " + " ".join(cells))
        for m, o, v in self.critical:
            lines.append(f"critical speed: mode {m + 1} meets the {o}x line at "
                         f"{self.parameter} = {v:.6g}")
        for m, o, v, z in self.damped:
            lines.append(f"mode {m + 1} meets the {o}x line at {self.parameter} = {v:.6g} "
                         f"critically damped (zeta {z:.3g} > {CRITICALLY_DAMPED}): no "
                         "critical speed")
        for m, v in self.onset:
            lines.append(f"onset of instability: mode {m + 1} at {self.parameter} = {v:.6g}")
        if not self.onset:
            lines.append("no instability in the range")
        return "\n".join(lines)

    def plot(self, path=None, orders=(1,)):
        """Frequency against the parameter: whirl by marker (^ forward, v backward),
        damping ratio by colour (white at zeta = 0, red unstable, blue damped; the scale
        ``ZETA_RANGE``), the spin lines; saved to ``path`` (.png, .pdf, .svg) when given,
        whole or not at all."""
        from ..files import check_target
        if path is not None:
            check_target(path, (".png", ".pdf", ".svg"), "picture")
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        from matplotlib.colors import TwoSlopeNorm
        fig, ax = plt.subplots(figsize=(7, 4.5))
        zeta = np.clip(self.damping_ratio, ZETA_RANGE[0], ZETA_RANGE[1])
        # neutral (white) at zeta = 0, the stability margin: red below, blue above
        norm = TwoSlopeNorm(vmin=ZETA_RANGE[0], vcenter=0.0, vmax=ZETA_RANGE[1])
        for k in range(self.frequency.shape[1]):
            f = np.where(self.frequency[:, k] > 0, self.frequency[:, k], np.nan)
            ax.plot(self.values, f, "-", color="0.75", lw=1, zorder=1)
            for marker, tag in (("^", "forward"), ("v", "backward"), ("o", None)):
                sel = np.array([w[k] == tag for w in self.whirl]) & (self.frequency[:, k] > 0)
                if sel.any():
                    sc = ax.scatter(self.values[sel], self.frequency[sel, k], c=zeta[sel, k],
                                    cmap="coolwarm_r", norm=norm, marker=marker,
                                    s=22, zorder=2, edgecolors="k", linewidths=0.3)
        if self.spin_is_parameter:
            for o in orders:
                ax.plot(self.values, o * self.values, "k--", lw=0.8, label=f"{o}x spin")
        for m, o, v in self.critical:
            ax.axvline(v, color="tab:orange", lw=0.8, ls=":")
        for m, v in self.onset:
            ax.axvline(v, color="tab:red", lw=1.2, label=f"instability onset ({v:.4g})")
        ax.set_xlabel(mathtext(self.parameter))
        ax.set_ylabel("damped natural frequency [rad/s]")
        ax.set_ylim(bottom=0)
        ax.set_title("Campbell diagram (^ forward, v backward whirl; colour: damping ratio)",
                     fontsize=9)
        try:
            fig.colorbar(sc, ax=ax, label="damping ratio")
        except NameError:
            pass
        if ax.get_legend_handles_labels()[0]:
            ax.legend(fontsize=8, loc="upper left")
        fig.tight_layout()
        if path is not None:
            from ..files import replacing
            with replacing(path) as tmp:        # a link at ``path`` is replaced
                fig.savefig(tmp, dpi=120)
            plt.close(fig)
        return fig


def _crossings(x, y):
    """Values of ``x`` where the samples ``y`` change sign (linear interpolation)."""
    out = []
    for i in range(len(x) - 1):
        if y[i] == 0:
            out.append(float(x[i]))
        elif y[i] * y[i + 1] < 0:
            out.append(float(x[i] - y[i] * (x[i + 1] - x[i]) / (y[i + 1] - y[i])))
    return out


def _onsets(x, real, freq):
    """Values of ``x`` where a real part turns from negative to positive (an onset of
    instability).  A real part within round-off of zero (an undamped mode: exactly 0, or
    1e-12 of its frequency) is neutral: it is no onset, and neither is staying at zero."""
    tol = 1e-9 * (np.abs(freq) + 1e-12)
    sign = np.where(np.abs(real) <= tol, 0, np.sign(real))
    out, last = [], None                      # the last sample with a definite sign
    for i in range(len(x)):
        if sign[i] == 0:
            continue
        if last is not None and sign[last] < 0 < sign[i]:
            out.append(float(x[last] - real[last] * (x[i] - x[last]) / (real[i] - real[last])))
        last = i
    return out


def _builder(scene, parameter):
    """``value -> (model, q0, u0)``: a model file's scene rebuilt with the parameter set,
    or a user's function of the value returning a ``Model`` (or a scene)."""
    if hasattr(scene, "rebuild"):
        if parameter not in scene.parameters:
            raise ModelError(f"campbell: {parameter!r} is not a parameter of {scene.path}; "
                             f"its parameters are {', '.join(scene.parameters) or '(none)'}")

        def build(v):
            sc = scene.rebuild({f"parameters.{parameter}": float(v)})
            return sc.model, sc.q0, sc.u0
        return build
    if callable(scene):
        from ..compiled.model import Model

        def build(v):
            out = scene(float(v))
            if isinstance(getattr(out, "model", None), Model):
                return out.model, out.q0, out.u0
            if not isinstance(out, Model):
                raise ModelError(f"campbell: the function of {parameter} returned "
                                 f"{type(out).__name__} at {parameter} = {v:g}; it must "
                                 "return a compiled Model (System.compile()) or a scene")
            return out, out.default_coordinates(), np.zeros(out.nu)
        return build
    raise ModelError("campbell: give a scene (mb.load_model) or a function of the parameter "
                     "value that returns a compiled Model")


def campbell(scene, parameter, values, orders=(1,), whirl=(), at="equilibrium",
             fixed=(), spin_is_parameter=True, progress=None):
    """Modes against ``parameter`` over ``values``; see the module docstring.

    ``scene``: a model file's scene (``parameter`` is a name in its ``[parameters]``; the
    scene's case, overrides and effects are kept) or a function ``value -> Model``.
    ``at``: ``"equilibrium"`` (found again at each value, warm-started) or ``"initial"``
    (the scene's initial configuration).  ``whirl``: lateral coordinate pairs (see
    ``analysis.modes``); ``orders``: the spin lines ``n x`` for critical speeds.
    ``progress``: a callable ``progress(done, total)`` called after each value (``mbdyn
    campbell`` passes ``cli.common.Estimate``: the time the diagram will take, on stderr).
    """
    orders, whirl, fixed = _checked(parameter, orders, whirl, at, fixed, progress)
    build = _builder(scene, parameter)
    values = _values(values)
    rows = _modes_at_each(build, parameter, values, whirl, at, fixed, spin_is_parameter,
                          progress)
    order, macs = _track(rows)
    freq, real, zeta, whirls = _tracked(rows, order)
    critical, onset, damped = _crossings_of(values, freq, real, zeta, orders,
                                            spin_is_parameter)
    return Campbell(parameter, values, freq, real, zeta, whirls, np.array(macs),
                    critical, onset, spin_is_parameter, damped)


def _checked(parameter, orders, whirl, at, fixed, progress):
    """``orders``, ``whirl`` and ``fixed`` checked (``at``, ``parameter`` and ``progress``
    too)."""
    if not isinstance(at, str) or at not in ("equilibrium", "initial"):
        raise ModelError(f"campbell: at must be 'equilibrium' or 'initial', got {at!r}")
    if not isinstance(parameter, str):
        raise ModelError(f"campbell: parameter must be a name, got {parameter!r}")
    if not isinstance(orders, (list, tuple)):
        raise ModelError(f"campbell: orders must be a list of whole numbers >= 1, e.g. "
                         f"(1, 2), got {orders!r}")
    orders = [arguments.count(o, "campbell", "each of orders") for o in orders]
    whirl = arguments.pairs(whirl, "campbell", "whirl")
    fixed = arguments.names(fixed, "campbell", "fixed")
    if progress is not None and not callable(progress):
        raise ModelError(f"campbell: progress must be a function (done, total), got "
                         f"{progress!r}")
    return orders, whirl, fixed


def _values(values):
    """The parameter values as a finite 1-D array of two or more."""
    try:
        values = np.asarray(values, dtype=float)
    except (TypeError, ValueError):
        raise ModelError(f"campbell: values must be numbers, got {values!r}") from None
    if values.ndim != 1 or len(values) < 2 or not np.all(np.isfinite(values)):
        raise ModelError("campbell: give at least two finite parameter values")
    return values


def _modes_at_each(build, parameter, values, whirl, at, fixed, spin_is_parameter, progress):
    """The ``Modes`` at each value: the model built, its equilibrium found (warm-started
    from the previous value's) or its initial configuration, linearised."""
    guess = None
    rows = []
    for i, v in enumerate(values):
        model, q0, _ = build(v)
        q = q0 if guess is None or at == "initial" else guess
        if at == "equilibrium":
            try:
                eq = equilibrium(model, q, np.zeros(model.nu), fixed=fixed)
            except EquilibriumError as exc:
                raise ModelError(f"campbell: at {parameter} = {v:g}: {exc}") from None
            q = eq.q
        lin = linearize(model, q, np.zeros(model.nu))
        guess = q
        sign = np.sign(v) if spin_is_parameter and v != 0 else 1.0
        rows.append(compute_modes(lin, whirl=whirl, spin=sign))
        if progress is not None:
            progress(i + 1, len(values))
    return rows


def _track(rows):
    """``order``: for each value, the indices of its modes in the order of the first
    value's (assigned to those of the previous value by MAC); ``macs``: the MAC of each
    assignment."""
    from scipy.optimize import linear_sum_assignment
    n = min(len(r.modes) for r in rows)
    order = [list(range(n))]
    macs = []
    for i in range(1, len(rows)):
        prev = [rows[i - 1].modes[j] for j in order[-1]]
        cur = rows[i].modes
        score = np.array([[mac(p.shape, c.shape) for c in cur[:max(n, len(cur))]]
                          for p in prev])
        # add a small frequency-proximity term to break ties between equal shapes
        fp = np.array([[p.damped_frequency for _ in cur[:score.shape[1]]] for p in prev])
        fc = np.array([[c.damped_frequency for c in cur[:score.shape[1]]] for _ in prev])
        cost = -(score - 1e-3 * np.abs(fp - fc) / (np.abs(fp) + np.abs(fc) + 1e-300))
        r_, c_ = linear_sum_assignment(cost)
        assigned = [int(c) for _, c in sorted(zip(r_, c_))]
        order.append(assigned)
        macs.append([score[a, b] for a, b in zip(range(n), assigned)])
    return order, macs


def _tracked(rows, order):
    """Damped frequency, real part, damping ratio (arrays: value x tracked mode) and
    whirl (lists) of the tracked modes."""
    freq = np.array([[rows[i].modes[j].damped_frequency for j in order[i]]
                     for i in range(len(rows))])
    real = np.array([[rows[i].modes[j].eigenvalue.real for j in order[i]]
                     for i in range(len(rows))])
    zeta = np.array([[rows[i].modes[j].damping_ratio for j in order[i]]
                     for i in range(len(rows))])
    whirls = [[rows[i].modes[j].whirl for j in order[i]] for i in range(len(rows))]
    return freq, real, zeta, whirls


def _crossings_of(values, freq, real, zeta, orders, spin_is_parameter):
    """``critical``: ``(mode, order, value)`` where a mode's frequency meets a spin line
    (where it oscillates on both sides) damped at most ``CRITICALLY_DAMPED`` there (the
    ratio interpolated linearly); ``onset``: ``(mode, value)`` where its real part crosses
    zero; ``damped``: ``(mode, order, value, zeta)``, the crossings of modes damped more;
    each sorted by value."""
    critical, onset, damped = [], [], []
    for k in range(freq.shape[1]):
        if spin_is_parameter:
            oscillating = freq[:, k] > 0
            for o in orders:
                gap = freq[:, k] - o * np.abs(values)
                for i in range(len(values) - 1):     # only where the mode oscillates
                    if not (oscillating[i] and oscillating[i + 1]):
                        continue
                    for v in _crossings(values[i:i + 2], gap[i:i + 2]):
                        x0, x1, z0, z1 = values[i], values[i + 1], zeta[i, k], zeta[i + 1, k]
                        z = float(z0 + (z1 - z0) * (v - x0) / (x1 - x0) if x1 != x0 else z0)
                        if z > CRITICALLY_DAMPED:
                            damped.append((k, o, v, z))
                        else:
                            critical.append((k, o, v))
        for v in _onsets(values, real[:, k], freq[:, k]):
            onset.append((k, v))
    critical.sort(key=lambda c: c[2])
    onset.sort(key=lambda c: c[1])
    damped.sort(key=lambda c: c[2])
    return critical, onset, damped
