"""Flexible bodies added to a ``System`` and checked across the tree at compile: their
modal coordinates' names, their effects (``flexibility_BODY``, ``geometric_stiffening``),
and what may attach to them in this step (joints at the frame origin; no loads, no force
elements at points on them, no closed loops).
"""
from __future__ import annotations

import dataclasses

import numpy as np

from ..compiled.flexible_model import FlexibleModel
from ..elements.bodies import make_body
from ..elements.flexible_bodies import make_flexible_body
from ..errors import ModelError

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
    record = make_flexible_body(name, flexible, lumped, base)
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
    if on and system._loop_joints:
        raise ModelError(f"system {system.name!r}: closed loops with flexible bodies "
                         f"({', '.join(b.name for b in on)}) are not there yet (the next "
                         "step); switch their flexibility off or open the loops")
    names = {b.name for b in on}
    for parent, child, joint in system.graph.edges(data="joint"):
        if parent in names and np.any(np.asarray(joint.position, float) != 0.0):
            raise ModelError(f"joint {joint.name!r}: it attaches {child!r} to the flexible "
                             f"body {parent!r} at {joint.position.tolist()}; in this step "
                             "joints attach to a flexible body at its frame origin only "
                             "(position = [0, 0, 0], the beam's root); joints at its other "
                             "nodes are the next step")
    for load in system._loads.values():
        if load.body in names:
            raise ModelError(f"load {load.name!r}: loads on the flexible body {load.body!r} "
                             "are not there yet (the next step: their modal forces); put it "
                             "on another body or switch the flexibility off")
    for el in system._forces.values():
        touched = names.intersection(el.frames)
        if touched and "joint" not in el.params:
            raise ModelError(f"force {el.name!r}: force elements at points of the flexible "
                             f"body {sorted(touched)[0]!r} are not there yet (the next step); "
                             "joint forces and actuators are")
    return on


def flexible_model(model, on, state):
    """The compiled model: ``model`` itself without flexible bodies on; else the
    ``FlexibleModel`` over it (its tree compiled with those bodies massless)."""
    if not on:
        return model
    return FlexibleModel(model, on, stiffening=state[STIFFENING])


def massless(bodies, on):
    """The tree's body records with the flexible ones in ``on`` massless (their inertia is
    the flexible model's), drawn as before."""
    names = {b.name for b in on}
    return [dataclasses.replace(make_body(b.name), shape=b.shape) if b.name in names else b
            for b in bodies]
