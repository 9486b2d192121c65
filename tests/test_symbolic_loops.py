"""Closed loops in the symbolic layer (``mbdyn.symbolic.loops``): the constraint equations
``phi(q, t)``, their Jacobian and ``gamma`` against the numeric engine's
(``Model.constraint_residuals``, ``Model.constraint_jacobian``) at random states; the
equations with multipliers ``M u' = f + G^T lambda`` (by Jourdain, Lagrange and
Newton-Euler) solved at a state against ``Model.forward_dynamics``; ``mbdyn eom`` on the
four-bar in every format, and the derivation trace's step 3."""
from __future__ import annotations

import json
import pathlib

import numpy as np
import pytest
import sympy

import mbdyn as mb
from mbdyn.cli import main
from mbdyn.symbolic import derive
from mbdyn.symbolic.loops import loop_equations
from mbdyn.symbolic.walk import Walk
from random_trees import (build_system, quat_to_matrix, random_rotation, random_tree,
                          random_unit)

ROOT = pathlib.Path(__file__).resolve().parents[1]
MODELS = ROOT / "models"
LOOP_KINDS = ("revolute", "prismatic", "spherical", "fixed", "universal", "cylindrical",
              "distance", "coupling")


# ----------------------------------------------------------------------------- models
def place_loops(system, model, q, loops, t=0.0):
    """Add ``loops`` (dicts: kind, parent, child, and position / child_position / axis /
    follower, leader, ratio) to ``system``, each placed so that it closes at ``q``."""
    kin = model.kinematics(q, np.zeros(model.nu), t=t)
    frames = list(model.frames)

    def frame(name):
        if name == "ground":
            return np.eye(3), np.zeros(3)
        i = frames.index(name)
        return kin.R[i], kin.r[i]
    for spec in loops:
        spec = dict(spec)
        name, kind = spec.pop("name"), spec.pop("kind")
        if kind == "coupling":
            qa = q[model.coordinate_index(spec["follower"])]
            qb = q[model.coordinate_index(spec["leader"])]
            system.add_joint(name, "coupling", offset=float(qa - spec["ratio"] * qb), **spec)
            continue
        parent, child = spec.pop("parent"), spec.pop("child")
        (Rp, rp), (Rc, rc) = frame(parent), frame(child)
        sp = np.asarray(spec.pop("position"), float)
        P = rp + Rp @ sp
        if kind == "distance":
            sc = np.asarray(spec.pop("child_position"), float)
            spec["length"] = float(np.linalg.norm(rc + Rc @ sc - P))
            spec["child_position"] = sc
        else:
            Cp = np.asarray(spec.pop("orientation", np.eye(3)), float)
            spec.update(orientation=Cp, child_position=Rc.T @ (P - rc),
                        child_orientation=Rc.T @ Rp @ Cp)
        system.add_joint(name, kind, parent, child, position=sp, **spec)
    return system.compile()


def _body(s, name, mass, com, inertia=(0.02, 0.03, 0.04)):
    s.add_body(name, mass=mass, com=com, inertia=inertia)


def spatial_tree(L=None):
    """A spatial tree of revolute, euler and prismatic joints (Lagrange can derive it),
    with the parameters ``L`` and ``m`` kept as symbols."""
    s = mb.System("spatial loops", gravity=(0.3, -9.81, 0.5), parameters={"L": 0.4, "m": 1.3})
    L, m = s.symbols("L m")
    _body(s, "b0", m, (L / 2, 0, 0))
    _body(s, "b1", 0.8, (0, 0.1, 0.05), (0.03, 0.02, 0.025))
    _body(s, "b2", 0.5, (0.05, 0, 0))
    _body(s, "b3", 1.1, (0, L / 2, 0))
    _body(s, "b4", 0.7, (0.1, 0, 0.05))
    s.add_joint("j0", "revolute", "ground", "b0", axis=(0.2, 0.3, 1.0))
    s.add_joint("j1", "euler", "b0", "b1", position=(L, 0, 0), sequence="ZXY")
    s.add_joint("j2", "prismatic", "b1", "b2", axis="y", position=(0, 0.2, 0))
    s.add_joint("j3", "revolute", "ground", "b3", axis="x", position=(0.6, 0.1, 0.2))
    s.add_joint("j4", "revolute", "b3", "b4", axis=(0, 0.6, 0.8), position=(0, L, 0))
    return s


def spatial_model():
    """The tree closed by a spherical joint, a distance and a coupling (5 rows, 7 speeds)."""
    s = spatial_tree()
    model = s.compile()
    q = np.array([0.3, 0.2, -0.4, 0.5, 0.1, 0.7, -0.2])
    loops = [dict(name="ball", kind="spherical", parent="b2", child="b4", position=(0.1, 0.2, 0)),
             dict(name="rod", kind="distance", parent="b0", child="b3", position=(0.1, 0, 0.05),
                  child_position=(0, 0.3, 0.1)),
             dict(name="gear", kind="coupling", follower="j3", leader="j0", ratio=-0.7)]
    return place_loops(s, model, q, loops)


def prismatic_model():
    """An euler-revolute-prismatic chain whose end slides in a rocker (prismatic loop)."""
    s = mb.System("prismatic loop", gravity=(0, 0, -9.81))
    _body(s, "c0", 1.0, (0.1, 0, 0))
    _body(s, "c1", 0.6, (0.2, 0, 0))
    _body(s, "c2", 0.4, (0, 0, 0.1))
    _body(s, "c3", 0.9, (0, 0.2, 0))
    s.add_joint("k0", "euler", "ground", "c0", sequence="ZYX")
    s.add_joint("k1", "revolute", "c0", "c1", axis="y", position=(0.3, 0, 0))
    s.add_joint("k2", "prismatic", "c1", "c2", axis=(1, 0, 1), position=(0.4, 0, 0))
    s.add_joint("k3", "revolute", "ground", "c3", axis="z", position=(0.5, 0.4, 0.1))
    model = s.compile()
    q = np.array([0.4, -0.3, 0.2, 0.5, 0.1, 0.9])
    loops = [dict(name="slot", kind="prismatic", parent="c3", child="c2",
                  position=(0.05, 0.1, 0.2), axis=(0.3, 0.1, 1.0),
                  orientation=quat_to_matrix((0.9, 0.1, -0.3, 0.2)))]
    return place_loops(s, model, q, loops)


def quaternion_model():
    """A spherical tree joint (u != q') closed by a universal and a cylindrical joint."""
    s = mb.System("quaternion loops", gravity=(0, -9.81, 0))
    _body(s, "d0", 1.2, (0.1, 0.2, 0))
    _body(s, "d1", 0.5, (0.1, 0, 0))
    _body(s, "d2", 0.8, (0, 0.15, 0))
    _body(s, "d3", 0.6, (0, 0, 0.1))
    _body(s, "d4", 0.4, (0.1, 0.1, 0))
    s.add_joint("s0", "spherical", "ground", "d0", position=(0, 0.5, 0))
    s.add_joint("r1", "revolute", "d0", "d1", axis="z", position=(0.3, 0, 0))
    s.add_joint("r2", "revolute", "ground", "d2", axis="x", position=(0.5, 0, 0.2))
    s.add_joint("p3", "prismatic", "d2", "d3", axis="y", position=(0, 0.3, 0))
    s.add_joint("r4", "revolute", "d3", "d4", axis="x", position=(0, 0, 0.2))
    model = s.compile()
    w = np.array([0.9, 0.2, -0.3, 0.25])
    q = np.concatenate([w / np.linalg.norm(w), [0.4, 0.3, 0.1, -0.2]])
    loops = [dict(name="cross", kind="universal", parent="d1", child="d3",
                  position=(0.2, 0.05, 0), axis="z", axis2="x")]
    return place_loops(s, model, q, loops)


def load(path, case=None):
    scene = mb.load_model(str(MODELS / path), case=case)
    return scene.model, scene.q0, scene.u0


@pytest.fixture(scope="module")
def models():
    out = {"four_bar": load("four_bar.toml"), "four_bar_free": load("four_bar.toml", "free"),
           "slider_crank": load("slider_crank.toml"), "bricard": load("bricard.toml")}
    for name, build in (("spatial", spatial_model), ("prismatic", prismatic_model),
                        ("quaternion", quaternion_model)):
        model = build()
        out[name] = (model, None, None)
    return out


NAMES = ("four_bar", "four_bar_free", "slider_crank", "bricard", "spatial", "prismatic",
         "quaternion")


def random_q(model, rng):
    q = rng.uniform(-np.pi, np.pi, model.nq)
    for j in model.elements[1]:
        if j.kind in ("spherical", "free") and j.drive is None:
            k = model.coordinate_index(j.coordinates[0]) + (3 if j.kind == "free" else 0)
            q[k:k + 4] = random_rotation(rng)
    return q


# ----------------------------------------------------------------------------- phi, G, gamma
def _check_constraints(model, eq, rng, states=4):
    assert eq.rows == model.constraint_rows
    phi, G, phi_t, gamma = (eq.numeric(w) for w in ("phi", "G", "phi_t", "gamma"))
    for _ in range(states):
        q, u, t = random_q(model, rng), rng.normal(size=model.nu), float(rng.uniform(0, 2))
        ph, psi = model.constraint_residuals(q, u, t)
        gn = model._con[5].copy()
        np.testing.assert_allclose(phi(q, t=t).ravel(), ph, rtol=0, atol=1e-12)
        Gs = G(q, t=t)
        np.testing.assert_allclose(Gs, model.constraint_jacobian(q, t), rtol=0, atol=1e-12)
        scale = 1 + np.abs(u).max()
        np.testing.assert_allclose(Gs @ u + phi_t(q, t=t).ravel(), psi, rtol=0,
                                   atol=1e-12 * scale)
        np.testing.assert_allclose(gamma(q, u, t).ravel(), gn, rtol=0, atol=1e-11 * scale ** 2)


@pytest.mark.parametrize("name", NAMES)
def test_constraints_agree_with_the_engine(models, name):
    model = models[name][0]
    eq = loop_equations(Walk(model))
    _check_constraints(model, eq, np.random.default_rng(NAMES.index(name)))


@pytest.mark.parametrize("kind", LOOP_KINDS)
def test_every_loop_kind_on_a_random_tree(kind):
    """Each kind closing a random tree (quaternion and euler joints, drives): phi, G = Phi_q
    N(q), phi_t and gamma against the engine."""
    seed = LOOP_KINDS.index(kind)
    for attempt in range(20):           # a coupling needs two free 1-DoF joints
        rt = random_tree(100 + seed + 10 * attempt, 4, loads=False)
        free = [j.name for j in rt.model.elements[1] if j.kind in ("revolute", "prismatic")
                and j.drive is None]
        if kind != "coupling" or len(free) >= 2:
            break
    system = build_system(rt.spec)[0]
    rng = np.random.default_rng(seed)
    frames = list(rt.model.frames)
    if kind == "coupling":
        spec = dict(name="loop", kind=kind, follower=free[0], leader=free[1], ratio=0.6)
    else:
        spec = dict(name="loop", kind=kind, parent="ground", child=frames[-1],
                    position=rng.normal(scale=0.3, size=3))
        if kind == "distance":
            spec["child_position"] = rng.normal(scale=0.3, size=3)
        else:
            spec["orientation"] = quat_to_matrix(random_rotation(rng))
        if kind in ("revolute", "prismatic", "cylindrical", "universal"):
            spec["axis"] = random_unit(rng)
        if kind == "universal":
            a2 = np.cross(spec["axis"], random_unit(rng))
            spec["axis2"] = a2 / np.linalg.norm(a2)
    model = place_loops(system, rt.model, rt.q, [spec], rt.t)
    eq = loop_equations(Walk(model))
    _check_constraints(model, eq, rng, states=3)
    assert len(eq.rows) == mb.elements.constraints.LOOP_KINDS[kind]


def test_parameters_stay_symbols(models):
    """The toml's lengths are the model's parameters in phi (the loop joint keeps them)."""
    eq = loop_equations(Walk(models["four_bar"][0]))
    names = {s.name for s in eq.phi.free_symbols}
    assert {"a", "b", "c", "d", "Omega", "phi0", "rocker", "coupler", "t"} <= names
    assert eq.phi[2:, 0] == sympy.zeros(3, 1)           # the planar loop's redundant rows
    L = sympy.Symbol("L", real=True)
    spatial = loop_equations(Walk(models["spatial"][0]))
    assert L in spatial.phi.free_symbols
    assert not spatial.speed_form and loop_equations(Walk(models["quaternion"][0])).speed_form


# ----------------------------------------------------------------------------- dynamics
def _state(model, q0, u0, rng):
    """A random state on the mechanism near its assembled (or constructed) one."""
    q = q0 if q0 is not None else _closing_q(model)
    u = rng.normal(size=model.nu)
    for size in (0.05, 0.02, 0.005, 0.0):     # Bricard's loop closes only near its path
        try:
            return model.project(q + size * rng.normal(size=model.nq), u, 0.0)
        except mb.SimulationError:
            continue
    raise AssertionError("no state on the mechanism")


def _closing_q(model):
    phi = lambda q: model.constraint_residuals(q)[0]  # noqa: E731
    for q in (np.array([0.3, 0.2, -0.4, 0.5, 0.1, 0.7, -0.2]),
              np.array([0.4, -0.3, 0.2, 0.5, 0.1, 0.9])):
        if q.size == model.nq and np.abs(phi(q)).max() < 1e-9:
            return q
    w = np.array([0.9, 0.2, -0.3, 0.25])
    return np.concatenate([w / np.linalg.norm(w), [0.4, 0.3, 0.1, -0.2]])


def _evaluate(d, q, u, t):
    M = np.atleast_2d(d.numeric("mass_matrix")(q, u, t))
    f = np.atleast_1d(d.numeric("forcing")(q, u, t))
    c = d.constraints
    return M, f, c.numeric("G")(q, u, t), c.numeric("gamma")(q, u, t).ravel()


DYNAMICS = [(n, m) for n in NAMES for m in ("jourdain", "lagrange", "newton-euler")
            if not (n == "quaternion" and m == "lagrange")]


@pytest.mark.parametrize("name,method", DYNAMICS)
def test_equations_with_multipliers_give_the_engines_accelerations(models, name, method):
    model, q0, u0 = models[name]
    rng = np.random.default_rng(7)
    q, u = _state(model, q0, u0, rng)
    t = 0.0
    d = derive(model, method)
    M, f, G, gamma = _evaluate(d, q, u, t)
    ud = model.forward_dynamics(q, u, t)
    scale = 1 + np.abs(ud).max()
    _, lam = model.multipliers(q, u, t)                     # the engine's multipliers
    np.testing.assert_allclose(np.linalg.solve(M, f + G.T @ lam), ud, rtol=0,
                               atol=1e-10 * scale)
    n, k = M.shape[0], G.shape[0]                           # the augmented system alone
    A = np.block([[M, -G.T], [G, np.zeros((k, k))]])
    x = np.linalg.lstsq(A, np.concatenate([f, gamma]), rcond=1e-13)[0]
    np.testing.assert_allclose(x[:n], ud, rtol=0, atol=1e-10 * scale)
    if method == "newton-euler":        # its own projection of the multipliers' loads,
        for q in (q, random_q(model, rng)):     # on the mechanism and off it
            G = d.constraints.numeric("G")(q, u, t)
            GT = _numeric_matrix(d, d.equations.details["constraint_forces"], q, u, t)
            np.testing.assert_allclose(GT, G.T, rtol=0, atol=1e-12 * (1 + np.abs(G).max()))


def _numeric_matrix(d, expr, q, u, t):
    from mbdyn.symbolic.evaluate import evaluate
    sym = d.walk.sym
    vals = {sym.t: t, **dict(zip(sym.q, map(float, q))), **dict(zip(sym.u, map(float, u)))}
    vals.update({s: float(d.model.parameters[n]) for n, s in sym.params.items()})
    return np.array(evaluate(list(expr), vals), float).reshape(expr.shape)


def test_constrained_equations_rows(models):
    """``constrained_equations()``: nu rows with the multipliers, then G u' = gamma; by
    Lagrange the left side is d/dt dL/dq' - dL/dq (M q'' - f + Q)."""
    model, q0, u0 = models["slider_crank"]
    for method in ("jourdain", "lagrange"):
        d = derive(model, method)
        eqs = d.constrained_equations()
        assert len(eqs) == model.nu + len(model.constraint_rows)
        lam = set(d.constraints.multipliers)
        assert all(lam & e.rhs.free_symbols for e in eqs[:model.nu] if e.rhs != 0)
        rates = set(d.rates)
        assert all(rates & e.lhs.free_symbols for e in eqs[model.nu:] if e.lhs != 0)
    Q = d.equations.details["generalized_forces"]
    assert sympy.simplify(eqs[0].rhs - Q[0] - d.constraints.constraint_forces()[0]) == 0


def test_newton_euler_reactions_with_multipliers(models):
    """Solved by Newton-Euler, the tree joints' reactions include the loop joint's
    multipliers; with the engine's multipliers they are the engine's reactions."""
    model, q0, u0 = models["slider_crank"]
    d = derive(model, "newton-euler", solve=True)
    rng = np.random.default_rng(3)
    q, u = _state(model, q0, u0, rng)
    ud, lam = model.multipliers(q, u, 0.0)
    sym = d.walk.sym
    vals = {**dict(zip(d.constraints.multipliers, map(float, lam)))}
    acc = sympy.Matrix([d.accelerations[s] for s in d.speeds]).xreplace(vals)
    got = _numeric_matrix(d, acc, q, u, 0.0).ravel()
    np.testing.assert_allclose(got, ud, rtol=0, atol=1e-10 * (1 + np.abs(ud).max()))
    engine = model.reactions(q, u, 0.0, frame="child")
    for joint in model.joints:
        comps = sympy.Matrix(d.reactions[joint]).xreplace(vals)
        ours = _numeric_matrix(d, comps, q, u, 0.0).ravel()
        want = np.concatenate(engine[joint])
        np.testing.assert_allclose(ours, want, rtol=0, atol=1e-9 * (1 + np.abs(want).max()))
    assert sym.t is not None


# ----------------------------------------------------------------------------- mbdyn eom
def _eom(capsys, *args):
    code = main(["eom", str(MODELS / "four_bar.toml"), *args])
    out = capsys.readouterr().out
    assert code == 0
    return out


def test_eom_four_bar_text(capsys):
    out = _eom(capsys)
    assert "M(q) u' = f(q, u, t) + G^T lambda" in out
    assert "phi[pin_B.x] = -a*cos(Omega*t + phi0) - b*cos(Omega*t + coupler + phi0) + " \
           "c*cos(rocker) + d" in out
    assert "Phi_q[pin_B.x, rocker] = -c*sin(rocker)" in out
    assert "gamma[pin_B.y]" in out and "(G^T lambda)[coupler_dot]" in out


def test_eom_four_bar_lagrange_and_steps(capsys):
    out = _eom(capsys, "--method", "lagrange", "--steps")
    step3 = out.split("(3) ")[1].split("(4-5)")[0]
    assert step3.startswith("Position vectors and constraint equations")
    assert "phi[pin_B.x] (point) = " in step3 and "phi[pin_B.perp1] (perp) = 0 = 0" in step3
    assert "I r_P' (pin_B, on rocker) = [c*cos(rocker) + d, c*sin(rocker), 0]" in step3
    assert "Constraint Jacobian and multipliers" in out
    assert "d/dt dL/dq' - dL/dq = Q + Phi_q^T lambda" in out


@pytest.mark.parametrize("fmt", ("latex", "markdown"))
def test_eom_four_bar_latex_and_markdown(capsys, fmt):
    out = _eom(capsys, "--format", fmt)
    assert r"\phi(q, t) = " in out and r"\Phi_q = " in out
    assert r"M \dot u = f + G^T \lambda" in out and r"\lambda_{\text{pin\_B.x}}" in out
    steps = _eom(capsys, "--format", fmt, "--steps")
    assert r"\phi_{\text{pin\_B.x}}" in steps


def test_eom_four_bar_json(capsys):
    obj = json.loads(_eom(capsys, "--format", "json"))
    c = obj["constraints"]
    assert c["rows"] == ["pin_B.x", "pin_B.y", "pin_B.z", "pin_B.perp1", "pin_B.perp2"]
    names = {n: sympy.Symbol(n) for n in ["a", "b", "c", "d", "Omega", "phi0", "t", "rocker",
                                          "coupler", "rocker_dot", "coupler_dot"]
             + c["multipliers"]}
    phi = [sympy.sympify(e, locals=names) for e in c["phi"]]
    a, b, cc, d, W, p0, t, rk, cp = (names[k] for k in ("a", "b", "c", "d", "Omega", "phi0",
                                                        "t", "rocker", "coupler"))
    want = -a * sympy.cos(W * t + p0) - b * sympy.cos(W * t + cp + p0) + cc * sympy.cos(rk) + d
    assert sympy.simplify(phi[0] - want) == 0
    assert len(c["jacobian"]) == 5 and len(c["jacobian"][0]) == 2
    assert json.loads(_eom(capsys, "--format", "json", "--steps"))["constraints"] is not None


def test_eom_tree_has_no_constraints(capsys):
    code = main(["eom", str(MODELS / "double_pendulum.toml"), "--format", "json"])
    assert code == 0
    assert json.loads(capsys.readouterr().out)["constraints"] is None


def test_symbolic_simulation_refuses_loops(models):
    model = models["four_bar_free"][0]
    with pytest.raises(mb.ModelError, match="loop joints"):
        mb.symbolic.compiled_rhs(model)


def test_subs_keeps_the_constraints(models):
    d = derive(models["four_bar"][0], "jourdain")
    e = d.subs({"phi0": 0, "Omega": 0})
    assert sympy.Symbol("Omega", real=True) not in e.constraints.phi.free_symbols
    assert all(x == 0 for x in e.constraints.phi_t)


def test_json_constraints_read_back(models):
    """Every expression of the JSON's constraints reads back with ``d.names()`` as the
    derivation's own (slider-crank by Newton-Euler, solved: accelerations in lambda)."""
    from mbdyn.symbolic import same_expression
    d = derive(models["slider_crank"][0], "newton-euler", solve=True)
    obj = json.loads(d.to_json())
    names = {n: sympy.Symbol(n) for n in d.names()}
    plain = {v: sympy.Symbol(k) for k, v in d.names().items()}
    c, eq = obj["constraints"], d.constraints
    for text, e in zip(c["phi"] + c["gamma"] + c["constraint_forces"],
                       list(eq.phi) + list(eq.gamma) + list(eq.constraint_forces())):
        assert same_expression(sympy.sympify(text, locals=names), e.xreplace(plain))
    for rows, M in ((c["jacobian"], eq.jacobian), (c["G"], eq.G)):
        for r, row in enumerate(rows):
            for k, text in enumerate(row):
                assert same_expression(sympy.sympify(text, locals=names), M[r, k].xreplace(plain))
    lam = {names[n] for n in c["multipliers"]}
    acc = sympy.sympify(obj["accelerations"]["theta_dot"], locals=names)
    assert lam & acc.free_symbols


@pytest.mark.parametrize("name", ("four_bar", "slider_crank"))
def test_compare_numerically_takes_the_engines_multipliers(models, name):
    """``compare_numerically`` on a closed mechanism, solved by Newton-Euler: M, f, the
    accelerations and every reaction at the engine's multipliers, on the mechanism."""
    from mbdyn.symbolic import compare_numerically
    model, q0, u0 = models[name]
    rng = np.random.default_rng(11)
    states = [(*_state(model, q0, u0, rng), 0.0) for _ in range(3)]
    d = derive(model, "newton-euler", solve=True)
    err = compare_numerically(d, states, what=("mass_matrix", "forcing", "accelerations",
                                               "reactions"))
    assert max(err.values()) < 1e-10, err
    with pytest.raises(mb.ModelError, match="multipliers"):
        d.numeric("accelerations")(*states[0])
