"""Flexible bodies in the symbolic layer (docs/flexible.md, "The equations in closed
form"): the equations by Jourdain, Newton-Euler and Lagrange, their inertia invariants as
named symbols, against the numeric engine at random states (M and f, the accelerations,
the reactions) and against each other symbolically; every format of ``mbdyn eom``; the
limits, each refused by name."""
from __future__ import annotations

import json
import warnings
from pathlib import Path

import numpy as np
import pytest
import sympy

import mbdyn as mb
from mbdyn.cli import main
from mbdyn.errors import ModelError
from mbdyn.symbolic import compare_methods, compare_numerically, derive

MODELS = Path(__file__).resolve().parents[1] / "models"
PENDULUM = MODELS / "flexible_pendulum.toml"
TOL = 1e-10
EB = {"length": 1.0, "elements": 4, "E": 7e10, "rho": 2700.0, "nu": 0.3,
      "rect": [0.03, 0.02], "theory": "euler-bernoulli"}


def _states(m, n=4, seed=2, modal=1e-2):
    """Random states: tree coordinates of order one, modal ones small (the reduced
    model's range), unit quaternions; ``t`` in [0, 1]."""
    rng = np.random.default_rng(seed)
    out = []
    modal_q = [m.coordinate_index(c) for c in m.modal_coordinates]
    for _ in range(n):
        q = m.default_coordinates() + rng.uniform(-1.0, 1.0, m.nq)
        q[modal_q] *= modal
        m.normalize_quaternions(q)
        out.append((q, rng.uniform(-1.0, 1.0, m.nu), float(rng.uniform(0, 1))))
    return out


def _pinned(modes=2, **kw):
    s = mb.System("pinned beam", gravity=(0, -9.81, 0.3))
    s.add_body("beam", flexible={"beam": EB, "modes": modes, "damping": 0.02}, **kw)
    s.add_joint("pin", "revolute", "ground", "beam", axis="z")
    return s


def _cantilever():
    s = mb.System("cantilever", gravity=(0.5, 0, -9.81))
    s.add_body("shaft", flexible={"beam": {**EB, "rect": [0.02, 0.02]}, "modes": 2})
    s.add_joint("clamp", "fixed", "ground", "shaft", orientation=("y", 0.3))
    return s.compile()


def _on_a_link():
    """A rigid link on a pin, the beam pinned at its end on a skew axis, with a rigid part
    off its axis: the frame's origin moves (stiffening off: its axial term would couple
    the accelerations)."""
    s = mb.System("beam on a link", gravity=(0, -9.81, 0))
    s.add_body("link", mass=0.7, com=(0.1, 0, 0), inertia=[1e-3, 2e-3, 2e-3])
    s.add_joint("a", "revolute", "ground", "link", axis="z")
    s.add_body("beam", flexible={"beam": EB, "modes": 2}, mass=0.2, com=(0.3, 0.02, 0.0),
               inertia=[1e-4, 1e-4, 1e-4])
    s.add_joint("b", "revolute", "link", "beam", axis=(0.0, 0.3, 1.0),
                position=(0.2, 0, 0))
    return s.compile(effects="-geometric_stiffening")


def _spun():
    """A blade spun by a drive about z: centrifugal and axial stiffening, the drive's
    acceleration in the bias."""
    s = mb.System("spun blade", gravity=(0, 0, -9.81))
    s.add_body("blade", flexible={"beam": EB, "modes": 2})
    s.add_joint("hub", "revolute", "ground", "blade", axis="z",
                drive=3 * mb.t + 2 * mb.t ** 2)
    return s.compile()


def _floating():
    s = mb.System("floating beam", gravity=(0, 0, -9.81))
    s.add_body("beam", flexible={"beam": EB, "modes": 1})
    s.add_joint("float", "free", "ground", "beam")
    return s.compile(effects="-geometric_stiffening")


def _rotor():
    """A shaft's four rigid lateral modes in a frame that does not spin, a disk's polar
    inertia giving the spin's gyroscopic matrix; held by nothing but inertia."""
    s = mb.System("rotor", gravity=(0, 0, 0))
    s.add_body("shaft", flexible={
        "reduction": "lateral", "modes": 4, "spin": 50.0,
        "beam": {"length": 0.6, "elements": 4, "E": 2.1e11, "rho": 7850.0, "nu": 0.3,
                 "circle": 0.03, "masses": [{"at": 0.3, "mass": 5.0, "polar": 0.05,
                                             "diametral": 0.03}]}})
    s.add_joint("mount", "fixed", "ground", "shaft")
    return s.compile()


def _generic(tmp):
    """A body from reduced data with random three-dimensional mode shapes at five nodes,
    each node's mass off the node with its own rotary inertia: every invariant full
    (J1, J2's pairs and Cr1 without symmetries), on a skew pin off its frame origin
    (stiffening off: the data carry none)."""
    from mbdyn.flexible.invariants import inertia_invariants, lumped_mass_points
    rng = np.random.default_rng(8)
    N, n = 5, 2
    nodes = np.column_stack([np.linspace(0.0, 0.8, N), rng.uniform(-0.02, 0.02, (N, 2))])
    nodes[0] = 0.0
    modes = rng.uniform(-1.0, 1.0, (N, 6, n))
    modes[0] = 0.0
    node_mass = np.zeros((N, 6, 6))
    for i in range(N):
        mi, si = rng.uniform(0.2, 0.5), rng.uniform(-0.01, 0.01, 3)
        S = np.array([[0, -si[2], si[1]], [si[2], 0, -si[0]], [-si[1], si[0], 0]])
        node_mass[i, :3, :3], node_mass[i, :3, 3:] = mi * np.eye(3), -mi * S
        node_mass[i, 3:, :3] = mi * S
        node_mass[i, 3:, 3:] = np.diag(rng.uniform(1e-4, 3e-4, 3)) - mi * S @ S
    inv = inertia_invariants(lumped_mass_points(nodes, node_mass, modes))
    path = tmp / "generic.npz"
    np.savez(path, mass=inv.modal_mass, stiffness=np.array([[900.0, 50.0], [50.0, 2500.0]]),
             modes=modes, nodes=nodes, node_mass=node_mass, damping=np.array([0.02, 0.03]))
    s = mb.System("generic body", gravity=(0.4, -9.81, 0.7))
    s.add_body("part", flexible={"data": str(path)})
    s.add_joint("pin", "revolute", "ground", "part", axis=(0.2, -0.3, 1.0),
                position=(0.1, 0.05, 0.0))
    return s.compile(effects="-geometric_stiffening")


def _tip_pendulum():
    s = _pinned()
    s.add_body("bob", mass=0.5, com=(0, -0.2, 0), inertia=[1e-3] * 3)
    s.add_joint("hang", "revolute", "beam", "bob", axis="z", position="tip")
    return s.compile()


MODELS_ = {"beam on a pin": lambda: _pinned().compile(),
           "beam on a pin with a rigid part": lambda: _pinned(
               mass=0.3, com=(0.5, 0.01, 0.02), inertia=[1e-3, 2e-3, 3e-3]).compile(),
           "cantilever, turned": _cantilever, "beam on a link": _on_a_link,
           "spun blade": _spun, "floating beam": _floating, "rotor": _rotor,
           "generic body from data": _generic, "pendulum at the tip (node frame)": _tip_pendulum}


@pytest.mark.parametrize("name", MODELS_)
def test_the_equations_agree_with_the_engine(name, tmp_path):
    """``M`` and ``f`` by each method, in own and inertial components, evaluated at random
    states with the invariants' values, equal the engine's to 1e-10."""
    make = MODELS_[name]
    m = make(tmp_path) if make is _generic else make()
    quaternions = any(j.kind in ("spherical", "free") for j in m.elements[1])
    methods = ("jourdain", "newton-euler") + (() if quaternions else ("lagrange",))
    states = _states(m)
    for method in methods:
        for frames in ("own", "inertial"):
            d = derive(m, method, frames=frames, measure=False)
            err = compare_numerically(d, states)
            assert max(err.values()) < TOL, (method, frames, err)
    assert all(s.name.startswith(tuple(m.flexible_bodies)) for s in d.walk.constants)


def test_the_three_methods_are_the_same_equations_symbolically():
    """By Lagrange the quadratic velocity vector comes out of ``1/2 w^T M_b(eta) w``;
    Jourdain and Newton-Euler write it in Kirchhoff's form: the three agree as
    expressions (not only in numbers)."""
    m = _pinned().compile()
    ds = [derive(m, method) for method in ("jourdain", "newton-euler", "lagrange")]
    assert all(compare_methods(ds).values())
    J = ds[0].names()
    assert J["beam_J2_2_2_zz"] in ds[0].mass_matrix[0, 0].free_symbols   # J(eta)'s zz


def test_solved_accelerations_and_reactions_agree_with_the_engine():
    m = _pinned(modes=1).compile()
    d = derive(m, "newton-euler", solve=True)
    err = compare_numerically(d, _states(m), what=("accelerations", "reactions"))
    assert max(err.values()) < TOL, err
    d = derive(m, "newton-euler", frames="inertial", solve=True)
    assert max(compare_numerically(d, _states(m, seed=4),
                                   what=("reactions",)).values()) < TOL


def test_a_closed_loop_beside_a_flexible_body():
    """A rigid four-bar (a loop joint) and a beam on a pin: the constraint equations and
    the floating frame's terms together, accelerations at the engine's multipliers."""
    s = mb.System("four-bar and beam", gravity=(0, -9.81, 0))
    for name, length in (("crank", 0.2), ("coupler", 0.5), ("rocker", 0.4)):
        s.add_body(name, mass=1.0, com=(length / 2, 0, 0), inertia=[1e-3, 1e-2, 1e-2])
    s.add_joint("A", "revolute", "ground", "crank", axis="z")
    s.add_joint("B", "revolute", "crank", "coupler", axis="z", position=(0.2, 0, 0))
    s.add_joint("D", "revolute", "ground", "rocker", axis="z", position=(0.45, 0, 0))
    s.add_joint("C", "revolute", "coupler", "rocker", axis="z", position=(0.5, 0, 0),
                child_position=(0.4, 0, 0))
    s.add_body("beam", flexible={"beam": EB, "modes": 2})
    s.add_joint("pin", "revolute", "ground", "beam", axis="z", position=(0, 1, 0))
    m = s.compile()
    q, u = m.assemble({"A": 0.8, "pin": 0.3, "beam_m1": 1e-3}, {"A": 1.0, "pin": 0.5},
                      {"B": 0.5, "D": 2.0})
    for method in ("jourdain", "newton-euler", "lagrange"):
        d = derive(m, method, solve=True)
        what = ("mass_matrix", "forcing", "accelerations") + (
            ("reactions",) if method == "newton-euler" else ())
        assert max(compare_numerically(d, [(q, u, 0.0)], what).values()) < TOL, method
    assert d.constraints is not None and d.subs({"beam_Kee_1_1": 0}).forcing != d.forcing


def test_the_invariants_are_named_and_valued():
    """Each named symbol holds its invariant's entry; round-off entries are exact zeros
    (a planar section's out-of-plane terms are not)."""
    m = _pinned().compile()
    d = derive(m, "jourdain")
    values = {s.name: v for s, v in d.walk.constants.items()}
    inv = m._flex[0].invariants
    assert values["beam_m"] == pytest.approx(inv.mass, rel=1e-15)
    assert values["beam_S0_x"] == pytest.approx(inv.first_moment[0], rel=1e-15)
    assert values["beam_J0_zz"] == pytest.approx(inv.inertia[2, 2], rel=1e-15)
    k = next(k for k in range(2) if abs(inv.modal_first_moment[1, k]) > 0.1)
    assert values[f"beam_S1_y_{k + 1}"] == pytest.approx(inv.modal_first_moment[1, k])
    assert values[f"beam_Kee_{k + 1}_{k + 1}"] == pytest.approx(m._flex[0].stiffness[k, k])
    assert "beam_S0_y" not in values and "beam_Kee_1_2" not in values     # exact zeros
    body = d.walk.flexible[0]
    assert body.S0[1] == 0 and body.Kee[0, 1] == 0


def _evaluate(expr_text, names, values):
    e = sympy.sympify(expr_text, locals={n: sympy.Symbol(n) for n in names})
    return float(e.subs({sympy.Symbol(n): v for n, v in values.items()}))


def test_every_format_lists_the_invariants_and_json_reads_back(tmp_path):
    """``mbdyn eom`` of the model file in text, LaTeX, Markdown and JSON: the invariants
    and their values in each; the JSON's ``M`` and ``f``, read back with the listed values,
    are the engine's."""
    outputs = {}
    for fmt in ("text", "latex", "markdown", "json"):
        path = tmp_path / f"eom.{fmt}"
        with open(path, "w") as out:
            import contextlib
            with contextlib.redirect_stdout(out):
                assert main(["eom", str(PENDULUM), "--format", fmt]) == 0
        outputs[fmt] = path.read_text()
    assert "arm_Kee_1_1 = " in outputs["text"] and "arm_J0_zz = " in outputs["text"]
    assert r"K^{\mathrm{arm}}_{ee,1,1}" in outputs["latex"] and "arm_Kee_1_1 = " in \
        outputs["latex"].replace(r"\_", "_")
    assert "arm_Mee_1_1 = " in outputs["markdown"]
    obj = json.loads(outputs["json"])
    flex = obj["flexible"]["arm"]
    assert flex["modal_coordinates"] == ["arm_m1", "arm_m2"]
    values = dict(flex["values"])
    m = mb.load_model(PENDULUM).model
    names = obj["coordinates"] + obj["speeds"] + list(values) + ["t"]
    for q, u, t in _states(m, 2):
        state = dict(zip(obj["coordinates"], q)) | dict(zip(obj["speeds"], u))
        at = {**values, **state, "t": t}
        M = np.array([[_evaluate(e, names, at) for e in row] for row in obj["mass_matrix"]])
        f = np.array([_evaluate(e, names, at) for e in obj["forcing"]])
        assert np.allclose(M, m.mass_matrix(q, t), rtol=0, atol=TOL * np.abs(M).max())
        assert np.allclose(f, m.forcing(q, u, t), rtol=0, atol=TOL * np.abs(f).max())


def test_steps_show_the_floating_frame(capsys):
    assert main(["eom", str(PENDULUM), "--steps", "--method", "lagrange"]) == 0
    out = capsys.readouterr().out
    assert "Flexible bodies (floating frame of reference)" in out
    assert "arm: M_b(eta)" in out and "arm_Cr0_z_1" in out


def _with_a_load():
    s = _pinned()
    s.add_load("push", "beam", force=(0, -1.0, 0), point="tip")
    return s.compile()


def _pinned_on_link_stiffened():
    s = mb.System("stiffened", gravity=(0, -9.81, 0))
    s.add_body("link", mass=0.7, com=(0.1, 0, 0), inertia=[1e-3, 2e-3, 2e-3])
    s.add_joint("a", "revolute", "ground", "link", axis="z")
    s.add_body("beam", flexible={"beam": EB, "modes": 2})
    s.add_joint("b", "revolute", "link", "beam", axis="z", position=(0.2, 0, 0))
    return s.compile()


@pytest.mark.parametrize("make, match", [
    (lambda: _pinned(modes=5).compile(), r"at most 4 modes.*limits\.MAX_SYMBOLIC_MODES"),
    (_with_a_load, r"loads and force elements at flexible bodies.*-push"),
    (lambda: _pinned().compile(effects="-gyroscopic"), "gyroscopic effect on only"),
    (_pinned_on_link_stiffened, r"axial term.*--effects=-geometric_stiffening"),
])
def test_what_the_symbolic_layer_does_not_write_is_refused_by_name(make, match):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", mb.ModelWarning)
        m = make()
    with pytest.raises(ModelError, match=match):
        derive(m, "jourdain")


def test_the_rotor_files_are_refused_by_name():
    """The shipped files the layer does not write say why: the rotor's 16 modes, the
    run-up's damper at the tip node (a force element at a flexible body)."""
    for name, match in (("jeffcott_flexible", "at most 4 modes"),
                        ("flexible_rotor_runup", "loads and force elements at flexible")):
        m = mb.load_model(MODELS / f"{name}.toml").model
        with pytest.raises(ModelError, match=match):
            derive(m)


def test_a_joint_at_a_node_solved_in_closed_form():
    """The pendulum at the beam's tip (a node frame's chain, moved by the modes through
    the named mode shapes at the node): the solved accelerations and reactions, evaluated
    in 40 digits (their closed forms are long quotients, whose evaluation in floats
    loses some 1e-11), equal the engine's to 1e-10; the chain's efforts push the modes
    (Newton-Euler's modal rows) as the Jourdain projection does."""
    m = _tip_pendulum()
    d = derive(m, "newton-euler", solve=True)
    names = {s.name for s in d.walk.constants}
    assert {"beam_tip_uy_2", "beam_tip_rz_2"} <= names and "beam_tip_uy_1" not in names
    for q, u, t in _states(m, 2, seed=6):
        vals = {s: sympy.Float(x, 40) for s, x in zip(d.walk.sym.q, q)}
        vals.update({s: sympy.Float(x, 40) for s, x in zip(d.walk.sym.u, u)})
        vals.update({s: sympy.Float(v, 40) for s, v in d.walk.constants.items()})
        vals[d.walk.sym.t] = sympy.Float(t, 40)
        ud = np.array([float(d.accelerations[s].xreplace(vals).evalf(40)) for s in m.speeds])
        ref = m.forward_dynamics(q, u, t)
        assert np.allclose(ud, ref, rtol=0, atol=TOL * np.abs(ref).max())
        reactions, kin = m.reactions(q, u, t), m.kinematics(q, u, t=t)
        for joint in m.joints:
            R = kin.R[m.frame_index(m.joint(joint).child)]
            comps = np.array([float(e.xreplace(vals).evalf(40)) for e in d.reactions[joint]])
            got, want = np.r_[R @ comps[:3], R @ comps[3:]], np.concatenate(reactions[joint])
            assert np.allclose(got, want, rtol=0, atol=TOL * np.abs(want).max()), joint


def test_loops_through_flexible_bodies():
    """The pendulum at the tip closed by a loop joint at the node (a free bob), and the
    flexible slider-crank file (the loop at the rod's tip): M and f on the constraints."""
    import test_flexible_loops as fl
    from test_flexible_reactions import _state
    tree, loop = fl._tip_pendulum(False), fl._tip_pendulum(True)
    q, u = fl._loop_state(tree, loop, *_state(tree))
    for method in ("jourdain", "newton-euler"):
        assert max(compare_numerically(derive(loop, method), [(q, u, 0.0)]).values()) < TOL
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", mb.ModelWarning)
        scene = mb.load_model(MODELS / "flexible_slider_crank.toml")
    d = derive(scene.model, "lagrange")
    assert d.constraints is not None
    assert max(compare_numerically(d, [(scene.q0, scene.u0, 0.0)]).values()) < TOL
