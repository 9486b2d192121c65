"""The inertia invariants of the floating frame (mbdyn/flexible/invariants.py) against
independent routes: the rigid body's closed forms, the FE mass matrix moved by the nodes'
kinematic map, and Kirchhoff's equations differentiated numerically."""
import math

import numpy as np
import pytest

from mbdyn.flexible import beam_from_spec
from mbdyn.flexible.invariants import (MassPoints, floating_frame_mass_matrix,
                                       inertia_invariants, lumped_mass_points,
                                       quadratic_velocity_vector, skew)
from mbdyn.flexible.reduction import craig_bampton, rigid_body_modes

RNG = np.random.default_rng(26)


def node_map(nodes, modes, eta):
    """The kinematic map of the nodes, built directly: node i's velocity
    ``v + omega x (x_i + Phi_i eta) + Phi_i eta'`` and angular velocity
    ``omega + Psi_i eta'`` as rows over ``w = (v, omega, eta')``: (6 N, 6 + n)."""
    N, _, n = modes.shape
    L = np.zeros((N, 6, 6 + n))
    for i in range(N):
        r = nodes[i] + modes[i, :3] @ eta
        L[i, :3, :3] = np.eye(3)
        L[i, :3, 3:6] = -np.array([[0, -r[2], r[1]], [r[2], 0, -r[0]], [-r[1], r[0], 0]])
        L[i, :3, 6:] = modes[i, :3]
        L[i, 3:, 3:6] = np.eye(3)
        L[i, 3:, 6:] = modes[i, 3:]
    return L.reshape(6 * N, 6 + n)


def random_lumped(N=7, n=4):
    nodes = RNG.normal(size=(N, 3))
    masses = RNG.uniform(0.5, 2.0, N)
    inertia = np.array([np.diag(RNG.uniform(0.01, 0.1, 3)) for _ in range(N)])
    modes = RNG.normal(size=(N, 6, n)) * 0.3
    M_fe = np.zeros((6 * N, 6 * N))
    for i in range(N):
        M_fe[6 * i:6 * i + 3, 6 * i:6 * i + 3] = masses[i] * np.eye(3)
        M_fe[6 * i + 3:6 * i + 6, 6 * i + 3:6 * i + 6] = inertia[i]
    points = MassPoints(masses, nodes, inertia, modes[:, :3], modes[:, 3:])
    return nodes, modes, M_fe, points


def test_skew():
    a, b = RNG.normal(size=3), RNG.normal(size=3)
    np.testing.assert_allclose(skew(a) @ b, np.cross(a, b))


def test_mass_matrix_equals_the_nodal_mass_moved_by_the_kinematic_map():
    nodes, modes, M_fe, points = random_lumped()
    inv = inertia_invariants(points)
    for _ in range(3):
        eta = RNG.normal(size=modes.shape[2])
        L = node_map(nodes, modes, eta)
        np.testing.assert_allclose(floating_frame_mass_matrix(inv, eta), L.T @ M_fe @ L,
                                   rtol=1e-12, atol=1e-12)


def test_at_rest_the_beam_is_its_rigid_body():
    """eta = 0: mass, first moment and inertia of a uniform beam with a tip disk."""
    E, rho, d, L, m_d, Ip, Id = 210e9, 7850.0, 0.03, 1.2, 3.0, 0.02, 0.011
    b = beam_from_spec({"length": L, "elements": 6, "circle": d, "E": E, "rho": rho,
                        "theory": "timoshenko",
                        "masses": [{"at": "tip", "mass": m_d, "polar": Ip, "diametral": Id}]})
    body = craig_bampton(b, ("root", "tip"), n_modes=4)
    inv = body.invariants
    A, I = math.pi * d * d / 4, math.pi * d ** 4 / 64
    m_beam = rho * A * L
    assert inv.mass == pytest.approx(m_beam + m_d, rel=1e-13)
    np.testing.assert_allclose(inv.first_moment, [m_beam * L / 2 + m_d * L, 0, 0], rtol=1e-13)
    J_lat = m_beam * L * L / 3 + rho * I * L + m_d * L * L + Id      # rotary inertia: on
    np.testing.assert_allclose(inv.inertia, np.diag([rho * 2 * I * L + Ip, J_lat, J_lat]),
                               rtol=1e-12, atol=1e-15)
    M0 = floating_frame_mass_matrix(inv, np.zeros(body.n_modes))
    np.testing.assert_allclose(M0[:3, :3], (m_beam + m_d) * np.eye(3), rtol=1e-13)
    np.testing.assert_allclose(M0[6:, 6:], body.mass_matrix, rtol=1e-10, atol=1e-14)
    # the same through the FE mass matrix: rigid modes and the elastic shapes
    basis = body.modes.reshape(-1, body.n_modes)
    L0 = np.hstack([rigid_body_modes(b.nodes, [0, 0, 0]), basis])
    np.testing.assert_allclose(M0, L0.T @ b.mass_matrix() @ L0, rtol=1e-10, atol=1e-12)


def test_consistent_and_nodal_routes_agree_as_the_mesh_is_refined():
    """Away from eta = 0 the beam's invariants (the interpolated field, integrated) and
    the nodal route (the FE mass matrix moved by the nodes' map) differ by the nodal
    interpolation of omega x u; the difference shrinks with the elements."""
    gaps = []
    for n_el in (4, 8, 16):
        b = beam_from_spec({"length": 1.0, "elements": n_el, "circle": 0.05, "E": 210e9,
                            "rho": 7850.0, "theory": "euler-bernoulli"})
        body = craig_bampton(b, ("root",), n_modes=4)
        eta = np.array([0.02, -0.01, 0.015, 0.005])
        L = node_map(b.nodes, body.modes, eta)
        direct = L.T @ b.mass_matrix() @ L
        gaps.append(np.abs(floating_frame_mass_matrix(body.invariants, eta) - direct).max()
                    / np.abs(direct).max())
    assert gaps[0] > gaps[1] > gaps[2] and gaps[2] < 1e-4


def kirchhoff(M_of_eta, eta, eta_dot, omega, v):
    """The quadratic velocity vector for (a_0, alpha, eta'') by Kirchhoff's equations,
    d/dt(dT/dv) + omega x dT/dv = F, d/dt(dT/domega) + omega x dT/domega + v x dT/dv = N,
    Lagrange's for eta, with T = 1/2 w^T M(eta) w and dM/deta by central differences
    (exact: M is quadratic in eta); v' is replaced by a_0 - omega x v."""
    n = len(eta)
    w = np.concatenate([v, omega, eta_dot])
    h = 1e-3
    dM = [(M_of_eta(eta + h * e) - M_of_eta(eta - h * e)) / (2 * h) for e in np.eye(n)]
    M = M_of_eta(eta)
    p = M @ w
    Mdot = sum(ed * d for ed, d in zip(eta_dot, dM))
    rhs = -Mdot @ w - np.concatenate([np.cross(omega, p[:3]),
                                      np.cross(omega, p[3:6]) + np.cross(v, p[:3]),
                                      [-0.5 * w @ d @ w for d in dM]])
    return rhs + M[:, :3] @ np.cross(omega, v)       # M [v'; ...] = M [a_0; ...] - M[:, :3] (w x v)


def test_quadratic_velocity_vector_against_kirchhoff_equations():
    nodes, modes, M_fe, points = random_lumped()
    inv = inertia_invariants(points)

    def direct(eta):
        L = node_map(nodes, modes, eta)
        return L.T @ M_fe @ L

    n = modes.shape[2]
    for _ in range(3):
        eta, eta_dot = RNG.normal(size=n), RNG.normal(size=n)
        omega, v = RNG.normal(size=3), RNG.normal(size=3)
        expected = kirchhoff(direct, eta, eta_dot, omega, v)
        got = quadratic_velocity_vector(inv, eta, eta_dot, omega)
        np.testing.assert_allclose(got, expected, rtol=1e-8, atol=1e-8 * np.abs(expected).max())


def test_a_node_mass_with_its_centre_off_the_node():
    """A 6 x 6 rigid-body mass about a node, [[m I, -m s~], [m s~, J_node]], becomes a
    point at x + s; at eta = 0 the mass matrix is the nodes' 6 x 6 blocks moved by the map."""
    N, n = 3, 2
    nodes, modes = RNG.normal(size=(N, 3)), RNG.normal(size=(N, 6, n))
    blocks = []
    for _ in range(N):
        m, s = RNG.uniform(1, 2), RNG.normal(size=3) * 0.1
        Jc = np.diag(RNG.uniform(0.1, 0.2, 3))
        S = skew(s)
        blocks.append(np.block([[m * np.eye(3), -m * S], [m * S, Jc - m * S @ S]]))
    M_fe = np.zeros((6 * N, 6 * N))
    for i, B in enumerate(blocks):
        M_fe[6 * i:6 * i + 6, 6 * i:6 * i + 6] = B
    inv = inertia_invariants(lumped_mass_points(nodes, np.array(blocks), modes))
    L = node_map(nodes, modes, np.zeros(n))
    np.testing.assert_allclose(floating_frame_mass_matrix(inv, np.zeros(n)), L.T @ M_fe @ L,
                               rtol=1e-12, atol=1e-12)


def test_rotating_cantilever_lag_softening_from_the_invariants():
    """Spin Omega about z through the root: flapwise (w) bending stiffens by the geometric
    stiffness alone (Southwell 1.1933), lagwise (v, in the plane of rotation) also
    softens by the centrifugal term of Q_v, 1/2 omega^T dJ/deta omega: coefficient
    1.1933 - 1 (Rayleigh quotients of the first modes)."""
    b = beam_from_spec({"length": 1.0, "elements": 16, "rect": [0.01, 0.015], "E": 70e9,
                        "rho": 2700.0, "theory": "euler-bernoulli"})
    body = craig_bampton(b, ("root",), n_modes=6)
    inv, n = body.invariants, body.n_modes
    omega = np.array([0.0, 0.0, 1.0])
    h = 1e-6
    softening = -np.array([(quadratic_velocity_vector(inv, h * e, np.zeros(n), omega)
                            - quadratic_velocity_vector(inv, -h * e, np.zeros(n), omega))[6:]
                           / (2 * h) for e in np.eye(n)]).T
    Kc = body.geometric_stiffness["centrifugal"]      # per unit omega_y^2 + omega_z^2
    tip = body.modes[b.node("tip")]
    planes = []
    for k in range(2):                    # the first two modes: one in v, one in w
        phi = np.eye(n)[k]
        coefficient = phi @ (Kc + softening) @ phi / (phi @ body.mass_matrix @ phi)
        in_plane = abs(tip[1, k]) > abs(tip[2, k])
        planes.append(in_plane)
        assert coefficient == pytest.approx(0.1933 if in_plane else 1.1933, abs=2e-4)
    assert sorted(planes) == [False, True]
