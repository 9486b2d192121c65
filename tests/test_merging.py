"""Rigidly attached frames merged into their carriers for the per-call dynamics
(``compiled.merging``): the merged tree gives the full tree's answers.

Every model is compiled twice, merged and with merging switched off (``merging.plan``
returning ``None``), and the per-call entries -- forward dynamics (``auto``,
``articulated``, ``state_derivative``), ``effort_array``, ``mass_matrix``, the low-level
entry's four -- agree to rounding; so do the routes that keep the full tree (Jourdain,
reactions, ``inverse_dynamics``).  The test robot has fixed frames on the ground, a chain
of fixed frames carrying mass and the next joint, a spherical joint below a fixed frame,
point loads and force elements on fixed frames (those are kept), a joint damper and an
actuator whose joint's parent is merged, a drive, and the gyroscopic effect off.  Models
that name frames inside their numbers (contacts, gravity compensation) or close loops are
not merged.  The ordinary entries' calls with no dispatch (``kernels.entries.direct``)
leave any other input to the checked route, arrays they would misread among them.
"""
import numpy as np
import pytest
import sympy

import mbdyn as mb
from mbdyn.compiled import merging


def rot(axis, angle):
    a = np.asarray(axis, float) / np.linalg.norm(axis)
    K = np.array([[0, -a[2], a[1]], [a[2], 0, -a[0]], [-a[1], a[0], 0]])
    return np.eye(3) + np.sin(angle) * K + (1 - np.cos(angle)) * K @ K


def inertia(rng, m):
    A = rng.normal(size=(3, 3))
    Q = np.linalg.qr(A)[0]
    return m * Q @ np.diag(rng.uniform(0.01, 0.05, 3)) @ Q.T


def robot(loads=False, drive=False, actuator=False):
    """A robot-like tree: base and plate fixed on the ground, link1 (revolute) carrying a
    cover, link2 below the cover carrying a flange and a tool, a finger sliding on the
    tool, a sensor fixed on link1 carrying a ball joint."""
    rng = np.random.default_rng(5)
    s = mb.System("merge-robot", gravity=(0.3, -0.2, -9.81))
    for name, m in [("base", 5.0), ("plate", 1.0), ("link1", 2.0), ("cover", 0.5),
                    ("link2", 1.5), ("flange", 0.0), ("tool", 0.3), ("finger", 0.1),
                    ("sensor", 0.2), ("ball", 0.4)]:
        if m:
            s.add_body(name, m, com=rng.normal(scale=0.1, size=3), inertia=inertia(rng, m))
        else:
            s.add_frame(name)
    t = mb.t
    s.add_joint("base_fix", "fixed", "ground", "base", position=(0.1, 0.0, 0.3),
                orientation=rot((1, 1, 0), 0.4))
    s.add_joint("plate_fix", "fixed", "base", "plate", position=(0.0, 0.2, 0.0))
    s.add_joint("j1", "revolute", "base", "link1", axis=(0, 0.6, 0.8), position=(0, 0, 0.2),
                drive=0.3 * sympy.sin(2 * t) if drive else None)
    s.add_joint("cover_fix", "fixed", "link1", "cover", position=(0.3, 0.0, 0.05),
                orientation=rot((0, 1, 1), -0.7))
    s.add_joint("j2", "revolute", "cover", "link2", axis=(1, 0, 0), position=(0, 0.1, 0))
    s.add_joint("flange_fix", "fixed", "link2", "flange", position=(0.4, 0, 0),
                orientation=rot((1, 0, 1), 1.1))
    s.add_joint("tool_fix", "fixed", "flange", "tool", position=(0, 0, 0.1))
    s.add_joint("j3", "prismatic", "tool", "finger", axis=(0, 1, 0), position=(0.05, 0, 0))
    s.add_joint("sensor_fix", "fixed", "link1", "sensor", position=(0, 0.2, 0.1),
                orientation=rot((0, 0, 1), 0.5))
    s.add_joint("j4", "spherical", "sensor", "ball", position=(0, 0, 0.1))
    if loads:
        s.add_load("push", "plate", force=(1.0, 2.0, 0.5), point=(0.1, 0, 0))
        s.add_load("twist", "link2", moment=(0.2, 0.0, -0.3), frame="body")
        s.add_force("tie", "spring-damper", body_a="ground", point_a=(0.5, 0.5, 1.0),
                    body_b="sensor", point_b=(0.02, 0, 0), stiffness=80.0, damping=2.0,
                    free_length=0.3)
        s.add_force("torsion", "joint-spring-damper", joint="j2", stiffness=3.0,
                    damping=0.2)
    if actuator:
        s.add_actuator("grip", "j3", "pd", kp=50.0, kd=2.0, setpoint=0.01)
    return s


def compiled_pair(system, monkeypatch, **options):
    merged = system.compile(**options)
    with monkeypatch.context() as m:
        m.setattr(merging, "plan", lambda model, loop_joints=0: None)
        full = system.compile(**options)
    return merged, full


def state(model, seed=1):
    rng = np.random.default_rng(seed)
    q = model.default_coordinates() + rng.uniform(-0.8, 0.8, model.nq)
    model.normalize_quaternions(q)
    return q, rng.normal(size=model.nu), rng.normal(size=model.nu)


def close(a, b, tol=1e-12):
    a, b = np.asarray(a), np.asarray(b)
    assert np.abs(a - b).max() <= tol * max(1.0, np.abs(b).max()), np.abs(a - b).max()


CASES = {"plain": {}, "loads": {"loads": True}, "drive": {"drive": True, "loads": True},
         "actuator": {"actuator": True, "loads": True}}


@pytest.mark.parametrize("case", CASES)
@pytest.mark.parametrize("gyroscopic", [True, False])
def test_the_merged_tree_gives_the_full_trees_dynamics(case, gyroscopic, monkeypatch):
    effects = None if gyroscopic else {"gyroscopic": False}
    merged, full = compiled_pair(robot(**CASES[case]), monkeypatch, effects=effects)
    expected = {"plain": 6, "loads": 4, "drive": 4, "actuator": 4}[case]
    assert merged._merged_frames == expected and full._merged_frames == 0
    q, u, ud = state(merged)
    for model in (merged, full):              # twice: the checked call, then the frozen one
        for _ in range(2):
            model._result = (model.forward_dynamics(q, u, 0.4),
                             model.forward_dynamics(q, u, 0.4, method="articulated"),
                             model.effort_array(q, u, ud, 0.4), model.mass_matrix(q, 0.4),
                             model.state_derivative(0.4, np.concatenate([q, u]),
                                                    "articulated"))
    for a, b in zip(merged._result, full._result):
        close(a, b)
    jourdain = full.forward_dynamics(q, u, 0.4, method="jourdain")
    close(merged._result[0], jourdain, 1e-9)
    # the routes that keep the full tree: every joint's reaction, fixed ones too
    close(merged.reaction_array(q, u, 0.4), full.reaction_array(q, u, 0.4))
    efforts, reactions = merged.inverse_dynamics(q, u, merged._result[0], 0.4)
    assert np.abs(list(efforts.values())).max() < 1e-9 * np.abs(merged._result[2]).max()
    wrenches = merged.reaction_array(q, u, 0.4)
    assert np.abs(wrenches[merged.joints.index("cover_fix")]).max() > 0.1
    for k, name in enumerate(merged.joints):
        close(np.concatenate(reactions[name]), wrenches[k], 1e-9)


@pytest.mark.parametrize("case", ["plain", "loads"])
def test_the_low_level_entry_on_the_merged_tree(case, monkeypatch):
    merged, full = compiled_pair(robot(**CASES[case]), monkeypatch)
    q, u, ud = state(merged, 2)
    for method in ("articulated", "jourdain"):
        a, b = merged.lowlevel(method), full.lowlevel(method)
        close(a.forward_dynamics(q, u).copy(), b.forward_dynamics(q, u))
        y = np.concatenate([q, u])
        close(a.state_derivative(y).copy(), b.state_derivative(y))
        close(a.inverse_dynamics(q, u, ud).copy(), b.inverse_dynamics(q, u, ud))
        close(a.mass_matrix(q).copy(), b.mass_matrix(q))
        close(a.reactions(q, u).copy(), b.reactions(q, u))


def test_merged_bodies_hold_the_whole_mass_and_its_centre(monkeypatch):
    """The merged tree's bodies, placed by the kinematics of the full tree, have the
    mass and the first moment of the frames they carry (the ground keeps its own)."""
    merged, _ = compiled_pair(robot(), monkeypatch)
    keep = merged._keep
    carrier, R, p = merging.placements(merged)
    plan = merging.plan(merged)
    moving = [i for i in range(merged.n_frames) if carrier[i] >= 0]
    assert np.isclose(plan["mass"].sum(), merged._mass[moving].sum())
    q = state(merged)[0]
    kin = merged.kinematics(q, np.zeros(merged.nu))
    first = sum(merged._mass[i] * (kin.r[i] + kin.R[i] @ merged._com[i]) for i in moving)
    kept = np.flatnonzero(keep)
    mine = sum(plan["mass"][k] * (kin.r[i] + kin.R[i] @ plan["com"][k])
               for k, i in enumerate(kept))
    close(mine, first)


def contact_robot():
    s = robot()
    s.add_shape("pad", "sphere", "tool", radius=0.05)
    s.add_shape("floor", "plane", "ground", normal=(0, 0, 1))
    s.add_contact("touch", pairs=[("pad", "floor")], stiffness=1e4)
    return s


def compensated_robot():
    s = robot()
    s.add_actuator("hold", "j2", "pd", kp=10.0, kd=1.0, setpoint=0.0,
                   gravity_compensation=True)
    return s


def loop_robot():
    s = robot()
    s.add_joint("close", "spherical", "ball", "ground", position=(0, 0, 0.3),
                child_position=(0.3, 0.5, 0.6))
    return s


@pytest.mark.parametrize("build", [contact_robot, compensated_robot])
def test_models_naming_frames_in_their_numbers_are_not_merged(build, monkeypatch):
    merged, full = compiled_pair(build(), monkeypatch)
    assert merged._merged_frames == 0
    q, u, ud = state(merged)
    close(merged.forward_dynamics(q, u), full.forward_dynamics(q, u))
    close(merged.effort_array(q, u, ud), full.effort_array(q, u, ud))


def unaligned(x):
    """``x``'s values in a float64 array whose data starts one byte off an 8-byte boundary."""
    raw = np.zeros(x.size * 8 + 1, np.uint8)
    out = np.ndarray(x.shape, np.float64, raw.data, offset=1)
    out[:] = x
    assert not out.flags.aligned
    return out


def test_the_direct_calls_leave_arrays_they_would_misread_to_the_checked_route():
    """The compiled entry that the ordinary methods call with no dispatch unboxes its
    arguments unchecked: an int64 array would be read as float64, a 2-d one overrun, a
    byte-swapped one read as garbage.  ``inputs.fits`` sends each of them to the checked
    route, which converts or rejects it as for any caller."""
    model = robot(loads=True).compile()
    q, u, ud = state(model)
    for _ in range(2):                        # the checked call, then the direct one
        ref = (model.forward_dynamics(q, u), model.effort_array(q, u, ud),
               model.mass_matrix(q))
    assert {"auto", "efforts", "mass matrix"} <= set(model._fast_calls)
    whole = np.round(q * 3)                   # integer values: exact as int64
    ref_whole = (model.forward_dynamics(whole, u), model.effort_array(whole, u, ud),
                 model.mass_matrix(whole))
    as_int = whole.astype(np.int64)
    assert np.array_equal(model.forward_dynamics(as_int, u), ref_whole[0])
    assert np.array_equal(model.effort_array(as_int, u, ud), ref_whole[1])
    assert np.array_equal(model.effort_array(whole, u.astype(">f8"), ud), ref_whole[1])
    assert np.array_equal(model.mass_matrix(as_int), ref_whole[2])
    swapped = q.astype(">f8")
    assert np.array_equal(model.forward_dynamics(swapped, u), ref[0])
    assert np.array_equal(model.mass_matrix(swapped), ref[2])
    odd = unaligned(q)
    assert np.array_equal(model.forward_dynamics(odd, unaligned(u)), ref[0])
    assert np.array_equal(model.effort_array(q, u, unaligned(ud)), ref[1])
    assert np.array_equal(model.mass_matrix(odd), ref[2])
    for column in (q.reshape(-1, 1), q.reshape(1, -1)):
        with pytest.raises(mb.ModelError, match="expects q of length"):
            model.forward_dynamics(column, u)
        with pytest.raises(mb.ModelError, match="expects q of length"):
            model.mass_matrix(column)
        with pytest.raises(mb.ModelError):
            model.effort_array(column, u, ud)


def test_closed_loops_are_not_merged():
    assert loop_robot().compile()._merged_frames == 0


def test_the_frozen_calls_refuse_what_the_checked_route_converts_or_rejects():
    model = robot(loads=True).compile()
    q, u, ud = (np.round(x * 64) / 64 for x in state(model))   # exact in float32 too
    ref = (model.forward_dynamics(q, u), model.effort_array(q, u, ud), model.mass_matrix(q))
    close(model.forward_dynamics(q, u, method="jourdain"), ref[0], 1e-9)
    assert {"auto", "jourdain", "efforts", "mass matrix"} <= set(model._fast_calls)
    read_only = q.copy()
    read_only.flags.writeable = False
    strided = np.repeat(q, 2)[::2]
    for qq in (list(q), q.astype(np.float32), read_only, strided):
        close(model.forward_dynamics(qq, list(u)), ref[0])
        close(model.forward_dynamics(qq, u, method="jourdain"), ref[0], 1e-9)
        close(model.effort_array(qq, u, list(ud)), ref[1])
        close(model.mass_matrix(qq), ref[2])
    with pytest.raises(mb.ModelError, match="expects q of length"):
        model.forward_dynamics(q[:-1], u)
    with pytest.raises(mb.ModelError, match="expects q of length"):
        model.forward_dynamics(q, u[:-1], method="jourdain")
    with pytest.raises(mb.ModelError, match="u_dot needs"):
        model.effort_array(q, u, ud[:-1])
    with pytest.raises(mb.ModelError, match="expects q of length"):
        model.mass_matrix(np.append(q, 0.0))
    bad = q.copy()
    bad[0] = np.nan
    with pytest.raises(mb.NonFiniteError):
        model.forward_dynamics(bad, u)
    with pytest.raises(mb.NonFiniteError):
        model.forward_dynamics(bad, u, method="jourdain")
    with pytest.raises(mb.NonFiniteError):
        model.effort_array(bad, u, ud)
