"""Hostile input, second round (issue 29): names that matplotlib reads as math, outputs
checked before the work, raw errors of the Python interface, contradictory effects, work
that grows without bound (sympy expansion, closed-form equations of long chains, a long
Campbell diagram).

Table-driven like ``tests/test_hostile.py``: a new case is one row.  Every test runs under
a time limit (``time_limit``, SIGALRM): a hang fails, it does not stall the suite.
"""
from __future__ import annotations

import os
import re
import signal
import subprocess
import sys

import numpy as np
import pytest

import mbdyn as mb
from mbdyn import limits
from test_hostile import BASE, in_process, model_text

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))

#: seconds a test may take unless it says otherwise (numba's first compilation included)
LIMIT_S = 150


class TimeLimit(BaseException):
    """A test ran past its time limit: a BaseException, so that the command's own handlers
    cannot turn it into an exit code."""


@pytest.fixture(autouse=True)
def time_limit():
    """Every test under ``LIMIT_S`` seconds; ``time_limit(s)`` sets another limit."""
    def arm(seconds):
        signal.alarm(int(seconds))

    def expire(signum, frame):
        raise TimeLimit("the test ran past its time limit")
    previous = signal.signal(signal.SIGALRM, expire)
    arm(LIMIT_S)
    yield arm
    signal.alarm(0)
    signal.signal(signal.SIGALRM, previous)


def run_cli(argv, tmp_path, text=None, timeout=120):
    """``mbdyn ARGV`` in a subprocess (its own memory, a time limit); ``{model}`` is a file
    holding ``text``, ``{tmp}`` the test's directory."""
    path = tmp_path / "model.toml"
    if text is not None:
        path.write_text(text, encoding="utf-8")
    argv = [a.replace("{model}", str(path)).replace("{tmp}", str(tmp_path)) for a in argv]
    env = dict(os.environ, PYTHONPATH=ROOT)
    env.pop("MBDYN_DEBUG", None)
    return subprocess.run([sys.executable, "-m", "mbdyn"] + argv, capture_output=True,
                          text=True, timeout=timeout, cwd=tmp_path, env=env)


def clean(err):
    """No traceback, no internal error, no escape character reached the user."""
    assert "Traceback" not in err and "internal error" not in err, err
    assert "\x1b" not in err


def chain(n, kind="revolute"):
    """A model file of an ``n``-link planar chain."""
    parts = ['[model]\nname = "chain"\ngravity = [0, "-g", 0]\n\n'
             '[parameters]\nm = 1.0\nl = 0.5\ng = 9.81\n']
    for k in range(n):
        parts.append(f'[[bodies]]\nname = "b{k}"\nmass = "m"\ncom = ["l", 0, 0]\n'
                     'inertia = [0.01, 0.01, 0.01]\n')
    for k in range(n):
        parent = "ground" if k == 0 else f"b{k - 1}"
        position = "[0, 0, 0]" if k == 0 else '["l", 0, 0]'
        parts.append(f'[[joints]]\nname = "j{k}"\nkind = "{kind}"\nparent = "{parent}"\n'
                     f'child = "b{k}"\naxis = "z"\nposition = {position}\n')
    parts.append("[simulation]\nt_end = 1.0\n")
    return "\n".join(parts)


# -- 8: closed-form equations of long chains ------------------------------------------------
# id, links, extra options, pattern of the refusal (None: it must print the equations)
EOM_CASES = [
    ("chain-20", 20, [], r"frames down to 'b\d+' alone would have [\d.e+]+ parts.*more "
                         r"than 2000000 \(limits.MAX_EQUATION_NODES.*fewer links"),
    ("chain-8-newton-euler", 8, ["--method", "newton-euler"],
     r"M and f by newton-euler would have 3.06e\+06 parts.*jourdain method without solving"),
    ("chain-6-solve", 6, ["--solve"], r"solved accelerations would have .* parts"),
    ("chain-2", 2, [], None),
    ("chain-3-solve-steps", 3, ["--method", "newton-euler", "--solve", "--steps"], None),
]


@pytest.mark.parametrize("case_id, links, options, pattern", EOM_CASES,
                         ids=[c[0] for c in EOM_CASES])
def test_eom_of_a_long_chain_is_refused_quickly_with_its_size(case_id, links, options,
                                                               pattern, tmp_path):
    proc = run_cli(["eom", "{model}"] + options, tmp_path, chain(links), timeout=60)
    clean(proc.stderr)
    if pattern is None:
        assert proc.returncode == 0, proc.stderr
        assert "j0_dot" in proc.stdout and "derived in" in proc.stdout
    else:
        assert proc.returncode == 1, proc.stderr
        assert re.search(pattern, proc.stderr), proc.stderr


def test_derive_in_python_keeps_a_long_chain_and_skips_only_the_slow_count(tmp_path):
    (tmp_path / "c.toml").write_text(chain(14))
    d = mb.derive(mb.load_model(tmp_path / "c.toml").model)      # seconds, not minutes
    assert "operations" not in d.stats                           # count_ops is exponential
    assert 0 < d.stats["operations_after_cse"] < 10_000
    with pytest.raises(mb.ModelError, match=r"M and f by jourdain would have"):
        mb.derive(mb.load_model(tmp_path / "c.toml").model, max_nodes=10**6)


# -- 1: names that matplotlib reads as math -------------------------------------------------
#: legal labels that matplotlib would parse as TeX math (an exception) or as markup
MATH_NAMES = ["cost $\\foo{$", "</b>$x^{$", "$$", "a\\$b$", "50% $ of \\$"]

#: the base model, hanging (so that it has an oscillating mode), named as math; with a case
MATH_MODEL = model_text(name='"cost $\\\\foo{$"', com='[0, "-l", 0]') + \
    '\n[cases."x $\\\\foo{$"]\ninitial = { theta = 0.3 }\n'


def _ffmpeg():
    try:
        import imageio_ffmpeg  # noqa: F401
        return True
    except ImportError:
        return False


# id, argv, the file it must write
MATH_CLI_CASES = [
    ("plot", ["plot", "{model}", "--out", "{tmp}/p.png"], "p.png"),
    ("plot-case", ["plot", "{model}", "--case", "x $\\foo{$", "--out", "{tmp}/p.png"],
     "p.png"),
    ("plot-phase", ["plot", "{model}", "--phase", "theta,theta_dot", "--out", "{tmp}/p.svg"],
     "p.svg"),
    ("run-plot", ["run", "{model}", "--case", "x $\\foo{$", "--plot", "{tmp}/r.pdf"], "r.pdf"),
    ("animate-gif", ["animate", "{model}", "--case", "x $\\foo{$", "--out", "{tmp}/a.gif",
                     "--speed", "4", "--fps", "10"], "a.gif"),
    ("animate-mp4", ["animate", "{model}", "--out", "{tmp}/a.mp4", "--speed", "4", "--fps",
                     "10"], "a.mp4"),
    ("modes-animate", ["modes", "{model}", "--animate", "{tmp}/m.gif"], "m.gif"),
    ("accuracy-plot", ["accuracy", "{model}", "--case", "x $\\foo{$", "--integrators", "RK45",
                       "--tolerances", "1e-4,1e-6", "--repeats", "1", "--plot",
                       "{tmp}/w.png"], "w.png"),
]


@pytest.mark.parametrize("case_id, argv, written", MATH_CLI_CASES,
                         ids=[c[0] for c in MATH_CLI_CASES])
def test_names_matplotlib_reads_as_math_are_drawn_literally(case_id, argv, written, tmp_path,
                                                           capsys):
    pytest.importorskip("matplotlib")
    if written.endswith(".mp4") and not _ffmpeg():
        pytest.skip("MP4 needs imageio-ffmpeg")
    code, out, err = in_process(argv, tmp_path, MATH_MODEL, capsys)
    clean(err)
    assert code == 0, err
    assert (tmp_path / written).stat().st_size > 0


def _svg_texts(fig_or_call, path):
    """The texts of an SVG written with its texts kept as text."""
    import html

    import matplotlib
    with matplotlib.rc_context({"svg.fonttype": "none"}):
        fig_or_call(path)
    return html.unescape(path.read_text())


def _math_named_result():
    s = mb.System(MATH_NAMES[0], gravity=(0, -9.81, 0))
    parent = "ground"
    for k, name in enumerate(MATH_NAMES):
        s.add_body(name, mass=1.0, com=(0, -0.3, 0))
        s.add_joint(name + " joint", "revolute", parent=parent, child=name, axis="z",
                    coordinates=[f"_q{k}"], position=(0, -0.3, 0) if k else (0, 0, 0))
        parent = name
    model = s.compile()
    res = mb.simulate(model, 0.3, q0={"_q0": 1.0}, integrator="rk4", dt=0.01,
                      events=[mb.Event(MATH_NAMES[1], "_q0 - 0.9")])
    res.compute_outputs(("reactions", "energy"), {MATH_NAMES[2]: (MATH_NAMES[2], (0, 0, 0))})
    return res


def test_python_labels_reach_a_picture_as_the_text_typed(tmp_path):
    pytest.importorskip("matplotlib")
    res = _math_named_result()
    assert res.events and res.events[0][0] == MATH_NAMES[1]
    joint = MATH_NAMES[3] + " joint"
    text = _svg_texts(lambda p: res.plot(series=["_q0", f"reaction_{joint}_Fx",
                                                 f"point_{MATH_NAMES[2]}"],
                                         out=p, title=MATH_NAMES[4]),
                      tmp_path / "p.svg")
    for literal in (MATH_NAMES[4], MATH_NAMES[1], f"reaction {joint} Fx",
                    f"{MATH_NAMES[2]} x"):
        assert literal in text, literal
    assert "\u200b_q0" in text             # a leading _ would have left the legend
    text = _svg_texts(lambda p: res.plot(phase="_q0,_q0_dot", out=p), tmp_path / "f.svg")
    assert f"{MATH_NAMES[0]}: phase portrait" in text
    res.animate(tmp_path / "a.gif", speed=2.0, fps=10.0, title=MATH_NAMES[1])
    from mbdyn.viz import snapshot
    text = _svg_texts(lambda p: snapshot(res, p, title=MATH_NAMES[3]), tmp_path / "s.svg")
    assert MATH_NAMES[3] in text


def _spring_model(k):
    """A mass on a spring of stiffness ``k``: a Campbell diagram's model function."""
    s = mb.System("r", gravity=(0, 0, 0))
    s.add_body("b", mass=1.0, com=(0, 0, 0))
    s.add_joint("x", "prismatic", "ground", "b", axis="x")
    s.add_force("spring", "joint-spring-damper", joint="x", stiffness=k)
    return s.compile()


def test_a_campbell_parameter_named_as_math_labels_its_axis_literally(tmp_path):
    pytest.importorskip("matplotlib")
    cb = mb.campbell(_spring_model, MATH_NAMES[1], [1.0, 2.0, 3.0], spin_is_parameter=False)
    text = _svg_texts(lambda p: cb.plot(p), tmp_path / "c.svg")
    assert MATH_NAMES[1] in text


def test_a_sweep_picture_shows_text_values_and_names_literally(tmp_path):
    pytest.importorskip("matplotlib")
    from mbdyn.analysis.sweep import SweepResult
    from mbdyn.viz.sweep_plots import plot_sweep
    quantity = "max:" + MATH_NAMES[0]
    rows = [{"parameters.l": v, quantity: float(k), "status": "ok"}
            for k, v in enumerate(MATH_NAMES[1:4])]
    result = SweepResult(["parameters.l", quantity, "status"], rows, None, {})
    text = _svg_texts(lambda p: plot_sweep(result, quantity, p, axes=["parameters.l"]),
                      tmp_path / "s.svg")
    for literal in [quantity] + MATH_NAMES[1:4]:
        assert literal in text, literal


# -- 2: outputs checked before the work -----------------------------------------------------
class WorkStarted(BaseException):
    """The command began its work before refusing its output path."""


# id, argv, pattern of the refusal
OUTPUT_CASES = []
for _command, _argv in (
        ("plot", ["plot", "{model}", "--out"]),
        ("run", ["run", "{model}", "--plot"]),
        ("animate", ["animate", "{model}", "--out"]),
        ("modes", ["modes", "{model}", "--animate"]),
        ("campbell", ["campbell", "{model}", "--parameter", "l", "--values", "1:2:100000",
                      "--plot"]),
        ("accuracy", ["accuracy", "{model}", "--plot"])):
    OUTPUT_CASES += [
        (f"{_command}-format", _argv + ["{tmp}/x.txt"], r"x.txt: unknown (picture|animation) "
                                                        r"format '.txt'; use one of"),
        (f"{_command}-folder", _argv + ["{tmp}/nope/x.png" if _command not in (
            "animate", "modes") else "{tmp}/nope/x.gif"], r"the folder .*nope does not "
                                                          "exist"),
        (f"{_command}-directory", _argv + ["{tmp}/d.png" if _command not in (
            "animate", "modes") else "{tmp}/d.gif"], r"d\.(png|gif): is a folder"),
    ]


@pytest.mark.parametrize("case_id, argv, pattern", OUTPUT_CASES,
                         ids=[c[0] for c in OUTPUT_CASES])
def test_an_output_is_checked_before_any_work(case_id, argv, pattern, tmp_path, capsys,
                                              monkeypatch):
    (tmp_path / "d.png").mkdir()
    (tmp_path / "d.gif").mkdir()

    def work(*args, **kwargs):          # every command's work starts by loading the model
        raise WorkStarted(case_id)
    monkeypatch.setattr("mbdyn.cli.common.load_model", work)
    code, out, err = in_process(argv, tmp_path, BASE, capsys)
    clean(err)
    assert code == 1, err
    assert re.search(pattern, err), err


def test_campbell_plot_in_python_checks_its_path_and_writes_whole(tmp_path):
    pytest.importorskip("matplotlib")
    cb = mb.campbell(_spring_model, "k", [1.0, 2.0], spin_is_parameter=False)
    with pytest.raises(mb.ModelError, match=r"x.txt: unknown picture format"):
        cb.plot(tmp_path / "x.txt")
    cb.plot(tmp_path / "c.png")
    assert sorted(os.listdir(tmp_path)) == ["c.png"]


# -- 4: effects switched both on and off ----------------------------------------------------
DAMPER = ('\n[[forces]]\nname = "damper"\nkind = "joint-spring-damper"\njoint = "hinge"\n'
          "damping = 0.1\n")

# id, the file's tail, argv, exit code, pattern
EFFECT_FILE_CASES = [
    ("on-and-off", '[effects]\noff = ["gravity"]\non = ["gravity"]\n', [], 1,
     r"model.toml: effects: effect 'gravity' is switched both on \(on = \['gravity'\]\) and "
     r"off \(off = \['gravity'\]\)"),
    ("false-and-on", '[effects]\ngravity = false\non = ["gravity"]\n', [], 1,
     r"effect 'gravity' is switched both on .* and off \(gravity = false\)"),
    ("in-one-case", '[cases.a.effects]\non = ["damper"]\noff = ["damper"]\n',
     ["--case", "a"], 1, r"effect 'damper' is switched both"),
    ("flag", "", ["--effects=-damper,+damper"], 1,
     r"--effects.*effect 'damper' is switched both on \(\+damper\) and off \(-damper\)"),
    ("off-list-not-a-list", "[effects]\noff = 5\n", [], 1, r"effects.off"),
    # a case decides what it switches: no contradiction with the file's table
    ("case-switches-back-on", '[effects]\noff = ["damper"]\ngravity = false\n'
     '[cases.a.effects]\non = ["damper", "gravity"]\n', ["--case", "a"], 0, r"^$"),
]


@pytest.mark.parametrize("case_id, tail, argv, code, pattern", EFFECT_FILE_CASES,
                         ids=[c[0] for c in EFFECT_FILE_CASES])
def test_an_effect_switched_both_ways_is_refused_with_its_name(case_id, tail, argv, code,
                                                               pattern, tmp_path, capsys):
    got, out, err = in_process(["info", "{model}"] + argv, tmp_path, BASE + DAMPER + tail,
                               capsys)
    clean(err)
    assert got == code, err
    assert re.search(pattern, err), err


def test_a_case_switches_back_on_what_the_file_switches_off(tmp_path):
    (tmp_path / "m.toml").write_text(BASE + DAMPER + '[effects]\noff = ["damper"]\n'
                                     'gravity = false\n[cases.a.effects]\non = ["damper"]\n')
    assert mb.load_model(tmp_path / "m.toml").model.effects == {
        "gravity": False, "gyroscopic": True, "damper": False}
    assert mb.load_model(tmp_path / "m.toml", case="a").model.effects == {
        "gravity": False, "gyroscopic": True, "damper": True}


def _pendulum(name="p"):
    s = mb.System(name, gravity=(0, -9.81, 0))
    s.add_body("bob", mass=1.0, com=(0.5, 0, 0))
    s.add_joint("hinge", "revolute", "ground", "bob", axis="z")
    return s


def _damped():
    s = _pendulum()
    s.add_force("damper", "joint-spring-damper", joint="hinge", damping=0.1)
    return s


EFFECT_API_CASES = [
    ("on-and-off", {"off": ["gravity"], "on": ["gravity"]},
     r"effect 'gravity' is switched both on \(on = \['gravity'\]\) and off"),
    ("false-and-on", {"gravity": False, "on": ["gravity"]},
     r"effect 'gravity' is switched both on .* and off \(gravity = false\)"),
    ("true-and-off", {"off": "damper", "damper": True}, r"effect 'damper' is switched both"),
    ("text", "-damper, +damper", r"effect 'damper' is switched both"),
    ("list", ["-gravity", "gravity"], r"effect 'gravity' is switched both"),
    ("off-number", {"off": 5}, r"effects: off = 5: give a list of effect names"),
    ("off-nested", {"off": [["gravity"]]}, r"unknown effect \['gravity'\]"),
]


@pytest.mark.parametrize("case_id, spec, pattern", EFFECT_API_CASES,
                         ids=[c[0] for c in EFFECT_API_CASES])
def test_compile_refuses_effects_switched_both_ways(case_id, spec, pattern):
    with pytest.raises(mb.ModelError, match=pattern):
        _damped().compile(effects=spec)


def test_the_same_switch_twice_is_no_contradiction():
    model = _damped().compile(effects={"off": ["gravity", "gravity"], "gravity": False})
    assert model.effects["gravity"] is False


# -- 5: an element between a body and itself: the same refusal in Python and in a file -----
# id, the element's keys (TOML), its keyword arguments, pattern
SAME_BODY_CASES = [
    ("spring", 'kind = "spring-damper"\nbody_a = "bob"\nbody_b = "bob"\nstiffness = 10.0',
     dict(kind="spring-damper", body_a="bob", body_b="bob", stiffness=10.0),
     r"^force 'e': body_a and body_b are both 'bob'; a spring acts between two bodies \(or "
     r"a body and the ground\)$"),
    ("spring-ground", 'kind = "spring-damper"\nbody_a = "ground"\nstiffness = 10.0',
     dict(kind="spring-damper", body_a="ground", stiffness=10.0),
     r"body_a and body_b are both 'ground'"),
    ("bushing", 'kind = "bushing"\nbody_a = "bob"\nbody_b = "bob"\n'
                'stiffness = [1, 1, 1, 1, 1, 1]',
     dict(kind="bushing", body_a="bob", body_b="bob", stiffness=[1] * 6),
     r"body_a and body_b are both 'bob'; a bushing acts between two bodies"),
    ("bearing", 'kind = "bearing"\nbody = "bob"\nhousing = "bob"\nkxx = 1.0\nkyy = 1.0',
     dict(kind="bearing", body="bob", housing="bob", kxx=1.0, kyy=1.0),
     r"the shaft body is 'bob' and the housing 'bob'; a bearing acts between"),
    ("bearing-ground", 'kind = "bearing"\nbody = "ground"\nkxx = 1.0\nkyy = 1.0',
     dict(kind="bearing", body="ground", kxx=1.0, kyy=1.0),
     r"the shaft body is 'ground'"),
]


@pytest.mark.parametrize("case_id, toml, keywords, pattern", SAME_BODY_CASES,
                         ids=[c[0] for c in SAME_BODY_CASES])
def test_an_element_between_a_body_and_itself_is_refused_alike(case_id, toml, keywords,
                                                               pattern, tmp_path):
    with pytest.raises(mb.ModelError, match=pattern) as python:
        _pendulum().add_force("e", keywords.pop("kind"), **keywords)
    path = tmp_path / "m.toml"
    path.write_text(BASE + f'\n[[forces]]\nname = "e"\n{toml}\n')
    with pytest.raises(mb.ModelFileError) as file:
        mb.load_model(path)
    assert file.value.key == "forces[0]"
    assert file.value.problem == str(python.value)


# -- 6: options at the edge of the floats: named, with the bound, no numpy warning ----------
# id, argv, pattern
EDGE_CASES = [
    ("animate-speed-1e-300", ["animate", "{model}", "--out", "{tmp}/a.gif", "--speed",
                              "1e-300"],
     r"speed 1e-300 \(--speed\) at [\d.]+ frames per second \(--fps\) would need 6.67e\+300 "
     r"frames for the 0.2 s of the run, more than 3000; raise the speed to at least 0.00"),
    ("animate-speed-denormal", ["animate", "{model}", "--out", "{tmp}/a.gif", "--speed",
                                "1e-320"], r"\(--speed\).*would need more than 1e308 frames"),
    ("campbell-log-through-zero", ["campbell", "{model}", "--parameter", "l",
                                   "--values=-1:1:3log"],
     r"--values '-1:1:3log': a logarithmic range needs START and STOP of one sign, neither "
     r"zero \(got -1 and 1\); for a linear range write -1:1:3"),
    ("campbell-log-from-zero", ["campbell", "{model}", "--parameter", "l", "--values",
                                "0:1:5log"], r"--values '0:1:5log': a logarithmic range"),
    ("campbell-inf", ["campbell", "{model}", "--parameter", "l", "--values", "inf:1:3"],
     r"--values 'inf:1:3': inf is not a finite number"),
    ("campbell-nan-list", ["campbell", "{model}", "--parameter", "l", "--values", "1,nan"],
     r"--values '1,nan': nan is not a finite number"),
    ("campbell-huge", ["campbell", "{model}", "--parameter", "l", "--values", "1:1e200:3"],
     r"--values '1:1e200:3': 1e\+200 is beyond the range mbdyn accepts"),
]


@pytest.mark.parametrize("case_id, argv, pattern", EDGE_CASES, ids=[c[0] for c in EDGE_CASES])
def test_an_option_at_the_edge_is_named_with_its_bound(case_id, argv, pattern, tmp_path,
                                                       capsys):
    code, out, err = in_process(argv, tmp_path, BASE, capsys)
    clean(err)
    assert code == 1, err
    assert re.search(pattern, err), err
    assert "warning" not in err and len(err) < 400, err     # no numpy warning, no 300 digits


def test_an_animation_at_a_tiny_speed_is_refused_in_python_too(tmp_path):
    res = mb.simulate(_pendulum().compile(), 0.2, integrator="rk4", dt=0.01)
    for speed in (1e-300, 1e-320):
        with pytest.raises(mb.ModelError, match=r"raise the speed to at least"):
            res.animate(tmp_path / "a.html", speed=speed)
    from mbdyn.viz.geometry import sample_times
    with pytest.raises(mb.ModelError, match=r"fps \(--fps\) must be a positive, finite"):
        sample_times(res, fps="many")
    assert not os.listdir(tmp_path)


# -- 7: sympy expansion bounded -------------------------------------------------------------
BIG_POWER = BASE.replace("[parameters]\n", "[parameters]\na = 0.3\nb = 0.3\nc = 0.4\n").replace(
    'mass = "m"\n', 'mass = "(a+b+c)**1000"\ninertia = [1, 1, 1]\ninertia_about = "origin"\n')


@pytest.mark.parametrize("command", ["run", "info", "eom"])
def test_a_huge_power_in_an_inertia_about_the_origin_is_not_expanded(command, tmp_path,
                                                                     capsys, time_limit):
    time_limit(60)                  # it ran past 60 s expanding (a+b+c)**1000
    code, out, err = in_process([command, "{model}"], tmp_path, BIG_POWER, capsys)
    clean(err)
    assert code == 0, err
    if command == "eom":
        assert "(a + b + c)**1000" in out


def test_an_inertia_about_the_origin_is_still_expanded_when_small(tmp_path):
    path = tmp_path / "m.toml"
    path.write_text(BIG_POWER.replace("(a+b+c)**1000", "(a+b)**2"))
    scene = mb.load_model(path)
    inertia = scene.model.body("bob").inertia
    np.testing.assert_allclose(np.diag(inertia), [1.0, 1 - 0.36 * 0.25, 1 - 0.36 * 0.25])
    path.write_text(BIG_POWER)
    np.testing.assert_allclose(np.diag(mb.load_model(path).model.body("bob").inertia),
                               [1.0, 0.75, 0.75])


# -- 9: a Campbell diagram at its maximum says how long it will take ------------------------
class _Stream:
    def __init__(self, tty):
        self.text, self.tty = "", tty

    def isatty(self):
        return self.tty

    def write(self, s):
        self.text += s

    def flush(self):
        pass


@pytest.mark.parametrize("tty", [False, True])
def test_an_estimate_extrapolates_the_first_values_after_the_first(tty):
    from mbdyn.cli.common import Estimate
    now = [0.0]
    stream = _Stream(tty)
    est = Estimate("values", stream=stream, clock=lambda: now[0])
    now[0] = 5.0                        # the first value pays for compilation
    est(1, 100_000)
    for done in (2, 3, 4):
        now[0] += 0.5
        est(done, 100_000)
    assert "mbdyn: 100000 values will take about 14 h (0.5 s each, timed over 3 of them)" \
        in stream.text
    now[0] += 0.5
    est(5, 100_000)
    assert ("\rmbdyn: 5 of 100000 values" in stream.text) == tty
    est.close()
    assert stream.text.count("will take") == 1


def test_a_short_loop_gives_no_estimate():
    from mbdyn.cli.common import Estimate
    now = [0.0]
    stream = _Stream(True)
    est = Estimate("values", stream=stream, clock=lambda: now[0])
    for done in range(1, 21):
        now[0] += 0.1
        est(done, 20)
    est.close()
    assert stream.text == ""


def test_campbell_at_its_maximum_says_how_long_before_the_work(tmp_path):
    """100 000 values (the documented maximum): the estimate comes after a few values; the
    run is then stopped (SIGTERM), cleanly."""
    (tmp_path / "model.toml").write_text(BASE)
    env = dict(os.environ, PYTHONPATH=ROOT)
    proc = subprocess.Popen([sys.executable, "-m", "mbdyn", "campbell", "model.toml",
                             "--parameter", "l", "--values", f"0.1:2:{limits.MAX_RANGE_POINTS}"],
                            cwd=tmp_path, env=env, stdout=subprocess.DEVNULL,
                            stderr=subprocess.PIPE, text=True)
    try:
        line = proc.stderr.readline()
        assert re.match(r"mbdyn: 100000 values will take about [\d.]+ (s|min|h|days) "
                        r"\([\d.e-]+ s each, timed over 3 of them\); Ctrl-C stops", line), line
        proc.send_signal(signal.SIGTERM)
        err = proc.stderr.read()
        assert proc.wait(timeout=60) == 143, err
        clean(err)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()


# -- 3: the Python interface: wrong types, NaN/inf, counts below one -> the package's errors --
def _model():
    return _pendulum().compile()


def _lin():
    return mb.linearize(_model(), [0.3], [0.0])


def _bearing(**keys):
    return _pendulum().add_force("bearing", "bearing", body="bob", **keys)


# id, call, exception, pattern
API_CASES = [
    # force elements
    ("bearing-speeds-number", lambda: _bearing(kxx=[1.0, 2.0], kyy=1.0, speeds=5),
     mb.ModelError, r"force 'bearing': speeds must be a list of spin speeds"),
    ("bearing-speeds-text", lambda: _bearing(kxx=[1.0, 2.0], kyy=1.0, speeds="ab"),
     mb.ModelError, r"speeds must be a list"),
    ("joint-spring-joint-list", lambda: _pendulum().add_force(
        "s", "joint-spring-damper", joint=["hinge"], stiffness=1.0), mb.ModelError,
     r"force 's': joint must be the name of a joint"),
    ("spring-body-number", lambda: _pendulum().add_force(
        "s", "spring-damper", body_a=5, stiffness=1.0), mb.ModelError,
     r"body_a must be the name of a body"),
    ("contact-exponent-huge", lambda: _pendulum().add_force(
        "c", "contact", body="bob", stiffness=1e5, restitution=0.5, exponent=1e308),
     mb.ModelError, r"force 'c': exponent 1e\+308: the impact .* cannot be computed"),
    ("effects-off-number", lambda: _pendulum().compile(effects={"off": 5}), mb.ModelError,
     r"off = 5: give a list of effect names"),
    ("parse-effects-known", lambda: mb.effects.parse_effects(None, None), mb.ModelError,
     r"known must be a list of effect names"),
    # joints
    ("joint-kind-list", lambda: _second(kind=[]), mb.ModelError, r"unknown kind \[\]"),
    ("joint-orientation-text", lambda: _second(orientation="abc"), mb.ModelError,
     r"orientation must be a 3x3 rotation matrix"),
    ("joint-orientation-angle", lambda: _second(orientation=("z", "right")), mb.ModelError,
     r"the angle of orientation \(axis, angle\) must be a number"),
    ("joint-orientation-nan", lambda: _second(orientation=("z", float("nan"))),
     mb.ModelError, r"must be finite"),
    ("joint-coordinates-number", lambda: _second(coordinates=5), mb.ModelError,
     r"coordinates must be a name or a list of names"),
    ("joint-speeds-number", lambda: _second(speeds=1.5), mb.ModelError,
     r"speeds must be a name or a list of names"),
    ("joint-drive-bool", lambda: _second(drive=True), mb.ModelError,
     r"drive must be a sympy expression of mb.t"),
    # analysis
    ("equilibrium-t-inf", lambda: mb.equilibrium(_model(), t=float("inf")), mb.ModelError,
     r"equilibrium: t must be a finite number, got inf"),
    ("equilibrium-t-nan", lambda: mb.equilibrium(_model(), t=float("nan")), mb.ModelError,
     r"equilibrium: t must be a finite number, got nan"),
    ("equilibrium-t-text", lambda: mb.equilibrium(_model(), t="now"), mb.ModelError,
     r"t must be a number"),
    ("equilibrium-u-huge", lambda: mb.equilibrium(_model(), u=[1e308]), mb.ModelError,
     r"generalized forces .* are not finite at the guess"),
    ("equilibrium-model-text", lambda: mb.equilibrium("pendulum"), mb.ModelError,
     r"equilibrium: model must be a compiled Model"),
    ("equilibrium-tol-zero", lambda: mb.equilibrium(_model(), tol=0), mb.ModelError,
     r"tol must be > 0"),
    ("equilibrium-max-iter-zero", lambda: mb.equilibrium(_model(), max_iter=0),
     mb.ModelError, r"max_iter must be a whole number >= 1"),
    ("equilibrium-fixed-number", lambda: mb.equilibrium(_model(), fixed=5), mb.ModelError,
     r"fixed must be a name or a list of names"),
    ("equilibrium-guess-text", lambda: mb.equilibrium(_model(), q_guess="abc"),
     mb.ModelError, r"q_guess must be an array of numbers"),
    ("linearize-step-zero", lambda: mb.linearize(_model(), [0.3], [0.0], step=0),
     mb.ModelError, r"linearize: step must be > 0"),
    ("linearize-step-huge", lambda: mb.linearize(_model(), [0.3], [0.0], step=1e300),
     mb.NonFiniteError, r"accelerations came out non-finite"),
    ("linearize-t-none", lambda: mb.linearize(_model(), t=None), mb.ModelError,
     r"linearize: t must be a number"),
    ("linearize-q0-text", lambda: mb.linearize(_model(), q0=["x"]), mb.ModelError,
     r"q0 must be an array of numbers"),
    ("linearize-model-none", lambda: mb.linearize(None), mb.ModelError,
     r"linearize: model must be a compiled Model"),
    ("modes-not-a-linearization", lambda: mb.modes(_model()), mb.ModelError,
     r"modes: give a linearisation"),
    ("modes-whirl-number", lambda: mb.modes(_lin(), whirl=5), mb.ModelError,
     r"whirl must be a list of pairs"),
    ("modes-tolerance-none", lambda: mb.modes(_lin(), rigid_tolerance=None), mb.ModelError,
     r"rigid_tolerance must be a number"),
    ("campbell-returns-none", lambda: mb.campbell(lambda v: None, "k", [1.0, 2.0]),
     mb.ModelError, r"campbell: the function of k returned NoneType at k = 1; it must "
                    r"return a compiled Model"),
    ("campbell-values-text", lambda: mb.campbell(_spring_model, "k", "abc"), mb.ModelError,
     r"campbell: values must be numbers"),
    ("campbell-orders-number", lambda: mb.campbell(_spring_model, "k", [1, 2], orders=2),
     mb.ModelError, r"orders must be a list of whole numbers"),
    ("campbell-orders-zero", lambda: mb.campbell(_spring_model, "k", [1, 2], orders=[0]),
     mb.ModelError, r"each of orders must be a whole number >= 1"),
    ("campbell-parameter-number", lambda: mb.campbell(_spring_model, 5, [1, 2]),
     mb.ModelError, r"parameter must be a name"),
    ("derive-max-nodes-text", lambda: mb.derive(_model(), max_nodes="many"), mb.ModelError,
     r"max_nodes must be a whole number"),
    # helpers
    ("sphere-mass-text", lambda: mb.inertia.sphere("1", 0.1), mb.ModelError,
     r"inertia.sphere: mass must be a number"),
    ("sphere-radius-huge", lambda: mb.inertia.sphere(1.0, 1e300), mb.ModelError,
     r"inertia.sphere: radius 1e\+300 is beyond the range"),
    ("disk-axis", lambda: mb.inertia.disk(1.0, 0.1, axis="w"), mb.ModelError,
     r"inertia.disk: axis must be 'x', 'y' or 'z'"),
    ("parallel-axis-mass-nan", lambda: mb.inertia.parallel_axis(np.eye(3), float("nan"),
                                                                (0, 0, 1)),
     mb.ModelError, r"parallel_axis: mass must be a finite number"),
    ("parallel-axis-offset-text", lambda: mb.inertia.parallel_axis(np.eye(3), 1.0, "up"),
     mb.ModelError, r"parallel_axis: give the inertia as a 3x3 tensor"),
    ("about-com-inertia-nan", lambda: mb.inertia.about_com(np.full((3, 3), np.nan), 1.0,
                                                           (0, 0, 1)),
     mb.ModelError, r"about_com: inertia: nan is not a finite number"),
    ("axis-angle-nan", lambda: mb.rotations.from_axis_angle("z", float("nan")),
     mb.ModelError, r"from_axis_angle: angle must be a finite number, got nan"),
    ("euler-number", lambda: mb.rotations.from_euler(5), mb.ModelError,
     r"from_euler: angles must be 3 finite numbers"),
    ("to-matrix-text", lambda: mb.rotations.to_matrix("abc"), mb.ModelError,
     r"to_matrix: 'abc' is not a quaternion"),
    ("from-matrix-text", lambda: mb.rotations.from_matrix("abc"), mb.ModelError,
     r"from_matrix: R must be 3 x 3 finite numbers"),
    ("body-rates-nan", lambda: mb.rotations.body_rates([1, 0, 0, 0], [np.nan, 0, 0]),
     mb.ModelError, r"body_rates: omega must be 3 finite numbers"),
    ("load-model-overrides-number", lambda: mb.load_model(
        os.path.join(ROOT, "models", "top.toml"), overrides=5), mb.ModelError,
     r"load_model: overrides must be a mapping"),
    ("plot-series-number", lambda: _run().plot(series=5), mb.ModelError,
     r"series must be series names"),
    ("plot-phase-number", lambda: _run().plot(phase=5), mb.ModelError,
     r"phase must be series names"),
]


def _second(kind="revolute", **keys):
    s = _pendulum()
    s.add_body("bob2", mass=1.0, com=(0.5, 0, 0))
    keys.setdefault("axis", "z" if kind in ("revolute", []) else None)
    return s.add_joint("j2", kind, "bob", "bob2", **keys)


def _run():
    return mb.simulate(_model(), 0.1, q0=[0.3])


@pytest.mark.parametrize("case_id, call, exc, pattern", API_CASES,
                         ids=[c[0] for c in API_CASES])
def test_python_interface_gives_the_packages_errors(case_id, call, exc, pattern):
    with pytest.raises(exc, match=pattern) as info:
        call()
    assert type(info.value).__module__.startswith("mbdyn")     # never a raw TypeError


def test_parallel_axis_takes_principal_moments_as_a_diagonal():
    # three moments were broadcast over the rows of the tensor: a silent wrong answer
    np.testing.assert_array_equal(mb.inertia.parallel_axis([1.0, 2.0, 3.0], 2.0, (0, 0, 1)),
                                  mb.inertia.parallel_axis(np.diag([1.0, 2.0, 3.0]), 2.0,
                                                           (0, 0, 1)))


# --- issue 29: the core Python interface (System, Model, simulate, Result) --------------
def _pendulum_model():
    s = mb.System("core", gravity=(0, -9.81, 0))
    s.add_body("b", mass=1.0, com=(0, -1, 0))
    s.add_joint("j", "revolute", parent="ground", child="b", axis="z")
    return s, s.compile()


CORE_CASES = [
    ("system-parameters", lambda s, m: mb.System("x", parameters=5), r"must be a mapping"),
    ("parameter-nan", lambda s, m: mb.System("x", parameters={"a": float("nan")}),
     r"parameter 'a' is nan"),
    ("parameter-huge", lambda s, m: mb.System("x", parameters={"a": 1e300}), r"beyond"),
    ("symbols-number", lambda s, m: mb.System("x", parameters={"a": 1}).symbols(5),
     r"symbols takes parameter names"),
    ("origin-com-short", lambda s, m: mb.System("y").add_body(
        "b", mass=1, com=(0, 0), inertia=(1, 1, 1), inertia_about="origin"), r"com must be"),
    ("origin-text", lambda s, m: mb.System("y").add_body(
        "b", mass=1, com=("a", 0, 0), inertia=(1, 1, 1), inertia_about="origin"),
     r"numbers or sympy expressions"),
    ("load-name-list", lambda s, m: s.add_load([1], "b", force=(0, 0, 1)), r"must be a string"),
    ("joint-unknown", lambda s, m: m.joint("zz"), r"unknown joint 'zz'"),
    ("coordinate-unhashable", lambda s, m: m.coordinate_index([]), r"unknown coordinate"),
    ("forcing-nan", lambda s, m: m.forcing([np.nan], [0]), r"non-finite values in j"),
    ("momentum-nan", lambda s, m: m.momentum([np.nan], [0]), r"non-finite values in j"),
    ("u_dot-text", lambda s, m: m.inverse_dynamics([0], [0], "abc"), r"u_dot must be"),
    ("y-text", lambda s, m: m.state_derivative(0, "abc"), r"the state y must be"),
    ("points-none", lambda s, m: m.point_positions([0], None), r"points must be a list"),
    ("simulate-number", lambda s, m: mb.simulate(5, 1.0), r"model must be a compiled"),
    ("rtol-none", lambda s, m: mb.simulate(m, 1.0, rtol=None), r"rtol must be a positive"),
    ("max_step-text", lambda s, m: mb.simulate(m, 1.0, max_step="x"), r"max_step must be"),
    ("events-none", lambda s, m: mb.simulate(m, 1.0, events=None), r"events must be a list"),
    ("progress-number", lambda s, m: mb.simulate(m, 1.0, progress=5), r"progress must be"),
    ("outputs-number", lambda s, m: mb.simulate(m, 0.1, outputs=5), r"outputs must be"),
    ("points-list", lambda s, m: mb.simulate(m, 0.1, points=[1]), r"points must be"),
    ("to_csv-none", lambda s, m: mb.simulate(m, 0.1).to_csv(None), r"give a file name"),
    ("animate-speed-text", lambda s, m: mb.simulate(m, 0.1).animate("x.gif", speed="fast"),
     r"speed must be a positive number"),
]


@pytest.mark.parametrize("case_id, call, pattern", CORE_CASES, ids=[c[0] for c in CORE_CASES])
def test_the_core_python_interface_refuses_wrong_arguments_with_its_errors(case_id, call,
                                                                            pattern):
    s, m = _pendulum_model()
    with pytest.raises((mb.ModelError, mb.NonFiniteError), match=pattern):
        call(s, m)


def test_a_zero_quaternion_is_named_by_every_evaluation():
    s = mb.System("ball", gravity=(0, 0, -9.81))
    s.add_body("b", mass=1, com=(0, 0, -1), inertia=(1, 1, 1))
    s.add_joint("j", "spherical", parent="ground", child="b")
    m = s.compile()
    q, u = np.zeros(4), np.zeros(3)
    for call in (lambda: m.forward_dynamics(q, u),
                 lambda: m.forward_dynamics(q, u, method="articulated"),
                 lambda: m.state_derivative(0.0, np.zeros(7)), lambda: m.newton_euler(q, u),
                 lambda: m.kinematics(q, u), lambda: m.mass_matrix(q),
                 lambda: m.energy(q, u), lambda: m.reactions(q, u),
                 lambda: m.coordinate_rates(q, u), lambda: m.inverse_dynamics(q, u, u)):
        with pytest.raises(mb.NonFiniteError, match=r"quaternion j_qw.*no direction"):
            call()


def _block_on_spring(stiffness=None, table=None):
    s = mb.System("block", gravity=(0, 0, -9.81))
    s.add_body("block", mass=2.0)
    s.add_joint("z", "prismatic", parent="ground", child="block", axis="z")
    kw = dict(force_table=table) if table is not None else dict(stiffness=stiffness)
    s.add_force("spring", "spring-damper", body_a="block", free_length=1.0,
                point_b=(0, 0, 2), **kw)
    return s.compile()


def test_a_stiff_model_under_an_implicit_integrator_is_not_told_to_take_one():
    """Radau on k = 1e12 (an undamped oscillation it must follow) is not told to try
    Radau; an explicit integrator is."""
    m = _block_on_spring(stiffness=1e12)
    with pytest.raises(mb.SimulationError) as info:
        mb.simulate(m, 3.0, {"z": 0.5}, integrator="Radau")
    assert "implicit integrator Radau takes tiny steps too" in str(info.value)
    assert "try Radau" not in str(info.value)
    with pytest.raises(mb.SimulationError, match="explicit integrator .*try Radau or BDF"):
        mb.simulate(m, 30.0, {"z": 0.5}, integrator="DOP853")


def test_an_absurd_stiffness_stops_early_with_the_stiff_model_message():
    """k = 1e100 under DOP853: steps of 1e-50 s near t = 0 are far above the rounding of
    t, so the step projection trips after its first window (it ran to max_samples, for
    18-45 s, when the rounding limit was measured against 1 s instead of t)."""
    import time
    m = _block_on_spring(stiffness=1e100)
    start = time.perf_counter()
    with pytest.raises(mb.SimulationError, match=r"would need about .* steps.*explicit"):
        mb.simulate(m, 3.0, {"z": 0.5}, integrator="DOP853")
    assert time.perf_counter() - start < 30


def test_a_force_element_that_blows_up_is_named():
    m = _block_on_spring(table=[[0, 0], [1e-3, 1e95]])
    with pytest.raises(mb.SimulationError, match=r"force element 'spring' \(spring-damper\) "
                                                 r"gives a force of"):
        mb.simulate(m, 1.0, {"z": 0.5}, integrator="rk4", dt=1e-3)


def test_a_large_star_compiles_and_steps_without_the_dense_system():
    """Memory that grew as n^2 (issue 29): the 6n x 6n dense Newton-Euler workspace is
    allocated on first use of its route only, so are the full Jacobians and ``M``; the
    compile check and the conditioning take no O(n^3) step on large models.  A 2,000-body
    star peaked at 1.74 GB and took 3 s; now about 0.22 GB, most of it the interpreter,
    numba and the kernels (tests/test_large_models.py has the larger sizes)."""
    snippet = r"""
import resource, sys, time
import mbdyn as mb
warm = mb.System("warm-up")                 # the kernels compiled (or loaded) first
warm.add_body("b", mass=1.0, inertia=(1e-3, 1e-3, 1e-3))
warm.add_joint("j", "revolute", parent="ground", child="b", axis="z")
mb.simulate(warm.compile(), 1e-3, integrator="rk4", dt=1e-3)
base = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
s = mb.System("star", gravity=(0, -9.81, 0))
for i in range(2000):
    s.add_body(f"b{i}", mass=1.0, com=(0.1, 0, 0), inertia=(1e-3, 1e-3, 1e-3))
    s.add_joint(f"j{i}", "revolute", parent="ground", child=f"b{i}", axis="z",
                position=(0, 0, 0.01 * i))
m = s.compile()
start = time.perf_counter()
r = mb.simulate(m, 1e-3, integrator="rk4", dt=1e-3)
assert getattr(m, "_A", None) is None                 # never allocated
assert m._JR.size == 0 and m._M.size == 0             # neither
assert r.stats["mass_matrix_condition_initial"] is None
held = sum(b.nbytes for b in m._packed[:2]) / 2**20
print(held, resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024 - base,
      time.perf_counter() - start)
"""
    out = subprocess.run([sys.executable, "-c", snippet], capture_output=True, text=True,
                         timeout=300, env=dict(os.environ, OPENBLAS_NUM_THREADS="1"))
    assert out.returncode == 0, out.stderr
    held_mb, growth_mb, step_s = map(float, out.stdout.split())
    # the model's arrays: O(n), about 4 MB here (the Jacobians and M would be 2 x 96 MB and
    # 2 x 32 MB, the dense system 1.1 GB); the peak's growth past the kernels' compile
    # (which alone can take most of a gigabyte on a cold cache)
    assert held_mb < 20 and growth_mb < 300 and step_s < 120, (held_mb, growth_mb, step_s)


def test_the_model_file_size_limit_is_named_and_settable(tmp_path, monkeypatch):
    """A generated 7,000-body chain is over the default 1 MB: refused with the limit and
    how to raise it; MBDYN_MAX_FILE_BYTES raises it (and a bad value is named)."""
    rows = ['[model]\nname = "chain"\n']
    for i in range(7000):
        parent = "ground" if i == 0 else f"b{i - 1}"
        rows.append(f'[[bodies]]\nname = "b{i}"\nmass = 1.0\ncom = [0.1, 0, 0]\n'
                    f'inertia = [0.001, 0.001, 0.001]\n\n[[joints]]\nname = "j{i}"\n'
                    f'type = "revolute"\nparent = "{parent}"\nchild = "b{i}"\naxis = "z"\n'
                    f'position = [{0.1 if i else 0}, 0, 0]\n')
    path = tmp_path / "chain.toml"
    path.write_text("\n".join(rows))
    assert path.stat().st_size > 1_000_000
    monkeypatch.delenv("MBDYN_MAX_FILE_BYTES", raising=False)
    with pytest.raises(mb.ModelFileError, match=r"more than a model file may be "
                                                r"\(1000000\).*MBDYN_MAX_FILE_BYTES"):
        mb.load_model(path)
    monkeypatch.setenv("MBDYN_MAX_FILE_BYTES", "lots")
    with pytest.raises(mb.ModelError, match=r"MBDYN_MAX_FILE_BYTES='lots'"):
        mb.load_model(path)
    monkeypatch.setenv("MBDYN_MAX_FILE_BYTES", "5000000")
    from mbdyn.io.document import read_bytes
    assert len(read_bytes(path)) == path.stat().st_size
