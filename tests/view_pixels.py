"""Checks of the HTML view (mbdyn/viz/view.js) by what it puts on the screen: its canvas's
pixels in a screenshot, against the run's centres of mass and a pinhole camera computed
here from the view's camera (eye, target, up, field of view) -- not from its own
projection."""
from __future__ import annotations

import io

import numpy as np

TEXTS = "#mbdyn-labels, #mbdyn-title, #mbdyn-scale, #mbdyn-hint"


def canvas_pixels(page, texts=False):
    """The canvas's pixels ``(h, w, 3)`` (uint8) in a screenshot; the texts over it hidden
    unless ``texts``."""
    from PIL import Image
    if not texts:
        page.evaluate(f"document.querySelectorAll('{TEXTS}').forEach(e => "
                      "e.style.display = 'none')")
    png = page.locator("#mbdyn-canvas").screenshot()
    if not texts:
        page.evaluate(f"document.querySelectorAll('{TEXTS}').forEach(e => "
                      "e.style.display = '')")
    with Image.open(io.BytesIO(png)) as im:
        return np.asarray(im.convert("RGB"))


def drawn_box(pixels, background=245):
    """``(left, top, right, bottom)`` of the pixels that are not the white background, and
    their count."""
    ink = (pixels < background).any(axis=2)
    rows, cols = np.nonzero(ink)
    if not len(rows):
        return None, 0
    return (cols.min(), rows.min(), cols.max(), rows.max()), int(ink.sum())


def pinhole(camera, points):
    """CSS pixels ``(n, 2)`` of world ``points`` seen by a pinhole camera at ``eye`` looking
    at ``target`` with ``up`` kept vertical, a vertical field of view ``fov`` and square
    pixels (one scale on every axis) in a ``width`` x ``height`` canvas."""
    eye, target, up = (np.asarray(camera[k], float) for k in ("eye", "target", "up"))
    back = (eye - target) / np.linalg.norm(eye - target)
    right = np.cross(up, back)
    right /= np.linalg.norm(right)
    above = np.cross(back, right)
    v = np.asarray(points, float) - eye
    depth = -v @ back
    f = 0.5 * camera["height"] / np.tan(camera["fov"] / 2)      # pixels per unit at depth 1
    return np.column_stack([0.5 * camera["width"] + f * (v @ right) / depth,
                            0.5 * camera["height"] - f * (v @ above) / depth])


def hex_rgb(colour):
    colour = colour.lstrip("#")
    if len(colour) == 3:
        colour = "".join(c * 2 for c in colour)
    return np.array([int(colour[i:i + 2], 16) for i in (0, 2, 4)])


def check_markers(page, colours):
    """Each centre of mass drawn as its marker where the pinhole camera puts it: the pixel
    there has the marker's colour (``colours``, "#rrggbb"), and ``project`` agrees with the
    pinhole camera to a thousandth of a pixel.  Returns the drawn centres of mass."""
    drawn = np.array(page.evaluate("window.mbdynView.positions()"))
    cam = page.evaluate("window.mbdynView.camera()")
    at = pinhole(cam, drawn)
    own = np.array([page.evaluate(f"window.mbdynView.project({p.tolist()})") for p in drawn])
    assert np.abs(own - at).max() < 1e-3, (own, at)
    pixels = canvas_pixels(page)
    assert pixels.shape[:2] == (round(cam["height"]), round(cam["width"]))
    for (x, y), colour in zip(at, colours):
        got = pixels[int(np.floor(y)), int(np.floor(x))].astype(int)   # the pixel holding it
        assert np.abs(got - hex_rgb(colour)).max() <= 12, (x, y, got, colour)
    return drawn
