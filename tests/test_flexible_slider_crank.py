"""The flexible slider-crank (models/flexible_slider_crank.toml) against the published
problem: the IVP test set's "Slider Crank" (B. Simeon, crank.f 1998, after Simeon, Math.
Modelling of Systems 2 (1996) 1-18; Test Set for IVP Solvers, Bari,
https://archimede.dm.uniba.it/~testset/, as distributed in the R package deTestSet,
src/Ex_crank.f): its discretisation of the rod, its consistent initial accelerations and
multipliers, and its reference solution at t = 0.1 s (MEBDFI, rtol = atol = 1e-14).

One term of the published equations is not the floating frame's of its own shape
functions: the rod's inertia about the pin, ``J(q) = J2 + 2 rho c12^T q + q^T M_q q``,
and the centrifugal forces ``phi2'^2 M_q q`` take the modal mass ``M_q``, whose axial
block is 15 times the consistent mass of the axial shape functions (crank.f's MQ(3:4,
3:4) = rho B H L [[8, 1], [1, 2]], where the integrals of u_i u_j are [[8, 1], [1, 2]] /
15).  mbdyn takes ``M_q`` as given for the modal inertia, and the quadratic inertia
(invariant ``J2``) from the rod's mass points, i.e. consistent: the model file gives
the published problem but for that term.  ``_published`` puts the test set's term in
(``J2``'s axial block times 15): the equations are then the published ones, which the
checks below show to round-off (accelerations) and to the integration (t = 0.1 s)."""
from __future__ import annotations

import dataclasses
import pathlib
import warnings

import numpy as np
import pytest

import mbdyn as mb

MODEL = pathlib.Path(__file__).resolve().parents[1] / "models" / "flexible_slider_crank.toml"
L, B, H, RHO, E = 0.3, 0.008, 0.008, 7870.0, 2e11
OMEGA = 150.0
#: the test set's consistent initial values (crank.f, ini = 1): positions, velocities
#: (phi2' absolute), accelerations and multipliers
Y0 = {"x3": 0.450016933, "phi2": 0.0, "rod_m1": 0.0, "rod_m2": 0.0,
      "rod_m3": 0.103339863e-4, "rod_m4": 0.169327969e-4}
V0 = {"x3": -.268938672e-5, "phi2": -.749957670e2, "rod_m1": 0.444896105,
      "rod_m2": 0.463434311e-2, "rod_m3": -.178591076e-5, "rod_m4": -.268938672e-5}
A0 = {"x3": -5.062194923138079e3, "phi2": -1.344541576008661e-3,
      "rod_m1": -6.833142732779555e-5, "rod_m2": 1.449382650173157e-8,
      "rod_m3": -4.268463211410861, "rod_m4": 2.098334687947376e-1}
LAMBDA_X = 3.824589508329281e2            # the slider pin's force along x (their sign)
#: the reference solution at t = 0.1 (crank.f, cranksoln): phi1, phi2 (absolute), x3,
#: q1 .. q4; q1 is the rod's midpoint deflection
REFERENCE = {"phi1": 0.1500000000000104e2, "phi2": -0.3311734988256260,
             "x3": 0.1697373328427860, "rod_m1": 0.1893192899613509e-3,
             "rod_m2": 0.2375751249879174e-4, "rod_m3": -0.5323896770569702e-5,
             "rod_m4": -0.8363313279112129e-5}


def _scene():
    with warnings.catch_warnings():      # the data's modal mass: the test set's (above)
        warnings.filterwarnings("ignore", ".*the modal mass from node_mass",
                                category=mb.ModelWarning)
        return mb.load_model(MODEL)


def _published(model):
    """The model with the test set's quadratic inertia ``q^T M_q q`` (module docstring):
    the rod's invariant ``J2``, axial block times 15."""
    fb = model._flex[0]
    J2 = fb.invariants.inertia_2.copy()
    J2[2:, 2:] *= 15.0
    model._flex = (dataclasses.replace(
        fb, invariants=dataclasses.replace(fb.invariants, inertia_2=J2)),)
    return model


def _published_state(m):
    """The test set's initial state in mbdyn's coordinates (phi2 relative to the crank)."""
    rates = {**V0, "phi2": V0["phi2"] - OMEGA}
    return m.q_vector(Y0), m.u_vector(rates)


# ------------------------------------------------------------------ the rod
def test_the_rod_is_the_test_sets_discretisation():
    """The rod as mbdyn reads it (invariants from the 20 Gauss points) against crank.f's
    closed forms: c1, c2 (first moments), c12, c21 (moments about the pin), B (the
    lateral-axial coupling), the modal mass and stiffness, the rigid inertia J2."""
    m = _scene().model
    inv, fb = m._flex[0].invariants, m._flex[0]
    facm, fack, facb = RHO * B * H * L, E * B * H / L, B * H * L
    pi = np.pi
    c1 = facb * np.array([0, 0, 2 / 3, 1 / 6])
    c2 = facb * np.array([2 / pi, 0, 0, 0])
    c12 = L * facb * np.array([0, 0, 1 / 3, 1 / 6])
    c21 = L * facb * np.array([1 / pi, -0.5 / pi, 0, 0])
    Bq = np.zeros((4, 4))
    Bq[0, 2], Bq[0, 3], Bq[1, 3] = -16 / pi ** 3, 8 / pi ** 3 - 1 / pi, 0.5 / pi
    Bq[2:, :2] = -Bq[:2, 2:].T
    rel = 1e-13
    assert np.allclose(inv.modal_first_moment[0], RHO * c1, rtol=0, atol=rel * facm)
    assert np.allclose(inv.modal_first_moment[1], RHO * c2, rtol=0, atol=rel * facm)
    assert np.allclose(inv.coupling[2], RHO * c21, rtol=0, atol=rel * facm * L)
    assert np.allclose(inv.inertia_1[:, 2, 2], 2 * RHO * c12, rtol=0, atol=rel * facm * L)
    assert np.allclose(inv.coupling_1[:, 2, :], RHO * facb * Bq, rtol=0, atol=rel * facm)
    assert inv.inertia[2, 2] == pytest.approx(0.0045339259, rel=1e-8)      # crank.f's J2
    assert inv.mass == pytest.approx(0.151104, rel=1e-14)
    Mq = facm * np.array([[.5, 0, 0, 0], [0, .5, 0, 0], [0, 0, 8, 1], [0, 0, 1, 2]])
    assert np.array_equal(fb.mass, Mq)
    assert fb.stiffness[0, 0] == pytest.approx(fack * pi ** 4 / 24 * (H / L) ** 2, rel=1e-15)
    assert fb.stiffness[3, 2] == pytest.approx(-fack * 8 / 3, rel=1e-15)
    # the quadratic inertia: the consistent mass of the shape functions, whose axial
    # block is the test set's modal mass / 15 (module docstring)
    consistent = Mq.copy()
    consistent[2:, 2:] /= 15
    assert np.allclose(inv.inertia_2[:, :, 2, 2], consistent, rtol=0, atol=1e-13 * facm)


def test_initial_accelerations_and_multiplier_against_the_test_set():
    """At the published initial state: the accelerations and the slider pin's force the
    test set lists with it (16 digits).  Its q1, q2 are printed as 0 where their
    unprinted digits (~1e-14 m) move q1'', q2'' by 3e-8: those two to that."""
    for published in (True, False):
        m = _scene().model
        if published:
            _published(m)
        q, u = _published_state(m)
        ud, lam = m.multipliers(q, u)
        ours = {c: ud[m.speed_index(f"{c}_dot")] for c in A0}
        if published:
            for c in ("x3", "phi2", "rod_m3", "rod_m4"):
                assert ours[c] == pytest.approx(A0[c], rel=1e-10), c
            assert -lam[0] == pytest.approx(LAMBDA_X, rel=1e-10)     # B.x, our sign
            assert abs(ours["rod_m1"] - A0["rod_m1"]) < 5e-8
            assert abs(ours["rod_m2"] - A0["rod_m2"]) < 5e-8
        else:                       # the consistent quadratic inertia: the axial ones
            assert ours["x3"] == pytest.approx(A0["x3"], rel=3e-5)
            assert ours["phi2"] == pytest.approx(A0["phi2"], rel=1e-10)
            assert abs(ours["rod_m4"] / A0["rod_m4"] - 1) > 0.1


def test_the_model_files_initial_state_is_the_test_sets():
    """The file's [initial] and [initial_speeds] (a modal coordinate's name standing for
    its rate) give the published state; the loop gives the slider and the rod's turn."""
    scene = _scene()
    m, q, u = scene.model, scene.q0, scene.u0
    for c in ("rod_m1", "rod_m2", "rod_m3", "rod_m4"):
        assert q[m.coordinate_index(c)] == Y0[c]
        assert u[m.speed_index(f"{c}_dot")] == V0[c]
    assert q[m.coordinate_index("x3")] == pytest.approx(Y0["x3"], abs=5e-10)   # 9 digits
    assert u[m.speed_index("phi2_dot")] + OMEGA == pytest.approx(V0["phi2"], abs=1e-7)
    assert u[m.speed_index("x3_dot")] == pytest.approx(V0["x3"], abs=1e-12)


# ------------------------------------------------------------------ the reference
def _at_the_end(scene, published=False):
    m = scene.model
    if published:
        _published(m)
    res = scene.simulate(rtol=1e-5, atol=1e-8, output_dt=0.1)
    assert res.t[-1] == pytest.approx(0.1)
    q = res.q[-1]
    out = {c: q[m.coordinate_index(c)] for c in m.coordinates}
    out["phi2"] += OMEGA * 0.1                     # absolute, as the test set's
    out["midpoint"] = m.node_row("rod.mid.y", m.coordinates) @ q
    return out, res


@pytest.mark.slow
def test_midpoint_deflection_at_t_01_against_the_reference_solution():
    """The rod's midpoint deflection (node "mid", v(L/2) = q1) and the other
    coordinates at t = 0.1 s, DOP853 at rtol = 1e-5: with the published equations to
    the initial data's printed digits (9: q1 2e-7, x3 1.5e-9 relative) and the
    integration; as the model file has them, the consistent quadratic inertia moves the
    axial coordinates by 3e-4 and the midpoint by 3e-6."""
    end, res = _at_the_end(_scene(), published=True)
    assert end["midpoint"] == end["rod_m1"]
    tol = {"phi2": 1e-9, "x3": 1e-8, "rod_m1": 1e-6, "rod_m2": 1e-6, "rod_m3": 3e-5,
           "rod_m4": 3e-5}
    for c, t in tol.items():
        assert end[c] == pytest.approx(REFERENCE[c], rel=t), c
    assert res.stats["constraint_drift"] < 1e-13
    end, _ = _at_the_end(_scene())
    assert end["midpoint"] == pytest.approx(REFERENCE["rod_m1"], rel=1e-5)
    assert end["rod_m2"] == pytest.approx(REFERENCE["rod_m2"], rel=5e-5)
    assert end["phi2"] == pytest.approx(REFERENCE["phi2"], rel=5e-8)
    assert end["x3"] == pytest.approx(REFERENCE["x3"], rel=5e-8)
    for c in ("rod_m3", "rod_m4"):
        assert 1e-5 < abs(end[c] / REFERENCE[c] - 1) < 1e-3, c
