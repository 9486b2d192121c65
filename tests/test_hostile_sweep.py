"""Hostile input to sweeps and to every output mbdyn writes (issue 29), table-driven where
it fits: Dask scheduler addresses that hang or lie, resume files that are not tables,
Python arguments of the wrong kind, torn results pairs, spreadsheet formulas, symbolic
links at an output path, two sweeps on one table, outputs checked before the work,
temporary folders, and long sweeps announced.  Every case runs under a time limit (a
subprocess's ``timeout``, or ``time_limit`` below in this process) and none may print a
traceback or exit 70.
"""
from __future__ import annotations

import json
import os
import re
import signal
import subprocess
import sys
import textwrap

import pytest

import mbdyn as mb
from mbdyn.cli import main
from mbdyn.io.results import verify_results

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(ROOT, "tests"))
from test_hostile import BASE  # noqa: E402  (the small pendulum model of test_hostile)

#: seconds a test in this process may take (the slowest compiles numba's kernels first)
TIME_LIMIT = 240


class TimeLimit(Exception):
    """A test ran past ``TIME_LIMIT``."""


@pytest.fixture(autouse=True)
def time_limit():
    """Fail a test that runs past ``TIME_LIMIT`` seconds (SIGALRM in the main thread)."""
    def expired(signum, frame):
        raise TimeLimit(f"the test ran past {TIME_LIMIT} s")
    previous = signal.signal(signal.SIGALRM, expired)
    signal.setitimer(signal.ITIMER_REAL, TIME_LIMIT)
    try:
        yield
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, previous)


def env():
    """The environment of a subprocess: this checkout's mbdyn, no debug tracebacks."""
    e = dict(os.environ, PYTHONPATH=ROOT)
    e.pop("MBDYN_DEBUG", None)
    return e


def run_main(argv, tmp_path, capsys, text=BASE):
    """``mbdyn ARGV`` in this process; ``{model}`` is a file holding ``text``, ``{tmp}`` the
    test's folder.  Returns ``(code, out, err)``; no traceback, no internal error."""
    path = tmp_path / "model.toml"
    if text is not None and not path.exists():
        path.write_text(text, encoding="utf-8")
    argv = [a.replace("{model}", str(path)).replace("{tmp}", str(tmp_path)) for a in argv]
    code = main(argv)
    out, err = capsys.readouterr()
    assert "Traceback" not in err and "internal error" not in err, err
    assert code != 70, err
    return code, out, err


SWEEP = ["sweep", "{model}", "--grid", "parameters.l=0.4:0.5:2"]


# --- issue 29, item 6: a symbolic link at an output path is replaced, never written through

#: id, command line (``{tmp}/LINK`` is made a symbolic link to a file outside), the link
LINKED_OUTPUTS = [
    ("run-out", ["run", "{model}", "--out", "{tmp}/out"], "out/model.csv"),
    ("run-out-json", ["run", "{model}", "--out", "{tmp}/out"], "out/model.json"),
    ("run-plot", ["run", "{model}", "--plot", "{tmp}/p.png"], "p.png"),
    ("plot", ["plot", "{model}", "--out", "{tmp}/p.png"], "p.png"),
    ("animate", ["animate", "{model}", "--out", "{tmp}/a.gif", "--fps", "10"], "a.gif"),
    ("sweep-out", SWEEP + ["--out", "{tmp}/s.csv"], "s.csv"),
    ("sweep-plot-file", SWEEP + ["--plot", "t_final", "--plot-file", "{tmp}/s.png"],
     "s.png"),
    ("campbell-plot", ["campbell", "{model}", "--parameter", "l", "--values", "0.4:0.5:2",
                       "--not-spin", "--plot", "{tmp}/c.png"], "c.png"),
]


@pytest.mark.parametrize("case_id, argv, link", LINKED_OUTPUTS,
                         ids=[c[0] for c in LINKED_OUTPUTS])
def test_a_link_at_an_output_is_replaced_not_written_through(case_id, argv, link, tmp_path,
                                                             capsys):
    pytest.importorskip("matplotlib")
    outside = tmp_path / "outside"
    outside.mkdir()
    victim = outside / "victim.txt"
    victim.write_text("precious\n")
    target = tmp_path / link
    target.parent.mkdir(exist_ok=True)
    target.symlink_to(victim)
    code, out, err = run_main(argv, tmp_path, capsys)
    assert code == 0, err
    assert victim.read_text() == "precious\n"                 # never written through
    assert not target.is_symlink() and target.is_file() and target.stat().st_size > 0
    assert not [n for n in os.listdir(target.parent) if ".tmp" in n]


#: id, command line whose output path is an existing folder; the message must name it
FOLDER_OUTPUTS = [
    ("run-out-csv", ["run", "{model}", "--out", "{tmp}/out"], "out/model.csv"),
    ("plot", ["plot", "{model}", "--out", "{tmp}/p.png"], "p.png"),
    ("animate", ["animate", "{model}", "--out", "{tmp}/a.gif"], "a.gif"),
    ("sweep-out", SWEEP + ["--out", "{tmp}/s.csv"], "s.csv"),
    ("sweep-plot-file", SWEEP + ["--plot", "t_final", "--plot-file", "{tmp}/s.png"],
     "s.png"),
    ("campbell-plot", ["campbell", "{model}", "--parameter", "l", "--values", "0.4:0.5:2",
                       "--not-spin", "--plot", "{tmp}/c.png"], "c.png"),
]


@pytest.mark.parametrize("case_id, argv, folder", FOLDER_OUTPUTS,
                         ids=[c[0] for c in FOLDER_OUTPUTS])
def test_an_output_that_is_a_folder_is_named_not_its_temporary(case_id, argv, folder,
                                                               tmp_path, capsys):
    (tmp_path / folder).mkdir(parents=True)
    code, out, err = run_main(argv, tmp_path, capsys)
    assert code == 1, err
    assert folder.split("/")[-1] in err and ".tmp" not in err, err
    assert len(err.strip().splitlines()) == 1, err
    assert not [n for n in os.listdir(tmp_path / folder.split("/")[0]) if ".tmp" in n]


# --- issue 29, item 4: a results pair is all or nothing under SIGINT and SIGTERM

WRITE_TWICE = textwrap.dedent("""\
    import signal, sys, time
    from mbdyn.io import load_model, write_results
    from mbdyn.io import results
    if sys.argv[3] == "mbdyn":                       # the handler the mbdyn command sets
        from mbdyn.cli import _on_sigterm
        signal.signal(signal.SIGTERM, _on_sigterm)
    scene = load_model(sys.argv[1])
    write_results(sys.argv[2], scene, scene.simulate())          # the old pair
    second = scene.simulate(t_end=0.4)

    def pause():                                     # the test's hook: the window
        print("window", flush=True)
        time.sleep(3)
    results._between_renames = pause
    write_results(sys.argv[2], scene, second)
    print("after", flush=True)
""")


@pytest.mark.parametrize("sig, handler", [(signal.SIGTERM, "default"),
                                          (signal.SIGTERM, "mbdyn"),
                                          (signal.SIGINT, "default")])
def test_a_signal_between_the_renames_of_a_pair_acts_after_both(sig, handler, tmp_path):
    (tmp_path / "model.toml").write_text(BASE)
    script = tmp_path / "write_twice.py"
    script.write_text(WRITE_TWICE)
    out = tmp_path / "out"
    proc = subprocess.Popen([sys.executable, str(script), str(tmp_path / "model.toml"),
                             str(out), handler], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True, env=env(), cwd=tmp_path)
    try:
        assert proc.stdout.readline() == "window\n"
        proc.send_signal(sig)
        rest, err = proc.communicate(timeout=120)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
    assert "after" not in rest                      # the signal did stop the program ...
    assert proc.returncode != 0
    names = sorted(os.listdir(out))
    assert names == ["model.csv", "model.json"], names        # ... after the whole pair
    assert verify_results(out / "model.json")
    meta = json.loads((out / "model.json").read_text())
    assert meta["t_final"] == pytest.approx(0.4)               # the new pair


# --- issue 29, item 9: a sweep leaves no temporary folder, however it ends

def _leftovers(folder):
    """What mbdyn left in the temporary folder ``folder``."""
    return [n for n in os.listdir(folder) if n.startswith("mbdyn")]


@pytest.mark.parametrize("scheduler", ["serial", "processes"])
def test_a_finished_sweep_leaves_no_temporary_folder(scheduler, tmp_path):
    (tmp_path / "model.toml").write_text(BASE)
    tmpdir = tmp_path / "tmpdir"
    tmpdir.mkdir()
    proc = subprocess.run([sys.executable, "-m", "mbdyn", "sweep", "model.toml", "--grid",
                           "parameters.l=0.4:0.5:2", "--scheduler", scheduler, "--workers",
                           "1", "--out", "s.csv"], capture_output=True, text=True,
                          timeout=300, cwd=tmp_path, env=dict(env(), TMPDIR=str(tmpdir)))
    assert proc.returncode == 0, proc.stderr
    assert _leftovers(tmpdir) == []


def test_a_sweep_that_fails_leaves_no_temporary_folder(tmp_path, monkeypatch):
    import tempfile
    from mbdyn.analysis.sweep import run_member, sweep

    class Breaks:
        """Runs the first member, then fails (a lost worker, a bug)."""
        name = "breaks"

        def map_unordered(self, fn, tasks):
            for i, task in enumerate(tasks):
                if i:
                    raise RuntimeError("the scheduler broke")
                yield i, fn(task)

        def close(self):
            pass
    monkeypatch.setattr(tempfile, "tempdir", str(tmp_path))
    (tmp_path / "model.toml").write_text(BASE)
    with pytest.raises(RuntimeError, match="broke"):
        sweep(str(tmp_path / "model.toml"), {"parameters.l": [0.4, 0.5]}, scheduler=Breaks())
    assert _leftovers(tmp_path) == []
    assert run_member                      # the worker function itself writes nothing either


def test_an_interrupted_sweep_leaves_no_temporary_folder(tmp_path):
    (tmp_path / "model.toml").write_text(BASE)
    tmpdir = tmp_path / "tmpdir"
    tmpdir.mkdir()
    table = tmp_path / "s.csv"
    proc = subprocess.Popen([sys.executable, "-m", "mbdyn", "sweep", "model.toml", "--grid",
                             "parameters.l=0.4:0.5:400", "--out", str(table)],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            cwd=tmp_path, env=dict(env(), TMPDIR=str(tmpdir)))
    try:
        import time
        deadline = time.monotonic() + 200
        while time.monotonic() < deadline and proc.poll() is None:
            if table.exists() and len(table.read_text().splitlines()) >= 4:   # 2 members
                break
            time.sleep(0.05)
        assert proc.poll() is None, "the sweep ended before it could be interrupted"
        proc.send_signal(signal.SIGINT)
        out, err = proc.communicate(timeout=60)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
    assert proc.returncode == 130, err
    assert "Traceback" not in err
    assert _leftovers(tmpdir) == []
