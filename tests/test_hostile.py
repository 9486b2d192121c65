"""Hostile input, table-driven: each row is one input a hostile (or careless) user gives,
the exit code the ``mbdyn`` command must end with and a pattern its one-line message must
match (naming the key or element and what to change).  A new case is one line in a table.

Classes (issue 15): hangs and memory blow-ups, crashes ("internal error"), silent garbage,
leaks and unclear messages, torn results.  Every row runs under a time limit; none may
print a traceback or exit 70.
"""
from __future__ import annotations

import json
import os
import re
import signal
import subprocess
import sys
import textwrap
import time

import numpy as np
import pytest

import mbdyn as mb
from mbdyn.cli import main
from mbdyn.io.results import verify_results

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))

#: a small valid model; rows change it with {"path.to.key": value-as-TOML-text} or replace it
BASE = """\
[model]
name = "pendulum"
gravity = [0, "-g", 0]

[parameters]
m = 1.0
l = 0.5
g = 9.81

[[bodies]]
name = "bob"
mass = "m"
com = ["l", 0, 0]

[[joints]]
name = "hinge"
kind = "revolute"
parent = "ground"
child = "bob"
axis = "z"
coordinates = ["theta"]

[initial]
theta = 0.5

[simulation]
t_end = 0.2
"""


def model_text(**changes):
    """BASE with lines ``key = ...`` replaced: ``model_text(mass='1e308')``."""
    lines = BASE.splitlines()
    for key, value in changes.items():
        for i, line in enumerate(lines):
            if line.split(" = ")[0] == key:
                lines[i] = f"{key} = {value}"
                break
        else:
            raise KeyError(key)
    return "\n".join(lines) + "\n"


def run_cli(argv, tmp_path, text=None, timeout=60):
    """Run ``mbdyn ARGV`` in a subprocess (time-limited); ``{model}`` in ARGV is a file
    holding ``text``."""
    path = tmp_path / "model.toml"
    if text is not None:
        path.write_text(text, encoding="utf-8")
    argv = [a.replace("{model}", str(path)).replace("{tmp}", str(tmp_path)) for a in argv]
    env = dict(os.environ, PYTHONPATH=ROOT)
    env.pop("MBDYN_DEBUG", None)
    proc = subprocess.run([sys.executable, "-m", "mbdyn"] + argv, capture_output=True,
                          text=True, timeout=timeout, cwd=tmp_path, env=env)
    return proc


def in_process(argv, tmp_path, text, capsys):
    path = tmp_path / "model.toml"
    if text is not None:
        path.write_text(text, encoding="utf-8")
    argv = [a.replace("{model}", str(path)).replace("{tmp}", str(tmp_path)) for a in argv]
    code = main(argv)
    out, err = capsys.readouterr()
    return code, out, err


RUN = ["run", "{model}"]

# id, model text, argv, exit code, pattern of the message
FILE_CASES = [
    # -- hangs and memory blow-ups
    ("tower-of-exp-in-set", BASE, RUN + ["--set", "parameters.l=sin(exp(exp(exp(9))))"], 1,
     r"parameters.l.*overflows"),
    ("nested-power-in-set", BASE, RUN + ["--set", "parameters.l=(((2**1000)**1000)**1000)"],
     1, r"parameters.l.*too large"),
    ("nested-power-in-file", model_text(l='"((10**100)**10)**10"'), RUN, 1,
     r"parameters.l.*(overflows|too large)"),
    ("huge-exponent", model_text(l='"2**(10**9)"'), RUN, 1, r"parameters.l.*exponent"),
    ("deep-nesting", model_text(l='"' + "sin(" * 80 + "1" + ")" * 80 + '"'), RUN, 1,
     r"parameters.l.*nested 8\d deep"),
    ("long-expression", model_text(l='"' + "+".join(["1"] * 1500) + '"'), RUN, 1,
     r"parameters.l.*too long"),
    ("fixed-step-t-end-1e6", model_text(t_end="1e6") + 'integrator = "rk4"\ndt = 1e-3\n',
     RUN, 1, r"simulation.*max_steps"),
    ("fixed-step-dt-1e-300", model_text() + 'integrator = "rk4"\ndt = 1e-300\n', RUN, 1,
     r"simulation.dt.*below the range"),
    ("fixed-step-dt-1e-90", model_text() + 'integrator = "rk4"\ndt = 1e-90\n', RUN, 1,
     r"simulation.*max_steps"),
    ("fixed-step-samples", model_text(t_end="5e3") + 'integrator = "rk4"\ndt = 1e-3\n', RUN,
     1, r"simulation.*max_samples.*output_dt"),
    ("output-dt-tiny", model_text() + "output_dt = 1e-12\n", RUN, 1,
     r"simulation.output_dt.*max_samples"),
    ("step-budget", model_text(t_end="100"), RUN + ["--max-steps", "50"], 3,
     r"max_steps = 50.*Radau"),
    ("wall-time-budget", model_text(t_end="1e4"), RUN + ["--max-wall-time", "0.5"], 3,
     r"max_wall_time"),
    # -- crashes that were "internal error"
    ("nested-toml-arrays", BASE + "[outputs]\nx = " + "[" * 3000 + "]" * 3000 + "\n", RUN,
     1, r"nested"),
    ("nested-inline-tables", BASE + "y = " + "{a = " * 40 + "1" + "}" * 40 + "\n", RUN, 1,
     r"nested"),
    ("huge-integer-literal", model_text(m="1" + "0" * 5000), RUN, 1, r"digits"),
    ("big-integer-literal", model_text(m="1" + "0" * 45), RUN, 1,
     r"parameters.m.*digits"),
    ("drive-log-t", model_text(coordinates='["theta"]\ndrive = "log(t)"'), RUN, 1,
     r"joints\[0\]\.drive.*hinge.*undefined at t=0"),
    ("drive-sqrt-minus-t", model_text(coordinates='["theta"]\ndrive = "sqrt(-t)"'), RUN, 1,
     r"joints\[0\]\.drive.*undefined"),
    # -- silent garbage
    ("full-width-t", BASE, RUN + ["--set", "initial.theta=\uff54"], 1,
     r"initial.theta.*not ASCII.*'t'"),
    ("greek-pi", model_text(theta='"\u03c0/4"'), RUN, 1, r"initial.theta.*write pi"),
    ("full-width-coordinate", model_text(coordinates='["\u03b8"]'), RUN, 1,
     r"joints\[0\].coordinates.*ASCII"),
    ("full-width-parameter", BASE.replace("l = 0.5", '"\uff4c" = 0.5'), RUN, 1,
     r"parameters.*ASCII"),
    ("dt-with-adaptive", BASE, RUN + ["--dt", "0.01"], 0, r"--dt is ignored"),
    ("nan-literal", model_text(m="nan"), RUN, 1, r"parameters.m.*not a finite"),
    ("inf-literal", model_text(l="inf"), RUN, 1, r"parameters.l.*not a finite"),
    # -- unclear messages
    ("mass-1e308", model_text(mass="1e308"), RUN, 1, r"bodies\[0\].mass.*range"),
    ("gravity-1e308", model_text(gravity='[0, -1e308, 0]'), RUN, 1,
     r"model.gravity\[1\].*range"),
    ("parameter-1e200-expr", model_text(l='"1e100*1e100"'), RUN, 1,
     r"parameters.l.*range"),
    ("rtol-zero", model_text() + "rtol = 0\n", RUN, 1, r"simulation.rtol.*> 0"),
    ("atol-negative", BASE, RUN + ["--atol", "-1"], 1, r"atol.*> 0"),
    ("max-step-zero", model_text() + "max_step = 0\n", RUN, 1, r"simulation.max_step.*> 0"),
    ("escape-in-name", model_text(name='"\\u001b[31mred"'), RUN, 1,
     r"model.name.*control characters"),
    ("escape-in-key", BASE.replace("l = 0.5", '"\\u001b[2J" = 0.5'), RUN, 1,
     r"control characters"),
    ("nul-in-text", BASE.replace('name = "bob"', 'name = "b\\u0000b"'), RUN, 1,
     r"control characters"),
    ("unknown-case", BASE, RUN + ["--case", "\x1b[31mred"], 1, r"no case '\\x1b\[31mred'"),
    ("joint-named-pi", BASE.replace('coordinates = ["theta"]\n', "").replace(
        'name = "hinge"', 'name = "pi"').replace("theta = 0.5", "pi = 0.5"), RUN, 1,
     r"joints\[0\].*'pi' is reserved"),
    ("joint-named-lambda", BASE.replace('name = "hinge"', 'name = "lambda"'), RUN, 1,
     r"joints\[0\].name.*Python keyword"),
    ("denormal-mass", model_text(mass="1e-320"), RUN, 1, r"bodies\[0\].mass.*below"),
    ("rtol-with-fixed-step", model_text() + 'integrator = "rk4"\ndt = 0.01\nrtol = 1e-3\n',
     RUN, 0, r"simulation.rtol ignored"),
    ("output-dt-not-multiple", model_text() + 'integrator = "rk4"\ndt = 0.01\n'
     'output_dt = 0.015\n', RUN, 0, r"not a multiple of dt"),
    ("shape-color", BASE.replace('com = ["l", 0, 0]', 'com = ["l", 0, 0]\nshape = { type = '
                                 '"sphere", radius = 0.05, color = "#zzzzzz" }'), RUN, 1,
     r"bodies\[0\].*shape color"),
    ("sweep-out-extension", BASE, ["sweep", "{model}", "--grid", "parameters.l=1:2:2", "--out",
                                   "{tmp}/s.xlsx"], 1, r"--out .*\.csv"),
    ("t-end-flag-huge", BASE, RUN + ["--t-end", "1e300"], 1, r"--t-end 1e300.*range"),
    ("t-end-flag-nan", BASE, RUN + ["--t-end", "nan"], 1, r"--t-end nan.*not a finite"),
    ("max-steps-fraction", BASE, RUN + ["--max-steps", "1.5"], 1, r"whole number"),
    ("output-dt-below-dt", model_text() + 'integrator = "rk4"\ndt = 0.01\noutput_dt = 1e-3\n',
     RUN, 0, r"output_dt.*smaller than dt"),
    ("accuracy-t-end-nan", BASE, ["accuracy", "{model}", "--t-end", "nan"], 1,
     r"--t-end nan.*not a finite"),                     # run's flag, run's message
    ("modes-amplitude-nan", BASE, ["modes", "{model}", "--amplitude", "nan"], 2,
     r"--amplitude: 'nan'"),
    ("sweep-workers-negative", BASE, ["sweep", "{model}", "--grid", "parameters.l=1:2:2",
                                      "--workers", "-3"], 2, r"--workers: '-3' is not >= 1"),
    ("sweep-too-many-members", BASE, ["sweep", "{model}", "--grid", "parameters.l=1:2:99999",
                                      "--grid", "parameters.m=1:2:99999"], 1,
     r"members, more than"),
    ("campbell-too-many-values", BASE, ["campbell", "{model}", "--parameter", "l", "--values",
                                        "1:2:1000000000"], 1, r"more than 100000"),
    ("animate-too-many-frames", BASE, ["animate", "{model}", "--out", "{tmp}/a.gif",
                                       "--speed", "1e-9"], 1, r"frames.*raise the speed"),
]


@pytest.mark.parametrize("case_id, text, argv, code, pattern",
                         FILE_CASES, ids=[c[0] for c in FILE_CASES])
def test_hostile_model_input(case_id, text, argv, code, pattern, tmp_path, capsys):
    got, out, err = in_process(argv, tmp_path, text, capsys)
    assert got == code, (got, err)
    assert "Traceback" not in err and "internal error" not in err
    assert "\x1b" not in err and "\x1b" not in out          # no terminal injection
    assert re.search(pattern, err), err


# id, bytes of the file (or a special), argv, exit code, pattern
RAW_CASES = [
    ("binary-file", b"\x00\x01\x02\xff" * 100, RUN, 1, r"(UTF-8|NUL)"),
    ("nul-byte", BASE.encode() + b"\x00", RUN, 1, r"NUL"),
    ("too-large-file", b"# " + b"x" * 1_100_000 + b"\n", RUN, 1, r"bytes"),
    ("empty-file", b"", RUN, 1, r"t_end|bodies|body|empty|model"),
    ("dev-zero", "/dev/zero", ["run", "/dev/zero"], 1, r"not a regular file"),
    ("directory", "{tmp}", ["run", "{tmp}"], 1, r"directory"),
    ("missing-file", None, ["run", "{tmp}/nope.toml"], 1, r"no such file"),
]


@pytest.mark.parametrize("case_id, data, argv, code, pattern", RAW_CASES,
                         ids=[c[0] for c in RAW_CASES])
def test_hostile_files(case_id, data, argv, code, pattern, tmp_path, capsys):
    if isinstance(data, bytes):
        (tmp_path / "model.toml").write_bytes(data)
    got, out, err = in_process(argv, tmp_path, None, capsys)
    assert got == code, (got, err)
    assert re.search(pattern, err), err


def test_a_fifo_is_refused_not_waited_on(tmp_path):
    fifo = tmp_path / "model.toml"
    os.mkfifo(fifo)
    proc = run_cli(["run", str(fifo)], tmp_path, timeout=60)
    assert proc.returncode == 1 and "not a regular file" in proc.stderr


# -- the Python interface: id, call, exception, pattern
def _pendulum():
    s = mb.System("p", gravity=(0, -9.81, 0))
    s.add_body("bob", mass=1.0, com=(0.5, 0, 0))
    s.add_joint("hinge", "revolute", "ground", "bob", axis="z")
    return s


def _ball():
    s = mb.System("ball")
    s.add_body("bob", mass=1.0, com=(0.5, 0, 0), inertia=(0.1, 0.1, 0.1))
    s.add_joint("ball", "spherical", "ground", "bob")
    return s


API_CASES = [
    ("t-eval-nan-unsorted", lambda: mb.simulate(_pendulum(), 1.0, t_eval=[0.5, np.nan, 0.2]),
     mb.ModelError, r"t_eval"),
    ("rtol-zero", lambda: mb.simulate(_pendulum(), 1.0, rtol=0), mb.ModelError, r"rtol"),
    ("max-step-zero", lambda: mb.simulate(_pendulum(), 1.0, max_step=0), mb.ModelError,
     r"max_step"),
    ("dt-1e-300", lambda: mb.simulate(_pendulum(), 1.0, integrator="rk4", dt=1e-300),
     mb.ModelError, r"max_steps"),
    ("dt-nan", lambda: mb.simulate(_pendulum(), 1.0, integrator="rk4", dt=float("nan")),
     mb.ModelError, r"dt > 0"),
    ("samples", lambda: mb.simulate(_pendulum(), 4e3, integrator="euler", dt=1e-3),
     mb.ModelError, r"max_samples"),
    ("budget-bad", lambda: mb.simulate(_pendulum(), 1.0, max_steps=0), mb.ModelError,
     r"max_steps must be a positive whole number"),
    ("nan-q-spherical", lambda: _ball().compile().forward_dynamics(
        np.array([np.nan, 0, 0, 0]), np.zeros(3)), mb.NonFiniteError, r"ball_qw"),
    ("nan-q-revolute", lambda: _pendulum().compile().forward_dynamics(
        np.array([np.nan]), np.zeros(1)), mb.NonFiniteError, r"non-finite values in hinge"),
    ("nan-mass-matrix", lambda: _ball().compile().mass_matrix(np.array([np.nan, 0, 0, 0])),
     mb.NonFiniteError, r"non-finite"),
    ("zero-quaternion", lambda: mb.simulate(_ball(), 1.0, q0=np.zeros(4)),
     mb.NonFiniteError, r"no direction"),
    ("drive-log-t", lambda: mb.simulate(_drive_system(_log_t()), 1.0),
     mb.SimulationError, r"joint 'j'.*drive.*undefined at t=0"),
    ("nan-event", lambda: mb.simulate(_pendulum(), 2.0, q0={"hinge": 0.1},
                                      events=[mb.Event("e", "sqrt(hinge) - 10")]),
     mb.SimulationError, r"event 'e'.*not a finite number"),
    ("full-width-coordinate", lambda: _second_link(["\uff54"]), mb.ModelError, r"ASCII"),
    ("escape-frame-name", lambda: _pendulum().add_body("\x1b[2J"), mb.ModelError,
     r"control characters"),
    ("fullwidth-parameter", lambda: mb.System("s", parameters={"\uff4d": 1.0}),
     mb.ModelError, r"ASCII"),
    ("gravity-text", lambda: mb.System("s", gravity="down"), mb.ModelError, r"gravity"),
    ("q0-text", lambda: mb.simulate(_pendulum(), 1.0, q0={"hinge": "abc"}), mb.ModelError,
     r"coordinates must be numbers"),
    ("q-text", lambda: _pendulum().compile().forward_dynamics("abc", np.zeros(1)),
     mb.ModelError, r"arrays of numbers"),
    ("t-end-text", lambda: mb.simulate(_pendulum(), "soon"), mb.ModelError, r"t_end"),
    ("t-eval-empty", lambda: mb.simulate(_pendulum(), 1.0, t_eval=[]), mb.ModelError,
     r"t_eval is empty"),
    ("events-text", lambda: mb.simulate(_pendulum(), 1.0, events="hinge > 1"),
     mb.ModelError, r"list of mb.Event"),
    ("event-direction", lambda: mb.Event("e", "hinge > 1", direction=5), mb.ModelError,
     r"direction must be"),
    ("q0-wrong-length", lambda: mb.simulate(_pendulum(), 1.0, q0=np.zeros(5)),
     mb.ModelError, r"q0: expected 1"),
    ("u0-inf", lambda: mb.simulate(_pendulum(), 1.0, u0=[np.inf]), mb.ModelError,
     r"Inf in hinge_dot"),
    ("effects-number", lambda: _pendulum().compile(effects=5), mb.ModelError,
     r"give effects as"),
    ("zero-quaternion-matrix", lambda: mb.rotations.to_matrix([0, 0, 0, 0]), mb.ModelError,
     r"not a quaternion"),
    ("negative-mass-helper", lambda: mb.inertia.sphere(-1.0, 0.1), mb.ModelError,
     r"sphere: mass"),
    ("coordinate-named-t", lambda: _second_link(["t"]), mb.ModelError, r"'t' is reserved"),
    ("speed-same-as-coordinate", lambda: _second_link(["a"], speeds=["a"]), mb.ModelError,
     r"more than one"),
    ("drive-with-kink", lambda: _drive_system(abs(mb.t - 0.5)), mb.ModelError,
     r"kink or a jump"),
    ("load-model-number", lambda: mb.load_model(123), mb.ModelError, r"path"),
    ("load-model-overrides-text", lambda: mb.load_model(
        os.path.join(ROOT, "models", "top.toml"), overrides="parameters.Mz=1"),
     mb.ModelError, r"overrides must be a mapping"),
    ("csv-unwritable", lambda: mb.simulate(_pendulum(), 0.1).to_csv("/proc/nope/x.csv"),
     OSError, r"cannot write /proc/nope/x.csv"),
]


def _second_link(coordinates, speeds=None):
    s = _pendulum()
    s.add_body("bob2", mass=1.0, com=(0.5, 0, 0))
    s.add_joint("j2", "revolute", "bob", "bob2", axis="z", coordinates=coordinates,
                speeds=speeds)


def _drive_system(expr):
    s = mb.System("d")
    s.add_body("b", mass=1.0, com=(1, 0, 0))
    s.add_joint("j", "revolute", "ground", "b", axis="z", drive=expr)
    return s


def _log_t():
    import sympy
    return sympy.log(mb.t)



@pytest.mark.parametrize("case_id, call, exc, pattern", API_CASES,
                         ids=[c[0] for c in API_CASES])
def test_hostile_api_input(case_id, call, exc, pattern):
    with pytest.raises(exc, match=pattern):
        call()


# -- budgets stop a run and keep what it computed
def test_a_stiff_model_under_an_explicit_integrator_stops_at_the_step_budget():
    s = mb.System("stiff", gravity=(0, 0, 0))
    s.add_body("b", mass=1e-6, com=(0, 0, 0))
    s.add_joint("x", "prismatic", "ground", "b", axis="x")
    s.add_force("spring", "joint-spring-damper", joint="x", stiffness=1e9)
    with pytest.raises(mb.SimulationError, match="max_steps = 2000.*Radau") as info:
        mb.simulate(s, 10.0, q0={"x": 0.01}, max_steps=2000)
    assert len(info.value.result.t) > 100 and info.value.result.t[-1] < 10.0


def test_a_run_that_cannot_finish_at_its_pace_stops_early_with_the_projection():
    s = mb.System("stiff", gravity=(0, 0, 0))
    s.add_body("b", mass=1e-6, com=(0, 0, 0))
    s.add_joint("x", "prismatic", "ground", "b", axis="x")
    s.add_force("spring", "joint-spring-damper", joint="x", stiffness=1e9)
    with pytest.raises(mb.SimulationError, match=r"would need about .* steps.*Radau") as info:
        mb.simulate(s, 1e4, q0={"x": 0.01}, max_steps=100_000)
    assert len(info.value.result.t) <= 2000      # stopped at the first projection


def test_a_burst_of_tiny_steps_does_not_trip_the_projection():
    model = mb.load_model(os.path.join(ROOT, "models", "bouncing_ball.toml"))
    res = model.simulate(max_steps=200_000)       # impacts: bursts of tiny steps
    assert res.stats["status"] == "ok"
    assert res.t[-1] == pytest.approx(model.settings["t_end"])


def test_decimated_fixed_step_runs_keep_the_integrators_own_states():
    s = _pendulum()
    full = mb.simulate(s, 1.0, q0={"hinge": 0.3}, integrator="rk4", dt=0.01)
    thin = mb.simulate(s, 1.0, q0={"hinge": 0.3}, integrator="rk4", dt=0.01, decimate=7)
    assert np.allclose(thin.t[:-1], full.t[::7][:len(thin.t) - 1])
    np.testing.assert_array_equal(thin.q[:-1], full.q[::7][:len(thin.t) - 1])
    assert thin.t[-1] == full.t[-1] and np.array_equal(thin.q[-1], full.q[-1])


def test_fixed_step_t_eval_is_interpolated_stretch_by_stretch():
    """10,000 steps: five compiled stretches; the output times in the steps that straddle
    two stretches take the derivative at the join from the next stretch's first step."""
    from mbdyn.integrate.samples import hermite
    s = _pendulum()
    model = s.compile()
    full = mb.simulate(model, 1.0, q0={"hinge": 0.3}, integrator="rk4", dt=1e-4)
    te = np.concatenate([np.linspace(0, 1.0, 37), [0.19995, 0.20005, 0.39999]])
    te.sort()
    r = mb.simulate(model, 1.0, q0={"hinge": 0.3}, integrator="rk4", dt=1e-4, t_eval=te)
    y = np.hstack([full.q, full.u])
    i = np.clip(np.searchsorted(full.t, te), 1, len(full.t) - 1)
    f0 = np.array([model.state_derivative(full.t[k], y[k]) for k in i - 1])
    f1 = np.array([model.state_derivative(full.t[k], y[k]) for k in i])
    h = (full.t[i] - full.t[i - 1])[:, None]
    want = hermite((te - full.t[i - 1])[:, None] / h, h, y[i - 1], f0, y[i], f1)
    np.testing.assert_allclose(r.q[1:, 0], want[1:, 0], rtol=0, atol=1e-14)


# -- results: never torn, never outside --out
def _write_twice(tmp_path, fail_at):
    """Write a results pair, then a second one interrupted at ``os.replace`` call
    ``fail_at``; returns the directory."""
    from mbdyn.io import load_model, write_results
    from mbdyn.io import results as results_module
    path = tmp_path / "model.toml"
    path.write_text(BASE)
    scene = load_model(path)
    first = scene.simulate()
    out = tmp_path / "out"
    write_results(out, scene, first)
    second = scene.simulate(t_end=0.4)
    calls = []
    real = os.replace

    def interrupted(a, b):
        calls.append(b)
        if len(calls) == fail_at:
            raise KeyboardInterrupt
        return real(a, b)
    results_module.os.replace = interrupted
    try:
        with pytest.raises(KeyboardInterrupt):
            write_results(out, scene, second)
    finally:
        results_module.os.replace = real
    return out


@pytest.mark.parametrize("fail_at", [1, 2])
def test_an_interrupted_write_leaves_no_torn_pair_and_no_temporary(tmp_path, fail_at):
    out = _write_twice(tmp_path, fail_at)
    names = sorted(os.listdir(out))
    assert not [n for n in names if n.endswith(".tmp")], names
    if "model.json" in names:
        assert verify_results(out / "model.json")
    else:
        assert names == ["model.csv"]       # a CSV alone: the JSON comes last


def test_a_case_name_cannot_write_outside_out(tmp_path, capsys):
    text = BASE + '\n[cases."../../evil"]\ninitial = { theta = 0.1 }\n'
    code, out, err = in_process(["run", "{model}", "--case", "../../evil", "--out",
                                 "{tmp}/out"], tmp_path, text, capsys)
    assert code == 0, err
    assert sorted(os.listdir(tmp_path / "out")) == ["model_.._.._evil.csv",
                                                    "model_.._.._evil.json"]
    assert sorted(os.listdir(tmp_path)) == ["model.toml", "out"]


def test_stale_temporaries_of_a_killed_run_are_removed(tmp_path, capsys):
    out = tmp_path / "out"
    out.mkdir()
    dead = subprocess.Popen([sys.executable, "-c", "pass"])
    dead.wait()
    stale = out / f".model.csv.{dead.pid}.abc.tmp"
    stale.write_text("half")
    code, _, err = in_process(["run", "{model}", "--out", str(out)], tmp_path, BASE, capsys)
    assert code == 0, err
    assert not stale.exists()
    assert verify_results(out / "model.json")


def test_sigterm_during_a_run_with_out_leaves_no_temporary_and_no_torn_pair(tmp_path):
    text = model_text(t_end="40") + "output_dt = 1e-4\n"
    (tmp_path / "model.toml").write_text(text)
    env = dict(os.environ, PYTHONPATH=ROOT)
    out = tmp_path / "out"
    for delay in (0.5, 3.0, 6.0):
        proc = subprocess.Popen([sys.executable, "-m", "mbdyn", "run", "model.toml", "--out",
                                 str(out)], cwd=tmp_path, env=env, stderr=subprocess.PIPE,
                                text=True)
        time.sleep(delay)
        proc.send_signal(signal.SIGTERM)
        _, err = proc.communicate(timeout=120)
        # -15: killed while Python was still importing, before mbdyn set its handler
        assert proc.returncode in (0, 143, -signal.SIGTERM), err
        assert "Traceback" not in err
        if out.exists():
            names = os.listdir(out)
            assert not [n for n in names if n.endswith(".tmp")], names
            if "model.json" in names:
                assert verify_results(out / "model.json")


def test_a_reader_that_closes_the_pipe_gets_no_broken_pipe_message(tmp_path):
    env = dict(os.environ, PYTHONPATH=ROOT)
    proc = subprocess.Popen([sys.executable, "-m", "mbdyn", "eom",
                             os.path.join(ROOT, "models", "top.toml"), "--steps"],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, env=env)
    proc.stdout.read(10)
    proc.stdout.close()
    err = proc.stderr.read().decode()
    proc.wait(timeout=120)
    assert "Broken pipe" not in err and "Traceback" not in err, err
    assert proc.returncode in (0, 141)


def test_the_json_names_the_csv_it_describes(tmp_path, capsys):
    code, _, err = in_process(["run", "{model}", "--out", "{tmp}/o"], tmp_path, BASE, capsys)
    assert code == 0, err
    meta = json.loads((tmp_path / "o" / "model.json").read_text())
    data = (tmp_path / "o" / "model.csv").read_bytes()
    assert meta["csv_bytes"] == len(data) and meta["samples"] == data.count(b"\n") - 1
    assert verify_results(tmp_path / "o" / "model.json")


# --- issue 29: text that reaches a page or a picture is escaped for where it lands --------

#: each payload would run script (set a flag, change the title, open a dialog) if it were
#: read as markup or script rather than text; all are legal labels in Python
INJECTIONS = [
    "</script><script>document.title='PWNED';window.__pwned=1</script>",
    "<img src=x onerror=\"window.__pwned=2;document.title='PWNED'\">",
    "<!--<script>window.__pwned=3</script>",
    "\u2028</SCRIPT ><svg onload=alert(1)>",
    "{plot_id}<a href=\"javascript:alert(4)\">link</a> & \"quotes\" 'single'",
]


def _hostile_named_result(t_end=0.2):
    s = mb.System(INJECTIONS[0], gravity=(0, -9.81, 0))
    parent = "ground"
    for k, name in enumerate(INJECTIONS):
        s.add_body(name, mass=1.0, com=(0, -0.3, 0))
        s.add_joint(f"j{k}", "revolute", parent=parent, child=name, axis="z",
                    position=(0, -0.3, 0) if k else (0, 0, 0))
        parent = name
    return mb.simulate(s.compile(), t_end=t_end, q0={"j0": 1.0}, integrator="RK45")


def _nothing_ran(page, log, title):
    assert page.evaluate("window.__pwned === undefined")
    assert page.evaluate("document.title") == title
    assert log["dialogs"] == [] and log["outside"] == []
    assert page.evaluate("document.querySelectorAll('script').length") == \
        page.evaluate("document.querySelectorAll('script').length")  # page still parses
    assert not [e for e in log["errors"] if "PWNED" in e or "pwned" in e]


def test_hostile_names_run_nothing_in_the_html_view(tmp_path):
    import browser
    result = _hostile_named_result()
    out = tmp_path / "view.html"
    result.animate(out, fps=10)
    with browser.page() as (page, log):
        page.goto(out.as_uri())
        page.wait_for_function("window.mbdynView !== undefined", timeout=30000)
        title = page.evaluate("document.title")
        assert "PWNED" not in title
        # the names arrive as the literal text the user typed, and are shown as text
        assert page.evaluate("window.mbdynView.names") == INJECTIONS
        # shown as text: the title, and each body's label beside its marker
        assert page.evaluate("document.getElementById('mbdyn-title').textContent") \
            == INJECTIONS[0]
        assert page.evaluate("Array.from(document.querySelectorAll('.mbdyn-label'), "
                             "e => e.textContent)") == INJECTIONS
        assert page.evaluate("Array.from(document.querySelectorAll('.mbdyn-label'), "
                             "e => e.children.length)") == [0] * len(INJECTIONS)
        page.evaluate("window.mbdynView.goto(1)")
        page.wait_for_timeout(300)
        _nothing_ran(page, log, title)
        assert page.evaluate("document.querySelectorAll('img, iframe, a[href^=javascript]')"
                             ".length") == 0
        assert log["errors"] == []


def test_hostile_names_run_nothing_in_an_svg_picture(tmp_path):
    pytest.importorskip("matplotlib")
    import browser
    result = _hostile_named_result()
    out = tmp_path / "plot.svg"
    result.plot(out=out)
    text = out.read_text()
    assert "<script" not in text.lower() and "onerror" not in text.lower() or \
        "&lt;script" in text.lower() or "<script" not in text.lower()
    with browser.page() as (page, log):
        page.goto(out.as_uri())
        page.wait_for_timeout(300)
        _nothing_ran(page, log, page.evaluate("document.title"))
        assert page.evaluate("document.querySelectorAll('script, img, foreignObject')"
                             ".length") == 0
