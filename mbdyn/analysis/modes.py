"""Modes of a linearised model: eigenvalues, frequencies, damping, shapes, stability, whirl.

The eigenvalues ``s = sigma +/- i w_d`` of the state matrix ``A`` (on ``[x, x']``) give the
damped frequency ``w_d``, the undamped (natural) frequency ``w_n = |s|``, the damping
ratio ``zeta = -sigma / w_n`` and the logarithmic decrement ``delta = -2 pi sigma / w_d``
(the log of the ratio of successive peaks of a free response).  A mode is listed once per
complex-conjugate pair (``w_d > 0``); real eigenvalues (overdamped or divergent motions)
are listed with ``w_d = 0``.  Zero eigenvalues are rigid-body modes (a coordinate the model
does not restrain) and are flagged ``rigid``.  The model is stable when every real part is
negative (``stability`` says which mode is not).

A closed mechanism's linearisation is in independent coordinates (``lin.names``); each
mode also carries ``motion``, the shape over every coordinate (``lin.coordinates``: the
dependent ones follow through ``lin.basis``), scaled as ``shape``.

Whirl: for a rotor, give the pairs of lateral coordinates ``(y, z)`` that span planes
across the spin axis, with ``y x z`` along the spin: a mode whirls *forward* when its orbit
turns the same way as the spin, *backward* otherwise.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import ModelError
from . import arguments


@dataclass
class Mode:
    """One mode; ``shape`` is complex over the linearisation's coordinates, scaled so that
    its largest component is 1 (real)."""
    eigenvalue: complex
    natural_frequency: float       # rad/s, |s|
    damped_frequency: float        # rad/s, |Im s|
    damping_ratio: float
    log_decrement: float | None
    shape: np.ndarray
    names: tuple
    participation: np.ndarray      # share of each coordinate in the shape (sums to 1)
    rigid: bool
    whirl: str | None = None       # "forward", "backward" or None
    tolerance: float = 0.0         # |real part| below this: neutrally stable (undamped)
    #: closed loops: the shape over every coordinate (independent and dependent), named
    #: by ``coordinates``; for a tree the same as ``shape``
    motion: np.ndarray | None = None
    coordinates: tuple = ()

    def __post_init__(self):
        if self.motion is None:
            self.motion, self.coordinates = self.shape, tuple(self.names)

    @property
    def frequency_hz(self):
        return self.damped_frequency / (2 * np.pi)

    @property
    def natural_frequency_hz(self):
        return self.natural_frequency / (2 * np.pi)

    @property
    def stable(self):
        """Decaying, undamped (real part within round-off of zero) or rigid."""
        return self.eigenvalue.real <= self.tolerance or self.rigid

    def to_dict(self):
        return {"eigenvalue": [self.eigenvalue.real, self.eigenvalue.imag],
                "natural_frequency": self.natural_frequency,
                "damped_frequency": self.damped_frequency,
                "frequency_hz": self.frequency_hz,
                "damping_ratio": self.damping_ratio, "log_decrement": self.log_decrement,
                "rigid": bool(self.rigid), "stable": bool(self.stable), "whirl": self.whirl,
                "shape": {n: [c.real, c.imag] for n, c in zip(self.names, self.shape)},
                "participation": dict(zip(self.names, self.participation.tolist())),
                **({} if self.coordinates == tuple(self.names) else {
                    "motion": {n: [c.real, c.imag]
                               for n, c in zip(self.coordinates, self.motion)}})}

    def __repr__(self):
        tag = " rigid" if self.rigid else ""
        whirl = f" {self.whirl}" if self.whirl else ""
        return (f"<Mode {self.damped_frequency:.6g} rad/s ({self.frequency_hz:.6g} Hz), "
                f"zeta {self.damping_ratio:.4g}{tag}{whirl}>")


@dataclass
class Modes:
    """The modes of a ``Linearization``, by increasing natural frequency."""
    linearization: object
    modes: list
    eigenvalues: np.ndarray

    def __iter__(self):
        return iter(self.modes)

    def __len__(self):
        return len(self.modes)

    def __getitem__(self, k):
        return self.modes[k]

    @property
    def largest_real_part(self):
        flexible = [m.eigenvalue.real for m in self.modes if not m.rigid]
        return max(flexible) if flexible else 0.0

    @property
    def stable(self):
        return all(m.stable for m in self.modes)

    @property
    def stability(self):
        """A sentence: stable, or which mode grows and how fast."""
        bad = [m for m in self.modes if not m.stable]
        if not bad:
            if self.largest_real_part >= -max((m.tolerance for m in self.modes), default=0):
                return ("stable: no mode grows (some are undamped: real parts within "
                        "round-off of zero)")
            return (f"stable: every mode decays (largest real part "
                    f"{self.largest_real_part:.4g} 1/s)")
        worst = max(bad, key=lambda m: m.eigenvalue.real)
        return (f"unstable: the mode at {worst.damped_frequency:.6g} rad/s grows as "
                f"exp({worst.eigenvalue.real:.4g} t)")

    def to_dict(self):
        return {"stable": bool(self.stable), "stability": self.stability,
                "largest_real_part": float(self.largest_real_part),
                "modes": [m.to_dict() for m in self.modes]}

    def table(self):
        """The modes as text lines."""
        lines = [f"{'#':>3} {'f_d [Hz]':>12} {'w_d [rad/s]':>13} {'w_n [rad/s]':>13} "
                 f"{'zeta':>10} {'log dec':>9}  dominant coordinates"]
        for k, m in enumerate(self.modes, 1):
            order = np.argsort(-m.participation)
            dom = ", ".join(f"{m.names[i]} {100 * m.participation[i]:.0f}%"
                            for i in order[:3] if m.participation[i] > 0.05)
            tag = "  (rigid)" if m.rigid else (f"  ({m.whirl} whirl)" if m.whirl else "")
            ld = f"{m.log_decrement:9.4g}" if m.log_decrement is not None else f"{'-':>9}"
            lines.append(f"{k:>3} {m.frequency_hz:>12.6g} {m.damped_frequency:>13.6g} "
                         f"{m.natural_frequency:>13.6g} {m.damping_ratio:>10.4g} {ld}  "
                         f"{dom}{tag}")
            if m.coordinates != tuple(m.names):
                lines.append(f"{'':>4}with {_dependent_motion(m)}")
        lines.append(self.stability)
        return "\n".join(lines)


def modes(lin, whirl=(), spin=1.0, rigid_tolerance=1e-7):
    """The modes of a linearisation ``lin`` (``mb.linearize``).

    ``whirl``: pairs ``(y, z)`` of coordinate names spanning planes across the spin axis
    (``y x z`` along the spin); ``spin``: the sign (or value) of the spin speed.
    ``rigid_tolerance``: eigenvalues smaller than this times the largest are rigid-body.
    """
    from .linearize import Linearization
    if not isinstance(lin, Linearization):
        raise ModelError(f"modes: give a linearisation (mb.linearize(model, q0, u0)), got "
                         f"{type(lin).__name__}")
    whirl = arguments.pairs(whirl, "modes", "whirl")
    spin = arguments.number(spin, "modes", "spin")
    rigid_tolerance = arguments.number(rigid_tolerance, "modes", "rigid_tolerance",
                                       positive=True)
    n = lin.n
    names = lin.names
    index = _whirl_rows(lin, whirl)
    values, vectors = np.linalg.eig(lin.A)
    scale = max(np.abs(values).max(initial=0.0), 1e-300)
    out = []
    for s, v in zip(values, vectors.T):
        if s.imag < -1e-12 * scale:           # one of each conjugate pair
            continue
        if abs(s.imag) <= 1e-12 * scale:
            s = complex(s.real, 0.0)
        shape = v[:n]
        if np.abs(shape).max() < 1e-300:
            shape = v[n:]
        k = int(np.argmax(np.abs(shape)))
        shape = shape / shape[k]
        wn = abs(s)
        rigid = wn <= rigid_tolerance * scale
        wd = abs(s.imag)
        zeta = -s.real / wn if wn > 0 else 0.0
        logdec = (-2 * np.pi * s.real / wd) if wd > 0 else None
        part = np.abs(shape) ** 2
        part = part / part.sum()
        direction = None
        if whirl and wd > 0 and not rigid:
            # y = Re(a e^{iwt}), z = Re(b e^{iwt}): turns from y to z when Im(conj(a) b) < 0
            turn = _turn(shape, whirl, index)
            if abs(turn) > 1e-9 * np.abs(shape).max() ** 2:
                direction = "forward" if np.sign(turn) == np.sign(spin or 1.0) else "backward"
        out.append(Mode(complex(s), float(wn), float(wd), float(zeta),
                        None if logdec is None else float(logdec), shape, tuple(names),
                        part, bool(rigid), direction, 1e-9 * scale))
    out.sort(key=lambda m: (m.natural_frequency, m.damped_frequency))
    if whirl:
        _circular_pairs(out, whirl, index, spin)
    for m in out:       # closed loops: the dependent coordinates follow the independent
        m.motion = m.shape if lin.basis is None else lin.basis @ m.shape
        m.coordinates = tuple(lin.coordinates)
    return Modes(lin, out, values)


def _dependent_motion(mode):
    """``th4 0.195, th3 -1.21``: how the dependent coordinates move in a mode, per unit of
    its largest independent one (a magnitude and phase where it is not in or out of
    phase)."""
    parts = []
    for name, c in zip(mode.coordinates, mode.motion):
        if name in mode.names:
            continue
        if abs(c.imag) <= 1e-9 * max(abs(c), 1e-300):
            parts.append(f"{name} {c.real:.4g}")
        else:
            parts.append(f"{name} {abs(c):.4g} at {np.degrees(np.angle(c)):.0f} deg")
    return ", ".join(parts)


def _whirl_rows(lin, whirl):
    """``{name: row}``: each whirl name's displacement as a row over the linearisation's
    coordinates: a coordinate's unit row, or a flexible body's node ``BODY.NODE.y`` /
    ``BODY.NODE.z`` (its lateral displacement in body axes, ``model.node_row``)."""
    names = lin.names
    rows = {}
    for pair in whirl:
        for p in pair:
            if p in names:
                rows[p] = np.eye(len(names))[names.index(p)]
            elif hasattr(lin.model, "node_row") and isinstance(p, str) and p.count(".") == 2:
                rows[p] = lin.model.node_row(p, names)
        missing = [p for p in pair if p not in rows]
        if len(pair) != 2 or missing:
            raise ModelError(f"whirl pair {pair!r}: give two coordinate names of the "
                             f"linearisation ({', '.join(names)}), or a flexible body's "
                             "node as BODY.NODE.y and BODY.NODE.z")
    return rows


def _turn(shape, whirl, index):
    """Sense of the orbit of a shape in the lateral planes: > 0 turning from y to z."""
    return sum(-np.imag(np.conj(index[y] @ shape) * (index[z] @ shape)) for y, z in whirl)


def _circular_pairs(out, whirl, index, spin):
    """Two modes with the same eigenvalue (an isotropic rotor's forward and backward
    whirl) have no preferred shapes: any combination is a mode.  Choose the two that turn
    most clearly each way -- the extremes of the orbit sense over their plane."""
    from scipy.linalg import eigh
    k = 0
    while k < len(out) - 1:
        a, b = out[k], out[k + 1]
        same = abs(a.eigenvalue - b.eigenvalue) <= 1e-8 * max(abs(a.eigenvalue), 1e-300)
        if not same or a.rigid or a.damped_frequency == 0:
            k += 1
            continue
        V = np.column_stack([a.shape, b.shape])
        H = np.zeros((len(a.shape), len(a.shape)), complex)
        for y, z in whirl:
            H += 0.5j * (np.outer(index[y], index[z]) - np.outer(index[z], index[y]))
        _, C = eigh(V.conj().T @ H @ V, V.conj().T @ V)
        for mode, c in zip((a, b), C.T):
            shape = V @ c
            shape = shape / shape[int(np.argmax(np.abs(shape)))]
            mode.shape = shape
            part = np.abs(shape) ** 2
            mode.participation = part / part.sum()
            turn = _turn(shape, whirl, index)
            mode.whirl = (None if abs(turn) <= 1e-9 * np.abs(shape).max() ** 2 else
                          "forward" if np.sign(turn) == np.sign(spin or 1.0) else "backward")
        k += 2
