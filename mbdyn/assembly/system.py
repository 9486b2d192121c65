"""``System``: what a user assembles -- a tree of frames (nodes) joined by joints (edges).

The tree lives in a networkx ``DiGraph`` rooted at the frame ``"ground"``.  Elements are
validated when added; the tree as a whole (connectivity, inertia of every degree of
freedom) at ``compile()``.  Every error names the element and says what to change.
"""
from __future__ import annotations

import collections.abc
import math
import warnings

import networkx as nx
import numpy as np
import sympy

from ..compiled.model import Model
from ..elements.effects import parse_effects, warn_if_unphysical
from ..elements.values import has_symbols, numeric
from ..elements.bodies import inertia_tensor, make_body, origin_inertia_parts
from ..elements.joints import make_joint
from ..elements.loads import make_load
from ..errors import ModelError, ModelWarning, SingularMassMatrixError
from ..limits import magnitude_problem
from ..names import identifier_problem, label_problem
from .actuation import add_actuator, add_controller, attach_plant, check_force
from . import contacts
from .composite import add_composite_joint
from . import flexible as flex
from .flexible_nodes import attach_at_nodes
from .loops import add_loop_joint, check_loops, loop_bodies
from ..elements.forces import GLOBAL_EFFECTS, make_force

GROUND = "ground"


class System:
    """A multibody system under construction.

    ``gravity`` is the gravitational acceleration vector in world components
    (default ``(0, 0, -9.81)``).  ``parameters`` ``{name: value}`` declares named
    parameters: any number given to the system may then be a sympy expression of them
    (``m, l = s.symbols("m l")``), which the symbolic layer keeps and the numeric layers
    evaluate.
    """

    def __init__(self, name="system", gravity=(0.0, 0.0, -9.81), parameters=None):
        self.name = str(name)
        self.parameters = {}
        if parameters is not None and not isinstance(parameters, collections.abc.Mapping):
            raise ModelError(f"system {name!r}: parameters must be a mapping {{name: value}}, "
                             f"got {type(parameters).__name__}")
        for pname, value in (parameters or {}).items():
            problem = identifier_problem(pname)
            if problem:
                raise ModelError(f"system {name!r}: parameter name {pname!r} {problem}")
            try:
                self.parameters[pname] = float(value)
            except (TypeError, ValueError):
                raise ModelError(f"system {name!r}: parameter {pname!r} must be a number, "
                                 f"got {value!r}") from None
            problem = (f"is {value!r}; give a finite number" if not math.isfinite(
                self.parameters[pname]) else magnitude_problem(self.parameters[pname]))
            if problem:
                raise ModelError(f"system {name!r}: parameter {pname!r} {problem}")
        self.gravity_symbolic = gravity if has_symbols(gravity) else None
        gravity = numeric(gravity, self.parameters, f"system {name!r}", "gravity")
        try:
            g = np.asarray(gravity, dtype=float).reshape(-1)
        except (TypeError, ValueError):
            raise ModelError(f"system {name!r}: gravity must be three finite numbers, "
                             f"got {gravity!r}") from None
        if g.shape != (3,) or not np.all(np.isfinite(g)):
            raise ModelError(f"system {name!r}: gravity must be three finite numbers, "
                             f"got {gravity!r}")
        self.gravity = g
        self.graph = nx.DiGraph()
        self.graph.add_node(GROUND, body=make_body(GROUND))
        self._joints = {}
        self._loop_joints = {}          # name -> LoopJoint (assembly.loops)
        self._state_names = set()     # the joints' coordinates and speeds
        self._loads = {}
        self._forces = {}
        self._controllers = {}          # name -> Controller (assembly.actuation)
        self._shapes = {}             # contact shapes (assembly.contacts)
        self._flexible = {}             # name -> FlexibleBody (assembly.flexible)

    # ------------------------------------------------------------------ building
    def symbols(self, names):
        """sympy symbols of declared parameters: ``m, l = s.symbols("m l")``."""
        if isinstance(names, str):
            names = names.replace(",", " ").split()
        elif isinstance(names, (list, tuple)) and all(isinstance(n, str) for n in names):
            names = list(names)
        else:
            raise ModelError(f"system {self.name!r}: symbols takes parameter names, as one "
                             f"text ('m l') or a list of texts, got {names!r}")
        missing = [n for n in names if n not in self.parameters]
        if missing:
            raise ModelError(f"system {self.name!r}: {', '.join(missing)} are not parameters; "
                             f"declared: {', '.join(self.parameters) or '(none)'}")
        syms = tuple(sympy.Symbol(n, real=True) for n in names)
        return syms[0] if len(syms) == 1 else syms

    def _check_new_frame(self, name):
        problem = label_problem(name)
        if problem:
            raise ModelError(f"frame name {name!r} {problem}")
        if name in self.graph:
            what = "the ground frame" if name == GROUND else "a frame"
            raise ModelError(f"body/frame {name!r}: the name is already used by {what}; "
                             "choose another name")

    def add_body(self, name, mass=0.0, com=(0, 0, 0), inertia=None, shape=None,
                 inertia_about="com", flexible=None):
        """A rigid body: ``mass``, centre of mass ``com`` in body components (from the
        frame origin), ``inertia`` about the centre of mass in body axes -- ``None``/0 for a
        particle, three principal moments, or a 3x3 tensor (see ``mbdyn.inertia``).
        ``shape``: how pictures draw it (``mbdyn.elements.bodies.make_shape``).
        ``inertia_about="origin"``: the inertia is given about the frame origin instead (as
        the textbook's top data are); it is moved to the centre of mass by the parallel-axis
        theorem, ``I_G = I_O - m (|c|^2 E - c c^T)``.  ``flexible``: a modally reduced
        flexible body whose frame is the beam's root (``mbdyn.elements.flexible_bodies``,
        docs/flexible.md); ``mass``, ``com``, ``inertia`` are then a rigid part fixed to it."""
        self._check_new_frame(name)
        if inertia_about not in ("com", "origin"):
            raise ModelError(f"body {name!r}: inertia_about must be 'com' or 'origin', got "
                             f"{inertia_about!r}")
        if inertia_about == "origin":
            if inertia is None:
                raise ModelError(f"body {name!r}: inertia_about='origin' needs an inertia")
            I_O, c, mass = origin_inertia_parts(name, mass, com, inertia)
            I_G = I_O - mass * ((c.T * c)[0, 0] * sympy.eye(3) - c * c.T)
            inertia = [[float(v) if not getattr(v, "free_symbols", None) else v
                        for v in I_G.row(r)] for r in range(3)]
        if flexible is not None:
            return flex.add_flexible_body(self, name, mass, com, inertia, shape, flexible)
        self.graph.add_node(name, body=make_body(name, mass, com, inertia, self.parameters,
                                                 shape))
        return name

    def add_frame(self, name, shape=None):
        """A massless frame (e.g. a gimbal ring or an intermediate joint frame); ``shape``
        draws it (an arm, a disk)."""
        self._check_new_frame(name)
        self.graph.add_node(name, body=make_body(name, shape=shape))
        return name

    def add_joint(self, name, kind, parent=None, child=None, *, axis=None,
                  position=(0, 0, 0), orientation=None, sequence=None, coordinates=None,
                  speeds=None, drive=None, **loop):
        """Join ``child`` to ``parent``.

        ``kind``: ``"revolute"`` / ``"prismatic"`` (need ``axis``, a vector or
        ``"x"``/``"y"``/``"z"``, in the joint frame), ``"euler"`` (three rotations about
        moving axes, ``sequence`` default ``"ZXZ"``), ``"spherical"`` (unit quaternion),
        ``"fixed"``, ``"free"``.  ``position`` and ``orientation`` place the joint frame in
        the parent frame (orientation: 3x3 matrix ``P s = C J s``, quaternion ``(w,x,y,z)``
        or ``(axis, angle)``).  ``coordinates`` (and ``speeds``) name the joint's
        coordinates; ``drive`` prescribes ``q(t)`` of a 1-DoF joint (a sympy expression of
        ``mb.t`` or three callables ``(q, q', q'')``).

        A joint given ``child_position`` (the joint's point in the child's body frame), or
        ``cut=True``, closes a loop (``assembly.loops``): kinds revolute, prismatic,
        spherical, fixed, ``universal`` (``axis`` in the parent's joint frame, ``axis2`` in
        the child's), ``cylindrical``, plus ``"distance"`` (``length``: a massless rod
        between ``position`` on the parent and ``child_position`` on the child) and
        ``"coupling"`` (``follower``, ``leader``, ``ratio``, ``offset``: ``q_follower =
        ratio q_leader + offset``; no parent or child).  ``child_orientation`` places the
        joint frame in the child.  In the tree, ``universal`` and ``cylindrical`` are two
        1-DoF joints through a massless frame (``assembly.composite``).
        """
        closing = {k for k in loop if k not in ("axis2",)}
        element = f"joint {name!r}"
        position = flex.joint_point(self, element, parent, "position", position)
        if kind in ("universal", "cylindrical") and not closing:
            return add_composite_joint(self, name, kind, parent, child, axis=axis,
                                       position=position, orientation=orientation,
                                       coordinates=coordinates, drive=drive,
                                       axis2=loop.get("axis2"), sequence=sequence,
                                       speeds=speeds)
        if loop or kind in ("distance", "coupling"):
            if "child_position" in loop:
                loop["child_position"] = flex.joint_point(
                    self, element, child, "child_position", loop["child_position"])
            return add_loop_joint(self, name, kind, parent, child, axis=axis,
                                  position=position, orientation=orientation, **loop)
        problem = label_problem(name)
        if problem:
            raise ModelError(f"joint name {name!r} {problem}")
        if name in self._joints or name in self._loop_joints:
            raise ModelError(f"{element}: the name is already used by another joint")
        for role, frame in (("parent", parent), ("child", child)):
            if frame not in self.graph:
                raise ModelError(f"{element}: unknown {role} frame {frame!r}; add it first "
                                 "with add_body or add_frame (known: "
                                 f"{', '.join(self.graph.nodes)})")
        if child == GROUND:
            raise ModelError(f"{element}: the ground cannot be a child; swap parent and child")
        if child == parent:
            raise ModelError(f"{element}: parent and child are both {child!r}")
        existing = next(iter(self.graph.in_edges(child, data="joint")), None)
        if existing is not None:
            raise ModelError(f"{element}: frame {child!r} already has a parent joint "
                             f"{existing[2].name!r}; to close a loop, give this joint "
                             f"child_position (the joint's point in {child!r}'s body "
                             "frame), and it becomes a loop joint")
        if nx.has_path(self.graph, child, parent):
            raise ModelError(f"{element}: joining {parent!r} -> {child!r} closes a cycle "
                             f"({child!r} is already an ancestor of {parent!r}); the system "
                             "must be a tree")
        joint = make_joint(name, kind, parent, child, axis=axis, position=position,
                           orientation=orientation, sequence=sequence, coordinates=coordinates,
                           speeds=speeds, drive=drive, parameters=self.parameters)
        clash = self._state_names.intersection(joint.coordinates + joint.speeds)
        if clash:
            raise ModelError(f"{element}: coordinate/speed names {sorted(clash)} are already "
                             "used by another joint; pass coordinates=(...) to rename them")
        self._joints[name] = joint
        self._state_names.update(joint.coordinates + joint.speeds)
        self.graph.add_edge(parent, child, joint=joint)
        return name

    def add_load(self, name, body, force=None, moment=None, point=(0, 0, 0), frame="world"):
        """A force (acting at ``point``, body components) and/or a moment on ``body``.

        ``force``/``moment``: three numbers, or a function ``f(t, q, u)`` returning three
        numbers (``q``, ``u`` arrays in ``Model.coordinates``/``Model.speeds`` order);
        ``frame``: ``"world"`` or ``"body"`` components.
        """
        problem = label_problem(name)
        if problem:
            raise ModelError(f"load name {name!r} {problem}")
        if name in self._loads or name in self._forces or name in GLOBAL_EFFECTS:
            raise ModelError(f"load {name!r}: the name is already used by another load, a "
                             "force element or an effect; loads and force elements share "
                             "one namespace (their names are the scene's effects)")
        if body not in self.graph or body == GROUND:
            raise ModelError(f"load {name!r}: unknown body {body!r}; loads act on bodies "
                             f"and frames added with add_body or add_frame (known: "
                             f"{', '.join(n for n in self.graph if n != GROUND)})")
        point = flex.named_points(self, f"load {name!r}", (("body", "point"),),
                                  {"body": body, "point": point})["point"]
        self._loads[name] = make_load(name, body, force, moment, point, frame, self.parameters)
        return name

    def add_force(self, name, kind, **params):
        """A force element (see ``mbdyn.forces`` and docs/model-files.md, "Force elements").

        ``kind``: ``"spring-damper"`` (``body_a``, ``point_a``, ``body_b`` (default the
        ground), ``point_b``, ``stiffness``, ``damping``, ``free_length``, ``preload`` or
        ``force_table`` / ``damping_table``), ``"joint-spring-damper"`` (``joint``,
        ``stiffness``, ``damping``, ``rest``, ``preload`` or tables), ``"bushing"``
        (``body_a``, ``point_a``, ``body_b``, ``point_b``, 6x6 ``stiffness``, ``damping``),
        ``"bearing"`` (shaft ``body``, ``point``, ``housing``, ``center``, ``axis``,
        ``kxx`` ... ``cyy`` constant or tabulated against ``speeds`` of ``speed``),
        ``"contact"`` (``body``, ``center``, ``radius``, ``shape``, ``stiffness``,
        ``exponent``, ``restitution``, ``impact_speed``, ``friction``, ``slip_speed``,
        ``plane_point``, ``plane_normal``).  Points are in their body's components.
        """
        if name in self._forces or name in self._loads:
            raise ModelError(f"force {name!r}: the name is already used by another force "
                             "element or load; loads and force elements share one namespace "
                             "(their names are the scene's effects)")
        params = flex.named_points(self, f"force {name!r}", flex.POINT_KEYS.get(kind, ()),
                                   params)
        el = make_force(name, kind, self.parameters, self.gravity, **params)
        check_force(self, el)
        self._forces[name] = el
        return name

    def add_actuator(self, name, joint, kind="torque", **params):
        """A joint actuator: an effort on the coordinate of a revolute or prismatic
        ``joint``, equal and opposite on child and parent; ``kind`` ``"torque"``,
        ``"motor"``, ``"pd"`` or ``"pid"`` and their keys as in ``mbdyn.elements.actuators``
        (docs/actuators.md).  A named effect; compiled (no Python per step)."""
        return add_actuator(self, name, joint, kind, **params)

    def add_controller(self, name, function, rate, joints, limit=None):
        """A controller in Python, ``function(t, q, u) -> efforts`` (one per joint),
        called ``rate`` times a second; its efforts held between calls (zero-order hold)
        by one actuator per joint, ``NAME_JOINT``: the run between samples stays compiled."""
        return add_controller(self, name, function, rate, joints, limit)
    add_shape, add_contact = contacts.add_shape, contacts.add_contact     # docs/contact.md

    def effect_names(self):
        """Every effect of the system: ``gravity``, ``gyroscopic``, loads, force elements."""
        return (GLOBAL_EFFECTS + tuple(self._loads) + tuple(self._forces)
                + flex.effect_names(self))

    # ------------------------------------------------------------------ inspection
    @property
    def bodies(self):
        return {n: d["body"] for n, d in self.graph.nodes(data=True) if n != GROUND}

    @property
    def joints(self):
        return dict(self._joints)

    @property
    def loads(self):
        return dict(self._loads)

    @property
    def forces(self):
        return dict(self._forces)

    # ------------------------------------------------------------------ compile
    def topological_frames(self):
        """Non-ground frames, parents before children (raises if any is not connected)."""
        reachable = nx.descendants(self.graph, GROUND)
        orphans = [n for n in self.graph if n != GROUND and n not in reachable]
        if orphans:
            raise ModelError(f"system {self.name!r}: frames {', '.join(orphans)} are not "
                             "connected to the ground; join each (or its topmost parent) to "
                             "'ground' or to a connected frame with add_joint")
        return [n for n in nx.topological_sort(self.graph) if n != GROUND]

    def compile(self, check_inertia=True, effects=None):
        """Validate the whole tree and return a frozen ``Model``.

        ``check_inertia`` evaluates the mass matrix at a few random configurations and
        refuses degrees of freedom that carry no inertia (a singular ``M``), naming them.
        ``effects`` switches contributions on or off by name (``"-gravity,-damper"``, a list
        of such items, or ``{"gravity": False, "off": [...]}``; see ``mbdyn.effects``):
        the model holds only what is on, exactly as if the rest were deleted.
        """
        state = parse_effects(effects, self.effect_names())
        warn_if_unphysical(state, self.name)
        loop_joints = check_loops(self)
        order = self.topological_frames()
        if not order:
            raise ModelError(f"system {self.name!r} has no bodies; add bodies and joints")
        bodies = [self.graph.nodes[n]["body"] for n in order]
        flexible = flex.flexible_on(self, order, state)
        joints = [next(iter(self.graph.in_edges(n, data="joint")))[2] for n in order]
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            for b in bodies:            # re-run the checks so the model carries the warnings
                inertia_tensor(b.inertia, f"body {b.name!r}")
        found = [str(w.message) for w in caught if issubclass(w.category, ModelWarning)]
        gravity = self.gravity if state["gravity"] else np.zeros(3)
        loads, forces, flex_loads, flex_forces = flex.split_elements(
            flexible, [ld for ld in self._loads.values() if state[ld.name]],
            [el for el in self._forces.values() if state[el.name]])
        bodies, joints, at_nodes, nodes = attach_at_nodes(
            self, flex.massless(bodies, flexible), joints, loop_joints, flexible)
        model = Model(self.name, bodies, joints, loads, gravity,
                      warnings=found, parameters=self.parameters,
                      gravity_symbolic=self.gravity_symbolic if state["gravity"] else None,
                      forces=forces, effects=state, loop_joints=at_nodes,
                      controllers=[c for c in self._controllers.values()
                                   if any(state[a] for a in c.actuators)])
        model = flex.flexible_model(model, flexible, state, flex_loads, flex_forces, nodes)
        if check_inertia and model.nu and not loop_joints:
            _check_inertia_of_every_dof(model)
        model.loops = {j.name: loop_bodies(self, j) for j in loop_joints}
        attach_plant(self, model, state)
        return model


def _check_inertia_of_every_dof(model, samples=3, seed=12345):
    """Refuse degrees of freedom that carry no inertia in any configuration.

    A configuration singularity (Euler angles at ``sin(theta) = 0``) is singular at some
    states only; a degree of freedom without inertia is singular at all of them.
    """
    rng = np.random.default_rng(seed)
    singular_sets = []
    for _ in range(samples):
        q = model.default_coordinates() + rng.uniform(-1.0, 1.0, model.nq)
        model.normalize_quaternions(q)
        try:
            model._check_at_rest(q)
            return
        except SingularMassMatrixError as exc:
            singular_sets.append(set(exc.coordinates))
    names = sorted(set.intersection(*singular_sets), key=model.speeds.index) or \
        sorted(set.union(*singular_sets), key=model.speeds.index)
    hint = ""
    for j in dict.fromkeys(model._speed_joint[model._speed_index[n]] for n in names):
        joint = model.joint(j)
        body = model.body(joint.child)
        if joint.kind in ("spherical", "free") and not np.any(body.inertia):
            hint = (f"  Joint {j!r} carries a particle ({joint.child!r} has mass but no "
                    "inertia), whose spin about its own lever carries none: use two revolute "
                    "joints instead, or give the body a small isotropic inertia (e.g. "
                    "inertia=[1e-9, 1e-9, 1e-9]), which leaves its translation and conical "
                    "motion exact and only adds an unobservable spin.")
    raise ModelError(f"system {model.name!r}: the degrees of freedom {model.describe_speeds(names)} "
                     "carry no inertia -- the mass matrix is singular in every configuration.  "
                     "Give the bodies these joints move mass or inertia about the joint axes, "
                     "or remove (fix) those joints." + hint)

