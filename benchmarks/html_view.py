#!/usr/bin/env python
"""Size and load time of the HTML view (``mbdyn animate ... --out FILE.html``).

    python benchmarks/html_view.py            # a 10 s run of two models, about a minute
    python benchmarks/html_view.py --keep DIR # also keep the pages (and screenshots) in DIR

For each model: the page of a 10 s run at the default 30 frames per second, its size, and
the time headless Chromium (Debian's ``chromium``, driven by Playwright, every request
outside file:// blocked) takes from navigation to ``window.mbdynView`` being defined (the
view drawn and ready to play): the median of three fresh browsers; and the same for a page
holding only plotly.js and one empty 3D plot (the floor of any page made with plotly).  Screenshots at
1280x800 and 1920x1080 are written beside the pages with ``--keep``.
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


def load_time(path, viewport=(1280, 800), shot=None):
    """Seconds from navigation to ``window.mbdynView`` in a fresh headless Chromium."""
    import browser
    with browser.page(viewport) as (page, log):
        t0 = time.perf_counter()
        page.goto(path.as_uri())
        page.wait_for_function("window.mbdynView !== undefined", timeout=60000,
                               polling=10)
        elapsed = time.perf_counter() - t0
        if shot is not None:
            page.wait_for_timeout(300)
            page.screenshot(path=str(shot))
        assert log["errors"] == [] and log["outside"] == [], log
    return elapsed


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--keep", type=Path, help="folder to keep the pages in")
    args = parser.parse_args()
    warnings.simplefilter("ignore")
    folder = args.keep or Path(tempfile.mkdtemp())
    folder.mkdir(parents=True, exist_ok=True)
    print("| model | frames | page size | load time (median of 3) |")
    print("|---|---|---|---|")
    for label, path, case, t_end in RUNS:
        scene = mb.load_model(ROOT / path, case=case)
        result = scene.simulate(t_end=t_end)
        stem = Path(path).stem
        out = folder / f"{stem}.html"
        n = result.animate(out)
        times = [load_time(out) for _ in range(3)]
        if args.keep:
            for w, h in ((1280, 800), (1920, 1080)):
                load_time(out, (w, h), folder / f"{stem}_{w}x{h}.png")
        print(f"| {label} ({result.t[-1]:.2f} s) | {n} | {out.stat().st_size / 1e6:.2f} MB "
              f"| {statistics.median(times):.2f} s |")
    floor = folder / "plotly_alone.html"         # the floor: plotly.js and one empty 3D plot
    from mbdyn.viz.html import plotly_js
    floor.write_text("<!DOCTYPE html><html><head><meta charset='utf-8'><script>" + plotly_js()
                     + "</script></head><body><div id='g' style='height:700px'></div><script>"
                     "Plotly.newPlot('g',[{type:'scatter3d',x:[0,1],y:[0,1],z:[0,1]}])"
                     ".then(function(){window.mbdynView={};});</script></body></html>")
    times = [load_time(floor) for _ in range(3)]
    print(f"| plotly.js alone, one empty 3D plot | - | {floor.stat().st_size / 1e6:.2f} MB "
          f"| {statistics.median(times):.2f} s |")


if __name__ == "__main__":
    main()
