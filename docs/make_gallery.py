#!/usr/bin/env python
"""Regenerate docs/gallery.md and its pictures: one still (with trails) and one HTML view
per model in models/ (every file found there, so new models join by re-running).

    python docs/make_gallery.py          # about a minute
"""
import subprocess
import sys
import time
import warnings
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))
import mbdyn as mb  # noqa: E402
from mbdyn.viz import animate, snapshot  # noqa: E402

IMG = ROOT / "docs" / "img"
#: shorter runs for the pictures (the files' own t_end where absent): seconds simulated
T_END = {"top": 2.4, "jeffcott_rotor": 0.1, "quarter_car": 4.0, "rotating_pendulum": 8.0,
         "bouncing_ball": 1.2, "free_body": 4.0, "gyroscope": 3.0}


def main():
    warnings.simplefilter("ignore")
    lines = ["# Gallery", "",
             "One picture per model in `models/`: the state at the end of a run with the "
             "centres of mass' trails, made by `python docs/make_gallery.py` (which also "
             "regenerates this page).  Each is a still of what `mbdyn animate` shows; the "
             "command under each picture makes the animation (`--out FILE.gif`, `.mp4` or "
             "`.html`: a self-contained page to orbit, zoom, play and scrub, no network "
             "needed).", "",
             "| model | HTML view size |", "|---|---|"]
    body = []
    for path in sorted((ROOT / "models").glob("*.toml")):
        stem = path.stem
        scene = mb.load_model(path)
        t_end = T_END.get(stem, scene.settings.get("t_end") or 2.0)
        t0 = time.perf_counter()
        result = scene.simulate(t_end=min(t_end, scene.settings.get("t_end") or t_end))
        picture = IMG / f"gallery_{stem}.png"
        title = scene.name + (f" (case {scene.case})" if scene.case else "")
        snapshot(result, picture, title=title)
        html = Path("/tmp") / f"gallery_{stem}.html"
        animate(result, html)
        size = html.stat().st_size / 1e6
        html.unlink()
        lines.append(f"| `{stem}` | {size * 1000:.0f} KB |")
        case = f" --case {scene.case}" if scene.case else ""
        body += [f"## {scene.name}", "", f"![{stem}](img/{picture.name})", "",
                 "```sh", f"mbdyn animate models/{path.name}{case} --out {stem}.html",
                 "```", ""]
        print(f"{stem}: {time.perf_counter() - t0:.1f} s")
    lines += ["", "An HTML view is the run's data -- each solid's mesh once and, per frame "
              "(30 per second of playback), every frame's pose -- and mbdyn's own viewer "
              "(about 30 KB of script, no library inside; docs/performance.md, \"The HTML "
              "view\").", ""]
    (ROOT / "docs" / "gallery.md").write_text("\n".join(lines + body))


if __name__ == "__main__":
    main()
