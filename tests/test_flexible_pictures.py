"""Flexible bodies in the pictures (``viz.flexible_shapes``): the deformed shape drawn from
the run's modal coordinates, scaled so that it shows, and said so in the title."""
from __future__ import annotations

import numpy as np
import pytest

import mbdyn as mb
from mbdyn.viz.flexible_shapes import DRAWN, deflection_scale, flexible_primitives
from mbdyn.viz.geometry import prepare
from mbdyn.viz.view_data import view_data

EB = {"length": 1.0, "elements": 10, "E": 2.1e11, "rho": 7850.0, "nu": 0.3,
      "section": {"circle": 0.02}, "theory": "euler-bernoulli"}


@pytest.fixture(scope="module")
def sagging():
    """A steel cantilever released straight under gravity (damped): it sags, ~2 mm."""
    s = mb.System("cantilever")
    s.add_body("beam", flexible={"beam": EB, "modes": 4, "damping": 0.05})
    s.add_joint("clamp", "fixed", "ground", "beam")
    m = s.compile()
    return mb.simulate(m, 0.2, np.zeros(m.nq), np.zeros(m.nu), integrator="DOP853",
                       rtol=1e-8, atol=1e-12)


def test_segments_join_the_deformed_nodes(sagging):
    """Each cylinder's centre is the midpoint of its two nodes at ``x_i + s Phi_i eta``,
    the deflection read through ``FlexibleModel.node_row`` (another route to the mode
    shapes), and its axis runs from one node to the next."""
    m = sagging.model
    q = sagging.q[-1]
    scale = deflection_scale(m, sagging.q)
    prims = flexible_primitives(m, m.kinematics(q, np.zeros(m.nu)), q, scale)
    nodes = m.flexible["beam"].reduced.nodes
    assert len(prims) == len(nodes) - 1
    deformed = np.array([[nodes[i, c] + scale * m.node_row(f"beam.{i}.{'xyz'[c]}",
                                                           m.coordinates) @ q
                          for c in range(3)] for i in range(len(nodes))])
    for k, (kind, (R, centre), size, _) in enumerate(prims):
        a, b = deformed[k], deformed[k + 1]
        assert kind == "cylinder"
        assert np.allclose(centre, 0.5 * (a + b), atol=1e-12)
        assert np.allclose(R[:, 2], (b - a) / np.linalg.norm(b - a), atol=1e-12)
        assert np.allclose(R.T @ R, np.eye(3), atol=1e-12)
        assert size[1] == pytest.approx(np.linalg.norm(nodes[k + 1] - nodes[k]))
    assert deformed[-1, 2] < -0.5 * scale * 1.8e-3        # the tip sags, drawn larger


def test_scale_is_a_round_number_that_shows_the_largest_deflection(sagging):
    m = sagging.model
    scale = deflection_scale(m, sagging.q)
    largest = max(np.abs(m.node_row(f"beam.{i}.z", m.coordinates) @ q)
                  for q in sagging.q for i in range(11))
    assert scale * largest <= DRAWN * 1.0 * (1 + 1e-12)
    assert scale * largest > DRAWN * 1.0 / 2.5            # rounded down to 1, 2, 5 x 10^k
    mantissa = scale / 10 ** np.floor(np.log10(scale))
    assert min(abs(mantissa - v) for v in (1, 2, 5)) < 1e-9
    run = prepare(sagging, np.linspace(0, 0.2, 3))
    assert run.deflection_scale == scale
    assert f"flexible deflections x{scale:g}" in view_data(run, "t", 1.0, 30.0, 10)["title"]


def test_rigid_bodies_and_flexibility_off_draw_nothing_more():
    s = mb.System("p")
    s.add_body("arm", flexible={"beam": EB, "modes": 2})
    s.add_joint("pin", "revolute", "ground", "arm", axis="y")
    rigid = s.compile(effects={"flexibility_arm": False})
    res = mb.simulate(rigid, 0.05, [0.3], [0.0], integrator="rk4", dt=1e-3)
    assert deflection_scale(rigid, res.q) == 1.0
    assert flexible_primitives(rigid, rigid.kinematics(res.q[-1], res.u[-1]), res.q[-1]) == []
    assert "flexible" not in view_data(prepare(res, [0.0, 0.05]), "t", 1.0, 30.0, 10)["title"]


def test_a_body_at_a_node_moves_the_modal_coordinates_in_the_state():
    """With a pendulum at the beam's tip (a node frame) the modal coordinates sit
    elsewhere in ``q`` than after the tree's: the drawing reads them by name; the tip's
    segment ends at the deformed tip, drawn ``s`` times, the bob at the true one."""
    s = mb.System("tip", gravity=(0, 0, -9.81))
    s.add_body("beam", flexible={"beam": EB, "modes": 3})
    s.add_joint("clamp", "fixed", "ground", "beam")
    s.add_body("bob", mass=1.0, inertia=[1e-3] * 3)
    s.add_joint("hang", "revolute", "beam", "bob", axis="y", position="tip")
    m = s.compile()
    assert m.coordinates[0] == "hang"
    q = m.q_vector({"beam_m1": 2e-3, "hang": 0.3})
    kin = m.kinematics(q)
    prims = flexible_primitives(m, kin, q, 10.0)
    tip = np.array([1.0, 0, 0]) + np.array([m.node_row(f"beam.tip.{c}", m.coordinates) @ q
                                           for c in "xyz"])
    (kind, (R, centre), size, _) = prims[-1]
    end = centre + 0.5 * size[1] * R[:, 2]
    assert np.allclose(end, [1.0, 0, 0] + 10.0 * (tip - [1.0, 0, 0]), atol=1e-3 * size[1])
    assert np.allclose(kin.r[m.frame_index("bob")], tip, atol=1e-15)
