"""Equilibrium, linearisation and modes of closed mechanisms, in independent coordinates
(issue 24, item 7): a four-bar on a torsional spring against its reduced 1-DoF equation
derived here by hand, the flyball governor against its closed forms
(``loop_references.governor_*``), and tree models left as they were."""
import json
import subprocess
import sys
import warnings
from pathlib import Path

import numpy as np
import pytest

import mbdyn as mb
from mbdyn.errors import ModelError

HERE = Path(__file__).resolve().parent
MODELS = HERE.parent / "models"
sys.path.insert(0, str(HERE))

from loop_mechanisms import MASSES, four_bar  # noqa: E402
from loop_references import (fourbar_accelerations, fourbar_com_motion,  # noqa: E402
                             fourbar_positions, fourbar_velocities, governor_equilibrium_speed,
                             governor_frequency)

A, B, C, D = 0.1, 0.3, 0.25, 0.3          # the four-bar of loop_mechanisms.four_bar
K_SPRING, REST, DAMPING = 5.0, 1.0, 0.02  # N m/rad, rad, N m s/rad on the crank joint
G = 9.81


def sprung_four_bar(damping=0.0):
    s = four_bar(compile_=False)
    s.add_force("spring", "joint-spring-damper", joint="th2", stiffness=K_SPRING, rest=REST,
                damping=damping)
    return s.compile()


def assembled(model, th2=1.0):
    return model.assemble(initial={"th2": th2}, guess={"th3": -0.4, "th4": 1.5})


# ----------------------------------------------------------------------------- by hand
def reduced_four_bar(th2, branch):
    """The four-bar as a 1-DoF system in the crank angle ``th2``, by hand: Freudenstein's
    positions, the velocity ratios ``w3/w2``, ``w4/w2`` and, with ``w2 = 1, al2 = 0``, the
    second derivatives of the angles along the closed path; from them each centre's
    ``dr/dth2`` and ``d2r/dth2^2`` (``fourbar_com_motion``).  Then

        m_eff = sum(m |dr_G/dth2|^2 + I_G (dth/dth2)^2),
        V     = k (th2 - rest)^2 / 2 + g sum(m y_G),
        V'    = k (th2 - rest) + g sum(m dy_G/dth2),
        V''   = k + g sum(m d2y_G/dth2^2)        (the spring plus the gravity stiffness),

    returned with the absolute angles and the ratios."""
    th3, th4 = fourbar_positions(th2, A, B, C, D, branch)
    w3, w4 = fourbar_velocities(th2, th3, th4, 1.0, A, B, C, D)
    al3, al4 = fourbar_accelerations(th2, th3, th4, 1.0, w3, w4, 0.0, A, B, C, D)
    coms = ((A / 2, 0.0), (B / 2, 0.0), (C / 2, 0.0))
    _, v, acc = fourbar_com_motion((th2, th3, th4), (1.0, w3, w4), (0.0, al3, al4), A, D,
                                   coms)
    masses = (MASSES["crank"], MASSES["coupler"], MASSES["rocker"])
    inertias = [m * L ** 2 / 12 + 1e-4 for m, L in zip(masses, (A, B, C))]
    m_eff = sum(m * (vk ** 2).sum() + inertia * w ** 2
                for m, vk, inertia, w in zip(masses, v, inertias, (1.0, w3, w4)))
    dV = K_SPRING * (th2 - REST) + G * sum(m * vk[1] for m, vk in zip(masses, v))
    ddV = K_SPRING + G * sum(m * ak[1] for m, ak in zip(masses, acc))
    return {"th3": th3, "th4": th4, "w3": w3, "w4": w4, "m_eff": m_eff, "dV": dV,
            "ddV": ddV}


def hand_equilibrium(th2, branch):
    """Newton-Raphson on ``V'(th2) = 0`` with the hand ``V''``."""
    for _ in range(50):
        r = reduced_four_bar(th2, branch)
        step = r["dV"] / r["ddV"]
        th2 -= step
        if abs(step) < 1e-15:
            break
    return th2, reduced_four_bar(th2, branch)


def branch_of(q, model):
    th2, th4 = q[model.coordinate_index("th2")], q[model.coordinate_index("th4")]
    return min(("open", "crossed"), key=lambda b: abs(np.angle(np.exp(
        1j * (fourbar_positions(th2, A, B, C, D, b)[1] - th4)))))


@pytest.fixture(scope="module")
def sprung():
    model = sprung_four_bar()
    q, u = assembled(model)
    eq = mb.equilibrium(model, q, u)
    th2, hand = hand_equilibrium(REST, branch_of(eq.q, model))
    return model, eq, th2, hand


# ----------------------------------------------------------------------------- four-bar
def test_four_bar_equilibrium_is_the_hand_one(sprung):
    model, eq, th2, hand = sprung
    idx = model.coordinate_index
    assert eq.q[idx("th2")] == pytest.approx(th2, abs=1e-9)
    assert eq.q[idx("th4")] == pytest.approx(hand["th4"], abs=1e-9)
    assert eq.q[idx("th3")] == pytest.approx(hand["th3"] - th2, abs=1e-9)
    assert abs(hand["dV"]) < 1e-12 and eq.independent and not eq.time_dependent
    assert np.abs(model.constraint_residuals(eq.q, eq.u)[0]).max() < 1e-12


def test_four_bar_has_one_natural_frequency_the_hand_one(sprung):
    """One degree of freedom, ``w^2 = V''/m_eff`` on the closed path, to 1e-6."""
    model, eq, th2, hand = sprung
    w_hand = np.sqrt(hand["ddV"] / hand["m_eff"])
    for independent in (None, "th2", "th3", "th4"):
        lin = mb.linearize(model, eq.q, eq.u, independent=independent)
        md = mb.modes(lin)
        assert lin.n == 1 and len(md) == 1, independent
        assert md[0].natural_frequency == pytest.approx(w_hand, rel=1e-6), independent
        assert md.stable and md[0].damping_ratio == pytest.approx(0.0, abs=1e-9)
    lin = mb.linearize(model, eq.q, eq.u, independent="th2")
    assert lin.names == ("th2",) and set(lin.coordinates) == {"th2", "th3", "th4"}
    assert lin.M[0, 0] == pytest.approx(hand["m_eff"], rel=1e-9)
    assert lin.K[0, 0] == pytest.approx(hand["ddV"], rel=1e-6)


def test_four_bar_mode_moves_the_dependent_coordinates_by_the_velocity_ratios(sprung):
    model, eq, th2, hand = sprung
    mode = mb.modes(mb.linearize(model, eq.q, eq.u, independent="th2"))[0]
    motion = dict(zip(mode.coordinates, mode.motion))
    assert motion["th2"] == pytest.approx(1.0)
    assert motion["th4"].real == pytest.approx(hand["w4"], rel=1e-9)
    assert motion["th3"].real == pytest.approx(hand["w3"] - 1.0, rel=1e-9)   # relative
    d = mode.to_dict()
    assert set(d["motion"]) == {"th2", "th3", "th4"} and list(d["shape"]) == ["th2"]


def test_the_constraint_forces_geometric_stiffness_is_kept(sprung):
    """The projection ``S^T (-df/dq) S`` of the tree's stiffness misses the part of the
    loop's reaction (``lambda``, which carries the links' weight here): it is far from
    the hand stiffness, which the linearisation on the constraints matches."""
    model, eq, th2, hand = sprung
    lin = mb.linearize(model, eq.q, eq.u, independent="th2")
    S = lin.basis
    h = 1e-6
    J = np.empty((model.nu, model.nu))
    for k in range(model.nu):
        e = np.zeros(model.nu)
        e[k] = h
        J[:, k] = (model.forcing(eq.q + e, eq.u) - model.forcing(eq.q - e, eq.u)) / (2 * h)
    naive = -(S.T @ J @ S)[0, 0]
    lam = model.multipliers(eq.q, eq.u)[1]
    assert np.abs(lam).max() > 1.0                    # the loop carries load
    assert abs(naive - hand["ddV"]) > 0.05 * hand["ddV"]
    assert lin.K[0, 0] == pytest.approx(hand["ddV"], rel=1e-6)


def test_four_bar_damping_in_independent_coordinates(sprung):
    """A damper on the crank joint: in the crank angle ``D = c`` and
    ``zeta = c / (2 sqrt(k_eff m_eff))``."""
    _, _, th2, hand = sprung
    model = sprung_four_bar(DAMPING)
    q, u = assembled(model, th2)
    eq = mb.equilibrium(model, q, u)
    assert eq.q[model.coordinate_index("th2")] == pytest.approx(th2, abs=1e-9)
    lin = mb.linearize(model, eq.q, eq.u, independent="th2")
    assert lin.D[0, 0] == pytest.approx(DAMPING, rel=1e-7)
    mode = mb.modes(lin)[0]
    assert mode.damping_ratio == pytest.approx(
        DAMPING / (2 * np.sqrt(hand["ddV"] * hand["m_eff"])), rel=1e-6)
    assert mode.natural_frequency == pytest.approx(np.sqrt(hand["ddV"] / hand["m_eff"]),
                                                   rel=1e-6)


def test_four_bar_equilibrium_from_afar(sprung):
    """Started half a turn of the crank away, the chart centred again after each step
    reaches the same equilibrium."""
    model, eq, th2, _ = sprung
    q, u = assembled(model, 2.3)
    far = mb.equilibrium(model, q, u)
    assert far.q == pytest.approx(eq.q, abs=1e-9)


def test_four_bar_mode_animation_stays_on_the_constraints(sprung):
    from mbdyn.viz.modeshape import mode_motion
    model, eq, _, _ = sprung
    lin = mb.linearize(model, eq.q, eq.u)
    res = mode_motion(lin, mb.modes(lin)[0], amplitude=0.2, samples=20)
    phi = [np.abs(model.constraint_residuals(q)[0]).max() for q in res.q]
    assert max(phi) < 1e-10
    th2 = res.q[:, model.coordinate_index("th2")]
    assert th2.max() - th2.min() > 0.05


def test_a_body_hung_on_a_distance_rod_in_rotation_vector_coordinates():
    """A free body (position and quaternion) held by a massless rod of length ``L`` at a
    point ``e`` above its centre: the rod's one constraint leaves five coordinates, three
    of them a rotation vector.  In each vertical plane it is a double pendulum whose first
    link is massless, by hand ``M = [[m L^2, m L e], [m L e, m e^2 + I]]``,
    ``K = diag(m g L, m g e)``; the spin about the vertical is a rigid-body mode."""
    from scipy.linalg import eigh
    L, e, m, inertia = 0.8, 0.1, 2.0, (0.01, 0.02, 0.03)
    s = mb.System("rod pendulum", gravity=(0, 0, -G))
    s.add_body("bob", mass=m, inertia=inertia)
    s.add_joint("float", "free", "ground", "bob")
    s.add_joint("rod", "distance", "ground", "bob", child_position=(0, 0, e), length=L)
    model = s.compile()
    q, u = model.assemble({"float_x": 0.3, "float_y": -0.2}, guess={"float_z": -L})
    eq = mb.equilibrium(model, q, u, fixed="float_rz")       # the spin: nothing holds it
    assert eq.q[:3] == pytest.approx([0.0, 0.0, -L - e], abs=1e-9)
    lin = mb.linearize(model, eq.q, eq.u)
    assert len(lin.names) == 5 and {"float_rx", "float_ry", "float_rz"} <= set(lin.names)
    md = mb.modes(lin)
    hand = []
    for I in inertia[:2]:
        M = np.array([[m * L * L, m * L * e], [m * L * e, m * e * e + I]])
        hand += list(np.sqrt(eigh(np.diag([m * G * L, m * G * e]), M, eigvals_only=True)))
    flexible = [mode.natural_frequency for mode in md if not mode.rigid]
    assert sorted(flexible) == pytest.approx(sorted(hand), rel=1e-6)
    assert sum(mode.rigid for mode in md) == 2          # the spin: a double zero root


# ----------------------------------------------------------------------------- governor
def governor(case=None):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", mb.ModelWarning)
        return mb.load_model(MODELS / "watt_governor.toml", case=case)


def test_governor_oscillates_about_its_steady_state_at_the_closed_form_frequency():
    """The spindle is driven at the steady speed of 30 degrees: in the spindle's frame the
    arms rest (a relative equilibrium: the drive's rotation enters the constrained
    accelerations), and their small oscillation is ``governor_frequency``."""
    sc = governor("steady")
    eq = mb.equilibrium(sc.model, sc.q0, sc.u0)
    assert not eq.time_dependent
    assert eq.q[sc.model.coordinate_index("alpha1")] == pytest.approx(np.pi / 6, abs=1e-9)
    lin = mb.linearize(sc.model, eq.q, eq.u, independent="alpha1")
    md = mb.modes(lin)
    assert len(md) == 1 and md.stable
    assert md[0].natural_frequency == pytest.approx(governor_frequency(np.pi / 6), rel=1e-6)
    motion = dict(zip(md[0].coordinates, md[0].motion.real))
    a = sc.model.parameters["a"]
    assert motion["alpha2"] == pytest.approx(1.0, rel=1e-8)
    assert motion["beta1"] == pytest.approx(-2.0, rel=1e-8)
    assert motion["zs"] == pytest.approx(2 * a * np.sin(np.pi / 6), rel=1e-8)


def test_governor_finds_its_steady_angle_at_another_speed():
    """At Omega = 10 rad/s, released at 20 degrees, the arms' steady angle is where
    ``governor_equilibrium_speed`` is 10; the frequency there is the closed form's, in
    whichever independent coordinate the pivoted QR picks."""
    sc = governor()
    eq = mb.equilibrium(sc.model, sc.q0, sc.u0)
    alpha = eq.q[sc.model.coordinate_index("alpha1")]
    assert governor_equilibrium_speed(alpha) == pytest.approx(10.0, rel=1e-9)
    assert np.degrees(alpha) == pytest.approx(32.85, abs=0.01)
    md = mb.modes(mb.linearize(sc.model, eq.q, eq.u))
    assert md[0].natural_frequency == pytest.approx(governor_frequency(alpha), rel=1e-6)


# ----------------------------------------------------------------------------- limits
def test_loop_refusals():
    model = sprung_four_bar()
    q, u = assembled(model)
    with pytest.raises(ModelError, match="numeric route"):
        mb.linearize(model, q, u, route="symbolic")
    with pytest.raises(ModelError, match="cannot all be independent"):
        mb.linearize(model, q, u, independent=["th2", "th4"])
    with pytest.raises(ModelError, match="unknown coordinate"):
        mb.linearize(model, q, u, independent="nope")
    driven = four_bar(drive=2 * mb.t)
    qd, ud = driven.assemble(guess={"th3": -0.4, "th4": 1.5})
    with pytest.raises(ModelError, match="no degrees of freedom"):
        mb.linearize(driven, qd, ud)
    with pytest.raises(ModelError, match="no degrees of freedom"):
        mb.equilibrium(driven, qd, ud)


def test_tree_models_are_linearised_as_before():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", mb.ModelWarning)
        sc = mb.load_model(MODELS / "double_pendulum.toml")
    eq = mb.equilibrium(sc.model, sc.q0)
    assert eq.independent == () and "independent" not in eq.to_dict()
    lin = mb.linearize(sc.model, eq.q)
    assert lin.basis is None and lin.coordinates == lin.names
    assert "basis" not in lin.to_dict()
    md = mb.modes(lin)
    for m in md:
        assert m.motion is m.shape and m.coordinates == m.names and "motion" not in m.to_dict()
    assert len(md.table().splitlines()) == len(md) + 2      # no lines of dependent motion
    assert [m.frequency_hz for m in md] == pytest.approx([1.348, 8.734], abs=1e-3)
    with pytest.raises(ModelError, match="no closed loops"):
        mb.linearize(sc.model, eq.q, independent="theta1")


def test_modes_command_on_a_closed_mechanism():
    out = subprocess.run([sys.executable, "-m", "mbdyn", "modes", "models/watt_governor.toml",
                          "--case", "steady", "--independent", "alpha1", "--json"],
                         capture_output=True, text=True, cwd=HERE.parent, timeout=600)
    assert out.returncode == 0, out.stderr
    d = json.loads(out.stdout)
    assert d["linearization"]["coordinates"] == ["alpha1"]
    assert set(d["linearization"]["basis"]) == {"alpha1", "alpha2", "zs", "beta1", "beta2"}
    assert d["equilibrium"]["independent"]
    mode = d["modes"][0]
    assert mode["natural_frequency"] == pytest.approx(governor_frequency(np.pi / 6), rel=1e-6)
    assert mode["motion"]["beta2"][0] == pytest.approx(-2.0, rel=1e-8)
