"""The C entries of the hottest per-call methods (``kernels.fastcall``), made once a method
is called often.

A C entry's function compiles in 1-2 s on a machine that has not cached it yet (then it
loads in milliseconds).  A model whose mass matrix is asked for a few times (``mbdyn
info``, a script's one call) would pay that for nothing, so a method's first ``WARM`` calls
after its checked call take the Python fast path, counted by a ``Pending`` in the entry's
place; the next one makes the entry and puts it there.
"""
from __future__ import annotations

from ..kernels import fastcall
from .recycling import FREE

#: calls of a method on its Python fast path before its C entry is made
WARM = 200


class Pending:
    """Stands for the C entry of ``key`` on ``model`` until the method has been called
    ``WARM`` times: returns None (the caller's Python fast path answers), then makes the
    entry, stores it with ``store`` and calls it."""

    __slots__ = ("key", "arguments", "store", "calls")

    def __init__(self, key, arguments, store):
        self.key, self.arguments, self.store, self.calls = key, arguments, store, 0

    def __call__(self, *arrays):
        self.calls += 1
        if self.calls <= WARM:
            return None
        entry = self.make()
        return None if entry is None else entry(*arrays)

    def make(self):
        """The entry (None without the extension), stored in this one's place."""
        entry = fastcall.entry(self.key, *self.arguments)
        self.store(entry)
        return entry


def pending(model, key, packed, store):
    """What stands for ``key``'s C entry on ``packed`` (``(fb, ib)`` or ``(fb, ib,
    forces)``), to be stored by ``store``: a ``Pending``, or None where the extension is
    not built or switched off."""
    if not fastcall.enabled():
        return None
    forces = packed[2][1] if len(packed) > 2 else 0
    return Pending(key, (packed[0], packed[1], forces, model.nq, model.nu, FREE != -1),
                   store)
