"""The state of a model with flexible bodies, and the tree's: the map between them.

The tree (``FlexibleModel.tree``) is compiled with every node frame's chain of 1-DoF
joints (``elements.flexible_nodes``), whose coordinates follow from the modal ones:
``q_chain = D eta``, ``u_chain = D eta'`` (``D``: each chain coordinate's row of
``[Phi_p; Psi_p]``, constant).  The model's coordinates are the tree's without the
chains', then the modal ones; its *extended* state is the tree's whole state, then the
modal one.  ``P`` maps the model's speeds to the extended ones (``u_x = P u``); it is
constant, so the accelerations map the same way (``u_x' = P u'``), and

    M = P^T M_x P,    f = P^T f_x,    G = G_x P,    gamma = gamma_x

for the extended ``M_x``, ``f_x`` (the tree's Jourdain terms plus the flexible bodies'),
``G_x`` and ``gamma_x`` (the tree's constraint rows): no velocity-product term arises.
Without node frames the model's state is the extended one and no map is made.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True, eq=False)
class StateMap:
    """``keep_q``, ``keep_u``: the tree's free coordinates and speeds that are the
    model's (tree indices, in order); ``chain_q``, ``chain_u``: the node frames' chain
    coordinates and speeds (tree indices), ``D`` (chain x modal) their rows; ``P`` the
    extended speeds per model speed; the tree's ``nq``, ``nu`` and the ``modal`` count."""
    keep_q: np.ndarray
    keep_u: np.ndarray
    chain_q: np.ndarray
    chain_u: np.ndarray
    D: np.ndarray
    P: np.ndarray
    nq: int
    nu: int
    modal: int

    def extended(self, q, u):
        """``(q_x, u_x)``: the tree's state (chain coordinates from ``eta``) and the modal
        one, from the model's ``(q, u)`` (``u`` may be ``None``)."""
        k, nq, nm = self.keep_q.size, self.nq, self.modal
        qx = np.empty(nq + nm)
        qx[self.keep_q] = q[:k]
        qx[nq:] = q[k:]
        qx[self.chain_q] = self.D @ qx[nq:]
        return qx, (None if u is None else self.P @ u)

    def model_state(self, qx, ux):
        """The model's ``(q, u)`` from extended ones."""
        return (np.concatenate([qx[self.keep_q], qx[self.nq:]]),
                np.concatenate([ux[self.keep_u], ux[self.nu:]]))

    def tree_index(self, k):
        """The extended speed index of the model's speed ``k``."""
        kept = self.keep_u.size
        return int(self.keep_u[k]) if k < kept else self.nu + k - kept


def state_map(tree, packs, node_frames):
    """The ``StateMap`` of the tree with the node frames ``node_frames`` (their
    flexible bodies' ``FlexPack`` in ``packs``), or ``None`` without node frames."""
    if not node_frames:
        return None
    modal = sum(fb.n for fb in packs)
    start = {fb.name: fb.u.start - tree.nu for fb in packs}
    chain_q, chain_u, rows = [], [], []
    for nf in node_frames:
        for name, row in zip(nf.joints, nf.rows):
            joint = tree.joint(name)
            chain_q.append(tree.coordinate_index(joint.coordinates[0]))
            chain_u.append(tree.speed_index(joint.speeds[0]))
            full = np.zeros(modal)
            full[start[nf.body]:start[nf.body] + row.size] = row
            rows.append(full)
    chain_q, chain_u = np.array(chain_q, np.int64), np.array(chain_u, np.int64)
    keep_q = np.setdiff1d(np.arange(tree.nq), chain_q)
    keep_u = np.setdiff1d(np.arange(tree.nu), chain_u)
    D = np.array(rows, float).reshape(len(rows), modal)
    nu = keep_u.size + modal
    P = np.zeros((tree.nu + modal, nu))
    P[keep_u, np.arange(keep_u.size)] = 1.0
    P[tree.nu + np.arange(modal), keep_u.size + np.arange(modal)] = 1.0
    P[chain_u, keep_u.size:] = D
    return StateMap(keep_q, keep_u, chain_q, chain_u, D, P, tree.nq, tree.nu, modal)


def remapped_layout(tree, smap, packs):
    """The tree's per-coordinate records in the model's indices, the chains' left out:
    ``(quaternions, euler_middle, free_joint_slots, speed_joint)``.  Without a map the
    tree's own (the model's indices start with the tree's)."""
    modal_joint = [fb.name for fb in packs for _ in range(fb.n)]
    if smap is None:
        return (list(tree._quaternions), list(tree._euler_middle),
                list(tree._free_joint_slots), list(tree._speed_joint) + modal_joint)
    q_at = -np.ones(tree.nq, np.int64)
    q_at[smap.keep_q] = np.arange(smap.keep_q.size)
    u_at = -np.ones(tree.nu, np.int64)
    u_at[smap.keep_u] = np.arange(smap.keep_u.size)
    quaternions = [slice(int(q_at[s.start]), int(q_at[s.start]) + 4)
                   for s in tree._quaternions]
    euler = [(j, int(q_at[k]), proper) for j, k, proper in tree._euler_middle]
    slots = [(code, int(q_at[q0]), nq, int(u_at[u0]), nu)
             for code, q0, nq, u0, nu in tree._free_joint_slots if q_at[q0] >= 0]
    speed_joint = [tree._speed_joint[k] for k in smap.keep_u] + modal_joint
    return quaternions, euler, slots, speed_joint
