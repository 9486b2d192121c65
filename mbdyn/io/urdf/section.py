"""``[model] urdf = "robot.urdf"``: the URDF a model file includes (or the ``.urdf`` file
``load_model`` was given, whose document is only this key), read before the ``System`` is
made (it names the model) and added to it before the file's own bodies and joints, which
may then hang from its links.  ``floating``, ``accept_inertia`` and ``mesh_path`` (a
folder or a list of folders, relative to the model file, where ``package://`` meshes are
looked for) go with it.
"""
from __future__ import annotations

import os
import warnings

from ...errors import ModelWarning
from ..errors import ModelFileError
from . import add_robot, is_urdf
from .parse import Reader, parse_urdf

OPTIONS = ("floating", "accept_inertia", "mesh_path")


def read_section(b, model_table):
    """``(path, Robot)`` of the document's ``[model] urdf`` (``None`` without one), read
    through the ``SceneBuilder`` ``b`` (its file, its errors, ``b.urdf_text``)."""
    urdf = model_table.get("urdf")
    if urdf is None:
        for key in OPTIONS:
            if key in model_table:
                raise b.error(("model", key), "applies to a URDF robot only; add "
                              "urdf = \"robot.urdf\" to [model], or remove it")
        return None
    if not urdf.strip():
        raise b.error(("model", "urdf"), "is empty; give the URDF file's path")
    own = is_urdf(b.file) and urdf == os.path.basename(b.file)
    path = b.file if own else os.path.join(os.path.dirname(b.file), urdf)
    text = getattr(b, "urdf_text", None) if own else None
    if text is None:
        from ..document import read_bytes
        try:
            text = read_bytes(path)
        except ModelFileError as exc:
            if own:
                raise
            raise b.error(("model", "urdf"), f"{path}: {exc.problem}") from None
    return path, parse_urdf(text, path)


def add_section(b, read):
    """Add the ``(path, Robot)`` ``read`` to ``b.system``; ``(report, body specs, joint
    specs)`` for the ``Scene`` (``mbdyn info`` lists the bodies and joints)."""
    if read is None:
        return None, [], []
    path, robot = read
    model_table = b.doc.get("model", {})
    own = path == b.file
    folders = model_table.get("mesh_path", [])
    folders = [folders] if isinstance(folders, str) else list(folders)
    base = os.path.dirname(os.path.abspath(str(b.file)))
    folders = [os.path.join(base, os.path.expanduser(f)) for f in folders]
    with b.engine(() if own else ("model", "urdf")):
        builder = add_robot(b.system, Reader(path), robot,
                            floating=model_table.get("floating", False),
                            accept_inertia=model_table.get("accept_inertia", False),
                            mesh_path=folders)
    for message in builder.warnings:
        warnings.warn(message, ModelWarning, stacklevel=2)
    bodies = [{"name": n, "urdf": True} for n in builder.bodies]
    joints = [{"name": n, "urdf": True} for n in builder.joints]
    return builder.report, bodies, joints
