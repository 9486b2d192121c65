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


def _default_sigint():
    """Run in the child before it starts: SIGINT back to its default action.  A suite
    started in the background by a shell without job control inherits SIGINT ignored,
    and a Python started with SIGINT ignored keeps ignoring it (no KeyboardInterrupt),
    so the interruptions below would stop nothing."""
    signal.signal(signal.SIGINT, signal.SIG_DFL)


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
                            stderr=subprocess.PIPE, text=True, env=env(), cwd=tmp_path,
                            preexec_fn=_default_sigint)
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
                            cwd=tmp_path, env=dict(env(), TMPDIR=str(tmpdir)),
                            preexec_fn=_default_sigint)
    try:
        import time
        deadline = time.monotonic() + 200
        while time.monotonic() < deadline and proc.poll() is None:
            if table.exists() and len(table.read_text().splitlines()) >= 3:   # 2 members
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


# --- issue 29, item 3: the Python call refuses arguments of the wrong kind, naming them

class Refuse:
    """A scheduler that fails the test if any member is sent to it."""
    name = "refuse"

    def map_unordered(self, fn, tasks):
        raise AssertionError("work started")

    def close(self):
        pass


GRID = {"parameters.l": [0.4, 0.5]}

#: id, keywords of ``sweep`` (model, overrides and scheduler have defaults), pattern
SWEEP_API_CASES = [
    ("scheduler-number", dict(scheduler=42), r"scheduler=42: not a scheduler"),
    ("scheduler-object", dict(scheduler=object()), r"not a scheduler.*map_unordered"),
    ("scheduler-unknown", dict(scheduler="threads"), r"unknown scheduler 'threads'"),
    ("workers-negative", dict(workers=-1), r"workers=-1: give a whole number >= 1"),
    ("workers-fraction", dict(workers=1.5), r"workers=1.5"),
    ("workers-bool", dict(workers=True), r"workers=True"),
    ("batch-size-negative", dict(batched=True, batch_size=-1), r"batch_size=-1"),
    ("batch-size-zero", dict(batched=True, batch_size=0), r"batch_size=0"),
    ("members-not-tables", dict(overrides=[1, 2]), r"overrides\[0\] is int 1, not a member"),
    ("members-text", dict(overrides="parameters.l=1"), r"overrides must be a grid"),
    ("members-number", dict(overrides=5), r"overrides must be a grid"),
    ("members-other-paths", dict(overrides=[{"parameters.l": 1}, {"parameters.m": 1}]),
     r"overrides\[1\] sets parameters.m but overrides\[0\] sets parameters.l"),
    ("grid-path-number", dict(overrides={1: [1.0]}), r"grid path 1 \(int\)"),
    ("quantities-text", dict(quantities="final"), r"quantities='final': give a list"),
    ("quantities-numbers", dict(quantities=[1, 2]), r"quantities=\[1, 2\]"),
    ("cases-text", dict(cases="a"), r"cases='a': give a list of case names"),
    ("fixed-list", dict(fixed=["simulation.t_end=1"]), r"fixed=\['simulation.t_end=1'\]"),
    ("fixed-path-number", dict(fixed={1: 2}), r"fixed path 1"),
    ("out-number", dict(out=5), r"out=5: give the path"),
    ("out-extension", dict(out="t.txt"), r"out='t.txt'.*\.csv"),
    ("resume-without-out", dict(resume=True), r"resume=True needs out="),
    ("model-number", dict(model=42), r"model must be the path of a model file"),
    ("model-none", dict(model=None), r"model must be the path"),
    ("require-columns-text", dict(require_columns="t_final"), r"require_columns="),
    ("scheduler-timeout-negative", dict(scheduler_timeout=-1), r"scheduler_timeout=-1"),
    ("scheduler-timeout-nan", dict(scheduler_timeout=float("nan")), r"scheduler_timeout=nan"),
    ("address-no-port", dict(scheduler="tcp://"), r"scheduler 'tcp://': not an address"),
    ("address-port-text", dict(scheduler="tcp://127.0.0.1:abc"), r"the port 'abc'"),
]


@pytest.mark.parametrize("case_id, kwargs, pattern", SWEEP_API_CASES,
                         ids=[c[0] for c in SWEEP_API_CASES])
def test_hostile_sweep_arguments(case_id, kwargs, pattern, tmp_path, monkeypatch):
    from mbdyn.analysis.sweep import sweep
    monkeypatch.chdir(tmp_path)
    (tmp_path / "model.toml").write_text(BASE)
    kwargs = dict(kwargs)
    model = kwargs.pop("model", str(tmp_path / "model.toml"))
    overrides = kwargs.pop("overrides", GRID)
    kwargs.setdefault("scheduler", Refuse())
    with pytest.raises(mb.ModelError, match=pattern):
        sweep(model, overrides, **kwargs)
    assert sorted(os.listdir(tmp_path)) == ["model.toml"]          # nothing written


# --- issue 29, item 8: every output is checked before any work

#: id, extra sweep options, pattern (the option and what to change)
SWEEP_OUTPUT_CASES = [
    ("plot-file-txt", ["--plot", "t_final", "--plot-file", "{tmp}/x.txt"],
     r"--plot-file .*x.txt: unknown picture format '.txt'; use one of .png"),
    ("plot-file-no-folder", ["--plot", "t_final", "--plot-file", "{tmp}/no/x.png"],
     r"--plot-file .*x.png: the folder .*no does not exist"),
    ("plot-file-folder", ["--plot", "t_final", "--plot-file", "{tmp}"],
     r"--plot-file .*: unknown picture format"),
    ("plot-beside-out-bad-column", ["--out", "{tmp}/s.csv", "--plot", "nope"],
     r"nope: not a column"),
    ("out-folder", ["--out", "{tmp}/d.csv"], r"--out .*d.csv: is a folder"),
    ("parquet-folder", ["--out", "{tmp}/d.parquet"], r"d.parquet: is a folder"),
]


@pytest.mark.parametrize("case_id, extra, pattern", SWEEP_OUTPUT_CASES,
                         ids=[c[0] for c in SWEEP_OUTPUT_CASES])
def test_sweep_outputs_are_checked_before_any_work(case_id, extra, pattern, tmp_path, capsys,
                                                   monkeypatch):
    import mbdyn.analysis.sweep as sw
    monkeypatch.setattr(sw, "make_scheduler", lambda *a: Refuse())   # no member may run
    (tmp_path / "d.csv").mkdir()
    (tmp_path / "d.parquet").mkdir()
    code, out, err = run_main(SWEEP + extra, tmp_path, capsys)
    assert code == 1, err
    assert re.search(pattern, err), err
    assert not (tmp_path / "s.csv").exists()


def test_plot_sweep_checks_its_path_before_drawing(tmp_path):
    pytest.importorskip("matplotlib")
    from mbdyn.analysis.sweep import SweepResult
    from mbdyn.viz.sweep_plots import plot_sweep
    result = SweepResult(["member", "parameters.l", "t_final"],
                         [{"member": 0, "parameters.l": 0.4, "t_final": 0.2}], None, {})
    with pytest.raises(mb.ModelError, match=r"x.txt: unknown picture format '.txt'"):
        plot_sweep(result, "t_final", tmp_path / "x.txt")


# --- issue 29, item 7: two sweeps on one table: the second is refused, not a silent loss

def _start_sweep(tmp_path, table, members=400, extra=()):
    """A sweep in a subprocess writing ``table``; returns once it has written 2 rows."""
    import time
    proc = subprocess.Popen([sys.executable, "-m", "mbdyn", "sweep", "model.toml", "--grid",
                             f"parameters.l=0.4:0.5:{members}", "--out", str(table),
                             *extra], stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            text=True, cwd=tmp_path, env=env(), preexec_fn=_default_sigint)
    deadline = time.monotonic() + 200
    while time.monotonic() < deadline and proc.poll() is None:
        if table.exists() and len(table.read_text().splitlines()) >= 3:    # 2 rows
            return proc
        time.sleep(0.05)
    proc.kill()
    proc.wait()
    pytest.fail("the first sweep did not start within 200 s")


def _stop(proc):
    if proc.poll() is None:
        proc.send_signal(signal.SIGINT)
        try:
            proc.communicate(timeout=60)
        except subprocess.TimeoutExpired:
            proc.kill()
            proc.communicate()


def test_a_second_sweep_on_the_same_table_is_refused(tmp_path, capsys):
    (tmp_path / "model.toml").write_text(BASE)
    table = tmp_path / "s.csv"
    # long enough to be still running however fast the machine (it is stopped below)
    first = _start_sweep(tmp_path, table, members=20000)
    try:
        code, out, err = run_main(SWEEP + ["--out", str(table)], tmp_path, capsys)
        assert code == 1, err
        assert re.search(rf"s.csv: another process \(process {first.pid}\) is writing this "
                         r"table now; wait for it to end or write elsewhere", err), err
        assert first.poll() is None                       # the first sweep goes on ...
        before = len(table.read_text().splitlines())
        import time
        time.sleep(1.0)
        assert len(table.read_text().splitlines()) >= before  # ... its table intact
        assert table.read_text().startswith("member,")        # a plain CSV, and
        assert json.loads((tmp_path / "s.json").read_text())["status"] == "running"
    finally:
        _stop(first)
    assert first.returncode == 130
    assert not (tmp_path / ".s.csv.lock").exists()          # released on the way out


def test_the_lock_of_a_killed_sweep_is_taken_over(tmp_path, capsys):
    (tmp_path / "model.toml").write_text(BASE)
    table = tmp_path / "s.csv"
    first = _start_sweep(tmp_path, table)
    first.kill()                                           # SIGKILL: no clean-up at all
    first.communicate(timeout=60)
    assert (tmp_path / ".s.csv.lock").exists()
    code, out, err = run_main(SWEEP + ["--out", str(table)], tmp_path, capsys)
    assert code == 0, err
    assert not (tmp_path / ".s.csv.lock").exists()
    assert len(table.read_text().splitlines()) == 1 + 2


def test_the_table_lock_refuses_a_second_holder_in_one_process(tmp_path):
    from mbdyn.files import TableLock
    with TableLock(tmp_path / "t.csv"):
        with pytest.raises(mb.ModelError, match=rf"process {os.getpid()}\) is writing"):
            TableLock(tmp_path / "t.csv").acquire()
    assert os.listdir(tmp_path) == []
    with TableLock(tmp_path / "t.csv"):                    # free again
        pass


# --- issue 29, item 2: a resume file is input: read bounded, checked, errors name the line

@pytest.fixture(scope="module")
def finished_table(tmp_path_factory):
    """The lines (bytes) of the table of ``SWEEP`` (2 members) as mbdyn writes it (its
    sidecar ``s.json`` is ``FINISHED_SIDECAR[0]``)."""
    from mbdyn.analysis.sweep import sweep
    folder = tmp_path_factory.mktemp("table")
    (folder / "model.toml").write_text(BASE)
    sweep(str(folder / "model.toml"), GRID, out=str(folder / "s.csv"))
    FINISHED_SIDECAR[:] = [(folder / "s.json").read_bytes()]
    return (folder / "s.csv").read_bytes().splitlines(keepends=True)


FINISHED_SIDECAR = []


def _with_sidecar(folder, sidecar=None):
    """The finished table's sidecar written into ``folder`` (or ``sidecar``'s bytes)."""
    (folder / "s.json").write_bytes(FINISHED_SIDECAR[0] if sidecar is None else sidecar)


def _row(lines, k, **cells):
    """``lines`` with cells of row ``k`` (0: the first member) replaced by name."""
    header = lines[0].decode().rstrip("\n").split(",")
    row = lines[1 + k].decode().rstrip("\n").split(",")
    for name, value in cells.items():
        row[header.index(name)] = value
    return lines[:1 + k] + [",".join(row).encode() + b"\n"] + lines[2 + k:]


#: id, the finished table's lines -> the file's bytes, pattern of the message
RESUME_CASES = [
    ("member-text", lambda ls: _row(ls, 0, member="abc"),
     r"s.csv: line 2: member 'abc' is not a member number of this sweep \(0 to 1\)"),
    ("member-fraction", lambda ls: _row(ls, 1, member="1.5"), r"line 3: member '1.5'"),
    ("member-negative", lambda ls: _row(ls, 0, member="-1"), r"line 2: member '-1'"),
    ("member-beyond", lambda ls: _row(ls, 1, member="7"), r"line 3: member '7'"),
    ("member-unicode-digit", lambda ls: _row(ls, 0, member="\u0661"), r"line 2: member"),
    ("member-twice", lambda ls: _row(ls, 1, member="0"), r"line 3: member 0 appears twice"),
    ("status-unknown", lambda ls: _row(ls, 0, status="maybe"),
     r"line 2: status 'maybe' is not one of ok, failed, error"),
    ("quantity-text", lambda ls: _row(ls, 0, t_final="abc"),
     r"line 2: t_final holds 'abc', not a number"),
    ("override-changed", lambda ls: _row(ls, 1, **{"parameters.l": "9.0"}),
     r"line 3: member 1's parameters.l is '9.0', the sweep's is '0.5'"),
    ("cells-missing", lambda ls: ls[:1] + [b"0,0.4,ok\n"] + ls[2:],
     r"line 2: has 3 cells, the table \d+ columns"),
    ("not-utf8", lambda ls: ls[:1] + [ls[1][:-1] + b"\xff\xfe\n"] + ls[2:],
     r"line 2: is not UTF-8 text \(invalid start byte at byte \d+\)"),
    ("nul-byte", lambda ls: ls[:1] + [ls[1].replace(b",ok,", b",o\x00k,")] + ls[2:],
     r"line 2: holds a NUL byte"),
    ("line-20-mb", lambda ls: ls[:1] + [b"0,0.4,ok," + b"x" * 20_000_000 + b"\n"] + ls[2:],
     r"line 2: is longer than 1000000 bytes"),
    ("field-200-kb", lambda ls: _row(ls, 0, error="x" * 200_000), r"line 2: field larger"),
    ("binary-first-line", lambda ls: [b"\x89PNG\r\n"] + ls[1:], r"line 1: is not UTF-8"),
    ("another-sweep-old-format", lambda ls: [b"# mbdyn sweep table v1 spec=0000\n"] + ls,
     r"s.csv: not a table of this sweep"),
]


@pytest.mark.parametrize("case_id, corrupt, pattern", RESUME_CASES,
                         ids=[c[0] for c in RESUME_CASES])
def test_hostile_resume_files(case_id, corrupt, pattern, finished_table, tmp_path, capsys,
                              monkeypatch):
    import mbdyn.analysis.sweep as sw
    monkeypatch.setattr(sw, "make_scheduler", lambda *a: Refuse())   # no member may run
    table = tmp_path / "s.csv"
    data = b"".join(corrupt(list(finished_table)))
    table.write_bytes(data)
    _with_sidecar(tmp_path)
    code, out, err = run_main(SWEEP + ["--out", str(table), "--resume"], tmp_path, capsys)
    assert code == 1, err
    assert re.search(pattern, err), err
    assert len(err) < 1000 and len(err.strip().splitlines()) == 1
    assert table.read_bytes() == data                       # left as it was
    assert (tmp_path / "s.json").read_bytes() == FINISHED_SIDECAR[0]


def _another_spec(sidecar):
    meta = json.loads(sidecar)
    meta["spec"] = "0000"
    return json.dumps(meta).encode()


#: id, the finished sidecar's bytes -> the sidecar's bytes (None: none), message pattern
SIDECAR_CASES = [
    ("another-sweep", _another_spec, r"s.csv: not a table of this sweep"),
    ("no-sidecar", lambda b: None, r"s.csv: has no s.json beside it"),
    ("not-json", lambda b: b"{not json", r"s.json: is not JSON \("),
    ("other-json", lambda b: b'{"format": "x"}', r"s.json: is not the sidecar of a sweep"),
    ("huge", lambda b: b" " * 2_000_000, r"s.json: is longer than 1000000 bytes"),
]


@pytest.mark.parametrize("case_id, corrupt, pattern", SIDECAR_CASES,
                         ids=[c[0] for c in SIDECAR_CASES])
def test_a_table_is_resumed_only_with_its_own_sidecar(case_id, corrupt, pattern,
                                                      finished_table, tmp_path, capsys,
                                                      monkeypatch):
    import mbdyn.analysis.sweep as sw
    monkeypatch.setattr(sw, "make_scheduler", lambda *a: Refuse())   # no member may run
    (tmp_path / "s.csv").write_bytes(b"".join(finished_table))
    sidecar = corrupt(FINISHED_SIDECAR[0])
    if sidecar is not None:
        _with_sidecar(tmp_path, sidecar)
    code, _, err = run_main(SWEEP + ["--out", "{tmp}/s.csv", "--resume"], tmp_path, capsys)
    assert code == 1 and re.search(pattern, err), err
    assert len(err.strip().splitlines()) == 1
    assert (tmp_path / "s.csv").read_bytes() == b"".join(finished_table)


def test_a_table_of_the_old_format_is_resumed_and_rewritten(finished_table, tmp_path,
                                                            capsys):
    """Before the sidecar, a table's first line held its fingerprint: such a table (here
    cut after its first row) is resumed, and written in the new format."""
    spec = json.loads(FINISHED_SIDECAR[0])["spec"]
    old = [f"# mbdyn sweep table v1 spec={spec}\n".encode()] + finished_table[:2]
    (tmp_path / "s.csv").write_bytes(b"".join(old))
    code, out, err = run_main(SWEEP + ["--out", "{tmp}/s.csv", "--resume"], tmp_path, capsys)
    assert code == 0 and "1 run now" in out, err
    assert (tmp_path / "s.csv").read_bytes() == b"".join(finished_table)
    meta = json.loads((tmp_path / "s.json").read_text())
    assert meta["spec"] == spec and meta["status"] == "complete" and meta["rows"] == 2


def test_a_resume_file_that_is_a_fifo_is_refused_not_waited_on(tmp_path, capsys):
    os.mkfifo(tmp_path / "s.csv")
    code, out, err = run_main(SWEEP + ["--out", "{tmp}/s.csv", "--resume"], tmp_path, capsys)
    assert code == 1 and "s.csv: is not a regular file" in err, err


def test_a_row_cut_by_a_kill_is_run_again_and_a_whole_table_resumes(finished_table, tmp_path,
                                                                    capsys):
    table = tmp_path / "s.csv"
    table.write_bytes(b"".join(finished_table[:2]) + finished_table[2][:-9])   # cut row
    _with_sidecar(tmp_path)
    code, out, err = run_main(SWEEP + ["--out", str(table), "--resume"], tmp_path, capsys)
    assert code == 0, err
    assert "1 run now" in out
    assert table.read_bytes() == b"".join(finished_table)
    code, out, err = run_main(SWEEP + ["--out", str(table), "--resume"], tmp_path, capsys)
    assert code == 0 and "0 run now" in out, err             # a finished table: nothing
    assert table.read_bytes() == b"".join(finished_table)


# --- issue 29, item 5: no text cell of a CSV mbdyn writes is a spreadsheet formula

FORMULA_CASES = ["=cmd|' /C calc'!A0", "@SUM(A1:A9)", "+1+cmd|' /C calc'!A0", "'quoted"]
FORMULA_MODEL = BASE + "".join(f'\n[cases."{name.replace(chr(92), chr(92) * 2)}"]\n'
                               f"initial = {{ theta = 0.{k + 1} }}\n"
                               for k, name in enumerate(FORMULA_CASES))
#: the middle value is no expression: its members' rows are errors (text in every cell)
FORMULA_GRID = '["-pi/8", "=HYPERLINK(\\"http://evil\\",\\"x\\")", "0.2"]'


def _formula_cells(rows):
    """The cells of CSV ``rows`` that a spreadsheet would evaluate as a formula."""
    bad = []
    for row in rows:
        for cell in row:
            try:
                float(cell)
                continue                      # a number stays a number, "-0.5" too
            except ValueError:
                pass
            if cell.startswith(("=", "+", "-", "@", "\t", "\r")):
                bad.append(cell)
    return bad


def test_sweep_tables_hold_no_spreadsheet_formula(tmp_path, capsys):
    import csv
    from mbdyn.analysis.sweep import read_table
    argv = ["sweep", "{model}", "--grid", "initial.theta=" + FORMULA_GRID] + sum(
        (["--case", name] for name in FORMULA_CASES), [])
    code, out, err = run_main(argv + ["--out", "{tmp}/s.csv"], tmp_path, capsys,
                              text=FORMULA_MODEL)
    assert code == 0, err
    text = (tmp_path / "s.csv").read_text()
    rows = list(csv.reader(text.splitlines()))
    assert _formula_cells(rows) == []
    assert "'=cmd|' /C calc'!A0" in [r[1] for r in rows]            # escaped, not lost
    statuses = [r[rows[0].index("status")] for r in rows[1:]]
    assert statuses.count("error") == len(FORMULA_CASES)             # the middle value
    # a reader gets the texts back exactly; a resume keeps the table byte for byte
    table = read_table(str(tmp_path / "s.csv"))
    assert list(dict.fromkeys(table["case"])) == FORMULA_CASES
    assert table["initial.theta"][1].startswith("=HYPERLINK(")
    code, out, err = run_main(argv + ["--out", "{tmp}/s.csv", "--resume"], tmp_path, capsys)
    assert code == 0 and "0 run now" in out, err
    assert (tmp_path / "s.csv").read_text() == text
    # the table printed on stdout (no --out) is CSV too
    code, out, err = run_main(argv, tmp_path, capsys)
    assert code == 0, err
    printed = list(csv.reader(out.splitlines()[1 + len(FORMULA_CASES):]))
    assert printed[0][:2] == ["member", "case"] and _formula_cells(printed) == []


def test_escaping_a_cell_is_undone_exactly():
    from mbdyn.escape import spreadsheet_cell, spreadsheet_text
    for text in FORMULA_CASES + ["plain", "", "''", "-", "'=x", "\t1"]:
        cell = spreadsheet_cell(text)
        assert not cell.startswith(("=", "+", "-", "@", "\t", "\r"))
        assert spreadsheet_text(cell) == text


# --- issue 29, item 1: a Dask scheduler address is checked, and every wait on it bounded

class FakeScheduler:
    """A loopback listener (a thread) that accepts and answers as ``mode`` says: never,
    garbage, HTTP, a huge length prefix, a closed connection, or a small message that is
    not Dask's handshake."""

    ANSWERS = {"silent": None, "close": b"",
               "garbage": b"\\x13\\x37garbage!!" * 10,
               "http": b"HTTP/1.1 400 Bad Request\\r\\nContent-Length: 0\\r\\n\\r\\n",
               "huge-length": (2 ** 62).to_bytes(8, "little"),
               "small-junk": (24).to_bytes(8, "little") + b"\\x05" * 24}

    def __init__(self, mode):
        import socket
        import threading
        self.answer = self.ANSWERS[mode]
        self.listener = socket.create_server(("127.0.0.1", 0))
        self.address = f"tcp://127.0.0.1:{self.listener.getsockname()[1]}"
        self.connections = []
        threading.Thread(target=self._serve, daemon=True).start()

    def _serve(self):
        while True:
            try:
                conn, _ = self.listener.accept()
            except OSError:                      # closed: the test is over
                return
            self.connections.append(conn)
            if self.answer == b"":
                conn.close()
            elif self.answer is not None:
                conn.sendall(self.answer)

    def close(self):
        self.listener.close()
        for conn in self.connections:
            conn.close()


#: id, what the listener does, pattern of the message (after the address)
FAKE_SCHEDULERS = [
    ("accepts-never-answers", "silent", r"accepted the connection but did not answer "
                                        r"within 2 s \(--scheduler-timeout\)"),
    ("answers-garbage", "garbage", r"is not a Dask scheduler: its first message announces "
                                   r"\d+ bytes"),
    ("answers-http", "http", r"is not a Dask scheduler: its first message announces"),
    ("announces-2-62-bytes", "huge-length", r"announces 4611686018427387904 bytes"),
    ("closes-at-once", "close", r"closed the connection without the Dask handshake"),
    ("small-junk", "small-junk", r"its first message is not the Dask handshake"),
]


@pytest.mark.parametrize("case_id, mode, pattern", FAKE_SCHEDULERS,
                         ids=[c[0] for c in FAKE_SCHEDULERS])
def test_a_scheduler_address_that_is_no_dask_scheduler_ends_in_bounded_time(
        case_id, mode, pattern, tmp_path, capsys):
    import time
    pytest.importorskip("distributed")
    fake = FakeScheduler(mode)
    try:
        start = time.monotonic()
        code, out, err = run_main(SWEEP + ["--scheduler", fake.address,
                                           "--scheduler-timeout", "2", "--out",
                                           "{tmp}/s.csv"], tmp_path, capsys)
        elapsed = time.monotonic() - start
    finally:
        fake.close()
    assert code == 1, err
    assert re.search(re.escape(fake.address) + r".*" + pattern, err), err
    assert "out of memory" not in err and len(err.strip().splitlines()) == 1
    assert elapsed < 60                        # model loading included; the wait is 2 s
    assert not (tmp_path / "s.csv").exists()   # refused before the table was started


#: malformed addresses: the option is named, exit code 2 (a bad command line)
BAD_ADDRESSES = [
    ("tcp://127.0.0.1:abc", r"the port 'abc' is not a whole number from 1 to 65535"),
    ("tcp://", r"not an address tcp://HOST:PORT"),
    ("tcp://:8786", r"not an address"),
    ("tcp://127.0.0.1", r"not an address"),
    ("tcp://127.0.0.1:0", r"the port '0'"),
    ("tcp://127.0.0.1:99999", r"the port '99999'"),
    ("tcp://127.0.0.1:8786/x", r"the port '8786/x'|not an address"),
    ("tcp://me@127.0.0.1:8786", r"not an address"),
    ("tcp://[::1:8786", r"not an address"),
    ("tcp://127.0.0.1:\uff18\uff17", r"the port"),
    ("udp://127.0.0.1:8786", r"unknown scheduler"),
]


@pytest.mark.parametrize("address, pattern", BAD_ADDRESSES, ids=[a for a, _ in BAD_ADDRESSES])
def test_a_malformed_scheduler_address_is_refused_naming_the_option(address, pattern,
                                                                    tmp_path, capsys):
    code, out, err = run_main(SWEEP + ["--scheduler", address], tmp_path, capsys)
    assert code == 2, err
    assert "--scheduler" in err and re.search(pattern, err), err


def test_a_real_scheduler_without_workers_or_stopped_ends_in_bounded_time(tmp_path):
    """A real ``dask scheduler`` on loopback: with no workers the sweep ends after the
    timeout; stopped (SIGSTOP) while members wait, the check finds it silent; stopped
    before the sweep, the handshake times out."""
    import socket
    import time
    pytest.importorskip("distributed")
    from mbdyn.analysis.schedulers import DaskScheduler, probe
    from mbdyn.analysis.sweep import sweep
    (tmp_path / "model.toml").write_text(BASE)
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
    address = f"tcp://127.0.0.1:{port}"
    proc = subprocess.Popen([sys.executable, "-m", "distributed.cli.dask_scheduler", "--host",
                             "127.0.0.1", "--port", str(port), "--no-dashboard"],
                            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, env=env())
    try:
        deadline = time.monotonic() + 90
        while True:
            try:
                probe(address, 2)
                break
            except mb.ModelError:
                assert time.monotonic() < deadline and proc.poll() is None, \
                    "the Dask scheduler did not start within 90 s"
                time.sleep(0.3)
        start = time.monotonic()
        # 5 s: on a loaded machine a live scheduler may take over 2 s to answer
        with pytest.raises(mb.ModelError, match=re.escape(address) + r" has had no workers "
                           r"for 5 s; start some with `dask worker"):
            sweep(str(tmp_path / "model.toml"), GRID, scheduler=address, scheduler_timeout=5)
        assert time.monotonic() - start < 45
        client = DaskScheduler(address, timeout=2)
        proc.send_signal(signal.SIGSTOP)
        start = time.monotonic()
        with pytest.raises(mb.ModelError, match=re.escape(address) + r" stopped answering"):
            list(client.map_unordered(abs, [1, 2]))
        client.close()
        assert time.monotonic() - start < 30
        start = time.monotonic()
        with pytest.raises(mb.ModelError, match=r"accepted the connection but did not answer"):
            sweep(str(tmp_path / "model.toml"), GRID, scheduler=address, scheduler_timeout=2)
        assert time.monotonic() - start < 30
    finally:
        proc.send_signal(signal.SIGCONT)
        proc.kill()
        proc.wait()


# --- issue 29, item 10: a long sweep says how many members and about how long

class Clock:
    """A clock the test moves."""

    def __init__(self):
        self.now = 100.0

    def __call__(self):
        return self.now


def test_a_million_member_sweep_is_announced_with_an_estimate():
    import io
    from mbdyn.analysis.sweep import _Progress
    clock, stream = Clock(), io.StringIO()
    progress = _Progress(1_000_000, 0, counter=True, stream=stream, clock=clock)
    clock.now += 4.0                              # the first member: workers starting
    progress.update()
    for _ in range(2):                            # then 3.6 ms a member
        clock.now += 0.0036
        progress.update()
    text = stream.getvalue()
    assert re.search(r"^mbdyn sweep: 1000000 members to run; about 60 min left "
                     r"\(0\.0036 s a member, from the first 3\)$", text, re.M), text
    clock.now += 1.0
    progress.update()
    progress.close()
    assert "\rmbdyn sweep: 4/1000000 members, 5 s, about 60 min left" in stream.getvalue()
    assert stream.getvalue().endswith("\n")


def test_a_short_sweep_says_nothing_and_a_slow_first_member_is_enough():
    import io
    from mbdyn.analysis.sweep import _Progress
    clock, stream = Clock(), io.StringIO()
    progress = _Progress(4, 0, counter=False, stream=stream, clock=clock)
    for _ in range(4):
        clock.now += 0.5
        progress.update()
    progress.close()
    assert stream.getvalue() == ""                 # 2 s in all: nothing to announce
    progress = _Progress(10, 2, counter=False, stream=stream, clock=clock)
    clock.now += 30.0                              # one member took 30 s: 7 more to run
    progress.update()
    assert re.search(r"mbdyn sweep: 8 members to run \(2 kept from before\); about "
                     r"3\.5 min left \(30 s a member, from the first 1\)",
                     stream.getvalue()), stream.getvalue()


def test_the_command_announces_a_long_sweep_on_stderr(tmp_path, capsys, monkeypatch):
    import mbdyn.analysis.sweep as sw
    monkeypatch.setattr(sw, "ANNOUNCE_AFTER", 0.0)  # every sweep is "long"
    code, out, err = run_main(SWEEP + ["--json"], tmp_path, capsys)
    assert code == 0, err
    assert json.loads(out)["member"] == [0, 1]     # stdout: the JSON alone
    assert re.search(r"^mbdyn sweep: 2 members to run; about .* left", err, re.M), err


@pytest.mark.parametrize("argv", [
    ["campbell", "{model}", "--parameter", "l", "--values", "0.4:0.5:2", "--not-spin",
     "--plot", "{tmp}/c.txt"],
    ["accuracy", "{model}", "--plot", "{tmp}/c.txt"],
], ids=["campbell", "accuracy"])
def test_diagram_paths_are_checked_before_the_work(argv, tmp_path, capsys, monkeypatch):
    import importlib

    def no_work(*args, **kwargs):
        raise AssertionError("work started")
    monkeypatch.setattr(importlib.import_module("mbdyn.analysis.campbell"), "campbell",
                        no_work)
    monkeypatch.setattr(importlib.import_module("mbdyn.cli.accuracy"), "accuracy_study",
                        no_work)
    code, out, err = run_main(argv, tmp_path, capsys)
    assert code == 1, err
    assert re.search(r"--plot .*c.txt: unknown picture format '.txt'", err), err
