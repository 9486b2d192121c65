"""``FlexibleModel``: a compiled model with flexible bodies (modal coordinates).

It holds the tree compiled as every model is (``model.tree``, a ``Model``), with its
flexible bodies as massless frames there, and per flexible body what its terms read
(``FlexPack``: invariants, modal mass, stiffness, damping, geometric stiffness).  The
free coordinates and speeds are the tree's, then each flexible body's modal coordinates
``BODY_m1 ...`` and rates ``BODY_m1_dot ...``, in tree order: appended, so that every
index into the tree's state (quaternions, Euler angles, events, drives) stays valid in
the model's.  Its dynamics are ``algorithms.flexible_dynamics`` (Python, Jourdain);
anything else it reads from the tree by name (``__getattr__``), and the routes that are
not there yet for flexible bodies say so.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..algorithms import flexible_dynamics as flex
from ..algorithms import flexible_forces
from ..algorithms import flexible_kernels as compiled
from ..algorithms import flexible_loops as flex_loops
from ..algorithms import flexible_newton_euler as flex_ne
from ..algorithms import flexible_reactions as flex_reactions
from ..errors import ModelError
from .flexible_packing import FlexibleKernels
from .flexible_states import remapped_layout, state_map
from .model import Model


@dataclass(frozen=True, eq=False)
class FlexPack:
    """One flexible body as its terms read it: the tree's ``frame`` index, its slices
    ``q`` and ``u`` of the model's state, ``n`` modes, the ``invariants`` (with the rigid
    part fixed to it), modal ``mass``, ``stiffness``, ``damping``, and the geometric
    stiffness per unit ``omega_y^2 + omega_z^2`` (``centrifugal``) and per unit
    ``a_x - g_x`` (``axial``): zero for reduced data, which carry none; a rotor's
    ``spin`` (rad/s about x, its frame not spinning) and ``gyroscopic`` ``G_ee`` (or
    ``None``)."""
    name: str
    frame: int
    q: slice
    u: slice
    n: int
    invariants: object
    mass: np.ndarray
    stiffness: np.ndarray
    damping: np.ndarray
    centrifugal: np.ndarray
    axial: np.ndarray
    spin: float = 0.0
    gyroscopic: np.ndarray | None = None


def pack_flexible(tree, records):
    """The ``FlexPack`` of each ``FlexibleBody`` in ``records`` (tree order), their modal
    coordinates after the tree's."""
    packs, nq, nu = [], tree.nq, tree.nu
    for rec in records:
        red, n = rec.reduced, rec.n_modes
        zero = np.zeros((n, n))
        packs.append(FlexPack(
            rec.name, tree.frame_index(rec.name), slice(nq, nq + n), slice(nu, nu + n), n,
            rec.invariants, red.mass_matrix, red.stiffness_matrix, red.damping_matrix,
            red.geometric_stiffness.get("centrifugal", zero),
            red.geometric_stiffness.get("axial_acceleration", zero), rec.spin,
            red.gyroscopic))
        nq, nu = nq + n, nu + n
    return tuple(packs)


def _not_yet(what):
    def refuse(self, *args, **kwargs):
        raise ModelError(f"model {self.name!r} has flexible bodies "
                         f"({', '.join(self.flexible_bodies)}): {what} is not there yet for "
                         "them (the next step); switch their flexibility off "
                         f"(effects: -{self.tree_effect_example}) to use it")
    refuse.__name__ = what
    return refuse


class FlexibleModel(Model):
    """A compiled model with flexible bodies; build it with ``System.compile()``."""

    def __init__(self, tree, records, stiffening=True, loads=(), forces=(), nodes=()):
        # not Model.__init__: the tree is compiled already, and read through __getattr__
        self.tree = tree
        self.name = tree.name
        self.stiffening = bool(stiffening)
        self.flexible_bodies = tuple(r.name for r in records)
        self.flexible = {r.name: r for r in records}
        self._flex = pack_flexible(tree, records)
        #: the node frames joints attach to (``elements.flexible_nodes``), tree order
        self.node_frames = tuple(nodes)
        self._map = state_map(tree, self._flex, self.node_frames)
        modal = sum((r.coordinates for r in records), ())
        self._nux = tree.nu + len(modal)           # the extended speeds: tree's, modal
        keep_q = range(tree.nq) if self._map is None else self._map.keep_q
        keep_u = range(tree.nu) if self._map is None else self._map.keep_u
        self.coordinates = tuple(tree.coordinates[k] for k in keep_q) + modal
        self.speeds = (tuple(tree.speeds[k] for k in keep_u)
                       + sum((r.speeds for r in records), ()))
        self.nq, self.nu = len(self.coordinates), len(self.speeds)
        self.modal_coordinates = modal
        (self._quaternions, self._euler_middle, self._free_joint_slots,
         self._speed_joint) = remapped_layout(tree, self._map, self._flex)
        chain = {j for nf in self.node_frames for j in nf.joints}
        self.joints = tuple(j for j in tree.joints if j not in chain)
        bodies, joints, tree_loads = tree.elements
        self.elements = (bodies, tuple(j for j in joints if j.name not in chain), tree_loads)
        self._coordinate_index = {c: k for k, c in enumerate(self.coordinates)}
        self._speed_index = {c: k for k, c in enumerate(self.speeds)}
        self._body = {**tree._body, **{r.name: r.rigid for r in records}}
        self.bodies = tuple(f for f in tree.frames if f in self._body
                            and self._body[f].has_inertia)
        self.tree_effect_example = f"flexibility_{records[0].name}"
        tree._full_workspace()        # the Jacobians and M the terms read
        self._outer = None            # the model's state of an evaluation (load functions)
        if self._map is not None:
            _outer_load_functions(self)
        # loads and force elements at points of the flexible bodies: evaluated in Python
        self.loads = tree.loads + tuple(ld.name for ld in loads)
        self.forces = tree.forces + tuple(el.name for el in forces)
        self._force_elements = tree._force_elements + tuple(forces)
        self._flex_elements = flexible_forces.pack(self, loads, forces)
        #: the arrays of the compiled evaluations and loops (``kernels.flexible``)
        self._kernels = FlexibleKernels(self)

    def _extended(self, q, u=None):
        """``(q_x, u_x)``: the tree's state then the modal one (``compiled.
        flexible_states``), from the model's ``(q, u)``; the same arrays without node
        frames."""
        self._outer = (q, np.zeros(self.nu) if u is None else u)
        if self._map is None:
            return q, u
        return self._map.extended(q, u)

    def _model_state(self, qx, ux):
        """The model's ``(q, u)`` from extended ones."""
        return (qx, ux) if self._map is None else self._map.model_state(qx, ux)

    def _extended_speed(self, k):
        """The extended index of the model's speed ``k``."""
        return k if self._map is None else self._map.tree_index(k)

    def __getattr__(self, name):
        tree = self.__dict__.get("tree")
        if tree is None:
            raise AttributeError(name)
        return getattr(tree, name)

    def __repr__(self):
        return (f"<FlexibleModel {self.name!r}: {self.n_frames} frames, flexible "
                f"{', '.join(self.flexible_bodies)}, nq={self.nq}, nu={self.nu}>")

    def node_row(self, name, names):
        """``BODY.NODE.c`` (``c``: x, y or z): that node's displacement component (body
        axes) as a row over the coordinates ``names`` (the modal ones' mode shapes)."""
        body, node, comp = name.split(".")
        if body not in self.flexible or comp not in ("x", "y", "z"):
            raise ModelError(f"{name!r}: give BODY.NODE.c with BODY a flexible body "
                             f"({', '.join(self.flexible_bodies)}) and c one of x, y, z")
        rec = self.flexible[body]
        try:
            i = rec.reduced.node(int(node) if node.isdigit() else node)
        except ModelError as exc:
            raise ModelError(f"{name!r}: {exc}") from None
        row = np.zeros(len(names))
        for k, c in enumerate(rec.coordinates):
            if c in names:
                row[list(names).index(c)] = rec.reduced.modes[i, "xyz".index(comp), k]
        return row

    def describe_speeds(self, speeds):
        tree = [s for s in speeds if s in self.tree._speed_index]
        modal = [s for s in speeds if s not in self.tree._speed_index]
        parts = ([self.tree.describe_speeds(tree)] if tree else []) + (
            [f"{', '.join(modal)} (modal)"] if modal else [])
        return "; ".join(parts) or "some coordinates"

    @property
    def has_callable_loads(self):
        """True when some load is a Python function (the tree's, or one at a flexible
        body's point), or the flexible bodies' terms are numpy's (``compiled_terms``
        off, the default; or contacts between shapes): runs then take the Python
        routes."""
        return (self.tree.has_callable_loads or bool(self._kernels.load_functions)
                or not self._kernels.supported)

    @property
    def compiled_terms(self):
        """True when the flexible bodies' terms (``u'``, ``M``, ``f``, the multipliers,
        the projection) are evaluated by the compiled function and runs take the
        compiled loops (``algorithms.flexible_kernels``); False (the default): by numpy
        (``flexible_dynamics``, ``flexible_loops``) and scipy's or the Python loops.
        Opt-in: its first use compiles for 20 to 30 s of CPU per kind of model
        (without or with loops, force elements), once per installation (numba's cache);
        ``docs/flexible.md``, "Routes and cost"."""
        return self._kernels.supported

    @compiled_terms.setter
    def compiled_terms(self, on):
        if on and not self._kernels.takes:
            raise ModelError(f"model {self.name!r}: the compiled flexible terms do not take "
                             "contacts between shapes; keep compiled_terms = False")
        self._kernels.opted = bool(on)

    @property
    def flexible_forces(self):
        """True when modal damping or the geometric stiffening (forces no potential
        gives) act: ``T + V`` alone is then not conserved."""
        return self.stiffening or any(fb.damping.any() for fb in self._flex)

    @property
    def has_loops(self):
        """True when loop joints close the tree (at points of flexible bodies or not)."""
        return self.tree._con is not None

    def forward_dynamics(self, q, u, t=0.0, method="jourdain"):
        """``u'``: of ``M u' = f``, or with loops of ``M u' = f + G^T lam``,
        ``G u' = gamma`` (``algorithms.flexible_kernels``: compiled with
        ``compiled_terms``, else numpy's ``flexible_dynamics``, ``flexible_loops``);
        ``"newton-euler"`` (or ``"-dense"``): the system with reaction unknowns
        (``algorithms.flexible_newton_euler``)."""
        if method in flex_ne.METHODS:
            return flex_ne.forward_dynamics(self, q, u, t)
        return compiled.forward_dynamics(self, q, u, t, method)

    def formulation(self, method="auto"):
        """``"jourdain"`` for ``"auto"`` and ``"jourdain"``, the Newton-Euler routes as
        named; ``"articulated"`` is refused."""
        if method in ("auto", "jourdain"):
            return "jourdain"
        if method in flex_ne.METHODS:
            return method
        raise ModelError(f"model {self.name!r} has flexible bodies "
                         f"({', '.join(self.flexible_bodies)}): methods 'jourdain' (or "
                         f"'auto'), 'newton-euler' and 'newton-euler-dense' are there for "
                         f"them, in Python; not {method!r}")

    # the tree's frames (the node frames among them, moved by the modal coordinates)
    def _tree_state(self, q, u=None, ud=None):
        q = np.asarray(q, float)
        qx, ux = self._extended(q, None if u is None else np.asarray(u, float))
        udx = None
        if ud is not None:
            udx = np.asarray(ud, float) if self._map is None else \
                self._map.P @ np.asarray(ud, float)
        nqt, nut = self.tree.nq, self.tree.nu
        return (qx[:nqt], None if ux is None else ux[:nut],
                None if udx is None else udx[:nut])

    def kinematics(self, q, u=None, ud=None, t=0.0):
        return self.tree.kinematics(*self._tree_state(q, u, ud), t)

    def _model_columns(self, J):
        """A tree Jacobian (3, tree speeds) as columns of the model's speeds."""
        out = np.zeros((3, self._nux))
        out[:, :J.shape[1]] = J
        return out if self._map is None else out @ self._map.P

    def jacobian_rotation(self, q, frame, t=0.0):
        return self._model_columns(self.tree.jacobian_rotation(self._tree_state(q)[0],
                                                               frame, t))

    def jacobian_translation(self, q, frame, point=None, t=0.0):
        return self._model_columns(self.tree.jacobian_translation(
            self._tree_state(q)[0], frame, point, t))

    def point_positions(self, q, points, t=0.0):
        return self.tree.point_positions(self._tree_state(q)[0], points, t)

    def element_power(self, q, u, t=0.0):
        """The force elements' ``(V, P_nc, P_actuators)``, the flexible bodies' modal
        damping and geometric stiffening counted in ``P_nc`` (``modal_power``)."""
        V, P_nc, P_act = self.tree.element_power(*self._tree_state(q, u)[:2], t)
        V_f, P_f, _ = flex.element_energies(self, q, u, t)
        return V + V_f, P_nc + P_f + flex.modal_power(self, q, u, t), P_act

    def u_vector(self, values=None):
        """As ``Model.u_vector``; a modal coordinate's name stands for its rate too."""
        if isinstance(values, dict):
            rates = {c: s for r in self.flexible.values()
                     for c, s in zip(r.coordinates, r.speeds)}
            values = {rates.get(k, k): v for k, v in values.items()}
        return Model.u_vector(self, values)

    def element_energy(self, q, u, t=0.0):
        V, P_nc, P_act = self.element_power(q, u, t)
        return V, P_nc + P_act

    def load_power(self, q, u, t=0.0):
        return self.tree.load_power(*self._tree_state(q, u)[:2], t) + \
            flex.element_energies(self, q, u, t)[2]

    state_derivative = flex.state_derivative
    coordinate_rates = flex.coordinate_rates
    mass_matrix = compiled.mass_matrix
    forcing = compiled.forcing
    energy = flex.energy
    momentum = flex.momentum
    mass_matrix_condition = flex.mass_matrix_condition
    _check_at_rest = flex.check_at_rest
    constraint_residuals = flex_loops.constraint_residuals
    constraint_jacobian = flex_loops.constraint_jacobian
    multipliers = compiled.multipliers
    project = compiled.project

    reactions = flex_reactions.reactions
    reaction_uniqueness = flex_reactions.reaction_uniqueness

    def reaction_array(self, q, u, t=0.0, frame="world"):
        """The tree joints' reactions as one array, a row per joint of ``joints``."""
        out = self.reactions(q, u, t, frame=frame)
        return np.array([np.concatenate(out[name]) for name in self.joints])

    newton_euler = flex_ne.newton_euler
    inverse_dynamics = _not_yet("inverse_dynamics")
    inverse_dynamics_along = _not_yet("inverse_dynamics_along")
    lowlevel = _not_yet("the low-level compiled entry")

    def loop_arguments(self, method="jourdain"):
        """The arrays the compiled loops take (``Model.loop_arguments``), laid out for
        the flexible bodies' route (``kernels.routes``)."""
        self.formulation(method)
        return self._kernels.loop_arguments(self)


def _outer_load_functions(model):
    """The tree's loads given as Python functions ``(t, q, u)`` called with the model's
    state (the tree's holds the node frames' chain coordinates, which the user's
    function does not know); loads written as expressions read the tree's by name."""
    tree = model.tree
    given = {ld.name for ld in tree.elements[2]
             if callable(ld.force) or callable(ld.moment)}

    def outer(fn):
        def load(t, q, u):
            return fn(t, *model._outer)
        return load
    tree._load_functions = [(name, row, outer(fn) if name in given else fn)
                            for name, row, fn in tree._load_functions]
