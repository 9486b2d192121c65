"""Sweeps: the same table from every scheduler (serial, processes, a Dask LocalCluster, a
real external Dask cluster on loopback), batched members bit-identical to single runs,
kill-and-resume, bad overrides refused before any work."""
import os
import signal
import socket
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

import mbdyn as mb
from mbdyn.analysis.sweep import expand, parse_range, read_table, sweep
from mbdyn.errors import ModelError

ROOT = Path(__file__).resolve().parents[1]
TOP = str(ROOT / "models" / "top.toml")
PENDULUM = str(ROOT / "models" / "double_pendulum.toml")

# four members of the top, 0.6 s of the listing's scheme: case a (Mz two ways) runs to
# the end; case c fails at 0.525 s (the listing's scheme blows up) and must be recorded
GRID = {"parameters.Mz": [-0.025, -0.001]}
CASES = ["a", "c"]
FIXED = {"simulation.t_end": 0.6}
QUANTITIES = ("final", "events", "t_final", "max:theta", "energy_drift", "steps")


def _same(a, b):
    assert a.columns == b.columns
    assert len(a.rows) == len(b.rows)
    for ra, rb in zip(a.rows, b.rows):
        for c in a.columns:
            va, vb = ra[c], rb[c]
            if isinstance(va, float) and np.isnan(va):
                assert isinstance(vb, float) and np.isnan(vb), (c, va, vb)
            else:
                assert va == vb, (ra["member"], c, va, vb)


@pytest.fixture(scope="module")
def serial_table():
    return sweep(TOP, GRID, QUANTITIES, cases=CASES, fixed=FIXED)


def test_serial_table_records_failures_and_matches_single_runs(serial_table):
    rows = serial_table.rows
    assert [r["case"] for r in rows] == ["a", "a", "c", "c"]
    assert [r["parameters.Mz"] for r in rows] == [-0.025, -0.001, -0.025, -0.001]
    assert [r["status"] for r in rows[:2]] == ["ok", "ok"]
    assert rows[3]["status"] == "failed" and rows[3]["error"]       # recorded, not raised
    assert rows[3]["t_final"] < 0.6                                  # stopped at the failure
    # member 1 is case a with Mz = -0.001: the same as one run by hand
    res = mb.load_model(TOP, case="a", overrides={"parameters.Mz": -0.001,
                                                  "simulation.t_end": 0.6}).simulate()
    assert rows[1]["final.theta"] == float(res["theta"][-1])
    assert rows[1]["max.theta"] == float(np.max(res["theta"]))
    assert rows[1]["t_final"] == float(res.t[-1])
    assert np.isnan(rows[1]["event.floor"])          # 0.6 s: not yet on the floor


def test_processes_give_the_same_table(serial_table):
    _same(serial_table, sweep(TOP, GRID, QUANTITIES, cases=CASES, fixed=FIXED,
                              scheduler="processes", workers=2))


def test_dask_local_cluster_gives_the_same_table(serial_table):
    _same(serial_table, sweep(TOP, GRID, QUANTITIES, cases=CASES, fixed=FIXED,
                              scheduler="dask", workers=2))


def _free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


@pytest.fixture(scope="module")
def dask_cluster(request):
    """A real ``dask scheduler`` and two ``dask worker`` processes on 127.0.0.1."""
    pytest.importorskip("distributed")
    port = _free_port()
    address = f"tcp://127.0.0.1:{port}"
    env = dict(os.environ, PYTHONPATH=str(ROOT) + os.pathsep + os.environ.get("PYTHONPATH", ""))
    procs = []

    def stop():
        for p in reversed(procs):
            if p.poll() is None:
                p.terminate()
        for p in procs:
            try:
                p.wait(timeout=15)
            except subprocess.TimeoutExpired:
                p.kill()
                p.wait()
    request.addfinalizer(stop)
    common = dict(env=env, cwd=str(ROOT), stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    procs.append(subprocess.Popen([sys.executable, "-m", "distributed.cli.dask_scheduler",
                                   "--host", "127.0.0.1", "--port", str(port),
                                   "--no-dashboard"], **common))
    for _ in range(2):
        procs.append(subprocess.Popen([sys.executable, "-m", "distributed.cli.dask_worker",
                                       address, "--nthreads", "1", "--nworkers", "1",
                                       "--host", "127.0.0.1", "--no-dashboard"], **common))
    from dask.distributed import Client
    deadline = time.monotonic() + 90
    while True:
        try:
            with Client(address, timeout=5) as c:
                c.wait_for_workers(2, timeout=max(1, deadline - time.monotonic()))
            break
        except Exception:
            if time.monotonic() > deadline or any(p.poll() is not None for p in procs):
                pytest.fail("the Dask scheduler and workers did not start within 90 s")
            time.sleep(0.5)
    return address


def test_external_dask_cluster_gives_the_same_table(serial_table, dask_cluster):
    _same(serial_table, sweep(TOP, GRID, QUANTITIES, cases=CASES, fixed=FIXED,
                              scheduler=dask_cluster))


@pytest.mark.parametrize("integrator,t_end,method", [("rk4", 0.3, "auto"),
                                                     ("semi-implicit-euler", 0.30005, "auto"),
                                                     ("rk4", 0.3, "articulated")])
def test_batched_members_bit_identical_to_single_runs(integrator, t_end, method):
    # 0.30005 s is not a whole number of steps: the shortened last step is batched too
    grid = {"initial.theta1": [0.1, 1.0, 3.0], "initial.theta2": [-0.5, "pi/4"]}
    fixed = {"simulation.integrator": integrator, "simulation.t_end": t_end,
             "simulation.dt": 1e-3, "parameters.m1": 0.001, "simulation.method": method}
    q = ("final", "t_final", "steps", "rhs_evaluations")
    batched = sweep(PENDULUM, grid, q, fixed=fixed, batched=True)
    serial = sweep(PENDULUM, grid, q, fixed=fixed)
    _same(serial, batched)
    for row in batched.rows:                          # and against simulate by hand
        scene = mb.load_model(PENDULUM, overrides=dict(
            fixed, **{"initial.theta1": row["initial.theta1"],
                      "initial.theta2": row["initial.theta2"]}))
        res = scene.simulate(outputs=(), points={})
        assert row["final.theta1"] == res.q[-1, 0] and row["final.theta2_dot"] == res.u[-1, 1]
        assert row["t_final"] == res.t[-1] == t_end


def test_batched_takes_the_default_quantities_of_a_model_without_events():
    """``mbdyn sweep --batched`` with no ``-q``: the default quantities include events,
    which have no columns for a model without them; same table as serial."""
    grid = {"initial.theta1": [0.1, 2.0]}
    fixed = {"simulation.integrator": "rk4", "simulation.t_end": 0.05, "simulation.dt": 1e-3}
    batched = sweep(PENDULUM, grid, fixed=fixed, batched=True)
    _same(sweep(PENDULUM, grid, fixed=fixed), batched)
    assert "final.theta1" in batched.columns and "t_final" in batched.columns


def test_batched_refuses_what_it_cannot_run():
    with pytest.raises(ModelError, match="events"):
        sweep(TOP, GRID, ("final",), batched=True)
    with pytest.raises(ModelError, match="adaptive"):
        sweep(PENDULUM, {"initial.theta1": [0.1]}, ("final",),
              fixed={"simulation.integrator": "DOP853"}, batched=True)


class _Refuse:
    """A scheduler that fails the test if anything is sent to it."""
    name = "refuse"

    def map_unordered(self, fn, tasks):
        raise AssertionError("work started")

    def close(self):
        pass


@pytest.mark.parametrize("grid,match", [
    ({"initial.thetaa": [0.1]}, "not a coordinate"),
    ({"parameters.nope": [1.0]}, "nope"),
    ({"nosection.x": [1.0]}, "unknown section"),
    ({"parameters.Mz": "0:1"}, "START:STOP:N"),
    ({"parameters.Mz": "a:b:3"}, "numbers"),
    ({"parameters.Mz": "-1:1:3:log"}, "log spacing"),
    ({"parameters.Mz": "0:1:0"}, "no members"),
    ({"parameters.Mz": []}, "no values"),
])
def test_bad_overrides_fail_before_any_work(grid, match):
    with pytest.raises(ModelError, match=match):
        sweep(TOP, grid, scheduler=_Refuse())
    with pytest.raises(ModelError, match="unknown quantity"):
        sweep(TOP, {"parameters.Mz": [0.0]}, ("final", "maxx:theta"), scheduler=_Refuse())


def test_ranges():
    assert parse_range("0:1:3") == [0.0, 0.5, 1.0]
    assert np.allclose(parse_range("-1e-3:-1e-1:3:log"), [-1e-3, -1e-2, -1e-1])
    assert parse_range('[1, "pi/4"]') == [1, "pi/4"]
    assert len(expand({"a.b": [1, 2], "c.d": [3, 4, 5]}, ["x", "y"])) == 12


def test_kill_and_resume_gives_the_uninterrupted_table(tmp_path):
    # 16 members of 3 s each: a member takes about 0.1 s on a warm cache, so the kill
    # lands while members remain (6 members of 1.5 s all finished inside one 0.05 s poll)
    grid = ["--grid", "parameters.Mz=-0.03:-0.001:16", "--set", "simulation.t_end=3",
            "-q", "final", "-q", "events", "-q", "max:theta"]
    env = dict(os.environ, PYTHONPATH=str(ROOT))
    cmd = [sys.executable, "-m", "mbdyn", "sweep", TOP] + grid
    full, part = tmp_path / "full.csv", tmp_path / "part.csv"
    subprocess.run(cmd + ["--out", str(full)], check=True, env=env, cwd=ROOT, timeout=300,
                   capture_output=True)
    p = subprocess.Popen(cmd + ["--out", str(part)], env=env, cwd=ROOT,
                         stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    try:
        deadline = time.monotonic() + 240
        while time.monotonic() < deadline and p.poll() is None:
            if part.exists() and len(part.read_text().splitlines()) >= 3:   # 2 members
                break
            time.sleep(0.05)
        assert p.poll() is None, "the sweep finished before it could be killed"
        p.send_signal(signal.SIGKILL)
        p.wait(timeout=30)
    finally:
        if p.poll() is None:
            p.kill()
            p.wait()
    kept = len(part.read_text().splitlines()) - 1                        # the header
    assert 2 <= kept < 16
    r = subprocess.run(cmd + ["--out", str(part), "--resume"], env=env, cwd=ROOT, timeout=300,
                       capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    assert f"{16 - kept} run now" in r.stdout
    assert part.read_text() == full.read_text()
    t = read_table(str(full))
    assert list(t["member"]) == list(range(16)) and set(t["status"]) == {"ok"}


def test_cli_json_and_plot(tmp_path, capsys, monkeypatch):
    import json
    from mbdyn.cli import main
    args = ["sweep", PENDULUM, "--grid", "initial.theta1=0.1:0.3:2", "--grid",
            "initial.theta2=[0.0, 0.2]", "--set", "simulation.t_end=0.05", "-q", "final"]
    assert main(args + ["--json"]) == 0
    out, err = capsys.readouterr()
    table = json.loads(out)
    assert table["member"] == [0, 1, 2, 3] and table["initial.theta2"] == [0.0, 0.2, 0.0, 0.2]
    assert err == ""
    png = tmp_path / "t_final.theta1.png"
    assert main(args + ["--out", str(tmp_path / "t.csv"), "--plot", "final.theta1"]) == 0
    assert png.exists() and png.stat().st_size > 1000
    import mbdyn.analysis.sweep as sw
    monkeypatch.setattr(sw, "make_scheduler", lambda *a: _Refuse())   # no member may run
    assert main(args + ["--plot", "nope", "--plot-file", str(png)]) == 1
    assert "not a column" in capsys.readouterr().err
