"""Flexible bodies added to a ``System`` and checked across the tree at compile: their
modal coordinates' names, their effects (``flexibility_BODY``, ``geometric_stiffening``),
and what may attach to them: joints, tree or loop joints, at any point (at its node
frame, ``assembly.flexible_nodes``); loads and spring-dampers, bushings and bearings at
their nodes, evaluated in Python by ``algorithms.flexible_forces``.
"""
from __future__ import annotations

import dataclasses

import numpy as np

from ..algorithms.flexible_forces import KINDS
from ..compiled.flexible_model import FlexibleModel
from ..elements.bodies import make_body
from ..elements.flexible_bodies import make_flexible_body
from ..errors import ModelError
from ..flexible.points import node_position

#: the global effect of every system with flexible bodies: the axial force's stiffness
STIFFENING = "geometric_stiffening"


def flexibility_effect(body):
    """The effect that switches ``body``'s flexibility: ``flexibility_BODY`` (an identifier,
    like every effect name, so that it reads the same in ``[effects]``, ``--effects`` and
    ``--set effects.flexibility_BODY=false``)."""
    return f"flexibility_{body}"


def add_flexible_body(system, name, mass, com, inertia, shape, flexible, base=None):
    """``System.add_body(..., flexible=...)``: the rigid part (``mass``, ``com``,
    ``inertia`` about its centre of mass) is validated as a rigid body's, then the
    ``FlexibleBody`` is built (``mbdyn.elements.flexible_bodies``)."""
    lumped = make_body(name, mass, com, inertia, system.parameters, shape)
    if lumped.symbolic:
        raise ModelError(f"body {name!r}: a flexible body's mass, com and inertia must be "
                         "numbers (its invariants are numeric), not expressions of "
                         f"parameters ({', '.join(lumped.symbolic)})")
    record = make_flexible_body(name, flexible, lumped, base, system.parameters)
    clash = system._state_names.intersection(record.coordinates + record.speeds)
    if clash:
        raise ModelError(f"body {name!r}: its modal coordinates {sorted(clash)} are already "
                         "used by a joint's coordinates; rename that joint's coordinates")
    effect = flexibility_effect(name)
    if effect in system._loads or effect in system._forces:
        raise ModelError(f"body {name!r}: its effect name {effect!r} is already a load's or "
                         "force element's name; rename that element")
    system._state_names.update(record.coordinates + record.speeds)
    system._flexible[name] = record
    system.graph.add_node(name, body=record.rigid)
    return name


def effect_names(system):
    """The effects flexible bodies add (none without them): ``geometric_stiffening`` and
    one ``flexibility_BODY`` per flexible body."""
    if not system._flexible:
        return ()
    names = (STIFFENING,) + tuple(flexibility_effect(b) for b in system._flexible)
    taken = [n for n in names if n in system._loads or n in system._forces]
    if taken:
        raise ModelError(f"system {system.name!r}: {', '.join(taken)} name effects of the "
                         "flexible bodies; rename the loads or force elements so named")
    return names


def flexible_on(system, order, state):
    """The flexible bodies whose flexibility the scene keeps on, in tree order, after the
    checks of what attaches to them."""
    on = [system._flexible[n] for n in order
          if n in system._flexible and state[flexibility_effect(n)]]
    if not on:
        return on
    names = {b.name for b in on}
    for el in system._forces.values():
        touched = names.intersection(el.frames)
        if touched and "joint" not in el.params and el.kind not in KINDS:
            raise ModelError(f"force {el.name!r}: a {el.kind} at the flexible body "
                             f"{sorted(touched)[0]!r} is not there yet; {', '.join(KINDS)}, "
                             "loads, joint forces and actuators are")
    for b in on:
        _check_held(system, b)
    return on


def _check_held(system, body):
    """A rotor's lateral modes carry its whole motion: its frame must be fixed to the
    ground (else the frame's motion repeats the rigid modes, and the spin's gyroscopic
    terms hold in a frame that does not turn only)."""
    if body.reduced.method != "lateral":
        return
    parent, _, joint = next(iter(system.graph.in_edges(body.name, data="joint")))
    if parent != "ground" or joint.kind != "fixed":
        raise ModelError(f"body {body.name!r}: with reduction = \"lateral\" its modes carry "
                         "its whole lateral motion in a frame that does not move; fix it to "
                         f"the ground (joint {joint.name!r} is a {joint.kind} joint to "
                         f"{parent!r}) and hold it with force elements (bearings) at its "
                         "nodes")


def split_elements(on, loads, forces):
    """``(tree loads, tree forces, flexible loads, flexible forces)``: the loads and force
    elements at points of the flexible bodies ``on`` go to ``algorithms.flexible_forces``
    (joint forces and actuators stay in the tree)."""
    names = {b.name for b in on}
    flex_loads = [ld for ld in loads if ld.body in names]
    flex_forces = [el for el in forces if "joint" not in el.params
                   and names.intersection(el.frames)]
    return ([ld for ld in loads if ld not in flex_loads],
            [el for el in forces if el not in flex_forces], flex_loads, flex_forces)


#: each force kind's (body key, point key) pairs, the body's default
POINT_KEYS = {"spring-damper": (("body_a", "point_a"), ("body_b", "point_b")),
              "bushing": (("body_a", "point_a"), ("body_b", "point_b")),
              "bearing": (("body", "point"),)}


def named_points(system, element, pairs, values):
    """``values`` with each point given as a node's name (a string) replaced by that
    node's position on the flexible body (body axes); ``pairs``: (body key, point key)."""
    out = dict(values)
    for body_key, point_key in pairs:
        point = out.get(point_key)
        if not isinstance(point, str):
            continue
        body = out.get(body_key, "ground")
        record = system._flexible.get(body)
        if record is None:
            raise ModelError(f"{element}: {point_key} = {point!r} names a node, but "
                             f"{body!r} is not a flexible body; give three numbers (its "
                             "components)")
        out[point_key] = node_position(record.reduced, point,
                                       f"{element}: {point_key}").tolist()
    return out


def joint_point(system, element, frame, key, value):
    """A joint's ``position`` (or ``child_position``) on ``frame``: as given, or, given
    as a node's name (``"tip"``) on a flexible body, that node's position (body axes)."""
    if not isinstance(value, str):
        return value
    record = system._flexible.get(frame)
    if record is None:
        raise ModelError(f"{element}: {key} = {value!r} names a node, but {frame!r} is not "
                         "a flexible body; give three numbers (the point in its frame)")
    return node_position(record.reduced, value, f"{element}: {key}").tolist()


def flexible_model(model, on, state, loads=(), forces=(), nodes=()):
    """The compiled model: ``model`` itself without flexible bodies on; else the
    ``FlexibleModel`` over it (its tree compiled with those bodies massless and the
    ``nodes``' frames), with the ``loads`` and ``forces`` at their points."""
    if not on:
        return model
    return FlexibleModel(model, on, stiffening=state[STIFFENING], loads=loads,
                         forces=forces, nodes=nodes)


def massless(bodies, on):
    """The tree's body records with the flexible ones in ``on`` massless (their inertia is
    the flexible model's), drawn as before."""
    names = {b.name for b in on}
    return [dataclasses.replace(make_body(b.name), shape=b.shape) if b.name in names else b
            for b in bodies]
