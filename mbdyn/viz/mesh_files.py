"""Triangle-mesh files (STL, OBJ, DAE, ...) read for the pictures, through ``trimesh``
(the optional extra ``pip install "mbdyn[meshes]"``).

A body's drawing shape ``{"type": "mesh", "file": ...}`` (a URDF ``<visual>`` mesh;
docs/urdf.md) is read here, once per file and process: a file larger than
``limits.MAX_MESH_FILE_BYTES`` is refused unread, the bytes are handed to ``trimesh`` (it
opens no other file: an OBJ's materials and a DAE's textures are not looked for) and a
mesh of more than ``limits.MAX_MESH_TRIANGLES`` triangles is decimated by vertex
clustering (``decimate``) so that the pictures, and the HTML page that carries every mesh
once, stay small.  A file that cannot be read -- trimesh absent, too large, not a mesh --
is left out of the pictures (the link is drawn as without it) with one warning per file
saying why and what to do.
"""
from __future__ import annotations

import io
import os
import warnings

import numpy as np

from .. import limits
from ..errors import ModelWarning

_CACHE = {}          # (path, size, mtime) -> (vertices, faces) or None (warned)


class Unreadable(Exception):
    """Why a mesh file is not drawn."""


def file_mesh(path):
    """``(vertices (n, 3), faces (m, 3))`` of the mesh file ``path`` in its own units and
    axes (decimated to at most ``limits.MAX_MESH_TRIANGLES``), or ``None`` after one
    warning if it cannot be read."""
    path = str(path)
    try:
        st = os.stat(path)
        key = (path, st.st_size, st.st_mtime_ns)
    except OSError:
        key = (path, None, None)
    if key not in _CACHE:
        try:
            _CACHE[key] = read_mesh(path)
        except Unreadable as exc:
            _CACHE[key] = None
            warnings.warn(f"mesh {path}: not drawn ({exc}); the link is drawn without it",
                          ModelWarning, stacklevel=2)
    return _CACHE[key]


def read_mesh(path, max_bytes=None, max_triangles=None):
    """The mesh of ``path`` (decimated); raises ``Unreadable`` saying why not."""
    max_bytes = limits.MAX_MESH_FILE_BYTES if max_bytes is None else max_bytes
    try:
        import trimesh
    except ImportError:
        raise Unreadable("reading mesh files needs trimesh: pip install "
                         "\"mbdyn[meshes]\"") from None
    try:
        with open(path, "rb") as fh:
            data = fh.read(max_bytes + 1)
    except OSError as exc:
        raise Unreadable(f"cannot open it: {exc.strerror or exc}") from None
    if len(data) > max_bytes:
        raise Unreadable(f"the file is larger than {max_bytes} bytes "
                         "(limits.MAX_MESH_FILE_BYTES); give a smaller mesh")
    kind = os.path.splitext(path)[1].lstrip(".").lower()
    try:
        loaded = trimesh.load(io.BytesIO(data), file_type=kind, force="mesh")
        vertices = np.asarray(loaded.vertices, dtype=float).reshape(-1, 3)
        faces = np.asarray(loaded.faces, dtype=np.int64).reshape(-1, 3)
    except Exception as exc:  # noqa: BLE001 -- a hostile or broken file: any reader error
        raise Unreadable(f"trimesh could not read it as {kind or 'a mesh'}: "
                         f"{type(exc).__name__}: {str(exc)[:120]}") from None
    if not len(faces) or not np.all(np.isfinite(vertices)) or \
            faces.min() < 0 or faces.max() >= len(vertices):
        raise Unreadable("it holds no triangles, or broken ones")
    return decimate(vertices, faces, max_triangles)


def decimate(vertices, faces, max_triangles=None):
    """At most ``max_triangles`` (default ``limits.MAX_MESH_TRIANGLES``) triangles by vertex
    clustering: the vertices in one cell of a grid over the bounding box merge into their
    mean, triangles that lose a corner (and repeats) go; the grid coarsens by a quarter a
    pass until the mesh fits.  Unused vertices are dropped."""
    limit = limits.MAX_MESH_TRIANGLES if max_triangles is None else max_triangles
    lo = vertices.min(axis=0)
    extent = max(float((vertices.max(axis=0) - lo).max()), 1e-300)
    cells = 256.0
    while len(faces) > limit:
        h = extent / cells
        keys = np.floor((vertices - lo) / h).astype(np.int64)
        _, cluster, counts = np.unique(keys, axis=0, return_inverse=True,
                                       return_counts=True)
        cluster = cluster.ravel()
        merged = np.zeros((len(counts), 3))
        np.add.at(merged, cluster, vertices)
        merged /= counts[:, None]
        f = cluster[faces]
        f = f[(f[:, 0] != f[:, 1]) & (f[:, 1] != f[:, 2]) & (f[:, 0] != f[:, 2])]
        _, first = np.unique(np.sort(f, axis=1), axis=0, return_index=True)
        vertices, faces = merged, f[np.sort(first)]
        lo = vertices.min(axis=0) if len(vertices) else lo
        cells *= 0.75
    used, faces = np.unique(faces, return_inverse=True)
    return vertices[used], faces.reshape(-1, 3)
