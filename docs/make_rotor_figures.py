#!/usr/bin/env python
"""Regenerate the pictures of docs/flexible.md, "Flexible rotors" (about half a minute):
the Campbell diagram of models/jeffcott_flexible.toml (``Campbell.plot``) and its
comparison with ROSS (tests/data/ross_campbell.json, benchmarks/ross_reference.py).

    python docs/make_rotor_figures.py
"""
import json
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
MODEL = ROOT / "models" / "jeffcott_flexible.toml"
#: the whirl judged at the bearings and the disk (the disk alone stands still in the
#: conical modes)
WHIRL = [(f"shaft.{n}.y", f"shaft.{n}.z") for n in ("root", "disk", "tip")]


def campbell_picture():
    """The model file as it is (16 modes), 0 to 1500 rad/s."""
    cb = mb.campbell(mb.load_model(MODEL), "Omega", np.linspace(0, 1500, 31), whirl=WHIRL)
    fig = cb.plot(orders=(1,))
    ax = fig.axes[0]
    ax.set_ylim(0, 3000)
    ax.set_title("Flexible Jeffcott rotor (models/jeffcott_flexible.toml): ^ forward, "
                 "v backward whirl; colour: damping ratio", fontsize=9)
    fig.savefig(IMG / "flexible_rotor_campbell.png", dpi=120)
    plt.close(fig)
    print(cb.table())


def modes_at(speed, n_modes):
    """The whole model's (36 modes) damped frequencies and log decrements at ``speed``."""
    scene = mb.load_model(MODEL).rebuild({"parameters.Omega": speed,
                                          "bodies.shaft.flexible.modes": n_modes})
    m = scene.model
    lin = mb.linearize(m, np.zeros(m.nq), np.zeros(m.nu))
    modes = sorted((x for x in mb.modes(lin, whirl=WHIRL).modes if x.damped_frequency > 1),
                   key=lambda x: x.damped_frequency)
    return modes


def ross_comparison():
    """ROSS's modes (open markers) on mbdyn's whole model (dots) and the 16-mode model file
    (crosses); the relative differences printed."""
    ref = json.loads((ROOT / "tests" / "data" / "ross_campbell.json").read_text())
    speeds = ref["speeds"]
    n = len(ref["modes"][0])
    whole = [modes_at(s, 36)[:n] for s in speeds]
    file_ = [modes_at(s, 16)[:6] for s in speeds]
    fig, (a1, a2) = plt.subplots(1, 2, figsize=(11, 4.2))
    for k in range(n):
        a1.plot(speeds, [w[k].damped_frequency for w in whole], "o", color="0.3", ms=3)
        a2.plot(speeds, [w[k].log_decrement for w in whole], "o", color="0.3", ms=3)
    for i, s in enumerate(speeds):
        for r in ref["modes"][i]:
            mk = "^" if r["whirl"] == 0.0 else "v" if r["whirl"] == 1.0 else "o"
            a1.plot(s, r["wd"], mk, color="C3", ms=6, mfc="none")
            a2.plot(s, r["log_dec"], mk, color="C3", ms=6, mfc="none")
        a1.plot([s] * len(file_[i]), [m.damped_frequency for m in file_[i]], "x",
                color="C0", ms=5)
    a1.set_yscale("log")
    a1.set_xlabel("spin speed Omega [rad/s]")
    a1.set_ylabel("damped frequency [rad/s]")
    a2.set_xlabel("spin speed Omega [rad/s]")
    a2.set_ylabel("logarithmic decrement")
    a2.set_yscale("symlog", linthresh=0.1)
    a2.axhline(0, color="k", lw=0.6)
    a1.plot([], [], "o", color="0.3", ms=3, label="mbdyn, every lateral DoF (36 modes)")
    a1.plot([], [], "x", color="C0", label="mbdyn, the model file's 16 modes")
    a1.plot([], [], "^", color="C3", mfc="none", label=f"ROSS {ref['ross_version']} "
            "(^ forward, v backward, o mixed)")
    a1.legend(fontsize=8, loc="lower right")
    fig.suptitle("Flexible Jeffcott rotor against ROSS: the eight lowest modes", fontsize=10)
    fig.tight_layout()
    fig.savefig(IMG / "flexible_rotor_ross.png", dpi=120)
    plt.close(fig)
    freq = max(abs(m.damped_frequency / r["wd"] - 1) for w, rs in zip(whole, ref["modes"])
               for m, r in zip(w, rs))
    logd = max(abs(m.log_decrement - r["log_dec"]) for w, rs in zip(whole, ref["modes"])
               for m, r in zip(w, rs))
    trunc = max(min(abs(m.damped_frequency / r["wd"] - 1) for m in w)
                for w, rs in zip(file_, ref["modes"]) for r in rs[:4])
    print(f"whole model vs ROSS: frequency {freq:.1e} (relative), log decrement {logd:.1e}; "
          f"16 modes, lowest four: {trunc:.1e}")


if __name__ == "__main__":
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        campbell_picture()
        ross_comparison()
