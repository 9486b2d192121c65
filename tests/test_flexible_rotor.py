"""Flexible rotors (docs/flexible.md, "Flexible rotors"): a shaft of beam elements in a
frame that does not spin, its spin's gyroscopic terms, bearings at its nodes; critical
speeds against the Jeffcott closed form and Rayleigh's quotient, the gyroscopic split of
an overhung disk against its closed form, and the Campbell data of
models/jeffcott_flexible.toml against ROSS (tests/data/ross_campbell.json, written by
benchmarks/ross_reference.py)."""
import json
import math
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import mbdyn as mb
from mbdyn.errors import ModelError

HERE = Path(__file__).resolve().parent
MODEL = HERE.parent / "models" / "jeffcott_flexible.toml"
E, D, SPAN, M_DISK = 2.1e11, 0.0319, 0.8, 10.0
EI = E * math.pi * D ** 4 / 64
KS = 48 * EI / SPAN ** 3                   # the shaft's stiffness at a mid-span disk
WHIRL = [("shaft.disk.y", "shaft.disk.z")]


def rotor(rho, kb, spin=0.0, theory="euler-bernoulli", rotary=False, modes=36):
    """A disk at mid-span of an 8-element shaft on two isotropic bearings ``kb`` at its
    ends; ``modes = 36``: every lateral DoF (no truncation)."""
    s = mb.System("rotor", gravity=(0, 0, 0), parameters={"Omega": spin})
    beam = {"theory": theory, "rotary_inertia": rotary, "length": SPAN, "elements": 8,
            "E": E, "rho": rho, "nu": 0.3, "circle": D, "nodes": {"disk": 0.4},
            "masses": [{"at": 0.4, "mass": M_DISK, "polar": 0.05, "diametral": 0.03}]}
    s.add_body("shaft", flexible={"reduction": "lateral", "modes": modes, "spin": "Omega",
                                  "beam": beam})
    s.add_joint("mount", "fixed", "ground", "shaft")
    for name, node, x in (("left", "root", 0.0), ("right", "tip", SPAN)):
        s.add_force(name, "bearing", body="shaft", point=node, center=[x, 0, 0], axis="x",
                    kxx=kb, kyy=kb)
    return s.compile()


def frequencies(model):
    lin = mb.linearize(model, np.zeros(model.nq), np.zeros(model.nu))
    return sorted(m.damped_frequency for m in mb.modes(lin).modes if m.damped_frequency > 1)


@pytest.mark.parametrize("kb", [1e12, 1e6], ids=["rigid", "isotropic"])
def test_critical_speed_of_a_light_shaft_against_jeffcott(kb):
    """Light shaft (rho = 1: 0.6 g against the 10 kg disk), mid-span disk: the critical
    speed (the Campbell diagram's crossing with 1x) is sqrt(k / m) with the shaft's
    48 E I / L^3 in series with the two bearings; the shaft's mass shifts it by
    17/35 of its share (1.6e-5)."""
    cb = mb.campbell(lambda v: rotor(1.0, kb, spin=v), "Omega", [200.0, 300.0, 400.0],
                     whirl=WHIRL)
    k = 1 / (1 / KS + 1 / (2 * kb))
    expected = math.sqrt(k / M_DISK)
    crossings = [c[2] for c in cb.critical]
    assert len(crossings) == 2                      # forward and backward whirl
    for w in crossings:
        assert w == pytest.approx(expected, rel=3e-5)


def test_the_shafts_own_mass_lowers_the_critical_speed_as_rayleigh_says():
    """A steel shaft (5.0 kg) on rigid bearings: Rayleigh's quotient with the static
    deflection shape, sqrt(k / (m + 17/35 m_s)), is an upper bound, 2.8e-4 above the
    finite elements; the light shaft's sqrt(k / m) is 11.5 % above."""
    f = frequencies(rotor(7850.0, 1e12))[0]
    m_shaft = 7850.0 * math.pi / 4 * D ** 2 * SPAN
    rayleigh = math.sqrt(KS / (M_DISK + 17 / 35 * m_shaft))
    assert f < rayleigh
    assert f == pytest.approx(rayleigh, rel=5e-4)
    assert math.sqrt(KS / M_DISK) / f - 1 == pytest.approx(0.1155, abs=1e-3)


def _overhung(k11, k12, k22, m, Id, Ip, spin):
    """Forward and backward whirl of a disk at the tip of a massless cantilever:
    (k11 - m w^2)(k22 - Id w^2 + Ip spin w) = k12^2, roots w > 0 forward, w < 0
    backward (Lalanne & Ferraris, ch. 2)."""
    poly = np.polymul([-m, 0, k11], [-Id, Ip * spin, k22])
    poly[-1] -= k12 ** 2
    roots = np.roots(poly).real
    return np.sort(roots[roots > 0])[0], np.sort(-roots[roots < 0])[0]


def test_gyroscopic_split_of_an_overhung_disk_held_by_a_bushing():
    """A light cantilever (0.5 m, d = 30 mm) held by a bushing at its root node (lateral
    kt = 1e9 N/m, tilt kr = 1e8 N m: its moments act through the node's rotation), a
    disk (m = 8 kg, Id = 0.08, Ip = 0.16) at the tip: forward and backward whirl against
    the closed form at three spins (the tip's stiffness: the inverse of the cantilever's
    flexibility plus the bushing's, ``1/kt + L^2/kr``, ``L/kr``, ``1/kr``; the shaft's
    mass, 35 mg, shifts it by 5e-7), equal at rest, told apart at the tip's node."""
    L, d, m, Id, kt, kr = 0.5, 0.03, 8.0, 0.08, 1e9, 1e8
    ei = E * math.pi * d ** 4 / 64
    flexibility = np.linalg.inv([[12 * ei / L ** 3, -6 * ei / L ** 2],
                                 [-6 * ei / L ** 2, 4 * ei / L]])
    flexibility += [[1 / kt + L ** 2 / kr, L / kr], [L / kr, 1 / kr]]
    (k11, k12), (_, k22) = np.linalg.inv(flexibility)
    for spin in (0.0, 300.0, 1000.0):
        s = mb.System("overhung", gravity=(0, 0, 0))
        s.add_body("shaft", flexible={
            "reduction": "lateral", "modes": 20, "spin": spin,
            "beam": {"theory": "euler-bernoulli", "length": L, "elements": 4, "E": E,
                     "rho": 0.1, "nu": 0.3, "circle": d,
                     "masses": [{"at": "tip", "mass": m, "polar": 2 * Id,
                                 "diametral": Id}]}})
        s.add_joint("mount", "fixed", "ground", "shaft")
        s.add_force("clamp", "bushing", body_a="shaft", point_a="root",
                    stiffness=[kt, kt, kt, kr, kr, kr])
        model = s.compile()
        lin = mb.linearize(model, np.zeros(model.nq), np.zeros(model.nu))
        low = sorted(mb.modes(lin, whirl=[("shaft.tip.y", "shaft.tip.z")]).modes,
                     key=lambda x: x.damped_frequency)[:2]
        fwd, bwd = _overhung(k11, k12, k22, m, Id, 2 * Id, spin)
        assert sorted(x.damped_frequency for x in low) == pytest.approx(sorted([fwd, bwd]),
                                                                        rel=2e-6)
        got = {x.whirl: x.damped_frequency for x in low}
        if spin:
            assert got["forward"] == pytest.approx(fwd, rel=2e-6)
            assert got["backward"] == pytest.approx(bwd, rel=2e-6)
        else:
            assert low[0].damped_frequency == pytest.approx(low[1].damped_frequency,
                                                            rel=1e-6)


def test_unbalance_response_in_time_is_the_harmonic_solution():
    """The model file at Omega = 150 rad/s (8 modes), started on the steady unbalance
    response solved by hand in the frequency domain, ``(-W^2 M + i W (C + W G_ee) + K) X
    = Phi_disk^T F`` with the bearings' ``K_b``, ``C_b`` at their nodes assembled from
    the table's values: the simulation (the Python route: spin, bearings, the turning
    load at the node) stays on it to 1e-8 over 0.03 s; with the gyroscopic sign flipped
    the hand solution is off by 2.5e-4."""
    from mbdyn.elements.tables import Table
    W = 150.0
    model = mb.load_model(MODEL).rebuild({"parameters.Omega": W,
                                          "bodies.shaft.flexible.modes": 8}).model
    red = model.flexible["shaft"].reduced
    M, K = red.mass_matrix, red.stiffness_matrix.copy()
    C = red.damping_matrix + W * red.gyroscopic
    for el in model._force_elements:
        p = el.params
        k = {c: p[c](W) if isinstance(p[c], Table) else p[c] for c in
             ("kxx", "kxy", "kyx", "kyy", "cxx", "cxy", "cyx", "cyy")}
        P = red.modes[red.node("root" if p["point"][0] == 0 else "tip"), 1:3]
        K += P.T @ [[k["kxx"], k["kxy"]], [k["kyx"], k["kyy"]]] @ P
        C += P.T @ [[k["cxx"], k["cxy"]], [k["cyx"], k["cyy"]]] @ P
    force = 10.0 * 1e-4 * W ** 2                 # m eps Omega^2 (cos W t, sin W t)
    f = red.modes[red.node("disk"), 1:3].T @ np.array([force, -1j * force])
    X = np.linalg.solve(-W ** 2 * M + 1j * W * C + K, f)
    T = 0.03
    res = mb.simulate(model, T, X.real, (1j * W * X).real, rtol=1e-10, atol=1e-14)
    for k in (len(res.t) // 2, -1):
        expected = (X * np.exp(1j * W * res.t[k])).real
        assert np.abs(res.q[k] - expected).max() < 1e-8 * np.abs(X).max()
    orbit = red.modes[red.node("disk"), 1:3] @ X
    assert np.imag(np.conj(orbit[0]) * orbit[1]) < 0      # y then z: with the spin
    wrong = np.linalg.solve(-W ** 2 * M + 1j * W * (C - 2 * W * red.gyroscopic) + K, f)
    res = mb.simulate(model, T, wrong.real, (1j * W * wrong).real, rtol=1e-10, atol=1e-14)
    off = np.abs(res.q[-1] - (wrong * np.exp(1j * W * T)).real).max()
    assert off > 1e-5 * np.abs(wrong).max()


# ------------------------------------------------------------------ against ROSS
REF = json.loads((HERE / "data" / "ross_campbell.json").read_text())


def _mbdyn_modes(speed, overrides=()):
    """The model file's modes at ``speed``, every lateral DoF kept (the whole model, as
    ROSS's), lowest first: damped frequency, log decrement, whirl at the disk."""
    scene = mb.load_model(MODEL).rebuild({"parameters.Omega": speed,
                                          "bodies.shaft.flexible.modes": 36,
                                          **dict(overrides)})
    model = scene.model
    lin = mb.linearize(model, np.zeros(model.nq), np.zeros(model.nu))
    modes = [m for m in mb.modes(lin, whirl=WHIRL).modes if m.damped_frequency > 1.0]
    return sorted(modes, key=lambda m: m.damped_frequency)


def test_campbell_data_of_the_flexible_jeffcott_rotor_against_ross():
    """ROSS's eight lowest modes at six speeds (anisotropic, cross-coupled bearings,
    Timoshenko elements with Cowper's shear coefficient, gyroscopic terms): damped
    frequencies to 1e-7 (measured 3e-9), log decrements to 1e-7 absolute (measured
    3e-9); the whirl where both name one (ROSS 0 forward, 1 backward)."""
    compared = 0
    for speed, ross in zip(REF["speeds"], REF["modes"]):
        ours = _mbdyn_modes(speed)[:len(ross)]
        np.testing.assert_allclose([m.damped_frequency for m in ours],
                                   [r["wd"] for r in ross], rtol=1e-7)
        np.testing.assert_allclose([m.log_decrement for m in ours],
                                   [r["log_dec"] for r in ross], atol=1e-7, rtol=1e-7)
        for m, r in zip(ours, ross):
            if m.whirl and r["whirl"] in (0.0, 1.0):
                assert m.whirl == ("forward" if r["whirl"] == 0.0 else "backward")
                compared += 1
    assert compared >= 25


def test_a_wrong_bearing_convention_is_caught_by_the_ross_comparison():
    """kxy and kyx exchanged (the transposed convention): the frequencies leave ROSS's
    by far more than the tolerance, so the comparison can fail."""
    table = REF["bearing_table"]
    swap = {f"forces.{b}.{c}": table[o] for b in ("left_bearing", "right_bearing")
            for c, o in (("kxy", "kyx"), ("kyx", "kxy"))}
    ours = _mbdyn_modes(400.0, swap)[:4]
    ross = REF["modes"][REF["speeds"].index(400.0)][:4]
    err = max(abs(m.damped_frequency / r["wd"] - 1) for m, r in zip(ours, ross))
    assert err > 1e-3


def test_campbell_of_the_model_file_finds_the_oil_whip_onset_where_ross_does():
    """The model's 16 modes (truncated: the lowest four frequencies within 0.07 % of
    ROSS's): the forward mode near 254 rad/s turns unstable between 200 and 400 rad/s,
    where ROSS's log decrement of that mode changes sign (+0.126 to -0.299)."""
    scene = mb.load_model(MODEL)
    cb = mb.campbell(scene, "Omega", np.linspace(0, 800, 9), whirl=WHIRL)
    assert len(cb.onset) == 1
    mode, value = cb.onset[0]
    assert 200 < value < 400
    k = list(cb.values).index(400.0)
    assert cb.whirl[k][mode] == "forward"
    assert cb.frequency[k, mode] == pytest.approx(253.793, rel=3e-3)
    ross = REF["modes"][REF["speeds"].index(200.0)][2], REF["modes"][
        REF["speeds"].index(400.0)][0]
    assert ross[0]["log_dec"] > 0 > ross[1]["log_dec"]
    assert cb.critical                                  # crossings with 1x are found


def test_campbell_command_on_the_flexible_rotor(tmp_path):
    plot = tmp_path / "campbell.png"
    out = subprocess.run([sys.executable, "-m", "mbdyn", "campbell", str(MODEL),
                          "--parameter", "Omega", "--values", "100:500:3", "--whirl",
                          "shaft.disk.y,shaft.disk.z", "--json", "--plot", str(plot)],
                         capture_output=True, text=True, cwd=HERE.parent, timeout=600)
    assert out.returncode == 0, out.stderr
    d = json.loads(out.stdout)["campbell"]
    assert d["values"] == [100.0, 300.0, 500.0]
    assert {"forward", "backward"} <= {w for m in d["modes"] for w in m["whirl"]}
    assert plot.stat().st_size > 10000


def test_rotor_input_errors_are_named():
    beam = {"length": 1.0, "elements": 4, "E": E, "rho": 7850.0, "circle": 0.02}
    s = mb.System("a")
    with pytest.raises(ModelError, match="flexible.spin: a spinning rotor needs "
                                         "reduction = \"lateral\""):
        s.add_body("shaft", flexible={"beam": beam, "modes": 2, "spin": 100.0})
    with pytest.raises(ModelError, match="flexible.spin: 'Om' is not a parameter"):
        s.add_body("shaft", flexible={"beam": beam, "modes": 2, "spin": "Om",
                                      "reduction": "lateral"})
    with pytest.raises(ModelError, match="flexible.spin: must be a finite spin speed"):
        s.add_body("shaft", flexible={"beam": beam, "modes": 2, "spin": [1],
                                      "reduction": "lateral"})
    s.add_body("shaft", flexible={"beam": beam, "modes": 6, "reduction": "lateral"})
    s.add_joint("pin", "revolute", "ground", "shaft", axis="y")
    with pytest.raises(ModelError, match="body 'shaft': with reduction = \"lateral\".*fix "
                                         "it to the ground"):
        s.compile()
    with pytest.raises(ModelError, match="whirl pair.*BODY.NODE.y"):
        m = rotor(1.0, 1e6, modes=8)
        mb.modes(mb.linearize(m, np.zeros(m.nq), np.zeros(m.nu)),
                 whirl=[("shaft.disk.y", "disk_z")])
