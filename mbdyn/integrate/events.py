"""Events of a run: zero crossings of a condition, given as text (the model files' syntax,
read by the safe parser of ``mbdyn.elements.expressions``), as a sympy expression of ``t`` and the
coordinate and speed names, or as a function ``g(t, q, u)``; and the records a run keeps.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import ModelError


@dataclass(frozen=True)
class Event:
    """A zero crossing of ``condition``; ``direction`` +1 (rising), -1 (falling) or 0
    (either; a text condition ``"theta >= 1"`` implies rising); a ``terminal`` event stops
    the run.  ``condition``: text such as ``"theta >= pi/2"``, a sympy expression of ``t``
    and the model's coordinate and speed names (a crossing of zero), or ``g(t, q, u)``
    returning a signed number (never a bool: its crossing could not be located)."""
    name: str
    condition: object
    terminal: bool = False
    direction: int | None = 0

    def __post_init__(self):
        if self.direction not in (None, 0, 1, -1):
            raise ModelError(f"event {self.name!r}: direction must be +1 (rising), -1 "
                             f"(falling) or 0 (either), got {self.direction!r}")


class EventRecord(tuple):
    """An event that occurred: unpacks as ``(name, t)`` (``for name, t in res.events``),
    and carries the state there: ``.name``, ``.t``, ``.q``, ``.u`` (arrays), ``.state``
    (``{name: value}``)."""

    def __new__(cls, name, t, q=None, u=None, names=()):
        rec = super().__new__(cls, (name, float(t)))
        rec.q = None if q is None else np.asarray(q, dtype=float).copy()
        rec.u = None if u is None else np.asarray(u, dtype=float).copy()
        rec._names = tuple(names)
        return rec

    @property
    def name(self):
        return self[0]

    @property
    def t(self):
        return self[1]

    @property
    def state(self):
        if self.q is None:
            return {}
        return dict(zip(self._names, np.concatenate([self.q, self.u]).tolist()))

    def __reduce__(self):
        return (EventRecord, (self[0], self[1], self.q, self.u, self._names))


class CompiledCondition:
    """``g(t, q, u)`` of a sympy condition ``g`` over ``args`` (``t``, then the model's
    coordinate and speed symbols): evaluated in compiled code by its program
    (``mbdyn.compiled.programs.condition_program``), the same program the compiled loops run after
    every step; by numpy when the stack machine cannot evaluate it (``program`` is
    ``None``)."""

    def __init__(self, g, args, text):
        from ..compiled.programs import condition_program
        self.g, self.args, self.text = g, tuple(args), text
        self.program = condition_program(g, {s.name: k for k, s in enumerate(self.args[1:])})
        self._fn = None
        self._stack = None

    @property
    def fn(self):
        """The numpy function ``fn(t, *q, *u)`` of the condition."""
        if self._fn is None:
            import sympy
            self._fn = sympy.lambdify(self.args, self.g, modules="numpy")
        return self._fn

    def __call__(self, t, q, u):
        if self.program is None:
            return float(self.fn(t, *q, *u))
        from ..kernels.programs import STACK, evaluate
        if self._stack is None:
            self._stack = np.empty(STACK)
        y = np.concatenate((np.asarray(q, dtype=float).ravel(),
                            np.asarray(u, dtype=float).ravel()))
        self._check_size(y.shape[0])
        ops, consts = self.program
        return float(evaluate(ops, consts, 0, len(ops), float(t), y, self._stack))

    def rows(self, ts, ys):
        """The condition at every row ``(ts[i], ys[i])`` of a motion (``ys`` rows
        ``[q, u]``); ``None`` when it cannot be evaluated on whole columns."""
        ts = np.ascontiguousarray(ts, dtype=float)
        if self.program is not None:
            from ..kernels.events import condition_rows
            from ..kernels.programs import STACK
            ys = np.ascontiguousarray(ys, dtype=float)
            if ys.ndim != 2 or len(ys) != len(ts):
                raise ModelError(f"condition {self.text!r}: expected one state row per time "
                                 f"({len(ts)}), got states of shape {ys.shape}")
            self._check_size(ys.shape[1])
            out = np.empty(ts.shape[0])
            ops, consts = self.program
            condition_rows(ops, consts, 0, len(ops), ts, ys, np.empty(STACK), out)
            return out
        try:
            v = np.asarray(self.fn(ts, *np.asarray(ys).T), dtype=float)
        except (TypeError, ValueError):
            return None
        return np.broadcast_to(v, ts.shape).copy() if v.shape in ((), ts.shape) else None

    def _check_size(self, size):
        """The compiled program reads ``y`` unchecked: refuse a state of another size."""
        if size != len(self.args) - 1:
            raise ModelError(f"condition {self.text!r}: expected q and u of "
                             f"{len(self.args) - 1} values in all (the model's coordinates "
                             f"and speeds), got {size}")

    def __getstate__(self):
        return {**self.__dict__, "_fn": None, "_stack": None}

    def __repr__(self):
        return f"<condition {self.text!r}>"


def sympy_condition(g, model, text):
    """The ``CompiledCondition`` of ``g``, a sympy expression of ``t`` and the model's
    coordinate and speed names (parameters already substituted)."""
    import sympy
    args = [sympy.Symbol(n) for n in ("t",) + model.coordinates + model.speeds]
    g = g.subs({s: sympy.Symbol(s.name) for s in g.free_symbols})
    return CompiledCondition(g, args, text)


def compile_condition(condition, model, name):
    """``(g(t, q, u), implied direction or None)`` of a condition given as text, sympy or a
    function."""
    import sympy

    from ..elements.expressions import ExpressionError, parse_condition, symbol
    order = ("t",) + model.coordinates + model.speeds
    if isinstance(condition, CompiledCondition):
        # compiled for a model: it reads the state by position, so it is recompiled for
        # another order of coordinates and speeds
        if tuple(s.name for s in condition.args) == order:
            return condition, None
        unknown = sorted(s.name for s in condition.g.free_symbols if s.name not in order)
        if unknown:
            raise ModelError(f"event {name!r}: its condition {condition.text!r} uses "
                             f"{', '.join(unknown)}, which are not t, coordinates or speeds "
                             "of this model")
        return sympy_condition(condition.g, model, condition.text), None
    if callable(condition) and not isinstance(condition, sympy.Basic):
        return condition, None
    names = {n: symbol(n) for n in order}
    names.update({n: symbol(n) for n in model.parameters if n not in names})
    implied = None
    if isinstance(condition, str):
        try:
            g, implied = parse_condition(condition, names)
        except ExpressionError as exc:
            raise ModelError(f"event {name!r}: {exc}") from None
        text = condition
    elif isinstance(condition, sympy.Basic):
        if isinstance(condition, sympy.core.relational.Relational):
            g = condition.lhs - condition.rhs
            implied = 1 if isinstance(condition, (sympy.GreaterThan, sympy.StrictGreaterThan)) \
                else -1 if isinstance(condition, (sympy.LessThan, sympy.StrictLessThan)) \
                else None
        else:
            g = condition
        unknown = sorted(s.name for s in g.free_symbols if s.name not in names)
        if unknown:
            raise ModelError(f"event {name!r}: its condition uses {', '.join(unknown)}, which "
                             f"are not t, coordinates, speeds or parameters of the model")
        text = str(condition)
    else:
        raise ModelError(f"event {name!r}: the condition must be text such as 'theta >= 1', "
                         "a sympy expression, or a function g(t, q, u)")
    g = g.subs({s: model.parameters[s.name] for s in g.free_symbols
                if s.name in model.parameters})
    return sympy_condition(g, model, text), implied


def as_event(e, model):
    """An ``Event`` whose condition is a function ``g(t, q, u)``, from an ``Event``, a
    dict or a tuple; text and sympy conditions compiled, the implied direction applied."""
    if isinstance(e, dict):
        e = Event(**e)
    elif isinstance(e, (tuple, list)):
        e = Event(*e)
    elif not isinstance(e, Event):
        raise ModelError(f"event {e!r}: give an mb.Event(name, condition, terminal, direction)")
    if e.direction not in (None, 0, 1, -1):
        raise ModelError(f"event {e.name!r}: direction must be +1 (rising), -1 (falling) or "
                         f"0 (either), got {e.direction!r}")
    g, implied = compile_condition(e.condition, model, e.name)
    direction = e.direction
    if implied is not None:
        if direction not in (0, None, implied):
            raise ModelError(f"event {e.name!r}: direction {direction} contradicts the "
                             f"condition {e.condition!r}, which fires when it becomes true")
        direction = implied
    return Event(e.name, g, bool(e.terminal), int(direction or 0))


def check_conditions(events, model, t, q, u):
    """Evaluate each condition once at the start: a bool is refused (its crossing cannot be
    located), a non-number or NaN is named."""
    for e in events:
        try:
            v = e.condition(t, q, u)
        except Exception as exc:
            raise ModelError(f"event {e.name!r}: its condition failed at the initial state: "
                             f"{type(exc).__name__}: {exc}") from None
        if isinstance(v, (bool, np.bool_)):
            raise ModelError(f"event {e.name!r}: the condition returned {v!r}, a bool; return "
                             "a signed quantity whose zero crossing is the event (e.g. q[0] "
                             "rather than q[0] < 0), or give the condition as text, "
                             "'theta < 0'")
        try:
            v = float(v)
        except (TypeError, ValueError):
            raise ModelError(f"event {e.name!r}: the condition returned {v!r}, not a "
                             "number") from None
        if not math.isfinite(v):
            raise ModelError(f"event {e.name!r}: the condition is {v} at the initial state; "
                             "it must be a finite number (check for divisions by zero)")
