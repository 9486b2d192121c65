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
  ``import mbdyn`` (the same version).  The address is checked before anything is
  connected (``parse_address``), the peer's handshake read by ``probe`` (bounded in time
  and in bytes) before Dask's client talks to it, and every later wait is bounded by
  ``timeout`` (``DaskScheduler``).

Tasks may be an iterable (a generator): the pools keep a bounded number in flight.
"""
from __future__ import annotations

import asyncio
import concurrent.futures as cf
import numbers
import os
import re
import socket
import struct
import threading
import time

from .. import limits
from ..errors import ModelError
from .arguments import brief


NAMES = ("serial", "processes", "dask")


def make_scheduler(spec="serial", workers=None, timeout=None):
    """The scheduler named by ``spec`` (see the module docstring); ``workers``: the number
    of local worker processes (default: the number of cores); ``timeout``: the longest
    wait on a Dask scheduler (default ``limits.SCHEDULER_TIMEOUT``)."""
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
    return DaskScheduler(None if spec == "dask" else spec, workers, timeout)


def check_spec(spec):
    """Refuse a scheduler ``spec`` that is neither one of ``NAMES``, an address
    ``tcp://HOST:PORT`` nor a scheduler object (with ``map_unordered`` and ``close``),
    before anything is started or connected."""
    if not isinstance(spec, str):
        if callable(getattr(spec, "map_unordered", None)) and callable(
                getattr(spec, "close", None)):
            return
        raise ModelError(f"scheduler={brief(spec)}: not a scheduler; give 'serial', "
                         "'processes', 'dask', 'tcp://HOST:PORT' (an existing Dask "
                         "scheduler) or an object with map_unordered(fn, tasks) and close()")
    if spec in NAMES:
        return
    if spec.startswith("tcp://"):
        parse_address(spec)
        return
    raise ModelError(f"unknown scheduler {brief(spec)}; use serial, processes, dask or "
                     "tcp://HOST:PORT (an existing Dask scheduler)")


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
        """At most ``4 * workers`` tasks in flight: a million members are not all
        submitted (and held) at once."""
        pending = {}
        try:
            for i, f in _windowed(enumerate(tasks), 4 * self.workers, pending,
                                  lambda item: self.pool.submit(fn, item[1]),
                                  lambda fs: cf.wait(fs, return_when=cf.FIRST_COMPLETED)[0]):
                yield i, f.result()
        finally:
            for f in pending:
                f.cancel()

    def close(self):
        self.pool.shutdown(wait=True, cancel_futures=True)


def _windowed(items, window, pending, submit, wait_some):
    """``(index, finished future)`` of ``items`` (``(index, task)`` pairs) submitted with
    ``submit`` and kept at most ``window`` in flight in ``pending`` (``{future: index}``);
    ``wait_some(futures)`` returns some finished ones."""
    items = iter(items)
    exhausted = False
    while True:
        while not exhausted and len(pending) < window:
            item = next(items, None)
            if item is None:
                exhausted = True
            else:
                pending[submit(item)] = item[0]
        if not pending:
            return
        for f in wait_some(list(pending)):
            yield pending.pop(f), f


# --------------------------------------------------------------------------- Dask

#: bytes of the first message a Dask scheduler sends (its handshake is ~100 bytes); a
#: peer that announces more is not one, and nothing is allocated for it
MAX_HANDSHAKE = 65536
#: tasks a Dask client keeps submitted at once
DASK_WINDOW = 1024


def parse_address(spec):
    """``(host, port)`` of a Dask scheduler address ``tcp://HOST:PORT`` (HOST a name, an
    IPv4 address or ``[IPv6]``, PORT 1..65535); ``ModelError`` naming what is wrong."""
    m = _ADDRESS.fullmatch(spec)
    if not m:
        raise ModelError(f"scheduler {brief(spec)}: not an address tcp://HOST:PORT; write "
                         "e.g. tcp://127.0.0.1:8786 (a host name or address, a port number)")
    host, port = m.group("host") or m.group("ipv6"), m.group("port")
    if not (port.isascii() and port.isdigit()) or not 1 <= int(port) <= 65535:
        raise ModelError(f"scheduler {brief(spec)}: the port {brief(port)} is not a whole "
                         "number from 1 to 65535; write e.g. tcp://127.0.0.1:8786")
    return host, int(port)


_ADDRESS = re.compile(r"tcp://(?:(?P<host>[A-Za-z0-9](?:[A-Za-z0-9.-]{0,252}))|"
                      r"\[(?P<ipv6>[0-9A-Fa-f:.]{2,45})\]):(?P<port>[^/?#@]{0,20})")


def probe(address, timeout):
    """Check that ``address`` is a Dask scheduler before Dask's client connects: connect,
    then read its handshake -- the first message a Dask server sends -- within
    ``timeout`` seconds, allocating at most ``MAX_HANDSHAKE`` bytes for it.  A peer that
    never answers, answers garbage or HTTP, or announces a huge message is refused with
    a ``ModelError`` naming the address and what it did."""
    host, port = parse_address(address)
    deadline = time.monotonic() + timeout
    try:
        sock = socket.create_connection((host, port), timeout=timeout)
    except OSError as exc:
        reason = "no answer" if isinstance(exc, socket.timeout) else (exc.strerror or exc)
        raise ModelError(f"cannot reach the Dask scheduler at {address}: {reason}; start "
                         f"one with `dask scheduler` and workers with `dask worker "
                         f"{address}`") from None
    with sock:
        prefix = _receive(sock, 8, deadline, address, timeout)
        size = struct.unpack("Q", prefix)[0]
        if not 8 <= size <= MAX_HANDSHAKE:
            raise ModelError(f"{address} is not a Dask scheduler: its first message "
                             f"announces {size} bytes (a Dask handshake has at most "
                             f"{MAX_HANDSHAKE}; HTTP or another service answers so); check "
                             "the host and the port")
        _check_handshake(_receive(sock, size, deadline, address, timeout), address)


def _receive(sock, n, deadline, address, timeout):
    """``n`` bytes from ``sock`` before ``deadline``, else a ``ModelError``."""
    data = bytearray()
    while len(data) < n:
        left = deadline - time.monotonic()
        try:
            if left <= 0:
                raise socket.timeout
            sock.settimeout(left)
            chunk = sock.recv(n - len(data))
        except socket.timeout:
            raise ModelError(f"the Dask scheduler at {address} accepted the connection but "
                             f"did not answer within {timeout:g} s (--scheduler-timeout); is "
                             "it a Dask scheduler, and is it running?") from None
        except OSError as exc:
            raise ModelError(f"the Dask scheduler at {address} dropped the connection "
                             f"({exc.strerror or exc}); is it a Dask scheduler?") from None
        if not chunk:
            raise ModelError(f"{address} closed the connection without the Dask handshake; "
                             "is it a Dask scheduler?")
        data += chunk
    return bytes(data)


def _check_handshake(data, address):
    """Refuse ``data`` unless it is a Dask handshake (a table of the peer's settings)."""
    try:
        from distributed.protocol.core import loads
        from distributed.protocol.utils import unpack_frames
        count = struct.unpack_from("Q", data)[0]
        if not 1 <= count <= 16 or 8 * (1 + count) > len(data):
            raise ValueError(f"{count} frames")
        message = loads(unpack_frames(data), deserialize=False)
        if not isinstance(message, dict) or "pickle-protocol" not in message:
            raise ValueError("not a handshake")
    except Exception as exc:
        raise ModelError(f"{address} is not a Dask scheduler: its first message is not the "
                         f"Dask handshake ({type(exc).__name__}); check the host and the "
                         "port") from None


def _within(seconds, call, failure):
    """``call()`` in a helper thread, waited for at most ``seconds``; past them
    ``ModelError(failure)`` (the thread is left to end on its own)."""
    box = {}

    def target():
        try:
            box["value"] = call()
        except BaseException as exc:       # handed to the caller
            box["error"] = exc
    thread = threading.Thread(target=target, daemon=True, name="mbdyn-dask-wait")
    thread.start()
    thread.join(seconds)
    if thread.is_alive():
        raise ModelError(failure)
    if "error" in box:
        raise box["error"]
    return box.get("value")


class DaskScheduler:
    """A Dask cluster: a ``LocalCluster`` of this machine (``address`` None) or the
    scheduler at ``address``.  Every wait on a scheduler at an address is bounded by
    ``timeout`` seconds (``limits.SCHEDULER_TIMEOUT``): the connection and handshake,
    each finished member's result, and -- while members run -- a check every ``timeout``
    that the scheduler still answers and has workers.  A scheduler that fails one ends
    the sweep with a ``ModelError`` naming the address and what went wrong."""
    name = "dask"

    def __init__(self, address=None, workers=None, timeout=None):
        try:
            from dask.distributed import Client, LocalCluster
        except ImportError:
            raise ModelError("the dask scheduler needs dask.distributed: "
                             "pip install \"mbdyn[dask]\" (or dask[distributed])") from None
        self.timeout = float(timeout or limits.SCHEDULER_TIMEOUT)
        self.address = address
        self.cluster = None
        if address is None:
            self.cluster = LocalCluster(n_workers=workers or _cores(), threads_per_worker=1,
                                        processes=True, dashboard_address=None)
            self.client = Client(self.cluster)
            return
        self.name = address
        probe(address, self.timeout)
        self.client = self._connect(Client)

    def _connect(self, Client):
        """Dask's client of ``address``, its connection bounded by the timeout."""
        try:
            return _within(2 * self.timeout, lambda: Client(self.address,
                                                            timeout=self.timeout),
                           f"the Dask scheduler at {self.address} did not complete the "
                           f"connection within {2 * self.timeout:g} s (--scheduler-timeout)")
        except ModelError:
            raise
        except Exception as exc:           # garbage from the peer: any error, even memory
            raise ModelError(f"cannot use the Dask scheduler at {self.address}: "
                             f"{type(exc).__name__}: {brief(str(exc), 120)}; is it a Dask "
                             "scheduler of a compatible version?") from None

    def map_unordered(self, fn, tasks):
        """At most ``DASK_WINDOW`` tasks submitted at once; every wait bounded."""
        pending = {}
        try:
            for i, f in _windowed(enumerate(tasks), DASK_WINDOW, pending,
                                  lambda item: self.client.submit(fn, item[1], pure=False),
                                  self._wait_some):
                yield i, self._result(f)
        finally:
            self._cancel([f for f in pending if not f.done()])

    def _wait_some(self, futures):
        """Some finished ``futures``; while none finishes, every ``timeout`` seconds the
        scheduler must answer (and have workers, after ``timeout`` without)."""
        from dask.distributed import wait
        idle_since = None
        while True:
            try:
                return wait(futures, timeout=self.timeout, return_when="FIRST_COMPLETED").done
            except TimeoutError:
                if self.address is None:
                    continue
                workers = self._workers()
                if workers:
                    idle_since = None
                elif idle_since is None:
                    idle_since = time.monotonic()
                elif time.monotonic() - idle_since >= self.timeout:
                    raise ModelError(f"the Dask scheduler at {self.address} has had no "
                                     f"workers for {self.timeout:g} s; start some with "
                                     f"`dask worker {self.address}`") from None

    def _workers(self):
        """The number of workers the scheduler reports, asked within the timeout."""
        try:
            info = self.client.sync(self.client.scheduler.identity,
                                    callback_timeout=self.timeout)
        except Exception as exc:
            raise ModelError(f"the Dask scheduler at {self.address} stopped answering "
                             f"(no answer within {self.timeout:g} s: {type(exc).__name__}); "
                             "is it still running?") from None
        return len(info.get("workers", {})) if isinstance(info, dict) else 0

    def _result(self, future):
        """A finished member's row, fetched within the timeout; a member's own exception
        is raised as it is."""
        if future.status == "error":
            return future.result()
        try:
            return future.result(timeout=self.timeout)
        except (TimeoutError, OSError, asyncio.CancelledError, cf.CancelledError) as exc:
            raise ModelError(f"lost the result of a member from the Dask scheduler at "
                             f"{self.address or 'the local cluster'} "
                             f"({type(exc).__name__}; waited at most {self.timeout:g} s)") \
                from None

    def _cancel(self, futures):
        if futures:
            try:
                _within(self.timeout, lambda: self.client.cancel(futures), "")
            except Exception:                  # a lost scheduler forgets them anyway
                pass

    def close(self):
        try:
            _within(2 * self.timeout, lambda: self.client.close(timeout=self.timeout), "")
        except Exception:                      # closing a lost scheduler's client: no more
            pass
        if self.cluster is not None:
            self.cluster.close()
