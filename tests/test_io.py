"""Model files: loading, cases, overrides, errors, results export (mbdyn.io)."""
import json
import math
import os
import pathlib
import warnings

import numpy as np
import pytest
import sympy

import mbdyn as mb
from mbdyn.io import ModelFileError, load_model, summary, write_results
from mbdyn.io import results as results_module
from mbdyn.io.schema import parse_set_value, split_path

HERE = pathlib.Path(__file__).resolve().parent
ROOT = HERE.parent
MODELS = ROOT / "models"
MALFORMED = sorted((HERE / "malformed").glob("*.toml"))
pytestmark = pytest.mark.filterwarnings("ignore:.*triangle inequality")


def write(tmp_path, text, name="m.toml"):
    p = tmp_path / name
    p.write_text(text)
    return p


PENDULUM = """
[model]
name = "pendulum"
gravity = [0, 0, "-g"]

[parameters]
g = 9.81
m = 2.0
l = 0.5
k = "2*m"

[[bodies]]
name = "bob"
mass = "m"
com = [0, 0, "-l"]

[[joints]]
name = "theta"
kind = "revolute"
child = "bob"
axis = "x"
position = [0, 0, "l/2"]

[initial]
theta = "pi/6"

[initial_speeds]
theta = 0.25

[simulation]
t_end = 0.5
"""


# ----------------------------------------------------------------------------- loading
def test_contract_load_model_scene(tmp_path):
    scene = mb.load_model(write(tmp_path, PENDULUM))
    assert isinstance(scene, mb.Scene)
    assert scene.model.coordinates == ("theta",)
    assert scene.model.speeds == ("theta_dot",)
    np.testing.assert_allclose(scene.q0, [math.pi / 6])
    np.testing.assert_allclose(scene.u0, [0.25])
    assert scene.parameters == {"g": 9.81, "m": 2.0, "l": 0.5, "k": 4.0}
    assert scene.case is None
    res = scene.simulate()
    assert res.t[-1] == pytest.approx(0.5)
    assert res.stats["integrator"] == "DOP853"
    res2 = scene.simulate(t_end=0.1, integrator="rk4", dt=0.01)
    assert res2.t[-1] == pytest.approx(0.1) and res2.stats["integrator"] == "rk4"


def test_parameters_reach_the_system_symbolically(tmp_path):
    """Values written with parameters are sympy expressions of the parameter symbols in
    the System (for the symbolic layer); plain numbers stay numbers."""
    scene = load_model(write(tmp_path, PENDULUM))
    system = scene.system
    assert system.parameters == {"g": 9.81, "m": 2.0, "l": 0.5, "k": 4.0}
    m, l, g = system.symbols("m l g")
    body = system.bodies["bob"]
    assert body.mass == 2.0 and body.symbolic["mass"] == m
    assert sympy.simplify(body.symbolic["com"][2] + l) == 0
    joint = system.joints["theta"]
    assert sympy.simplify(joint.symbolic["position"][2] - l / 2) == 0
    np.testing.assert_allclose(joint.position, [0, 0, 0.25])
    assert system.gravity_symbolic is not None
    assert sympy.simplify(system.gravity_symbolic[2] + g) == 0


def test_top_inertia_about_origin_is_converted_symbolically():
    scene = load_model(MODELS / "top.toml")
    body = scene.system.bodies["top"]
    m, h, A, C = scene.system.symbols("m h A C")
    I = body.symbolic["inertia"]
    assert sympy.simplify(I[0][0] - (A - m * h**2)) == 0
    assert sympy.simplify(I[2][2] - C) == 0
    p = scene.parameters
    np.testing.assert_allclose(np.diag(body.inertia),
                               [p["A"] - p["m"] * p["h"]**2] * 2 + [p["C"]], rtol=1e-12)
    assert any("triangle inequality" in w for w in scene.warnings)


def test_warnings_are_reported_once_and_kept(tmp_path):
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        scene = load_model(MODELS / "top.toml")
    tri = [w for w in caught if "triangle inequality" in str(w.message)]
    assert len(tri) == 1 and issubclass(tri[0].category, mb.ModelWarning)
    assert scene.warnings == scene.model.warnings


def test_cases_default_and_explicit():
    a = load_model(MODELS / "top.toml")
    assert a.case == "a" and a.cases == ("a", "b", "c", "d", "floor")
    assert a.parameters["Mz"] == -0.025
    b = load_model(MODELS / "top.toml", case="b")
    assert b.case == "b" and b.parameters["Mz"] == -0.001
    i = b.model.speed_index("psi_dot")
    assert b.u0[i] == pytest.approx((50 / 180) * 2 * 3 * 3.14159)
    with pytest.raises(ModelFileError, match=r"no case 'e'.*the cases are: a, b, c, d"):
        load_model(MODELS / "top.toml", case="e")


def test_case_merges_elements_by_name_and_replaces_arrays(tmp_path):
    text = PENDULUM + """
[cases.heavy.bodies.bob]
mass = 5

[cases.heavy.parameters]
l = 1.0

[cases.other]
loads = [{ name = "push", body = "bob", force = [1, 0, 0] }]
"""
    p = write(tmp_path, text)
    heavy = load_model(p, case="heavy")
    body = heavy.model.body("bob")
    assert body.mass == 5.0 and body.com[2] == -1.0
    other = load_model(p, case="other")
    assert other.model.loads == ("push",)


def test_overrides_by_path_index_and_name(tmp_path):
    p = write(tmp_path, PENDULUM)
    s = load_model(p, overrides={"parameters.l": 1.0, "initial.theta": "pi/3",
                                 "bodies.bob.mass": 3, "joints[0].axis": "y",
                                 "simulation.t_end": "2*pi"})
    assert s.parameters["l"] == 1.0 and s.q0[0] == pytest.approx(math.pi / 3)
    assert s.model.body("bob").mass == 3.0
    np.testing.assert_allclose(s.model.joint("theta").axis, [0, 1, 0])
    assert s.settings["t_end"] == pytest.approx(2 * math.pi)
    s2 = load_model(p, overrides=["bodies.0.mass=4", "model.gravity=[0, 0, -1.62]",
                                  "simulation.integrator=rk4", "simulation.dt=1e-3"])
    assert s2.model.body("bob").mass == 4.0
    np.testing.assert_allclose(s2.model.gravity, [0, 0, -1.62])
    assert s2.settings["integrator"] == "rk4" and s2.settings["dt"] == 1e-3


@pytest.mark.parametrize("override, fragment", [
    ({"parameters.mm": 1}, "--set|overrides\\['parameters.mm'\\].*'mm' is not a parameter.*did you mean 'm'"),
    ({"bodies.bobb.mass": 1}, "no entry named 'bobb'; did you mean 'bob'"),
    ({"bodies[3].mass": 1}, "index 3 does not exist"),
    ({"bodies.bob.mas": 1}, "unknown key; did you mean 'mass'"),
    ({"simulation.t_end.x": 1}, "is a value, not a table"),
    ({"model": 3}, "model is a table"),
    ({"nonsense.x": 1}, "unknown section 'nonsense'"),
    ({"cases.a": 1}, "cannot override cases"),
    ({"initial.thetaa": 1}, "did you mean 'theta'"),
    ({"simulation.integrator": "rk45"}, "did you mean 'RK45'"),
    ({"simulation.method": "lagrange"}, "unknown method 'lagrange'"),
    ({"simulation.rtol": -1}, "must be > 0"),
])
def test_override_errors_name_the_override(tmp_path, override, fragment):
    with pytest.raises(ModelFileError, match=fragment) as err:
        load_model(write(tmp_path, PENDULUM), overrides=override)
    key = next(iter(override))
    assert f"overrides[{key!r}]" in str(err.value)


def test_set_value_parsing_and_paths():
    assert parse_set_value("0.3") == 0.3
    assert parse_set_value("3") == 3
    assert parse_set_value("true") is True
    assert parse_set_value("[0, 0, -1]") == [0, 0, -1]
    assert parse_set_value('"quoted"') == "quoted"
    assert parse_set_value("pi/8") == "pi/8"
    assert parse_set_value("RK45") == "RK45"
    with pytest.raises(ValueError):
        parse_set_value("  ")
    assert split_path("bodies[2].mass") == ["bodies", 2, "mass"]
    assert split_path("bodies.2.mass") == ["bodies", 2, "mass"]
    assert split_path("bodies.disk.mass") == ["bodies", "disk", "mass"]
    assert split_path("cases.45_45.initial.theta1") == ["cases", "45_45", "initial", "theta1"]
    for bad in ("", ".a", "a.", "a..b", "a[x]"):
        with pytest.raises(ValueError):
            split_path(bad)


def test_initial_speeds_by_speed_or_coordinate_name(tmp_path):
    base = PENDULUM.replace("[initial_speeds]\ntheta = 0.25", "[initial_speeds]\ntheta_dot = 0.5")
    assert load_model(write(tmp_path, base)).u0[0] == 0.5
    both = PENDULUM.replace("theta = 0.25", "theta = 0.25\ntheta_dot = 0.5")
    with pytest.raises(ModelFileError, match=r"initial_speeds.theta_dot: sets the speed "
                                             r"'theta_dot' a second time"):
        load_model(write(tmp_path, both))


def test_unnormalised_quaternion_is_normalised_with_a_warning(tmp_path):
    text = """
[[bodies]]
name = "b"
mass = 1
com = [0, 0, -1]
inertia = [0.1, 0.1, 0.1]
[[joints]]
name = "ball"
kind = "spherical"
child = "b"
[initial]
ball_qw = 1
ball_qx = 1
"""
    with pytest.warns(mb.ModelWarning, match="has length 1.41421; it is normalised"):
        s = load_model(write(tmp_path, text))
    np.testing.assert_allclose(s.q0, [2**-0.5, 2**-0.5, 0, 0])


def test_driven_coordinates_cannot_be_initialised(tmp_path):
    with pytest.raises(ModelFileError, match=r"initial.arm_turn'\]: is the coordinate of "
                                             "driven joint 'arm_turn'"):
        load_model(MODELS / "rotating_pendulum.toml", overrides={"initial.arm_turn": 1})


def test_coordinate_named_like_a_parameter_is_refused(tmp_path):
    text = PENDULUM.replace('axis = "x"', 'axis = "x"\ncoordinates = "m"')
    with pytest.raises(ModelFileError, match="joints\\[0\\].coordinates: 'm' is also a parameter"):
        load_model(write(tmp_path, text))


def test_missing_and_unreadable_files(tmp_path):
    with pytest.raises(ModelFileError, match="no such file"):
        load_model(tmp_path / "nope.toml")
    with pytest.raises(ModelFileError, match="is a directory"):
        load_model(tmp_path)
    bad = tmp_path / "latin1.toml"
    bad.write_bytes('[model]\nname = "caf\xe9"\n'.encode("latin-1"))
    with pytest.raises(ModelFileError, match="UTF-8"):
        load_model(bad)


def test_t_end_needed_only_to_run(tmp_path):
    s = load_model(write(tmp_path, PENDULUM.replace("t_end = 0.5", "")))
    with pytest.raises(ModelFileError, match="simulation.t_end: is not set"):
        s.simulate()
    assert s.simulate(t_end=0.01).t[-1] == pytest.approx(0.01)


# ----------------------------------------------------------------------------- malformed
def test_there_are_at_least_twenty_malformed_files():
    assert len(MALFORMED) >= 20


@pytest.mark.parametrize("path", MALFORMED, ids=[p.stem for p in MALFORMED])
def test_malformed_files_are_refused_naming_the_key(path):
    expect = path.read_text().splitlines()[0]
    assert expect.startswith("# expect: ")
    key = expect[len("# expect: "):].strip()
    with pytest.raises(ModelFileError) as err:
        load_model(path)
    msg = str(err.value)
    assert msg.startswith(f"{path}: "), msg
    assert key in msg, f"{key!r} not in {msg!r}"
    assert "\n" not in msg
    assert len(msg) > len(str(path)) + len(key) + 10      # says what is wrong


# ----------------------------------------------------------------------------- events
def test_events_from_conditions(tmp_path):
    text = PENDULUM + """
[[events]]
name = "up"
condition = "theta >= pi/4"
terminal = true

[[events]]
name = "down"
condition = "theta_dot*l < -0.1"

[[events]]
name = "zero"
condition = "theta"
direction = "falling"
"""
    s = load_model(write(tmp_path, text), overrides={"initial_speeds.theta": 4.0})
    up, down, zero = s.events
    assert (up.name, up.terminal, up.direction) == ("up", True, 1)
    assert (down.terminal, down.direction) == (False, -1)
    assert zero.direction == -1
    assert up.condition(0.0, np.array([1.0]), np.array([0.0])) == pytest.approx(1 - math.pi / 4)
    assert down.condition(0.0, np.array([0.0]), np.array([2.0])) == pytest.approx(1.1)
    assert [e["direction"] for e in s.event_specs] == ["rising", "falling", "falling"]
    res = s.simulate(t_end=3.0)
    assert [name for name, _ in res.events] == ["up"]
    assert res.q[-1, 0] == pytest.approx(math.pi / 4, abs=1e-8)


def test_event_already_true_warns(tmp_path):
    text = PENDULUM + '[[events]]\nname = "x"\ncondition = "theta > 0"\n'
    with pytest.warns(mb.ModelWarning, match="already holds at the initial state"):
        load_model(write(tmp_path, text))


# ----------------------------------------------------------------------------- results
SUMMARY_KEYS = {"model": str, "case": (str, type(None)), "t_final": float, "q": dict,
                 "reactions": (dict, type(None)), "drive_efforts": (dict, type(None)),
                 "points": (dict, type(None)),
                "u": dict, "events": list, "energy": (dict, type(None)), "stats": dict,
                 "quality": dict}
STATS_KEYS = {"integrator": str, "method": str, "steps": int, "rhs_evaluations": int,
              "wall_time_s": float}


def check_summary(d):
    assert set(d) == set(SUMMARY_KEYS)
    for k, typ in SUMMARY_KEYS.items():
        assert isinstance(d[k], typ), k
    assert set(d["stats"]) == set(STATS_KEYS)
    for k, typ in STATS_KEYS.items():
        assert isinstance(d["stats"][k], typ), k
    for e in d["events"]:
        assert set(e) == {"name", "t"} and isinstance(e["name"], str) and isinstance(e["t"], float)
    if d["energy"] is not None:
        assert set(d["energy"]) == {"initial", "final"}
    assert all(isinstance(v, float) for v in list(d["q"].values()) + list(d["u"].values()))


def test_summary_schema(tmp_path):
    s = load_model(MODELS / "bead_on_rod.toml")
    res = s.simulate()
    d = summary(s, res)
    check_summary(d)
    json.dumps(d)
    assert d["case"] is None and d["events"][0]["name"] == "end_of_rod"
    assert d["energy"]["final"] > d["energy"]["initial"]      # the drive does work
    assert list(d["q"]) == ["x"] and list(d["u"]) == ["x_dot"]


def test_write_results_files(tmp_path):
    s = load_model(MODELS / "bead_on_rod.toml")
    res = s.simulate()
    csv_path, json_path = write_results(tmp_path / "out", s, res)
    assert os.path.basename(csv_path) == "bead_on_rod.csv"
    lines = pathlib.Path(csv_path).read_text().splitlines()
    header = lines[0].split(",")
    assert header[:3] == ["t", "x", "x_dot"]
    assert "reaction_x_Fy" in header and "effort_turn" in header and "energy_total" in header
    data = np.loadtxt(csv_path, delimiter=",", skiprows=1)
    assert data.shape == (len(res.t), len(header))
    np.testing.assert_allclose(data[:, 1], res["x"], rtol=1e-14)
    meta = json.loads(pathlib.Path(json_path).read_text())
    check_summary({k: meta[k] for k in SUMMARY_KEYS})
    assert meta["columns"] == header and meta["csv"] == "bead_on_rod.csv"
    assert meta["status"] == "ok" and meta["parameters"]["Omega"] == 2.0
    assert sorted(os.listdir(tmp_path / "out")) == ["bead_on_rod.csv", "bead_on_rod.json"]


def test_interrupted_write_leaves_no_partial_file(tmp_path, monkeypatch):
    target = tmp_path / "r.csv"
    results_module.atomic_write(target, "old complete content\n")

    def boom(src, dst):
        raise KeyboardInterrupt
    monkeypatch.setattr(results_module.os, "replace", boom)
    with pytest.raises(KeyboardInterrupt):
        results_module.atomic_write(target, "new content that never lands\n")
    assert target.read_text() == "old complete content\n"
    assert os.listdir(tmp_path) == ["r.csv"]          # the temporary file is gone


def test_output_dt_thins_fixed_step_results_without_interpolation():
    s = load_model(MODELS / "top.toml", overrides={"simulation.t_end": 0.1})
    res = s.simulate()
    full = s.simulate(output_dt=s.settings["dt"])
    assert len(res.t) == 11 and res.t[-1] == pytest.approx(0.1)
    idx = [int(round(t / s.settings["dt"])) for t in res.t]
    np.testing.assert_array_equal(res.q, full.q[idx])


def test_progress_shows_after_the_delay_on_a_terminal():
    from mbdyn.cli.common import Progress

    class Stream:
        def __init__(self):
            self.text = ""

        def isatty(self):
            return True

        def write(self, s):
            self.text += s

        def flush(self):
            pass
    now = [0.0]
    st = Stream()
    p = Progress(10.0, stream=st, clock=lambda: now[0])
    p(1.0)
    assert st.text == ""                    # not before two seconds
    now[0] = 2.5
    p(5.0)
    assert "t = 5 of 10 s ( 50.0%)" in st.text
    now[0] = 2.6
    p(6.0)
    assert "t = 6" not in st.text           # throttled
    p.close()
    assert st.text.endswith("\n")
    quiet = Stream()
    quiet.isatty = lambda: False
    q = Progress(10.0, stream=quiet, clock=lambda: now[0] + 100)
    q(5.0)
    q.close()
    assert quiet.text == ""
