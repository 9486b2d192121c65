"""The Newton-Euler equations with reaction unknowns of models with flexible bodies
(docs/flexible.md, "Two formulations"): the accelerations against the Jourdain route's,
the reactions against the inverse dynamics after it (``model.reactions``), on trees,
loops through flexible bodies, elements at nodes, a driven spinning blade, the flexible
slider-crank and the flexible rotor; the chain efforts against the joint at the node;
runs by either route; and that the route stands without the Jourdain terms."""
from __future__ import annotations

import warnings

import numpy as np
import pytest

import mbdyn as mb
from mbdyn.algorithms import flexible_dynamics, flexible_newton_euler
from mbdyn.errors import ModelError
from test_flexible_joints import _spatial, _state as _spatial_state
from test_flexible_loops import EB, _assembled, _loop_state, _slider_crank, _tip_pendulum
from test_flexible_reactions import _state as _pin_state
from test_flexible_reactions import _with_elements
from test_flexible_slider_crank import _published_state, _scene

STEEL = {"length": 1.0, "elements": 10, "E": 2.1e11, "rho": 7850.0, "nu": 0.3,
         "section": {"circle": 0.02}}


def _random_state(m, seed=5, modal=1e-3):
    """Tree coordinates and speeds of order one, modal ones small (mass-normalised modes:
    a unit deflects a metre-long beam by about that much), quaternions normalised."""
    rng = np.random.default_rng(seed)
    q, u = m.default_coordinates().copy(), rng.uniform(-1.0, 1.0, m.nu)
    quaternion = {k for s in m._quaternions for k in range(s.start, s.stop)}
    for k, c in enumerate(m.coordinates):
        if c in m.modal_coordinates:
            q[k] = rng.uniform(-modal, modal)
        elif k not in quaternion:
            q[k] = rng.uniform(-1.0, 1.0)
    m.normalize_quaternions(q)
    modal_rates = [m.speed_index(s) for s in m.speeds[-len(m.modal_coordinates):]]
    u[modal_rates] *= 0.1
    return q, u


def _cantilever():
    s = mb.System("cantilever", gravity=(0, 0, -9.81))
    s.add_body("shaft", flexible={"beam": STEEL, "modes": 4, "damping": 0.01})
    s.add_joint("clamp", "fixed", "ground", "shaft")
    m = s.compile()
    return m, *_random_state(m)


def _free_beam(effects=None):
    """A free-floating beam with a rigid part off its axis, under gravity."""
    s = mb.System("free", gravity=(0.5, 0, -9.81))
    s.add_body("shaft", flexible={"beam": STEEL, "modes": 4, "damping": 0.01}, mass=0.3,
               com=(0.2, 0.01, 0), inertia=[1e-3, 2e-3, 3e-3])
    s.add_joint("float", "free", "ground", "shaft")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", mb.ModelWarning)     # gyroscopic off
        m = s.compile(effects=effects)
    return m, *_random_state(m)


def _blade():
    """A blade spun up about z by a drive (stiffening on: centrifugal and axial)."""
    s = mb.System("spin", gravity=(0, 0, 0))
    s.add_body("blade", flexible={"beam": {"length": 1.0, "elements": 12, "E": 7e10,
                                           "rho": 2700.0, "rect": [0.02, 0.01],
                                           "theory": "euler-bernoulli"}, "modes": 3})
    s.add_joint("hub", "revolute", "ground", "blade", axis="z",
                drive=30 * mb.t + 5 * mb.t ** 2)
    m = s.compile()
    return m, *_random_state(m)


def _tip(loop):
    tree = _tip_pendulum(False)
    q, u = _pin_state(tree)
    if not loop:
        return tree, q, u
    closed = _tip_pendulum(True)
    return closed, *_loop_state(tree, closed, q, u)


def _pinned_with_elements():
    m = _with_elements()
    return m, *_pin_state(m)


def _spatial_beam():
    m = _spatial().compile()
    return m, *_spatial_state(m)[:2]


def _crank(drive):
    m = _slider_crank(drive=drive).compile()
    return m, *_assembled(m, drive)


def _three_beams():
    beam = {**EB, "length": 0.5, "elements": 4, "rect": [0.02, 0.03]}
    s = mb.System("three beams", gravity=(0, -9.81, 0))
    s.add_body("a", flexible={"beam": beam, "modes": 2})
    s.add_joint("pa", "revolute", "ground", "a", axis="z")
    s.add_body("b", flexible={"beam": beam, "modes": 2})
    s.add_joint("pb", "revolute", "ground", "b", axis="z", position=(0.7, 0, 0))
    s.add_body("c", flexible={"beam": {**beam, "length": 0.8}, "modes": 2})
    s.add_joint("pc", "revolute", "a", "c", axis="z", position="tip")
    s.add_joint("K", "revolute", "c", "b", axis="z", position="tip", child_position="tip")
    m = s.compile()
    bent = {}                  # the crank and the coupler bent in the plane, and moving
    for body, value in (("a", 1e-4), ("c", -2e-4)):
        red = m.flexible[body].reduced
        tip = red.modes[red.node("tip")]
        k = int(np.argmax(np.abs(tip[1]) - np.abs(tip[2])))
        bent[m.flexible[body].coordinates[k]] = value
    q, u = m.assemble({"pa": 1.2, **bent}, {"pa": 1.0, **{c: 10 * v for c, v in
                                                          bent.items()}},
                      {"pb": 1.9, "pc": -1.2})
    return m, q, u


def _slider_crank_file():
    m = _scene().model
    return m, *_published_state(m)


def _rotor():
    m = mb.load_model("models/jeffcott_flexible.toml").model
    return m, *_random_state(m, modal=1e-5)


MODELS = {"cantilever": _cantilever, "free beam": _free_beam,
          "free beam, gyroscopic off": lambda: _free_beam("-gyroscopic"),
          "driven blade": _blade, "beam on a ball, bob at a point": _spatial_beam,
          "pendulum at the tip": lambda: _tip(False),
          "pendulum at the tip, by a loop": lambda: _tip(True),
          "elements at nodes": _pinned_with_elements,
          "slider-crank, driven": lambda: _crank(True),
          "slider-crank, free": lambda: _crank(False),
          "four-bar of three beams": _three_beams,
          "flexible slider-crank file": _slider_crank_file, "flexible rotor file": _rotor}


@pytest.mark.parametrize("name", MODELS)
def test_the_two_routes_agree_on_accelerations_and_reactions(name):
    """``u'`` by the Newton-Euler system equals the Jourdain route's; each reaction equals
    the inverse dynamics' after it (``model.reactions``): to 1e-10 of the largest (of
    1 N or 1 N m where none transmits more: a free joint's are zero)."""
    m, q, u = MODELS[name]()
    t = 0.0 if m.has_loops else 0.013         # the loops assembled at t = 0
    ud_j = m.forward_dynamics(q, u, t)
    ud_n, r_n = m.newton_euler(q, u, t)
    assert np.abs(ud_j).max() > 0
    assert np.allclose(ud_n, ud_j, rtol=0, atol=1e-10 * np.abs(ud_j).max())
    assert np.array_equal(m.forward_dynamics(q, u, t, method="newton-euler"), ud_n)
    r_j = m.reactions(q, u, t)
    assert set(r_n) == set(r_j) == set(m.reaction_joints)
    for part in (0, 1):
        scale = max(max(np.abs(r[part]).max() for r in r_j.values()), 1.0)
        for joint in r_j:
            assert np.allclose(r_n[joint][part], r_j[joint][part], rtol=0,
                               atol=1e-10 * scale), (joint, part)
    child = m.reactions(q, u, t, method="newton-euler", frame="child")
    assert all(np.allclose(child[j][0], m.reactions(q, u, t, frame="child")[j][0],
                           rtol=0, atol=1e-10 * max(1.0, np.abs(child[j][0]).max()))
               for j in child)


def test_a_chain_carries_the_pull_of_the_joint_at_its_node():
    """The node frame's chain is massless: the efforts along its prismatic coordinates
    (what the beam exerts on the node frame, along the chain's axes) are the components
    of the force the tip joint passes on to the bob; with the effort's sign flipped in
    the modal rows the accelerations are off."""
    m, q, u = _tip(False)
    sol = flexible_newton_euler.solve(m, q, u)
    F_hang = flexible_newton_euler.reactions_of(m, sol)["hang"][0]
    tree = m.tree
    for k, name in enumerate(m.node_frames[0].joints[:2]):      # uy, uz: prismatic
        j = tree._joint[name]
        axis = tree._R[tree.frame_index(j.child)] @ j.axis
        assert sol.tau[k] == pytest.approx(F_hang @ axis, rel=1e-12, abs=1e-12)
    assert abs(sol.tau[0]) > 1.0
    K, rhs, (nu, nr, nc) = flexible_newton_euler._system(m, q, u, 0.0, None)
    K[6 * tree.n_frames:, nu + nr:nu + nr + nc] *= -1.0
    wrong = np.linalg.solve(K, rhs)[:nu]
    assert np.abs(wrong - sol.ud).max() > 1e-3 * np.abs(sol.ud).max()


def test_the_route_stands_without_the_jourdain_terms(monkeypatch):
    """The Newton-Euler route does not call the Jourdain route: with its terms made to
    fail, ``u'`` and the reactions still come (and equal those computed before)."""
    m, q, u = _crank(True)
    ud, r = m.newton_euler(q, u)

    def refuse(*args, **kwargs):
        raise AssertionError("the Jourdain route was called")
    for name in ("terms", "extended_terms", "forward_dynamics", "body_forces"):
        monkeypatch.setattr(flexible_dynamics, name, refuse)
    ud2, r2 = m.newton_euler(q, u)
    assert np.array_equal(ud, ud2)
    assert all(np.array_equal(r[j][0], r2[j][0]) for j in r)
    with pytest.raises(AssertionError, match="Jourdain route was called"):
        m.forward_dynamics(q, u)


def test_runs_by_the_newton_euler_route_follow_the_jourdain_run():
    m, q, u = _tip(False)
    runs = {method: mb.simulate(m, 0.004, q, u, method=method, rtol=1e-10, atol=1e-12)
            for method in ("jourdain", "newton-euler", "newton-euler-dense")}
    ref = runs["jourdain"]
    for method, res in runs.items():
        assert res.stats["method"] == method
        assert np.allclose(res.q[-1], ref.q[-1], rtol=0, atol=1e-11)
        assert np.allclose(res.u[-1], ref.u[-1], rtol=0, atol=1e-8)


def test_the_articulated_route_is_refused_by_name():
    m, q, u = _cantilever()
    with pytest.raises(ModelError, match="'newton-euler' and 'newton-euler-dense'"):
        m.forward_dynamics(q, u, method="articulated")
    with pytest.raises(ModelError, match="reactions take method"):
        m.reactions(q, u, method="articulated")
