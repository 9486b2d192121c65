"""Sweep throughput: the double pendulum, rk4, 10,000 steps a member (4 s, dt = 4e-4),
members differing in their initial angles; members per second and state-steps per second
(members x steps x 4 states) for serial, batched (one compiled prange call), processes and
Dask (LocalCluster, 2 workers).

    OPENBLAS_NUM_THREADS=1 python benchmarks/sweeps.py [--members-batched 400] [--rounds 3]

Medians of ``--rounds``; the compile (numba cache load) is warmed first in this process;
processes and Dask include starting their workers (that is what a user waits for) -- the
column ``warm`` repeats them with the pool/cluster already up where possible.
"""
import argparse
import os
import statistics
import sys
import time

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))

from mbdyn.analysis.schedulers import make_scheduler  # noqa: E402
from mbdyn.analysis.sweep import sweep  # noqa: E402

MODEL = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "models",
                     "double_pendulum.toml")
FIXED = {"simulation.integrator": "rk4", "simulation.t_end": 4.0, "simulation.dt": 4e-4,
         "outputs.reactions": False, "outputs.energy": False}
STEPS, STATES = 10_000, 4
Q = ("final", "t_final", "steps")


def grid(n):
    a = int(round(n ** 0.5))
    b = -(-n // a)
    return {"initial.theta1": f"0.1:3.0:{a}", "initial.theta2": f"-1.0:1.0:{b}"}


def timed(fn, rounds):
    times = []
    for _ in range(rounds):
        t = time.perf_counter()
        n = fn()
        times.append(time.perf_counter() - t)
    return n, statistics.median(times)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--members", type=int, default=16)
    ap.add_argument("--members-batched", type=int, default=400)
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--skip-dask", action="store_true")
    args = ap.parse_args()
    sweep(MODEL, grid(2), Q, fixed=FIXED)                          # warm the compile
    sweep(MODEL, grid(2), Q, fixed=FIXED, batched=True)
    rows = []

    def add(name, n, wall, note=""):
        rows.append((name, n, wall, n / wall, n * STEPS * STATES / wall, note))

    n, w = timed(lambda: len(sweep(MODEL, grid(args.members), Q, fixed=FIXED)), args.rounds)
    add("serial", n, w)
    n, w = timed(lambda: len(sweep(MODEL, grid(args.members_batched), Q, fixed=FIXED,
                                   batched=True)), args.rounds)
    add("batched (prange, 2 threads)", n, w)
    n, w = timed(lambda: len(sweep(MODEL, grid(args.members), Q, fixed=FIXED,
                                   scheduler="processes", workers=2)), args.rounds)
    add("processes (2, incl. start)", n, w)
    pool = make_scheduler("processes", 2)
    sweep(MODEL, grid(2), Q, fixed=FIXED, scheduler=_Keep(pool))
    n, w = timed(lambda: len(sweep(MODEL, grid(args.members), Q, fixed=FIXED,
                                   scheduler=_Keep(pool))), args.rounds)
    add("processes (2, warm)", n, w)
    pool.close()
    if not args.skip_dask:
        n, w = timed(lambda: len(sweep(MODEL, grid(args.members), Q, fixed=FIXED,
                                       scheduler="dask", workers=2)), 1)
        add("dask LocalCluster (2, incl. start)", n, w)
        cluster = make_scheduler("dask", 2)
        sweep(MODEL, grid(2), Q, fixed=FIXED, scheduler=_Keep(cluster))
        n, w = timed(lambda: len(sweep(MODEL, grid(args.members), Q, fixed=FIXED,
                                       scheduler=_Keep(cluster))), args.rounds)
        add("dask LocalCluster (2, warm)", n, w)
        n, w = timed(lambda: len(sweep(MODEL, grid(args.members_batched), Q, fixed=FIXED,
                                       batched=True, scheduler=_Keep(cluster))), args.rounds)
        add("dask (2, warm) + batched", n, w)
        cluster.close()
    print(f"double pendulum, rk4, {STEPS} steps a member, {STATES} states; "
          f"medians of {args.rounds}; {os.cpu_count()} cores (shared)")
    print("| how | members | wall s | members/s | state-steps/s |")
    print("|---|---:|---:|---:|---:|")
    for name, n, wall, ms, ss, _ in rows:
        print(f"| {name} | {n} | {wall:.2f} | {ms:.1f} | {ss:.3g} |")


class _Keep:
    """A scheduler passed on without closing it at the end of a sweep (reuse warm)."""

    def __init__(self, inner):
        self.inner = inner
        self.name = inner.name
        self.workers = getattr(inner, "workers", 2)

    def map_unordered(self, fn, tasks):
        return self.inner.map_unordered(fn, tasks)

    def close(self):
        pass


if __name__ == "__main__":
    main()
