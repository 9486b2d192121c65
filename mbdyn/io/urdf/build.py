"""A URDF ``Robot`` added to a ``System`` through its public API (``add_body``,
``add_frame``, ``add_joint``, ``add_force``): no second model representation.

* links are bodies named after them (a link without ``<inertial>`` is a massless frame);
  the body frame is the link frame, the centre of mass the inertial origin, the inertia
  turned from the inertial frame into the link frame;
* joints are joints named after them, their coordinates too (made identifiers where the
  URDF name is not one: ``base-joint`` -> ``base_joint``, with a warning).  The joint frame
  is the child link's frame, placed in the parent's by ``<origin>``; ``<axis>`` is in it.
  ``revolute`` and ``continuous`` -> ``revolute``; ``prismatic``; ``fixed``; ``floating`` ->
  ``free``; ``planar`` -> two prismatic joints and a revolute through massless frames
  ``NAME.slide1``, ``NAME.slide2`` (joints and coordinates ``NAME_slide1``,
  ``NAME_slide2``, ``NAME_turn``);
* the root link hangs from the ground by a joint ``root``: ``fixed`` by default, ``free``
  with ``floating``; a root link named ``world`` is the ground itself;
* ``<dynamics damping>`` -> a ``joint-spring-damper`` ``damping_COORD``;
  ``<dynamics friction>`` -> one with the law ``friction tanh(v / 0.01)``
  (regularised Coulomb), ``friction_COORD``; ``<limit lower upper>`` of a revolute or
  prismatic joint -> a stop ``limit_COORD`` (``effects.add_stops``); ``<mimic>`` -> a
  ``coupling`` loop joint ``mimic_COORD``.  All are named effects;
* a link's ``<visual>`` elements are its body's drawing shapes (``visuals``: meshes found
  through ``mesh_path``, drawn by the pictures).
"""
from __future__ import annotations

import re

import numpy as np
import sympy

from ...assembly.system import GROUND
from ...elements.expressions import RESERVED
from ...names import identifier_problem
from .effects import add_effects
from .tree import check_inertia, link_inertia, rpy_matrix, tree_order
from .visuals import link_shapes

#: the joint kind each URDF type becomes
KINDS = {"revolute": "revolute", "continuous": "revolute", "prismatic": "prismatic",
         "fixed": "fixed", "floating": "free", "planar": "planar"}
ROOT = "root"


class RobotBuilder:
    """Adds one ``Robot`` to ``system``; ``report`` says what was read and made,
    ``warnings`` what the user should know, ``bodies`` and ``joints`` the names added."""

    def __init__(self, system, reader, robot, floating=False, accept_inertia=False,
                 mesh_path=()):
        self.system, self.reader, self.robot = system, reader, robot
        self.mesh_path, self.missing_meshes = list(mesh_path or ()), set()
        self.floating, self.accept = bool(floating), bool(accept_inertia)
        self.warnings, self.bodies, self.joints = [], [], []
        self.taken = set(system.parameters) | {"t"}
        for j in system.joints.values():
            self.taken.update(j.coordinates + j.speeds)
        self.coordinate = {}              # URDF joint -> its coordinate's (base) name
        self.report = {"file": reader.file, "robot": robot.name, "massless": [],
                       "joints": [], "renamed": {}, "effects": {}, "stops": {},
                       "accepted_inertia": [], "transmissions": robot.transmissions,
                       "not_used": dict(robot.not_used)}

    def build(self):
        root, order = tree_order(self.reader, self.robot)
        self.root = root
        self.report["root"] = root
        self.ground = root == "world"
        self.report["base"] = "world" if self.ground else (
            "floating" if self.floating else "fixed")
        self.links(order)
        self.root_joint()
        for joint in order:
            self.joint(joint)
        add_effects(self, order)
        self.warn_not_used()
        return self.report

    def error(self, where, problem):
        return self.reader.error(where, problem)

    def frame(self, link):
        return GROUND if (link == self.root and self.ground) else link

    # -- links
    def links(self, order):
        names = [self.root] + [j.child for j in order]
        for name in names:
            if name == GROUND:
                raise self.error(f"link {name!r}", "mbdyn names its fixed frame 'ground'; a "
                                 "link cannot take that name (a root link named 'world' is "
                                 "the ground)")
            link = self.robot.links[name]
            if self.frame(name) == GROUND:
                if link.inertial is not None and link.inertial.mass > 0:
                    self.warnings.append(f"{self.reader.file}: link 'world' is the ground; "
                                         "its <inertial> is not used")
                continue
            shapes = link_shapes(link, self.reader.file, self.mesh_path, self.warnings,
                                 self.missing_meshes) or None
            if link.inertial is None or (link.inertial.mass == 0 and (
                    link.inertial.inertia is None or not any(link.inertial.inertia))):
                self.system.add_frame(name, shape=shapes)
                self.report["massless"].append(name)
            else:
                mass, com, inertia = link_inertia(link.inertial)
                inertia, warning = check_inertia(self.reader, name, inertia, self.accept)
                if warning:
                    self.warnings.append(warning)
                    self.report["accepted_inertia"].append(name)
                self.system.add_body(name, mass=mass, com=com.tolist(),
                                     inertia=inertia.tolist(), shape=shapes)
            self.bodies.append(name)

    def root_joint(self):
        if self.ground:
            if self.floating:
                raise self.error("link 'world'", "the root link is 'world', the ground: "
                                 "there is no base to set floating; remove the floating "
                                 "option, or make the joint from 'world' a floating joint")
            return
        if ROOT in self.robot.joints:
            raise self.error(f"joint {ROOT!r}", "mbdyn names the joint of the base 'root'; "
                             "rename this joint")
        kind = "free" if self.floating else "fixed"
        self.system.add_joint(ROOT, kind, GROUND, self.root)
        self.joints.append(ROOT)
        self.taken.update(self.system.joints[ROOT].coordinates +
                          self.system.joints[ROOT].speeds)

    # -- joints
    def name_for(self, joint):
        """An identifier for the coordinates of ``joint``, unique among the model's names
        (a warning when it differs from the URDF's name)."""
        base = re.sub(r"[^A-Za-z0-9_]", "_", joint.name)
        if not base or base[0].isdigit():
            base = "j_" + base
        if base in RESERVED or identifier_problem(base):
            base = base.strip("_") + "_joint"
        name, k = base, 2
        while any(n in self.taken for n in (name, name + "_dot")):
            name, k = f"{base}_{k}", k + 1
        self.taken.update((name, name + "_dot"))
        if name != joint.name:
            self.report["renamed"][joint.name] = name
            self.warnings.append(f"{self.reader.file}: joint {joint.name!r}: its "
                                 f"coordinate is named {name!r} (a name of letters, "
                                 "digits and underscores, unique in the model)")
        self.coordinate[joint.name] = name
        return name

    def axis(self, joint):
        a = np.array(joint.axis, dtype=float)
        norm = float(np.linalg.norm(a))
        if norm < 1e-12:
            raise self.error(f"joint {joint.name!r}", "its <axis xyz> is zero; give the "
                             "direction of the axis")
        return (a / norm).tolist()

    def joint(self, joint):
        kind = KINDS[joint.type]
        c = self.name_for(joint) if kind != "fixed" else None      # no coordinates
        parent, child = self.frame(joint.parent), joint.child
        place = dict(position=list(joint.xyz), orientation=rpy_matrix(joint.rpy).tolist())
        add = self.system.add_joint
        if kind in ("revolute", "prismatic"):
            add(joint.name, kind, parent, child, axis=self.axis(joint), coordinates=[c],
                **place)
        elif kind == "fixed":
            add(joint.name, kind, parent, child, **place)
        elif kind == "free":
            parts = ("x", "y", "z", "qw", "qx", "qy", "qz", "vx", "vy", "vz", "wx", "wy", "wz")
            names = [f"{c}_{p}" for p in parts]
            self.taken.update(names)
            add(joint.name, kind, parent, child, coordinates=names[:7], speeds=names[7:],
                **place)
        else:
            self.planar(joint, c, parent, child, place)
            return
        self.joints.append(joint.name)
        self.report["joints"].append(self.describe(joint, kind, [joint.name]))

    def planar(self, joint, c, parent, child, place):
        """Two prismatic joints along ``e1``, ``e2`` (in the plane normal to the axis,
        ``e1 x e2 = axis``) and a revolute about the axis, through two massless frames."""
        n = np.array(self.axis(joint))
        first = np.eye(3)[int(np.argmin(np.abs(n)))]
        e1 = first - (first @ n) * n
        e1 /= np.linalg.norm(e1)
        e2 = np.cross(n, e1)
        f1, f2 = f"{joint.name}.slide1", f"{joint.name}.slide2"
        names = [f"{joint.name}_slide1", f"{joint.name}_slide2", f"{joint.name}_turn"]
        coords = [f"{c}_slide1", f"{c}_slide2", f"{c}_turn"]
        self.taken.update(coords + [x + "_dot" for x in coords])
        self.system.add_frame(f1)
        self.system.add_frame(f2)
        add = self.system.add_joint
        add(names[0], "prismatic", parent, f1, axis=e1.tolist(), coordinates=[coords[0]],
            **place)
        add(names[1], "prismatic", f1, f2, axis=e2.tolist(), coordinates=[coords[1]])
        add(names[2], "revolute", f2, child, axis=n.tolist(), coordinates=[coords[2]])
        self.bodies.extend([f1, f2])
        self.joints.extend(names)
        self.report["joints"].append(self.describe(joint, "planar", names))

    def describe(self, joint, kind, parts):
        entry = {"name": joint.name, "type": joint.type, "as": kind,
                 "parent": joint.parent, "child": joint.child,
                 "coordinates": [q for p in parts for q in self.system.joints[p].coordinates]}
        for key in ("limit", "dynamics", "mimic"):
            if getattr(joint, key):
                entry[key] = dict(getattr(joint, key))
        return entry

    def warn_not_used(self):
        skipped = self.report["not_used"]
        if not skipped:
            return
        notes = {"link/collision": "contacts are not made from them",
                 "transmission": "listed by mbdyn info; no actuator model"}
        text = ", ".join(f"<{tag}> ({count}{'; ' + notes[tag] if tag in notes else ''})"
                         for tag, count in skipped.items())
        self.warnings.append(f"{self.reader.file}: not used by mbdyn: {text}")


def add_robot(system, reader, robot, floating=False, accept_inertia=False, mesh_path=()):
    """Add ``robot`` to ``system``; the ``RobotBuilder`` (its ``report``, ``warnings``,
    ``bodies``, ``joints``).  ``mesh_path``: folders ``package://`` meshes are looked for
    in (``visuals``)."""
    builder = RobotBuilder(system, reader, robot, floating, accept_inertia, mesh_path)
    builder.build()
    return builder
