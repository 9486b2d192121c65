"""Queries of the contact elements between shapes on a compiled model: the signed gap of
a contact or of one pair of its shapes (for events at the onset and the release of a
contact, docs/contact.md), and the duration of an impact for step-size hints.
"""
from __future__ import annotations

import math

import numpy as np

from ..errors import ModelError
from ..kernels import contact as kc
from ..kernels.forces import FORCE_WORK

KIND = "shape-contact"


def _contacts(model):
    return [(k, el) for k, el in enumerate(model._force_elements) if el.kind == KIND]


def _find(model, which):
    """``(row, first, second)``: the force-table row of the contact element ``which``
    names (its name, or two of its shapes' names) and the pair's shape indices (-1: all)."""
    contacts = _contacts(model)
    names = ", ".join(el.name for _, el in contacts) or "(none)"
    if isinstance(which, str):
        for k, el in contacts:
            if el.name == which:
                return k, -1, -1
        raise ModelError(f"unknown contact {which!r}; the model's contacts between shapes "
                         f"are {names} (a contact switched off is not in the model)")
    if not (isinstance(which, (tuple, list)) and len(which) == 2
            and all(isinstance(n, str) for n in which)):
        raise ModelError(f"a contact gap needs a contact's name or two shape names, got "
                         f"{which!r}")
    for k, el in contacts:
        shapes = [s.name for s in el.params["shapes"]]
        if all(n in shapes for n in which):
            i, j = shapes.index(which[0]), shapes.index(which[1])
            pairs = el.params["pairs"]
            if pairs is None or (i, j) in pairs or (j, i) in pairs:
                if el.params["shapes"][i].body == el.params["shapes"][j].body:
                    break
                return k, i, j
    raise ModelError(f"no contact of the model acts between shapes {which[0]!r} and "
                     f"{which[1]!r}; the model's contacts between shapes are {names}")


def contact_gap(model, which, q, t=0.0):
    """The signed gap (m) of a contact between shapes at the coordinates ``q``: the
    smallest distance between the surfaces of its pairs, negative where they overlap
    (by the penetration).  ``which``: a contact element's name (all its pairs; every pair
    of a group, without broad phase) or two shape names (that pair).  It falls through
    zero at the onset of a contact and rises through zero at its release: a condition
    for ``mb.Event`` (``mb.contact_event``)."""
    k, first, second = _find(model, which)
    q, u = model._state(q, np.zeros(model.nu))
    model._kinematics_kernel(q, u, t)
    off = int(model._force_int[k, 3])
    return float(kc.gap(off, model._force_data, model._R, model._r, model._w, model._v,
                        model._com, model._F, model._N, first, second,
                        model._scratch[FORCE_WORK:]))


def impact_durations(model):
    """``[(contact name, duration (s), mass (kg))]``: how long an impact of each contact
    between shapes lasts at its ``impact_speed`` for its lightest bodies (their reduced
    mass, or the lightest body's mass against the ground): ``m x'' = -k x^n`` from ``x' =
    v`` to the release, ``2 (x_max / v) sqrt(pi) Gamma(1 + a) / Gamma(1/2 + a)`` with
    ``a = 1 / (n + 1)`` and ``x_max = ((n + 1) m v^2 / (2 k))^a``."""
    out = []
    for _, el in _contacts(model):
        p = el.params
        masses = sorted(model.body(b).mass for b in dict.fromkeys(
            s.body for s in p["shapes"]) if b != "ground" and model.body(b).mass > 0)
        if not masses:
            continue
        m = masses[0] * masses[1] / (masses[0] + masses[1]) if len(masses) > 1 else masses[0]
        n, k, v = p["exponent"], p["stiffness"], p["impact_speed"]
        a = 1.0 / (n + 1.0)
        x_max = ((n + 1.0) * m * v * v / (2.0 * k)) ** a
        duration = 2.0 * x_max / v * math.sqrt(math.pi) * math.gamma(1.0 + a) \
            / math.gamma(0.5 + a)
        out.append((el.name, duration, m))
    return out


def contact_forces(model, q, u, t=0.0, max_points=512):
    """The touching points of every contact (between shapes, and of spheres and disks on
    the floor) at the state ``(q, u, t)``: an array ``(k, 6)`` of the world point (for a
    pair of shapes the middle of their overlap, for the floor contact the sphere's or
    rim's deepest point) and the force (world components) on one of the two bodies: the
    one that is not the ground, else the second shape's of the pair (the other gets the
    opposite).  At most ``max_points``; empty when nothing touches."""
    if not any(el.kind in ("contact", KIND) for el in model._force_elements):
        return np.zeros((0, 6))
    model._kinematics_kernel(q, u, t)
    acc = np.zeros(kc.RECORDS + 6 * int(max_points))
    from ..kernels import forces as kf
    kf.force_elements(model._force_int, model._force_data, model._parent, model._axis,
                      model._com, model._qfull, model._ufull, model._R, model._r, model._w,
                      model._v, model._F, model._N, acc, model._scratch, model._force_shapes)
    n = min(int(acc[3]), int(max_points))
    return acc[kc.RECORDS:kc.RECORDS + 6 * n].reshape(n, 6).copy()
