"""A rotor's reduction: the lateral (bending) modes of a free-free beam, rigid ones
included, for a body whose frame does not spin (rotordynamics' non-rotating frame).

An axisymmetric rotor spinning at ``Omega`` about its axis x is written in a frame that
does not turn with it: ``M q'' + (C + Omega G) q' + K q = f`` with ``G`` the beam's
gyroscopic matrix (``Beam.gyroscopic_matrix``).  Its bearings, fixed in the world, are
then constant (anisotropic ones too), which a frame spinning with the shaft would make
periodic in time.  Valid for a rotor whose section and disks are axisymmetric (the mass
and stiffness do not change as it turns), at a constant spin.

``lateral_modes`` keeps the DoFs ``v, w, ry, rz`` of every node (axial motion and
torsion held, as in the 4-DoF rotordynamics element) and reduces on the free-free modes
of ``(K, M)``: the four rigid lateral motions (two translations, two tilts; 0 Hz) and the
bending modes.  The frame must be held (fixed to the ground): the modes carry the
rotor's whole lateral motion, on whatever holds it (bearings: force elements at nodes).
"""
from __future__ import annotations

import numpy as np
import scipy.linalg

from ..errors import ModelError
from .invariants import inertia_invariants
from .reduced import ReducedBody, frame_held_modes, modal_damping
from .reduction import _count, _damping_ratios

#: the lateral components of a node's six DoFs
LATERAL = ("v", "w", "ry", "rz")


def _amplitudes(beam, basis):
    """Each mode's size: its largest lateral displacement, or tilt times the mean
    element's length if larger.  Dividing by it makes ``eta`` a length, of the order of
    the deflection: mass-normalised modes of a light shaft under heavy disks have
    displacements of hundreds per unit ``eta``, tilts of tens of thousands, which numeric
    differences and error tolerances on ``eta`` cannot meet."""
    h = beam.length / beam.n_elements
    shapes = basis.reshape(beam.n_nodes, 6, -1)
    return np.maximum(np.abs(shapes[:, 1:3]).max(axis=(0, 1)),
                      h * np.abs(shapes[:, 4:6]).max(axis=(0, 1)))


def lateral_modes(beam, n_modes=None, f_max=None, damping=0.0):
    """The :class:`ReducedBody` of ``beam``'s free-free lateral modes (rigid ones first,
    0 Hz), each scaled to a largest displacement of 1 (``_amplitudes``), with the
    gyroscopic matrix ``G_ee`` per unit spin; ``modes``
    counts the rigid ones (a beam has four), so ``4 * n_nodes`` keeps every lateral DoF
    (no truncation)."""
    K, M = beam.stiffness_matrix(), beam.mass_matrix()
    lat = beam.dofs(components=LATERAL)
    try:
        lam, X = scipy.linalg.eigh(K[np.ix_(lat, lat)], M[np.ix_(lat, lat)])
    except np.linalg.LinAlgError:
        raise ModelError("the lateral mass matrix is not positive definite: give the beam "
                         "rotary inertia (rotary_inertia = true) or a disk on every "
                         "massless rotation") from None
    count = _count(np.sqrt(np.clip(lam, 0.0, None)) / (2 * np.pi), n_modes, f_max)
    if count == 0:
        raise ModelError("no modes kept: raise modes or f_max")
    basis = np.zeros((beam.n_dofs, count))
    basis[lat] = X[:, :count]
    basis /= _amplitudes(beam, basis)
    Kee, Mee = basis.T @ K @ basis, basis.T @ M @ basis
    Kee, Mee = 0.5 * (Kee + Kee.T), 0.5 * (Mee + Mee.T)
    G = basis.T @ beam.gyroscopic_matrix() @ basis
    frequencies, _ = frame_held_modes(Kee, Mee)
    Cee = modal_damping(Kee, Mee, _damping_ratios(damping, count))
    zero = np.zeros((count, count))
    return ReducedBody(method="lateral", mass_matrix=Mee, stiffness_matrix=Kee,
                       damping_matrix=Cee, modes=basis.reshape(beam.n_nodes, 6, -1),
                       nodes=beam.nodes, invariants=inertia_invariants(beam.mass_points(basis)),
                       frequencies=frequencies, interface=(), reference=None,
                       node_names=dict(beam.node_names),
                       geometric_stiffness={"centrifugal": zero, "axial_acceleration": zero},
                       gyroscopic=0.5 * (G - G.T))
