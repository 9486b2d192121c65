"""The model file a sweep runs: read once (``model_text``), then loaded for each member
from that text with the member's overrides (``load_member``).

Members are model files, so loading one imports ``mbdyn.io`` -- lazily, inside these
functions; with ``grid.parse_range``, which reads values as ``--set`` does, the only
places where *analysis* reaches up to *io* (tests/test_layers.py lists both).
"""
from __future__ import annotations

import warnings


def _triples(fixed, overrides):
    """``(path, value, origin)`` for ``load_model``: the fixed ones, then the member's."""
    return ([(p, v, f"fixed {p}={v!r}") for p, v in fixed]
            + [(p, v, f"sweep {p}={v!r}") for p, v in overrides])


def load_member(name, text, fixed, member):
    """The ``Scene`` of one ``member`` of the model ``text`` (named ``name`` in messages; no
    file is written), with the ``fixed`` overrides and then the member's; warnings are
    ignored."""
    from ...io.loader import load_model
    over = _triples(fixed, member["overrides"])
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return load_model(name, case=member["case"], overrides=over, text=text)


def load_task(task, member):
    """The ``Scene`` of one member, from the model text the task carries (no file is
    written: messages name the model file the sweep was given)."""
    return load_member(task["model_name"], task["model_text"], task["fixed"], member)


def model_text(path):
    """The model file's text, read once as ``load_model`` reads a file (a regular file,
    bounded, UTF-8), newlines as a text-mode read gives them: every member gets it."""
    from ...io.loader import decode_text, read_bytes
    text = decode_text(read_bytes(path), str(path))
    return text.replace("\r\n", "\n").replace("\r", "\n")
