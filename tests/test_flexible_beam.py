"""The beam model of mbdyn/flexible against closed forms: sections, element matrices,
frequencies of cantilevers, simply supported Timoshenko beams, bars in tension and
torsion, the Jeffcott rotor, gyroscopic whirl and centrifugal stiffening."""
import math
import warnings

import numpy as np
import pytest

from mbdyn.errors import ModelError, ModelWarning
from mbdyn.flexible import beam_from_spec, make_section, natural_frequencies, natural_modes, whirl
from mbdyn.flexible.sections import rectangle_torsion_constant
from mbdyn.flexible.shapes import PLANE_XY, PLANE_XZ

STEEL = {"E": 210e9, "rho": 7850.0, "nu": 0.3}
CANTILEVER_BETA_L = np.array([1.8751040687, 4.6940911330, 7.8547574382])


def beam(length=1.0, elements=10, section=("circle", 0.02), theory="euler-bernoulli", **kw):
    spec = {"length": length, "elements": elements, section[0]: section[1],
            "theory": theory, **STEEL}
    spec.update(kw)
    return beam_from_spec(spec)


def held(b, nodes=(), components=(), at_nodes=()):
    """DoFs held: every DoF of ``nodes``, ``components`` everywhere, and (node, comps)."""
    out = set(b.dofs(nodes)) if nodes else set()
    if components:
        out |= set(b.dofs(components=components))
    for node, comps in at_nodes:
        out |= set(b.dofs([node], comps))
    return sorted(out)


# ----------------------------------------------------------------------------- sections
def test_sections_and_cowper_coefficients():
    c = make_section("circle", 0.1, 0.3, "k")
    assert c.area == pytest.approx(math.pi * 0.0025) and c.Iy == c.Iz == pytest.approx(
        math.pi * 1e-4 / 64) and c.J == pytest.approx(2 * c.Iy)
    assert c.ky == pytest.approx(6 * 1.3 / (7 + 1.8))
    t0 = make_section("tube", [0.1, 0.0], 0.3, "k")           # d_in = 0 is the circle
    assert t0.ky == pytest.approx(c.ky) and t0.area == pytest.approx(c.area)
    t = make_section("tube", [0.1, 0.09], 0.3, "k")           # thin tube: kappa -> ~0.53
    assert t.Iy == pytest.approx(math.pi * (0.1 ** 4 - 0.09 ** 4) / 64)
    assert 0.52 < t.ky < 0.54
    r = make_section("rect", [0.02, 0.06], 0.3, "k")          # b along y, h along z
    assert r.Iy == pytest.approx(0.02 * 0.06 ** 3 / 12) and r.Iz == pytest.approx(0.06 * 0.02 ** 3 / 12)
    assert r.ky == pytest.approx(10 * 1.3 / (12 + 3.3))
    # Saint-Venant: square 0.140577 a^4; thin strip -> b t^3 / 3
    assert rectangle_torsion_constant(1.0, 1.0) == pytest.approx(0.140577, abs=2e-6)
    assert rectangle_torsion_constant(100.0, 1.0) == pytest.approx(100 / 3 * (1 - 0.630 / 100), rel=1e-4)


# ------------------------------------------------------------------- element matrices
def _hermite_plane(L, phi):
    """Closed-form Timoshenko plane matrices (Friedman & Kosmatka 1993; Przemieniecki for
    phi = 0) on (v1, th1, v2, th2): stiffness / (EI), translational mass / (rho A),
    rotary mass / (rho I), geometric stiffness / N (phi = 0 only)."""
    f = phi
    K = np.array([[12, 6 * L, -12, 6 * L], [6 * L, (4 + f) * L * L, -6 * L, (2 - f) * L * L],
                  [-12, -6 * L, 12, -6 * L], [6 * L, (2 - f) * L * L, -6 * L, (4 + f) * L * L]]
                 ) / ((1 + f) * L ** 3)
    a, b = 70 * f * f + 147 * f + 78, (35 * f * f + 77 * f + 44) * L / 4
    c, d = 35 * f * f + 63 * f + 27, (35 * f * f + 63 * f + 26) * L / 4
    e, g = (7 * f * f + 14 * f + 8) * L * L / 4, (7 * f * f + 14 * f + 6) * L * L / 4
    Mt = L / (210 * (1 + f) ** 2) * np.array([[a, b, c, -d], [b, e, d, -g], [c, d, a, -b],
                                              [-d, -g, -b, e]])
    p, q, s = (15 * f - 3) * L, (10 * f * f + 5 * f + 4) * L * L, (5 * f * f - 5 * f - 1) * L * L
    Mr = 1 / (30 * (1 + f) ** 2 * L) * np.array([[36, -p, -36, -p], [-p, q, p, s],
                                                 [-36, p, 36, p], [-p, s, p, q]])
    Kg = 1 / (30 * L) * np.array([[36, 3 * L, -36, 3 * L], [3 * L, 4 * L * L, -3 * L, -L * L],
                                  [-36, -3 * L, 36, -3 * L], [3 * L, -L * L, -3 * L, 4 * L * L]])
    return K, Mt, Mr, Kg


@pytest.mark.parametrize("theory", ["euler-bernoulli", "timoshenko"])
def test_element_matrices_match_their_closed_forms(theory):
    L = 0.3
    b = beam(L, 1, ("rect", [0.05, 0.08]), theory)
    s, E, G, rho = b.sections[0], 210e9, b.G[0], 7850.0
    K, M, Gy = b.stiffness_matrix(), b.mass_matrix(), b.gyroscopic_matrix()
    Kg = b.geometric_stiffness(1000.0)
    rot = 1.0 if theory == "timoshenko" else 0.0
    S = np.diag([1.0, -1.0, 1.0, -1.0])
    for plane, I, kappa in ((PLANE_XY, s.Iz, s.ky), (PLANE_XZ, s.Iy, s.kz)):
        phi = 12 * E * I / (kappa * G * s.area * L * L) if rot else 0.0
        Kc, Mt, Mr, Kgc = _hermite_plane(L, phi)
        T = np.eye(4) if plane == PLANE_XY else S       # ry = -dw/dx
        ix = np.ix_(plane, plane)
        np.testing.assert_allclose(K[ix], E * I * T @ Kc @ T, rtol=1e-12, atol=1e-6)
        np.testing.assert_allclose(M[ix], T @ (rho * s.area * Mt + rot * rho * I * Mr) @ T,
                                   rtol=1e-12, atol=1e-12)
        if phi == 0:
            np.testing.assert_allclose(Kg[ix], 1000.0 * T @ Kgc @ T, rtol=1e-12, atol=1e-9)
    # axial and torsion: linear elements
    bar = np.array([[1, -1], [-1, 1]]) / L
    np.testing.assert_allclose(K[np.ix_([0, 6], [0, 6])], E * s.area * bar, rtol=1e-12)
    np.testing.assert_allclose(K[np.ix_([3, 9], [3, 9])], G * s.J * bar, rtol=1e-12)
    lump = L / 6 * np.array([[2, 1], [1, 2]])
    np.testing.assert_allclose(M[np.ix_([0, 6], [0, 6])], rho * s.area * lump, rtol=1e-12)
    np.testing.assert_allclose(M[np.ix_([3, 9], [3, 9])], rho * s.Ip * lump, rtol=1e-12)
    # gyroscopic: skew, the rotary-mass pattern with the polar moment (Nelson & McVaugh)
    np.testing.assert_allclose(Gy, -Gy.T, atol=1e-15)
    if rot:
        phi_xz = 12 * E * s.Iy / (s.kz * G * s.area * L * L)
        phi_xy = 12 * E * s.Iz / (s.ky * G * s.area * L * L)
        if abs(phi_xz - phi_xy) < 1e-12:
            Mr = _hermite_plane(L, phi_xy)[2]
            np.testing.assert_allclose(Gy[np.ix_(PLANE_XZ, PLANE_XY)], -rho * s.Ip * S @ Mr)
    else:
        assert not Gy.any()


def test_rigid_motions_cost_no_strain_and_carry_the_mass():
    b = beam_from_spec({"segments": [
        {"length": 0.4, "elements": 3, "tube": [0.05, 0.03], **STEEL},
        {"length": 0.6, "elements": 4, "rect": [0.03, 0.02], "E": 70e9, "rho": 2700.0}],
        "masses": [{"at": "tip", "mass": 2.0, "polar": 0.01, "diametral": 0.005}]})
    K, M = b.stiffness_matrix(), b.mass_matrix()
    x = b.x
    rigid = np.zeros((b.n_dofs, 6))        # translations, then rotations about the origin
    for i, xi in enumerate(x):
        rigid[6 * i:6 * i + 3, :3] = np.eye(3)
        rigid[6 * i:6 * i + 3, 3:] = np.array([[0, 0, 0], [0, 0, xi], [0, -xi, 0]])  # theta x x_i
        rigid[6 * i + 3:6 * i + 6, 3:] = np.eye(3)
    assert np.abs(K @ rigid).max() < 1e-6 * np.abs(K).max()
    mass = 0.4 * 7850 * math.pi * (0.05 ** 2 - 0.03 ** 2) / 4 + 0.6 * 2700 * 0.03 * 0.02 + 2.0
    Mr = rigid.T @ M @ rigid
    np.testing.assert_allclose(np.diag(Mr)[:3], mass, rtol=1e-12)
    assert np.all(np.linalg.eigvalsh(M) > 0) and np.allclose(M, M.T)


# ------------------------------------------------------------------------ frequencies
def _cantilever_plane(b):
    """A cantilever bending in the x-y plane only: root held, u, w, rx, ry held."""
    return held(b, nodes=["root"], components=("u", "w", "rx", "ry"))


def test_cantilever_euler_bernoulli_frequencies_converge():
    E, rho, d, L = 210e9, 7850.0, 0.02, 1.0
    A, I = math.pi * d * d / 4, math.pi * d ** 4 / 64
    exact = CANTILEVER_BETA_L ** 2 * math.sqrt(E * I / (rho * A * L ** 4)) / (2 * math.pi)
    errors = []
    for n in (2, 5, 10, 20):
        b = beam(L, n, ("circle", d))
        f = natural_frequencies(b.stiffness_matrix(), b.mass_matrix(), _cantilever_plane(b))
        errors.append(np.abs(f[:3] - exact) / exact)
    errors = np.array(errors)
    assert errors[2, 0] < 1e-6 and errors[3, 2] < 2e-5      # 10 elements: 8.6e-7 on mode 1
    assert np.all(np.diff(errors, axis=0) < 0)              # each refinement better
    assert errors[2, 0] / errors[3, 0] > 14                 # O(h^4)


def _timoshenko_simply_supported(E, G, rho, A, I, kappa, L, n):
    """The n-th bending frequency (Hz) of a simply supported Timoshenko beam: with
    v = a sin(k x), theta = b cos(k x), k = n pi / L, the two equations
    kGA (v' - theta)' = rho A v'' and EI theta'' + kGA (v' - theta) = rho I theta'' give
    (kGA k^2 - rhoA w^2)(EI k^2 + kGA - rhoI w^2) - (kGA k)^2 = 0, whose lower root in
    w^2 is the bending mode (Timoshenko 1921; Han, Benaroya & Wei, J. Sound Vib. 225, 1999)."""
    k, kGA = n * math.pi / L, kappa * G * A
    a = rho * A * rho * I
    b = -(kGA * k * k * rho * I + rho * A * (E * I * k * k + kGA))
    c = kGA * E * I * k ** 4
    w2 = (-b - math.sqrt(b * b - 4 * a * c)) / (2 * a)
    return math.sqrt(w2) / (2 * math.pi)


def test_short_simply_supported_timoshenko_beam():
    """L / d = 5: shear and rotary inertia lower the third frequency by a third.  The
    element's shear strain is constant, so its frequencies converge as h^2."""
    d, L = 0.1, 0.5
    errors = []
    for n_el in (40, 80):
        b = beam(L, n_el, ("circle", d), "timoshenko")
        s = b.sections[0]
        fixed = held(b, components=("u", "w", "rx", "ry"),
                     at_nodes=[("root", ["v"]), ("tip", ["v"])])
        f = natural_frequencies(b.stiffness_matrix(), b.mass_matrix(), fixed)
        exact = np.array([_timoshenko_simply_supported(210e9, b.G[0], 7850.0, s.area, s.Iz,
                                                       s.ky, L, n) for n in (1, 2, 3)])
        errors.append(f[:3] / exact - 1)
    errors = np.array(errors)
    assert np.all(errors > 0) and np.all(errors[1] < [5e-6, 6e-5, 2.5e-4])
    np.testing.assert_allclose(errors[0] / errors[1], 4.0, rtol=0.01)
    euler = (3 * math.pi / L) ** 2 * math.sqrt(210e9 * s.Iz / (7850 * s.area)) / (2 * math.pi)
    assert exact[2] < 0.75 * euler                       # far from Euler-Bernoulli's


@pytest.mark.parametrize("what", ["axial", "torsion"])
def test_bar_frequencies_fixed_free(what):
    L, n = 2.0, 60
    b = beam(L, n, ("rect", [0.03, 0.05]))
    s = b.sections[0]
    comp = "u" if what == "axial" else "rx"
    others = [c for c in ("u", "v", "w", "rx", "ry", "rz") if c != comp]
    f = natural_frequencies(b.stiffness_matrix(), b.mass_matrix(),
                            held(b, nodes=["root"], components=others))
    c = math.sqrt(210e9 / 7850) if what == "axial" else math.sqrt(b.G[0] * s.J / (7850 * s.Ip))
    exact = np.array([(2 * k - 1) * math.pi * c / (2 * L) for k in (1, 2, 3)]) / (2 * math.pi)
    err = np.abs(f[:3] - exact) / exact
    assert np.all(err < 1e-3) and err[0] < 1e-4            # linear elements: O(h^2)


def test_jeffcott_rotor_critical_speed():
    """A light simply supported shaft with a disk at mid-span: the first critical speed
    is sqrt(k/m), k = 48 E I / L^3, and spin leaves it alone (the disk does not tilt)."""
    L, d, m = 0.8, 0.02, 10.0
    b = beam_from_spec({"length": L, "elements": 8, "circle": d, "E": 210e9, "rho": 1.0,
                        "theory": "euler-bernoulli", "rotary_inertia": True,
                        "masses": [{"at": 0.4, "mass": m, "polar": 0.05, "diametral": 0.025}]})
    I = math.pi * d ** 4 / 64
    jeffcott = math.sqrt(48 * 210e9 * I / L ** 3 / m) / (2 * math.pi)
    fixed = held(b, at_nodes=[("root", ["u", "v", "w", "rx"]), ("tip", ["v", "w"])])
    f = natural_frequencies(b.stiffness_matrix(), b.mass_matrix(), fixed)
    assert f[0] == pytest.approx(jeffcott, rel=2e-4) and f[1] == pytest.approx(jeffcott, rel=2e-4)
    fw, _ = whirl(b.mass_matrix(), b.gyroscopic_matrix(), b.stiffness_matrix(), 2000.0, fixed)
    np.testing.assert_allclose(fw[:2], jeffcott, rtol=2e-4)


def _overhung_disk_whirl(k11, k12, k22, m, Id, Ip, spin):
    """Whirl of a disk on the tip of a massless cantilever: with r = v + i w and the tilt
    theta = rz - i ry, (k11 - m w^2)(k22 - Id w^2 + Ip spin w) - k12^2 = 0; roots w > 0
    are forward whirl, w < 0 backward (Lalanne & Ferraris, Rotordynamics Prediction in
    Engineering, ch. 2)."""
    poly = np.polymul([-m, 0, k11], [-Id, Ip * spin, k22])
    poly[-1] -= k12 ** 2
    roots = np.roots(poly).real
    return np.sort(roots[roots > 0])[0], np.sort(-roots[roots < 0])[0]


def test_gyroscopic_splitting_of_an_overhung_disk():
    L, d, m, Id = 0.5, 0.03, 8.0, 0.08
    b = beam_from_spec({"length": L, "elements": 4, "circle": d, "E": 210e9, "rho": 0.1,
                        "theory": "euler-bernoulli",
                        "masses": [{"at": "tip", "mass": m, "polar": 2 * Id, "diametral": Id}]})
    EI = 210e9 * math.pi * d ** 4 / 64
    k11, k12, k22 = 12 * EI / L ** 3, -6 * EI / L ** 2, 4 * EI / L
    fixed = held(b, nodes=["root"], components=("u", "rx"))
    M, G, K = b.mass_matrix(), b.gyroscopic_matrix(), b.stiffness_matrix()
    tip = b.node("tip")
    previous = None
    for spin in (0.0, 300.0, 1000.0):
        f, direction = whirl(M, G, K, spin, fixed, y_dof=6 * tip + 1, z_dof=6 * tip + 2)
        fwd, bwd = (w / (2 * math.pi) for w in _overhung_disk_whirl(k11, k12, k22, m, Id,
                                                                     2 * Id, spin))
        assert sorted(f[:2]) == pytest.approx(sorted([fwd, bwd]), rel=1e-4)
        if spin:
            assert list(direction[:2]) == [-1, 1]              # backward below forward
            assert f[1] - f[0] > (previous if previous else 0.0)
            previous = f[1] - f[0]
        else:
            assert f[0] == pytest.approx(f[1], rel=1e-9)     # at rest they coincide


def test_centrifugal_stiffening_of_a_rotating_cantilever():
    """Flapwise bending of a uniform cantilever spinning about an axis through its root:
    the Southwell coefficient of mode 1 is 1.1933 (mode 2: 6.478), and the frequencies
    at spin Omega / sqrt(EI / (m L^4)) = 1, 2, 3, 4 are 3.6816, 4.1373, 4.7973, 5.5850
    (Hodges & Rutkowski, AIAA J. 19, 1981; Wright, Smith, Thresher & Wang, J. Appl.
    Mech. 49, 1982)."""
    E, rho, d, L = 70e9, 2700.0, 0.01, 1.0
    b = beam_from_spec({"length": L, "elements": 20, "circle": d, "E": E, "rho": rho,
                        "theory": "euler-bernoulli"})
    K, M, Kc = b.stiffness_matrix(), b.mass_matrix(), b.centrifugal_stiffness()
    fixed = held(b, nodes=["root"], components=("u", "v", "rx", "rz"))
    A, I = math.pi * d * d / 4, math.pi * d ** 4 / 64
    w0 = math.sqrt(E * I / (rho * A * L ** 4))
    _, modes = natural_modes(K, M, fixed)
    southwell = [p @ Kc @ p / (p @ M @ p) for p in modes[:, :2].T]
    np.testing.assert_allclose(southwell, [1.1933, 6.478], rtol=3e-4)
    for spin, expected in ((1, 3.6816), (2, 4.1373), (3, 4.7973), (4, 5.5850)):
        f = natural_frequencies(K + (spin * w0) ** 2 * Kc, M, fixed)[0]
        assert 2 * math.pi * f / w0 == pytest.approx(expected, abs=2e-4)
    # the axial force behind it, against rho A ((L^2 - x^2) / 2 + R (L - x))
    x = np.linspace(0, L, 7)
    m_out, s_out = b.outboard(x)
    np.testing.assert_allclose(s_out + 0.3 * m_out,
                               rho * A * ((L * L - x * x) / 2 + 0.3 * (L - x)), rtol=1e-12)


def test_euler_buckling_from_the_geometric_stiffness():
    b = beam(1.0, 10, ("circle", 0.02))
    free = [i for i in range(b.n_dofs) if i not in _cantilever_plane(b)]
    K, Kg = b.stiffness_matrix(), b.geometric_stiffness(-1.0)
    lam = np.linalg.eigvals(np.linalg.solve(-Kg[np.ix_(free, free)], K[np.ix_(free, free)]))
    EI = 210e9 * math.pi * 0.02 ** 4 / 64
    assert min(lam.real) == pytest.approx(math.pi ** 2 * EI / 4, rel=1e-6)


# ------------------------------------------------------------------- input and nodes
def test_named_nodes_snap_to_the_nearest():
    b = beam_from_spec({"length": 1.0, "elements": 10, "circle": 0.02, **STEEL,
                        "nodes": {"mid": 0.43, "half": 0.45}})
    assert b.node("mid") == 4 and b.node("half") == 4 and b.node("tip") == 10
    assert b.node(0.96) == 10 and b.node("root") == 0
    thirds = beam_from_spec({"length": 1.0, "elements": 3, "circle": 0.02, **STEEL})
    assert thirds.node(0.5) == 1                  # halfway (to rounding): nearer the root
    with pytest.raises(ModelError, match="off the beam"):
        thirds.node(1.5)
    np.testing.assert_allclose(b.nodes[:, 0], np.linspace(0, 1, 11))


@pytest.mark.parametrize("change, message", [
    ({"circle": None, "hexagon": 0.1}, r"flexible\.beam\.hexagon: unknown key"),
    ({"circle": -0.02}, r"flexible\.beam\.circle: the diameter d must be a positive"),
    ({"circle": None, "tube": [0.02, 0.03]}, r"flexible\.beam\.tube: the inner diameter"),
    ({"circle": None, "rect": [0.02]}, r"flexible\.beam\.rect: give two lengths"),
    ({"circle": None}, r"flexible\.beam\.section: give exactly one of"),
    ({"elements": 0}, r"flexible\.beam\.elements: must be a whole number >= 1"),
    ({"elements": 2.5}, r"flexible\.beam\.elements"),
    ({"nu": 0.5}, r"flexible\.beam\.nu: Poisson"),
    ({"E": float("nan")}, r"flexible\.beam\.E: must be a finite number"),
    ({"rho": 0}, r"flexible\.beam\.rho: must be > 0"),
    ({"lenght": 1.0}, r"did you mean 'length'"),
    ({"theory": "bernoulli"}, r"flexible\.beam\.theory"),
    ({"nodes": {"x1": 1.5}}, r"flexible\.beam\.nodes\.x1: 1\.5 is off the beam"),
    ({"nodes": {"1x": 0.5}}, r"flexible\.beam\.nodes: the name '1x'"),
    ({"masses": [{"at": "hub", "mass": 1.0}]}, r"masses\[0\]\.at: no node named 'hub'"),
    ({"masses": [{"at": 0.5, "mass": -1.0}]}, r"masses\[0\]\.mass: must be >= 0"),
    ({"masses": [{"at": 0.5}]}, r"masses\[0\]: give a mass"),
    ({"elements": 5000}, r"5000 elements \(at most"),
])
def test_bad_input_names_its_key(change, message):
    spec = {"length": 1.0, "elements": 4, "circle": 0.02, **STEEL}
    spec.update(change)
    spec = {k: v for k, v in spec.items() if v is not None}
    with pytest.raises(ModelError, match=message):
        beam_from_spec(spec)


def test_segments_and_odd_disks():
    with pytest.raises(ModelError, match=r"segments\[1\]\.length: missing"):
        beam_from_spec({"segments": [{"length": 1.0, "circle": 0.02, **STEEL},
                                     {"circle": 0.02, **STEEL}]})
    with pytest.raises(ModelError, match="either segments or one segment's keys"):
        beam_from_spec({"segments": [{"length": 1.0, "circle": 0.02, **STEEL}], "length": 1})
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        beam_from_spec({"length": 1.0, "circle": 0.02, **STEEL,
                        "masses": [{"at": "tip", "polar": 1.0, "diametral": 0.1}]})
    assert any(issubclass(w.category, ModelWarning) for w in caught)
