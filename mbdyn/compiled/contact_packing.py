"""Contact elements between shapes laid out for their kernel (``kernels.contact``): the
header, one record per shape, the listed pairs and each cam's profile block, appended to
the force elements' float array (``compiled.force_packing``, whose ``_PACKERS`` holds
``pack_contact``).
"""
from __future__ import annotations

import numpy as np

from ..elements.contacts import cam_spline
from ..kernels import contact as kc
from ..kernels.forces import FORCE_WORK
from .states import frame_slot

MODES = {"pairs": kc.PAIRS, "sweep": kc.SWEEP, "all": kc.ALL}


def shape_record(model, shape, element):
    """The ``SREC`` floats of one shape (its cam block offset left at -1)."""
    rec = np.zeros(kc.SREC)
    rec[0] = kc.KINDS[shape.kind]
    rec[1] = frame_slot(model, shape.body, f"{element}, shape {shape.name!r}")
    rec[2:5] = shape.position
    rec[5:14] = np.asarray(shape.axes, float).reshape(9)
    rec[14] = shape.bound
    rec[15:18] = shape.size
    rec[18] = -1.0
    return rec


def cam_block(profile):
    """A cam's profile block: ``[n, knots (n+1), (x_k, y_k) (2n), coefficients (4n)]``."""
    angles, radii = profile
    knots, coefficients = cam_spline(angles, radii)
    xy = np.column_stack([radii * np.cos(angles), radii * np.sin(angles)])
    return np.concatenate([[len(angles)], knots, xy.reshape(-1), coefficients.reshape(-1)])


def pack_contact(model, el, element, row, data, laws):
    """A contact element's row and numbers (see ``kernels.contact``); the scratch it
    needs is noted in ``model._force_work`` (``compiled.layout.workspace``)."""
    p = el.params
    shapes = p["shapes"]
    pairs = p["pairs"] or ()
    header = np.zeros(kc.HEADER)
    header[:8] = [len(shapes), len(pairs), MODES[p["mode"]], p["stiffness"], p["exponent"],
                  p["damping_factor"], p["friction"], p["slip_speed"]]
    off = data.put(header)
    first = data.put(np.concatenate([shape_record(model, s, element) for s in shapes]))
    if pairs:
        data.put(np.asarray(pairs, float).reshape(-1))
    for k, s in enumerate(shapes):
        if s.kind == "cam":
            data.values[first + kc.SREC * k + 18] = float(data.put(cam_block(s.profile)))
    row[:4] = [kc.CONTACT_SHAPES, -1, -1, off]
    model._force_work = max(getattr(model, "_force_work", 0),
                            FORCE_WORK + kc.CONTACT_WORK + 7 * len(shapes))
