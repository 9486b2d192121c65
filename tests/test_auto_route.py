"""The ordinary API takes the fast route by default (issue 25, item 9): ``method="auto"``
is ``Model.formulation("auto")``, Jourdain below ``ARTICULATED_FROM`` free speeds, the
articulated bodies above."""
import numpy as np
import pytest

import mbdyn as mb
from mbdyn.algorithms.forward_dynamics import ARTICULATED_FROM


def chain(n):
    s = mb.System("chain")
    prev = "ground"
    for i in range(n):
        s.add_body(f"b{i}", mass=1.0, com=(0.5, 0, 0), inertia=(0.01, 0.1, 0.1))
        s.add_joint(f"j{i}", "revolute", parent=prev, child=f"b{i}", axis="y",
                    position=(1.0 if i else 0, 0, 0))
        prev = f"b{i}"
    return s.compile(check_inertia=False)


def test_default_route_is_the_measured_crossover():
    rng = np.random.default_rng(1)
    for n, route in ((3, "jourdain"), (ARTICULATED_FROM + 4, "articulated")):
        m = chain(n)
        assert m.formulation("auto") == route
        q, u = rng.uniform(-1, 1, n), rng.uniform(-1, 1, n)
        default = m.forward_dynamics(q, u)
        assert np.array_equal(default, m.forward_dynamics(q, u, method=route))
        other = "articulated" if route == "jourdain" else "jourdain"
        assert np.allclose(default, m.forward_dynamics(q, u, method=other), rtol=1e-9,
                           atol=1e-9)
        y = np.concatenate([q, u])
        assert np.array_equal(m.state_derivative(0.0, y),
                              m.state_derivative(0.0, y, method=route))


def mixed_chain(n):
    s = mb.System("mixed")
    prev = "ground"
    for i in range(n):
        s.add_body(f"b{i}", mass=1.0, com=(0.5, 0.1, 0), inertia=(0.01, 0.1, 0.1))
        kind = "revolute" if i % 2 else "spherical"
        s.add_joint(f"j{i}", kind, parent=prev, child=f"b{i}",
                    axis="y" if kind == "revolute" else None,
                    position=(1.0 if i else 0, 0, 0))
        prev = f"b{i}"
    return s.compile(check_inertia=False)


def test_reaction_array_is_the_reactions_without_dictionaries():
    # issue 25, item 8: one array, a row per joint; against the dense Newton-Euler system
    rng = np.random.default_rng(2)
    for n in (2, 9):
        m = mixed_chain(n)
        q = m.default_coordinates() + rng.uniform(-0.3, 0.3, m.nq)
        m.normalize_quaternions(q)
        u = rng.uniform(-1, 1, m.nu)
        for frame in ("world", "child"):
            d = m.reactions(q, u, method="newton-euler-dense", frame=frame)
            ref = np.array([np.concatenate(d[j]) for j in m.joints])
            got = m.reaction_array(q, u, frame=frame)
            assert got.shape == (len(m.joints), 6)
            assert np.max(np.abs(got - ref)) < 1e-12 * np.max(np.abs(ref))
        low = m.lowlevel()
        assert np.array_equal(low.reactions(q, u), m.reaction_array(q, u))
        out = np.empty((len(m.joints), 6))
        assert low.reactions(q, u, out=out) is out


def test_reaction_array_of_a_closed_mechanism_and_bad_out():
    scene = mb.load_model("models/four_bar.toml")
    m = scene.model
    d = m.reactions(scene.q0, scene.u0)
    got = m.reaction_array(scene.q0, scene.u0)
    assert np.allclose(got, [np.concatenate(d[j]) for j in m.joints])
    low = mixed_chain(3).lowlevel()
    with pytest.raises(mb.ModelError, match=r"out must be .*shape \(3, 6\)"):
        low.reactions(np.array([1.0, 0, 0, 0, 0.1, 1.0, 0, 0, 0]), np.zeros(7),
                      out=np.empty((2, 6)))
