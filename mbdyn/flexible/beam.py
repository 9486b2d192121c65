"""A straight beam along the body's x axis from its frame origin, by finite elements.

Nodes at ``x_0 = 0 < x_1 < ... < x_N`` carry six DoFs each, ``(u, v, w, rx, ry, rz)`` in
body axes (the DoF of node ``i``, component ``c`` is ``6 i + c``).  Every matrix below is
assembled from the element interpolation of ``shapes.py`` by 4-point Gauss quadrature,
exact for these polynomials (the tests compare each element matrix with its closed form):

* stiffness  ``K = int EA u'^2 + GJ rx'^2 + EIy ry'^2 + EIz rz'^2
  + ky G A (v' - rz)^2 + kz G A (w' + ry)^2 dx`` (no shear terms for Euler-Bernoulli);
* mass       ``M = int rhoA (u^2 + v^2 + w^2) + rho Ip rx^2 + r rho (Iy ry^2 + Iz rz^2) dx``
  (consistent; ``r = 1`` with rotary inertia), plus point masses and rigid disks on nodes;
* gyroscopic ``G = int r rho Ip (ry rz - rz ry) dx`` (skew) plus the disks' polar
  inertia: a spin ``Omega`` about x gives ``M q'' + Omega G q' + K q = f``;
* geometric stiffness for an axial force ``N(x)`` (tension positive):
  ``K_G = int N (v'^2 + w'^2) dx``.

Beams are made by ``beam_from_spec`` (mbdyn/flexible/spec.py), which validates the input.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..errors import ModelError
from .invariants import MassPoints
from .shapes import GAUSS_POINTS, GAUSS_WEIGHTS, element_rows

COMPONENTS = ("u", "v", "w", "rx", "ry", "rz")


def nearest_node(x, where):
    """The index of the node of ``x`` nearest to ``where``; of two as near (to 1e-9 of
    the beam's length), the one nearer the root."""
    gap = np.abs(np.asarray(x) - where)
    return int(np.flatnonzero(gap <= gap.min() + 1e-9 * max(abs(x[-1]), 1e-300))[0])


@dataclass(frozen=True)
class Attachment:
    """A rigid body on a node: ``mass`` (kg), ``polar`` inertia about x and ``diametral``
    inertia about y and z (kg m^2), about the node."""
    node: int
    mass: float = 0.0
    polar: float = 0.0
    diametral: float = 0.0


@dataclass(frozen=True, eq=False)
class Beam:
    """A beam model: node positions ``x`` along the body's x axis, per element its
    material (``E``, ``G``, ``rho``) and :class:`Section`, the rigid ``attachments`` and
    the ``node_names``.  ``theory`` is "timoshenko" or "euler-bernoulli"."""
    x: np.ndarray
    E: np.ndarray
    G: np.ndarray
    rho: np.ndarray
    sections: tuple
    theory: str = "timoshenko"
    rotary_inertia: bool = True
    attachments: tuple = ()
    node_names: dict = field(default_factory=dict)

    # -- layout
    @property
    def n_nodes(self):
        return len(self.x)

    @property
    def n_elements(self):
        return len(self.x) - 1

    @property
    def n_dofs(self):
        return 6 * len(self.x)

    @property
    def length(self):
        return float(self.x[-1])

    @property
    def nodes(self):
        """Node positions in body axes, (n_nodes, 3)."""
        out = np.zeros((self.n_nodes, 3))
        out[:, 0] = self.x
        return out

    def node(self, which):
        """A node's index from its index, its name, or a position along x (the nearest
        node; halfway between two, the one nearer the root)."""
        if isinstance(which, str):
            if which not in self.node_names:
                raise ModelError(f"no node named {which!r}; named nodes: "
                                 f"{', '.join(self.node_names) or 'none'}")
            return self.node_names[which]
        if isinstance(which, (int, np.integer)) and not isinstance(which, bool):
            if not 0 <= which < self.n_nodes:
                raise ModelError(f"node {which} is not one of 0 .. {self.n_nodes - 1}")
            return int(which)
        where = float(which)
        if not -1e-9 * self.length <= where <= self.length * (1 + 1e-9):
            raise ModelError(f"position {where:g} is off the beam (0 .. {self.length:g})")
        return nearest_node(self.x, where)

    def dofs(self, nodes=None, components=COMPONENTS):
        """Indices of the DoFs ``components`` (names from u, v, w, rx, ry, rz) of
        ``nodes`` (default all), node by node."""
        nodes = range(self.n_nodes) if nodes is None else [self.node(n) for n in nodes]
        comps = [COMPONENTS.index(c) for c in components]
        return np.array([6 * n + c for n in nodes for c in comps], dtype=int)

    # -- element properties
    def _lengths(self):
        return np.diff(self.x)

    def _shear_parameters(self):
        """``phi`` of the x-y and x-z planes per element (zero for Euler-Bernoulli)."""
        if self.theory != "timoshenko":
            zero = np.zeros(self.n_elements)
            return zero, zero
        L = self._lengths()
        s = self.sections
        EIz = self.E * np.array([c.Iz for c in s])
        EIy = self.E * np.array([c.Iy for c in s])
        GA = self.G * np.array([c.area for c in s])
        return (12 * EIz / (np.array([c.ky for c in s]) * GA * L * L),
                12 * EIy / (np.array([c.kz for c in s]) * GA * L * L))

    def element_points(self):
        """Per element the Gauss points' positions ``x`` (n_el, 4), quadrature weights
        times length (n_el, 4) and the rows ``T, R, dT, dR`` (n_el, 4, 3, 12) of
        ``shapes.element_rows``."""
        L = self._lengths()
        phi_xy, phi_xz = self._shear_parameters()
        rows = [element_rows(GAUSS_POINTS, L[e], phi_xy[e], phi_xz[e])
                for e in range(self.n_elements)]
        T, R, dT, dR = (np.array([r[k] for r in rows]) for k in range(4))
        xg = self.x[:-1, None] + L[:, None] * GAUSS_POINTS[None, :]
        return xg, L[:, None] * GAUSS_WEIGHTS[None, :], T, R, dT, dR

    def _assemble(self, element_matrices):
        out = np.zeros((self.n_dofs, self.n_dofs))
        for e, Ke in enumerate(element_matrices):
            out[6 * e:6 * e + 12, 6 * e:6 * e + 12] += Ke
        return out

    # -- matrices in body axes, over all n_dofs DoFs
    def stiffness_matrix(self):
        """The elastic stiffness matrix ``K`` (n_dofs, n_dofs), body axes."""
        _, wl, T, R, dT, dR = self.element_points()
        s = self.sections
        area = np.array([c.area for c in s])
        EA, GJ = self.E * area, self.G * np.array([c.J for c in s])
        EIy, EIz = self.E * np.array([c.Iy for c in s]), self.E * np.array([c.Iz for c in s])
        K = (np.einsum("eg,e,egi,egj->eij", wl, EA, dT[:, :, 0], dT[:, :, 0])
             + np.einsum("eg,e,egi,egj->eij", wl, GJ, dR[:, :, 0], dR[:, :, 0])
             + np.einsum("eg,e,egi,egj->eij", wl, EIy, dR[:, :, 1], dR[:, :, 1])
             + np.einsum("eg,e,egi,egj->eij", wl, EIz, dR[:, :, 2], dR[:, :, 2]))
        if self.theory == "timoshenko":
            gy = dT[:, :, 1] - R[:, :, 2]          # shear strain in the x-y plane
            gz = dT[:, :, 2] + R[:, :, 1]          # shear strain in the x-z plane
            kGy = np.array([c.ky for c in s]) * self.G * area
            kGz = np.array([c.kz for c in s]) * self.G * area
            K += (np.einsum("eg,e,egi,egj->eij", wl, kGy, gy, gy)
                  + np.einsum("eg,e,egi,egj->eij", wl, kGz, gz, gz))
        return self._assemble(K)

    def _section_inertia(self):
        """Per element ``rho A`` and the rotary inertia per length ``rho (Ip, r Iy, r Iz)``."""
        s, r = self.sections, 1.0 if self.rotary_inertia else 0.0
        rhoA = self.rho * np.array([c.area for c in s])
        rot = self.rho[:, None] * np.array([[c.Ip, r * c.Iy, r * c.Iz] for c in s])
        return rhoA, rot

    def mass_matrix(self):
        """The consistent mass matrix ``M`` (n_dofs, n_dofs), body axes, with the
        attachments' masses and inertias on their nodes."""
        _, wl, T, R, _, _ = self.element_points()
        rhoA, rot = self._section_inertia()
        M = (np.einsum("eg,e,egki,egkj->eij", wl, rhoA, T, T)
             + np.einsum("eg,ek,egki,egkj->eij", wl, rot, R, R))
        M = self._assemble(M)
        for a in self.attachments:
            i = 6 * a.node
            M[i:i + 6, i:i + 6] += np.diag([a.mass] * 3 + [a.polar, a.diametral, a.diametral])
        return M

    def gyroscopic_matrix(self):
        """The skew gyroscopic matrix ``G`` of a spin about x (per unit spin speed):
        ``M q'' + Omega G q' + K q = f``; the shaft's part only with rotary inertia."""
        _, wl, _, R, _, _ = self.element_points()
        _, rot = self._section_inertia()
        polar = rot[:, 0] if self.rotary_inertia else np.zeros(self.n_elements)
        Ge = np.einsum("eg,e,egi,egj->eij", wl, polar, R[:, :, 1], R[:, :, 2])
        G = self._assemble(Ge - np.transpose(Ge, (0, 2, 1)))
        for a in self.attachments:
            G[6 * a.node + 4, 6 * a.node + 5] += a.polar
            G[6 * a.node + 5, 6 * a.node + 4] -= a.polar
        return G

    def geometric_stiffness(self, axial_force):
        """The geometric stiffness ``K_G`` of the bending DoFs under the axial force
        ``axial_force`` (N, tension positive): a number, or a function of x (arrays in,
        arrays out) that is smooth inside each element."""
        xg, wl, _, _, dT, _ = self.element_points()
        N = axial_force(xg) if callable(axial_force) else np.full(xg.shape, float(axial_force))
        N = np.broadcast_to(np.asarray(N, dtype=float), xg.shape)
        Kg = (np.einsum("eg,eg,egi,egj->eij", wl, N, dT[:, :, 1], dT[:, :, 1])
              + np.einsum("eg,eg,egi,egj->eij", wl, N, dT[:, :, 2], dT[:, :, 2]))
        return self._assemble(Kg)

    def mass_points(self, modes):
        """The beam as :class:`~mbdyn.flexible.invariants.MassPoints` for the mode shapes
        ``modes`` (n_dofs, n): each element's Gauss points (weights times ``rho A`` and
        the rotary inertia), so that the invariants are the consistent model's integrals,
        exact for its polynomials; then the attachments on their nodes."""
        modes = np.asarray(modes, dtype=float)
        xg, wl, T, R, _, _ = self.element_points()
        rhoA, rot = self._section_inertia()
        Phi_e = np.stack([modes[6 * e:6 * e + 12] for e in range(self.n_elements)])
        n_pts = xg.size
        position = np.zeros((n_pts, 3))
        position[:, 0] = xg.ravel()
        mass = (wl * rhoA[:, None]).ravel()
        inertia = np.zeros((n_pts, 3, 3))
        inertia[:, [0, 1, 2], [0, 1, 2]] = (wl[:, :, None] * rot[:, None, :]).reshape(-1, 3)
        trans = np.einsum("egij,ejn->egin", T, Phi_e).reshape(n_pts, 3, -1)
        rotat = np.einsum("egij,ejn->egin", R, Phi_e).reshape(n_pts, 3, -1)
        if self.attachments:
            a = self.attachments
            node_modes = modes.reshape(self.n_nodes, 6, -1)[[t.node for t in a]]
            position = np.vstack([position, self.nodes[[t.node for t in a]]])
            mass = np.concatenate([mass, [t.mass for t in a]])
            inertia = np.concatenate([inertia, [np.diag([t.polar, t.diametral, t.diametral])
                                                for t in a]])
            trans = np.concatenate([trans, node_modes[:, :3]])
            rotat = np.concatenate([rotat, node_modes[:, 3:]])
        return MassPoints(mass, position, inertia, trans, rotat)

    def outboard(self, x):
        """The mass beyond each position ``x`` and its first moment about the origin:
        ``(m_out(x), s_out(x))`` with ``m_out = int_x^L rhoA ds + sum m_j`` and
        ``s_out = int_x^L rhoA s ds + sum m_j x_j`` over attachments at ``x_j > x``."""
        x = np.asarray(x, dtype=float)
        rhoA, _ = self._section_inertia()
        a, b = self.x[:-1], self.x[1:]
        lo = np.maximum(x[..., None], a)                 # each element's part beyond x
        hi = np.maximum(x[..., None], b)
        m = np.sum(rhoA * (hi - lo), axis=-1)
        s = np.sum(rhoA * (hi * hi - lo * lo) / 2.0, axis=-1)
        for att in self.attachments:
            beyond = self.x[att.node] > x
            m = m + att.mass * beyond
            s = s + att.mass * self.x[att.node] * beyond
        return m, s

    def centrifugal_stiffness(self, hub_radius=0.0):
        """``K_G`` per unit ``Omega^2`` for a spin ``Omega`` about an axis perpendicular to x
        through ``(-hub_radius, 0, 0)``: the axial force is
        ``N(x) = Omega^2 (s_out(x) + hub_radius m_out(x))``, e.g.
        ``rhoA Omega^2 ((L^2 - x^2)/2 + R (L - x))`` for a uniform beam."""
        def force(x):
            m, s = self.outboard(x)
            return s + hub_radius * m
        return self.geometric_stiffness(force)

    def axial_acceleration_stiffness(self):
        """``K_G`` per unit acceleration ``a_x`` of the frame along x (gravity along x
        enters as ``a_x = -g_x``): the axial force is ``N(x) = -a_x m_out(x)``."""
        return self.geometric_stiffness(lambda x: -self.outboard(x)[0])
