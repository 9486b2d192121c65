#!/usr/bin/env python
"""Size and load time of the HTML view (``mbdyn animate ... --out FILE.html``).

    python benchmarks/html_view.py            # a 10 s run of two models, about a minute
    python benchmarks/html_view.py --keep DIR # also keep the pages (and screenshots) in DIR
    python benchmarks/html_view.py --also OLD/double_pendulum.html OLD/top.html
                                              # time other pages (an older version's) too

For each model: the page of a 10 s run at the default 30 frames per second, its size, and
the time headless Chromium (Debian's ``chromium``, driven by Playwright, every request
outside file:// blocked) takes from navigation to ``window.mbdynView`` being defined (the
view drawn, a frame on the screen, ready to play): the median of three fresh browsers, with
WebGL (what headless Chromium gives: SwiftShader) and without it (``--disable-3d-apis``:
the 2D-canvas fallback).  Pages given with ``--also`` are timed in the same rounds (each
round loads every page once, in turn), so that a baseline and the candidate see the same
load on a shared machine; an empty page that is ready at its first frame is the browser's
own floor.  Screenshots at 1280x800 and 1920x1080 are written beside the
pages with ``--keep``.
"""
import argparse
import statistics
import sys
import tempfile
import time
import warnings
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "tests"))

import mbdyn as mb  # noqa: E402

#: (label, model file, case, seconds simulated)
RUNS = [("double_pendulum", "models/double_pendulum.toml", None, 10.0),
        ("top (case d)", "models/top.toml", "d", 10.0)]
ROUNDS = 3


def load_time(path, viewport=(1280, 800), shot=None, args=()):
    """Seconds from navigation to ``window.mbdynView`` in a fresh headless Chromium, and the
    renderer the page used (``None`` for a page that does not say)."""
    import browser
    with browser.page(viewport, args) as (page, log):
        t0 = time.perf_counter()
        page.goto(path.as_uri())
        page.wait_for_function("window.mbdynView !== undefined", timeout=60000,
                               polling=10)
        elapsed = time.perf_counter() - t0
        renderer = page.evaluate("window.mbdynView.renderer || null")
        if shot is not None:
            page.wait_for_timeout(300)
            page.screenshot(path=str(shot))
        assert log["errors"] == [] and log["outside"] == [], log
    return elapsed, renderer


def main():
    import browser
    parser = argparse.ArgumentParser()
    parser.add_argument("--keep", type=Path, help="folder to keep the pages in")
    parser.add_argument("--also", type=Path, nargs="*", default=[],
                        help="other pages to time in the same rounds (e.g. a baseline's)")
    args = parser.parse_args()
    warnings.simplefilter("ignore")
    folder = args.keep or Path(tempfile.mkdtemp())
    folder.mkdir(parents=True, exist_ok=True)
    pages = []                                  # (label, path, frames)
    for label, path, case, t_end in RUNS:
        scene = mb.load_model(ROOT / path, case=case)
        result = scene.simulate(t_end=t_end)
        out = folder / f"{Path(path).stem}.html"
        n = result.animate(out)
        pages.append((f"{label} ({result.t[-1]:.2f} s)", out, n))
        if args.keep:
            for w, h in ((1280, 800), (1920, 1080)):
                load_time(out, (w, h), folder / f"{out.stem}_{w}x{h}.png")
    floor = folder / "empty.html"               # the browser's own floor: a page that is ready
    floor.write_text("<!DOCTYPE html><html><head><meta charset='utf-8'></head><body>"
                     "<script>requestAnimationFrame(function () { window.mbdynView = {}; });"
                     "</script></body></html>")
    pages.append(("an empty page (the browser's floor)", floor, "-"))
    ours = {p for _, p, _ in pages}
    pages += [(f"`{p.name}` (--also)", p.resolve(), "-") for p in args.also]
    modes = {p: (("webgl", ()), ("2d", browser.NO_WEBGL)) if p in ours else (("webgl", ()),)
             for _, p, _ in pages}             # another page may need WebGL (plotly's did)
    times, renderers = {}, {}
    for _ in range(ROUNDS):                     # round-robin: every page once a round
        for _, p, _ in pages:
            for mode, flags in modes[p]:
                elapsed, renderers[p, mode] = load_time(p, args=flags)
                times.setdefault((p, mode), []).append(elapsed)
    print(f"| page | frames | size | load, WebGL (median of {ROUNDS}) "
          f"| load, no WebGL (median of {ROUNDS}) |")
    print("|---|---|---|---|---|")
    for label, p, n in pages:
        cells = [f"{statistics.median(times[p, mode]):.2f} s"
                 + (f" ({renderers[p, mode]})" if renderers[p, mode] else "")
                 if (p, mode) in times else "-" for mode in ("webgl", "2d")]
        print(f"| {label} | {n} | {p.stat().st_size / 1e6:.3f} MB | {cells[0]} | {cells[1]} |")


if __name__ == "__main__":
    main()
