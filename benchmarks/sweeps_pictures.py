"""The pictures of docs/sweeps.md, made with mbdyn.analysis.sweep.

    OPENBLAS_NUM_THREADS=1 python benchmarks/sweeps_pictures.py [--scheduler processes]

1. The top (case a's speeds): floor-touch time over (Mz, theta0), DOP853 (rtol 1e-9) and
   the listing's semi-implicit Euler (30000 steps over 10 s), side by side.
2. The double pendulum's sensitivity to initial conditions: the separation of two
   members whose theta1 differ by 1e-9 rad, over time (a grid over simulation.t_end),
   batched rk4 -- its slope on a log scale estimates the largest Lyapunov exponent.
"""
import argparse
import os
import sys
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, ".."))

from mbdyn.analysis.sweep import sweep  # noqa: E402
from mbdyn.viz.sweep_plots import plot_sweep  # noqa: E402

TOP = os.path.join(HERE, "..", "models", "top.toml")
PENDULUM = os.path.join(HERE, "..", "models", "double_pendulum.toml")
IMG = os.path.join(HERE, "..", "docs", "img")


def top(scheduler, n_mz, n_theta):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    grid = {"parameters.Mz": f"-0.03:-0.002:{n_mz}", "initial.theta": f"0.2:0.6:{n_theta}"}
    runs = [("DOP853, rtol 1e-9 (converged)", {"simulation.integrator": "DOP853",
                                               "simulation.rtol": 1e-9,
                                               "simulation.atol": 1e-12}),
            ("listing: semi-implicit Euler, dt = 1/3000 s", {})]
    fig, axes = plt.subplots(1, 2, figsize=(12, 4.8), dpi=100)
    for ax, (title, fixed) in zip(axes, runs):
        fixed = dict(fixed, **{"simulation.t_end": 10.0, "outputs.reactions": False,
                               "outputs.energy": False})
        t = time.perf_counter()
        r = sweep(TOP, grid, ("events", "t_final"), cases=["a"], fixed=fixed,
                  scheduler=scheduler, workers=2)
        print(f"top {title}: {len(r)} members in {time.perf_counter() - t:.1f} s; "
              f"{sum(x['status'] != 'ok' for x in r.rows)} failed")
        plot_sweep(r, "event.floor", None, axes=list(grid), ax=ax, title=title)
    fig.suptitle(f"heavy top (case a's speeds): time to touch the floor, s "
                 f"({n_mz} x {n_theta} grid; blank: not within 10 s or failed)")
    fig.tight_layout()
    fig.savefig(os.path.join(IMG, "sweep_top_floor.png"))
    plt.close(fig)


def pendulum():
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(7, 4.8), dpi=100)
    times = np.linspace(0.25, 8.0, 24)
    delta = 1e-9
    for label, (a, b) in {"45/45 (the listing's)": ("-pi/4", "pi/4"),
                          "90/90": ("pi/2", "pi/2"), "180/45": ("pi", "pi/4")}.items():
        members = [{"initial.theta1": a0, "initial.theta2": b, "simulation.t_end": float(t)}
                   for t in times for a0 in (a, f"{a} + {delta}")]
        t0 = time.perf_counter()
        r = sweep(PENDULUM, members, ("final",), batched=True, fixed={
            "simulation.integrator": "rk4", "simulation.dt": 2e-4,
            "outputs.reactions": False, "outputs.energy": False})
        print(f"pendulum {label}: {len(r)} members in {time.perf_counter() - t0:.1f} s")
        y = np.array([[x[f"final.{n}"] for n in ("theta1", "theta2", "theta1_dot",
                                                  "theta2_dot")] for x in r.rows])
        sep = np.linalg.norm(y[1::2] - y[0::2], axis=1)
        ax.semilogy(times, sep, "o-", ms=3, label=label)
        grow = (sep > 1e3 * delta) & (sep < 1e-2)
        if grow.sum() >= 3:
            lam = np.polyfit(times[grow], np.log(sep[grow]), 1)[0]
            print(f"  Lyapunov estimate {lam:.2f} 1/s")
            ax.plot([], [], " ", label=f"  slope: lambda ~ {lam:.1f} 1/s")
    ax.set_xlabel("t, s")
    ax.set_ylabel("|y(theta1 + 1e-9) - y(theta1)|  (rad, rad/s)")
    ax.set_title("double pendulum: growth of a 1e-9 rad difference (rk4, dt = 2e-4 s)")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(os.path.join(IMG, "sweep_pendulum_divergence.png"))
    plt.close(fig)


if __name__ == "__main__":
    ap = argparse.ArgumentParser()
    ap.add_argument("--scheduler", default="processes")
    ap.add_argument("--grid", type=int, nargs=2, default=(8, 6))
    a = ap.parse_args()
    pendulum()
    top(a.scheduler, *a.grid)
