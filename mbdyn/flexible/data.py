"""Reduced flexible-body data from any finite-element program, as NPZ or TOML.

An ``.npz`` file (``numpy.savez``; read without pickling, so text arrays must be plain
unicode arrays) or a ``.toml`` file (or a Python dict) with these keys; N nodes, n modes:

==============  ===============  ==========================================================
key             shape            meaning
==============  ===============  ==========================================================
``mass``        (n, n)           modal mass matrix ``M_ee = Phi^T M Phi``: symmetric,
                                 positive definite
``stiffness``   (n, n)           modal stiffness ``K_ee = Phi^T K Phi``: symmetric, positive
                                 definite (semi-definite only with ``allow_rigid_modes``:
                                 a rigid-body mode among the modes repeats the frame's
                                 motion, so it is refused unless asked for)
``modes``       (N, 6, n)        per unit modal coordinate, each node's displacement
                                 (u, v, w) and small rotation (rx, ry, rz), body axes,
                                 relative to the floating frame
``nodes``       (N, 3)           node positions in body axes from the frame origin (m)
``node_mass``   (N,) or          lumped masses (kg), or each node's rigid-body mass matrix
                (N, 6, 6)        about the node, translation first: ``[[m I, -m s~],
                                 [m s~, J]]`` (s: its centre of mass from the node)
``damping``     (n,) or (n, n)   optional: modal damping ratios, or the damping matrix
``names``       (N,)             optional: node names (identifiers)
``interface``   list             optional: nodes (indices or names) where joints attach
``reference``   index or name    optional: the node the frame is attached to; the modes
                                 must vanish there
==============  ===============  ==========================================================

The invariants come from the lumped ``node_mass`` (mbdyn/flexible/invariants.py); the
modal mass is taken as given.  A modal mass far from the lumped masses' (``sum m_i
Phi_i^T Phi_i``, traces off by more than a factor 2) draws a warning: the modes or the
masses are then in other units or axes.
"""
from __future__ import annotations

import math
import tomllib
import warnings
from pathlib import Path

import numpy as np

from ..errors import ModelError, ModelWarning
from ..limits import MAX_FLEXIBLE_NODES, MAX_MODES, max_file_bytes
from ..names import identifier_problem
from .invariants import inertia_invariants, lumped_mass_points
from .reduced import ReducedBody, frame_held_modes, modal_damping

KEYS = ("mass", "stiffness", "modes", "nodes", "node_mass", "damping", "names",
        "interface", "reference")
REQUIRED = ("mass", "stiffness", "modes", "nodes", "node_mass")


def read_reduced_data(path):
    """The keys of an ``.npz`` or ``.toml`` file as a dict (no pickles, no evaluation)."""
    path = Path(path)
    size = path.stat().st_size
    limit = max_file_bytes() * (1000 if path.suffix == ".npz" else 1)
    if size > limit:
        raise ModelError(f"{path}: {size} bytes (at most {limit}; MBDYN_MAX_FILE_BYTES "
                         "raises it)")
    if path.suffix == ".npz":
        try:
            with np.load(path, allow_pickle=False) as archive:
                return {k: archive[k] for k in archive.files}
        except ValueError as exc:
            raise ModelError(f"{path}: {exc}; save text arrays (names) as plain unicode "
                             "arrays, e.g. np.array(['root', 'tip'])") from None
    if path.suffix == ".toml":
        try:
            return tomllib.loads(path.read_text(encoding="utf-8"))
        except (tomllib.TOMLDecodeError, UnicodeDecodeError) as exc:
            raise ModelError(f"{path}: not a TOML file ({exc})") from None
    raise ModelError(f"{path}: give a .npz or .toml file")


def load_reduced_body(path, **options):
    """The :class:`ReducedBody` of an ``.npz`` or ``.toml`` file (``options`` as for
    :func:`reduced_body_from_data`)."""
    return reduced_body_from_data(read_reduced_data(path), key=str(path), **options)


def _array(data, name, key, ndim):
    where = f"{key}.{name}"
    try:
        value = np.array(data[name], dtype=float)
    except (TypeError, ValueError):
        raise ModelError(f"{where}: must be an array of numbers") from None
    if value.ndim not in ndim:
        raise ModelError(f"{where}: must have {' or '.join(map(str, ndim))} dimensions, "
                         f"got shape {value.shape}")
    if not np.all(np.isfinite(value)):
        bad = tuple(int(i) for i in np.argwhere(~np.isfinite(value))[0])
        raise ModelError(f"{where}: holds a non-finite number at {list(bad)}")
    return value


def _symmetric(A, where):
    scale = max(np.abs(A).max(), 1e-300)
    gap = np.abs(A - A.swapaxes(-1, -2))
    if gap.max() > 1e-8 * scale:
        i = tuple(int(k) for k in np.unravel_index(gap.argmax(), gap.shape))
        raise ModelError(f"{where}: not symmetric (|A - A^T| = {gap.max():.3g} at {list(i)}, "
                         f"{gap.max() / scale:.2g} of its largest entry); give the symmetric "
                         "matrix")
    return 0.5 * (A + A.swapaxes(-1, -2))


def _definite(A, where, semi=False, remedy=""):
    lam = np.linalg.eigvalsh(A)
    top = max(np.abs(lam).max(), 1e-300)
    if lam.min() < (-1e-9 * top if semi else 1e-12 * top):
        what = "positive semi-definite" if semi else "positive definite"
        raise ModelError(f"{where}: not {what} (eigenvalue {lam.min():.3g} against "
                         f"{top:.3g}){remedy}")


def _node_mass(data, N, key):
    m = _array(data, "node_mass", key, (1, 3))
    where = f"{key}.node_mass"
    if m.shape not in ((N,), (N, 6, 6)):
        raise ModelError(f"{where}: shape {m.shape}; give ({N},) masses or ({N}, 6, 6) "
                         "matrices, one per node")
    if m.ndim == 1:
        if np.any(m < 0):
            raise ModelError(f"{where}: node {int(np.flatnonzero(m < 0)[0])} has a negative "
                             "mass")
        return m
    m = _symmetric(m, where)
    for i, block in enumerate(m):
        mass, scale = block[0, 0], max(np.abs(block).max(), 1e-300)
        if np.abs(block[:3, :3] - mass * np.eye(3)).max() > 1e-8 * scale:
            raise ModelError(f"{where}[{i}]: the translation block must be m I (a mass is "
                             "the same in every direction)")
        if np.abs(block[:3, 3:] + block[:3, 3:].T).max() > 1e-8 * scale or \
                (mass <= 0 and np.abs(block[:3, 3:]).max() > 0):
            raise ModelError(f"{where}[{i}]: the coupling block must be -m s~ (skew, zero "
                             "without mass)")
        _definite(block, f"{where}[{i}]", semi=True)
    return m


def _node_refs(data, name, names, N, key):
    value = data.get(name)
    if value is None:
        return None
    if isinstance(value, np.ndarray) and value.ndim == 0:
        value = value.item()
    single = not isinstance(value, (list, tuple, np.ndarray)) or np.ndim(value) == 0
    out = []
    for item in ([value] if single else list(value)):
        item = item.item() if isinstance(item, np.generic) else item
        if isinstance(item, str):
            if item not in names:
                raise ModelError(f"{key}.{name}: no node named {item!r}")
            out.append(names[item])
        elif isinstance(item, int) and not isinstance(item, bool) and 0 <= item < N:
            out.append(item)
        else:
            raise ModelError(f"{key}.{name}: {item!r} is neither a node name nor an index "
                             f"0 .. {N - 1}")
    return out[0] if single else tuple(out)


def _names(data, N, key):
    if "names" not in data:
        return {}
    names = [str(n) for n in np.asarray(data["names"]).ravel()]
    if len(names) != N:
        raise ModelError(f"{key}.names: {len(names)} names for {N} nodes")
    for name in names:
        problem = identifier_problem(name)
        if problem:
            raise ModelError(f"{key}.names: {name!r} {problem}")
    if len(set(names)) != N:
        raise ModelError(f"{key}.names: a name is given twice")
    return {n: i for i, n in enumerate(names)}


def _damping(data, K, M, n, key):
    if "damping" not in data:
        return np.zeros((n, n))
    C = _array(data, "damping", key, (0, 1, 2))
    if C.ndim < 2:
        if C.ndim == 1 and len(C) != n or np.any(C < 0):
            raise ModelError(f"{key}.damping: give {n} damping ratios >= 0 (or one, or an "
                             "n x n matrix)")
        return modal_damping(K, M, C)
    if C.shape != (n, n):
        raise ModelError(f"{key}.damping: shape {C.shape}, the modes need ({n}, {n})")
    C = _symmetric(C, f"{key}.damping")
    _definite(C, f"{key}.damping", semi=True)
    return C


def reduced_body_from_data(data, key="flexible.data", allow_rigid_modes=False):
    """The :class:`ReducedBody` of the reduced ``data`` (keys in this module's
    docstring), every key checked; ``key`` names the data in messages."""
    if not isinstance(data, dict):
        raise ModelError(f"{key}: must be a table of {', '.join(REQUIRED)}")
    for name in data:
        if name not in KEYS:
            raise ModelError(f"{key}.{name}: unknown key; known: {', '.join(KEYS)}")
    for name in REQUIRED:
        if name not in data:
            raise ModelError(f"{key}.{name}: missing (needed: {', '.join(REQUIRED)})")
    M = _array(data, "mass", key, (2,))
    n = M.shape[0]
    if M.shape != (n, n) or not 1 <= n <= MAX_MODES:
        raise ModelError(f"{key}.mass: must be square, n x n with 1 <= n <= {MAX_MODES}, "
                         f"got shape {M.shape}")
    K = _array(data, "stiffness", key, (2,))
    if K.shape != (n, n):
        raise ModelError(f"{key}.stiffness: shape {K.shape}, the mass matrix is ({n}, {n})")
    M, K = _symmetric(M, f"{key}.mass"), _symmetric(K, f"{key}.stiffness")
    _definite(M, f"{key}.mass")
    _definite(K, f"{key}.stiffness", semi=allow_rigid_modes,
              remedy="" if allow_rigid_modes else
              "; leave rigid-body modes out (the frame carries that motion) or pass "
              "allow_rigid_modes=True")
    modes = _array(data, "modes", key, (3,))
    N = modes.shape[0]
    if modes.shape[1:] != (6, n) or not 1 <= N <= MAX_FLEXIBLE_NODES:
        raise ModelError(f"{key}.modes: shape {modes.shape}; give (nodes, 6, {n}) with at most "
                         f"{MAX_FLEXIBLE_NODES} nodes: u, v, w, rx, ry, rz per mode")
    nodes = _array(data, "nodes", key, (2,))
    if nodes.shape != (N, 3):
        raise ModelError(f"{key}.nodes: shape {nodes.shape}, the modes need ({N}, 3)")
    node_mass = _node_mass(data, N, key)
    names = _names(data, N, key)
    interface = _node_refs(data, "interface", names, N, key) or ()
    reference = _node_refs(data, "reference", names, N, key)
    if isinstance(reference, tuple):
        raise ModelError(f"{key}.reference: give one node")
    if reference is not None and np.abs(modes[reference]).max() > 1e-8 * np.abs(modes).max():
        raise ModelError(f"{key}.reference: the modes do not vanish at node {reference}; give "
                         "the modes relative to a frame attached there, or leave reference out")
    invariants = inertia_invariants(lumped_mass_points(nodes, node_mass, modes))
    if invariants.mass <= 0:
        raise ModelError(f"{key}.node_mass: the body has no mass")
    _check_modal_mass(M, invariants.modal_mass, key)
    frequencies, _ = frame_held_modes(K, M)
    return ReducedBody(method="data", mass_matrix=M, stiffness_matrix=K,
                       damping_matrix=_damping(data, K, M, n, key), modes=modes,
                       nodes=nodes, invariants=invariants, frequencies=frequencies,
                       interface=tuple(interface), reference=reference, node_names=names)


def _check_modal_mass(M, lumped, key):
    """A warning when the lumped masses' modal mass is off the given one by more than a
    factor of two overall (traces): units or axes that differ, not a lumping error."""
    ratio = np.trace(lumped) / np.trace(M)
    if not 0.5 <= ratio <= 2.0:
        warnings.warn(f"{key}: the modal mass from node_mass and modes (trace {np.trace(lumped):.4g}) "
                      f"is {ratio:.3g} times the key mass's (trace {np.trace(M):.4g}); check "
                      "that they share units and axes", ModelWarning, stacklevel=3)
