"""Craig-Bampton and free-interface reductions (mbdyn/flexible/reduction.py) against the
full finite-element model: frequencies, static deflections, the floating body's free-free
frequencies, damping."""
import math

import numpy as np
import pytest
import scipy.linalg

from mbdyn.errors import ModelError
from mbdyn.flexible import beam_from_spec, natural_frequencies
from mbdyn.flexible.invariants import floating_frame_mass_matrix
from mbdyn.flexible.reduction import craig_bampton, free_interface, rigid_body_modes

E, RHO, D, L = 210e9, 7850.0, 0.02, 1.0


def beam(theory="euler-bernoulli", elements=20):
    return beam_from_spec({"length": L, "elements": elements, "rect": [D, 1.5 * D], "E": E,
                           "rho": RHO, "theory": theory, "nodes": {"mid": 0.5}})


def clamped_frequencies(b):
    return natural_frequencies(b.stiffness_matrix(), b.mass_matrix(), b.dofs(["root"]))


def test_craig_bampton_frequencies_converge_to_the_full_model():
    b = beam()
    full = clamped_frequencies(b)
    errors = []
    for n in (3, 6, 12):
        body = craig_bampton(b, ("root", "tip", "mid"), n_modes=n)
        assert body.n_modes == n + 12
        errors.append(body.frequencies[:6] / full[:6] - 1)
    errors = np.array(errors)
    assert np.all(errors >= -1e-12)                 # Rayleigh-Ritz: from above
    assert np.all(np.diff(errors, axis=0) <= 1e-15) and errors[-1].max() < 3e-4
    assert errors[-1, 0] < 1e-6
    # interface at the root only: modal truncation, the kept modes exact
    body = craig_bampton(b, "root", n_modes=8)
    np.testing.assert_allclose(body.frequencies, full[:8], rtol=1e-8)
    np.testing.assert_allclose(body.modes[0], 0.0)           # the frame is the root's
    assert body.reference == 0 and body.interface == (0,)


def test_frequency_cut_off():
    b = beam()
    full = clamped_frequencies(b)
    body = craig_bampton(b, "root", f_max=0.5 * (full[4] + full[5]))
    assert body.n_modes == 5
    assert craig_bampton(b, "root", n_modes=3, f_max=1e9).n_modes == 3


@pytest.mark.parametrize("theory", ["euler-bernoulli", "timoshenko"])
def test_static_correction_gives_the_exact_tip_deflection(theory):
    """A tip force P along y: v = P L^3 / (3 E Iz) + P L / (ky G A), rotation P L^2 / (2 E Iz)
    (the element is exact for it); free-interface modes alone miss it."""
    b = beam(theory, elements=6)
    s, P = b.sections[0], 100.0
    v_exact = P * L ** 3 / (3 * E * s.Iz) + (P * L / (s.ky * b.G[0] * s.area)
                                             if theory == "timoshenko" else 0.0)
    for interface, exact in ((("root", "tip"), True), (("root",), False)):
        body = free_interface(b, interface, n_modes=4)
        tip = body.modes[b.node("tip")]
        eta = np.linalg.solve(body.stiffness_matrix, tip[1] * P)
        if exact:
            assert tip[1] @ eta == pytest.approx(v_exact, rel=1e-9)
            assert tip[5] @ eta == pytest.approx(P * L * L / (2 * E * s.Iz), rel=1e-9)
        else:
            assert abs(tip[1] @ eta / v_exact - 1) > 1e-4
    np.testing.assert_allclose(body.mass_matrix, np.eye(body.n_modes), atol=1e-10)
    np.testing.assert_allclose(body.modes[0], 0.0, atol=1e-12)


@pytest.mark.parametrize("method", [free_interface, craig_bampton])
def test_the_floating_body_has_the_free_free_frequencies(method):
    """Frame motion (6) plus elastic coordinates: the free-free beam.  Free-interface modes
    span the kept free-free modes exactly; Craig-Bampton's approach them from above."""
    b = beam(elements=12)
    K, M = b.stiffness_matrix(), b.mass_matrix()
    free_free = np.sqrt(np.clip(scipy.linalg.eigh(K, M, eigvals_only=True), 0, None))[6:]
    body = method(b, ("root", "tip"), n_modes=8)
    M6 = floating_frame_mass_matrix(body.invariants, np.zeros(body.n_modes))
    K6 = scipy.linalg.block_diag(np.zeros((6, 6)), body.stiffness_matrix)
    lam = scipy.linalg.eigh(K6, M6, eigvals_only=True)
    assert np.all(np.abs(lam[:6]) < 1e-6 * lam[6])
    got = np.sqrt(lam[6:14])
    if method is free_interface:
        np.testing.assert_allclose(got, free_free[:8], rtol=1e-8)
    else:
        assert np.all(got >= free_free[:8] * (1 - 1e-10))
        np.testing.assert_allclose(got[:4], free_free[:4], rtol=5e-3)
    # the invariants' M(0) is the FE mass matrix on the rigid and elastic shapes
    L0 = np.hstack([rigid_body_modes(b.nodes, [0, 0, 0]), body.modes.reshape(-1, body.n_modes)])
    np.testing.assert_allclose(M6, L0.T @ M @ L0, rtol=1e-9, atol=1e-12)


def test_modal_damping_ratios():
    b = beam(elements=8)
    body = craig_bampton(b, ("root", "tip"), n_modes=4, damping=0.02)
    n = body.n_modes
    A = np.block([[np.zeros((n, n)), np.eye(n)],
                  [-np.linalg.solve(body.mass_matrix, body.stiffness_matrix),
                   -np.linalg.solve(body.mass_matrix, body.damping_matrix)]])
    lam = np.linalg.eigvals(A)
    lam = lam[lam.imag > 0]
    np.testing.assert_allclose(-lam.real / np.abs(lam), 0.02, rtol=1e-6)
    per_mode = craig_bampton(b, "root", n_modes=3, damping=[0.01, 0.02, 0.03])
    X = scipy.linalg.eigh(per_mode.stiffness_matrix, per_mode.mass_matrix)[1]
    np.testing.assert_allclose(np.diag(X.T @ per_mode.damping_matrix @ X),
                               2 * np.array([0.01, 0.02, 0.03]) * 2 * math.pi
                               * per_mode.frequencies, rtol=1e-9)


@pytest.mark.parametrize("kwargs, message", [
    ({}, "give n_modes"),
    ({"n_modes": 10_000}, "10000 asked"),
    ({"n_modes": -1}, "n_modes: must be a whole number"),
    ({"f_max": -5.0}, "f_max: must be a positive"),
    ({"n_modes": 2, "interface": ("root", "root")}, "listed twice"),
    ({"n_modes": 2, "interface": ("root", "hub")}, "no node named 'hub'"),
    ({"n_modes": 2, "damping": -0.1}, "damping: ratios must be"),
    ({"n_modes": 2, "damping": [0.1, 0.2, 0.3]}, "damping: give one modal damping ratio or"),
    ({"n_modes": 0}, "no elastic coordinates"),
])
def test_bad_requests(kwargs, message):
    kwargs.setdefault("interface", ("root",))
    with pytest.raises(ModelError, match=message):
        craig_bampton(beam(elements=4), **kwargs)
