"""Model files (TOML) -> ``System`` -> compiled ``Model`` -> a ready-to-run ``Scene``.

``load_model(path, case=None, overrides=None)`` reads the file with ``tomllib``, checks its
shape (``mbdyn.io.schema``), merges the chosen case and the overrides, then builds the
``System``: parameters become ``System(parameters=...)`` and every value written as an
expression of parameters is handed to the engine as a sympy expression of the parameter
symbols (the symbolic layer reads them); numbers stay numbers.  Errors are
``ModelFileError``: file, key path, what is wrong, what to change.  The format is
documented in ``docs/model-files.md``.
"""
from __future__ import annotations

import contextlib
import copy
import math
import os
import re
import stat
import tomllib
import warnings

import numpy as np
import sympy

from ..algorithms.forward_dynamics import METHODS as _METHODS
from .. import limits
from ..elements.values import t as TIME
from ..errors import ModelError, ModelWarning
from ..assembly.system import GROUND, System
from ..integrate.settings import DEFAULTS as SIMULATE_DEFAULTS
from ..integrate.settings import FIXED_STEP, INTEGRATORS
from ..integrate.events import Event
from ..integrate.simulation import simulate as _simulate
from ..integrate.events import sympy_condition as _condition
from ..elements.expressions import expanded_terms
from .errors import ModelFileError
from .expressions import ExpressionError, parse, parse_condition, symbol, to_float
from .schema import (DIRECTIONS, Checker, _suggest, apply_case, apply_override,
                     parse_set_value, scan_document, split_path)

#: The formulations a run can use -- the one list behind ``[simulation] method`` and
#: ``mbdyn run --method``.  Extend it here when a formulation is added.
METHODS = ("auto",) + tuple(_METHODS) + ("symbolic",)

#: ``[simulation]`` defaults.
DEFAULT_SIMULATION = dict(SIMULATE_DEFAULTS)     # one set of defaults (mbdyn.integrate.settings)
SIMULATE_KEYWORDS = ("t_end", "integrator", "method", "rtol", "atol", "dt", "max_step",
                     "output_dt", "progress", "events", "outputs", "points", "max_steps",
                     "max_samples", "max_wall_time")
BUDGETS = ("max_steps", "max_samples", "max_wall_time")


def read_document(path):
    """The parsed TOML of ``path``; errors name the file (and the line of a syntax error).

    Only regular files of at most ``limits.MAX_FILE_BYTES`` are read (a FIFO or a device
    such as ``/dev/zero`` would block or never end); the parsed document is then checked
    against the nesting and number limits (``scan_document``).
    """
    return parse_document(read_bytes(path), str(path))


def read_bytes(path):
    """The bytes of the model file ``path``: a regular file of at most
    ``limits.MAX_FILE_BYTES`` (errors name the file)."""
    file = str(path)
    try:
        # non-blocking open: a FIFO without a writer must not hang the reader
        fd = os.open(path, os.O_RDONLY | getattr(os, "O_NONBLOCK", 0))
        with os.fdopen(fd, "rb") as fh:
            info = os.fstat(fd)
            if not stat.S_ISREG(info.st_mode):
                raise ModelFileError(file, "", "is not a regular file (a FIFO, device or "
                                     "socket); give a .toml model file")
            if info.st_size > limits.MAX_FILE_BYTES:
                raise ModelFileError(file, "", f"is {info.st_size} bytes, more than a model "
                                     f"file may be ({limits.MAX_FILE_BYTES}); is it really a "
                                     "model file?")
            if hasattr(os, "set_blocking"):
                os.set_blocking(fd, True)
            data = fh.read(limits.MAX_FILE_BYTES + 1)
    except FileNotFoundError:
        raise ModelFileError(file, "", "no such file; check the path") from None
    except IsADirectoryError:
        raise ModelFileError(file, "", "is a directory; give a .toml model file") from None
    except PermissionError:
        raise ModelFileError(file, "", "cannot be read (permission denied)") from None
    except OSError as exc:
        raise ModelFileError(file, "", f"cannot be read ({exc.strerror or exc})") from None
    if len(data) > limits.MAX_FILE_BYTES:
        raise ModelFileError(file, "", f"grew beyond {limits.MAX_FILE_BYTES} bytes while "
                             "being read; give a finished model file")
    return data


def decode_text(data, file="<text>"):
    """The text of a model file's bytes ``data`` (UTF-8); errors name ``file``."""
    try:
        return data.decode("utf-8") if isinstance(data, bytes) else data
    except UnicodeDecodeError as exc:
        raise ModelFileError(file, "", f"is not UTF-8 text ({exc.reason} at byte "
                             f"{exc.start}); save it as UTF-8") from None


def parse_document(data, file="<text>"):
    """The parsed TOML of ``data`` (bytes or text); errors name ``file``."""
    text = decode_text(data, file)
    if "\x00" in text:
        raise ModelFileError(file, f"line {text.count(chr(10), 0, text.index(chr(0))) + 1}",
                             "holds a NUL character; is it a binary file?")
    try:
        doc = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        msg = str(exc)
        m = re.search(r"\(at line (\d+), column (\d+)\)", msg)
        if m:
            msg = msg[:m.start()].strip()
            raise ModelFileError(file, f"line {m.group(1)}", f"TOML syntax error: {msg} "
                                 f"(column {m.group(2)}); see docs/model-files.md") from None
        msg = re.sub(r"\s*\(at end of document\)", "", msg)
        raise ModelFileError(file, "end of file", f"TOML syntax error: {msg}") from None
    except RecursionError:
        raise ModelFileError(file, "", f"arrays or tables are nested too deeply (at most "
                             f"{limits.MAX_NESTING} levels)") from None
    except ValueError:                # an integer literal of thousands of digits
        raise ModelFileError(file, "", f"holds an integer literal of more than 4300 digits "
                             f"(at most {limits.MAX_INTEGER_DIGITS}); write it as a float "
                             "such as 1.5e30") from None
    scan_document(doc, file)
    return doc


def _normalise_overrides(overrides):
    """``{path: value}`` or an iterable of ``"PATH=VALUE"`` texts -> [(path, value, origin)]."""
    if overrides is None or (isinstance(overrides, (dict, list, tuple)) and not overrides):
        return []
    if not isinstance(overrides, (dict, list, tuple)):
        raise ModelError(f"load_model: overrides must be a mapping {{\"parameters.k\": 1.0}} "
                         f"or a list of \"PATH=VALUE\" texts, got {overrides!r}")
    out = []
    if isinstance(overrides, dict):
        for path, value in overrides.items():
            out.append((str(path), value, f"overrides[{str(path)!r}]"))
        return out
    for item in overrides:
        if isinstance(item, tuple) and len(item) == 3:
            out.append(item)
            continue
        text = str(item)
        if "=" not in text:
            raise ModelFileError("--set", text, "expected PATH=VALUE, e.g. parameters.b=0.3")
        path, value = text.split("=", 1)
        try:
            parsed = parse_set_value(value)
        except ValueError as exc:
            raise ModelFileError("--set", text, str(exc)) from None
        out.append((path.strip(), parsed, f"--set {text}"))
    return out


def load_model(path, case=None, overrides=None, effects=None, *, text=None):
    """Read a model file and return a ready-to-run ``Scene``.

    ``case``: the name of a ``[cases.NAME]`` table to apply (default: the file's
    ``model.default_case``, if any).  ``overrides``: ``{"parameters.Mz": -0.01, ...}``
    (values: numbers, booleans, arrays, or strings holding expressions or names) or an
    iterable of ``"PATH=VALUE"`` texts as ``mbdyn run --set`` takes them; applied after
    the case.  ``effects``: switches applied after the file's ``[effects]``, as
    ``--effects`` takes them (``"-gravity,-damper"``, a list, or a mapping; see
    ``mbdyn.effects``).  ``text``: the file's content, already read (a sweep's member
    carries its model's text, not a file); ``path`` then only names it.  Raises
    ``ModelFileError`` (a ``ModelError``) naming file and key.
    """
    if not isinstance(path, (str, os.PathLike)):
        raise ModelError(f"load_model: path must be the path of a .toml file, got {path!r}")
    if isinstance(overrides, str):
        raise ModelError("load_model: overrides must be a mapping {\"parameters.k\": 1.0} or "
                         "a list of \"PATH=VALUE\" texts, not one string")
    if text is not None and len(text) > limits.MAX_FILE_BYTES:
        raise ModelFileError(path, "", f"is more than a model file may be "
                             f"({limits.MAX_FILE_BYTES} characters)")
    doc = read_document(path) if text is None else parse_document(text, str(path))
    checker = Checker(path)
    checker.check_document(doc)
    default_case = doc.get("model", {}).get("default_case")
    cases = list(doc.get("cases", {}))
    if default_case is not None and default_case not in cases:
        raise checker.error(("model", "default_case"), f"no case {default_case!r}; "
                            f"{_suggest(default_case, cases)}the cases are: "
                            f"{', '.join(cases) or '(none)'}")
    chosen = case if case is not None else default_case
    if chosen is not None:
        merged = apply_case(doc, str(chosen), checker)
    else:
        merged = copy.deepcopy({k: v for k, v in doc.items() if k != "cases"})
    for path_text, value, origin in _normalise_overrides(overrides):
        apply_override(merged, path_text, value, checker, origin)
    checker.check_document(merged)
    builder = _SceneBuilder(path, merged, checker, effects)
    scene = builder.build()
    scene.case = chosen
    scene.overrides = list(_normalise_overrides(overrides))
    scene.effects_spec = effects
    scene.cases = tuple(cases)
    scene.default_case = default_case
    for message, category in builder.emitted:
        warnings.warn(message, category, stacklevel=2)
    return scene


class Scene:
    """A model file loaded and ready to run.

    ``model`` (the compiled ``Model``), ``system``, ``q0``/``u0`` (arrays in
    ``model.coordinates``/``model.speeds`` order), ``settings`` (the ``[simulation]``
    values), ``events`` (``mb.Event``s), ``outputs`` (reactions, energy, points),
    ``parameters`` (``{name: value}``), ``warnings`` (every validation warning), ``case``.
    ``simulate(**overrides)`` runs it.
    """

    def __init__(self, **fields):
        self.path = None
        self.name = ""
        self.description = ""
        self.case = None
        self.cases = ()
        self.default_case = None
        self.__dict__.update(fields)

    def __repr__(self):
        case = f", case {self.case!r}" if self.case else ""
        return f"<Scene {self.name!r} from {self.path}{case}: {self.model!r}>"

    def rebuild(self, overrides=None):
        """The same file, case, overrides and effects, with further ``overrides``
        (``{"parameters.Omega": 300}``) applied last: a new ``Scene``."""
        return load_model(self.path, case=self.case,
                          overrides=list(getattr(self, "overrides", [])) +
                          _normalise_overrides(overrides),
                          effects=getattr(self, "effects_spec", None))

    @property
    def initial_state(self):
        """``{name: value}`` of the initial coordinates and speeds."""
        names = self.model.coordinates + self.model.speeds
        return dict(zip(names, np.concatenate([self.q0, self.u0]).tolist()))

    def simulate(self, **overrides):
        """Integrate with the file's ``[simulation]`` settings, events and outputs.

        Keywords override them: ``t_end``, ``integrator``, ``method``, ``rtol``, ``atol``,
        ``dt``, ``max_step``, ``output_dt`` (sampling of the result), ``events`` (a list
        of ``mb.Event``), ``outputs`` (a tuple of ``"reactions"``/``"energy"``),
        ``points`` and ``progress`` (a callable ``progress(t)``).
        """
        unknown = set(overrides) - set(SIMULATE_KEYWORDS)
        if unknown:
            raise TypeError(f"Scene.simulate() got unknown keywords {sorted(unknown)}; "
                            f"known: {', '.join(SIMULATE_KEYWORDS)}")
        s = dict(self.settings)
        s.update({k: v for k, v in overrides.items()
                  if k in self.settings or k in ("t_end", "dt", "max_step", "output_dt")
                  or k in BUDGETS})
        if s.get("t_end") is None:
            raise ModelFileError(self.path, "simulation.t_end", "is not set; add t_end = ... "
                                 "to [simulation] or pass --t-end (t_end=...)")
        if s["integrator"] in FIXED_STEP and not s.get("dt"):
            raise ModelFileError(self.path, "simulation.dt", f"integrator {s['integrator']!r} "
                                 "is fixed-step: add dt = ... to [simulation] or pass --dt")
        outputs = overrides.get("outputs")
        if outputs is None:
            outputs = tuple(k for k, on in (("reactions", bool(self.outputs["reactions"])),
                                            ("energy", self.outputs["energy"])) if on)
        points = overrides.get("points", self.outputs["points"])
        fixed = s["integrator"] in FIXED_STEP
        t_eval = None
        budgets = {k: s[k] for k in BUDGETS if s.get(k) is not None}
        max_samples = budgets.get("max_samples", limits.MAX_SAMPLES)
        if s.get("output_dt") and not fixed:
            if s["t_end"] / s["output_dt"] + 1 > max_samples:
                raise ModelFileError(self.path, "simulation.output_dt", f"t_end / output_dt = "
                                     f"{s['t_end'] / s['output_dt']:.3g} samples, more than "
                                     f"max_samples = {max_samples}; give a larger output_dt "
                                     "or raise max_samples (--max-samples)")
            n = int(math.floor(s["t_end"] / s["output_dt"] + 1e-9))
            t_eval = np.linspace(0.0, n * s["output_dt"], n + 1)
            if t_eval[-1] < s["t_end"] - 1e-12:
                t_eval = np.append(t_eval, s["t_end"])
        kwargs = dict(integrator=s["integrator"], rtol=s["rtol"], atol=s["atol"],
                      dt=s.get("dt") if fixed else None, method=s["method"],
                      events=overrides.get("events", self.events), t_eval=t_eval,
                      progress=overrides.get("progress"), **budgets)
        if s.get("max_step"):
            kwargs["max_step"] = s["max_step"]
        if fixed and s.get("output_dt"):     # the integrator's own states, every k-th step
            kwargs["decimate"] = max(1, int(round(s["output_dt"] / s["dt"])))
        try:
            result = _simulate(self.model, s["t_end"], self.q0.copy(), self.u0.copy(),
                               **kwargs)
        except ModelError as exc:
            if isinstance(exc, ModelFileError):
                raise
            raise ModelFileError(self.path, "simulation", str(exc)) from None
        if outputs or points:
            result.compute_outputs(tuple(outputs), points or None)
        return result


class _SceneBuilder:
    """Builds System, Model and Scene from a merged, shape-checked document."""

    def __init__(self, path, doc, checker, effects=None):
        self.effects_override = effects
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
        e = self.expr(value, path, self.P)
        try:
            v = to_float(e, self.values)
        except ExpressionError as exc:
            raise self.error(path, f"{value!r} does not give a finite real number: {exc}") \
                from None
        self.bounded(v, path)
        if positive and not v > 0:
            raise self.error(path, f"must be > 0, got {v:g}")
        if nonnegative and v < 0:
            raise self.error(path, f"must be >= 0, got {v:g}")
        return v

    def pval(self, value, path):
        """A value for the engine: a float, or the sympy expression of parameters."""
        e = self.expr(value, path, self.P)
        try:
            v = to_float(e, self.values)
        except ExpressionError as exc:
            raise self.error(path, f"{value!r} does not give a finite real number: {exc}") \
                from None
        self.bounded(v, path)
        return e if e.free_symbols else v

    def bounded(self, v, path):
        problem = limits.magnitude_problem(v)
        if problem:
            raise self.error(path, problem)

    def pvector(self, value, path, default=(0.0, 0.0, 0.0)):
        if value is None:
            return list(default)
        return [self.pval(v, path + (k,)) for k, v in enumerate(value)]

    # -- the build
    def build(self):
        doc = self.doc
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            self.parameters()
            model_table = doc.get("model", {})
            name = model_table.get("name") or os.path.splitext(os.path.basename(self.file))[0]
            gravity = self.pvector(model_table.get("gravity"), ("model", "gravity"),
                                   default=(0.0, 0.0, -9.81))
            with self.engine(("model",)):
                system = System(name, gravity=gravity, parameters=self.values)
            self.system = system
            self.bodies()
            self.joints()
            self.names_q = {}
            for j in system.joints.values():
                if j.drive is None:
                    for n in j.coordinates + j.speeds:
                        self.names_q[n] = symbol(n)
            self.PTQ = dict(self.PT)
            self.PTQ.update(self.names_q)
            self.loads()
            self.forces()
            effects = self.effects()
            with self.engine(()):
                model = system.compile(effects=effects)
            self.model = model
            q0, u0, initial = self.initial()
            settings = self.simulation()
            outputs = self.outputs()
            events, event_specs = self.events(q0, u0)
        messages = []
        for w in caught:
            text = str(w.message)
            if text not in (m for m, _ in messages):
                messages.append((text, w.category))
        for text in model.warnings:
            if text not in (m for m, _ in messages):
                messages.append((text, _category("ModelWarning")))
        self.emitted = messages
        return Scene(path=self.file, name=name, description=model_table.get("description", ""),
                     system=system, model=model, q0=q0, u0=u0, initial=initial,
                     parameters=dict(self.values), settings=settings, outputs=outputs,
                     events=events, event_specs=event_specs,
                     warnings=tuple(m for m, _ in messages), document=doc,
                     joint_specs=self.joint_specs, load_specs=self.load_specs,
                     body_specs=self.body_specs, force_specs=self.force_specs)

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

    def bodies(self):
        self.body_specs = []
        for i, b in enumerate(self.doc.get("bodies", [])):
            path = ("bodies", i)
            name = self.required(b, "name", path, "body")
            mass = self.pval(b.get("mass", 0.0), path + ("mass",))
            com = self.pvector(b.get("com"), path + ("com",))
            raw = b.get("inertia")
            if raw is None or (not isinstance(raw, list) and raw == 0):
                inertia = None
            elif all(isinstance(r, list) for r in raw):
                inertia = [[self.pval(v, path + ("inertia", r, c)) for c, v in enumerate(row)]
                           for r, row in enumerate(raw)]
            else:
                inertia = [self.pval(v, path + ("inertia", k)) for k, v in enumerate(raw)]
            about = b.get("inertia_about", "com")
            if about == "origin":
                if inertia is None:
                    raise self.error(path + ("inertia_about",), "\"origin\" needs an inertia "
                                     "to convert; give inertia = [...] or remove inertia_about")
                inertia = _inertia_about_com(inertia, mass, com)
            shape = None
            if "shape" in b:
                shape = dict(b["shape"])
                for key in ("radius", "length"):
                    if key in shape:
                        shape[key] = self.number(shape[key], path + ("shape", key),
                                                 positive=True)
                for key in ("center", "start", "end", "size"):
                    if key in shape:
                        shape[key] = [self.number(v, path + ("shape", key, k))
                                      for k, v in enumerate(shape[key])]
            with self.engine(path):
                self.system.add_body(name, mass=mass, com=com, inertia=inertia, shape=shape)
            self.body_specs.append(dict(b))

    def joints(self):
        self.joint_specs = []
        for i, j in enumerate(self.doc.get("joints", [])):
            path = ("joints", i)
            name = self.required(j, "name", path, "joint")
            kind = self.required(j, "kind", path, "joint")
            child = self.required(j, "child", path, "joint")
            parent = j.get("parent", GROUND)
            for role, frame in (("parent", parent), ("child", child)):
                if frame not in self.system.graph:
                    known = [n for n in self.system.graph]
                    raise self.error(path + (role,), f"unknown frame {frame!r}; "
                                     f"{_suggest(frame, known)}the frames are: "
                                     f"{', '.join(known)} (add bodies with [[bodies]])")
            axis = j.get("axis")
            if isinstance(axis, list):
                axis = self.pvector(axis, path + ("axis",))
            orientation = j.get("orientation")
            if isinstance(orientation, dict):
                oaxis = orientation["axis"]
                if isinstance(oaxis, list):
                    oaxis = self.pvector(oaxis, path + ("orientation", "axis"))
                orientation = (oaxis, self.pval(orientation["angle"],
                                                path + ("orientation", "angle")))
            elif isinstance(orientation, list) and len(orientation) == 4:
                orientation = [self.number(v, path + ("orientation", k))
                               for k, v in enumerate(orientation)]
            elif isinstance(orientation, list):
                orientation = [[self.number(v, path + ("orientation", r, c))
                                for c, v in enumerate(row)] for r, row in enumerate(orientation)]
            drive = None
            if "drive" in j:
                drive = self.expr(j["drive"], path + ("drive",), self.PT)
            coordinates = j.get("coordinates")
            speeds = j.get("speeds")
            for key, names in (("coordinates", coordinates), ("speeds", speeds)):
                for n in ([names] if isinstance(names, str) else names or []):
                    if n in self.P:
                        raise self.error(path + (key,), f"{n!r} is also a parameter; rename "
                                         "the coordinate or the parameter")
            with self.engine(path):
                self.system.add_joint(name, kind, parent, child, axis=axis,
                                      position=self.pvector(j.get("position"),
                                                            path + ("position",)),
                                      orientation=orientation, sequence=j.get("sequence"),
                                      coordinates=coordinates, speeds=speeds, drive=drive)
            joint = self.system.joints[name]
            if joint.drive is not None:
                try:                  # defined where the run starts (the files' t0 is 0)
                    for part in (joint.drive.position, joint.drive.velocity,
                                 joint.drive.acceleration):
                        part(0.0)
                except ArithmeticError as exc:
                    raise self.error(path + ("drive",), str(exc)) from None
            if joint.drive is None:
                clash = [n for n in joint.coordinates + joint.speeds if n in self.P or n == "t"]
                if clash:
                    raise self.error(path, f"its coordinate/speed names {clash} are also "
                                     "parameter names (or t); name them with coordinates = "
                                     "[...] / speeds = [...]")
            self.joint_specs.append(dict(j))

    def loads(self):
        self.load_specs = []
        for i, ld in enumerate(self.doc.get("loads", [])):
            path = ("loads", i)
            name = self.required(ld, "name", path, "load")
            body = self.required(ld, "body", path, "load")
            parts = {}
            for key in ("force", "moment"):
                if key in ld:
                    exprs = tuple(self.expr(v, path + (key, k), self.PTQ)
                                  for k, v in enumerate(ld[key]))
                    for k, e in enumerate(exprs):
                        e0 = e.subs({s: self.values[s.name] for s in e.free_symbols
                                     if s.name in self.values})
                        if not e0.free_symbols:
                            try:
                                to_float(e0)
                            except ExpressionError as exc:
                                raise self.error(path + (key, k), str(exc)) from None
                    parts[key] = exprs
            with self.engine(path):
                self.system.add_load(name, body, force=parts.get("force"),
                                     moment=parts.get("moment"),
                                     point=self.pvector(ld.get("point"), path + ("point",)),
                                     frame=ld.get("frame", "world"))
            self.load_specs.append(dict(ld))

    def forces(self):
        """``[[forces]]``: each table's keys handed to ``System.add_force``."""
        self.force_specs = []
        for i, fe in enumerate(self.doc.get("forces", [])):
            path = ("forces", i)
            name = self.required(fe, "name", path, "force element")
            kind = self.required(fe, "kind", path, "force element")
            kw = {}
            for key, value in fe.items():
                if key in ("name", "kind"):
                    continue
                kpath = path + (key,)
                if key in ("body_a", "body_b", "body", "housing", "joint", "speed", "shape",
                           "interpolation"):
                    kw[key] = value
                elif key in ("point_a", "point_b", "point", "center", "plane_point"):
                    kw[key] = self.pvector(value, kpath)
                elif key in ("axis", "plane_normal"):
                    kw[key] = value if isinstance(value, str) else self.pvector(value, kpath)
                elif key == "law":
                    for n in ("x", "v"):
                        if n in self.P:
                            raise self.error(kpath, f"a law's variables are x (elongation) and "
                                             f"v (its rate), but {n!r} is also a parameter; "
                                             "rename the parameter")
                    kw[key] = self.expr(value, kpath, dict(self.P, x=symbol("x"),
                                                          v=symbol("v")))
                elif key in ("force_table", "damping_table"):
                    kw[key] = [[self.number(x, kpath + (r, 0)), self.number(y, kpath + (r, 1))]
                               for r, (x, y) in enumerate(value)]
                elif isinstance(value, list):
                    if value and all(isinstance(r, list) for r in value):
                        kw[key] = [[self.number(v, kpath + (r, c)) for c, v in enumerate(row)]
                                   for r, row in enumerate(value)]
                    else:
                        kw[key] = [self.number(v, kpath + (k,)) for k, v in enumerate(value)]
                else:
                    kw[key] = self.pval(value, kpath)
            with self.engine(path):
                self.system.add_force(name, kind, **kw)
            self.force_specs.append(dict(fe))

    def effects(self):
        """The file's ``[effects]`` then the caller's switches, checked by name."""
        from ..elements.effects import parse_effects
        known = self.system.effect_names()
        with self.engine(("effects",)):
            state = parse_effects(self.doc.get("effects"), known, where="")
        if self.effects_override is not None:
            try:
                state = parse_effects(self.effects_override, known, "--effects", base=state)
            except ModelError as exc:
                raise ModelFileError("--effects", "", str(exc)) from None
        return state

    def initial(self):
        model = self.model
        driven = {}
        for j in self.system.joints.values():
            if j.drive is not None:
                for n in j.coordinates + j.speeds:
                    driven[n] = j.name
        rates = {}                      # coordinate -> its speed, where u = q'
        for j in self.system.joints.values():
            if j.drive is None and j.kind in ("revolute", "prismatic", "euler"):
                rates.update(zip(j.coordinates, j.speeds))
        q = {}
        for k, v in self.doc.get("initial", {}).items():
            path = ("initial", k)
            if k not in model.coordinates:
                if k in driven:
                    raise self.error(path, f"is the coordinate of driven joint "
                                     f"{driven[k]!r}; its motion comes from the drive -- "
                                     "remove it here")
                raise self.error(path, f"{k!r} is not a coordinate of the model; "
                                 f"{_suggest(k, model.coordinates)}the coordinates are: "
                                 f"{', '.join(model.coordinates) or '(none)'}")
            q[k] = self.number(v, path)
        u = {}
        for k, v in self.doc.get("initial_speeds", {}).items():
            path = ("initial_speeds", k)
            if k in model.speeds:
                target = k
            elif k in rates:
                target = rates[k]
            else:
                if k in driven:
                    raise self.error(path, f"belongs to driven joint {driven[k]!r}; its "
                                     "speed comes from the drive -- remove it here")
                raise self.error(path, f"{k!r} is not a speed of the model; "
                                 f"{_suggest(k, model.speeds + tuple(rates))}the speeds are: "
                                 f"{', '.join(model.speeds) or '(none)'}"
                                 + (f" (or, for their rates, the coordinates "
                                    f"{', '.join(rates)})" if rates else ""))
            if target in u:
                raise self.error(path, f"sets the speed {target!r} a second time; keep "
                                 "one of the two keys")
            u[target] = self.number(v, path)
        q0 = model.q_vector(dict(q)).copy()
        u0 = model.u_vector(dict(u)).copy()
        for j in self.system.joints.values():
            if j.drive is None and j.kind in ("spherical", "free"):
                names = j.coordinates[-4:]
                idx = [model.coordinate_index(n) for n in names]
                norm = float(np.linalg.norm(q0[idx]))
                if norm < 1e-12:
                    raise self.error(("initial", names[0]), f"the quaternion of joint "
                                     f"{j.name!r} ({', '.join(names)}) is zero; give a unit "
                                     "quaternion, e.g. [cos(a/2), sin(a/2), 0, 0]")
                if abs(norm - 1.0) > 1e-9:
                    warnings.warn(f"{self.file}: initial: the quaternion of joint {j.name!r} "
                                  f"({', '.join(names)}) has length {norm:.6g}; it is "
                                  "normalised to unit length", _category("ModelWarning"))
                    q0[idx] = q0[idx] / norm
        initial = dict(q)
        initial.update(u)
        return q0, u0, initial

    def simulation(self):
        sim = self.doc.get("simulation", {})
        s = dict(DEFAULT_SIMULATION)
        s["t_end"] = None
        path = ("simulation",)
        if "t_end" in sim:
            s["t_end"] = self.number(sim["t_end"], path + ("t_end",), positive=True)
        if "integrator" in sim:
            integ = sim["integrator"]
            if integ not in INTEGRATORS:
                raise self.error(path + ("integrator",), f"unknown integrator {integ!r}; "
                                 f"{_suggest(integ, INTEGRATORS)}use one of: "
                                 f"{', '.join(INTEGRATORS)}")
            s["integrator"] = integ
        if "method" in sim:
            if sim["method"] not in METHODS:
                raise self.error(path + ("method",), f"unknown method {sim['method']!r}; "
                                 f"{_suggest(sim['method'], METHODS)}use one of: "
                                 f"{', '.join(METHODS)}")
            s["method"] = sim["method"]
        for key in ("rtol", "atol", "dt", "max_step", "output_dt", "max_wall_time"):
            if key in sim:
                s[key] = self.number(sim[key], path + (key,), positive=True)
        for key in ("max_steps", "max_samples"):
            if key in sim:
                v = self.number(sim[key], path + (key,), positive=True)
                if v != int(v):
                    raise self.error(path + (key,), f"must be a whole number, got {v:g}")
                s[key] = int(v)
        if s["integrator"] in FIXED_STEP and not s.get("dt"):
            raise self.error(path + ("integrator",), f"{s['integrator']!r} is a fixed-step "
                             "integrator: add dt = ... to [simulation] (or pass --dt)")
        if s["integrator"] in FIXED_STEP:
            ignored = [k for k in ("rtol", "atol", "max_step") if k in sim]
            if ignored:
                warnings.warn(f"simulation.{', simulation.'.join(ignored)} ignored: the "
                              f"fixed-step integrator {s['integrator']} takes steps of dt",
                              ModelWarning)
            if s.get("t_end") and s["dt"] > s["t_end"]:
                warnings.warn(f"simulation.dt = {s['dt']:g} is longer than t_end = "
                              f"{s['t_end']:g}: the run is one shortened step", ModelWarning)
            ratio = s["output_dt"] / s["dt"] if s.get("output_dt") else 1.0
            if ratio >= 1 and abs(ratio - round(ratio)) > 1e-6 * ratio:
                warnings.warn(f"simulation.output_dt = {s['output_dt']:g} is not a multiple of "
                              f"dt = {s['dt']:g}: every {round(ratio)}-th step is kept "
                              f"(every {round(ratio) * s['dt']:g} s)", ModelWarning)
        if (s["integrator"] in FIXED_STEP and s.get("output_dt")
                and s["output_dt"] < s["dt"] * (1 - 1e-9)):
            warnings.warn(f"simulation.output_dt = {s['output_dt']:g} is smaller than dt = "
                          f"{s['dt']:g}: a fixed-step run keeps its own steps, so every step "
                          "is stored", ModelWarning)
        return s

    def outputs(self):
        out = self.doc.get("outputs", {})
        model = self.model
        path = ("outputs",)
        reactions = out.get("reactions", False)
        if reactions is True:
            reactions = list(model.joints)
        elif reactions is False:
            reactions = []
        else:
            for k, jn in enumerate(reactions):
                if jn not in model.joints:
                    raise self.error(path + ("reactions", k), f"{jn!r} is not a joint; "
                                     f"{_suggest(jn, model.joints)}the joints are: "
                                     f"{', '.join(model.joints)}")
        points = {}
        for pname, p in out.get("points", {}).items():
            ppath = path + ("points", pname)
            if p["frame"] not in model.frames:
                raise self.error(ppath + ("frame",), f"{p['frame']!r} is not a frame; "
                                 f"{_suggest(p['frame'], model.frames)}the frames are: "
                                 f"{', '.join(model.frames)}")
            if pname in model.coordinates or pname in model.speeds:
                raise self.error(ppath, f"{pname!r} is also a coordinate or speed name; "
                                 "rename the point")
            offset = [self.number(v, ppath + ("offset", k))
                      for k, v in enumerate(p.get("offset", [0, 0, 0]))]
            points[pname] = (p["frame"], tuple(offset))
        return {"reactions": reactions, "reactions_frame": out.get("reactions_frame", "world"),
                "energy": bool(out.get("energy", False)), "points": points}

    def events(self, q0, u0):
        model = self.model
        events, specs = [], []
        seen = set()
        for i, e in enumerate(self.doc.get("events", [])):
            path = ("events", i)
            name = self.required(e, "name", path, "event")
            if name in seen:
                raise self.error(path + ("name",), f"a second event named {name!r}; event "
                                 "names must differ")
            seen.add(name)
            text = self.required(e, "condition", path, "event")
            try:
                g, implied = parse_condition(text, self.PTQ)
            except ExpressionError as exc:
                raise self.error(path + ("condition",), str(exc)) from None
            explicit = e.get("direction")
            if isinstance(explicit, str):
                explicit = DIRECTIONS[explicit]
            if explicit is not None and implied is not None and explicit != implied:
                word = {1: "rising", -1: "falling", 0: "either"}
                raise self.error(path + ("direction",), f"{word[explicit]!r} contradicts the "
                                 f"condition {text!r}, which fires when it becomes true "
                                 f"({word[implied]}); remove direction or write the condition "
                                 "the other way round")
            direction = explicit if explicit is not None else (implied or 0)
            g = g.subs({s: self.values[s.name] for s in g.free_symbols
                        if s.name in self.values})
            cond = _condition(g, model, text)
            try:
                g0 = cond(0.0, q0, u0)
            except (ArithmeticError, ValueError, TypeError) as exc:
                raise self.error(path + ("condition",), f"cannot be evaluated at the initial "
                                 f"state: {exc}") from None
            if not math.isfinite(g0):
                raise self.error(path + ("condition",), "is not finite at the initial state; "
                                 "check for divisions by zero")
            holds = (g0 >= 0 and direction > 0) or (g0 <= 0 and direction < 0)
            if holds:
                warnings.warn(f"{self.file}: events[{i}] ({name!r}): the condition {text!r} "
                              "already holds at the initial state; the event fires only when "
                              "it becomes true again", _category("ModelWarning"))
            terminal = bool(e.get("terminal", False))
            events.append(Event(name, cond, terminal, int(direction)))
            specs.append({"name": name, "condition": text, "terminal": terminal,
                          "direction": {1: "rising", -1: "falling", 0: "either"}[direction]})
        return events, specs


def _category(name):
    from .. import errors
    return getattr(errors, name)


def _inertia_about_com(inertia, mass, com):
    """Inertia about the centre of mass from an inertia about the frame origin
    (``I_G = I_O - m (|d|^2 E - d d^T)``, ``d`` the centre of mass), kept symbolic: each
    entry expanded unless its expansion would exceed ``limits.MAX_EXPANDED_TERMS`` terms
    (``(a+b+c)**1000`` has half a million; it stays as written, which is as exact)."""
    def sym(v):                   # numbers and sympy objects only -- never text
        return v if isinstance(v, sympy.Basic) else sympy.Float(float(v))
    if not isinstance(inertia[0], list):
        I_O = sympy.diag(*[sym(v) for v in inertia])
    else:
        I_O = sympy.Matrix([[sym(v) for v in row] for row in inertia])
    d = sympy.Matrix([sym(v) for v in com])
    m = sym(mass)
    I_G = I_O - m * ((d.T * d)[0, 0] * sympy.eye(3) - d * d.T)
    out = []
    for r in range(3):
        row = []
        for c in range(3):
            e = I_G[r, c]
            if expanded_terms(e) <= limits.MAX_EXPANDED_TERMS:
                e = sympy.expand(e)
            row.append(float(e) if not e.free_symbols else e)
        out.append(row)
    return out


__all__ = ["load_model", "read_document", "Scene", "METHODS", "DEFAULT_SIMULATION",
           "split_path"]
