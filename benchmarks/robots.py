#!/usr/bin/env python
"""URDF robots: mbdyn against Pinocchio per call -- forward dynamics (``aba``), inverse
dynamics (``rnea``), mass matrix (``crba``) -- and the time to load a URDF file.

    python benchmarks/robots.py            # the robots of tests/data/ (and of
                                           # example-robot-data, when found)
    python benchmarks/robots.py --quick    # a shorter time budget

Pinocchio is for benchmarking only, never a dependency of mbdyn: install it into an
environment that also sees mbdyn's (as benchmarks/peers.py says), or, with Pinocchio in a
venv of its own (``python -m venv /tmp/pinvenv && /tmp/pinvenv/bin/pip install pin``,
the same numpy as mbdyn's environment), add its site folder on the way in:

    PYTHONPATH=. python -c "import site, runpy; \\
        site.addsitedir('/tmp/pinvenv/lib/python3.11/site-packages'); \\
        runpy.run_path('benchmarks/robots.py', run_name='__main__')"

Both sides read the same file with their own parser; the dampers, friction and stops
mbdyn makes of a URDF are switched off (Pinocchio's dynamics hold none), and the two are
checked to agree at the state timed.  mbdyn's entries: the ordinary API
(``Model.forward_dynamics(q, u)``, its default route; ``effort_array``, the generalized
forces as ``rnea`` gives them; ``inverse_dynamics``, which returns dictionaries of efforts
and reactions; ``mass_matrix``) and the low-level entry (``Model.lowlevel("auto")``:
``forward_dynamics``, ``inverse_dynamics``, ``mass_matrix``).  Per-call timing is
``forward_dynamics.measure`` (blocks sized to a time budget, rounds interleaved); the
ratio is mbdyn / Pinocchio.
"""
import os

for _var in ("OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "OMP_NUM_THREADS"):
    os.environ[_var] = "1"

import sys  # noqa: E402
import time  # noqa: E402
import warnings  # noqa: E402

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import forward_dynamics as fdb  # noqa: E402  (this folder: the per-call timer)
import numpy as np  # noqa: E402

DATA = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "tests", "data")
# (label, URDF file, floating base, options of mbdyn's reading)
ROBOTS = [(name, os.path.join(DATA, f"{name}.urdf"), floating, {})
          for name, floating in [("planar_arm", False), ("arm6", False), ("mixed", False),
                                 ("arm6", True)]]
# example-robot-data's (as benchmarks/robot_reference.py reads them: Panda's <mimic>
# removed, its fingers independent as in Pinocchio; TIAGo's antennas' inertia accepted)
ERD_ROBOTS = [
    ("ur5", "ur_description/urdf/ur5_robot.urdf", False, {}),
    ("panda", "panda_description/urdf/panda.urdf", False, {"strip_mimic": True}),
    ("solo12", "solo_description/robots/solo12.urdf", True, {}),
    ("tiago", "tiago_description/robots/tiago_no_hand.urdf", False,
     {"accept_inertia": True}),
]


def erd_folder():
    """example-robot-data's ``robots/`` folder (``$EXAMPLE_ROBOT_DATA``, or its cmeel
    prefix under a site folder on ``sys.path``), or None."""
    if os.environ.get("EXAMPLE_ROBOT_DATA"):
        return os.environ["EXAMPLE_ROBOT_DATA"]
    for entry in sys.path:
        folder = os.path.join(entry, "cmeel.prefix", "share", "example-robot-data", "robots")
        if os.path.isdir(folder):
            return folder
    return None


def robots():
    folder = erd_folder()
    if folder is None:
        return ROBOTS
    return ROBOTS + [(name, os.path.join(folder, rel), floating, options)
                     for name, rel, floating, options in ERD_ROBOTS
                     if os.path.isfile(os.path.join(folder, rel))]


def load_time(fn, rounds=20):
    """Median wall time of ``fn()`` over ``rounds`` calls (after one to warm up)."""
    fn()
    times = []
    for _ in range(rounds):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return float(np.median(times))


def pin_state(pmodel, model, q, u):
    """Pinocchio's ``(q, v)`` of mbdyn's ``(q, u)`` on a fixed base (joints by name;
    a continuous joint's angle as ``(cos, sin)``)."""
    import pinocchio as pin
    qp, vp = pin.neutral(pmodel), np.zeros(pmodel.nv)
    for jid in range(1, pmodel.njoints):
        j, name = pmodel.joints[jid], pmodel.names[jid]
        a = q[model.coordinates.index(name)]
        if j.nq == 2:
            qp[j.idx_q:j.idx_q + 2] = (np.cos(a), np.sin(a))
        else:
            qp[j.idx_q] = a
        vp[j.idx_v] = u[model.speeds.index(f"{name}_dot")]
    return qp, vp


def robot_rows(path, floating, options, budget, repeats):
    import re

    import pinocchio as pin

    import mbdyn as mb
    with open(path) as fh:
        text = fh.read()
    if options.get("strip_mimic"):
        text = re.sub(r"<mimic\b[^>]*/>", "", text)
    accept = options.get("accept_inertia", False)

    def read():
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            return mb.load_model(path, text=text, floating=floating, accept_inertia=accept)
    scene = read()
    model = scene.system.compile(effects=[f"-{n}" for n in scene.system.forces])
    pmodel = (pin.buildModelFromUrdf(path, pin.JointModelFreeFlyer()) if floating
              else pin.buildModelFromUrdf(path))
    pdata = pmodel.createData()
    rng = np.random.default_rng(1)
    q = model.default_coordinates() + rng.uniform(-1, 1, model.nq)
    model.normalize_quaternions(q)
    u = rng.normal(size=model.nu)
    ud = rng.normal(size=model.nu)
    low = model.lowlevel("auto")
    out = np.empty(model.nu)
    matrix = np.empty((model.nu, model.nu))
    wrenches = np.empty((model.n_frames, 6))
    cases = {
        "fd": (model.forward_dynamics, (q, u), {}, 1),
        "fd_low": (low.forward_dynamics, (q, u, 0.0, out), {}, 1),
        "id": (model.effort_array, (q, u, ud), {}, 1),
        "id_low": (low.inverse_dynamics, (q, u, ud, 0.0, out), {}, 1),
        "id_dict": (model.inverse_dynamics, (q, u, ud), {}, 1),
        "M": (model.mass_matrix, (q,), {}, 1),
        "M_low": (low.mass_matrix, (q, 0.0, matrix), {}, 1),
        "react": (model.reaction_array, (q, u), {}, 1),
        "react_low": (low.reactions, (q, u, 0.0, wrenches), {}, 1),
        "react_dict": (model.reactions, (q, u), {}, 1),
    }
    ratios = [("fd", "aba"), ("fd_low", "aba"), ("id", "rnea"), ("id_low", "rnea"),
              ("id_dict", "rnea"), ("M", "crba"), ("M_low", "crba"),
              ("react", "aba_rnea"), ("react_low", "aba_rnea"), ("react_dict", "aba_rnea")]
    if not floating:                         # the free flyer's speeds differ: not mapped
        qp, vp = pin_state(pmodel, model, q, u)
        tau = np.zeros(pmodel.nv)
        ap = pin_state(pmodel, model, q, ud)[1]
        ours = model.forward_dynamics(q, u)
        theirs = pin.aba(pmodel, pdata, qp, vp, tau)
        order = [model.speeds.index(f"{pmodel.names[j]}_dot") for j in range(1, pmodel.njoints)]
        assert np.allclose(ours[order], theirs, rtol=1e-9, atol=1e-9), (ours, theirs)
    else:
        qp, vp = pin.randomConfiguration(pmodel, -np.ones(pmodel.nq), np.ones(pmodel.nq)), \
            rng.normal(size=pmodel.nv)
        tau, ap = np.zeros(pmodel.nv), rng.normal(size=pmodel.nv)
    cases.update({
        "aba": (pin.aba, (pmodel, pdata, qp, vp, tau), {}, 1),
        "rnea": (pin.rnea, (pmodel, pdata, qp, vp, ap), {}, 1),
        "crba": (pin.crba, (pmodel, pdata, qp), {}, 1),
        # what reactions cost Pinocchio: the accelerations (aba), then the joint forces
        # of that motion (rnea, which leaves them in data.f)
        "aba_rnea": (lambda: pin.rnea(pmodel, pdata, qp, vp, pin.aba(pmodel, pdata, qp, vp,
                                                                      tau)), (), {}, 1),
    })
    stats, ratio = fdb.measure(cases, budget, repeats, ratios)

    load = (load_time(read), load_time(lambda: pin.buildModelFromUrdf(path)))
    return model.nu, stats, ratio, load


def main():
    quick = "--quick" in sys.argv
    budget, repeats = (1.0, 5) if quick else (4.0, 9)
    import pinocchio as pin
    print(f"Pinocchio {pin.__version__}; microseconds per call (median), ratio mbdyn / "
          "Pinocchio\n")
    print("| robot | nu | fd (ordinary) | fd (low-level) | aba | id (ordinary) | id (low-level) "
          "| id (dicts) | rnea | M (ordinary) | M (low-level) | crba | "
          "load mbdyn / Pinocchio (ms) |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|---|")
    reaction_rows = []
    for name, path, floating, options in robots():
        nu, st, ratio, load = robot_rows(path, floating, options, budget, repeats)
        reaction_rows.append((name, floating, nu, st, ratio))

        def us(key, against=None):
            text = f"{st[key]['median_us']:.2f}"
            return text + (f" ({ratio[(key, against)]['median']:.2f}x)" if against else "")
        print(f"| {name}{' floating' if floating else ''} | {nu} | {us('fd', 'aba')} | "
              f"{us('fd_low', 'aba')} | {us('aba')} | {us('id', 'rnea')} | "
              f"{us('id_low', 'rnea')} | {us('id_dict', 'rnea')} | {us('rnea')} | "
              f"{us('M', 'crba')} | {us('M_low', 'crba')} | {us('crba')} | {load[0] * 1e3:.1f} / "
              f"{load[1] * 1e3:.2f} |", flush=True)
    print("\nReactions (issue 25, item 8): every joint's wrench, against Pinocchio's aba + "
          "rnea\n")
    print("| robot | nu | reaction_array | lowlevel().reactions | reactions (dicts) | "
          "aba + rnea |")
    print("|---|---|---|---|---|---|")
    for name, floating, nu, st, ratio in reaction_rows:
        def us2(key, against=None):
            text = f"{st[key]['median_us']:.2f}"
            return text + (f" ({ratio[(key, against)]['median']:.2f}x)" if against else "")
        print(f"| {name}{' floating' if floating else ''} | {nu} | "
              f"{us2('react', 'aba_rnea')} | {us2('react_low', 'aba_rnea')} | "
              f"{us2('react_dict', 'aba_rnea')} | {us2('aba_rnea')} |")


if __name__ == "__main__":
    main()
