"""Loads and force elements at nodes of flexible bodies (algorithms/flexible_forces.py),
each against an independent route: the cantilever's closed form, finite differences of
the potential, an energy balance, the linear modal forces by hand."""
import math

import numpy as np
import pytest

import mbdyn as mb
from mbdyn.analysis.equilibrium import equilibrium
from mbdyn.errors import ModelError

E, D, L, RHO = 2.1e11, 0.02, 1.0, 7850.0
I = math.pi * D ** 4 / 64


def cantilever(modes, theory="euler-bernoulli", gravity=(0, 0, 0)):
    s = mb.System("cantilever", gravity=gravity)
    s.add_body("shaft", flexible={"beam": {"theory": theory, "length": L, "elements": 10,
                                           "E": E, "rho": RHO, "nu": 0.3,
                                           "section": {"circle": D}}, "modes": modes})
    s.add_joint("clamp", "fixed", "ground", "shaft")
    return s


def test_static_tip_load_against_the_cantilever_closed_form():
    """A point load P at the tip (a node by name): w = P L^3 / 3 E I; with every mode
    kept (60: the whole Euler-Bernoulli model, exact for a tip load) to round-off, with
    four to the modal truncation's 0.5 %."""
    P = 100.0
    exact = -P * L ** 3 / (3 * E * I)
    for modes, tol in ((60, 1e-9), (4, 5e-3)):
        s = cantilever(modes)
        s.add_load("tip", "shaft", force=(0, 0, -P), point="tip")
        m = s.compile()
        q = equilibrium(m, np.zeros(m.nq), np.zeros(m.nu), tol=1e-13).q
        w = m.flexible["shaft"].reduced.modes[-1, 2] @ q
        assert w == pytest.approx(exact, rel=tol)
        assert m.node_row("shaft.tip.z", m.coordinates) @ q == pytest.approx(w, rel=1e-12)


def test_a_body_load_in_body_axes_and_an_expression_load():
    """A load given in body components on a frame turned 90 degrees about x acts along
    the turned axis; a load that is an expression of t equals the constant at that t."""
    s = mb.System("turned", gravity=(0, 0, 0))
    s.add_body("shaft", flexible={"beam": {"theory": "euler-bernoulli", "length": L,
                                           "elements": 4, "E": E, "rho": RHO, "nu": 0.3,
                                           "circle": D}, "modes": 6})
    s.add_joint("clamp", "fixed", "ground", "shaft", orientation=[[1, 0, 0], [0, 0, -1], [0, 1, 0]])
    s.add_load("push", "shaft", force=(0, 0, -5.0), point="tip", frame="body")
    m = s.compile()
    red = m.flexible["shaft"].reduced
    f = m.forcing(np.zeros(m.nq), np.zeros(m.nu))
    np.testing.assert_allclose(f, red.modes[-1, 2] * -5.0, rtol=1e-12, atol=1e-12)
    t = mb.System("timed", gravity=(0, 0, 0), parameters={"a": 2.0})
    t.add_body("shaft", flexible={"beam": {"theory": "euler-bernoulli", "length": L,
                                           "elements": 4, "E": E, "rho": RHO, "nu": 0.3,
                                           "circle": D}, "modes": 6})
    t.add_joint("clamp", "fixed", "ground", "shaft")
    import sympy
    tt = sympy.Symbol("t")
    t.add_load("push", "shaft", force=(0, sympy.Symbol("a") * sympy.sin(tt), 0), point="tip")
    mt = t.compile()
    f = mt.forcing(np.zeros(mt.nq), np.zeros(mt.nu), t=0.3)
    np.testing.assert_allclose(f, red.modes[-1, 1] * 2.0 * math.sin(0.3), rtol=1e-12,
                               atol=1e-12)


def _potential(m, q):
    """The potential energy: the bodies' (strain) and the force elements'."""
    u = np.zeros(m.nu)
    return m.energy(q, u)[1] + m.element_power(q, u)[0]


def test_spring_at_a_point_off_the_nodes_is_the_gradient_of_its_potential():
    """A spring from a point off the beam (tied to its nearest node through the node's
    rotation) to the ground: the generalised forces are -dV/deta by central
    differences."""
    s = cantilever(6)
    s.add_force("spring", "spring-damper", body_a="shaft", point_a=[0.53, 0.01, 0.0],
                point_b=[0.6, 0.3, -0.2], stiffness=5e3, free_length=0.1, preload=20.0)
    m = s.compile()
    q = np.random.default_rng(1).normal(size=m.nq) * 1e-3
    f = m.forcing(q, np.zeros(m.nu))
    h = 1e-7
    grad = np.array([(_potential(m, q + h * e) - _potential(m, q - h * e)) / (2 * h)
                     for e in np.eye(m.nq)])
    np.testing.assert_allclose(f, -grad, rtol=1e-7, atol=1e-7 * np.abs(f).max())


def test_energy_balance_with_a_damper_at_a_node():
    """A spring-damper at a node: T + V + what the damper took stays constant (1e-9),
    and the damper takes energy out."""
    s = cantilever(6)
    s.add_force("damper", "spring-damper", body_a="shaft", point_a="tip",
                point_b=[1.0, 0.0, -0.3], stiffness=2e3, free_length=0.25, damping=5.0)
    m = s.compile()
    res = mb.simulate(m, 0.02, {"shaft_m1": 1e-3}, rtol=1e-11, atol=1e-14,
                      outputs=["energy"], t_eval=np.linspace(0, 0.02, 2001))
    assert res.stats["energy_drift"] < 1e-9
    assert res.energy["dissipated"][-1] > 1e-3 * abs(res.energy["total"][0])


def test_bushing_and_bearing_at_nodes_give_the_modal_forces_by_hand():
    """Linear elements at small deflection: a bushing to the ground at the tip gives
    ``-(Phi^T K_t Phi + Psi^T K_r Psi) eta``; a bearing at the middle node
    ``-Phi_yz^T (K_b [y, z] + C_b [y', z'])`` with its cross-coupled coefficients."""
    Kt, Kr = np.array([1e5, 2e5, 3e5]), np.array([4e3, 5e3, 6e3])
    kb = dict(kxx=1e6, kxy=3e5, kyx=-2e5, kyy=2e6, cxx=50.0, cxy=10.0, cyx=10.0, cyy=80.0)
    s = cantilever(6)
    s.add_force("mount", "bushing", body_a="shaft", point_a="tip", body_b="ground",
                point_b=[L, 0, 0], stiffness=np.concatenate([Kt, Kr]).tolist())
    s.add_force("bearing", "bearing", body="shaft", point=[0.5, 0, 0], center=[0.5, 0, 0],
                axis="x", **kb)
    m = s.compile()
    red = m.flexible["shaft"].reduced
    rng = np.random.default_rng(2)
    eta, eta_dot = rng.normal(size=m.nq) * 1e-7, rng.normal(size=m.nu) * 1e-4
    Phi, Psi = red.modes[-1, :3], red.modes[-1, 3:]
    Pm = red.modes[5, 1:3]                                   # node at x = 0.5: v, w
    Kb = np.array([[kb["kxx"], kb["kxy"]], [kb["kyx"], kb["kyy"]]])
    Cb = np.array([[kb["cxx"], kb["cxy"]], [kb["cyx"], kb["cyy"]]])
    by_hand = (-red.stiffness_matrix @ eta - Phi.T @ (Kt * (Phi @ eta))
               - Psi.T @ (Kr * (Psi @ eta)) - Pm.T @ (Kb @ Pm @ eta + Cb @ Pm @ eta_dot))
    # the bushing acts at b's point (the ground's, not the deflected tip): its moment
    # arm is second order, as is the rotation's
    np.testing.assert_allclose(m.forcing(eta, eta_dot), by_hand, rtol=1e-5,
                               atol=1e-9 * np.abs(by_hand).max())


def test_points_by_node_name_and_by_position_are_the_same_point():
    s = cantilever(4)
    s.add_force("a", "spring-damper", body_a="shaft", point_a="tip", point_b=[1, 0, -0.5],
                stiffness=100.0)
    s2 = cantilever(4)
    s2.add_force("a", "spring-damper", body_a="shaft", point_a=[L, 0, 0],
                 point_b=[1, 0, -0.5], stiffness=100.0)
    q = np.full(4, 1e-3)
    np.testing.assert_array_equal(s.compile().forcing(q, q), s2.compile().forcing(q, q))
    assert s.forces["a"].params["point_a"].tolist() == [L, 0.0, 0.0]


def test_bad_points_and_elements_at_flexible_bodies_are_named():
    s = cantilever(4)
    with pytest.raises(ModelError, match="force 'a': point_a: no node named 'nose'"):
        s.add_force("a", "spring-damper", body_a="shaft", point_a="nose", stiffness=1.0)
    s.add_body("box", mass=1.0, inertia=[1, 1, 1])
    s.add_joint("slide", "prismatic", "ground", "box", axis="z")
    with pytest.raises(ModelError, match="force 'b': point_a = 'tip' names a node, but "
                                         "'box' is not a flexible body"):
        s.add_force("b", "spring-damper", body_a="box", point_a="tip", stiffness=1.0)
    with pytest.raises(ModelError, match="load 'c': point: no node named 'nose'"):
        s.add_load("c", "shaft", force=(0, 0, 1), point="nose")
    s.add_force("d", "spring-damper", body_a="shaft", point_a="tip", body_b="box",
                law=lambda x, v: x ** 3)
    with pytest.raises(ModelError, match="force 'd': laws and tables of a spring-damper at "
                                         "a flexible body are not there yet"):
        s.compile()


def test_flexibility_off_puts_the_elements_back_in_the_compiled_tree():
    """Off, the body is rigid and the same elements act at the nodes' rest positions, in
    the kernels: a spring between the tip node and a sliding box."""
    s = cantilever(4)
    s.add_body("box", mass=2.0, inertia=[1, 1, 1])
    s.add_joint("slide", "prismatic", "ground", "box", axis="z", position=[L, 0, -0.5])
    s.add_force("a", "spring-damper", body_a="shaft", point_a="tip", body_b="box",
                stiffness=100.0, free_length=0.4)
    rigid = s.compile(effects="-flexibility_shaft")
    flexible = s.compile()
    assert "a" in rigid.forces and "a" in flexible.forces
    f_rigid = rigid.forcing([0.02], [0.0])
    f_flex = flexible.forcing(np.r_[0.02, np.zeros(4)], np.zeros(5))
    assert f_flex[0] == pytest.approx(f_rigid[0], rel=1e-12)
    assert f_rigid[0] == pytest.approx(100.0 * (0.48 - 0.4), rel=1e-12)   # pulls it up
