"""URDF ``<visual>`` elements in the pictures (docs/urdf.md, "Meshes"): primitives as
drawing shapes, mesh files found through ``package://`` and relative paths, read by
trimesh and decimated; a missing or unreadable mesh leaves the link drawn as before with
one warning."""
from __future__ import annotations

import builtins
import warnings

import numpy as np
import pytest

import mbdyn as mb
from mbdyn import limits
from mbdyn.io.urdf.tree import rpy_matrix
from mbdyn.viz import mesh_files
from mbdyn.viz.geometry import model_geometry

pytest.importorskip("trimesh")

TET = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], float)
TET_FACES = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])
INERTIA = ('<inertial><mass value="1"/><inertia ixx="0.1" ixy="0" ixz="0" iyy="0.1" '
           'iyz="0" izz="0.1"/></inertial>')


def binary_stl(path, vertices=TET, faces=TET_FACES):
    tri = vertices[faces]
    rec = np.zeros(len(faces), dtype=[("n", "<f4", 3), ("v", "<f4", (3, 3)), ("a", "<u2")])
    rec["n"] = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    rec["v"] = tri
    path.write_bytes(b"\0" * 80 + np.uint32(len(faces)).tobytes() + rec.tobytes())


def robot(tmp_path, visual, name="tet.stl"):
    """A one-joint robot in ``tmp_path/robo/urdf`` with the mesh ``robo/meshes/NAME``."""
    (tmp_path / "robo" / "meshes").mkdir(parents=True)
    (tmp_path / "robo" / "urdf").mkdir()
    binary_stl(tmp_path / "robo" / "meshes" / name)
    p = tmp_path / "robo" / "urdf" / "r.urdf"
    p.write_text(f'<robot name="r"><material name="red"><color rgba="1 0 0 1"/></material>'
                 f'<link name="base"/><link name="arm">{INERTIA}{visual}</link>'
                 '<joint name="q" type="continuous"><parent link="base"/><child link="arm"/>'
                 '<origin xyz="0 0 0.5"/><axis xyz="0 0 1"/></joint></robot>')
    return p


def meshes_of(scene, body="arm"):
    for g in model_geometry(scene.model):
        if g["name"] == body:
            return g["meshes"]


def load(p, **kw):
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        scene = mb.load_model(p, **kw)
        meshes = meshes_of(scene)
    return scene, meshes, " | ".join(str(w.message) for w in caught)


XYZ, RPY, SCALE = (0.1, 0.2, 0.3), (0.3, -0.2, 1.1), (2.0, 3.0, 0.5)
MESH = (f'<visual><origin xyz="{" ".join(map(str, XYZ))}" rpy="{" ".join(map(str, RPY))}"/>'
        '<geometry><mesh filename="{}" scale="2 3 0.5"/></geometry>'
        '<material name="red"/></visual>')


@pytest.mark.parametrize("filename", ["package://robo/meshes/tet.stl", "../meshes/tet.stl",
                                      "file://../meshes/tet.stl"])
def test_a_mesh_is_drawn_at_the_links_pose_with_origin_and_scale(tmp_path, filename):
    mesh_files._CACHE.clear()
    scene, meshes, text = load(robot(tmp_path, MESH.format(filename)))
    assert "not found" not in text
    (vertices, faces, colour), = meshes
    assert colour == "#ff0000" and len(faces) == 4
    # the body's axes: the closed form of the vertex (0, 0, 1) of the tetrahedron
    expected = np.array(XYZ) + rpy_matrix(RPY) @ (np.array(SCALE) * [0, 0, 1])
    assert np.min(np.linalg.norm(vertices - expected, axis=1)) < 1e-6
    # in the world, with the joint turned by 0.7 about z from its origin (0, 0, 0.5)
    result = scene.simulate(t_end=0.01)
    from mbdyn.viz.geometry import prepare, realise
    q = result.q[0].copy()
    q[0] = 0.7
    result.q[:] = q
    result.u[:] = 0.0
    run = prepare(result, [0.0])
    _, R, r = run.poses[0]
    solids = realise(run.drawing, 0.0, R, r).solids
    world = np.array([0, 0, 0.5]) + rpy_matrix((0, 0, 0.7)) @ expected
    assert any(np.min(np.linalg.norm(v - world, axis=1)) < 1e-6 for v, _, _ in solids)


def test_primitives_map_to_the_shapes(tmp_path):
    visual = ('<visual><origin xyz="0 0 0.2"/><geometry><cylinder radius="0.05" '
              'length="0.4"/></geometry></visual><visual><geometry><box size="0.1 0.2 0.3"/>'
              '</geometry><material name="m"><color rgba="0 0 1 1"/></material></visual>'
              '<visual><geometry><sphere radius="0.1"/></geometry></visual>')
    scene, meshes, _ = load(robot(tmp_path, visual))
    shapes = scene.system.graph.nodes["arm"]["body"].shape
    assert [s["type"] for s in shapes] == ["cylinder", "box", "sphere"]
    cylinder = meshes[0][0]             # along z, centred on its origin
    assert np.allclose(cylinder[:, 2].min(), 0.0) and np.allclose(cylinder[:, 2].max(), 0.4)
    assert meshes[1][2] == "#0000ff"


def test_a_missing_mesh_warns_once_and_draws_the_link_as_before(tmp_path):
    visual = MESH.format("package://robo/meshes/gone.stl") * 2
    scene, meshes, text = load(robot(tmp_path, visual))
    assert meshes == [] and text.count("'package://robo/meshes/gone.stl' not found") == 1
    assert "mesh_path" in text and "--mesh-path" in text
    assert scene.system.graph.nodes["arm"]["body"].mass == 1.0


def test_the_search_path_finds_a_package_elsewhere(tmp_path):
    p = robot(tmp_path, MESH.format("package://other/tet.stl"))
    (tmp_path / "lib" / "other").mkdir(parents=True)
    binary_stl(tmp_path / "lib" / "other" / "tet.stl")
    assert "not found" in load(p)[2]
    _, meshes, text = load(p, mesh_path=[tmp_path / "lib"])
    assert "not found" not in text and len(meshes) == 1
    wrapper = tmp_path / "robo" / "urdf" / "w.toml"
    wrapper.write_text('[model]\nurdf = "r.urdf"\nmesh_path = ["../../lib"]\n')
    _, meshes, text = load(wrapper)
    assert "not found" not in text and len(meshes) == 1


def test_without_trimesh_the_link_is_drawn_with_a_note(tmp_path, monkeypatch):
    mesh_files._CACHE.clear()
    real = builtins.__import__

    def no_trimesh(name, *args, **kwargs):
        if name == "trimesh":
            raise ImportError("no trimesh")
        return real(name, *args, **kwargs)
    monkeypatch.setattr(builtins, "__import__", no_trimesh)
    _, meshes, text = load(robot(tmp_path, MESH.format("package://robo/meshes/tet.stl")))
    assert meshes == [] and 'pip install "mbdyn[meshes]"' in text and "tet.stl" in text


def test_an_oversize_mesh_file_is_refused_unread(tmp_path, monkeypatch):
    mesh_files._CACHE.clear()
    monkeypatch.setattr(limits, "MAX_MESH_FILE_BYTES", 100)
    _, meshes, text = load(robot(tmp_path, MESH.format("package://robo/meshes/tet.stl")))
    assert meshes == [] and "larger than 100 bytes" in text


def test_a_fine_mesh_is_decimated(tmp_path):
    import trimesh
    sphere = trimesh.creation.icosphere(subdivisions=5)         # 20 480 triangles
    v, f = mesh_files.decimate(np.asarray(sphere.vertices), np.asarray(sphere.faces), 2000)
    assert 100 < len(f) <= 2000 and f.max() < len(v)
    assert np.allclose(np.linalg.norm(v, axis=1), 1.0, atol=0.05)   # still the sphere


def test_a_mesh_that_is_not_one_warns(tmp_path):
    mesh_files._CACHE.clear()
    p = robot(tmp_path, MESH.format("package://robo/meshes/bad.stl"))
    (tmp_path / "robo" / "meshes" / "bad.stl").write_bytes(b"solid x\nnot a mesh\n")
    _, meshes, text = load(p)
    assert meshes == [] and "bad.stl: not drawn" in text


def test_animate_with_mesh_path_embeds_the_mesh_once(tmp_path):
    import json
    import re

    from mbdyn.cli import main
    mesh_files._CACHE.clear()
    p = robot(tmp_path, MESH.format("package://other/tet.stl"))
    (tmp_path / "lib" / "other").mkdir(parents=True)
    binary_stl(tmp_path / "lib" / "other" / "tet.stl")
    out = tmp_path / "r.html"
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        assert main(["animate", str(p), "--mesh-path", str(tmp_path / "lib"), "--t-end",
                     "0.1", "--fps", "10", "--out", str(out)]) == 0
    assert not any("not found" in str(w.message) for w in caught)
    page = out.read_text()
    data = json.loads(re.search(r'id="mbdyn-data">(.*?)</script>', page, re.DOTALL).group(1))
    tets = [s for s in data["solids"] if len(s["f"]) == 12]       # 4 triangles, once
    assert len(tets) == 1 and tets[0]["color"] == "#ff0000"
    assert "<script src=" not in page                              # self-contained
