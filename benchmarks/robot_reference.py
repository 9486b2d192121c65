#!/usr/bin/env python
"""Reference dynamics of robots of example-robot-data computed by Pinocchio, written to
``tests/data/robot_reference.json`` (committed), which ``tests/test_robot_reference.py``
compares mbdyn against (issue 25).  Pinocchio and example-robot-data are never
dependencies of mbdyn: run this script in an environment of their own,

    python -m venv /tmp/pinvenv && /tmp/pinvenv/bin/pip install pin example-robot-data
    /tmp/pinvenv/bin/python benchmarks/robot_reference.py

The quantities and the mapping of states are those of ``benchmarks/urdf_reference.py``
(its ``one_state``: mass matrix, bias forces, forward and inverse dynamics, placements and
``LOCAL_WORLD_ALIGNED`` Jacobians of link frames, all in mbdyn's coordinates), here for

* UR5 (``ur_description/urdf/ur5_robot.urdf``): 6 revolute joints, fixed joints;
* Panda (``panda_description/urdf/panda.urdf``): 7 revolute, 2 prismatic fingers.  The
  second finger ``<mimic>``s the first: Pinocchio's parser (``mimic=False``, its default)
  makes it an independent joint, mbdyn a ``coupling`` loop joint; the test reads the file
  with its ``<mimic>`` removed, so both have the same tree;
* Solo12 (``solo_description/robots/solo12.urdf``), a quadruped on a free-flyer base;
* TIAGo without hand (``tiago_description/robots/tiago_no_hand.urdf``): continuous wheel
  joints, a prismatic torso lift and 25 fixed joints (the only robot of example-robot-data
  with all three besides PR2, which is far larger and full of mimics).  Two antenna links
  have a slightly negative principal moment: mbdyn reads it with ``accept_inertia`` (the
  moment set to 0); they hang by fixed joints from the fixed base, so no dynamics sees
  them.

Robots are stored by their path relative to example-robot-data's ``robots/`` folder; the
test reads the same files.  Frames: a few link frames per robot (evenly spread over
Pinocchio's body frames, the last always among them, and a wheel and a finger).
"""
from __future__ import annotations

import json
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
try:
    import pinocchio as pin
except ImportError:  # pragma: no cover - the generator's own environment
    sys.exit("this generator needs Pinocchio: pip install pin example-robot-data "
             "(in an environment of their own)")
from robots import ERD_ROBOTS, erd_folder
from urdf_reference import names_of, one_state, random_state

HERE = os.path.dirname(os.path.abspath(__file__))
DATA = os.path.join(HERE, "..", "tests", "data")
# (name, path under robots/, floating base, options for mbdyn's reader): the robots
# benchmarks/robots.py times
ROBOTS = ERD_ROBOTS
STATES = 2
FRAMES = 6
SEED = 2026


def robots_folder():
    """example-robot-data's ``robots/`` (``robots.erd_folder``), or exit saying how to get
    it."""
    folder = erd_folder()
    if folder is None:
        sys.exit("example-robot-data not found: pip install example-robot-data, or set "
                 "EXAMPLE_ROBOT_DATA to its robots/ folder")
    return folder


EXTRA_FRAMES = {"panda": ["panda_rightfinger"], "tiago": ["wheel_right_link"]}


def pick_frames(name, model):
    bodies = [f.name for f in model.frames
              if f.type == pin.FrameType.BODY and f.name not in ("world", "universe")]
    idx = np.unique(np.linspace(0, len(bodies) - 1, FRAMES).round().astype(int))
    return [bodies[i] for i in idx] + EXTRA_FRAMES.get(name, [])


def main():
    folder = robots_folder()
    rng = np.random.default_rng(SEED)
    out = {"generator": "benchmarks/robot_reference.py", "pinocchio": pin.__version__,
           "gravity": [0.0, 0.0, -9.81], "robots": []}
    for name, rel, floating, options in ROBOTS:
        path = os.path.join(folder, rel)
        model = (pin.buildModelFromUrdf(path, pin.JointModelFreeFlyer()) if floating
                 else pin.buildModelFromUrdf(path))
        model.gravity.linear = np.array(out["gravity"])
        data = model.createData()
        coords, speeds = names_of(model, floating)
        frames = pick_frames(name, model)
        states = []
        for _ in range(STATES):
            q, v = random_state(model, rng, floating)
            tau = rng.normal(size=model.nv)
            a = rng.normal(size=model.nv)
            st = one_state(model, data, q, v, tau, a, floating)
            st["frames"] = {f: st["frames"][f] for f in frames}
            states.append(st)
        out["robots"].append({"name": name, "file": rel, "floating": floating,
                              "options": options, "coordinates": coords,
                              "speeds": speeds, "states": states})
        print(f"{name}: nq {model.nq}, nv {model.nv}, frames {frames}")
    target = os.path.join(DATA, "robot_reference.json")
    with open(target, "w") as fh:
        json.dump(out, fh, separators=(",", ":"))
        fh.write("\n")
    print(f"wrote {os.path.relpath(target)} ({os.path.getsize(target) // 1024} kB)")


if __name__ == "__main__":
    main()
