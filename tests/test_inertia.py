"""``mbdyn.inertia`` against the textbook formulas and against an independent route: the
inertia tensor ``sum dm (|p|^2 E - p p^T)`` summed over a midpoint grid of the solid."""
import math
import warnings

import numpy as np
import pytest

import mbdyn as mb
from mbdyn import inertia as mi


def point_inertia(points, masses, about=(0.0, 0.0, 0.0)):
    """Inertia tensor of point masses about a point: ``sum m (|p|^2 E - p p^T)``."""
    p = np.asarray(points, dtype=float) - np.asarray(about, dtype=float)
    m = np.asarray(masses, dtype=float)
    return (np.einsum("n,n->", m, np.einsum("ni,ni->n", p, p)) * np.eye(3)
            - np.einsum("n,ni,nj->ij", m, p, p))


def midpoints(lo, hi, n):
    edges = np.linspace(lo, hi, n + 1)
    return 0.5 * (edges[1:] + edges[:-1]), (hi - lo) / n


def grid_box(mass, a, b, c, n=(30, 34, 38)):
    x, dx = midpoints(-a / 2, a / 2, n[0])
    y, dy = midpoints(-b / 2, b / 2, n[1])
    z, dz = midpoints(-c / 2, c / 2, n[2])
    X, Y, Z = np.meshgrid(x, y, z, indexing="ij")
    pts = np.stack([X.ravel(), Y.ravel(), Z.ravel()], axis=1)
    return pts, np.full(len(pts), mass * dx * dy * dz / (a * b * c))


def grid_cylinder(mass, radius, length, n=(60, 72, 40)):
    """Solid cylinder about z, centred at the origin (polar midpoint grid, dm = rho r dr dt dz)."""
    r, dr = midpoints(0.0, radius, n[0])
    t, dt = midpoints(0.0, 2 * math.pi, n[1])
    z, dz = midpoints(-length / 2, length / 2, n[2])
    Rr, Tt, Zz = np.meshgrid(r, t, z, indexing="ij")
    pts = np.stack([(Rr * np.cos(Tt)).ravel(), (Rr * np.sin(Tt)).ravel(), Zz.ravel()], axis=1)
    rho = mass / (math.pi * radius**2 * length)
    return pts, (rho * Rr * dr * dt * dz).ravel()


def grid_sphere(mass, radius, n=(60, 60, 72)):
    r, dr = midpoints(0.0, radius, n[0])
    ph, dph = midpoints(0.0, math.pi, n[1])
    th, dth = midpoints(0.0, 2 * math.pi, n[2])
    Rr, Ph, Th = np.meshgrid(r, ph, th, indexing="ij")
    pts = np.stack([(Rr * np.sin(Ph) * np.cos(Th)).ravel(), (Rr * np.sin(Ph) * np.sin(Th)).ravel(),
                    (Rr * np.cos(Ph)).ravel()], axis=1)
    rho = mass / (4 / 3 * math.pi * radius**3)
    return pts, (rho * Rr**2 * np.sin(Ph) * dr * dph * dth).ravel()


# ---------------------------------------------------------------------------- formulas
def test_formulas_of_the_common_shapes():
    m, r, L, a, b, c = 2.0, 0.3, 1.2, 0.1, 0.2, 0.4
    np.testing.assert_allclose(mi.disk(m, r), np.diag([m * r**2 / 4, m * r**2 / 4, m * r**2 / 2]))
    np.testing.assert_allclose(mi.cylinder(m, r, L),
                               np.diag([m * (3 * r**2 + L**2) / 12] * 2 + [m * r**2 / 2]))
    np.testing.assert_allclose(mi.rod(m, L), np.diag([m * L**2 / 12, m * L**2 / 12, 0.0]))
    np.testing.assert_allclose(mi.sphere(m, r), np.eye(3) * 2 * m * r**2 / 5)
    np.testing.assert_allclose(mi.box(m, a, b, c),
                               np.diag([m * (b**2 + c**2), m * (a**2 + c**2), m * (a**2 + b**2)]) / 12)


@pytest.mark.parametrize("axis, k", [("x", 0), ("y", 1), ("z", 2)])
def test_symmetry_axis_argument(axis, k):
    m, r, L = 1.5, 0.2, 0.7
    for fn, args, axial, transverse in (
            (mi.disk, (m, r), m * r**2 / 2, m * r**2 / 4),
            (mi.cylinder, (m, r, L), m * r**2 / 2, m * (3 * r**2 + L**2) / 12),
            (mi.rod, (m, L), 0.0, m * L**2 / 12)):
        I = fn(*args, axis=axis)
        expected = np.full(3, transverse)
        expected[k] = axial
        np.testing.assert_allclose(I, np.diag(expected), err_msg=f"{fn.__name__} axis={axis}")


def test_thin_disk_is_the_zero_length_cylinder():
    np.testing.assert_allclose(mi.cylinder(3.0, 0.5, 0.0), mi.disk(3.0, 0.5), rtol=1e-15)


# ---------------------------------------------------------------------------- grid sums
def test_box_against_a_grid_sum():
    m, a, b, c = 3.0, 0.2, 0.5, 0.9
    pts, dm = grid_box(m, a, b, c)
    assert dm.sum() == pytest.approx(m, rel=1e-12)
    np.testing.assert_allclose(mi.box(m, a, b, c), point_inertia(pts, dm), rtol=2e-3,
                               atol=1e-6 * m * c * c)


def test_cylinder_against_a_grid_sum():
    m, r, L = 2.0, 0.15, 0.6
    pts, dm = grid_cylinder(m, r, L)
    assert dm.sum() == pytest.approx(m, rel=1e-12)
    np.testing.assert_allclose(mi.cylinder(m, r, L), point_inertia(pts, dm), rtol=2e-3,
                               atol=1e-6 * m * L * L)


def test_sphere_against_a_grid_sum():
    m, r = 5.0, 0.4
    pts, dm = grid_sphere(m, r)
    assert dm.sum() == pytest.approx(m, rel=1e-3)
    np.testing.assert_allclose(mi.sphere(m, r), point_inertia(pts, dm), rtol=2e-3,
                               atol=1e-6 * m * r * r)


def test_rod_against_a_line_sum():
    m, L = 0.8, 1.7
    z, dz = midpoints(-L / 2, L / 2, 2000)
    pts = np.stack([np.zeros_like(z), np.zeros_like(z), z], axis=1)
    np.testing.assert_allclose(mi.rod(m, L), point_inertia(pts, np.full(len(z), m / len(z))),
                               rtol=1e-6, atol=1e-12)


# ---------------------------------------------------------------------------- parallel axes
def test_parallel_axis_against_a_grid_sum_about_an_offset_point():
    """A box about a point off every axis: products of inertia appear, with the sign of
    ``I_xy = -sum m x y``."""
    m, a, b, c = 2.0, 0.3, 0.4, 0.5
    pts, dm = grid_box(m, a, b, c)
    d = np.array([0.25, -0.4, 0.7])           # the point P, from the centre of mass
    I_P = mi.parallel_axis(mi.box(m, a, b, c), m, d)
    np.testing.assert_allclose(I_P, point_inertia(pts, dm, about=d), rtol=2e-3,
                               atol=1e-6 * m)
    assert I_P[0, 1] == pytest.approx(-m * d[0] * d[1] + 0.0)    # box is symmetric about G
    np.testing.assert_allclose(I_P, I_P.T)
    # the textbook's scalar form about each axis: I_xx = I_G,xx + m (d_y^2 + d_z^2)
    np.testing.assert_allclose(np.diag(I_P), np.diag(mi.box(m, a, b, c))
                               + m * np.array([d[1]**2 + d[2]**2, d[0]**2 + d[2]**2,
                                               d[0]**2 + d[1]**2]))


def test_parallel_axis_and_about_com_are_inverse():
    rng = np.random.default_rng(7)
    for _ in range(20):
        m = rng.uniform(0.1, 10)
        Q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
        I_G = Q @ np.diag(rng.uniform(0.01, 1.0, 3)) @ Q.T     # a rotated, full tensor
        d = rng.normal(size=3)
        I_P = mi.parallel_axis(I_G, m, d)
        np.testing.assert_allclose(mi.about_com(I_P, m, d), I_G, rtol=1e-12, atol=1e-13)
        np.testing.assert_allclose(mi.parallel_axis(I_G, m, -d), I_P, rtol=1e-13)
        # moving away from the centre of mass never decreases any moment of inertia
        n = rng.normal(size=3)
        n /= np.linalg.norm(n)
        assert n @ I_P @ n >= n @ I_G @ n - 1e-12


def test_top_data_about_the_contact_point():
    """The listing's top: ``A = 0.00209393``, ``C = 0.00220580`` about O, ``h = 0.0558``,
    ``m = 0.582``: about G the transverse moment is ``A - m h^2`` and the axial one ``C``;
    these break the triangle inequality (2 (A - m h^2) < C) and mbdyn warns but accepts
    them.  A real disk of the text's dimensions does not (its transverse moment about G is
    at least half its axial one)."""
    m, h, A, C = 0.582, 0.0558, 0.00209393, 0.00220580
    I_G = mi.about_com(np.diag([A, A, C]), m, (0.0, 0.0, -h))
    np.testing.assert_allclose(np.diag(I_G), [A - m * h * h, A - m * h * h, C], rtol=1e-14)
    np.testing.assert_allclose(I_G - np.diag(np.diag(I_G)), 0.0, atol=1e-18)
    assert 2 * I_G[0, 0] < I_G[2, 2]
    with pytest.warns(mb.ModelWarning, match=r"body 'top'.*triangle inequality"):
        mb.System().add_body("top", mass=m, com=(0, 0, h), inertia=I_G)
    disk = mi.cylinder(m, 0.05, 0.0215)
    assert 2 * disk[0, 0] >= disk[2, 2]


@pytest.mark.parametrize("shape", [
    lambda: mi.disk(1.0, 0.3),            # the limiting case A + B = C
    lambda: mi.rod(1.0, 2.0),             # the limiting case 0 + B = C
    lambda: mi.cylinder(1.0, 0.3, 0.05),
    lambda: mi.box(1.0, 0.1, 1.0, 3.0),
    lambda: mi.sphere(1.0, 0.3),
])
def test_helper_shapes_are_accepted_without_warning(shape):
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        mb.System().add_body("b", mass=1.0, inertia=shape())
