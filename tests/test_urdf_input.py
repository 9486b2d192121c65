"""Bad and hostile URDF input: malformed XML, entity bombs and external entities refused
unexpanded in bounded time, impossible inertias refused naming the link (unless
accepted), broken trees and unknown kinds as named errors, unused tags as warnings."""
import os
import pathlib
import time
import tracemalloc
import warnings

import pytest

import mbdyn as mb
from mbdyn.cli import main
from mbdyn.io import ModelFileError
from test_urdf import joint, link, urdf

DATA = pathlib.Path(__file__).resolve().parent / "data"
pytestmark = pytest.mark.filterwarnings("ignore:.*triangle inequality")
ARM = link("base") + link("arm") + joint("q", "continuous", "base", "arm", axis="0 0 1")


def refused(path, match, **kw):
    with pytest.raises(ModelFileError, match=match) as info:
        mb.load_model(path, **kw)
    return str(info.value)


# ------------------------------------------------------------ hostile XML
def test_malformed_xml_names_the_line(tmp_path):
    p = tmp_path / "bad.urdf"
    p.write_text('<robot name="r">\n<link name="a">\n</robot>\n')
    refused(p, r"bad.urdf: line 3: malformed XML: mismatched tag")


def test_billion_laughs_is_refused_unexpanded(tmp_path):
    lols = "".join(f'<!ENTITY lol{i} "{("&lol" + str(i - 1) + ";") * 10}">'
                   for i in range(1, 10))
    p = tmp_path / "bomb.urdf"
    p.write_text(f'<?xml version="1.0"?><!DOCTYPE robot [<!ENTITY lol0 "lol">{lols}]>'
                 '<robot name="r"><link name="&lol9;"/></robot>')
    tracemalloc.start()
    start = time.perf_counter()
    message = refused(p, "declares the XML entity 'lol0'.*entity bomb")
    elapsed = time.perf_counter() - start
    peak = tracemalloc.get_traced_memory()[1]
    tracemalloc.stop()
    assert elapsed < 2.0 and peak < 20e6          # 10^9 "lol"s would be 3 GB
    assert "lollol" not in message


def test_external_entity_is_refused_unread(tmp_path):
    secret = tmp_path / "secret.txt"
    secret.write_text("TOP-SECRET")
    p = tmp_path / "xxe.urdf"
    p.write_text(f'<?xml version="1.0"?><!DOCTYPE robot [<!ENTITY x SYSTEM '
                 f'"file://{secret}">]><robot name="&x;"><link name="a"/></robot>')
    message = refused(p, "declares the XML entity 'x'")
    assert "TOP-SECRET" not in message


def test_external_dtd_is_not_fetched(tmp_path):
    p = tmp_path / "dtd.urdf"
    p.write_text('<?xml version="1.0"?><!DOCTYPE robot SYSTEM "http://127.0.0.1:9/x.dtd">'
                 + f'<robot name="r">{ARM}</robot>')
    start = time.perf_counter()
    scene = mb.load_model(p)              # never fetched (port 9 would not answer)
    assert scene.model.coordinates == ("q",)
    assert time.perf_counter() - start < 5


def test_large_file_is_refused_by_its_size(tmp_path, monkeypatch):
    p = urdf(tmp_path, ARM + "<!--" + "x" * 5000 + "-->")
    monkeypatch.setenv("MBDYN_MAX_FILE_BYTES", "4000")
    refused(p, "more than a model file may be")


def test_deep_nesting_in_bounded_time(tmp_path):
    depth = 100_000
    p = urdf(tmp_path, ARM.replace('<link name="arm">', '<link name="arm">'
                                   + "<x>" * depth + "</x>" * depth))
    start = time.perf_counter()
    with pytest.warns(mb.ModelWarning, match="<link/x>"):
        mb.load_model(p)
    assert time.perf_counter() - start < 10


def test_not_a_robot(tmp_path):
    p = tmp_path / "x.urdf"
    p.write_text("<sdf><model/></sdf>")
    refused(p, "the top element is <sdf>, not <robot>")


def test_xacro_is_named(tmp_path):
    p = tmp_path / "x.urdf"
    p.write_text('<robot name="r" xmlns:xacro="http://www.ros.org/wiki/xacro">'
                 '<xacro:macro name="m"/><link name="a"/></robot>')
    refused(p, "xacro macro: expand the file first")


# ------------------------------------------------------------ values
@pytest.mark.parametrize("value", ["abc", "nan", "inf", "1_0", "0x10", ""])
def test_numbers_are_checked(tmp_path, value):
    p = urdf(tmp_path, link("base", mass=value) + link("arm")
             + joint("q", "continuous", "base", "arm", axis="0 0 1"))
    refused(p, r"link 'base': <mass> value (must be a number|is not a finite)")


def test_origin_needs_three_numbers(tmp_path):
    p = urdf(tmp_path, link("base") + link("arm")
             + joint("q", "continuous", "base", "arm", xyz="1 2", axis="0 0 1"))
    refused(p, "joint 'q': origin xyz must be 3 numbers")


def test_zero_axis(tmp_path):
    p = urdf(tmp_path, link("base") + link("arm")
             + joint("q", "continuous", "base", "arm", axis="0 0 0"))
    refused(p, "joint 'q': its <axis xyz> is zero")


def test_negative_mass(tmp_path):
    p = urdf(tmp_path, link("base") + link("arm", mass=-1)
             + joint("q", "continuous", "base", "arm", axis="0 0 1"))
    refused(p, "link 'arm': <mass> value -1 is negative")


def test_inertial_without_mass(tmp_path):
    p = urdf(tmp_path, link("base") + '<link name="arm"><inertial/></link>'
             + joint("q", "continuous", "base", "arm", axis="0 0 1"))
    refused(p, "link 'arm': <inertial> has no <mass")


def test_negative_principal_moment_refused_unless_accepted(tmp_path):
    p = urdf(tmp_path, link("base") + link("arm", inertia="0.01 0.02 0 0.01 0 0.01")
             + joint("q", "continuous", "base", "arm", axis="0 0 1"))
    refused(p, "link 'arm': its inertia has a negative principal moment")
    with pytest.warns(mb.ModelWarning, match="link 'arm'.*set to 0"):
        scene = mb.load_model(p, accept_inertia=True)
    assert scene.urdf["accepted_inertia"] == ["arm"]
    assert min(__import__("numpy").linalg.eigvalsh(scene.model.body("arm").inertia)) >= 0


def test_triangle_inequality_refused_unless_accepted(tmp_path):
    p = urdf(tmp_path, link("base") + link("arm", inertia="0.01 0 0 0.01 0 0.05")
             + joint("q", "continuous", "base", "arm", axis="0 0 1"))
    refused(p, "link 'arm': its principal moments .* break the triangle inequality")
    with pytest.warns(mb.ModelWarning, match="link 'arm'.*accepted"):
        mb.load_model(p, accept_inertia=True)
    wrapper = tmp_path / "w.toml"
    wrapper.write_text('[model]\nurdf = "robot.urdf"\naccept_inertia = true\n')
    with pytest.warns(mb.ModelWarning, match="accepted"):
        mb.load_model(wrapper)
    assert main(["info", str(p)]) == 1
    assert main(["info", str(p), "--accept-inertia"]) == 0


def test_thin_rod_at_the_triangle_equality_passes(tmp_path):
    p = urdf(tmp_path, link("base") + link("rod", inertia="0.02 0 0 0.02 0 0")
             + joint("q", "revolute", "base", "rod", axis="1 0 0",
                     extra='<limit lower="-1" upper="1" effort="1" velocity="1"/>'))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        mb.load_model(p)


def test_missing_inertial_is_a_massless_link(tmp_path, capsys):
    p = urdf(tmp_path, link("base") + link("arm") + '<link name="tip"/>'
             + joint("q", "continuous", "base", "arm", axis="0 0 1")
             + joint("fix", "fixed", "arm", "tip", xyz="1 0 0"))
    scene = mb.load_model(p)
    assert scene.urdf["massless"] == ["tip"]
    assert main(["info", str(p)]) == 0
    out = capsys.readouterr().out
    assert "massless links (no <inertial>): tip" in out
    assert "tip            massless frame" in out


def test_massless_moving_link_is_named(tmp_path):
    p = urdf(tmp_path, link("base") + '<link name="ghost"/>'
             + joint("q", "continuous", "base", "ghost", axis="0 0 1"))
    refused(p, "carry no inertia")


# ------------------------------------------------------------ the tree
def test_unknown_joint_type_suggests(tmp_path):
    p = urdf(tmp_path, link("base") + link("arm")
             + joint("q", "revolut", "base", "arm", axis="0 0 1"))
    refused(p, "joint 'q': unknown joint type 'revolut'; did you mean 'revolute'")


def test_two_parents(tmp_path):
    p = urdf(tmp_path, link("a") + link("b") + link("c")
             + joint("ab", "fixed", "a", "c") + joint("bc", "fixed", "b", "c"))
    refused(p, "link 'c': has two parents: joints 'ab' and 'bc'")


def test_cycle(tmp_path):
    p = urdf(tmp_path, link("root") + link("a") + link("b")
             + joint("ab", "fixed", "a", "b") + joint("ba", "fixed", "b", "a"))
    refused(p, r"link 'a': the joints form a cycle \(a -> b -> a\)")


def test_two_roots(tmp_path):
    p = urdf(tmp_path, link("a") + link("b") + link("c") + joint("ab", "fixed", "a", "b"))
    refused(p, r"has 2 root links \(a, c\)")


def test_unknown_link(tmp_path):
    p = urdf(tmp_path, link("base") + link("arm")
             + joint("q", "continuous", "base", "armm", axis="0 0 1"))
    refused(p, "joint 'q': its child link 'armm' is not defined; did you mean 'arm'")


@pytest.mark.parametrize("what", ["link", "joint"])
def test_duplicate_names(tmp_path, what):
    body = ARM + (link("arm") if what == "link" else
                  link("x") + joint("q", "fixed", "arm", "x"))
    refused(urdf(tmp_path, body), f"{what} '(arm|q)': is defined twice")


def test_link_named_ground(tmp_path):
    p = urdf(tmp_path, link("ground") + link("arm")
             + joint("q", "continuous", "ground", "arm", axis="0 0 1"))
    refused(p, "link 'ground': mbdyn names its fixed frame 'ground'")


def test_mimic_of_an_unknown_joint(tmp_path):
    p = urdf(tmp_path, ARM.replace('<axis xyz="0 0 1"/>',
                                   '<axis xyz="0 0 1"/><mimic joint="nope"/>'))
    refused(p, "joint 'q': <mimic joint='nope'>: no such joint")


def test_limits_upside_down(tmp_path):
    p = urdf(tmp_path, link("base") + link("arm")
             + joint("q", "revolute", "base", "arm", axis="0 0 1",
                     extra='<limit lower="1" upper="-1" effort="1" velocity="1"/>'))
    refused(p, "joint 'q': <limit> lower 1 is above upper -1")


# ------------------------------------------------------------ tags not used
def test_unused_tags_are_a_warning_naming_them(tmp_path, capsys):
    p = urdf(tmp_path, ARM.replace('<link name="arm">', '<link name="arm"><visual><geometry>'
                                   '<mesh filename="package://r/arm.stl"/></geometry>'
                                   '</visual><collision/>')
             + '<gazebo reference="arm"/><transmission name="t1">'
               '<type>transmission_interface/SimpleTransmission</type>'
               '<joint name="q"><hardwareInterface>EffortJointInterface</hardwareInterface>'
               '</joint><actuator name="motor"><mechanicalReduction>50</mechanicalReduction>'
               '</actuator></transmission>')
    with pytest.warns(mb.ModelWarning) as caught:
        scene = mb.load_model(p)
    text = " ".join(str(w.message) for w in caught)
    for tag in ("<link/collision>", "<gazebo>", "<transmission>"):
        assert tag in text
    # a <visual> is used now (docs/urdf.md, "Meshes"): its mesh, not found, is named
    assert "<link/visual>" not in text and "'package://r/arm.stl' not found" in text
    t = scene.urdf["transmissions"][0]
    assert (t["name"], t["type"]) == ("t1", "transmission_interface/SimpleTransmission")
    assert t["joints"][0]["name"] == "q" and t["actuators"][0]["reduction"] == "50"
    assert main(["info", str(p)]) == 0
    out = capsys.readouterr().out
    assert "transmission t1 (transmission_interface/SimpleTransmission): joints q; " \
           "actuators motor (reduction 50)" in out


def test_dynamics_of_a_fixed_joint_is_a_warning(tmp_path):
    p = urdf(tmp_path, ARM + link("x") + joint("f", "fixed", "arm", "x",
                                                extra='<dynamics damping="1"/>'))
    with pytest.warns(mb.ModelWarning, match="joint 'f': <dynamics> of a fixed joint"):
        mb.load_model(p)


def test_revolute_without_limit_is_a_warning(tmp_path):
    p = urdf(tmp_path, link("base") + link("arm")
             + joint("q", "revolute", "base", "arm", axis="0 0 1"))
    with pytest.warns(mb.ModelWarning, match="without <limit>"):
        mb.load_model(p)


def test_errors_on_the_command_line_are_one_line(tmp_path, capsys):
    p = urdf(tmp_path, link("a") + link("b") + link("c") + joint("ab", "fixed", "a", "b"))
    assert main(["info", str(p)]) == 1
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "root links" in err and os.path.basename(str(p)) in err
