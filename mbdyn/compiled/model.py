"""The compiled, frozen ``Model``: the model's data (``compiled.layout``) and its numeric
API, whose methods are the algorithms of ``mbdyn.algorithms`` (one job a module).

``System.compile()`` (``mbdyn.assembly``) validates the tree and hands its elements here
in topological order; this layer knows nothing of the tree, only of the element records.
A changed parameter means a new compile, which is cheap (the kernels are compiled once per
machine and cached by numba).

State conventions: ``q`` (coordinates) and ``u`` (speeds) are the *free* ones, in the order
``Model.coordinates`` / ``Model.speeds``; driven joints have no entry, their motion comes
from their drives.  Vectors are in inertial (world) components unless stated.
"""
from __future__ import annotations

import numpy as np

from ..algorithms import closure, contacts, diagnosis, inputs, jourdain
from ..algorithms import constrained as loops
from ..algorithms import loop_reactions as loop_reaction
from ..algorithms import energy as energies
from ..algorithms import forward_dynamics as forward
from ..algorithms import kinematics as motion
from ..algorithms import newton_euler as ne
from ..algorithms import reactions as joint_reactions
from ..errors import ModelError
from . import layout, route_packing, states
from .actuator_packing import reads_time, reflect_rotors, samplers
from .force_packing import pack_forces


class Model:
    """A compiled multibody model (frozen).  Build it with ``System.compile()``.

    Not thread-safe: evaluations share one preallocated workspace; every method returns
    fresh arrays.
    """

    def __init__(self, name, bodies, joints, loads, gravity, warnings=(), parameters=None,
                 gravity_symbolic=None, forces=(), effects=None, loop_joints=(),
                 controllers=()):
        self._arguments = _arguments(locals())    # what a pickled model is compiled from
        self.name = name
        self.warnings = tuple(warnings)
        self.gravity = np.array(gravity, dtype=float)
        #: the element records in topological order (for the symbolic layer and reports)
        self.elements = (tuple(bodies), tuple(joints), tuple(loads))
        self.parameters = dict(parameters or {})
        self.gravity_symbolic = gravity_symbolic
        self.frames = tuple(b.name for b in bodies)
        self.bodies = tuple(b.name for b in bodies if b.has_inertia)
        self.joints = tuple(j.name for j in joints)
        self._joint = {j.name: j for j in joints}
        self._body = {b.name: b for b in bodies}
        self._frame_index = {nm: i for i, nm in enumerate(self.frames)}
        self.n_frames = len(bodies)
        layout.tree(self, joints)
        layout.coordinates(self, joints, clock=reads_time(forces, self.parameters))
        layout.bodies(self, bodies)
        reflect_rotors(self, forces)
        layout.reactions(self, joints)
        load_functions = layout.loads(self, loads)
        # -- force elements and the effects the scene chose (only what is on is here)
        self._force_elements = tuple(forces)
        self.forces = tuple(el.name for el in forces)
        #: ``{effect: on}`` as the scene chose them (see ``mbdyn.elements.effects``)
        self.effects = dict(effects) if effects is not None else dict.fromkeys(
            ("gravity", "gyroscopic") + self.loads + self.forces, True)
        self.gyroscopic = bool(self.effects.get("gyroscopic", True))
        self._force_int, self._force_data, laws = pack_forces(self, forces)
        self._switches = np.array([1 if self.gyroscopic else 0], np.int64)
        layout.workspace(self, joints, len(loop_joints))
        #: the Jourdain route's packed kernels (forward dynamics, state derivative): set
        #: with the arrays they read, on first use (layout.full_workspace)
        self._jourdain_kernel = self._jourdain_rates = None
        layout.pack(self, len(loop_joints))
        #: (load name, the row of the load array its function fills, the function)
        self._load_functions = [(name, getattr(self, target)[k], fn)
                                for name, target, k, fn in load_functions]
        #: force laws evaluated in Python: (element, its force slot in the packed data, law)
        self._laws = laws
        #: drives, function loads or force laws: values Python writes before each compiled
        #: evaluation
        self._python_inputs = bool(self._time_inputs or self._load_functions or self._laws)
        #: the per-call entries' kernels as their one specialization's entry (no
        #: dispatch), with their packed arguments, by method (``kernels.entries.direct``,
        #: ``algorithms.inputs.freeze``): filled on first use
        self._fast_calls = {}
        self._fast_mass_matrix = self._fast_efforts = None   # the hottest two, as attributes
        self._c_mass_matrix = self._c_efforts = None         # and as one C call each
        self._c_forward = {}         # forward dynamics by articulated bodies, by method
        #: controllers in Python and PID integral terms, updated at their sampling
        #: instants between compiled stretches (``integrate.sampled``)
        self._controllers = tuple(controllers)
        self._samplers = samplers(self, controllers)
        layout.argument_groups(self)
        layout.constraints(self, loop_joints)
        #: the route ``method="auto"`` takes (``forward_dynamics.formulation``)
        self._auto_route = forward.formulation(self, "auto")

    def __repr__(self):
        return (f"<Model {self.name!r}: {self.n_frames} frames, {len(self.joints)} joints, "
                f"nq={self.nq}, nu={self.nu}>")

    def __reduce__(self):
        """Pickled as what it was compiled from, and compiled again when unpickled (with
        its loops' bodies and its actuators' plant, which ``System.compile`` adds): its
        arrays are views of two buffers whose addresses its kernels hold, with the address
        of its force elements' compiled function, and a copy would keep none of them (an
        unpickled copy read freed memory: the process crashed)."""
        if type(self) is not Model:
            raise TypeError(f"a {type(self).__name__} ({self.name!r}) cannot be pickled; "
                            "pickle the System or the model file it was compiled from")
        extras = {k: getattr(self, k) for k in ("loops", "_plant") if hasattr(self, k)}
        return _compiled_again, (self._arguments, extras)

    # ------------------------------------------------------------------ names and records
    def joint(self, name):
        """The joint record (kind, axis, parent, child, coordinates, drive...); a loop
        joint's record (``elements.constraints.LoopJoint``) too."""
        if isinstance(name, str) and name in self._loop_joint:
            return self._loop_joint[name]
        return _look_up(self._joint, name, "joint", "joints", self.joints)

    @property
    def has_loops(self):
        """True when loop joints close the tree (constraint equations)."""
        return self._con is not None

    def body(self, name):
        """The body record (mass, com, inertia about the centre of mass)."""
        return _look_up(self._body, name, "body or frame", "bodies and frames", self.frames)

    def coordinate_index(self, name):
        return _look_up(self._coordinate_index, name, "coordinate", "coordinates",
                        self.coordinates)

    def speed_index(self, name):
        return _look_up(self._speed_index, name, "speed", "speeds", self.speeds)

    def frame_index(self, name):
        return _look_up(self._frame_index, name, "frame", "frames", self.frames)

    @property
    def driven_joints(self):
        return tuple(d[0] for d in self._driven)

    def force_element(self, name):
        """The force-element record (kind, frames, parameters) by name."""
        for el in self._force_elements:
            if el.name == name:
                return el
        raise ModelError(f"unknown force element {name!r}; the model's force elements are "
                         f"{', '.join(self.forces) or '(none)'}")

    def describe_speeds(self, speeds):
        """``"theta2 (joint 'theta2')"``: the coordinates and joints behind some speeds
        (for a joint whose speeds are not coordinate rates, the speeds are named too)."""
        parts = []
        for j in dict.fromkeys(self._speed_joint[self._speed_index[s]] for s in speeds):
            joint = self._joint[j]
            mine = [x for x in speeds if self._speed_joint[self._speed_index[x]] == j]
            if joint.kind in ("spherical", "free"):
                parts.append(f"{', '.join(mine)} (joint {j!r})")
            else:
                coords = [joint.coordinates[joint.speeds.index(x)] for x in mine]
                parts.append(f"{', '.join(coords)} (joint {j!r})")
        return "; ".join(parts) or "some coordinates"

    # ------------------------------------------------------------------ states by name
    default_coordinates = states.default_coordinates
    q_vector = states.q_vector
    u_vector = states.u_vector
    _vector = states.vector
    _vector_of = states.vector_of
    normalize_quaternions = states.normalize_quaternions
    quaternion_drift = states.quaternion_drift

    # ------------------------------------------------------------------ evaluation core
    _fill = inputs.fill
    _as_arrays = inputs.as_arrays
    _require_finite = inputs.require_finite
    _state = inputs.state
    _fill_inputs = inputs.fill_inputs
    _fill_laws = inputs.fill_laws
    _check_finite = inputs.check_finite
    _lambdify_load = inputs.lambdify_load
    _kinematics_kernel = motion.kinematics_kernel
    _drop_velocity_products = motion.drop_velocity_products
    _jourdain_terms = jourdain.jourdain_terms
    _jourdain_packed = jourdain.jourdain_packed
    _mass_matrix = jourdain.mass_matrix_by
    _check_at_rest = jourdain.check_at_rest
    _newton_euler = ne.solve
    _reactions_from = ne.reactions_from
    _raise_singular = diagnosis.raise_singular
    _division_by_zero = inputs.division_by_zero
    _full_workspace = layout.full_workspace

    # ------------------------------------------------------------------ the numeric API
    kinematics = motion.kinematics
    jacobian_rotation = motion.jacobian_rotation
    jacobian_translation = motion.jacobian_translation
    point_positions = motion.point_positions
    coordinate_rates = motion.coordinate_rates
    mass_matrix = jourdain.mass_matrix
    forcing = jourdain.forcing
    forward_dynamics = forward.forward_dynamics
    formulation = forward.formulation
    state_derivative = forward.state_derivative
    newton_euler = ne.newton_euler
    reactions = joint_reactions.reactions
    reaction_array = joint_reactions.reaction_array
    inverse_dynamics = joint_reactions.inverse_dynamics
    effort_array = joint_reactions.effort_array
    inverse_dynamics_along = joint_reactions.inverse_dynamics_along
    drive_efforts = joint_reactions.drive_efforts
    energy = energies.energy
    momentum = energies.momentum
    element_energy = energies.element_energy
    element_power = energies.element_power
    contact_gap = contacts.contact_gap
    contact_forces = contacts.contact_forces
    load_power = energies.load_power
    euler_singularity = diagnosis.euler_singularity
    # closed loops (``algorithms.constrained``, ``algorithms.closure``)
    constraint_residuals = loops.constraint_residuals
    constraint_jacobian = loops.constraint_jacobian
    constraint_rank = loops.constraint_rank
    mobility = loops.mobility
    multipliers = loops.multipliers
    project = loops.project
    assemble = closure.assemble
    reaction_uniqueness = loop_reaction.reaction_uniqueness

    @property
    def reaction_joints(self):
        """The joints that have reactions: the tree's, then the loop joints'."""
        return loop_reaction.reaction_joints(self) if self._con is not None else self.joints
    _constrained_accelerations = loops.constrained_accelerations
    mass_matrix_condition = diagnosis.mass_matrix_condition

    def _dense_system(self):
        """``(A, b)``: the workspace of the dense Newton-Euler system (6n x 6n and 6n),
        allocated on the first use of that route and kept (with the full Jacobians it
        reads, ``_full_workspace``)."""
        self._full_workspace()
        if getattr(self, "_A", None) is None:
            self._A = np.zeros((6 * self.n_frames, 6 * self.n_frames))
            self._b = np.zeros(6 * self.n_frames)
        return self._A, self._b

    def lowlevel(self, method="auto"):
        """The low-level entry (``mbdyn.compiled.lowlevel.LowLevel``):
        ``forward_dynamics(q, u)`` and ``state_derivative(y)`` as single compiled calls on
        preallocated buffers, for loops of your own; ``method``: ``"auto"``,
        ``"jourdain"`` or ``"articulated"``."""
        from .lowlevel import LowLevel
        if self._con is not None:
            raise ModelError(f"model {self.name!r} has closed loops: its low-level entry is "
                             "not there yet (the tree's would ignore the loops); use "
                             "model.forward_dynamics(q, u, t) or model.state_derivative(t, y)")
        return LowLevel(self, self.formulation(method))

    # ------------------------------------------------------------------ compiled loops
    @property
    def has_callable_loads(self):
        """True when some load is a Python function (compiled loops cannot call it)."""
        return bool(self._load_functions or self._laws)

    def drive_values(self, times):
        """``(len(times), n_drives, 3)``: each drive's ``q, q', q''`` at ``times``."""
        out = np.empty((len(times), len(self._time_inputs), 3))
        for d, (_, _, _, drive) in enumerate(self._time_inputs):
            for k, tk in enumerate(times):
                out[k, d] = drive.position(tk), drive.velocity(tk), drive.acceleration(tk)
        return out

    def loop_arguments(self, method="jourdain"):
        """The arrays the compiled loops (``kernels.integrators.LOOPS``) take after their
        drive table: ``(nq, slots, quats, free_q, free_u, drive_q, drive_u, tree, body,
        loads, ws)``; laid out for ``method`` ``"jourdain"`` or ``"articulated"``
        (``compiled.route_packing``: the articulated and closed routes by address)."""
        return route_packing.loop_arguments(self, method)


def _arguments(given):
    """What ``Model.__init__`` was given (its ``locals()`` on entry), as ``Model(**...)``
    takes it again when a pickled model is compiled again (``Model.__reduce__``): the
    sequences as tuples, gravity and the parameters copied (the System may change its
    own after compiling)."""
    args = {k: v for k, v in given.items() if k != "self"}
    for k in ("bodies", "joints", "loads", "warnings", "forces", "loop_joints", "controllers"):
        args[k] = tuple(args[k])
    args["gravity"] = np.array(args["gravity"], dtype=float)
    args["parameters"] = dict(args["parameters"] or {})
    return args


def _compiled_again(arguments, extras):
    """A pickled ``Model`` (``Model.__reduce__``)."""
    model = Model(**arguments)
    for name, value in extras.items():
        setattr(model, name, value)
    return model


def _look_up(table, name, what, plural, known):
    """``table[name]``, or a ``ModelError`` naming what is unknown and listing the names
    there are."""
    try:
        return table[name]
    except (KeyError, TypeError):
        raise ModelError(f"unknown {what} {name!r}; the model's {plural} are "
                         f"{', '.join(map(str, known)) or '(none)'}") from None
