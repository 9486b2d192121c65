"""A flexible rotor that spins in its floating frame (models/flexible_rotor_runup.toml):
its first critical speed from mbdyn's reduced shaft against the closed form of a
cantilever with a tip mass, and the run-up through it -- the quasi-static unbalance
response below it, the peak just past it, the disk self-centring above it.  The default
(numpy) route, about 17 s; the compiled route and Exudyn are in
benchmarks/flexible_rotor_exudyn.py."""
import math
import tomllib
from pathlib import Path

import numpy as np
import pytest
from scipy.optimize import brentq

import mbdyn as mb

MODEL = Path(__file__).resolve().parent.parent / "models" / "flexible_rotor_runup.toml"
PAR = {k: float(v) for k, v in tomllib.load(open(MODEL, "rb"))["parameters"].items()}
E, RHO, D, L, M_DISK = 2.1e11, 7850.0, 0.02, 0.5, 5.0     # the beam's table
EI = E * math.pi * D ** 4 / 64
MU = RHO * math.pi * D ** 2 / 4 * L                          # the shaft's mass


def cantilever_tip_mass(M):
    """First bending frequency (rad/s) of a uniform Euler-Bernoulli cantilever carrying a
    point mass ``M`` at its tip: ``1 + cos l cosh l + (M / mu) l (cos l sinh l - sin l
    cosh l) = 0``, ``omega = l^2 sqrt(E I / (mu L^3))``."""
    def f(x):
        return (1 + math.cos(x) * math.cosh(x)
                + M / MU * x * (math.cos(x) * math.sinh(x) - math.sin(x) * math.cosh(x)))
    lam = brentq(f, 1e-3, 1.8751041)
    return lam ** 2 * math.sqrt(EI / (MU * L ** 3))


@pytest.fixture(scope="module")
def scene():
    return mb.load_model(MODEL)


def test_first_critical_speed_is_the_closed_form(scene):
    red = scene.model.flexible["shaft"].reduced
    w = 2 * np.pi * red.frequencies
    w_cf = cantilever_tip_mass(M_DISK)
    assert w_cf == pytest.approx(86.4941, abs=1e-4)
    # the bending pair (y, z) of the axisymmetric shaft, both at the closed form's
    assert w[0] == pytest.approx(w_cf, rel=1e-6)
    assert w[1] == pytest.approx(w_cf, rel=1e-6)
    # the second pair far above the run's top speed
    assert w[2] > 10 * PAR["ALPHA"] * scene.settings["t_end"]


@pytest.fixture(scope="module")
def runup(scene):
    m = scene.model
    t_end = scene.settings["t_end"]
    t = np.linspace(0.0, t_end, 1251)
    res = mb.simulate(m, t_end, scene.q0, scene.u0, integrator="DOP853", rtol=1e-6,
                      atol=1e-9, t_eval=t)
    red = m.flexible["shaft"].reduced
    eta = res.q[:, [m.coordinates.index(f"shaft_m{k}") for k in (1, 2, 3, 4)]]
    y = eta @ red.modes[red.node("tip"), 1:3, :].T          # (y, z) in the spinning frame
    return res.t, np.hypot(y[:, 0], y[:, 1])


def test_runup_peaks_just_past_the_critical_speed(runup):
    t, r = runup
    w_cr = cantilever_tip_mass(M_DISK + PAR["M_U"])         # the unbalance rides on the tip
    spin = PAR["ALPHA"] * t
    k = int(np.argmax(r))
    # a run-up's peak lags the critical speed (here by 17 %); never before it
    assert 1.0 < spin[k] / w_cr < 1.3
    # the largest deflection of the tight reference (DOP853 at rtol 1e-12), which Exudyn's
    # FFRF body of the same data meets (benchmarks/flexible_rotor_exudyn.py)
    assert r[k] == pytest.approx(2.2248e-4, rel=2e-3)
    # above it the disk self-centres: the deflection falls back (towards M_U EPS / M)
    assert r[-1] < 0.5 * r[k]
    assert r[spin < 0.5 * w_cr].max() < 0.05 * r[k]


def test_below_the_critical_speed_the_quasi_static_unbalance_response(runup, scene):
    """At half the critical speed the deflection is the first mode's static response to
    the unbalance's centrifugal force in the spinning frame, softened by the spin:
    ``y = phi^2 U Omega^2 / (omega^2 - Omega^2 (1 + m_u phi^2))`` (mass-normalised mode,
    ``phi`` its tip deflection, ``U = m_u eps``)."""
    t, r = runup
    red = scene.model.flexible["shaft"].reduced
    phi2 = float(np.sum(red.modes[red.node("tip"), 1:3, 0] ** 2))
    w2 = (2 * np.pi * red.frequencies[0]) ** 2
    m_u, U = PAR["M_U"], PAR["M_U"] * PAR["EPS"]
    for frac in (0.3, 0.5):
        W = frac * math.sqrt(w2)
        expected = phi2 * U * W ** 2 / (w2 - W ** 2 * (1 + m_u * phi2))
        assert np.interp(W / PAR["ALPHA"], t, r) == pytest.approx(expected, rel=0.05)
