"""What a running sweep says on stderr (``Progress``): a long sweep announced with an
estimate of its duration, and a counter on a terminal."""
from __future__ import annotations

import sys
import time

#: a sweep whose members left would take longer than this many seconds is announced on
#: stderr (members, estimated duration) once its first members have finished
ANNOUNCE_AFTER = 10.0
#: finished members timed before the estimate (fewer if the sweep is smaller, or if
#: ANNOUNCE_AFTER seconds pass first)
ESTIMATE_FROM = 3


class Progress:
    """What a sweep tells on stderr while it runs.

    * Once the first ``ESTIMATE_FROM`` members have finished (or ``ANNOUNCE_AFTER``
      seconds have passed), the time per member is measured -- between the first and the
      last finished member, so a worker's start-up does not count, or the first member's
      whole time if only one finished -- and the rest extrapolated; if it comes to more
      than ``ANNOUNCE_AFTER`` seconds, one line says how many members and about how long.
    * ``counter``: a plain counter line, rewritten in place at most five times a second:
      members done of all, time so far, about how long left.

    ``announce_after`` and ``estimate_from`` are those two bounds (``sweep`` passes the
    values ``mbdyn.analysis.sweep.ANNOUNCE_AFTER`` and ``ESTIMATE_FROM`` hold then).
    """

    def __init__(self, total, kept, counter, stream=None, clock=time.monotonic,
                 announce_after=ANNOUNCE_AFTER, estimate_from=ESTIMATE_FROM):
        self.total, self.kept, self.done = total, kept, kept
        self.announce_after, self.estimate_from = announce_after, estimate_from
        self.todo = total - kept
        self.counter = counter
        self.stream = stream if stream is not None else sys.stderr
        self.clock = clock
        self.start = clock()
        self.first = None                 # when the first member finished
        self.per_member = None            # seconds, once estimated
        self.shown = 0.0                  # when the counter was last written
        self.counted = False

    def update(self):
        """One more member finished."""
        now = self.clock()
        self.done += 1
        ran = self.done - self.kept
        if self.first is None:
            self.first = now
        if self.per_member is None and (ran >= min(self.estimate_from, self.todo)
                                        or now - self.start >= self.announce_after):
            self.per_member = ((now - self.first) / (ran - 1) if ran > 1
                               else now - self.start)
            left = self.per_member * (self.total - self.done)
            if left > self.announce_after:
                self._line(f"mbdyn sweep: {self.todo} members to run"
                           + (f" ({self.kept} kept from before)" if self.kept else "")
                           + f"; about {_duration(left)} left ({_duration(self.per_member)}"
                           f" a member, from the first {ran})")
        if self.counter and (now - self.shown >= 0.2 or self.done == self.total):
            self.shown = now
            left = (f", about {_duration(self.per_member * (self.total - self.done))} left"
                    if self.per_member is not None and self.done < self.total else "")
            self.stream.write(f"\rmbdyn sweep: {self.done}/{self.total} members, "
                              f"{_duration(now - self.start)}{left}   ")
            self.stream.flush()
            self.counted = True

    def _line(self, text):
        """``text`` as a line of its own (after the counter's line, if one is shown)."""
        self.stream.write(("\n" if self.counted else "") + text + "\n")
        self.stream.flush()
        self.counted = False

    def close(self):
        if self.counted:
            self.stream.write("\n")
            self.stream.flush()
            self.counted = False


def _duration(seconds):
    """A duration for people: ``0.2 s``, ``42 s``, ``3.5 min``, ``58 min``, ``1.5 h``,
    ``3.2 days``."""
    if seconds < 10:
        return f"{seconds:.2g} s"
    if seconds < 120:
        return f"{seconds:.0f} s"
    if seconds < 600:
        return f"{seconds / 60:.1f} min"
    if seconds < 7200:
        return f"{seconds / 60:.0f} min"
    if seconds < 172800:
        return f"{seconds / 3600:.1f} h"
    return f"{seconds / 86400:.1f} days"


class Callback:
    """``progress(done, total)`` called after each finished member (``done`` counts the
    members kept from before too)."""

    def __init__(self, function, total, kept):
        self.function, self.total, self.done = function, total, kept

    def update(self):
        self.done += 1
        self.function(self.done, self.total)

    def close(self):
        pass


class _Tqdm:
    """tqdm's bar over the members, on stderr."""

    def __init__(self, tqdm, total, kept):
        self.bar = tqdm(total=total, initial=kept, unit="member", desc="mbdyn sweep",
                        file=sys.stderr)

    def update(self):
        self.bar.update(1)

    def close(self):
        self.bar.close()


def tqdm_bar(total, kept):
    """A tqdm progress bar over the members if tqdm is installed, else ``None``."""
    try:
        from tqdm.auto import tqdm
    except ImportError:
        return None
    return _Tqdm(tqdm, total, kept)
