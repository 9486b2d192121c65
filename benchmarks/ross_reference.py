#!/usr/bin/env python
"""Reference Campbell data of the flexible Jeffcott rotor (``models/jeffcott_flexible.toml``)
computed by ROSS (ross-rotordynamics), written to ``tests/data/ross_campbell.json``
(committed), which ``tests/test_flexible_rotor.py`` compares mbdyn against.  ROSS is never
a dependency of mbdyn: run this script in an environment of its own,

    python3 -m venv /tmp/rossvenv && /tmp/rossvenv/bin/pip install ross-rotordynamics
    /tmp/rossvenv/bin/pip install "plotly<6"      # ROSS 2.3 imports a template plotly 6 lacks
    /tmp/rossvenv/bin/python benchmarks/ross_reference.py

The same rotor in ROSS: eight Timoshenko shaft elements of 0.1 m (``ShaftElement``: steel
E = 2.1e11 Pa, G = E / 2.6, rho = 7850 kg/m^3, outer diameter 0.0319 m; Cowper's shear
coefficient, rotary inertia and gyroscopic terms, as mbdyn's beam), the disk at node 4
(``DiskElement``: m = 10 kg, Id = 0.03, Ip = 0.05 kg m^2) and the two bearings at nodes 0
and 8 (``BearingElement``).  The model file's bearings are tabulated against the spin;
ROSS fits its own spline through such tables, mbdyn interpolates them (PCHIP), so the
reference is taken at the table's knots only (and at 0, where mbdyn holds the first
row), each speed with the bearings' constant coefficients of that row: the comparison
is of the rotor's equations, not of two interpolations.  Axes: ROSS's shaft runs along z
with lateral x, y (x cross y = z, the spin axis), mbdyn's along x with lateral y, z (y
cross z = x): the bearing coefficients map one to one (ROSS kxy = mbdyn's kxy).

Per speed, the modes of ``Rotor.run_modal`` with a damped frequency above 1 rad/s (ROSS
also returns the shaft's torsional and axial modes, which mbdyn's lateral rotor holds;
they are told apart by the lateral share of their shapes), up to ``N_MODES``: damped
frequency (rad/s), logarithmic decrement, damping ratio and whirl (ROSS's whirl value:
0 forward, 1 backward, 0.5 mixed).
"""
from __future__ import annotations

import json
import os
import sys
import warnings

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
OUT = os.path.join(HERE, "..", "tests", "data", "ross_campbell.json")
N_MODES = 8
SPEEDS = [0.0, 50.0, 100.0, 200.0, 400.0, 800.0]
#: the model file's bearing table (models/jeffcott_flexible.toml), rows by speed
TABLE = {"speeds": [50, 100, 200, 400, 800],
         "kxx": [4.0e6, 3.0e6, 2.2e6, 1.8e6, 1.6e6],
         "kxy": [1.0e6, 1.4e6, 1.8e6, 2.4e6, 3.2e6],
         "kyx": [-0.6e6, -0.9e6, -1.3e6, -1.8e6, -2.6e6],
         "kyy": [5.0e6, 3.5e6, 2.5e6, 2.0e6, 1.8e6],
         "cxx": [2.0e4, 1.2e4, 7.0e3, 4.0e3, 2.4e3],
         "cxy": [3.0e3, 2.0e3, 1.2e3, 7.0e2, 4.0e2],
         "cyx": [3.0e3, 2.0e3, 1.2e3, 7.0e2, 4.0e2],
         "cyy": [2.6e4, 1.6e4, 9.0e3, 5.0e3, 3.0e3]}
ROTOR = {"elements": 8, "element_length": 0.1, "diameter": 0.0319, "E": 2.1e11,
         "nu": 0.3, "rho": 7850.0, "disk_node": 4, "disk_mass": 10.0, "disk_Id": 0.03,
         "disk_Ip": 0.05, "bearing_nodes": [0, 8]}


def row(speed):
    """The bearing table's row at ``speed`` (the first row below the first knot)."""
    knots = TABLE["speeds"]
    k = 0 if speed <= knots[0] else knots.index(speed)
    return {c: TABLE[c][k] for c in TABLE if c != "speeds"}


def rotor(rs, speed):
    """The ROSS rotor with the bearings' coefficients at ``speed``."""
    r = ROTOR
    steel = rs.Material(name="steel_mbdyn", rho=r["rho"], E=r["E"],
                        G_s=r["E"] / (2 * (1 + r["nu"])))
    shaft = [rs.ShaftElement(L=r["element_length"], idl=0.0, odl=r["diameter"],
                             material=steel, shear_effects=True, rotary_inertia=True,
                             gyroscopic=True, shear_method_calc="cowper")
             for _ in range(r["elements"])]
    disk = rs.DiskElement(n=r["disk_node"], m=r["disk_mass"], Id=r["disk_Id"],
                          Ip=r["disk_Ip"])
    c = row(speed)
    bearings = [rs.BearingElement(n=n, **c) for n in r["bearing_nodes"]]
    return rs.Rotor(shaft, [disk], bearings)


def lateral_share(shape_vector, ndof):
    """The share of a mode's (complex) shape in the lateral DoFs (x, y, and the tilts)."""
    v = np.abs(np.asarray(shape_vector)) ** 2
    nodes = len(v) // ndof
    v = v[:nodes * ndof].reshape(nodes, ndof)
    lateral = v[:, [0, 1, 3, 4]].sum()
    return float(lateral / v.sum())


def modes_at(rs, speed):
    rt = rotor(rs, speed)
    modal = rt.run_modal(speed=speed, num_modes=4 * N_MODES + 12)
    ndof = rt.number_dof
    out = []
    whirl = modal.whirl_values()
    for k in range(len(modal.wd)):
        if modal.wd[k] <= 1.0:
            continue
        if lateral_share(modal.evectors[:ndof * len(rt.nodes), k], ndof) < 0.99:
            continue                    # a torsional or axial mode
        out.append({"wd": float(modal.wd[k]), "log_dec": float(modal.log_dec[k]),
                    "damping_ratio": float(modal.damping_ratio[k]),
                    "whirl": float(whirl[k])})
    out.sort(key=lambda m: m["wd"])
    return out[:N_MODES], ndof


def main():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        import ross as rs
    data = {"ross_version": rs.__version__,
            "command": "/tmp/rossvenv/bin/python benchmarks/ross_reference.py",
            "model": "models/jeffcott_flexible.toml", "rotor": ROTOR, "bearing_table": TABLE,
            "speeds": SPEEDS, "modes": []}
    for s in SPEEDS:
        modes, ndof = modes_at(rs, s)
        data["modes"].append(modes)
        print(f"Omega {s:6.0f}: " + "  ".join(f"{m['wd']:9.3f}({m['whirl']:.1f})"
                                             for m in modes))
    data["ross_dof_per_node"] = ndof
    with open(OUT, "w") as f:
        json.dump(data, f, indent=1)
        f.write("\n")
    print(f"wrote {os.path.relpath(OUT)}")


if __name__ == "__main__":
    sys.exit(main())
