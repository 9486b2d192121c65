"""Modal reduction of a beam to a floating-frame :class:`ReducedBody`.

The frame convention: the body frame is attached to the *reference node*, the first
interface node (by default the root, ``x = 0``, the frame origin).  The reference node's
six DoFs are held in every elastic shape, so the frame is the tangent frame of the beam
there (the "clamped" frame, common for beams attached at one end); the frame's own
motion carries the rigid-body motion.

* ``craig_bampton``: the fixed-interface modes (every interface node held) and one
  static *constraint mode* per DoF of each further interface node (that DoF 1, the
  other interface DoFs 0, the interior in static equilibrium): R. R. Craig and M. C. C.
  Bampton, "Coupling of substructures for dynamic analyses", AIAA J. 6, 1968.  Elastic
  coordinates: first the modal amplitudes, then the displacements and rotations of the
  further interface nodes relative to the frame.
* ``free_interface``: the free-free modes with the rigid-body motion of the reference
  node taken out (``Phi - R Phi_ref``: the same motions, seen from the tangent frame),
  plus the static response to unit forces and moments at the further interface nodes
  with the frame held (the static correction, or attachment modes: R. H. MacNeal, "A
  hybrid method of component mode synthesis", Computers & Structures 1, 1971).  The set
  is made mass-orthonormal by a Ritz step, so ``M_ee = I`` and ``K_ee`` is diagonal.

Modes are kept by number (``n_modes``), by a frequency cut-off (``f_max``, Hz) or both
(the first ``n_modes`` below ``f_max``).
"""
from __future__ import annotations

import math

import numpy as np
import scipy.linalg

from ..errors import ModelError
from ..limits import MAX_MODES
from .invariants import inertia_invariants, skew
from .modal import free_dofs
from .reduced import ReducedBody, frame_held_modes, modal_damping


def rigid_body_modes(nodes, point):
    """(6 N, 6) motions of the nodes (N, 3) as one rigid body: unit translations along
    x, y, z, then unit rotations about x, y, z through ``point``."""
    nodes = np.asarray(nodes, dtype=float)
    R = np.zeros((len(nodes), 6, 6))
    R[:, :3, :3] = R[:, 3:, 3:] = np.eye(3)
    R[:, :3, 3:] = -skew(nodes - np.asarray(point, dtype=float))    # theta x r = -r~ theta
    return R.reshape(-1, 6)


def _count(frequencies, n_modes, f_max):
    """How many of the ascending ``frequencies`` (Hz) to keep."""
    if n_modes is None and f_max is None:
        raise ModelError("give n_modes (how many modes), f_max (a cut-off in Hz) or both")
    count = len(frequencies)
    if f_max is not None:
        if isinstance(f_max, bool) or not isinstance(f_max, (int, float)) \
                or not math.isfinite(f_max) or f_max <= 0:
            raise ModelError(f"f_max: must be a positive frequency in Hz, got {f_max!r}")
        count = int(np.sum(frequencies <= f_max))
    if n_modes is not None:
        if isinstance(n_modes, bool) or not isinstance(n_modes, (int, np.integer)) \
                or n_modes < 0:
            raise ModelError(f"n_modes: must be a whole number >= 0, got {n_modes!r}")
        if n_modes > len(frequencies):
            raise ModelError(f"n_modes: {n_modes} asked, the model has {len(frequencies)}; "
                             "use more elements or fewer modes")
        count = min(count, int(n_modes))
    if count > MAX_MODES:
        raise ModelError(f"{count} modes (at most {MAX_MODES}); lower n_modes or f_max")
    return count


def _interface(beam, interface):
    if isinstance(interface, (str, int)):
        interface = [interface]
    nodes = [beam.node(n) for n in interface]
    if not nodes:
        raise ModelError("interface: give at least one node (the first is the reference "
                         "node the frame is attached to)")
    if len(set(nodes)) != len(nodes):
        raise ModelError(f"interface: a node is listed twice ({interface!r})")
    return nodes


def craig_bampton(beam, interface=("root",), n_modes=None, f_max=None, damping=0.0):
    """The Craig-Bampton :class:`ReducedBody` of ``beam``: fixed-interface modes and the
    constraint modes of the interface nodes after the first (the reference node)."""
    nodes = _interface(beam, interface)
    K, M = beam.stiffness_matrix(), beam.mass_matrix()
    held = beam.dofs(nodes[:1])
    boundary = beam.dofs(nodes[1:]) if len(nodes) > 1 else np.zeros(0, dtype=int)
    interior = free_dofs(beam.n_dofs, np.concatenate([held, boundary]))
    Kii, Mii = K[np.ix_(interior, interior)], M[np.ix_(interior, interior)]
    lam, Phi = scipy.linalg.eigh(Kii, Mii)
    count = _count(np.sqrt(np.clip(lam, 0, None)) / (2 * np.pi), n_modes, f_max)
    basis = np.zeros((beam.n_dofs, count + len(boundary)))
    basis[interior, :count] = Phi[:, :count]
    if len(boundary):
        basis[interior, count:] = -np.linalg.solve(Kii, K[np.ix_(interior, boundary)])
        basis[boundary, count:] = np.eye(len(boundary))
    return _reduced_body(beam, K, M, basis, "craig-bampton", nodes, damping)


def free_interface(beam, interface=("root",), n_modes=None, f_max=None, damping=0.0):
    """The free-interface :class:`ReducedBody` of ``beam``: free-free elastic modes seen
    from the frame attached at the reference node, with the static correction for unit
    loads at the further interface nodes."""
    nodes = _interface(beam, interface)
    K, M = beam.stiffness_matrix(), beam.mass_matrix()
    lam, X = scipy.linalg.eigh(K, M)
    if not np.all(np.abs(lam[:6]) <= 1e-8 * lam[6]):
        raise ModelError("the free beam does not have exactly six rigid-body modes")
    count = _count(np.sqrt(lam[6:]) / (2 * np.pi), n_modes, f_max)
    ref = beam.dofs(nodes[:1])
    Phi = X[:, 6:6 + count]
    Phi = Phi - rigid_body_modes(beam.nodes, beam.nodes[nodes[0]]) @ Phi[ref]
    free = free_dofs(beam.n_dofs, ref)
    static = np.zeros((beam.n_dofs, 6 * (len(nodes) - 1)))
    if len(nodes) > 1:
        loads = np.zeros((beam.n_dofs, static.shape[1]))
        loads[beam.dofs(nodes[1:]), np.arange(static.shape[1])] = 1.0
        static[free] = np.linalg.solve(K[np.ix_(free, free)], loads[free])
    basis = ritz_basis(np.hstack([Phi, static]), K, M)
    return _reduced_body(beam, K, M, basis, "free-interface", nodes, damping)


def ritz_basis(B, K, M, tol=1e-10):
    """The columns of ``B`` made mass-orthonormal and ordered by frequency (the Ritz
    vectors of ``(K, M)`` in the span of ``B``), dependent columns dropped."""
    B = B / np.sqrt(np.einsum("ik,ij,jk->k", B, M, B))      # unit modal mass each
    w, V = np.linalg.eigh(B.T @ M @ B)
    keep = w > tol * w.max()
    Q = B @ (V[:, keep] / np.sqrt(w[keep]))
    Kr = Q.T @ K @ Q
    _, U = np.linalg.eigh(0.5 * (Kr + Kr.T))
    return Q @ U


def _damping_ratios(damping, n):
    z = np.asarray(damping, dtype=float)
    if z.ndim > 1 or (z.ndim == 1 and len(z) != n):
        raise ModelError(f"damping: give one modal damping ratio or {n} (one per mode of the "
                         f"reduced body, by ascending frequency), got shape {z.shape}")
    if not np.all(np.isfinite(z)) or np.any(z < 0):
        raise ModelError(f"damping: ratios must be finite and >= 0, got {damping!r}")
    return z


def _reduced_body(beam, K, M, basis, method, nodes, damping):
    if basis.shape[1] == 0:
        raise ModelError("no elastic coordinates: keep at least one mode (n_modes, f_max) "
                         "or give a second interface node")
    Kee, Mee = basis.T @ K @ basis, basis.T @ M @ basis
    Kee, Mee = 0.5 * (Kee + Kee.T), 0.5 * (Mee + Mee.T)
    frequencies, _ = frame_held_modes(Kee, Mee)
    Cee = modal_damping(Kee, Mee, _damping_ratios(damping, basis.shape[1]))
    geometric = {"centrifugal": basis.T @ beam.centrifugal_stiffness() @ basis,
                 "axial_acceleration": basis.T @ beam.axial_acceleration_stiffness() @ basis}
    return ReducedBody(method=method, mass_matrix=Mee, stiffness_matrix=Kee,
                       damping_matrix=Cee, modes=basis.reshape(beam.n_nodes, 6, -1),
                       nodes=beam.nodes, invariants=inertia_invariants(beam.mass_points(basis)),
                       frequencies=frequencies, interface=tuple(nodes), reference=nodes[0],
                       node_names=dict(beam.node_names), geometric_stiffness=geometric)
