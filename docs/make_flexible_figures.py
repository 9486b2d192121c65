#!/usr/bin/env python
"""Regenerate the picture of docs/flexible.md (a second):

    python docs/make_flexible_figures.py
"""
import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))
from mbdyn.flexible import beam_from_spec, natural_modes  # noqa: E402

IMG = ROOT / "docs" / "img"
BETA_L = (1.8751040687, 4.6940911330, 7.8547574382)


def closed_form(x, beta_l, length):
    """Euler-Bernoulli cantilever mode shape, tip deflection 1."""
    b = beta_l / length
    s = (np.cosh(beta_l) + np.cos(beta_l)) / (np.sinh(beta_l) + np.sin(beta_l))
    phi = lambda y: np.cosh(b * y) - np.cos(b * y) - s * (np.sinh(b * y) - np.sin(b * y))
    return phi(x) / phi(length)


def cantilever_modes():
    length, elements = 1.0, 8
    beam = beam_from_spec({"length": length, "elements": elements, "circle": 0.02,
                           "E": 210e9, "rho": 7850.0, "theory": "euler-bernoulli"})
    held = sorted(set(beam.dofs(["root"])) | set(beam.dofs(components=("u", "w", "rx", "ry"))))
    freq, modes = natural_modes(beam.stiffness_matrix(), beam.mass_matrix(), held)
    x = np.linspace(0.0, length, 201)
    fig, ax = plt.subplots(figsize=(10, 3.8))
    for k, (beta_l, colour) in enumerate(zip(BETA_L, ("C0", "C1", "C2"))):
        v = modes[beam.dofs(components=("v",)), k]
        v = v / v[-1]
        exact = beta_l ** 2 * np.sqrt(210e9 * np.pi * 0.02 ** 4 / 64
                                      / (7850 * np.pi * 0.02 ** 2 / 4)) / (2 * np.pi)
        ax.plot(x, closed_form(x, beta_l, length), "-", color=colour, lw=1.2,
                label=f"mode {k + 1}: closed form, {exact:.3f} Hz")
        ax.plot(beam.x, v, "o", color=colour, ms=5,
                label=f"mode {k + 1}: {elements} elements, {freq[k]:.3f} Hz")
    ax.axhline(0.0, color="0.6", lw=0.6)
    ax.set_xlabel("x [m] (root clamped at x = 0)")
    ax.set_ylabel("v / v_tip")
    ax.set_title("Cantilever bending modes: beam elements (dots) and the closed form (lines)")
    ax.legend(fontsize=7, loc="center left", bbox_to_anchor=(1.01, 0.5))
    fig.tight_layout()
    fig.savefig(IMG / "flexible_cantilever_modes.png", dpi=110)
    plt.close(fig)


if __name__ == "__main__":
    cantilever_modes()
