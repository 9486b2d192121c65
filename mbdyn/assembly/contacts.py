"""Contact shapes and contact elements added to a ``System`` (bound as its methods
``add_shape`` and ``add_contact``; records in ``mbdyn.elements.contacts``, docs/contact.md).
"""
from __future__ import annotations

from ..elements.contacts import make_contact, make_shape
from ..errors import ModelError

GROUND = "ground"


def add_shape(system, name, kind, body, **keys):
    """A contact shape named ``name`` of ``kind`` on ``body`` (or ``"ground"``):
    ``"sphere"`` (``radius``), ``"plane"`` (``normal``: the outward normal of the body's
    half-space; ``position``: a point of the plane), ``"box"`` (``half_sizes`` or ``sizes``,
    ``orientation``), ``"capsule"`` or ``"cylinder"`` (``radius``, ``length``, ``axis``),
    ``"cam"`` (``profile``: rows ``[angle, radius]``, ``axis``).  ``position`` (the shape's
    centre; default the body's origin) and the directions are in the body's axes.  Shapes
    are not drawing shapes (``add_body(shape=...)``): a contact element names them."""
    if name in system._shapes:
        raise ModelError(f"shape {name!r}: the name is already used by another shape; "
                         "choose another")
    if body != GROUND and (not isinstance(body, str) or body not in system.graph):
        raise ModelError(f"shape {name!r}: unknown body {body!r}; add it first with "
                         f"add_body or add_frame (known: "
                         f"{', '.join(n for n in system.graph if n != GROUND)}, ground)")
    system._shapes[name] = make_shape(name, kind, body, system.parameters, **keys)
    return name


def add_contact(system, name, pairs=None, group=None, *, stiffness=None, **keys):
    """A contact element between shapes: ``pairs`` (``[("ball1", "ball2"), ...]``) or
    ``group`` (shape names: every pair of them on different bodies, found by a sweep and
    prune of their bounding boxes unless ``broad_phase=False``).  The force is
    Hunt-Crossley's, ``k delta^exponent (1 + c delta')`` with ``c`` from the
    ``restitution`` at ``impact_speed``, with regularised Coulomb ``friction`` (``slip_speed``)
    -- as the floor contact's (``add_force(kind="contact")``).  Its name is an effect."""
    if name in system._forces or name in system._loads:
        raise ModelError(f"contact {name!r}: the name is already used by a force element "
                         "or a load; contacts, force elements and loads share one "
                         "namespace (their names are the scene's effects)")
    system._forces[name] = make_contact(name, system._shapes, system.parameters, pairs=pairs,
                                        group=group, stiffness=stiffness, **keys)
    return name
