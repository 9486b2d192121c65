"""Writes models/data/flexible_slider_crank_rod.toml: the connecting rod of the flexible
slider-crank of the IVP test set (Simeon's problem), as reduced data mbdyn reads.

Source: the Test Set for IVP Solvers (Mazzia, Magherini et al., Bari;
https://archimede.dm.uniba.it/~testset/), problem "Slider Crank" (crank.f, B. Simeon
1998), after B. Simeon, Modelling a flexible slider crank mechanism by a mixed system of
DAEs and PDEs, Math. Modelling of Systems 2 (1996) 1-18.  The rod (length L = 0.3 m,
8 x 8 mm steel, E = 2e11 Pa, rho = 7870 kg/m^3) is a beam in the frame of its left end
(the crank pin), its x axis through the right end (the slider pin), discretised by

* two lateral shape functions v_k(xi) = sin(k pi xi), k = 1, 2 (xi = x / L: the simply
  supported beam's modes; v = 0 at both pins), coordinates q1, q2 (metres: q1 is the
  midpoint's deflection);
* two axial shape functions of one quadratic element with u(0) = 0, u_3 = 4 xi (1 - xi)
  (the middle node) and u_4 = xi (2 xi - 1) (the end), coordinates q3, q4 (metres).

The test set's modal matrices are taken as it writes them (FACM = rho B H L,
FACK = E B H / L):

    M = FACM [[1/2, 0, 0, 0], [0, 1/2, 0, 0], [0, 0, 8, 1], [0, 0, 1, 2]]
    K = FACK diag(pi^4/24 (H/L)^2, 2 pi^4/3 (H/L)^2) (+) FACK [[16/3, -8/3], [-8/3, 7/3]]

Its axial block is 15 times the consistent mass of these shape functions (the integrals
of u_i u_j are [[8, 1], [1, 2]] / 15): the published problem's, kept here, so that the
model is the published one (the reduced-data loader warns that the modal mass is off the
lumped masses', which is this factor).  The coupling terms of the floating frame (the
test set's c1, c2, c12, c21 and B) come from the invariants of mass points: the rod's
mass at 20 Gauss-Legendre points along it, each carrying the section's rotary inertia,
with the shape functions' values (and the lateral slope as the rotation about z) there.
Gauss quadrature of 20 points integrates these smooth integrands to round-off; this
script checks each integral against the test set's closed forms.  Nodes ``root``, ``mid``
and ``tip`` (no mass) carry the pins and the midpoint's deflection.

    python benchmarks/slider_crank_rod.py          # writes the file, prints the checks
"""
from __future__ import annotations

import pathlib
import sys

import numpy as np

ROOT = pathlib.Path(__file__).resolve().parents[1]
OUT = ROOT / "models" / "data" / "flexible_slider_crank_rod.toml"

L, B, H, E, RHO = 0.30, 0.0080, 0.0080, 0.20e12, 7870.0
GAUSS = 20


def shapes(xi):
    """``(u, v, rz)`` (3, len(xi), 4): axial and lateral displacement and the slope, per
    unit q1..q4, at ``xi = x / L``; exact zeros where the functions vanish."""
    xi = np.asarray(xi, float)
    u, v, rz = (np.zeros((xi.size, 4)) for _ in range(3))
    for k in (1, 2):
        s = np.sin(k * np.pi * xi)
        s[np.isclose(k * xi, np.round(k * xi), rtol=0, atol=1e-15)] = 0.0   # at nodes
        v[:, k - 1] = s
        rz[:, k - 1] = k * np.pi / L * np.cos(k * np.pi * xi)
    u[:, 2] = 4 * xi * (1 - xi)
    u[:, 3] = xi * (2 * xi - 1)
    return u, v, rz


def matrices():
    """The test set's modal mass and stiffness (crank.f, as written)."""
    facm, fack = RHO * B * H * L, E * B * H / L
    M = facm * np.array([[0.5, 0, 0, 0], [0, 0.5, 0, 0], [0, 0, 8, 1], [0, 0, 1, 2]])
    K = np.zeros((4, 4))
    K[0, 0] = fack * np.pi ** 4 / 24 * (H / L) ** 2
    K[1, 1] = fack * np.pi ** 4 * 2 / 3 * (H / L) ** 2
    K[2:, 2:] = fack * np.array([[16 / 3, -8 / 3], [-8 / 3, 7 / 3]])
    return M, K


def data():
    """The reduced data as a dict of plain lists (the TOML file's keys)."""
    g, w = np.polynomial.legendre.leggauss(GAUSS)
    xi = np.concatenate([[0.0], (g + 1) / 2, [0.5, 1.0]])
    weight = np.concatenate([[0.0], w / 2, [0.0, 0.0]])
    u, v, rz = shapes(xi)
    modes = np.zeros((xi.size, 6, 4))
    modes[:, 0], modes[:, 1], modes[:, 5] = u, v, rz
    m = RHO * B * H * L * weight
    Iy, Iz = H * B ** 3 / 12, B * H ** 3 / 12          # about y (out of plane), z
    node_mass = np.zeros((xi.size, 6, 6))
    node_mass[:, :3, :3] = m[:, None, None] * np.eye(3)
    node_mass[:, 3:, 3:] = (RHO * L * weight)[:, None, None] * np.diag([Iy + Iz, Iy, Iz])
    nodes = np.zeros((xi.size, 3))
    nodes[:, 0] = L * xi
    names = ["root"] + [f"g{k + 1:02d}" for k in range(GAUSS)] + ["mid", "tip"]
    M, K = matrices()
    return {"mass": M.tolist(), "stiffness": K.tolist(), "modes": modes.tolist(),
            "nodes": nodes.tolist(), "node_mass": node_mass.tolist(), "names": names,
            "interface": ["root", "tip"]}


def check(d):
    """Each floating-frame integral of the mass points against the test set's closed
    forms (crank.f): largest relative difference."""
    nodes, modes = np.array(d["nodes"]), np.array(d["modes"])
    m = np.array(d["node_mass"])[:, 0, 0]
    x, u, v = nodes[:, 0], modes[:, 0], modes[:, 1]
    facb = B * H * L
    closed = {
        "c1 = int A u_i": (m @ u / RHO, facb * np.array([0, 0, 2 / 3, 1 / 6])),
        "c2 = int A v_i": (m @ v / RHO, facb * np.array([2 / np.pi, 0, 0, 0])),
        "c12 = int A x u_i": ((m * x) @ u / RHO, L * facb * np.array([0, 0, 1 / 3, 1 / 6])),
        "c21 = int A x v_i": ((m * x) @ v / RHO,
                              L * facb * np.array([1 / np.pi, -0.5 / np.pi, 0, 0])),
        "B = int A (u_i v_j - v_i u_j)": ((u.T * m) @ v / RHO - (v.T * m) @ u / RHO,
                                          _coupling(facb)),
        "lateral mass int rho A v_i v_j": ((v.T * m) @ v, RHO * facb * np.diag([0.5, 0.5, 0, 0])),
        "J about the pin, m (L^2/3 + H^2/12)": (
            m @ x ** 2 + np.array(d["node_mass"])[:, 5, 5].sum(),
            RHO * facb * (L ** 2 / 3 + H ** 2 / 12)),
    }
    worst = 0.0
    for name, (ours, theirs) in closed.items():
        err = np.abs(np.asarray(ours) - theirs).max() / np.abs(theirs).max()
        worst = max(worst, err)
        print(f"{name:40s} {err:.1e}")
    return worst


def _coupling(facb):
    """The test set's B (BQ), rows and columns q1..q4."""
    Bq = np.zeros((4, 4))
    Bq[0, 2], Bq[0, 3], Bq[1, 3] = -16 / np.pi ** 3, 8 / np.pi ** 3 - 1 / np.pi, 0.5 / np.pi
    Bq[2, 0], Bq[3, 0], Bq[3, 1] = 16 / np.pi ** 3, -(8 / np.pi ** 3 - 1 / np.pi), -0.5 / np.pi
    return facb * Bq


def _toml(d):
    """The dict as TOML text (arrays of numbers and names, repr's 17 digits)."""
    def value(x):
        if isinstance(x, list):
            return "[" + ", ".join(value(y) for y in x) + "]"
        if isinstance(x, str):
            return f'"{x}"'
        return repr(float(x))
    body = "\n".join(f"{k} = {value(v)}" for k, v in d.items())
    return HEADER + "\n" + body + "\n"


HEADER = """\
# The connecting rod of the flexible slider-crank of the IVP test set (B. Simeon,
# crank.f; Math. Modelling of Systems 2 (1996) 1-18) as reduced data: two lateral shape
# functions sin(k pi x / L) and two axial ones of a quadratic element, coordinates
# q1..q4 in metres, with the test set's modal mass and stiffness as it writes them; the
# rod's mass at 20 Gauss points (the floating frame's coupling integrals to round-off)
# and nodes root, mid, tip.  Written by benchmarks/slider_crank_rod.py (its docstring
# says how and checks each integral); do not edit.
"""


if __name__ == "__main__":
    d = data()
    worst = check(d)
    if worst > 1e-13:
        sys.exit(f"the mass points miss the test set's integrals by {worst:.1e}")
    OUT.parent.mkdir(exist_ok=True)
    OUT.write_text(_toml(d))
    print(f"wrote {OUT.relative_to(ROOT)}")
