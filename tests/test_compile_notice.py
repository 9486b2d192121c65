"""A command that compiles says so, at once (issue 27, item 1): the notice on a fresh
numba cache within a second of the start, none when the kernels are cached, the cache
found where numba keeps it, progress on a terminal, and ``mbdyn warmup``."""
from __future__ import annotations

import io
import json
import os
import subprocess
import sys
import time
from pathlib import Path

import pytest

from mbdyn.cli import compiling, main

ROOT = Path(__file__).resolve().parent.parent
NOTICE = "mbdyn: compiling the numeric kernels for this machine, once: ~"


def _env(**extra):
    return dict(os.environ, PYTHONPATH=str(ROOT), MBDYN_COMPILE_NOTICE="1", **extra)


def test_the_readme_command_on_a_fresh_cache_says_so_within_a_second(tmp_path):
    """The README's first command with an empty numba cache: the first line on stderr is
    the notice, and it comes within 1 s of the start (the compile itself begins after
    about 1.5 s of imports and reading; the process is stopped once the line is read)."""
    start = time.perf_counter()
    proc = subprocess.Popen([sys.executable, "-m", "mbdyn", "run", "models/top.toml",
                             "--case", "a"], cwd=ROOT, stdout=subprocess.DEVNULL,
                            stderr=subprocess.PIPE, text=True,
                            env=_env(NUMBA_CACHE_DIR=str(tmp_path)))
    try:
        first = proc.stderr.readline()
        elapsed = time.perf_counter() - start
    finally:
        proc.kill()
        proc.wait()
    assert first.startswith(NOTICE) and "mbdyn warmup" in first, first
    # "~N s": the estimate counts every kernel the command compiles (the core ones, the
    # listing's loop, the report's), none cached
    from mbdyn.cli import compiling
    every = sum(compiling.SECONDS[name] for _, name in compiling.CORE) + compiling.RUN_EXTRA
    every += compiling.SECONDS["semi_implicit_euler_loop"]
    assert int(first[len(NOTICE):].split()[0]) == round(every), first
    assert elapsed < 1.0, elapsed


@pytest.mark.parametrize("model, name", [
    (["models/top.toml", "--case", "a"], "heavy top"),
    (["models/double_pendulum.toml", "--integrator", "DOP853"], "double pendulum"),
    (["models/four_bar.toml"], "four-bar linkage")])
def test_no_notice_when_the_kernels_are_cached(tmp_path, model, name):
    """Once compiled (the first run here, if the cache is cold), the same command says
    nothing about compiling -- with the listing's scheme, an adaptive one, a closed loop;
    ``--json`` keeps stdout one JSON object either way."""
    argv = [sys.executable, "-m", "mbdyn", "run", *model, "--t-end", "0.05", "--json"]
    for attempt in range(2):
        done = subprocess.run(argv, cwd=ROOT, capture_output=True, text=True, env=_env())
        assert done.returncode == 0, done.stderr
        assert json.loads(done.stdout)["model"] == name
    assert "compil" not in done.stderr, done.stderr


def test_the_estimate_counts_what_the_model_file_shows(tmp_path, monkeypatch):
    """On an empty cache, a closed loop's run (a joint with ``cut = true``, here in a
    case's joints only) and a model's force elements add their kernels' seconds to the
    notice's estimate; a URDF file (not TOML) counts the core alone."""
    text = ('[[bodies]]\nname = "b"\nmass = 1\n[[joints]]\nname = "j"\nkind = "revolute"\n'
            'parent = "ground"\nchild = "b"\n[cases.x]\n[[cases.x.joints]]\nname = "c"\n'
            'cut = true\n')
    closed = tmp_path / "closed.toml"
    closed.write_text(text)
    forces = tmp_path / "forces.toml"
    forces.write_text(text.replace("cut = true", "cut = false") + '[[forces]]\nname = "s"\n')
    data = compiling._read_toml(str(closed))
    assert compiling.features_of(data, ["--case", "x"]) == {"closed loop"}
    assert compiling.features_of(data) == set()         # not in the case run
    assert compiling.features_of(compiling._read_toml(str(forces))) == {"force elements"}
    top = compiling._read_toml(str(ROOT / "models" / "top.toml"))
    assert compiling.features_of(top, ["--case", "floor"]) == {"force elements"}
    assert compiling.features_of(top, ["--case", "a"]) == set()
    # what the case run makes, as the loader merges it: a case's list replaces the file's,
    # its table by name amends it; switched effects may leave the force elements out
    both = {"joints": [{"name": "j", "cut": True}], "forces": [{"name": "s"}],
            "cases": {"none": {"joints": [{"name": "j"}], "forces": []},
                      "cut": {"joints": {"k": {"cut": True}}}}}
    assert compiling.features_of(both) == {"closed loop", "force elements"}
    assert compiling.features_of(both, ["--case", "none"]) == set()
    assert compiling.features_of(dict(both, joints=[], forces=[]), ["--case", "cut"]) == \
        {"closed loop"}
    assert compiling.features_of(both, ["--effects=-s"]) == {"closed loop"}
    assert compiling.features_of(dict(both, effects={"s": False})) == {"closed loop"}
    for odd in ({"model": {"default_case": ["a"]}}, {"model": [], "cases": []},
                {"joints": "x", "forces": 3, "cases": {"a": 1}}):
        assert compiling.features_of(odd, ["--case", "a"]) <= {"force elements"}
        compiling.integrator_of("", [], odd)      # the loader refuses it, with a message
    assert compiling.features_of(compiling._read_toml(str(ROOT / "models" / "arm6.urdf"))) \
        == set()
    monkeypatch.setenv("NUMBA_CACHE_DIR", str(tmp_path / "empty"))
    monkeypatch.setenv("MBDYN_COMPILE_NOTICE", "1")
    seconds = compiling.SECONDS
    base = sum(seconds[q] for _, q in compiling.CORE + compiling.INTEGRATOR_KERNELS["DOP853"])
    for line, feature in ((["run", str(closed), "--case", "x"], "closed loop"),
                          (["run", str(forces)], "force elements")):
        monkeypatch.setitem(compiling._STATE, "announced", False)
        stream = io.StringIO()
        monkeypatch.setattr(sys, "stderr", stream)
        assert compiling.announce_if_cold("run", line)
        extra = sum(seconds[q] for _, q in compiling.FEATURE_KERNELS[feature])
        assert f"~{round(base + extra + compiling.RUN_EXTRA)} s" in stream.getvalue()


def test_the_check_finds_the_cache_where_numba_keeps_it(tmp_path):
    """``compiling.cache_dir`` names the folder numba's own locator chose, in the tree
    and under ``NUMBA_CACHE_DIR``; an index of other source is not taken for a hit."""
    probe = ("import json; from mbdyn.cli import compiling; import mbdyn.kernels.evaluate"
             " as e, mbdyn.kernels.dynamics as d\n"
             "fs = [e.kinematics_and_loads, d.jourdain_terms, d.cholesky_solve]\n"
             "print(json.dumps([[f._cache._cache_path, compiling.cache_dir("
             "f.py_func.__code__.co_filename)] for f in fs]))")
    for extra in ({}, {"NUMBA_CACHE_DIR": str(tmp_path)}):
        done = subprocess.run([sys.executable, "-c", probe], cwd=ROOT, capture_output=True,
                              text=True, env=_env(**extra), check=True)
        for numba_says, ours in json.loads(done.stdout):
            assert numba_says == ours


def test_an_index_of_other_source_or_another_numba_is_not_a_hit(tmp_path, monkeypatch):
    """numba stores the source's SHA-256 and its own version in the index, and the stamp
    carries the hash of every kernel module (``kernels.cache``): an index written for
    another source, another state of the kernels or by another numba does not count."""
    import hashlib
    import pickle
    monkeypatch.setenv("NUMBA_CACHE_DIR", str(tmp_path))
    source = compiling.PACKAGE / "kernels" / "evaluate.py"
    folder = Path(compiling.cache_dir(source))
    folder.mkdir(parents=True)
    tag = f"py{sys.version_info.major}{sys.version_info.minor}"
    index = folder / f"evaluate.kinematics_and_loads-30.{tag}.nbi"
    digest = hashlib.sha256(source.read_bytes()).digest()
    kernels = compiling.kernels_fingerprint().encode()
    for version, stamp, hit in ((compiling._numba_version(), digest + kernels, True),
                                (compiling._numba_version(), digest + b"0" * 64, False),
                                (compiling._numba_version(), digest, False),
                                (compiling._numba_version(), b"x" * 32 + kernels, False),
                                ("0.1.0", digest + kernels, False)):
        index.write_bytes(pickle.dumps(version) + b"(stamp " + stamp + b" overloads)")
        assert compiling.is_cached("evaluate", "kinematics_and_loads") is hit
    assert compiling.is_cached("evaluate", "energies") is False


def test_a_cached_core_is_seen_as_cached(monkeypatch):
    """After the core kernels ran in this process, the check finds every one of them,
    and the notice is not given."""
    import numpy as np

    import mbdyn as mb
    s = mb.System("p", gravity=(0, 0, -9.81))
    s.add_body("b", mass=1.0, com=(0, 0, -1), inertia=(1e-3, 1e-3, 1e-3))
    s.add_joint("q", "revolute", "ground", "b", axis="y")
    model = s.compile()
    model.forward_dynamics(np.array([0.1]), np.array([0.0]))
    model.mass_matrix_condition(np.array([0.1]))
    assert compiling.missing() == []
    monkeypatch.setenv("MBDYN_COMPILE_NOTICE", "1")
    monkeypatch.setitem(compiling._STATE, "announced", False)
    top = str(ROOT / "models" / "top.toml")
    assert compiling.announce_if_cold("run", ["run", top]) is False
    monkeypatch.setenv("NUMBA_CACHE_DIR", "/nonexistent/empty")
    assert set(compiling.missing()) == {"kinematics_and_loads", "jourdain_terms",
                                        "cholesky_solve"}
    assert compiling.announce_if_cold("run", ["run", "missing.toml"]) is False
    assert compiling.announce_if_cold("eom", ["eom", top]) is False
    assert compiling.announce_if_cold("run", ["run", top, "--help"]) is False


def test_the_notice_is_given_once_and_progress_shows_on_a_terminal(monkeypatch):
    """One notice, with the first kernel's estimate; on a terminal the kernel, the time
    so far and the estimate, rewritten in place and cleared; a closing line."""
    monkeypatch.setenv("MBDYN_COMPILE_NOTICE", "1")
    monkeypatch.setitem(compiling._STATE, "announced", False)
    monkeypatch.setitem(compiling._STATE, "estimate", None)

    class Terminal(io.StringIO):
        def isatty(self):
            return True
    stream = Terminal()
    watch = compiling.Watch(stream=stream)
    watch._start("jourdain_terms")
    time.sleep(0.7)
    watch._end()
    watch._start("energies")
    watch._end()
    watch._clear()
    watch.close()
    text = stream.getvalue()
    assert text.count(NOTICE) == 1
    estimate = round(compiling.SECONDS["jourdain_terms"] + compiling.RUN_EXTRA)
    assert (f"\rmbdyn: compiling jourdain_terms: 0 s so far of ~{estimate} s (0 kernels done)"
            in text)
    assert "\r\x1b[K" in text
    assert text.endswith("mbdyn: compiled 2 kernels in 1 s; they are cached for the next "
                         "runs\n")
    assert compiling.announce(5.0, stream) is False          # once per process
    quiet = io.StringIO()                                    # not a terminal: no progress
    watch = compiling.Watch(stream=quiet)
    watch._start("x")
    time.sleep(0.4)
    watch._end()
    assert "\r" not in quiet.getvalue()
    monkeypatch.setenv("MBDYN_COMPILE_NOTICE", "0")
    silent = io.StringIO()
    watch = compiling.Watch(stream=silent)
    watch._start("x")
    watch._end()
    watch.close()
    assert silent.getvalue() == ""


def test_warmup_compiles_the_main_routes_and_says_what_each_took(capsys):
    """``mbdyn warmup``: every main route runs (compiling what the cache lacks) and is
    reported with its time; a second call finds them all cached."""
    assert main(["warmup"]) == 0
    assert main(["warmup"]) == 0
    out = capsys.readouterr().out.split("mbdyn warmup:")[-1]
    for route in ("jourdain", "fixed-step", "articulated", "force elements", "closed loop",
                  "total"):
        assert f"\n  {route} " in out, out
    assert "failed" not in out and "batched" not in out
    assert out.count(" cached ") == 5, out
