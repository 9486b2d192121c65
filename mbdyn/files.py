"""How mbdyn writes its output files: the one place every writer goes through.

* **Whole or not at all.**  A file is written beside its target under a hidden temporary
  name, ``.NAME.PID.RANDOM.tmp`` (plus the target's extension, which picture and movie
  writers read), flushed and synced, then renamed over the target: a reader sees the old
  file or the new one, never a part, and an interruption removes the temporary.
* **A symbolic link at the target is replaced, never written through.**  The rename puts
  the new file where the link was; the file the link pointed at (perhaps outside the
  output folder) is left as it was.  Every output behaves so: results, pictures,
  animations, sweep tables and their plots, Campbell diagrams.
* **Modes as the user's umask makes them** (``0666 & ~umask``: 0644 under the usual 022),
  as ``open()`` would, not the 0600 of a temporary file.
* **Messages name the target the user gave**, never the temporary.
* ``check_target`` checks a target before any work: its format, that it is not a folder,
  that its folder exists and is writable.
* ``signals_held`` keeps SIGINT and SIGTERM out of a few renames that belong together
  (a results CSV and its JSON): a signal that arrives meanwhile acts after them.
* ``TableLock``: an advisory lock beside a file that one process writes for a long time
  (a sweep's table), so that a second writer is refused instead of replacing it.
"""
from __future__ import annotations

import contextlib
import os
import signal
import tempfile
import threading

from .errors import ModelError

TEMPORARY_SUFFIX = ".tmp"


def check_target(path, formats=None, what="output", option=None):
    """The extension of the output ``path``, checked before any work: one of ``formats``
    (if given), not a folder, in an existing folder this process may write into.
    ``option`` names where the path came from (``--plot-file``) in the message."""
    name = f"{option} {path}" if option else str(path)
    ext = os.path.splitext(str(path))[1].lower()
    if formats is not None and ext not in formats:
        raise ModelError(f"{name}: unknown {what} format {ext or '(none)'!r}; use one of "
                         f"{', '.join(formats)}")
    if os.path.isdir(path) and not os.path.islink(path):
        raise ModelError(f"{name}: is a folder; give a file name inside it")
    directory = os.path.dirname(os.path.abspath(path))
    if not os.path.isdir(directory):
        raise ModelError(f"{name}: the folder {directory} does not exist")
    if not os.access(directory, os.W_OK | os.X_OK):
        raise ModelError(f"{name}: cannot write into {directory} (permission denied)")
    return ext


def _target_error(exc, path):
    """``exc`` (an ``OSError`` about a temporary) retold about the target ``path``."""
    return OSError(exc.errno, exc.strerror or str(exc), str(path))


def temporary(path, keep_extension=False):
    """A new hidden temporary beside ``path``, ``.NAME.PID.RANDOM.tmp`` (``+ .EXT`` with
    ``keep_extension``), with the permissions a new file gets; returns ``(fd, tmp)``."""
    directory = os.path.dirname(os.path.abspath(path))
    suffix = TEMPORARY_SUFFIX + (os.path.splitext(str(path))[1] if keep_extension else "")
    try:
        fd, tmp = tempfile.mkstemp(prefix=f".{os.path.basename(path)}.{os.getpid()}.",
                                   suffix=suffix, dir=directory)
    except OSError as exc:
        raise _target_error(exc, path) from None
    os.chmod(tmp, 0o666 & ~current_umask())    # mkstemp's 0600 -> what open() would give
    return fd, tmp


def current_umask():
    """The process's umask, read without changing it where the system tells it
    (``/proc/self/status``: setting it to read it back would, for that instant, give a
    file another thread creates the wrong mode); else set and restored."""
    try:
        with open("/proc/self/status", encoding="ascii") as fh:
            for line in fh:
                if line.startswith("Umask:"):
                    return int(line.split()[1], 8)
    except (OSError, ValueError, IndexError):
        pass
    umask = os.umask(0o022)
    os.umask(umask)
    return umask


def remove(path):
    """Remove ``path`` if it is there (no error if it is not)."""
    try:
        os.unlink(path)
    except OSError:
        pass


def replace(tmp, path):
    """Rename the finished temporary ``tmp`` over ``path`` (a link there is replaced, not
    followed); on failure the temporary is removed and the error names ``path``."""
    try:
        os.replace(tmp, path)
    except BaseException as exc:
        remove(tmp)
        if isinstance(exc, OSError):
            raise _target_error(exc, path) from None
        raise


@contextlib.contextmanager
def replacing(path):
    """``with replacing(path) as tmp:`` write the file ``tmp`` (it has ``path``'s
    extension); when the block ends without error it is renamed over ``path``, otherwise
    removed."""
    fd, tmp = temporary(path, keep_extension=True)
    os.close(fd)
    try:
        yield tmp
    except BaseException:
        remove(tmp)
        raise
    replace(tmp, path)


def write_temporary(path, data):
    """``data`` (text, or bytes) in a flushed, synced temporary beside ``path``; returns the
    temporary's path (removed again on any error)."""
    fd, tmp = temporary(path)
    try:
        with os.fdopen(fd, "wb" if isinstance(data, bytes) else "w",
                       **({} if isinstance(data, bytes) else {"encoding": "utf-8",
                                                              "newline": ""})) as fh:
            fh.write(data)
            fh.flush()
            os.fsync(fh.fileno())
    except BaseException as exc:
        remove(tmp)
        if isinstance(exc, OSError):
            raise _target_error(exc, path) from None
        raise
    return tmp


def atomic_write(path, data):
    """Write ``data`` (text or bytes) to ``path`` whole or not at all (see the module
    docstring); the temporary is removed on any error or interruption."""
    replace(write_temporary(path, data), path)


def remove_stale_temporaries(directory, names):
    """Remove temporaries ``.NAME.PID.*.tmp[.EXT]`` of ``names`` left in ``directory`` by a
    process that no longer runs (killed with SIGKILL mid-write)."""
    try:
        entries = os.listdir(directory)
    except OSError:
        return
    for entry in entries:
        for name in names:
            prefix = f".{name}."
            if not entry.startswith(prefix) or TEMPORARY_SUFFIX not in entry[len(prefix):]:
                continue
            pid = entry[len(prefix):].split(".", 1)[0]
            if pid.isdigit() and int(pid) != os.getpid() and not running(int(pid)):
                remove(os.path.join(directory, entry))


def running(pid):
    """Whether a process ``pid`` runs on this machine."""
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except OSError:
        return True
    return True


# --------------------------------------------------------------------------- signals

HELD_SIGNALS = (signal.SIGINT, signal.SIGTERM)


@contextlib.contextmanager
def signals_held():
    """SIGINT and SIGTERM that arrive inside the block act when it ends (a Python handler
    is called, a default action taken); for a few renames that must happen together.
    Only the main thread can hold them (elsewhere the block runs unprotected)."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    arrived = []
    previous = {sig: signal.getsignal(sig) for sig in HELD_SIGNALS}
    previous = {sig: h for sig, h in previous.items() if h is not None}   # None: set in C
    for sig in previous:
        signal.signal(sig, lambda signum, frame: arrived.append(signum))
    try:
        yield
    finally:
        for sig, handler in previous.items():
            signal.signal(sig, handler)
        for sig in dict.fromkeys(arrived):
            _deliver(sig, previous[sig])


def _deliver(sig, handler):
    """Act on a signal that was held, as its handler ``handler`` would have."""
    if callable(handler):
        handler(sig, None)
    elif handler == signal.SIG_DFL:
        os.kill(os.getpid(), sig)


# --------------------------------------------------------------------------- locks

class TableLock:
    """An advisory lock on ``path`` (a file one process writes for long): the file
    ``.NAME.lock`` beside it, holding the owner's process id and locked with ``flock``
    while the owner runs.  The kernel releases the lock when its owner ends however it
    ends, so the lock file of a dead process is stale and simply taken over.
    ``acquire()`` raises ``ModelError`` naming the owner if another process holds it;
    ``release()`` removes the lock file.  Without ``fcntl`` (Windows) nothing is locked.
    """

    def __init__(self, path, what="table"):
        self.path = str(path)
        self.what = what
        folder, name = os.path.split(os.path.abspath(self.path))
        self.lock_path = os.path.join(folder, f".{name}.lock")
        self.fd = None

    def acquire(self):
        try:
            import fcntl
        except ImportError:
            return self
        while self.fd is None:
            fd = os.open(self.lock_path, os.O_RDWR | os.O_CREAT | getattr(os, "O_NOFOLLOW", 0),
                         0o644)
            try:
                fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
            except OSError:
                owner = _read_owner(fd)
                os.close(fd)
                raise ModelError(f"{self.path}: another process{owner} is writing this "
                                 f"{self.what} now; wait for it to end or write elsewhere "
                                 f"(its lock is {self.lock_path})") from None
            if _same_file(fd, self.lock_path):
                os.ftruncate(fd, 0)
                os.write(fd, f"{os.getpid()}\n".encode())
                self.fd = fd
            else:                       # its last owner removed it meanwhile: again
                os.close(fd)
        return self

    def release(self):
        if self.fd is not None:
            remove(self.lock_path)
            os.close(self.fd)
            self.fd = None

    def __enter__(self):
        return self.acquire()

    def __exit__(self, *exc):
        self.release()


def _read_owner(fd):
    """`` (process N)`` from a lock file's content, or ``""``."""
    try:
        text = os.pread(fd, 32, 0).decode("ascii", "replace").strip()
    except OSError:
        return ""
    return f" (process {text})" if text.isdigit() else ""


def _same_file(fd, path):
    """Whether the open file ``fd`` is still the file at ``path``."""
    try:
        a, b = os.fstat(fd), os.stat(path, follow_symlinks=False)
    except OSError:
        return False
    return (a.st_dev, a.st_ino) == (b.st_dev, b.st_ino)
