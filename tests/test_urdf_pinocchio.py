"""URDF robots against Pinocchio: mass matrix, bias forces, forward and inverse dynamics,
frame placements and frame Jacobians at seeded random states, to 1e-9 relative.

The reference arrays are ``tests/data/urdf_reference.json``, written by
``benchmarks/urdf_reference.py`` with Pinocchio's own URDF parser (urdfdom) in an
environment of its own: Pinocchio is neither a dependency nor imported here.  A wrong
import convention (rpy order, axis frame, inertia frame, the free base's speeds) fails
these comparisons by far more than the tolerance.
"""
import json
import pathlib

import numpy as np
import pytest

import mbdyn as mb
from reference_states import indices, states

DATA = pathlib.Path(__file__).resolve().parent / "data"
REFERENCE = json.loads((DATA / "urdf_reference.json").read_text())
CASES = [(r["file"], r["floating"]) for r in REFERENCE["robots"]]
RTOL = 1e-9


def close(ours, theirs):
    theirs = np.asarray(theirs)
    scale = max(np.abs(theirs).max(), 1e-300)
    assert np.abs(np.asarray(ours) - theirs).max() <= RTOL * scale, (ours, theirs)


@pytest.fixture(scope="module", params=CASES, ids=[f"{f}{'-floating' * fl}" for f, fl in CASES])
def robot(request):
    file, floating = request.param
    entry = next(r for r in REFERENCE["robots"] if (r["file"], r["floating"]) == request.param)
    scene = mb.load_model(DATA / file, floating=floating)
    # Pinocchio's dynamics hold no dampers, friction or stops: switch them off
    model = scene.system.compile(effects=[f"-{n}" for n in scene.system.forces])
    qi, ui = indices(model, entry)
    return model, entry, qi, ui


def test_gravity_is_the_references(robot):
    model, *_ = robot
    assert np.array_equal(model.gravity, REFERENCE["gravity"])


def test_mass_matrix_and_bias_forces(robot):
    model, entry, qi, ui = robot
    for st, q, u in states(model, entry, qi, ui):
        close(model.mass_matrix(q)[np.ix_(ui, ui)], st["M"])
        close(-model.forcing(q, u)[ui], st["nle"])       # M u' = f = tau - nle


def test_forward_dynamics_with_joint_efforts(robot):
    model, entry, qi, ui = robot
    for st, q, u in states(model, entry, qi, ui):
        tau = np.zeros(model.nu)
        tau[ui] = st["tau"]
        ud = np.linalg.solve(model.mass_matrix(q), model.forcing(q, u) + tau)
        close(ud[ui], st["ud"])
        free = np.linalg.solve(np.array(st["M"]), -np.array(st["nle"]))   # no efforts
        for method in ("jourdain", "articulated", "newton-euler"):
            close(model.forward_dynamics(q, u, method=method)[ui], free)


def test_inverse_dynamics(robot):
    model, entry, qi, ui = robot
    for st, q, u in states(model, entry, qi, ui):
        a = np.zeros(model.nu)
        a[ui] = st["a"]
        efforts, _ = model.inverse_dynamics(q, u, a)
        close([efforts[model.speeds[i]] for i in ui], st["rnea"])


def test_frame_placements_and_jacobians(robot):
    model, entry, qi, ui = robot
    for st, q, u in states(model, entry, qi, ui):
        k = model.kinematics(q)
        for frame, ref in st["frames"].items():
            i = model.frame_index(frame)
            close(k.R[i], ref["R"])
            close(k.r[i], ref["p"])
            J = np.vstack([model.jacobian_translation(q, frame, point=(0, 0, 0)),
                           model.jacobian_rotation(q, frame)])
            close(J[:, ui], ref["J"])
