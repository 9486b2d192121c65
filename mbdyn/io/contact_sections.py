"""The sections of a model file that add contacts between shapes: ``[[shapes]]`` (contact
shapes on bodies; not the drawing ``shape`` of a body) and ``[[contacts]]`` (contact
elements between them), read through the ``SceneBuilder`` ``b`` and added to
``b.system`` (docs/contact.md).
"""
from __future__ import annotations

from .system_sections import _orientation

#: keys read as vectors; as axes (a name or a vector)
VECTORS = ("position", "half_sizes", "sizes")
AXES = ("normal", "axis")


def add_shapes(b):
    """``[[shapes]]``: each table's keys handed to ``System.add_shape``."""
    specs = []
    for path, sh, name in b.entries("shapes", "shape"):
        kind = b.required(sh, "kind", path, "shape")
        body = b.required(sh, "body", path, "shape")
        kw = {}
        for key, value in sh.items():
            where = path + (key,)
            if key in ("name", "kind", "body"):
                continue
            if key in VECTORS:
                kw[key] = b.pvector(value, where)
            elif key in AXES:
                kw[key] = value if isinstance(value, str) else b.pvector(value, where)
            elif key == "orientation":
                kw[key] = _orientation(b, value, where)
            elif key == "profile":
                kw[key] = b.numbers(value, where)
            else:
                kw[key] = b.pval(value, where)
        with b.engine(path):
            b.system.add_shape(name, kind, body, **kw)
        specs.append(dict(sh))
    return specs


def add_contacts(b):
    """``[[contacts]]``: each table's keys handed to ``System.add_contact``."""
    specs = []
    for path, ct, name in b.entries("contacts", "contact"):
        kw = {key: (value if key in ("pairs", "group", "broad_phase")
                    else b.pval(value, path + (key,)))
              for key, value in ct.items() if key != "name"}
        with b.engine(path):
            b.system.add_contact(name, **kw)
        specs.append(dict(ct))
    return specs
