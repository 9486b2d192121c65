"""Minimal coordinates about an operating point: the tangent space of the configuration.

Revolute, prismatic and Euler-angle coordinates are their own tangent coordinates.  A unit
quaternion (spherical joints, the rotation of free joints) is perturbed on the right,
``q = q0 (x) exp(theta / 2)``, with ``theta`` a rotation vector in the child's axes, so a
rotation has three tangent coordinates, not four redundant components.  The tangent
coordinates then number ``nu``, one per speed, and are named after the coordinates (a
quaternion's as ``JOINT_rx``, ``_ry``, ``_rz``).
"""
from __future__ import annotations

import numpy as np

from ..kernels.joints import KIND_CODES
from ..elements.rotations import product as quaternion_product

SPHERICAL, FREE = KIND_CODES["spherical"], KIND_CODES["free"]


def rotation_quaternion(theta):
    """``exp(theta / 2)``: the unit quaternion of the rotation vector ``theta``."""
    angle = float(np.linalg.norm(theta))
    if angle < 1e-12:
        return np.array([1.0, *(0.5 * np.asarray(theta))]) / np.sqrt(1 + 0.25 * angle ** 2)
    return np.array([np.cos(angle / 2), *(np.sin(angle / 2) * np.asarray(theta) / angle)])


class Tangent:
    """The tangent coordinates of ``model`` about the configuration ``q0``."""

    def __init__(self, model, q0):
        self.model = model
        self.q0 = np.array(q0, dtype=float)
        self.names = []
        self.quaternion_blocks = []      # (q start of the quaternion, x start of theta)
        x = 0
        slots = model._free_joint_slots
        for (code, qs, nq, us, nu), joint in zip(slots, _free_joints(model)):
            if code == SPHERICAL:
                self.quaternion_blocks.append((qs, x))
                self.names += [f"{joint.name}_r{c}" for c in "xyz"]
            elif code == FREE:
                self.names += list(joint.coordinates[:3])
                self.quaternion_blocks.append((qs + 3, x + 3))
                self.names += [f"{joint.name}_r{c}" for c in "xyz"]
            else:
                self.names += list(joint.coordinates)
            x += nu
        modal = tuple(getattr(model, "modal_coordinates", ()))   # flexible bodies' (scalar)
        self.names += list(modal)
        self.n = x + len(modal)
        scalar = np.ones(model.nq, bool)
        for qs, _ in self.quaternion_blocks:
            scalar[qs:qs + 4] = False
        self._scalar_q = np.flatnonzero(scalar)
        xs = np.ones(self.n, bool)
        for _, xs0 in self.quaternion_blocks:
            xs[xs0:xs0 + 3] = False
        self._scalar_x = np.flatnonzero(xs)

    def retract(self, x):
        """The configuration ``q`` at tangent coordinates ``x``."""
        q = self.q0.copy()
        q[self._scalar_q] += np.asarray(x)[self._scalar_x]
        for qs, xs in self.quaternion_blocks:
            q[qs:qs + 4] = quaternion_product(self.q0[qs:qs + 4],
                                              rotation_quaternion(x[xs:xs + 3]))
        return q

    def basis(self):
        """``dq/dx`` at ``x = 0`` (nq x n): how each tangent coordinate moves ``q``."""
        B = np.zeros((self.model.nq, self.n))
        B[self._scalar_q, self._scalar_x] = 1.0
        for qs, xs in self.quaternion_blocks:
            q0 = self.q0[qs:qs + 4]
            for k in range(3):
                e = np.zeros(4)
                e[k + 1] = 0.5
                B[qs:qs + 4, xs + k] = quaternion_product(q0, e)
        return B

    def rate_coupling(self, u0):
        """``B`` in ``x' = u + B x`` to first order: ``-[u0]x / 2`` on each rotation block
        (the right perturbation's kinematics), zero elsewhere."""
        B = np.zeros((self.n, self.n))
        for _, xs in self.quaternion_blocks:
            w = np.asarray(u0)[xs:xs + 3]
            B[xs:xs + 3, xs:xs + 3] = -0.5 * np.array([[0, -w[2], w[1]], [w[2], 0, -w[0]],
                                                       [-w[1], w[0], 0]])
        return B


def _free_joints(model):
    return [j for j in model.elements[1] if j.drive is None and j.nu]
