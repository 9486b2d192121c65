"""The pictures of docs/constraints.md: the four-bar as the animation draws it, and the
constraint drift and energy of the free four-bar over 10 s (compiled DOP853, projected,
against scipy's Radau on the same index-1 equations, not projected).

    python docs/make_constraints_figures.py
"""
from __future__ import annotations

import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import mbdyn as mb  # noqa: E402

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent / "tests"))
from loop_mechanisms import four_bar  # noqa: E402


def drift_figure(out):
    m = four_bar()
    q, u = m.assemble({"th2": 0.9}, {"th2": -4.0}, guess={"th3": 0.5, "th4": 1.5})
    fig, (ax1, ax2) = plt.subplots(2, 1, figsize=(7, 6))
    tolerances = [1e-6, 1e-8, 1e-10, 1e-12]
    for integrator, style, what in (("DOP853", "o-", "compiled, projected every step"),
                                    ("Radau", "s--", "scipy, not projected")):
        # every step stored (t_eval None): the residual of the integrator's own states
        drift = [mb.simulate(m, 10.0, q, u, integrator=integrator, rtol=tol,
                             atol=tol * 1e-2).stats["constraint_drift_unprojected"]
                 for tol in tolerances]
        ax1.loglog(tolerances, np.maximum(drift, 1e-17), style, label=f"{integrator} ({what})")
    ax1.set_xlabel("rtol (atol = rtol / 100)")
    ax1.set_ylabel("largest |phi| over 10 s [m]")
    ax1.legend(fontsize=8)
    t = np.linspace(0, 10, 1001)
    for integrator, style in (("DOP853", "-"), ("Radau", "--")):
        res = mb.simulate(m, 10.0, q, u, integrator=integrator, rtol=1e-10, atol=1e-12,
                          t_eval=t, outputs=("energy",))
        E = res.energy["total"]
        ax2.semilogy(res.t, np.abs(E - E[0]) / abs(E[0]) + 1e-17, style, label=integrator)
    ax2.set_ylabel("relative energy error (rtol 1e-10)")
    ax2.set_xlabel("t [s]")
    ax2.legend(fontsize=8)
    fig.suptitle("free four-bar over 10 s: constraint drift and energy")
    fig.tight_layout()
    fig.savefig(out, dpi=110)


def picture(out):
    from PIL import Image
    scene = mb.load_model(str(HERE.parent / "models" / "four_bar.toml"))
    res = scene.simulate(t_end=0.6)
    gif = Path(out).with_suffix(".gif")
    res.animate(str(gif))
    im = Image.open(gif)
    im.seek(im.n_frames - 1)
    im.convert("RGB").save(out)
    gif.unlink()


if __name__ == "__main__":
    drift_figure(HERE / "img" / "four_bar_drift.png")
    picture(HERE / "img" / "four_bar.png")
