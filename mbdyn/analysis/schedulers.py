"""Where the members of a sweep run: one small interface, several engines.

A scheduler is an object with ``map_unordered(fn, tasks)``: it calls the module-level
function ``fn`` on each task (plain data: dicts, strings and numbers -- never closures)
and yields ``(index, result)`` pairs in the order the tasks finish, and ``close()``.

* ``"serial"``: in this process, in order.
* ``"processes"``: a ``concurrent.futures`` pool of worker processes (spawned, so each
  starts clean; numba's on-disk cache makes their compile a load).
* ``"dask"``: a ``dask.distributed.LocalCluster`` of worker processes with one thread each
  and no dashboard.
* ``"tcp://HOST:PORT"``: an existing Dask scheduler.  Its workers must be able to
  ``import mbdyn`` (the same version).
"""
from __future__ import annotations

import numbers
import os

from ..errors import ModelError


NAMES = ("serial", "processes", "dask")


def make_scheduler(spec="serial", workers=None):
    """The scheduler named by ``spec`` (see the module docstring); ``workers``: the number
    of local worker processes (default: the number of cores)."""
    check_spec(spec)
    if workers is not None and (isinstance(workers, bool) or not isinstance(
            workers, numbers.Integral) or workers < 1):
        raise ModelError(f"workers={workers!r}: give a whole number >= 1 (local worker "
                         "processes), or None for one per core")
    if not isinstance(spec, str):
        return spec                       # already a scheduler object
    if spec == "serial":
        return SerialScheduler()
    if spec == "processes":
        return ProcessScheduler(workers)
    return DaskScheduler(None if spec == "dask" else spec, workers)


def check_spec(spec):
    """Refuse a scheduler ``spec`` that is neither one of ``NAMES``, an address
    ``tcp://HOST:PORT`` nor a scheduler object (with ``map_unordered`` and ``close``),
    before anything is started or connected."""
    if not isinstance(spec, str):
        if callable(getattr(spec, "map_unordered", None)) and callable(
                getattr(spec, "close", None)):
            return
        raise ModelError(f"scheduler={_brief(spec)}: not a scheduler; give 'serial', "
                         "'processes', 'dask', 'tcp://HOST:PORT' (an existing Dask "
                         "scheduler) or an object with map_unordered(fn, tasks) and close()")
    if spec in NAMES or spec.startswith("tcp://"):
        return
    raise ModelError(f"unknown scheduler {_brief(spec)}; use serial, processes, dask or "
                     "tcp://HOST:PORT (an existing Dask scheduler)")


def _brief(value, width=40):
    """``repr(value)``, shortened to ``width`` characters for a message."""
    text = repr(value)
    return text if len(text) <= width else text[:width - 3] + "..."


def _cores():
    return len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count()


class SerialScheduler:
    name = "serial"

    def map_unordered(self, fn, tasks):
        for i, task in enumerate(tasks):
            yield i, fn(task)

    def close(self):
        pass


class ProcessScheduler:
    name = "processes"

    def __init__(self, workers=None):
        import concurrent.futures as cf
        import multiprocessing as mp
        self.workers = workers or _cores()
        self.pool = cf.ProcessPoolExecutor(self.workers, mp_context=mp.get_context("spawn"))

    def map_unordered(self, fn, tasks):
        import concurrent.futures as cf
        futures = {self.pool.submit(fn, task): i for i, task in enumerate(tasks)}
        try:
            for f in cf.as_completed(futures):
                yield futures[f], f.result()
        finally:
            for f in futures:
                f.cancel()

    def close(self):
        self.pool.shutdown(wait=True, cancel_futures=True)


class DaskScheduler:
    name = "dask"

    def __init__(self, address=None, workers=None):
        try:
            from dask.distributed import Client, LocalCluster
        except ImportError:
            raise ModelError("the dask scheduler needs dask.distributed: "
                             "pip install \"mbdyn[dask]\" (or dask[distributed])") from None
        self.cluster = None
        if address is None:
            self.cluster = LocalCluster(n_workers=workers or _cores(), threads_per_worker=1,
                                        processes=True, dashboard_address=None)
            self.client = Client(self.cluster)
        else:
            try:
                self.client = Client(address, timeout=30)
            except OSError as exc:
                raise ModelError(f"cannot reach the Dask scheduler at {address}: {exc}; "
                                 "start one with `dask scheduler` and workers with "
                                 f"`dask worker {address}`") from None
            self.name = address

    def map_unordered(self, fn, tasks):
        from dask.distributed import as_completed
        futures = [self.client.submit(fn, task, pure=False) for task in tasks]
        index = {f.key: i for i, f in enumerate(futures)}
        try:
            for f in as_completed(futures):
                yield index[f.key], f.result()
        finally:
            self.client.cancel([f for f in futures if not f.done()])

    def close(self):
        self.client.close()
        if self.cluster is not None:
            self.cluster.close()
