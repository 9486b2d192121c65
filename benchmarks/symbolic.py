"""Closed-form equations of motion: mbdyn.symbolic against sympy.physics.mechanics.

The model is a 3D chain of n rigid links hanging from the ground: revolute joints about
alternating local x and y axes (joint 1 about x), link i of mass m_i and length l_i with its
centre of mass l_i/2 below its joint and the next joint l_i below, principal inertias
Ix_i, Iy_i, Iz_i about the centre of mass, gravity -g along Z -- all symbolic.  The same
chain is built with sympy.physics.mechanics (System + PinJoint + KanesMethod, which ships
with sympy; it is used here only) and the two are checked to give the same M and f at a
random state.

For n = 1, 2, 3, 4, 6, 8 the script prints, measured in this one run on this machine:
the derivation time of each (mbdyn.derive(model, "jourdain") vs System.form_eoms with
KanesMethod; CPU time of the process, which a busy machine disturbs less than wall time --
both are in the JSON), the size of M and f (sympy.count_ops, before and after common subexpression
elimination), and the cost of one call of mbdyn's generated, numba-compiled right-hand side
(best of several repeats, which is what a quiet machine would show) next to the numeric
engine's forward dynamics.  A second table shows where the operations sit at the largest n:
M, f and the last link's equation written nested (as the walk builds them), fully expanded,
compact (mbdyn's default) and by KanesMethod.  A third gives the textbook's point: the double
pendulum written with each body's own moving frame against one frame for all vectors.

    python benchmarks/symbolic.py                 # everything (Kane at n = 8 takes minutes)
    python benchmarks/symbolic.py --n 1 2 3 --no-kane
    python benchmarks/symbolic.py --json out.json
"""
from __future__ import annotations

import argparse
import json
import os
import sys
import tempfile
import time
import timeit
import warnings

import numpy as np
import sympy as sp

import mbdyn as mb
from mbdyn.symbolic import compiled_rhs, derive
from mbdyn.symbolic.evaluate import evaluate
from mbdyn.symbolic.simplify import operations_after_cse

NS = (1, 2, 3, 4, 6, 8)


# ----------------------------------------------------------------------------- models
def chain_values(n):
    values = {"g": 9.81}
    for i in range(1, n + 1):
        values.update({f"m{i}": 1.0 + 0.1 * i, f"l{i}": 0.5 + 0.05 * i, f"Ix{i}": 0.02 * i,
                       f"Iy{i}": 0.021 * i, f"Iz{i}": 0.005 * i})
    return values


def mbdyn_chain(n):
    s = mb.System(f"{n}-link chain", gravity=(0, 0, -sp.Symbol("g", real=True)),
                  parameters=chain_values(n))
    parent, offset = "ground", 0
    for i in range(1, n + 1):
        m, l, Ix, Iy, Iz = s.symbols(f"m{i} l{i} Ix{i} Iy{i} Iz{i}")
        s.add_body(f"link{i}", mass=m, com=(0, 0, -l / 2), inertia=(Ix, Iy, Iz))
        s.add_joint(f"q{i}", "revolute", parent=parent, child=f"link{i}",
                    axis="x" if i % 2 else "y", position=(0, 0, -offset),
                    speeds=(f"u{i}",))
        parent, offset = f"link{i}", l
    return s


def kane_chain(n):
    """The same chain with sympy.physics.mechanics; returns (M, f, q, u)."""
    from sympy.physics.mechanics import (KanesMethod, PinJoint, Point, ReferenceFrame,
                                         RigidBody, System, dynamicsymbols, inertia)
    g = sp.Symbol("g")
    N = ReferenceFrame("N")
    O = Point("O")
    O.set_vel(N, 0)
    ground = RigidBody("ground", O, N, sp.S(0), (inertia(N, 0, 0, 0), O))
    system = System.from_newtonian(ground)
    parent = ground
    qs, us = [], []
    for i in range(1, n + 1):
        m, l, Ix, Iy, Iz = sp.symbols(f"m{i} l{i} Ix{i} Iy{i} Iz{i}")
        q, u = dynamicsymbols(f"q{i} u{i}")
        B = ReferenceFrame(f"B{i}")
        G = Point(f"G{i}")
        body = RigidBody(f"link{i}", G, B, m, (inertia(B, Ix, Iy, Iz), G))
        axis = parent.frame.x if i % 2 else parent.frame.y
        parent_point = O if i == 1 else -sp.Symbol(f"l{i - 1}") / 2 * parent.frame.z
        joint = PinJoint(f"J{i}", parent, body, coordinates=q, speeds=u,
                         parent_point=parent_point, child_point=l / 2 * B.z, joint_axis=axis)
        system.add_bodies(body)
        system.add_joints(joint)
        parent = body
        qs.append(q)
        us.append(u)
    system.apply_uniform_gravity(-g * N.z)
    system.form_eoms(eom_method=KanesMethod)
    return system.mass_matrix, system.forcing, qs, us


def kane_numeric(M, f, qs, us, n, q, u):
    """Kane's M and f at a state (dynamic symbols replaced by plain symbols)."""
    from sympy.physics.mechanics import msubs
    qsym = sp.symbols(f"q1:{n + 1}")
    usym = sp.symbols(f"u1:{n + 1}")
    t = sp.Symbol("t")
    rep = {sp.Derivative(x, t): y for x, y in zip(qs, usym)}
    rep.update(dict(zip(qs, qsym)))
    rep.update(dict(zip(us, usym)))
    Ms, fs = msubs(M, rep), msubs(f, rep)
    vals = {sp.Symbol(k): v for k, v in chain_values(n).items()}
    vals.update(dict(zip(qsym, q)))
    vals.update(dict(zip(usym, u)))
    return (np.array(evaluate(list(Ms), vals)).reshape(n, n),
            np.array(evaluate(list(fs), vals)))


# ----------------------------------------------------------------------------- timing
def best_call_time(fn, *args, number=20000, repeat=7):
    """Seconds per call: best of ``repeat`` runs of ``number`` calls."""
    return min(timeit.repeat(lambda: fn(*args), number=number, repeat=repeat)) / number


def run_chain(n, kane=True, check=True):
    row = {"n": n}
    model = mbdyn_chain(n).compile()
    t0, c0 = time.perf_counter(), time.process_time()
    d = derive(model, "jourdain", measure=False)
    row["mbdyn_derive_s"] = time.process_time() - c0
    row["mbdyn_derive_wall_s"] = time.perf_counter() - t0
    row["mbdyn_ops"] = int(sum(sp.count_ops(e) for e in d.mass_matrix)
                           + sum(sp.count_ops(e) for e in d.forcing))
    row["mbdyn_ops_cse"] = operations_after_cse([d.mass_matrix, d.forcing])
    # generated right-hand side
    rhs = compiled_rhs(model)
    rng = np.random.default_rng(n)
    q, u = rng.uniform(-1, 1, n), rng.uniform(-1, 1, n)
    y = np.concatenate([q, u])
    rhs.function(0.0, y, rhs.parameters)                  # compile (or load) first
    row["rhs_us"] = best_call_time(rhs.function, 0.0, y, rhs.parameters) * 1e6
    row["engine_us"] = best_call_time(model.forward_dynamics, q, u, 0.0, number=5000) * 1e6
    ud = model.forward_dynamics(q, u)
    row["rhs_error"] = float(np.abs(rhs(0.0, y)[n:] - ud).max() / np.abs(ud).max())
    if kane:
        t0, c0 = time.perf_counter(), time.process_time()
        M, f, qs, us = kane_chain(n)
        row["kane_derive_s"] = time.process_time() - c0
        row["kane_derive_wall_s"] = time.perf_counter() - t0
        row["kane_ops"] = int(sp.count_ops(M) + sp.count_ops(f))
        row["kane_ops_M"] = int(sp.count_ops(M))
        row["kane_ops_f_last"] = int(sp.count_ops(f[n - 1]))
        t0 = time.perf_counter()
        row["kane_ops_cse"] = operations_after_cse([M, f])
        row["kane_cse_s"] = time.perf_counter() - t0
        if check and n <= 4:
            Mk, fk = kane_numeric(M, f, qs, us, n, q, u)
            Mo = model.mass_matrix(q)
            fo = model.forcing(q, u)
            row["kane_vs_mbdyn"] = float(max(np.abs(Mk - Mo).max() / np.abs(Mo).max(),
                                             np.abs(fk - fo).max() / np.abs(fo).max()))
    return row


def representation_sizes(n, kane_row=None):
    """Where the operations of the n-link chain sit, for three forms of the same equations:
    the walk's nested expressions (``simplify="none"``), fully expanded, and mbdyn's default
    (``compact``: the shorter of the two per expression) -- with KanesMethod's for scale.
    ``f[n]`` is the last link's equation, which holds no other link's acceleration: its size
    is what one link's bias acceleration costs in each form."""
    model = mbdyn_chain(n).compile()
    rows = []
    for mode in ("none", "expand", "compact"):
        d = derive(model, "jourdain", simplify=mode, measure=False)
        rows.append({"form": mode, "M": int(sum(sp.count_ops(e) for e in d.mass_matrix)),
                     "f": int(sum(sp.count_ops(e) for e in d.forcing)),
                     "f_last": int(sp.count_ops(d.forcing[n - 1]))})
    if kane_row is not None and "kane_ops_M" in kane_row:
        rows.append({"form": "KanesMethod", "M": kane_row["kane_ops_M"],
                     "f": kane_row["kane_ops"] - kane_row["kane_ops_M"],
                     "f_last": kane_row["kane_ops_f_last"]})
    return rows


def print_representation_table(n, rows, out=sys.stdout):
    head = f"form (n = {n})      ops M      ops f   ops f[{n}]"
    out.write(head + "\n" + "-" * len(head) + "\n")
    for r in rows:
        out.write(f"{r['form']:<16}{r['M']:9d}{r['f']:11d}{r['f_last']:10d}\n")


def double_pendulum_sizes():
    """The textbook's point: own moving frames vs one frame, raw and simplified."""
    g = sp.Symbol("g", real=True)
    s = mb.System("double pendulum", gravity=(0, -g, 0),
                  parameters={"m1": 0.00046, "m2": 0.0046, "l1": 0.07, "l2": 0.07, "g": 9.81})
    m1, m2, l1, l2 = s.symbols("m1 m2 l1 l2")
    s.add_body("link1", mass=m1, com=(0, -l1, 0))
    s.add_joint("theta1", "revolute", parent="ground", child="link1", axis="-z")
    s.add_body("link2", mass=m2, com=(0, -l2, 0))
    s.add_joint("theta2", "revolute", parent="link1", child="link2", axis="-z",
                position=(0, -l1, 0))
    rows = []
    models = [("double pendulum", s.compile())]
    top = mb.System("top", parameters={"m": 0.582, "h": 0.0558, "A": 0.00209393,
                                       "C": 0.0022058, "Mz": -0.025})
    m, h, A, C, Mz = top.symbols("m h A C Mz")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        top.add_body("top", mass=m, com=(0, 0, h), inertia=(A - m * h**2, A - m * h**2, C))
        top.add_joint("contact", "euler", parent="ground", child="top", sequence="ZXZ",
                      coordinates=("psi", "theta", "phi"))
        top.add_load("Mz", "top", moment=(0, 0, Mz), frame="body")
        models.append(("heavy top", top.compile()))
    for name, model in models:
        for method in ("newton-euler", "jourdain", "lagrange"):
            for frames in ("own", "inertial"):
                for simplify in ("none", "compact"):
                    d = derive(model, method, frames=frames, simplify=simplify)
                    rows.append({"model": name, "method": method, "frames": frames,
                                 "simplify": simplify, "derive_s": d.stats["derive_s"],
                                 "ops": d.stats["operations"],
                                 "ops_cse": d.stats["operations_after_cse"]})
    return rows


# ----------------------------------------------------------------------------- output
def print_chain_table(rows, out=sys.stdout):
    head = ("  n | CPU s:    mbdyn    Kane  ratio | ops M+f: mbdyn      Kane  ratio | "
            "after cse: mbdyn    Kane | rhs us: generated  engine")
    out.write(head + "\n" + "-" * len(head) + "\n")
    for r in rows:
        k = "kane_derive_s" in r
        out.write(
            f"{r['n']:3d} | {r['mbdyn_derive_s']:14.2f} "
            + (f"{r['kane_derive_s']:7.2f} {r['kane_derive_s'] / r['mbdyn_derive_s']:6.1f}"
               if k else f"{'-':>7} {'-':>6}")
            + f" | {r['mbdyn_ops']:14d} "
            + (f"{r['kane_ops']:9d} {r['kane_ops'] / r['mbdyn_ops']:6.1f}" if k
               else f"{'-':>9} {'-':>6}")
            + f" | {r['mbdyn_ops_cse']:16d} "
            + (f"{r['kane_ops_cse']:7d}" if k else f"{'-':>7}")
            + f" | {r['rhs_us']:17.2f} {r['engine_us']:7.1f}\n")
    checks = [f"n={r['n']}: {r['kane_vs_mbdyn']:.1e}" for r in rows if "kane_vs_mbdyn" in r]
    if checks:
        out.write("Kane's M and f vs mbdyn's at a random state (relative): "
                  + ", ".join(checks) + "\n")
    out.write("generated rhs vs engine accelerations (relative): "
              + ", ".join(f"n={r['n']}: {r['rhs_error']:.1e}" for r in rows) + "\n")


def print_size_table(rows, out=sys.stdout):
    head = "model            method        frames    simplify  derive s   ops M+f  after cse"
    out.write(head + "\n" + "-" * len(head) + "\n")
    for r in rows:
        out.write(f"{r['model']:<16} {r['method']:<13} {r['frames']:<9} {r['simplify']:<9}"
                  f"{r['derive_s']:8.2f} {r['ops']:9d} {r['ops_cse']:10d}\n")


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--n", type=int, nargs="+", default=list(NS), help="chain lengths")
    ap.add_argument("--no-kane", action="store_true", help="skip sympy.physics.mechanics")
    ap.add_argument("--no-sizes", action="store_true",
                    help="skip the frames and representation tables")
    ap.add_argument("--json", metavar="FILE", help="also write the results as JSON")
    args = ap.parse_args(argv)
    os.environ.setdefault("MBDYN_CACHE_DIR", os.path.join(tempfile.gettempdir(),
                                                          "mbdyn-benchmark-cache"))
    print(f"sympy {sp.__version__}, numpy {np.__version__}, mbdyn {mb.__version__}, "
          f"{os.cpu_count()} CPUs, load average {os.getloadavg()[0]:.1f}\n")
    rows = []
    for n in args.n:
        rows.append(run_chain(n, kane=not args.no_kane))
        print(f"  ... n = {n} done", file=sys.stderr, flush=True)
    print("3D n-link chain (revolute joints about alternating x, y), Jourdain vs KanesMethod")
    print_chain_table(rows)
    result = {"chain": rows}
    if not args.no_sizes:
        n = max(args.n)
        forms = representation_sizes(n, next(r for r in rows if r["n"] == n))
        print(f"\nWhere the size sits: the {n}-link chain's M and f in three forms")
        print_representation_table(n, forms)
        result["forms"] = forms
        sizes = double_pendulum_sizes()
        print("\nOwn moving frames vs one frame (the textbook's point), three methods")
        print_size_table(sizes)
        result["frames"] = sizes
    if args.json:
        with open(args.json, "w") as fh:
            json.dump(result, fh, indent=2)
    return 0


if __name__ == "__main__":
    sys.exit(main())
