"""A link's ``<visual>`` elements as its body's drawing shapes (docs/urdf.md, "Meshes").

Boxes, spheres and cylinders (along their z, centred) become the shapes of
``mbdyn.elements.bodies.make_shape``; a mesh a ``{"type": "mesh", "file": ...}`` shape
holding the file's resolved path and the ``<mesh scale>``; each placed by the visual's
``<origin>`` (``center`` and ``rotation``) and coloured by its material.  The file is
*found* here but *read* by the pictures (``mbdyn.viz.mesh_files``): loading a model never
reads a mesh.  A mesh's ``filename``:

* ``package://NAME/REST``: ``REST`` under a folder ``NAME`` found in each folder of the
  search path (``mesh_path``, in order), or -- a package's own folder -- a folder named
  ``NAME`` among the URDF's folder and its parents, or one of their children;
* ``file://PATH`` or a plain path: relative to the URDF's folder unless absolute.

A mesh not found is left out (the link is drawn as without it), with one warning per file
naming it and how to give the search path.
"""
from __future__ import annotations

import os
from urllib.parse import unquote

from .tree import rpy_matrix

#: how a user gives the search path, for the warnings
HOW = ("give the folder that holds the package with mesh_path=[...] (load_model), "
       "--mesh-path DIR or [model] mesh_path = [\"DIR\"]")


def search_folders(urdf_file, mesh_path=()):
    """The folders a ``package://`` name is looked for in: ``mesh_path``, then the URDF's
    folder and its parents."""
    here = os.path.dirname(os.path.abspath(str(urdf_file)))
    parents = [here]
    while os.path.dirname(parents[-1]) != parents[-1]:
        parents.append(os.path.dirname(parents[-1]))
    return [os.path.abspath(os.path.expanduser(str(p))) for p in mesh_path] + parents


def resolve(filename, urdf_file, mesh_path=()):
    """The path of the mesh ``filename`` names (``None`` if no file is found)."""
    base = os.path.dirname(os.path.abspath(str(urdf_file)))
    if filename.startswith("package://"):
        name, _, rest = filename[len("package://"):].partition("/")
        rest = unquote(rest)
        for folder in search_folders(urdf_file, mesh_path):
            for candidate in (os.path.join(folder, name, rest),
                              os.path.join(folder, rest) if os.path.basename(folder) == name
                              else None):
                if candidate and os.path.isfile(candidate):
                    return candidate
        return None
    if filename.startswith("file://"):
        filename = unquote(filename[len("file://"):])
    path = os.path.join(base, os.path.expanduser(filename))
    return path if os.path.isfile(path) else None


def link_shapes(link, urdf_file, mesh_path, warnings_out, missing):
    """The drawing shapes (a list; empty for none) of a ``parse.Link``'s visuals; a mesh
    not found adds one warning to ``warnings_out`` (``missing``: the names warned of)."""
    shapes = []
    for v in link.visuals:
        shape = {"center": list(v.xyz), "color": v.color or ""}
        if any(v.rpy):
            shape["rotation"] = rpy_matrix(v.rpy).tolist()
        values = v.values
        if v.kind == "box":
            shape.update(type="box", size=list(values["size"]))
        elif v.kind == "sphere":
            shape.update(type="sphere", radius=values["radius"])
        elif v.kind == "cylinder":
            shape.update(type="cylinder", radius=values["radius"], length=values["length"],
                         axis="z")
        elif v.kind == "mesh":
            path = resolve(values["filename"], urdf_file, mesh_path)
            if path is None:
                if values["filename"] not in missing:
                    missing.add(values["filename"])
                    warnings_out.append(
                        f"{urdf_file}: link {link.name!r}: mesh {values['filename']!r} not "
                        f"found, so not drawn; {HOW}")
                continue
            shape.update(type="mesh", file=path, scale=list(values["scale"]))
        else:
            continue
        if shape.get("radius", 1.0) <= 0 or shape.get("length", 1.0) <= 0 or \
                any(x <= 0 for x in shape.get("size", ())):
            continue                      # a zero-sized primitive draws nothing
        shapes.append(shape)
    return shapes
