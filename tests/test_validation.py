"""Every validation error names the element at fault and says what to change.

Each test builds the smallest system that shows one mistake and checks, with
``pytest.raises(mb.ModelError, match=...)``, that the message names the element (by its
kind and name, e.g. ``joint 'hinge'``) and mentions the remedy.
"""
import math
import warnings

import numpy as np
import pytest
import sympy

import mbdyn as mb


def pendulum(name="pendulum"):
    """A valid one-body system to start each mistake from."""
    s = mb.System(name)
    s.add_body("bob", mass=1.0, com=(0.0, 0.0, -1.0))
    s.add_joint("hinge", "revolute", parent="ground", child="bob", axis="x")
    return s


def test_valid_base_system_compiles():
    model = pendulum().compile()
    assert model.coordinates == ("hinge",)
    assert model.warnings == ()


# ---------------------------------------------------------------------------- the tree
def test_cycle_is_refused():
    s = mb.System("loop")
    s.add_body("a", mass=1.0, com=(1, 0, 0))
    s.add_body("b", mass=1.0, com=(1, 0, 0))
    s.add_joint("ab", "revolute", parent="a", child="b", axis="z")
    # 'a' has no parent yet, but it is an ancestor of 'b': joining b -> a closes a loop
    with pytest.raises(mb.ModelError, match=r"joint 'ba'.*cycle.*tree"):
        s.add_joint("ba", "revolute", parent="b", child="a", axis="z")


def test_frame_with_two_parent_joints_is_refused():
    s = pendulum()
    s.add_body("arm", mass=1.0, com=(1, 0, 0))
    s.add_joint("j1", "revolute", parent="ground", child="arm", axis="z")
    with pytest.raises(mb.ModelError,
                       match=r"joint 'j2'.*'arm' already has a parent joint 'j1'.*child_position"):
        s.add_joint("j2", "revolute", parent="bob", child="arm", axis="z")


def test_closing_a_loop_through_a_hung_frame_is_refused():
    s = pendulum()
    with pytest.raises(mb.ModelError, match=r"joint 'back'.*ground cannot be a child.*swap"):
        s.add_joint("back", "revolute", parent="bob", child="ground", axis="z")


def test_frames_not_connected_to_ground_are_refused_at_compile():
    s = pendulum("floating")
    s.add_body("loose", mass=1.0)
    s.add_frame("loose_child")
    s.add_joint("jl", "fixed", parent="loose", child="loose_child")
    with pytest.raises(mb.ModelError,
                       match=r"system 'floating'.*loose.*not\s+connected to the ground.*add_joint"):
        s.compile()


def test_empty_system_is_refused():
    with pytest.raises(mb.ModelError, match=r"system 'empty'.*no bodies.*add bodies"):
        mb.System("empty").compile()


# ---------------------------------------------------------------------------- names
def test_duplicate_body_name_is_refused():
    s = pendulum()
    with pytest.raises(mb.ModelError, match=r"body/frame 'bob'.*already used.*choose another"):
        s.add_body("bob", mass=2.0)
    with pytest.raises(mb.ModelError, match=r"body/frame 'bob'.*already used.*choose another"):
        s.add_frame("bob")


def test_body_named_ground_is_refused():
    s = mb.System()
    with pytest.raises(mb.ModelError, match=r"'ground'.*ground frame.*choose another"):
        s.add_body("ground", mass=1.0)


def test_duplicate_joint_name_is_refused():
    s = pendulum()
    s.add_body("bob2", mass=1.0, com=(0, 0, -1))
    with pytest.raises(mb.ModelError, match=r"joint 'hinge'.*already used by another joint"):
        s.add_joint("hinge", "revolute", parent="bob", child="bob2", axis="x")


def test_duplicate_coordinate_names_are_refused():
    s = pendulum()
    s.add_body("bob2", mass=1.0, com=(0, 0, -1))
    with pytest.raises(mb.ModelError, match=r"joint 'hinge2'.*\['hinge', 'hinge_dot'\].*already used.*coordinates="):
        s.add_joint("hinge2", "revolute", parent="bob", child="bob2", axis="x",
                    coordinates="hinge")


@pytest.mark.parametrize("role", ["parent", "child"])
def test_unknown_parent_or_child_is_refused(role):
    s = pendulum()
    s.add_body("bob2", mass=1.0, com=(0, 0, -1))
    frames = {"parent": "bob", "child": "bob2"}
    frames[role] = "bobb"
    with pytest.raises(mb.ModelError,
                       match=rf"joint 'j'.*unknown {role} frame 'bobb'.*add_body or add_frame"):
        s.add_joint("j", "revolute", axis="x", **frames)


def test_unknown_kind_is_refused():
    s = pendulum()
    s.add_body("bob2", mass=1.0, com=(0, 0, -1))
    with pytest.raises(mb.ModelError, match=r"joint 'j'.*unknown kind 'hinge'.*'revolute'"):
        s.add_joint("j", "hinge", parent="bob", child="bob2", axis="x")


# ---------------------------------------------------------------------------- axes
def _one_more(s):
    s.add_body("bob2", mass=1.0, com=(0, 0, -1))
    return s


def test_zero_axis_is_refused():
    s = _one_more(pendulum())
    with pytest.raises(mb.ModelError, match=r"joint 'j'.*axis.*zero length.*'z'"):
        s.add_joint("j", "revolute", parent="bob", child="bob2", axis=(0, 0, 0))


@pytest.mark.parametrize("axis", [(0.0, math.nan, 1.0), (math.inf, 0.0, 0.0)])
def test_non_finite_axis_is_refused(axis):
    s = _one_more(pendulum())
    with pytest.raises(mb.ModelError, match=r"joint 'j'.*axis must be finite"):
        s.add_joint("j", "prismatic", parent="bob", child="bob2", axis=axis)


def test_bad_axis_name_is_refused():
    s = _one_more(pendulum())
    with pytest.raises(mb.ModelError, match=r"joint 'j'.*axis 'w'.*'x', 'y', 'z'"):
        s.add_joint("j", "revolute", parent="bob", child="bob2", axis="w")


@pytest.mark.parametrize("kind", ["revolute", "prismatic"])
def test_missing_axis_is_refused(kind):
    s = _one_more(pendulum())
    with pytest.raises(mb.ModelError, match=rf"joint 'j'.*{kind} joint needs an axis.*axis="):
        s.add_joint("j", kind, parent="bob", child="bob2")


def test_axis_on_a_joint_without_one_is_refused():
    s = _one_more(pendulum())
    with pytest.raises(mb.ModelError, match=r"joint 'j'.*spherical joint takes no axis.*remove"):
        s.add_joint("j", "spherical", parent="bob", child="bob2", axis="z")


# ---------------------------------------------------------------------------- masses
@pytest.mark.parametrize("mass", [-1.0, -1e-9])
def test_negative_mass_is_refused(mass):
    s = mb.System()
    with pytest.raises(mb.ModelError, match=r"body 'heavy'.*mass must be finite and >= 0"):
        s.add_body("heavy", mass=mass)


@pytest.mark.parametrize("mass", [math.nan, math.inf])
def test_non_finite_mass_is_refused(mass):
    s = mb.System()
    with pytest.raises(mb.ModelError, match=r"body 'heavy'.*mass must be finite"):
        s.add_body("heavy", mass=mass)


def test_non_numeric_mass_is_refused():
    s = mb.System()
    with pytest.raises(mb.ModelError, match=r"body 'heavy'.*mass must be a number"):
        s.add_body("heavy", mass="lots")


def test_non_finite_centre_of_mass_is_refused():
    s = mb.System()
    with pytest.raises(mb.ModelError, match=r"body 'heavy'.*com must be finite"):
        s.add_body("heavy", mass=1.0, com=(0, math.nan, 0))


# ---------------------------------------------------------------------------- inertia
def test_non_symmetric_inertia_is_refused():
    s = mb.System()
    I = [[1.0, 0.1, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]
    with pytest.raises(mb.ModelError, match=r"body 'rotor'.*not symmetric.*I\[i\]\[j\]"):
        s.add_body("rotor", mass=1.0, inertia=I)


@pytest.mark.parametrize("inertia", [
    (1.0, 1.0, -0.5),                                    # a negative principal moment
    [[1.0, 2.0, 0.0], [2.0, 1.0, 0.0], [0.0, 0.0, 1.0]],  # eigenvalues 3, -1, 1
])
def test_inertia_not_positive_semi_definite_is_refused(inertia):
    s = mb.System()
    with pytest.raises(mb.ModelError,
                       match=r"body 'rotor'.*not positive semi-definite.*cannot be negative"):
        s.add_body("rotor", mass=1.0, inertia=inertia)


def test_inertia_of_wrong_shape_or_non_finite_is_refused():
    s = mb.System()
    with pytest.raises(mb.ModelError, match=r"body 'rotor'.*inertia must be.*3x3"):
        s.add_body("rotor", mass=1.0, inertia=(1.0, 2.0))
    with pytest.raises(mb.ModelError, match=r"body 'rotor'.*inertia has non-finite"):
        s.add_body("rotor", mass=1.0, inertia=(1.0, math.nan, 1.0))


def test_triangle_inequality_is_a_warning_and_the_model_runs():
    s = mb.System("odd top")
    # principal moments 1, 1, 3 about the centre of mass: 1 + 1 < 3
    with pytest.warns(mb.ModelWarning,
                      match=r"body 'disk'.*triangle inequality.*Check the data"):
        s.add_body("disk", mass=1.0, com=(0, 0, 0.1), inertia=(1.0, 1.0, 3.0))
    s.add_joint("contact", "spherical", parent="ground", child="disk")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", mb.ModelWarning)
        model = s.compile()
    assert len(model.warnings) == 1
    assert "body 'disk'" in model.warnings[0] and "triangle inequality" in model.warnings[0]
    q = model.q_vector()
    u = np.array([0.1, 0.2, 5.0])
    ud = model.forward_dynamics(q, u)
    assert np.all(np.isfinite(ud))
    # with I = diag(1, 1, 3) about G and m h^2 = 0.01: Euler about O, no gravity moment at q=0
    # A' = 1.01 (x, y), C = 3: A' wx' = (A' - C) wy wz, A' wy' = (C - A') wz wx, wz' = 0
    A, C = 1.01, 3.0
    np.testing.assert_allclose(ud, [(A - C) * 0.2 * 5.0 / A, (C - A) * 5.0 * 0.1 / A, 0.0],
                               rtol=1e-12, atol=1e-14)
    res = mb.simulate(model, t_end=0.1, integrator="RK45")
    assert np.all(np.isfinite(res.q))


def test_a_well_posed_body_raises_no_warning():
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        s = mb.System()
        s.add_body("box", mass=2.0, inertia=mb.inertia.box(2.0, 0.1, 0.2, 0.3))
        s.add_joint("j", "spherical", parent="ground", child="box")
        assert s.compile().warnings == ()


# ---------------------------------------------------------------------------- singular M
def test_particle_on_its_own_revolute_axis_is_refused():
    """A particle on the axis of its revolute joint: that degree of freedom has no inertia."""
    s = pendulum("bead")
    s.add_body("bead", mass=1.0, com=(0.0, 0.0, 0.0))          # on the axis through its origin
    s.add_joint("spin", "revolute", parent="bob", child="bead", axis="z",
                position=(0.0, 0.0, -1.0))
    with pytest.raises(mb.ModelError,
                       match=r"system 'bead'.*degrees of freedom spin \(joint 'spin'\).*no "
                             r"inertia.*mass or inertia"):
        s.compile()


def test_massless_leaf_frame_is_refused():
    s = pendulum("ghost")
    s.add_frame("ghost")
    s.add_joint("slide", "prismatic", parent="bob", child="ghost", axis="y")
    with pytest.raises(mb.ModelError, match=r"system 'ghost'.*degrees of freedom slide \(joint 'slide'\).*no inertia"):
        s.compile()


def test_singular_mass_matrix_names_the_coordinates_at_evaluation():
    """Without the compile check the evaluation itself names the speeds."""
    s = pendulum("bead")
    s.add_body("bead", mass=1.0)
    s.add_joint("spin", "revolute", parent="bob", child="bead", axis="z")
    model = s.compile(check_inertia=False)
    with pytest.raises(mb.SingularMassMatrixError, match=r"degrees of freedom spin \(joint 'spin'\)") as e:
        model.forward_dynamics(model.q_vector(), model.u_vector())
    assert e.value.coordinates == ("spin_dot",)


def _long_chain_with_bead(bead_inertia):
    """A 45-link chain (past the size where LAPACK factorizes M) ending in a bead on a
    spin joint about its own axis: with no inertia about that axis M is singular."""
    from mbdyn.kernels.dynamics import LAPACK_CHOLESKY_FROM
    s = mb.System("long chain")
    parent = "ground"
    for i in range(45):
        s.add_body(f"link{i}", mass=1.0, com=(0.0, 0.0, -0.5), inertia=(0.1, 0.1, 0.02))
        s.add_joint(f"q{i}", "revolute", parent=parent, child=f"link{i}",
                    axis="x" if i % 2 else "y", position=(0.0, 0.0, -1.0 if i else 0.0))
        parent = f"link{i}"
    s.add_body("bead", mass=1.0, inertia=(1.0, 1.0, bead_inertia))
    s.add_joint("spin", "revolute", parent=parent, child="bead", axis="z",
                position=(0.0, 0.0, -1.0))
    model = s.compile(check_inertia=False)
    assert model.nu >= LAPACK_CHOLESKY_FROM
    return model


@pytest.mark.parametrize("bead_inertia", [0.0, 1e-30])
def test_singular_mass_matrix_of_a_large_model_names_the_coordinate(bead_inertia):
    """Zero inertia makes LAPACK's factorization fail; 1e-30 passes it with a pivot far
    below the matrix's scale -- both are reported, naming the speed."""
    model = _long_chain_with_bead(bead_inertia)
    rng = np.random.default_rng(0)
    q = rng.uniform(-1, 1, model.nq)
    with pytest.raises(mb.SingularMassMatrixError, match=r"degrees of freedom spin \(joint 'spin'\)"):
        model.forward_dynamics(q, np.zeros(model.nu))


def test_large_model_accelerations_solve_m_and_f():
    model = _long_chain_with_bead(0.01)
    rng = np.random.default_rng(1)
    q, u = rng.uniform(-1, 1, model.nq), rng.uniform(-1, 1, model.nu)
    ud = model.forward_dynamics(q, u)
    expected = np.linalg.solve(model.mass_matrix(q), model.forcing(q, u))
    assert np.allclose(ud, expected, rtol=1e-9, atol=1e-9 * np.abs(expected).max())


# ---------------------------------------------------------------------------- euler / drives
@pytest.mark.parametrize("sequence", ["ZZX", "XYY", "ZX", "ABC", "ZXZY"])
def test_bad_euler_sequence_is_refused(sequence):
    s = _one_more(pendulum())
    with pytest.raises(mb.ModelError,
                       match=rf"joint 'gimbal'.*sequence '{sequence}' is not valid.*'ZXZ'"):
        s.add_joint("gimbal", "euler", parent="bob", child="bob2", sequence=sequence)


def test_sequence_on_a_non_euler_joint_is_refused():
    s = _one_more(pendulum())
    with pytest.raises(mb.ModelError, match=r"joint 'j'.*only an euler joint takes a sequence"):
        s.add_joint("j", "spherical", parent="bob", child="bob2", sequence="ZXZ")


@pytest.mark.parametrize("kind", ["euler", "spherical", "free", "fixed"])
def test_drive_on_a_joint_that_is_not_1_dof_is_refused(kind):
    s = _one_more(pendulum())
    with pytest.raises(mb.ModelError,
                       match=rf"joint 'j'.*only a revolute or prismatic joint can be driven.*{kind}"):
        s.add_joint("j", kind, parent="bob", child="bob2", drive=2.0 * mb.t)


def test_drive_with_free_symbols_is_refused():
    s = _one_more(pendulum())
    Omega = sympy.Symbol("Omega")
    with pytest.raises(mb.ModelError, match=r"joint 'arm'.*symbols Omega besides t.*parameters"):
        s.add_joint("arm", "revolute", parent="bob", child="bob2", axis="z", drive=Omega * mb.t)


def test_drive_of_wrong_type_is_refused():
    s = _one_more(pendulum())
    with pytest.raises(mb.ModelError, match=r"joint 'arm'.*drive must be.*three callables"):
        s.add_joint("arm", "revolute", parent="bob", child="bob2", axis="z",
                    drive=(math.sin, math.cos))
    with pytest.raises(mb.ModelError, match=r"joint 'arm'.*drive must be.*three callables"):
        s.add_joint("arm", "revolute", parent="bob", child="bob2", axis="z", drive="fast")


def test_drive_of_a_declared_parameter_is_accepted():
    """The remedy the message proposes works: a parameter of the system."""
    s = mb.System(parameters={"Omega": 2.0})
    Omega = s.symbols("Omega")
    s.add_frame("arm")
    s.add_joint("arm", "revolute", parent="ground", child="arm", axis="z", drive=Omega * mb.t)
    s.add_body("bob", mass=1.0, com=(0, 0, -1))
    s.add_joint("hinge", "revolute", parent="arm", child="bob", axis="x", position=(1, 0, 0))
    model = s.compile()
    kin = model.kinematics([0.0], [0.0], t=0.3)
    np.testing.assert_allclose(kin.w[kin.frame("arm")], [0, 0, 2.0], atol=1e-15)


# ---------------------------------------------------------------------------- loads
def test_load_on_unknown_body_is_refused():
    s = pendulum()
    with pytest.raises(mb.ModelError, match=r"load 'push'.*unknown body 'bobb'.*add_body"):
        s.add_load("push", "bobb", force=(1, 0, 0))


def test_load_on_ground_is_refused():
    s = pendulum()
    with pytest.raises(mb.ModelError, match=r"load 'push'.*unknown body 'ground'"):
        s.add_load("push", "ground", force=(1, 0, 0))


def test_duplicate_load_name_is_refused():
    s = pendulum()
    s.add_load("push", "bob", force=(1, 0, 0))
    with pytest.raises(mb.ModelError, match=r"load 'push'.*already used"):
        s.add_load("push", "bob", force=(0, 1, 0))


def test_load_without_force_or_moment_and_bad_frame_are_refused():
    s = pendulum()
    with pytest.raises(mb.ModelError, match=r"load 'push'.*give a force, a moment or both"):
        s.add_load("push", "bob")
    with pytest.raises(mb.ModelError, match=r"load 'push'.*frame must be 'world' or 'body'"):
        s.add_load("push", "bob", force=(1, 0, 0), frame="local")
    with pytest.raises(mb.ModelError, match=r"load 'push'.*force must be three numbers"):
        s.add_load("push", "bob", force=(1, 0))


@pytest.mark.parametrize("bad", [lambda t, q, u: (1.0, 2.0), lambda t, q, u: np.zeros((2, 3))])
def test_load_function_returning_wrong_shape_is_refused(bad):
    s = pendulum()
    s.add_load("push", "bob", force=bad)
    with pytest.raises(mb.ModelError, match=r"load 'push'.*returned \d+ values.*must return three"):
        model = s.compile()        # the compile-time inertia check already evaluates it
        model.forward_dynamics(model.q_vector(), model.u_vector())


def test_load_function_returning_wrong_shape_is_refused_at_evaluation():
    s = pendulum()
    s.add_load("push", "bob", force=lambda t, q, u: (1.0, 2.0) if t > 1 else (0.0, 0.0, 0.0))
    model = s.compile()
    with pytest.raises(mb.ModelError, match=r"load 'push'.*returned 2 values at t=2.*three"):
        model.forward_dynamics(model.q_vector(), model.u_vector(), t=2.0)


# ---------------------------------------------------------------------------- states
def test_unknown_coordinate_names_are_refused():
    model = pendulum().compile()
    with pytest.raises(mb.ModelError, match=r"unknown coordinate 'hnige'.*hinge"):
        model.q_vector({"hnige": 0.1})
    with pytest.raises(mb.ModelError, match=r"unknown speed 'hnige'.*hinge_dot"):
        model.u_vector({"hnige": 0.1})
    # a coordinate's name stands for its rate, as in model files (issue 14)
    assert model.u_vector({"hinge": 0.1}) == pytest.approx([0.1])


def test_unknown_coordinate_names_in_simulate_are_refused():
    model = pendulum().compile()
    with pytest.raises(mb.ModelError, match=r"unknown coordinate 'theta'.*hinge"):
        mb.simulate(model, t_end=0.1, q0={"theta": 0.1})
    with pytest.raises(mb.ModelError, match=r"unknown speed 'theta_dot'.*hinge_dot"):
        mb.simulate(model, t_end=0.1, u0={"theta_dot": 0.1})


def test_state_of_wrong_length_is_refused():
    model = pendulum("short").compile()
    with pytest.raises(mb.ModelError, match=r"expected 1 coordinates \(hinge\), got 2"):
        model.q_vector([0.1, 0.2])
    with pytest.raises(mb.ModelError, match=r"model 'short' expects q of length 1"):
        model.forward_dynamics([0.1, 0.2], [0.0])


def test_unknown_method_is_refused():
    model = pendulum().compile()
    with pytest.raises(mb.ModelError, match=r"unknown method 'lagrangian'.*jourdain"):
        model.forward_dynamics([0.1], [0.0], method="lagrangian")


# ---------------------------------------------------------------------------- orientation
@pytest.mark.parametrize("orientation, message", [
    (np.diag([1.0, 1.0, 2.0]), r"not a proper rotation.*C\^T C = I"),
    (np.diag([1.0, 1.0, -1.0]), r"not a proper rotation.*det C = \+1"),    # a reflection
    ([[0.0, 1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]], r"not a proper rotation"),
    ((1.0, 1.0, 0.0, 0.0), r"quaternion.*unit\s+length.*normalise"),
    (np.ones((2, 2)), r"orientation must be a 3x3 rotation matrix"),
    (np.full((3, 3), math.nan), r"orientation must be a 3x3 rotation matrix"),
])
def test_bad_orientation_is_refused(orientation, message):
    s = _one_more(pendulum())
    with pytest.raises(mb.ModelError, match=r"joint 'j'.*" + message):
        s.add_joint("j", "revolute", parent="bob", child="bob2", axis="z",
                    orientation=orientation)


def test_bad_orientation_axis_is_refused():
    s = _one_more(pendulum())
    with pytest.raises(mb.ModelError, match=r"joint 'j' orientation.*zero length"):
        s.add_joint("j", "revolute", parent="bob", child="bob2", axis="z",
                    orientation=((0, 0, 0), 0.5))


def test_non_finite_position_is_refused():
    s = _one_more(pendulum())
    with pytest.raises(mb.ModelError, match=r"joint 'j'.*position must be finite"):
        s.add_joint("j", "revolute", parent="bob", child="bob2", axis="z",
                    position=(0, math.inf, 0))


# ---------------------------------------------------------------------------- parameters
def test_undeclared_parameter_in_symbols_is_refused():
    s = mb.System("sym", parameters={"m": 1.0})
    with pytest.raises(mb.ModelError, match=r"system 'sym'.*\bl\b.*not parameters.*declared: m"):
        s.symbols("m l")


def test_undeclared_symbol_in_a_body_is_refused():
    s = mb.System("sym", parameters={"m": 1.0})
    l = sympy.Symbol("l", real=True)
    with pytest.raises(mb.ModelError,
                       match=r"body 'bob'.*com uses l.*not parameters.*System\(parameters="):
        s.add_body("bob", mass=s.symbols("m"), com=(0, 0, -l))


def test_undeclared_symbol_in_a_joint_is_refused():
    s = mb.System("sym", parameters={"m": 1.0})
    s.add_body("bob", mass=1.0, com=(0, 0, -1))
    a = sympy.Symbol("a", real=True)
    with pytest.raises(mb.ModelError, match=r"joint 'hinge'.*position uses a.*not parameters"):
        s.add_joint("hinge", "revolute", parent="ground", child="bob", axis="x",
                    position=(0, 0, a))


def test_undeclared_symbol_in_gravity_is_refused():
    g = sympy.Symbol("g")
    with pytest.raises(mb.ModelError, match=r"system 'sym'.*gravity uses g.*parameters"):
        mb.System("sym", gravity=(0, 0, -g))


def test_undeclared_symbol_in_a_load_expression_is_refused():
    s = pendulum("sym")
    k = sympy.Symbol("k")
    s.add_load("spring", "bob", moment=(-k * sympy.Symbol("hinge"), 0, 0))
    with pytest.raises(mb.ModelError, match=r"load 'spring'.*uses k.*neither t nor coordinates"):
        s.compile()


def test_bad_parameter_declarations_are_refused():
    with pytest.raises(mb.ModelError, match=r"system 'p'.*parameter 'm' must be a number"):
        mb.System("p", parameters={"m": "heavy"})
    with pytest.raises(mb.ModelError, match=r"system 'p'.*parameter name '2m'.*identifier"):
        mb.System("p", parameters={"2m": 1.0})


def test_declared_parameters_are_substituted():
    s = mb.System("sym", parameters={"m": 2.0, "l": 0.5})
    m, l = s.symbols("m l")
    s.add_body("bob", mass=m, com=(0, 0, -l))
    s.add_joint("hinge", "revolute", parent="ground", child="bob", axis="x")
    model = s.compile()
    assert model.body("bob").mass == 2.0
    # a simple pendulum: theta'' = -(g/l) sin(theta)
    np.testing.assert_allclose(model.forward_dynamics([0.3], [0.0]), [-9.81 / 0.5 * math.sin(0.3)],
                               rtol=1e-12)
