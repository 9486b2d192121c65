#!/usr/bin/env python
"""Regenerate the pictures of docs/vibration.md (about half a minute):

    python docs/make_vibration_figures.py
"""
import sys
import warnings
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))
import mbdyn as mb  # noqa: E402

IMG = ROOT / "docs" / "img"
warnings.simplefilter("ignore", mb.ModelWarning)


def rotating_pendulum():
    """Relative equilibrium and frequency of the rotating pendulum against the arm's speed
    (disk at rest on the arm), with the closed form from the text's equation."""
    base = mb.load_model(ROOT / "models/rotating_pendulum.toml",
                         overrides={"parameters.omega": 0.0})
    p = base.parameters
    speeds = np.linspace(0.0, 12.0, 49)
    beta, freq, closed = [], [], []
    guess = {"beta": 0.0}
    for W in speeds:
        sc = base.rebuild({"parameters.Omega": float(W)})
        eq = mb.equilibrium(sc.model, guess)
        guess = eq.q
        b = eq.q[0]
        beta.append(b)
        freq.append(mb.modes(mb.linearize(sc.model, eq.q))[0].natural_frequency)
        g, l, arm, r = p["g"], p["l"], p["b"], p["r"]
        closed.append(np.sqrt(g / l * np.cos(b) + (arm + r) * W ** 2 / l * np.sin(b)
                              - W ** 2 * np.cos(2 * b)))
    fig, (a1, a2) = plt.subplots(1, 2, figsize=(9, 3.6))
    a1.plot(speeds, np.degrees(beta), "o-", ms=3)
    a1.set_xlabel("arm speed Omega [rad/s]  (disk at rest on the arm)")
    a1.set_ylabel("relative equilibrium beta [deg]")
    a2.plot(speeds, freq, "o", ms=4, label="mb.modes (numeric linearisation)")
    a2.plot(speeds, closed, "-", label="closed form from the text's equation")
    a2.set_xlabel("arm speed Omega [rad/s]")
    a2.set_ylabel("natural frequency [rad/s]")
    a2.legend(fontsize=8)
    fig.suptitle("Rotating pendulum (textbook 1.4.1): the pendulum swings out and stiffens")
    fig.tight_layout()
    fig.savefig(IMG / "vibration_rotating_pendulum.png", dpi=110)
    plt.close(fig)


def double_pendulum():
    sc = mb.load_model(ROOT / "models/double_pendulum.toml")
    md = mb.modes(mb.linearize(sc.model))
    l = 0.07
    fig, axes = plt.subplots(1, 2, figsize=(7, 3.6))
    for ax, mode in zip(axes, md):
        shape = mode.shape.real / np.abs(mode.shape).max() * 0.5
        for sign, style in ((1, "-"), (-1, "--")):
            t1, t2 = sign * shape[0], sign * shape[1]
            x = [0, l * np.sin(t1), l * np.sin(t1) + l * np.sin(t1 + t2)]
            y = [0, -l * np.cos(t1), -l * np.cos(t1) - l * np.cos(t1 + t2)]
            ax.plot(x, y, style + "o", color="tab:blue")
        ax.set_aspect("equal")
        ax.set_xlim(-0.12, 0.12)
        ax.set_ylim(-0.16, 0.01)
        ax.set_title(f"{mode.frequency_hz:.3f} Hz\ntheta1 : theta2 = 1 : "
                     f"{(mode.shape[1] / mode.shape[0]).real:.3g}", fontsize=9)
        ax.axis("off")
    fig.suptitle("Double pendulum (textbook 1.4.2): the two modes, +/- extremes")
    fig.tight_layout()
    fig.savefig(IMG / "vibration_double_pendulum.png", dpi=110)
    plt.close(fig)


def top():
    sc = mb.load_model(ROOT / "models/top.toml", overrides={"parameters.Mz": 0.0})
    p = sc.parameters
    m, g, h, A, C = p["m"], p["g"], p["h"], p["A"], p["C"]
    theta = 0.5
    spins = np.geomspace(25, 2000, 25)     # steady precession needs C w3 > 2 sqrt(A cos(theta) m g h) = 22 rad/s
    nut, prec = [], []
    for w3 in spins:
        roots = np.roots([A * np.cos(theta), -C * w3, m * g * h]).real
        psid = min(roots, key=abs)
        phid = w3 - psid * np.cos(theta)
        md = mb.modes(mb.linearize(sc.model, {"theta": theta},
                                   {"psi_dot": psid, "phi_dot": phid}))
        nut.append(max(mo.damped_frequency for mo in md))
        prec.append(psid)
    fig, ax = plt.subplots(figsize=(6.5, 4))
    ax.loglog(spins, nut, "o", ms=4, label="nutation (mb.modes)")
    ax.loglog(spins, C * spins / A, "-", lw=1, label="C w3 / A (fast top)")
    ax.loglog(spins, prec, "s", ms=4, label="steady precession psi'")
    ax.loglog(spins, m * g * h / (C * spins), "--", lw=1, label="m g h / (C w3)")
    ax.set_xlabel("spin w3 [rad/s]")
    ax.set_ylabel("[rad/s]")
    ax.set_title("Heavy top (textbook 1.4.3) at theta = 0.5: nutation and precession", fontsize=9)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(IMG / "vibration_top.png", dpi=110)
    plt.close(fig)


def jeffcott():
    sc = mb.load_model(ROOT / "models/jeffcott_rotor.toml")
    cb = mb.campbell(sc, "Omega", np.linspace(50, 800, 31),
                     whirl=[("y", "z"), ("yl", "zl"), ("yr", "zr")])
    cb.plot(IMG / "vibration_jeffcott_campbell.png")
    return cb


if __name__ == "__main__":
    IMG.mkdir(exist_ok=True)
    rotating_pendulum()
    double_pendulum()
    top()
    cb = jeffcott()
    print(cb.table())
