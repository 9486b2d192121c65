"""Cross-sections of a beam along x: area, second moments, torsion constant and shear
coefficients, in the section's own axes y and z (the body's y and z).

Three kinds, each given by its dimensions:

* ``circle = d``             a solid circle of diameter ``d``;
* ``tube = [d_out, d_in]``   a circular tube (``d_in < d_out``; ``d_in = 0`` is a circle);
* ``rect = [b, h]``          a solid rectangle, ``b`` along y and ``h`` along z.

Shear coefficients (Timoshenko's kappa, the shear area over the area) are Cowper's
(G. R. Cowper, "The shear coefficient in Timoshenko's beam theory", J. Appl. Mech. 33,
1966, table 1), functions of Poisson's ratio ``nu``:

* circle  kappa = 6 (1 + nu) / (7 + 6 nu)
* tube    kappa = 6 (1 + nu) (1 + m^2)^2 / ((7 + 6 nu) (1 + m^2)^2 + (20 + 12 nu) m^2),
          m = d_in / d_out (m = 0 gives the circle's value)
* rect    kappa = 10 (1 + nu) / (12 + 11 nu), for shear along y and along z alike.

The torsion constant of a rectangle is Saint-Venant's series (exact, summed to 1e-12);
of a circle or tube it is the polar moment.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

from ..errors import ModelError

KINDS = ("circle", "tube", "rect")


@dataclass(frozen=True)
class Section:
    """A cross-section: ``area``; ``Iy`` and ``Iz``, second moments about y and z (``Iz``
    resists bending in the x-y plane, displacement v; ``Iy`` in the x-z plane, w);
    ``J`` the torsion constant (stiffness ``G J``); ``Ip = Iy + Iz`` the polar moment
    (torsional inertia ``rho Ip``); ``ky`` and ``kz`` the shear coefficients for shear
    along y and along z."""
    kind: str
    dims: tuple
    area: float
    Iy: float
    Iz: float
    J: float
    ky: float
    kz: float

    @property
    def Ip(self):
        return self.Iy + self.Iz


def cowper_circle(nu):
    return 6.0 * (1.0 + nu) / (7.0 + 6.0 * nu)


def cowper_tube(nu, m):
    a = (1.0 + m * m) ** 2
    return 6.0 * (1.0 + nu) * a / ((7.0 + 6.0 * nu) * a + (20.0 + 12.0 * nu) * m * m)


def cowper_rectangle(nu):
    return 10.0 * (1.0 + nu) / (12.0 + 11.0 * nu)


def rectangle_torsion_constant(b, h):
    """Saint-Venant's torsion constant of a solid ``b`` x ``h`` rectangle:
    ``J = a c^3 / 3 [1 - 192 c / (pi^5 a) sum_{n odd} tanh(n pi a / (2 c)) / n^5]``,
    ``a`` the longer side, ``c`` the shorter (Timoshenko & Goodier, Theory of Elasticity,
    section 109)."""
    a, c = max(b, h), min(b, h)
    total, n = 0.0, 1
    while True:
        term = math.tanh(n * math.pi * a / (2.0 * c)) / n ** 5
        total += term
        if term < 1e-14:
            break
        n += 2
    return a * c ** 3 / 3.0 * (1.0 - 192.0 * c / (math.pi ** 5 * a) * total)


def _positive(value, key, what):
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise ModelError(f"{key}: {what} must be a number, got {value!r}")
    value = float(value)
    if not math.isfinite(value) or value <= 0.0:
        raise ModelError(f"{key}: {what} must be a positive length in metres, got {value!r}")
    return value


def _pair(dims, key, names):
    if not isinstance(dims, (list, tuple)) or len(dims) != 2:
        raise ModelError(f"{key}: give two lengths [{', '.join(names)}], got {dims!r}")
    return dims


def make_section(kind, dims, nu, key):
    """The :class:`Section` of ``kind`` ("circle", "tube" or "rect") with dimensions
    ``dims``; ``key`` names the value in error messages (e.g.
    ``flexible.beam.segments[0].tube``)."""
    if kind == "circle":
        d = _positive(dims, key, "the diameter d")
        area, inertia = math.pi * d * d / 4.0, math.pi * d ** 4 / 64.0
        return Section(kind, (d,), area, inertia, inertia, 2.0 * inertia,
                       cowper_circle(nu), cowper_circle(nu))
    if kind == "tube":
        d_out, d_in = _pair(dims, key, ("d_out", "d_in"))
        d_out = _positive(d_out, key, "d_out")
        if isinstance(d_in, (int, float)) and not isinstance(d_in, bool) and d_in == 0:
            d_in = 0.0
        else:
            d_in = _positive(d_in, key, "d_in")
        if d_in >= d_out:
            raise ModelError(f"{key}: the inner diameter d_in = {d_in:g} must be smaller than "
                             f"the outer d_out = {d_out:g}; write [d_out, d_in]")
        area = math.pi * (d_out ** 2 - d_in ** 2) / 4.0
        inertia = math.pi * (d_out ** 4 - d_in ** 4) / 64.0
        k = cowper_tube(nu, d_in / d_out)
        return Section(kind, (d_out, d_in), area, inertia, inertia, 2.0 * inertia, k, k)
    if kind == "rect":
        b, h = _pair(dims, key, ("b", "h"))
        b, h = _positive(b, key, "the width b (along y)"), _positive(h, key, "the height h (along z)")
        k = cowper_rectangle(nu)
        return Section(kind, (b, h), b * h, b * h ** 3 / 12.0, h * b ** 3 / 12.0,
                       rectangle_torsion_constant(b, h), k, k)
    raise ModelError(f"{key}: unknown section {kind!r}; give one of circle = d, "
                     "tube = [d_out, d_in], rect = [b, h]")
