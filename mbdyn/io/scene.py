"""A model file loaded and ready to run: ``load_model`` reads it (``document``), checks its
shape (``checker``), merges the chosen case and the overrides (``cases``) and has the
``SceneBuilder`` make the ``Scene``: the compiled ``Model``, the initial state, the
settings, events and outputs; ``Scene.simulate`` runs it.
"""
from __future__ import annotations

import copy
import math
import os
import warnings

import numpy as np

from .. import limits
from ..errors import ModelError
from ..integrate.settings import FIXED_STEP
from ..integrate.simulation import simulate as _simulate
from .builder import SceneBuilder
from .cases import apply_case, apply_override
from .checker import Checker
from .document import parse_document, parse_set_value, read_document
from .errors import ModelFileError
from .settings import BUDGETS, SIMULATE_KEYWORDS
from .urdf import is_urdf
from .wording import suggest


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


def load_model(path, case=None, overrides=None, effects=None, *, text=None, floating=None,
               accept_inertia=None, mesh_path=None):
    """Read a model file (TOML, or a URDF robot: ``.urdf``) and return a ready-to-run
    ``Scene``.

    ``case``: the name of a ``[cases.NAME]`` table to apply (default: the file's
    ``model.default_case``, if any).  ``overrides``: ``{"parameters.Mz": -0.01, ...}``
    (values: numbers, booleans, arrays, or strings holding expressions or names) or an
    iterable of ``"PATH=VALUE"`` texts as ``mbdyn run --set`` takes them; applied after
    the case.  ``effects``: switches applied after the file's ``[effects]``, as
    ``--effects`` takes them (``"-gravity,-damper"``, a list, or a mapping; see
    ``mbdyn.effects``).  ``text``: the file's content, already read (a sweep's member
    carries its model's text, not a file); ``path`` then only names it.  ``floating``,
    ``accept_inertia``: a URDF robot's base hangs from the ground by a free joint ``root``;
    inertias no body can have are accepted (``[model] floating``, ``accept_inertia``;
    docs/urdf.md).  ``mesh_path``: a folder or a list of folders where a URDF's
    ``package://`` meshes are looked for (``[model] mesh_path``).  Raises ``ModelFileError`` (a ``ModelError``) naming file and key.
    """
    if not isinstance(path, (str, os.PathLike)):
        raise ModelError(f"load_model: path must be the path of a .toml or .urdf file, got {path!r}")
    if isinstance(overrides, str):
        raise ModelError("load_model: overrides must be a mapping {\"parameters.k\": 1.0} or "
                         "a list of \"PATH=VALUE\" texts, not one string")
    if text is not None and len(text) > limits.max_file_bytes():
        raise ModelFileError(path, "", f"is more than a model file may be "
                             f"({limits.max_file_bytes()} characters; MBDYN_MAX_FILE_BYTES "
                             "raises it)")
    urdf_text = None
    if is_urdf(path):                 # a document of one key: the robot
        doc, urdf_text = {"model": {"urdf": os.path.basename(str(path))}}, text
    else:
        doc = read_document(path) if text is None else parse_document(text, str(path))
    overrides = _normalise_overrides(overrides) + [
        (f"model.{key}", bool(value), f"{key}={bool(value)}")
        for key, value in (("floating", floating), ("accept_inertia", accept_inertia))
        if value is not None]
    if mesh_path is not None:
        folders = [mesh_path] if isinstance(mesh_path, (str, os.PathLike)) else mesh_path
        overrides.append(("model.mesh_path", [os.path.abspath(os.fspath(f))
                                              for f in folders], "mesh_path"))
    checker = Checker(path)
    checker.check_document(doc)
    default_case = doc.get("model", {}).get("default_case")
    cases = list(doc.get("cases", {}))
    if default_case is not None and default_case not in cases:
        raise checker.error(("model", "default_case"), f"no case {default_case!r}; "
                            f"{suggest(default_case, cases)}the cases are: "
                            f"{', '.join(cases) or '(none)'}")
    chosen = case if case is not None else default_case
    if chosen is not None:
        merged = apply_case(doc, str(chosen), checker)
    else:
        merged = copy.deepcopy({k: v for k, v in doc.items() if k != "cases"})
    for path_text, value, origin in overrides:
        apply_override(merged, path_text, value, checker, origin)
    checker.check_document(merged)
    builder = SceneBuilder(path, merged, checker, effects, urdf_text=urdf_text)
    scene = Scene(**builder.build())
    scene.case = chosen
    scene.overrides = list(overrides)
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
        self.urdf = None             # what a URDF robot held (docs/urdf.md), if any
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
        ``points``, ``progress`` (a callable ``progress(t)``) and ``error_estimate``
        (``simulate``'s).
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
                      progress=overrides.get("progress"),
                      error_estimate=bool(overrides.get("error_estimate")), **budgets)
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


