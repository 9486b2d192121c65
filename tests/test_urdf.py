"""URDF robots (mbdyn.io.urdf, docs/urdf.md): the specification's conventions against
transforms computed by hand, the joint kinds, the base, the effects a URDF carries, the
TOML wrapper, and forward dynamics against a System built by hand with the same numbers.
"""
import math
import pathlib
import warnings
import xml.etree.ElementTree as ET

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

import mbdyn as mb
from mbdyn.io import ModelFileError
from mbdyn.io.urdf import add_urdf, rpy_matrix

DATA = pathlib.Path(__file__).resolve().parent / "data"


def urdf(tmp_path, body, name="robot"):
    """A URDF file ``robot.urdf`` holding ``body`` inside ``<robot>``."""
    p = tmp_path / f"{name}.urdf"
    p.write_text(f'<?xml version="1.0"?>\n<robot name="{name}">\n{body}\n</robot>\n')
    return p


def link(name, mass=1.0, xyz="0 0 0", rpy="0 0 0", inertia="0.01 0 0 0.01 0 0.01"):
    ixx, ixy, ixz, iyy, iyz, izz = inertia.split()
    return (f'<link name="{name}"><inertial><origin xyz="{xyz}" rpy="{rpy}"/>'
            f'<mass value="{mass}"/><inertia ixx="{ixx}" ixy="{ixy}" ixz="{ixz}" '
            f'iyy="{iyy}" iyz="{iyz}" izz="{izz}"/></inertial></link>')


def joint(name, kind, parent, child, xyz="0 0 0", rpy="0 0 0", axis=None, extra=""):
    ax = f'<axis xyz="{axis}"/>' if axis else ""
    return (f'<joint name="{name}" type="{kind}"><parent link="{parent}"/>'
            f'<child link="{child}"/><origin xyz="{xyz}" rpy="{rpy}"/>{ax}{extra}</joint>')


# ------------------------------------------------------------ conventions, by hand
def test_rpy_is_fixed_axis_roll_pitch_yaw():
    """URDF: roll about x, then pitch about y, then yaw about z, all about the fixed axes:
    R = Rz(yaw) Ry(pitch) Rx(roll).  Each matrix here is written out by hand."""
    h = math.pi / 2
    assert np.allclose(rpy_matrix((h, 0, 0)), [[1, 0, 0], [0, 0, -1], [0, 1, 0]])
    assert np.allclose(rpy_matrix((0, h, 0)), [[0, 0, 1], [0, 1, 0], [-1, 0, 0]])
    assert np.allclose(rpy_matrix((0, 0, h)), [[0, -1, 0], [1, 0, 0], [0, 0, 1]])
    # roll 90 then pitch 90 (fixed axes): x stays x, then goes to -z; y goes to z, then x
    assert np.allclose(rpy_matrix((h, h, 0)), [[0, 1, 0], [0, 0, -1], [-1, 0, 0]])
    # roll 90, pitch 90, yaw 90: -z stays -z, so x -> -z; y -> z -> x -> y
    assert np.allclose(rpy_matrix((h, h, h)) @ [1, 0, 0], [0, 0, -1])
    assert np.allclose(rpy_matrix((h, h, h)) @ [0, 1, 0], [0, 1, 0])
    rpy = (0.3, -0.7, 1.9)                 # scipy's extrinsic "xyz" is the same convention
    assert np.allclose(rpy_matrix(rpy), Rotation.from_euler("xyz", rpy).as_matrix(),
                       atol=1e-15)


def test_joint_origin_places_the_child_link_frame(tmp_path):
    """The joint frame is the child link's frame, at <origin xyz> in the parent's frame,
    turned by rpy; a revolute turns it about <axis> given in that frame."""
    h = math.pi / 2
    p = urdf(tmp_path, link("base") + link("a") + link("b")
             + joint("fix", "fixed", "base", "a", xyz="1 2 3", rpy=f"{h} {h} 0")
             + joint("turn", "revolute", "a", "b", xyz="0.5 0 0", axis="0 0 1",
                     extra='<limit lower="-3" upper="3" effort="1" velocity="1"/>'))
    scene = mb.load_model(p)
    model = scene.model
    k = model.kinematics(model.q_vector({"turn": 0.3}))
    Ra = np.array([[0, 1, 0], [0, 0, -1], [-1, 0, 0]])      # by hand, above
    assert np.allclose(k.R[model.frame_index("a")], Ra, atol=1e-15)
    assert np.allclose(k.r[model.frame_index("a")], [1, 2, 3])
    c, s = math.cos(0.3), math.sin(0.3)
    Rz = np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]])
    assert np.allclose(k.R[model.frame_index("b")], Ra @ Rz, atol=1e-15)
    assert np.allclose(k.r[model.frame_index("b")], [1, 2, 3] + Ra @ [0.5, 0, 0])
    assert np.allclose(Ra @ [0.5, 0, 0], [0, 0, -0.5])


def test_prismatic_axis_in_the_joint_frame(tmp_path):
    p = urdf(tmp_path, link("base") + link("slider")
             + joint("s", "prismatic", "base", "slider", xyz="0 0 1", rpy="0 0 1.5707963267948966",
                     axis="1 0 0", extra='<limit lower="-1" upper="1" effort="1" velocity="1"/>'))
    model = mb.load_model(p).model
    k = model.kinematics(model.q_vector({"s": 0.25}))
    # yaw 90: the joint frame's x is the world's y
    assert np.allclose(k.r[model.frame_index("slider")], [0, 0.25, 1])


def test_inertial_frame_offset_and_turned(tmp_path):
    """<inertial><origin> is the centre of mass; the tensor is in the inertial frame and
    is turned into the link frame: with yaw 90 the inertial x is the link's y, so
    diag(1, 2, 3) becomes diag(2, 1, 3)."""
    p = urdf(tmp_path, link("base")
             + link("arm", mass=2.0, xyz="0.1 0 0.2", rpy="0 0 1.5707963267948966",
                    inertia="1 0 0 2 0 3")
             + joint("q", "continuous", "base", "arm", axis="0 0 1"))
    body = mb.load_model(p).model.body("arm")
    assert body.mass == 2.0
    assert np.allclose(body.com, [0.1, 0, 0.2])
    assert np.allclose(body.inertia, np.diag([2.0, 1.0, 3.0]), atol=1e-15)


def test_inertia_products_are_tensor_entries(tmp_path):
    """ixy, ixz, iyz are the tensor's off-diagonal entries as written (not negated)."""
    p = urdf(tmp_path, link("base") + link("b", inertia="2 0.1 -0.2 3 0.3 4")
             + joint("q", "continuous", "base", "b", axis="0 0 1"))
    body = mb.load_model(p).model.body("b")
    assert np.allclose(body.inertia, [[2, 0.1, -0.2], [0.1, 3, 0.3], [-0.2, 0.3, 4]])


def test_axis_is_normalised(tmp_path):
    p = urdf(tmp_path, link("base") + link("b")
             + joint("q", "continuous", "base", "b", axis="0 3 4"))
    assert np.allclose(mb.load_model(p).model.joint("q").axis, [0, 0.6, 0.8])


# ------------------------------------------------------------ names and kinds
def test_names_and_kinds_of_the_mixed_robot():
    scene = mb.load_model(DATA / "mixed.urdf")
    model = scene.model
    assert scene.name == "mixed"
    assert model.coordinates == ("spin", "slide", "wrist", "wheel_joint")
    assert model.speeds == ("spin_dot", "slide_dot", "wrist_dot", "wheel_joint_dot")
    kinds = {j: model.joint(j).kind for j in ("root", "spin", "slide", "bracket_joint",
                                               "wrist", "wheel_joint")}
    assert kinds == {"root": "fixed", "spin": "revolute", "slide": "prismatic",
                     "bracket_joint": "fixed", "wrist": "revolute",
                     "wheel_joint": "revolute"}
    assert set(model.frames) == {"base", "table", "carriage", "bracket", "hand", "wheel"}
    assert scene.urdf["massless"] == ["bracket"]
    assert not model.body("bracket").has_inertia


def test_floating_base_adds_a_free_root_joint():
    fixed = mb.load_model(DATA / "planar_arm.urdf")
    assert fixed.model.joint("root").kind == "fixed"
    assert fixed.urdf["base"] == "fixed"
    free = mb.load_model(DATA / "planar_arm.urdf", floating=True)
    assert free.model.joint("root").kind == "free"
    assert free.model.coordinates[:7] == ("root_x", "root_y", "root_z", "root_qw",
                                          "root_qx", "root_qy", "root_qz")
    assert free.urdf["base"] == "floating"
    # in free fall the base falls with g; the arm, at rest relative to it, stays at rest
    ud = free.model.forward_dynamics(free.q0, free.u0)
    assert np.allclose(ud[free.model.speeds.index("root_vz")], -9.81)
    assert np.allclose(np.delete(ud, free.model.speeds.index("root_vz")), 0, atol=1e-12)
    assert mb.load_model(DATA / "planar_arm.urdf", overrides={"model.floating": True}
                         ).model.nu == 8


def test_world_root_is_the_ground(tmp_path):
    p = urdf(tmp_path, '<link name="world"/>' + link("base") + link("arm")
             + joint("weld", "fixed", "world", "base", xyz="0 0 1")
             + joint("q", "continuous", "base", "arm", axis="0 1 0"))
    scene = mb.load_model(p)
    model = scene.model
    assert "world" not in model.frames and "root" not in [j for j in model.frames]
    assert model.joint("weld").parent == "ground"
    assert scene.urdf["base"] == "world"
    with pytest.raises(ModelFileError, match="'world', the ground"):
        mb.load_model(p, floating=True)


def test_floating_joint_inside_the_urdf(tmp_path):
    p = urdf(tmp_path, '<link name="world"/>' + link("ball")
             + joint("fly", "floating", "world", "ball", xyz="0 0 2"))
    model = mb.load_model(p).model
    assert model.joint("fly").kind == "free"
    assert model.coordinates == ("fly_x", "fly_y", "fly_z", "fly_qw", "fly_qx", "fly_qy",
                                 "fly_qz")
    q = model.default_coordinates()
    assert np.allclose(model.kinematics(q).r[model.frame_index("ball")], [0, 0, 2])
    assert np.allclose(model.forward_dynamics(q, np.zeros(6))[:3], [0, 0, -9.81])


@pytest.mark.parametrize("axis, e1, e2", [("0 0 1", [1, 0, 0], [0, 1, 0]),
                                          ("1 0 0", [0, 1, 0], [0, 0, 1])])
def test_planar_joint_is_two_slides_and_a_turn(tmp_path, axis, e1, e2):
    p = urdf(tmp_path, link("base") + link("puck")
             + joint("plane", "planar", "base", "puck", xyz="0 0 0.5", axis=axis))
    model = mb.load_model(p).model
    assert model.coordinates == ("plane_slide1", "plane_slide2", "plane_turn")
    assert {"plane.slide1", "plane.slide2"} <= set(model.frames)
    assert not model.body("plane.slide1").has_inertia
    q = model.q_vector({"plane_slide1": 0.2, "plane_slide2": -0.3, "plane_turn": 0.4})
    k = model.kinematics(q)
    assert np.allclose(k.r[model.frame_index("puck")],
                       np.array([0, 0, 0.5]) + 0.2 * np.array(e1) - 0.3 * np.array(e2))
    n = np.cross(e1, e2)
    assert np.allclose(k.R[model.frame_index("puck")],
                       Rotation.from_rotvec(0.4 * n).as_matrix())


def test_joint_names_that_are_not_identifiers_are_renamed(tmp_path):
    p = urdf(tmp_path, link("base") + link("a") + link("b") + link("c")
             + joint("base-joint", "continuous", "base", "a", axis="0 0 1")
             + joint("2nd", "continuous", "a", "b", axis="0 0 1")
             + joint("sin", "continuous", "b", "c", axis="0 0 1"))
    with pytest.warns(mb.ModelWarning) as caught:
        scene = mb.load_model(p)
    assert any("'base-joint': its coordinate is named 'base_joint'" in str(w.message)
               for w in caught)
    assert scene.model.coordinates == ("base_joint", "j_2nd", "sin_joint")
    assert scene.model.joint("base-joint").coordinates == ("base_joint",)
    assert scene.urdf["renamed"] == {"base-joint": "base_joint", "2nd": "j_2nd",
                                     "sin": "sin_joint"}


# ------------------------------------------------------------ effects
def test_damping_and_friction_are_named_effects():
    scene = mb.load_model(DATA / "mixed.urdf")
    assert scene.urdf["effects"]["damping"] == ["damping_spin"]
    assert scene.urdf["effects"]["friction"] == ["friction_spin"]
    model = scene.model
    off = scene.system.compile(effects="-damping_spin,-friction_spin")
    q = model.default_coordinates()
    i = model.speeds.index("spin_dot")
    for v in (0.003, 0.5, -2.0):
        u = np.zeros(model.nu)
        u[i] = v
        df = model.forcing(q, u) - off.forcing(q, u)
        # -(c v) - F tanh(v / v_s) on the joint, nothing else
        assert df[i] == pytest.approx(-0.1 * v - 0.2 * math.tanh(v / 0.01), rel=1e-12)
        assert np.allclose(np.delete(df, i), 0, atol=1e-12)


def test_limits_are_stops_scaled_to_the_joint():
    scene = mb.load_model(DATA / "planar_arm.urdf")
    model = scene.model
    stop = scene.urdf["stops"]["limit_elbow"]
    assert (stop["lower"], stop["upper"]) == (-2.8, 2.8)
    off = scene.system.compile(effects="-limit_elbow,-limit_shoulder")
    i = model.speeds.index("elbow_dot")
    m = off.mass_matrix(off.default_coordinates())[i, i]
    k = m * (2 * math.pi * 50) ** 2
    assert stop["stiffness"] == pytest.approx(k, rel=1e-12)
    assert stop["damping"] == pytest.approx(2 * math.sqrt(k * m), rel=1e-12)
    u = np.zeros(model.nu)
    for q_elbow, expected in ((0.0, 0.0), (2.79, 0.0), (2.9, -k * 0.1), (-3.0, k * 0.2)):
        q = model.q_vector({"elbow": q_elbow})
        df = model.forcing(q, u) - off.forcing(q, u)
        assert df[i] == pytest.approx(expected, rel=1e-9, abs=1e-9)
    q = model.q_vector({"elbow": 2.9})            # moving out of the stop: never pulls
    u[i] = -1e3
    assert (model.forcing(q, u) - off.forcing(q, u))[i] == 0.0


def test_a_stop_holds_the_joint_near_its_limit():
    scene = mb.load_model(DATA / "planar_arm.urdf", overrides={
        "initial.shoulder": 2.3, "initial_speeds.shoulder": 8.0})
    res = scene.simulate(t_end=0.5)
    free = mb.load_model(DATA / "planar_arm.urdf", overrides={
        "initial.shoulder": 2.3, "initial_speeds.shoulder": 8.0},
        effects="-limit_shoulder").simulate(t_end=0.5)
    assert free["shoulder"].max() > 2.9             # without the stop it swings past
    assert 2.5 < res["shoulder"].max() < 2.5 + 0.05
    assert res["shoulder_dot"].min() < 0             # and comes back from the stop


def test_initial_value_outside_the_limits_is_a_warning(tmp_path):
    p = urdf(tmp_path, link("base") + link("b")
             + joint("q", "revolute", "base", "b", axis="0 0 1",
                     extra='<limit lower="0.5" upper="1" effort="1" velocity="1"/>'))
    with pytest.warns(mb.ModelWarning, match="outside its limits"):
        mb.load_model(p)


def test_mimic_is_a_coupling(tmp_path):
    p = urdf(tmp_path, link("base") + link("left") + link("right")
             + joint("finger", "continuous", "base", "left", axis="0 0 1")
             + joint("twin", "continuous", "base", "right", xyz="0.1 0 0", axis="0 0 1",
                     extra='<mimic joint="finger" multiplier="-2" offset="0.1"/>'))
    scene = mb.load_model(p, overrides={"initial.finger": 0.3})
    model = scene.model
    assert "mimic_twin" in model.loop_joints
    q0 = dict(zip(model.coordinates, scene.q0))
    assert q0["twin"] == pytest.approx(-2 * 0.3 + 0.1, abs=1e-10)
    res = scene.simulate(t_end=0.2, outputs=())
    assert np.allclose(res["twin"], -2 * res["finger"] + 0.1, atol=1e-7)
    assert scene.urdf["effects"]["mimic"] == ["mimic_twin"]


def test_effects_switch_off_by_name():
    scene = mb.load_model(DATA / "planar_arm.urdf", effects="-limit_shoulder,-damping_elbow")
    assert scene.model.effects["limit_shoulder"] is False
    assert scene.model.effects["damping_elbow"] is False
    assert scene.model.effects["limit_elbow"] is True


# ------------------------------------------------------------ the TOML wrapper
def _same_model(a, b):
    assert a.coordinates == b.coordinates and a.speeds == b.speeds
    assert a.frames == b.frames
    rng = np.random.default_rng(3)
    for _ in range(3):
        q, u = rng.uniform(-1, 1, a.nq), rng.normal(size=a.nu)
        assert np.array_equal(a.mass_matrix(q), b.mass_matrix(q))
        assert np.array_equal(a.forcing(q, u), b.forcing(q, u))
        assert np.array_equal(a.forward_dynamics(q, u), b.forward_dynamics(q, u))


def test_wrapper_and_urdf_alone_give_the_same_model(tmp_path):
    """A TOML file holding only ``[model] urdf`` and the URDF alone: bit-identical."""
    (tmp_path / "robot").mkdir()
    target = tmp_path / "robot" / "arm6.urdf"
    target.write_bytes((DATA / "arm6.urdf").read_bytes())
    wrapper = tmp_path / "arm6.toml"
    wrapper.write_text('[model]\nurdf = "robot/arm6.urdf"\nfloating = true\n')
    a = mb.load_model(target, floating=True)
    b = mb.load_model(wrapper)
    assert a.name == b.name == "arm6"
    _same_model(a.model, b.model)
    ra = a.simulate(t_end=0.05, outputs=())
    rb = b.simulate(t_end=0.05, outputs=())
    assert np.array_equal(ra.t, rb.t) and np.array_equal(ra.q, rb.q)
    assert np.array_equal(ra.u, rb.u)


def test_wrapper_adds_what_urdf_cannot_say():
    scene = mb.load_model(DATA / "planar_arm.toml")
    model = scene.model
    assert "payload" in model.frames and model.joint("grip").parent == "tool"
    assert scene.initial_state["shoulder"] == pytest.approx(math.radians(30))
    assert scene.settings["t_end"] == 0.5
    assert model.effects["damping_elbow"] is False
    res = scene.simulate()
    assert [e.name for e in res.events] == ["elbow_straight"]
    light = mb.load_model(DATA / "planar_arm.toml", case="light")
    assert light.model.body("payload").mass == 0.1


def test_wrapper_options_need_a_urdf(tmp_path):
    p = tmp_path / "m.toml"
    p.write_text('[model]\nfloating = true\n[[bodies]]\nname = "b"\nmass = 1\n'
                 '[[joints]]\nname = "q"\nkind = "prismatic"\nchild = "b"\naxis = "z"\n')
    with pytest.raises(ModelFileError, match="model.floating: applies to a URDF robot"):
        mb.load_model(p)


def test_wrapper_names_a_missing_urdf(tmp_path):
    p = tmp_path / "m.toml"
    p.write_text('[model]\nurdf = "nowhere.urdf"\n')
    with pytest.raises(ModelFileError, match="model.urdf: .*nowhere.urdf: no such file"):
        mb.load_model(p)


def test_add_urdf_to_a_system_of_ones_own():
    s = mb.System("cell")
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        built = add_urdf(s, DATA / "planar_arm.urdf")
    assert built.report["robot"] == "planar_arm"
    s.add_body("box", mass=1.0, inertia=[0.1, 0.1, 0.1])
    s.add_joint("box_slide", "prismatic", "ground", "box", axis="x")
    model = s.compile()
    assert set(model.coordinates) == {"shoulder", "elbow", "box_slide"}


# ------------------------------------------------------------ against a System by hand
def _hand_built(path):
    """The robot of ``path`` built with ``mb.System`` from the URDF's numbers, read here
    with the standard library and turned with scipy (extrinsic x, y, z): independent of
    mbdyn's reader and of its rpy."""
    root = ET.parse(path).getroot()
    s = mb.System("by hand")
    children = {j.find("child").get("link") for j in root.iter("joint")}

    def floats(text, default="0 0 0"):
        return [float(v) for v in (text or default).split()]
    for ln in root.iter("link"):
        inertial = ln.find("inertial")
        if inertial is None:
            s.add_frame(ln.get("name"))
            continue
        o = inertial.find("origin")
        R = Rotation.from_euler("xyz", floats(o.get("rpy"))).as_matrix()
        i = {k: float(v) for k, v in inertial.find("inertia").attrib.items()}
        I = np.array([[i["ixx"], i["ixy"], i["ixz"]], [i["ixy"], i["iyy"], i["iyz"]],
                      [i["ixz"], i["iyz"], i["izz"]]])
        s.add_body(ln.get("name"), mass=float(inertial.find("mass").get("value")),
                   com=floats(o.get("xyz")), inertia=(R @ I @ R.T).tolist())
        if ln.get("name") not in children:
            s.add_joint("root", "fixed", "ground", ln.get("name"))
    for j in root.iter("joint"):
        o = j.find("origin")
        kind = {"continuous": "revolute"}.get(j.get("type"), j.get("type"))
        axis = floats(j.find("axis").get("xyz")) if j.find("axis") is not None else None
        s.add_joint(j.get("name"), kind, j.find("parent").get("link"),
                    j.find("child").get("link"), axis=axis if kind != "fixed" else None,
                    position=floats(o.get("xyz")),
                    orientation=Rotation.from_euler("xyz", floats(o.get("rpy"))).as_matrix())
    return s.compile()


@pytest.mark.parametrize("name", ["planar_arm", "arm6", "mixed"])
def test_forward_dynamics_against_a_system_built_by_hand(name):
    scene = mb.load_model(DATA / f"{name}.urdf")
    ours = scene.system.compile(effects=[f"-{n}" for n in scene.system.forces])
    hand = _hand_built(DATA / f"{name}.urdf")
    assert ours.coordinates == hand.coordinates
    rng = np.random.default_rng(11)
    for _ in range(4):
        q, u = rng.uniform(-2, 2, ours.nq), rng.normal(size=ours.nu)
        expected = hand.forward_dynamics(q, u)
        assert np.allclose(ours.forward_dynamics(q, u), expected, rtol=1e-12,
                           atol=1e-12 * np.abs(expected).max())
        assert np.allclose(ours.mass_matrix(q), hand.mass_matrix(q), rtol=1e-13, atol=1e-15)


def test_fixed_joints_keep_any_name_without_a_warning(tmp_path):
    p = urdf(tmp_path, link("base") + link("tip") + joint("tool-0 mount", "fixed", "base", "tip"))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        model = mb.load_model(p).model
    assert model.joint("tool-0 mount").kind == "fixed"
