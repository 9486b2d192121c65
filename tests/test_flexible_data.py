"""Reduced data from other programs (mbdyn/flexible/data.py): NPZ and TOML read alike,
and every bad key named with its remedy."""
import warnings

import numpy as np
import pytest

from mbdyn.errors import ModelError, ModelWarning
from mbdyn.flexible import beam_from_spec, craig_bampton
from mbdyn.flexible.data import load_reduced_body, reduced_body_from_data


def beam_data():
    """A cantilever's Craig-Bampton data with lumped node masses (half of each adjacent
    element's mass; rotary inertia neglected), as another program would write it."""
    b = beam_from_spec({"length": 1.0, "elements": 10, "circle": 0.02, "E": 210e9,
                        "rho": 7850.0, "theory": "euler-bernoulli"})
    body = craig_bampton(b, ("root", "tip"), n_modes=3)
    lumped = np.full(b.n_nodes, 7850.0 * np.pi * 0.01 ** 2 * 0.1)
    lumped[[0, -1]] /= 2
    names = np.array([f"n{i}" for i in range(b.n_nodes)], dtype="<U8")
    names[0], names[-1] = "root", "tip"
    return body, {"mass": body.mass_matrix, "stiffness": body.stiffness_matrix,
                  "modes": body.modes, "nodes": body.nodes, "node_mass": lumped,
                  "names": names, "interface": np.array([0, 10]), "reference": np.array(0)}


def _toml_array(a):
    a = np.asarray(a)
    if a.ndim == 0:
        return repr(float(a)) if a.dtype.kind == "f" else repr(a.item())
    return "[" + ", ".join(_toml_array(x) for x in a) + "]"


def test_npz_and_toml_give_the_same_body(tmp_path):
    body, data = beam_data()
    np.savez(tmp_path / "body.npz", **data)
    from_npz = load_reduced_body(tmp_path / "body.npz")
    lines = [f"{k} = {_toml_array(v)}" for k, v in data.items() if k not in ("names", "reference")]
    lines += ["names = [" + ", ".join(f'"{n}"' for n in data["names"]) + "]",
              'reference = "root"']
    (tmp_path / "body.toml").write_text("\n".join(lines))
    from_toml = load_reduced_body(tmp_path / "body.toml")
    for got in (from_npz, from_toml):
        np.testing.assert_allclose(got.mass_matrix, body.mass_matrix, rtol=1e-15)
        np.testing.assert_allclose(got.frequencies, body.frequencies, rtol=1e-10)
        np.testing.assert_allclose(got.modes, body.modes, rtol=1e-15)
        assert got.node("tip") == 10 and got.reference == 0 and got.interface == (0, 10)
        assert got.invariants.mass == pytest.approx(7850.0 * np.pi * 1e-4, rel=1e-12)
        # lumped first moment and inertia of the uniform rod: exact and O(h^2)
        assert got.invariants.first_moment[0] == pytest.approx(got.invariants.mass / 2)
        assert got.invariants.inertia[2, 2] == pytest.approx(got.invariants.mass / 3, rel=1e-2)
    # the lumped modal mass is close to the consistent one: no warning
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        reduced_body_from_data(data)


def test_rigid_body_modes_only_when_allowed():
    _, data = beam_data()
    K = data["stiffness"].copy()
    K[0, :] = K[:, 0] = 0.0                  # the first coordinate: no stiffness at all
    data = dict(data, stiffness=K)
    with pytest.raises(ModelError, match="stiffness: not positive definite.*allow_rigid_modes"):
        reduced_body_from_data(data)
    body = reduced_body_from_data(data, allow_rigid_modes=True)
    assert body.frequencies[0] == 0.0


def _changed(**change):
    _, data = beam_data()
    data.update(change)
    return {k: v for k, v in data.items() if v is not None}


def _bad_cases():
    _, d = beam_data()
    n, N = d["mass"].shape[0], d["nodes"].shape[0]
    asym = d["mass"].copy()
    asym[0, 1] += 1.0
    nan = d["stiffness"].copy()
    nan[1, 1] = np.nan
    aniso = np.zeros((N, 6, 6))
    aniso[:, :3, :3] = np.diag([1.0, 1.0, 2.0])
    moved = d["modes"].copy()
    moved[0, 1, 0] = 1.0
    return [
        (dict(mass=asym), r"flexible\.data\.mass: not symmetric"),
        (dict(mass=-d["mass"]), r"flexible\.data\.mass: not positive definite"),
        (dict(stiffness=nan), r"flexible\.data\.stiffness: holds a non-finite number at \[1, 1\]"),
        (dict(stiffness=d["stiffness"][:2, :2]), r"stiffness: shape \(2, 2\)"),
        (dict(modes=d["modes"][:, :5]), r"flexible\.data\.modes: shape"),
        (dict(nodes=d["nodes"][:3]), r"flexible\.data\.nodes: shape \(3, 3\)"),
        (dict(node_mass=-d["node_mass"]), r"node_mass: node 0 has a negative mass"),
        (dict(node_mass=aniso), r"node_mass\[0\]: the translation block must be m I"),
        (dict(node_mass=d["node_mass"][:4]), r"node_mass: shape \(4,\)"),
        (dict(names=np.array(["a"] * N)), r"names: a name is given twice"),
        (dict(names=np.array(["1a"] + [f"n{i}" for i in range(1, N)])), r"names: '1a'"),
        (dict(mass=None), r"flexible\.data\.mass: missing"),
        (dict(masses=1.0), r"flexible\.data\.masses: unknown key"),
        (dict(modes=moved), r"reference: the modes do not vanish at node 0"),
        (dict(interface=["root", "hub"]), r"interface: no node named 'hub'"),
        (dict(interface=[0, 99]), r"interface: 99 is neither"),
        (dict(damping=np.ones(n + 1)), r"damping: give \d+ damping ratios"),
        (dict(mass="heavy"), r"flexible\.data\.mass: must be an array of numbers"),
    ]


@pytest.mark.parametrize("change, message", _bad_cases())
def test_bad_data_names_its_key(change, message):
    with pytest.raises(ModelError, match=message):
        reduced_body_from_data(_changed(**change))


def test_files_refused(tmp_path):
    _, data = beam_data()
    np.savez(tmp_path / "pickled.npz", **dict(data, names=np.array(data["names"], dtype=object)))
    with pytest.raises(ModelError, match="plain unicode arrays"):
        load_reduced_body(tmp_path / "pickled.npz")
    (tmp_path / "body.json").write_text("{}")
    with pytest.raises(ModelError, match="give a .npz or .toml file"):
        load_reduced_body(tmp_path / "body.json")
    (tmp_path / "bad.toml").write_text("mass = [[1.0,")
    with pytest.raises(ModelError, match="not a TOML file"):
        load_reduced_body(tmp_path / "bad.toml")


def test_modal_mass_far_from_the_node_masses_warns():
    _, data = beam_data()
    with pytest.warns(ModelWarning, match="modal mass"):
        reduced_body_from_data(dict(data, node_mass=data["node_mass"] * 1000))
