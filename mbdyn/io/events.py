"""The ``[[events]]`` of a model file: each condition read as a function of the state
(``mbdyn.integrate.events``), its crossing direction from the comparison or the file,
checked at the initial state.
"""
from __future__ import annotations

import math
import warnings

from ..errors import ModelWarning
from ..integrate.contacts import contact_event
from ..integrate.events import Event
from ..integrate.events import sympy_condition as _condition
from .expressions import ExpressionError, parse_condition
from .keys import DIRECTIONS

#: a crossing direction in words: 1 "rising", -1 "falling", 0 "either"
WORDS = {number: word for word, number in DIRECTIONS.items()}


def read_events(b, q0, u0):
    """``(events, specs)``: the ``mb.Event``s of the builder ``b``'s document, and each as
    the file wrote it (name, condition, terminal, direction)."""
    model = b.model
    events, specs = [], []
    seen = set()
    for path, e, name in b.entries("events", "event"):
        if name in seen:
            raise b.error(path + ("name",), f"a second event named {name!r}; event "
                          "names must differ")
        seen.add(name)
        if "contact" in e:
            event = _contact_event(b, path, e, name)
            events.append(event)
            specs.append({"name": name, "condition": f"gap of contact {e['contact']!r}",
                          "terminal": event.terminal, "direction": WORDS[event.direction]})
            continue
        text = b.required(e, "condition", path, "event")
        try:
            g, implied = parse_condition(text, b.PTQ)
        except ExpressionError as exc:
            raise b.error(path + ("condition",), str(exc)) from None
        explicit = e.get("direction")
        if isinstance(explicit, str):
            explicit = DIRECTIONS[explicit]
        if explicit is not None and implied is not None and explicit != implied:
            raise b.error(path + ("direction",), f"{WORDS[explicit]!r} contradicts the "
                          f"condition {text!r}, which fires when it becomes true "
                          f"({WORDS[implied]}); remove direction or write the condition "
                          "the other way round")
        direction = explicit if explicit is not None else (implied or 0)
        g = g.subs({s: b.values[s.name] for s in g.free_symbols
                    if s.name in b.values})
        cond = _condition(g, model, text)
        try:
            g0 = cond(0.0, q0, u0)
        except (ArithmeticError, ValueError, TypeError) as exc:
            raise b.error(path + ("condition",), f"cannot be evaluated at the initial "
                          f"state: {exc}") from None
        if not math.isfinite(g0):
            raise b.error(path + ("condition",), "is not finite at the initial state; "
                          "check for divisions by zero")
        holds = (g0 >= 0 and direction > 0) or (g0 <= 0 and direction < 0)
        if holds:
            warnings.warn(f"{b.file}: events[{path[1]}] ({name!r}): the condition {text!r} "
                          "already holds at the initial state; the event fires only when "
                          "it becomes true again", ModelWarning)
        terminal = bool(e.get("terminal", False))
        events.append(Event(name, cond, terminal, int(direction)))
        specs.append({"name": name, "condition": text, "terminal": terminal,
                      "direction": WORDS[direction]})
    return events, specs


def _contact_event(b, path, e, name):
    """An event on the gap of a contact: ``contact = "NAME"`` (a contact element) or
    ``["SHAPE", "SHAPE"]`` (a pair); the onset (``"falling"``, the default), the release
    (``"rising"``) or both (``"either"``)."""
    if "condition" in e:
        raise b.error(path + ("contact",), "an event takes a condition or a contact, not "
                      "both")
    which = e["contact"]
    if isinstance(which, list) and len(which) != 2:
        raise b.error(path + ("contact",), "must be a contact's name or two shape names")
    direction = e.get("direction", -1)
    direction = DIRECTIONS[direction] if isinstance(direction, str) else direction
    with b.engine(path + ("contact",)):
        return contact_event(b.model, which if isinstance(which, str) else tuple(which),
                             name, bool(e.get("terminal", False)), int(direction))
