#!/usr/bin/env python
"""Time and file size of the pictures of the textbook's three models: a plot of the run
(PNG), a GIF animation (real time, 30 fps, first 2 s) and the HTML view (whole run).

    python benchmarks/pictures.py
"""
import os
import sys
import tempfile
import time
import warnings
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))
import mbdyn as mb  # noqa: E402


def main():
    warnings.simplefilter("ignore")
    tmp = Path(tempfile.mkdtemp())
    print(f"{'model':<20} {'run s':>6} | {'plot s':>7} {'KB':>6} | {'GIF s':>6} {'frames':>6} "
          f"{'MB':>5} | {'HTML s':>7} {'frames':>6} {'MB':>5}")
    for name, case in (("rotating_pendulum", None), ("double_pendulum", "45_45"),
                       ("top", "a")):
        scene = mb.load_model(ROOT / f"models/{name}.toml", case=case)
        t0 = time.perf_counter()
        res = scene.simulate()
        t_run = time.perf_counter() - t0
        t0 = time.perf_counter()
        res.plot(out=tmp / "p.png")
        t_plot = time.perf_counter() - t0
        short = scene.simulate(t_end=min(2.0, float(res.t[-1])))
        t0 = time.perf_counter()
        n_gif = short.animate(tmp / "a.gif")
        t_gif = time.perf_counter() - t0
        t0 = time.perf_counter()
        n_html = res.animate(tmp / "a.html")
        t_html = time.perf_counter() - t0
        size = lambda f: os.path.getsize(tmp / f)  # noqa: E731
        print(f"{name:<20} {t_run:>6.2f} | {t_plot:>7.2f} {size('p.png') / 1e3:>6.0f} | "
              f"{t_gif:>6.2f} {n_gif:>6} {size('a.gif') / 1e6:>5.2f} | {t_html:>7.2f} "
              f"{n_html:>6} {size('a.html') / 1e6:>5.2f}")


if __name__ == "__main__":
    main()
