"""mbdyn.symbolic: the three methods agree with each other (symbolically on small models)
and with the numeric engine (numerically at random states, every model), reports and the
JSON contract."""
import json
import warnings
from pathlib import Path

import pytest
import sympy as sp

import mbdyn as mb
from mbdyn.symbolic import (compare_methods, compare_numerically, derive, random_states,
                            same_expression, same_matrix)

MODELS = Path(__file__).resolve().parent.parent / "models"
TOL = 1e-10


def double_pendulum(axis="-z"):
    """The textbook's double pendulum (1.4.2) with its symbols as parameters; the angles
    turn about -z as in the listing (x1 = -l1 sin t1)."""
    params = {"m1": 0.00046, "m2": 0.0046, "l1": 0.07, "l2": 0.07, "g": 9.81}
    g = sp.Symbol("g", real=True)
    s = mb.System("double pendulum", gravity=(0, -g, 0), parameters=params)
    m1, m2, l1, l2 = s.symbols("m1 m2 l1 l2")
    s.add_body("link1", mass=m1, com=(0, -l1, 0))
    s.add_joint("theta1", "revolute", parent="ground", child="link1", axis=axis)
    s.add_body("link2", mass=m2, com=(0, -l2, 0))
    s.add_joint("theta2", "revolute", parent="link1", child="link2", axis=axis,
                position=(0, -l1, 0))
    return s


def kitchen_sink(quaternions=True):
    """Every joint kind, a driven prismatic joint along a skew axis, joint frames placed
    with every orientation form, full inertia tensors, loads as expressions of t, q and u in
    world and body components at points off the centre of mass."""
    s = mb.System("kitchen sink", gravity=(0.3, -1.0, -9.81),
                  parameters={"m": 1.5, "k": 2.0, "L": 0.4, "c": 0.3})
    m, k, L, c = s.symbols("m k L c")
    x, x_dot, w = sp.symbols("x x_dot arm_1_dot")
    s.add_frame("carriage")
    s.add_joint("drive", "prismatic", parent="ground", child="carriage", axis=(1, 1, 0),
                drive=sp.Rational(1, 5) * sp.sin(2 * mb.t))
    s.add_body("slider", mass=m, com=(0.1, 0, 0), inertia=(0.01, 0.02, 0.03))
    s.add_joint("x", "prismatic", parent="carriage", child="slider", axis="y",
                position=(0, 0.1, 0), orientation=("z", sp.pi / 6))
    s.add_body("arm", mass=0.7, com=(0, 0, -L / 2),
               inertia=[[0.02, 0.001, 0], [0.001, 0.03, 0.002], [0, 0.002, 0.01]])
    s.add_joint("arm", "euler", parent="slider", child="arm", sequence="XYZ",
                position=(0, 0, L))
    s.add_body("ball", mass=0.4, com=(0.05, 0, -0.1), inertia=(0.001, 0.001, 0.002))
    if quaternions:
        s.add_joint("ball", "spherical", parent="arm", child="ball", position=(0, 0, -L))
    else:
        s.add_joint("ball", "revolute", parent="arm", child="ball", axis=(0, 1, 1),
                    position=(0, 0, -L))
    s.add_body("tip", mass=0.2, com=(0, 0.02, 0), inertia=(0.0005, 0.0004, 0.0003))
    s.add_joint("weld", "fixed", parent="ball", child="tip", position=(0, 0, -0.1),
                orientation=(0.9238795325112867, 0.0, 0.3826834323650898, 0.0))
    s.add_load("spring", "slider", force=(0, -k * x - c * x_dot, 0), frame="body")
    s.add_load("push", "tip", force=(sp.cos(mb.t), 0, 0.5), point=(0.01, 0, 0.02))
    s.add_load("twist", "arm", moment=(0, 0, -sp.Rational(1, 10) * w), frame="body")
    return s


@pytest.fixture(scope="module")
def dp_model():
    return double_pendulum().compile()


@pytest.fixture(scope="module")
def dp_all(dp_model):
    return {m: derive(dp_model, m) for m in ("newton-euler", "jourdain", "lagrange")}


# ----------------------------------------------------------------------------- symbolic
def test_methods_are_the_same_equations_symbolically(dp_all):
    assert all(compare_methods(dp_all.values()).values())


def test_one_moving_frame_or_two_same_equations_but_longer(dp_model):
    own = derive(dp_model, "jourdain", simplify="none")
    one = derive(dp_model, "jourdain", frames="inertial", simplify="none")
    assert same_matrix(own.mass_matrix, one.mass_matrix)
    assert same_matrix(own.forcing, one.forcing)
    # the text's point: well-chosen moving frames keep the raw expressions short
    assert own.stats["operations"] < 0.5 * one.stats["operations"]


def test_mass_matrix_of_double_pendulum(dp_model):
    d = derive(dp_model, "jourdain")
    n = d.names()
    m1, m2, l1, l2, t2 = (n[k] for k in ("m1", "m2", "l1", "l2", "theta2"))
    expected = sp.Matrix([[(m1 + m2) * l1**2 + m2 * l2**2 + 2 * m2 * l1 * l2 * sp.cos(t2),
                           m2 * l2**2 + m2 * l1 * l2 * sp.cos(t2)],
                          [m2 * l2**2 + m2 * l1 * l2 * sp.cos(t2), m2 * l2**2]])
    assert same_matrix(d.mass_matrix, expected)
    assert d.coordinates == ("theta1", "theta2")
    assert [s.name for s in d.rates] == ["theta1_ddot", "theta2_ddot"]


def test_top_methods_agree_and_spin_drops_out():
    s = mb.System("top", parameters={"m": 0.582, "h": 0.0558, "A": 0.00209393, "C": 0.0022058,
                                     "Mz": -0.025})
    m, h, A, C, Mz = s.symbols("m h A C Mz")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        s.add_body("top", mass=m, com=(0, 0, h), inertia=(A - m * h**2, A - m * h**2, C))
    s.add_joint("contact", "euler", parent="ground", child="top", sequence="ZXZ",
                coordinates=("psi", "theta", "phi"))
    s.add_load("Mz", "top", moment=(0, 0, Mz), frame="body")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        model = s.compile()
    ds = [derive(model, m) for m in ("newton-euler", "jourdain", "lagrange")]
    assert all(compare_methods(ds).values())
    phi = ds[0].names()["phi"]
    assert all(phi not in e.free_symbols for e in ds[1].mass_matrix)   # sin^2+cos^2 = 1
    for d in ds:
        assert max(compare_numerically(d).values()) < TOL


# ----------------------------------------------------------------------------- numeric
#: model files whose flexible bodies the symbolic layer refuses (16 modes; a force element
#: at a node, the run-up's damper: its documented limits, docs/flexible.md;
#: tests/test_symbolic_flexible.py)
REFUSED = ("jeffcott_flexible", "flexible_rotor_runup")


def _model_files():
    """The model files the symbolic layer knows."""
    files = sorted(MODELS.glob("*.toml")) if MODELS.is_dir() else []
    return [p for p in files if p.stem not in REFUSED]


def _closed_form(el):
    from mbdyn.elements.tables import Table
    p = el.params
    if el.kind == "shape-contact":
        return False
    if el.kind == "actuator":
        return not (p["type"] in ("pid", "held") or p.get("gravity_compensation")
                    or any(isinstance(p.get(k), Table) for k in ("value", "setpoint",
                                                                 "command")))
    return True


@pytest.mark.parametrize("path", _model_files(), ids=lambda p: p.stem)
def test_every_model_file_agrees_with_the_engine(path):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        scene = mb.load_model(path)
    # what has no closed form (contact between shapes; PIDs, gravity compensation and
    # tables of actuators) is refused by the symbolic layer: the rest must agree
    off = [el.name for el in scene.model._force_elements if not _closed_form(el)]
    model = scene.system.compile(effects=[f"-{n}" for n in off]) if off else scene.model
    quaternions = any(j.kind in ("spherical", "free") for j in model.elements[1])
    states = random_states(model, 3)
    methods = ("jourdain", "newton-euler") if quaternions else ("jourdain", "newton-euler",
                                                                  "lagrange")
    for method in methods:
        err = compare_numerically(derive(model, method, measure=False), states)
        assert max(err.values()) < TOL, (method, err)


@pytest.mark.parametrize("quaternions", [True, False])
def test_kitchen_sink_agrees_with_the_engine(quaternions):
    model = kitchen_sink(quaternions).compile()
    states = random_states(model, 3, seed=5)
    methods = ("jourdain", "newton-euler") + (() if quaternions else ("lagrange",))
    for method in methods:
        err = compare_numerically(derive(model, method, measure=False), states)
        assert max(err.values()) < TOL, (method, err)


def test_inertial_frames_agree_with_the_engine():
    model = kitchen_sink(True).compile()
    d = derive(model, "jourdain", frames="inertial", measure=False)
    assert max(compare_numerically(d, random_states(model, 2, seed=9)).values()) < TOL


def test_random_trees_agree_with_the_engine():
    import sys
    sys.path.insert(0, str(Path(__file__).parent))
    from random_trees import random_tree
    # two-frame trees with random placements, axes, inertias and gravity: revolute +
    # spherical, a driven revolute + prismatic, revolute + euler
    for seed, methods in ((2, ("jourdain", "newton-euler")), (6, ("jourdain", "lagrange")),
                          (10, ("jourdain",))):
        tree = random_tree(seed, 2, loads=False)
        states = [(tree.q, tree.u, tree.t)] + random_states(tree.model, 1, seed=seed)
        for method in methods:
            err = compare_numerically(derive(tree.model, method, measure=False), states)
            assert max(err.values()) < TOL, (seed, method, err)


def test_solved_accelerations_and_reactions_agree_with_the_engine(dp_model):
    d = derive(dp_model, "newton-euler", solve=True)
    err = compare_numerically(d, what=("accelerations", "reactions"))
    assert max(err.values()) < TOL, err


def test_inertial_reactions_agree_with_the_engine(dp_model):
    d = derive(dp_model, "newton-euler", frames="inertial", solve=True)
    assert compare_numerically(d, what=("reactions",))["reactions"] < TOL


# ----------------------------------------------------------------------------- refusals
def test_lagrange_refuses_quaternion_joints():
    with pytest.raises(mb.ModelError, match="Lagrange"):
        derive(kitchen_sink(True).compile(), "lagrange")


def test_python_function_loads_are_refused():
    s = double_pendulum()
    s.add_load("f", "link2", force=lambda t, q, u: (1.0, 0.0, 0.0))
    with pytest.raises(mb.ModelError, match="Python function"):
        derive(s, "jourdain")


def test_unknown_method_is_refused(dp_model):
    with pytest.raises(mb.ModelError, match="unknown method"):
        derive(dp_model, "kane")


# ----------------------------------------------------------------------------- reports
def test_json_contract_and_parseable(dp_model):
    d = derive(dp_model, "newton-euler", solve=True)
    obj = json.loads(d.to_json())
    assert set(obj) == {"method", "coordinates", "speeds", "mass_matrix", "forcing",
                        "accelerations", "reactions", "constraints", "stats"}
    assert obj["constraints"] is None                   # a tree: no loop joints
    assert set(obj["stats"]) == {"derive_s", "operations", "operations_after_cse"}
    names = {n: sp.Symbol(n) for n in d.names()}
    plain = {v: sp.Symbol(k) for k, v in d.names().items()}
    assert obj["method"] == "newton-euler" and obj["coordinates"] == ["theta1", "theta2"]
    for r in range(2):
        for c in range(2):
            e = sp.sympify(obj["mass_matrix"][r][c], locals=names)
            assert same_expression(e, d.mass_matrix[r, c].xreplace(plain))
        assert same_expression(sp.sympify(obj["forcing"][r], locals=names),
                               d.forcing[r].xreplace(plain))
    for s, text in obj["accelerations"].items():
        assert same_expression(sp.sympify(text, locals=names),
                               d.accelerations[s].xreplace(plain))
    assert set(obj["reactions"]) == {"theta1", "theta2"}
    for j, comps in obj["reactions"].items():
        assert len(comps) == 6
        for text, e in zip(comps, d.reactions[j]):
            assert same_expression(sp.sympify(text, locals=names), e.xreplace(plain))
    obj = derive(dp_model, "jourdain").to_dict()
    assert obj["accelerations"] is None and obj["reactions"] is None


def test_steps_read_like_the_textbook(dp_model):
    text = derive(dp_model, "newton-euler", solve=True).to_text(steps=True)
    order = ["Reference frames", "Transformation matrices", "Position vectors",
             "Angular velocities and accelerations", "Velocities and accelerations",
             "Mass and inertia", "Linear and angular momentum", "Applied forces and moments",
             "Reaction forces and moments", "Newton-Euler equations",
             "Equations of motion M(q) u' = f", "Solution"]
    pos = [text.index(t) for t in order]
    assert pos == sorted(pos)
    assert "B2 omega_2 = [0, 0, -(theta1_dot + theta2_dot)]" in text
    assert "T_2 (B1 -> B2)" in text and "B2 a_G2 = [" in text
    for method, heading in (("jourdain", "Jacobians of translation and rotation"),
                            ("lagrange", "Energies and generalized forces")):
        assert heading in derive(dp_model, method).to_text(steps=True)


def test_latex_and_markdown(dp_model):
    d = derive(dp_model, "jourdain", solve=True)
    tex = d.to_latex(steps=True)
    assert tex.startswith("\\documentclass") and tex.rstrip().endswith("\\end{document}")
    assert "\\ddot{\\theta_{1}}" in tex
    md = d.to_markdown()
    assert "$$" in md and md.startswith("# ")
    json.loads(d.to_json(steps=True))            # steps serialise too
