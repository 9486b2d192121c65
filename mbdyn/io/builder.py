"""From a merged, shape-checked document to the fields of a ``Scene``: ``SceneBuilder``
reads the values (numbers, expressions of parameters, vectors) and the parameters, builds
the ``System`` section by section (``mbdyn.io.system_sections``), compiles the ``Model``
and reads the initial state (``initial``), the run's settings and outputs (``settings``)
and the events (``events``).  Every error is a ``ModelFileError`` at the key it concerns.
"""
from __future__ import annotations

import contextlib
import os
import warnings

import sympy

from .. import limits
from ..assembly.system import System
from ..elements.values import t as TIME
from ..errors import ModelError, ModelWarning
from .errors import ModelFileError
from .events import read_events
from .expressions import ExpressionError, parse, symbol, to_float
from .initial import read_initial
from .settings import read_outputs, read_simulation
from .system_sections import add_actuators, add_bodies, add_forces, add_joints, add_loads
from .contact_sections import add_contacts, add_shapes
from .urdf.section import add_section, read_section


class SceneBuilder:
    """Builds System, Model and the Scene's fields from a merged, shape-checked document."""

    def __init__(self, path, doc, checker, effects=None, urdf_text=None):
        self.effects_override = effects
        self.urdf_text = urdf_text   # a .urdf file's text, already read (a sweep's)
        self.path = path
        self.file = str(path)
        self.doc = doc
        self.checker = checker
        self.emitted = []            # (message, category) to re-emit once

    # -- helpers
    def error(self, path, problem):
        return self.checker.error(path, problem)

    @contextlib.contextmanager
    def engine(self, path):
        """Engine errors (``ModelError``) become file errors at ``path``."""
        try:
            yield
        except ModelFileError:
            raise
        except ModelError as exc:
            raise self.error(path, str(exc)) from None

    def required(self, table, key, path, what):
        if key not in table:
            raise self.error(path, f"{key} is missing; every {what} needs {key} = ...")
        return table[key]

    def entries(self, section, what):
        """``(path, table, name)`` of each entry of the array ``[[section]]``, its name
        required (``what`` names an entry in the message)."""
        for i, table in enumerate(self.doc.get(section, [])):
            path = (section, i)
            yield path, table, self.required(table, "name", path, what)

    def expr(self, value, path, names):
        """sympy expression of a number or expression string, names resolved."""
        if isinstance(value, (int, float)) and not isinstance(value, bool):
            return sympy.Float(value) if isinstance(value, float) else sympy.Integer(value)
        try:
            return parse(value, names)
        except ExpressionError as exc:
            raise self.error(path, str(exc)) from None

    def number(self, value, path, positive=False, nonnegative=False):
        """A float from a number or an expression of parameters."""
        v = self.evaluated(value, path)[1]
        if positive and not v > 0:
            raise self.error(path, f"must be > 0, got {v:g}")
        if nonnegative and v < 0:
            raise self.error(path, f"must be >= 0, got {v:g}")
        return v

    def pval(self, value, path):
        """A value for the engine: a float, or the sympy expression of parameters."""
        e, v = self.evaluated(value, path)
        return e if e.free_symbols else v

    def evaluated(self, value, path):
        """``(expression, float)`` of a number or an expression of parameters; the float
        finite and within the limits on magnitudes."""
        e = self.expr(value, path, self.P)
        try:
            v = to_float(e, self.values)
        except ExpressionError as exc:
            raise self.error(path, f"{value!r} does not give a finite real number: {exc}") \
                from None
        self.bounded(v, path)
        return e, v

    def bounded(self, v, path):
        problem = limits.magnitude_problem(v)
        if problem:
            raise self.error(path, problem)

    def pvector(self, value, path, default=(0.0, 0.0, 0.0)):
        if value is None:
            return list(default)
        return [self.pval(v, path + (k,)) for k, v in enumerate(value)]

    def numbers(self, value, path, read=None):
        """An array of values, or an array of rows of values, each read with ``read``
        (default ``number``) at its own key path."""
        read = read or self.number
        if value and all(isinstance(r, list) for r in value):
            return [[read(v, path + (r, c)) for c, v in enumerate(row)]
                    for r, row in enumerate(value)]
        return [read(v, path + (k,)) for k, v in enumerate(value)]

    # -- the build
    def compiled_terms(self, model):
        """``[model] compiled_terms = true``: the flexible bodies' terms by the compiled
        function (``FlexibleModel.compiled_terms``); a warning on a model without
        flexible bodies, the key named where the model cannot take them."""
        if not hasattr(type(model), "compiled_terms"):
            warnings.warn(f"{self.file}: [model] compiled_terms: the model has no flexible "
                          "bodies, whose terms it chooses; it changes nothing here",
                          ModelWarning)
            return
        try:
            model.compiled_terms = True
        except ModelError as exc:
            raise self.error(("model", "compiled_terms"), f"{exc}") from None

    def build(self):
        """The ``Scene``'s fields; the warnings met on the way, each once, in ``emitted``
        as ``(message, category)``."""
        doc = self.doc
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            self.parameters()
            model_table = doc.get("model", {})
            robot = read_section(self, model_table)
            name = model_table.get("name") or (robot[1].name if robot else os.path.splitext(
                os.path.basename(self.file))[0])
            system = self.add_system(name, model_table, robot)
            effects = self.effects()
            with self.engine(()):
                model = system.compile(effects=effects)
            self.model = model
            if model_table.get("compiled_terms"):
                self.compiled_terms(model)
            q0, u0, initial = read_initial(self)
            settings = read_simulation(self)
            outputs = read_outputs(self)
            events, event_specs = read_events(self, q0, u0)
        messages = []
        for text, category in ([(str(w.message), w.category) for w in caught]
                               + [(text, ModelWarning) for text in model.warnings]):
            if text not in (m for m, _ in messages):
                messages.append((text, category))
        self.emitted = messages
        return dict(path=self.file, name=name, description=model_table.get("description", ""),
                    system=system, model=model, q0=q0, u0=u0, initial=initial,
                    parameters=dict(self.values), settings=settings, outputs=outputs,
                    events=events, event_specs=event_specs,
                    warnings=tuple(m for m, _ in messages), document=doc,
                    joint_specs=self.joint_specs, load_specs=self.load_specs,
                    body_specs=self.body_specs, force_specs=self.force_specs,
                    urdf=self.urdf)

    def add_system(self, name, model_table, robot=None):
        """The ``System`` of ``[model]``, the URDF ``robot`` it includes (``(path,
        Robot)``), its bodies, joints, loads and force elements; the names a load may use
        (``PTQ``: parameters, ``t``, free coordinates and speeds)."""
        gravity = self.pvector(model_table.get("gravity"), ("model", "gravity"),
                               default=(0.0, 0.0, -9.81))
        with self.engine(("model",)):
            system = System(name, gravity=gravity, parameters=self.values)
        self.system = system
        self.urdf, bodies, joints = add_section(self, robot)
        self.body_specs = bodies + add_bodies(self)
        self.joint_specs = joints + add_joints(self)
        self.names_q = {}
        for j in system.joints.values():
            if j.drive is None:
                for n in j.coordinates + j.speeds:
                    self.names_q[n] = symbol(n)
        self.PTQ = dict(self.PT)
        self.PTQ.update(self.names_q)
        self.load_specs = add_loads(self)
        self.force_specs = add_forces(self) + add_actuators(self)
        self.shape_specs = add_shapes(self)
        self.contact_specs = add_contacts(self)
        return system

    def parameters(self):
        raw = self.doc.get("parameters", {})
        self.P = {n: symbol(n) for n in raw}
        exprs = {n: self.expr(v, ("parameters", n), self.P) for n, v in raw.items()}
        values = {}
        pending = dict(exprs)
        while pending:
            progressed = False
            for n, e in list(pending.items()):
                deps = {s.name for s in e.free_symbols}
                if n in deps:
                    raise self.error(("parameters", n), "refers to itself; give it a value "
                                     "that does not use its own name")
                if deps <= values.keys():
                    try:
                        values[n] = to_float(e, values)
                    except ExpressionError as exc:
                        raise self.error(("parameters", n), f"{raw[n]!r} does not give a "
                                         f"finite real number: {exc}") from None
                    self.bounded(values[n], ("parameters", n))
                    del pending[n]
                    progressed = True
            if not progressed:
                raise self.error(("parameters", next(iter(pending))), "parameters "
                                 f"{', '.join(pending)} depend on each other in a cycle; "
                                 "give one of them a number")
        self.values = values
        self.PT = dict(self.P)
        self.PT["t"] = TIME

    def effects(self):
        """The file's ``[effects]`` then the caller's switches, checked by name."""
        from ..elements.effects import parse_effects
        known = self.system.effect_names()
        with self.engine(("effects",)):
            state = parse_effects(self.doc.get("effects"), known, where="")
        if self.effects_override is not None:
            try:
                state = parse_effects(self.effects_override, known, where="", base=state)
            except ModelError as exc:
                raise ModelFileError("--effects", "", str(exc)) from None
        return state
