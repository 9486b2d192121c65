"""Robots of example-robot-data against Pinocchio (issue 25): UR5, Panda, Solo12 on a
free-flyer base, TIAGo (continuous, prismatic and fixed joints).  Mass matrix, bias forces,
forward and inverse dynamics, link placements and frame Jacobians (world axes, at the
frame's origin) at seeded random states, to 1e-9 relative: the largest absolute error of
an array at most 1e-9 times the reference array's largest absolute entry (max norm).

The reference arrays are ``tests/data/robot_reference.json``, written by
``benchmarks/robot_reference.py`` with Pinocchio's own URDF parser; neither Pinocchio nor
example-robot-data is a dependency.  The URDF files themselves are example-robot-data's:
found through ``$EXAMPLE_ROBOT_DATA`` (its ``robots/`` folder), the installed package
(``example_robot_data.getModelPath``), or its cmeel prefix under a site folder on
``sys.path`` or in ``/tmp/pinvenv``; the tests skip when none is there.  Placements are
compared, not only quantities a convention leaves unchanged, so a wrong import convention
(rpy order, axis or inertia frame, a fixed joint's placement) fails.
"""
import contextlib
import glob
import json
import os
import pathlib
import re
import sys
import warnings

import numpy as np
import pytest

import mbdyn as mb
from reference_states import indices, states

DATA = pathlib.Path(__file__).resolve().parent / "data"
REFERENCE = json.loads((DATA / "robot_reference.json").read_text())
ROBOTS = [r["name"] for r in REFERENCE["robots"]]
RTOL = 1e-9
CMEEL = os.path.join("cmeel.prefix", "share", "example-robot-data", "robots")


def robots_folder():
    """example-robot-data's ``robots/`` folder, or None."""
    candidates = []
    if os.environ.get("EXAMPLE_ROBOT_DATA"):
        candidates.append(os.environ["EXAMPLE_ROBOT_DATA"])
    with contextlib.suppress(Exception):          # absent or broken: look elsewhere
        from example_robot_data import getModelPath
        candidates.append(os.path.join(getModelPath("ur_description/urdf/ur5_robot.urdf"),
                                       "robots"))
    candidates += [os.path.join(entry, CMEEL) for entry in sys.path]
    candidates += glob.glob(os.path.join("/tmp/pinvenv/lib/python3*/site-packages", CMEEL))
    for folder in candidates:
        if os.path.isfile(os.path.join(folder, REFERENCE["robots"][0]["file"])):
            return pathlib.Path(folder)
    return None


FOLDER = robots_folder()
pytestmark = pytest.mark.skipif(
    FOLDER is None, reason="example-robot-data's robots not found (pip install "
    "example-robot-data, or set EXAMPLE_ROBOT_DATA to its robots/ folder)")


def error(ours, theirs):
    """The relative error ``max|ours - theirs| / max|theirs|``."""
    theirs = np.asarray(theirs, dtype=float)
    return np.abs(np.asarray(ours) - theirs).max() / max(np.abs(theirs).max(), 1e-300)


def close(ours, theirs, what=""):
    e = error(ours, theirs)
    assert e <= RTOL, f"{what}: relative error {e:.3g}"


def load(entry):
    """mbdyn's model of a reference robot, with the effects Pinocchio has not (dampers,
    friction, stops) switched off; a ``<mimic>`` removed when the reference has it
    independent."""
    path = FOLDER / entry["file"]
    options = entry["options"]
    text = path.read_text()
    if options.get("strip_mimic"):
        text = re.sub(r"<mimic\b[^>]*/>", "", text)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")          # meshes (package://...), tiny inertias
        scene = mb.load_model(path, text=text, floating=entry["floating"],
                              accept_inertia=options.get("accept_inertia", False))
    assert not [j for j in scene.system.joints if j.startswith("mimic_")]
    return scene.system.compile(effects=[f"-{n}" for n in scene.system.forces])


@pytest.fixture(scope="module", params=ROBOTS)
def robot(request):
    entry = next(r for r in REFERENCE["robots"] if r["name"] == request.param)
    model = load(entry)
    qi, ui = indices(model, entry)
    return model, entry, qi, ui


def test_gravity_is_the_references(robot):
    model, *_ = robot
    assert np.array_equal(model.gravity, REFERENCE["gravity"])


def test_mass_matrix_and_bias_forces(robot):
    model, entry, qi, ui = robot
    for st, q, u in states(model, entry, qi, ui):
        close(model.mass_matrix(q)[np.ix_(ui, ui)], st["M"], "M")
        close(-model.forcing(q, u)[ui], st["nle"], "bias")    # M u' = f = tau - nle


def test_forward_dynamics(robot):
    model, entry, qi, ui = robot
    for st, q, u in states(model, entry, qi, ui):
        tau = np.zeros(model.nu)
        tau[ui] = st["tau"]
        ud = np.linalg.solve(model.mass_matrix(q), model.forcing(q, u) + tau)
        close(ud[ui], st["ud"], "aba")
        free = np.linalg.solve(np.array(st["M"]), -np.array(st["nle"]))   # no efforts
        for method in ("jourdain", "articulated", "newton-euler"):
            close(model.forward_dynamics(q, u, method=method)[ui], free, method)


def test_inverse_dynamics(robot):
    model, entry, qi, ui = robot
    for st, q, u in states(model, entry, qi, ui):
        a = np.zeros(model.nu)
        a[ui] = st["a"]
        efforts, _ = model.inverse_dynamics(q, u, a)
        close([efforts[model.speeds[i]] for i in ui], st["rnea"], "rnea")


def test_frame_placements_and_jacobians(robot):
    model, entry, qi, ui = robot
    for st, q, u in states(model, entry, qi, ui):
        k = model.kinematics(q)
        for frame, ref in st["frames"].items():
            i = model.frame_index(frame)
            close(k.R[i], ref["R"], f"{frame} R")
            close(k.r[i], ref["p"], f"{frame} p")
            J = np.vstack([model.jacobian_translation(q, frame, point=(0, 0, 0)),
                           model.jacobian_rotation(q, frame)])
            close(J[:, ui], ref["J"], f"{frame} J")


def test_a_wrong_convention_fails():
    """The comparison is not blind to conventions: UR5 read with its joints' rpy order
    reversed (``rpy`` as ``(y, p, r)``) misses the placements by far more than 1e-9."""
    entry = next(r for r in REFERENCE["robots"] if r["name"] == "ur5")
    text = (FOLDER / entry["file"]).read_text()

    def swap(m):
        r, p, y = m.group(1).split()
        return f'rpy="{y} {p} {r}"'
    bad = re.sub(r'rpy="([^"]*)"', swap, text)
    assert bad != text
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        scene = mb.load_model(FOLDER / entry["file"], text=bad)
    model = scene.system.compile(effects=[f"-{n}" for n in scene.system.forces])
    qi = [model.coordinates.index(n) for n in entry["coordinates"]]
    st = entry["states"][0]
    q = np.zeros(model.nq)
    q[qi] = st["q"]
    k = model.kinematics(q)
    worst = max(max(error(k.R[model.frame_index(f)], ref["R"]),
                    error(k.r[model.frame_index(f)], ref["p"]))
                for f, ref in st["frames"].items())
    assert worst > 1e-3
