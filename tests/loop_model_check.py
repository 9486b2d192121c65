"""Geometry check of the closed-loop models in ``models/``, independent of the engine.

For each model (and each of its cases) this reads the TOML file, evaluates its numbers
with a small expression reader of its own, builds every body's frame from the tree
joints with its own rotations, and places both sides of every loop joint in the world.
Holding the values of ``[initial]`` (and the drives at t = 0), it solves the loop
equations for the other coordinates by Gauss-Newton from ``[guess]``, then the velocity
equations for the speeds not given in ``[initial_speeds]``, and reports the residuals,
the rank of the loop equations and the mobility -- and compares the assembled state with
the closed forms of ``loop_references``.  Nothing here imports mbdyn.

    python tests/loop_model_check.py            # a table for every model and case

The file format read here is the one issue 24 decided: a joint whose child already hangs
from another joint closes a loop (``cut = true`` chooses which, else the later one),
with ``position``/``axis``/``orientation`` in the parent and ``child_position``/
``child_orientation`` in the child.  Only the kinds these models use are read: tree
joints revolute, prismatic, fixed; loop joints revolute.
"""
import ast
import functools
import math
import pathlib
import sys
import tomllib

import numpy as np

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
import loop_references as ref

MODELS = pathlib.Path(__file__).resolve().parents[1] / "models"
LOOP_MODELS = ("four_bar", "slider_crank", "andrews_squeezer", "watt_governor", "bricard")
ARRAYS = ("bodies", "joints", "loads", "forces", "events")
FUNCS = {"sin": math.sin, "cos": math.cos, "tan": math.tan, "asin": math.asin,
         "acos": math.acos, "atan": math.atan, "atan2": math.atan2, "sinh": math.sinh,
         "cosh": math.cosh, "tanh": math.tanh, "sqrt": math.sqrt, "exp": math.exp,
         "log": math.log, "abs": abs, "sign": lambda x: float(np.sign(x)), "min": min,
         "max": max}
BINOPS = {ast.Add: lambda a, b: a + b, ast.Sub: lambda a, b: a - b,
          ast.Mult: lambda a, b: a * b, ast.Div: lambda a, b: a / b,
          ast.Pow: lambda a, b: a ** b}


# ----------------------------------------------------------------------------- values
def value(x, names):
    """A number, or an expression string evaluated with ``names`` (numbers, names,
    ``+ - * / **``, unary signs, the model files' functions; nothing is ``eval``-ed)."""
    if isinstance(x, (int, float)) and not isinstance(x, bool):
        return float(x)

    def walk(node):
        if isinstance(node, ast.Constant) and isinstance(node.value, (int, float)):
            return float(node.value)
        if isinstance(node, ast.Name):
            if node.id == "pi":
                return math.pi
            return names[node.id]
        if isinstance(node, ast.BinOp) and type(node.op) in BINOPS:
            return BINOPS[type(node.op)](walk(node.left), walk(node.right))
        if isinstance(node, ast.UnaryOp) and isinstance(node.op, (ast.USub, ast.UAdd)):
            v = walk(node.operand)
            return -v if isinstance(node.op, ast.USub) else v
        if isinstance(node, ast.Call) and isinstance(node.func, ast.Name) \
                and node.func.id in FUNCS and not node.keywords:
            return FUNCS[node.func.id](*(walk(a) for a in node.args))
        raise ValueError(f"cannot read {ast.dump(node)} in {x!r}")
    return walk(_tree(str(x).strip()))


@functools.lru_cache(maxsize=512)
def _tree(text):
    return ast.parse(text, mode="eval").body


def vector(v, names):
    return np.array([value(c, names) for c in v])


def parameters(doc):
    """The parameters' values, each expression after the ones it uses."""
    raw, out = dict(doc.get("parameters", {})), {}
    while raw:
        progress = False
        for k in list(raw):
            try:
                out[k] = value(raw[k], out)
            except KeyError:
                continue
            del raw[k]
            progress = True
        if not progress:
            raise ValueError(f"parameters that cannot be resolved: {sorted(raw)}")
    return out


def apply_case(doc, case):
    """``doc`` with ``[cases.case]`` merged as mbdyn merges it: arrays of tables replaced
    whole (a list) or element by element (a table of names); other tables key by key."""
    out = {k: v for k, v in doc.items() if k != "cases"}
    for key, val in doc["cases"][case].items():
        if key in ARRAYS:
            if isinstance(val, list):
                out[key] = val
            else:
                items = [dict(x) for x in out.get(key, [])]
                for name, part in val.items():
                    hit = [x for x in items if x.get("name") == name]
                    (hit[0].update(part) if hit else items.append({"name": name, **part}))
                out[key] = items
        else:
            out[key] = {**out.get(key, {}), **val}
    return out


AXES = {"x": (1.0, 0, 0), "y": (0, 1.0, 0), "z": (0, 0, 1.0)}


def axis(a, names):
    if isinstance(a, str):
        v = np.array(AXES[a.lstrip("+-")])
        return -v if a.startswith("-") else v
    v = vector(a, names)
    return v / np.linalg.norm(v)


def orientation(o, names):
    if o is None:
        return np.eye(3)
    if isinstance(o, dict):
        return ref.rotation(axis(o["axis"], names), value(o["angle"], names))
    arr = np.array([[value(c, names) for c in row] for row in o]) if np.ndim(o) == 2 \
        else vector(o, names)
    if arr.shape == (3, 3):
        return arr
    w, x, y, z = arr / np.linalg.norm(arr)
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
                     [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
                     [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]])


# ----------------------------------------------------------------------------- the model
class LoopModel:
    """The tree and the loop joints of one model document (a case already applied)."""

    def __init__(self, doc):
        self.doc = doc
        self.p = parameters(doc)
        by_child = {}
        for j in doc["joints"]:
            by_child.setdefault(j["child"], []).append(j)
        self.tree, self.loops = [], []
        for js in by_child.values():
            cut = [j for j in js if j.get("cut")]
            loop = cut if cut and len(cut) < len(js) else js[1:]
            self.loops += loop
            self.tree += [j for j in js if j not in loop]
        self.tree.sort(key=doc["joints"].index)
        self.coordinates = [j["name"] for j in self.tree
                            if j["kind"] in ("revolute", "prismatic") and "drive" not in j]
        self.driven = {j["name"]: j["drive"] for j in self.tree if "drive" in j}

    def drive(self, name, t):
        return value(self.driven[name], {**self.p, "t": t})

    def frames(self, q, t=0.0):
        """``{body: (R, r)}`` for coordinate values ``q`` (a dict) at time ``t``."""
        placed = {"ground": (np.eye(3), np.zeros(3))}
        pending = list(self.tree)
        while pending:
            j = next(j for j in pending if j["parent"] in placed)
            pending.remove(j)
            R, r = placed[j["parent"]]
            C = orientation(j.get("orientation"), self.p)
            r = r + R @ vector(j.get("position", (0, 0, 0)), self.p)
            if j["kind"] == "fixed":
                placed[j["child"]] = (R @ C, r)
                continue
            if j["kind"] not in ("revolute", "prismatic"):
                raise ValueError(f"joint {j['name']}: kind {j['kind']} not read here")
            qj = self.drive(j["name"], t) if j["name"] in self.driven else q[j["name"]]
            a = axis(j["axis"], self.p)
            if j["kind"] == "revolute":
                placed[j["child"]] = (R @ C @ ref.rotation(a, qj), r)
            else:
                placed[j["child"]] = (R @ C, r + R @ C @ (a * qj))
        return placed

    def loop_sides(self, q, t=0.0):
        """Per loop joint: the joint point and axis in the world seen from the parent and
        from the child."""
        fr, out = self.frames(q, t), {}
        for j in self.loops:
            if j["kind"] != "revolute":
                raise ValueError(f"loop joint {j['name']}: kind {j['kind']} not read here")
            (RP, rP), (RC, rC) = fr[j["parent"]], fr[j["child"]]
            CP = orientation(j.get("orientation"), self.p)
            CC = orientation(j.get("child_orientation"), self.p)
            a = axis(j["axis"], self.p)
            out[j["name"]] = (rP + RP @ vector(j.get("position", (0, 0, 0)), self.p),
                              RP @ CP @ a,
                              rC + RC @ vector(j.get("child_position", (0, 0, 0)), self.p),
                              RC @ CC @ a)
        return out

    def residual(self, q, t=0.0):
        """The loop equations: per revolute loop joint the gap between the two points (3)
        and the cross product of the two axes (3; rank 2)."""
        parts = [np.concatenate([pp - pc, np.cross(ap, ac)])
                 for pp, ap, pc, ac in self.loop_sides(q, t).values()]
        return np.concatenate(parts)

    def jacobian(self, q, names, t=0.0, h=1e-4):
        """``d residual / d q`` for the coordinates ``names``, by the fourth-order central
        difference (error ~h^4 + 1e-16/h: about 1e-12)."""
        def at(name, step):
            qs = dict(q)
            qs[name] += step
            return self.residual(qs, t)
        cols = [(8 * (at(n, h) - at(n, -h)) - (at(n, 2 * h) - at(n, -2 * h))) / (12 * h)
                for n in names]
        return np.array(cols).T.reshape(-1, len(names))

    def assemble(self, t=0.0, tol=1e-14, iterations=60):
        """Hold ``[initial]``, solve the rest from ``[guess]`` (0 where none); then the
        speeds.  Returns a report dict."""
        init = {k: value(v, self.p) for k, v in self.doc.get("initial", {}).items()}
        guess = {k: value(v, self.p) for k, v in self.doc.get("guess", {}).items()}
        q = {n: init.get(n, guess.get(n, 0.0)) for n in self.coordinates}
        q0 = dict(q)
        free = [n for n in self.coordinates if n not in init]
        before = {k: float(np.abs(np.r_[pp - pc, np.cross(ap, ac)]).max())
                  for k, (pp, ap, pc, ac) in self.loop_sides(q, t).items()}
        for _ in range(iterations if free else 0):
            J = self.jacobian(q, free, t)
            dx = np.linalg.lstsq(J, -self.residual(q, t), rcond=None)[0]
            for n, d in zip(free, dx):
                q[n] += d
            if np.abs(dx).max() < tol:
                break
        after = {k: float(np.abs(np.r_[pp - pc, np.cross(ap, ac)]).max())
                 for k, (pp, ap, pc, ac) in self.loop_sides(q, t).items()}
        parallel = min(float(ap @ ac) for _pp, ap, _pc, ac in self.loop_sides(q, t).values())
        u, vel_res = self.speeds(q, init, t)
        Jall = self.jacobian(q, self.coordinates, t)
        sv = np.linalg.svd(Jall, compute_uv=False)
        rank = int((sv > 1e-9 * sv.max()).sum())
        return {"q": q, "u": u, "held": sorted(init), "free": free,
                "moved": {n: q[n] - q0[n] for n in free}, "before": before, "after": after,
                "axes_aligned": parallel, "velocity_residual": vel_res,
                "equations": Jall.shape[0], "rank": rank,
                "mobility": len(self.coordinates) - rank}

    def speeds(self, q, init, t, h=1e-4):
        """Hold ``[initial_speeds]`` (a coordinate's name stands for its rate), solve the
        velocity equations ``J u = -dg/dt`` for the others."""
        given = {}
        for k, v in self.doc.get("initial_speeds", {}).items():
            given[k.removesuffix("_dot")] = value(v, self.p)
        names = self.coordinates
        J = self.jacobian(q, names, t)
        g_t = ((8 * (self.residual(q, t + h) - self.residual(q, t - h))
                - (self.residual(q, t + 2 * h) - self.residual(q, t - 2 * h))) / (12 * h)
               if self.driven else np.zeros(J.shape[0]))
        held = [n for n in names if n in given]
        free = [n for n in names if n not in given]
        rhs = -g_t - J[:, [names.index(n) for n in held]] @ np.array([given[n] for n in held])
        uf = np.linalg.lstsq(J[:, [names.index(n) for n in free]], rhs, rcond=None)[0] \
            if free else np.zeros(0)
        u = {**{n: given[n] for n in held}, **dict(zip(free, uf))}
        res = J @ np.array([u[n] for n in names]) + g_t
        return u, float(np.abs(res).max())


# ----------------------------------------------------------------------------- checks
def load(stem):
    with open(MODELS / f"{stem}.toml", "rb") as f:
        return tomllib.load(f)


def cases(doc):
    return [None] + list(doc.get("cases", {}))


def closed_form_errors(stem, case, m, rep):
    """``(positions, speeds)``: the largest differences between the assembled state and
    the closed forms."""
    p, q, u = m.p, rep["q"], rep["u"]
    if stem == "four_bar":
        branch = "crossed" if case == "crossed" else "open"
        t2 = q.get("crank", m.drive("crank", 0.0) if "crank" in m.driven else 0.0)
        w2 = u.get("crank", p["Omega"] if "crank" in m.driven else 0.0)
        t3, t4 = ref.fourbar_positions(t2, p["a"], p["b"], p["c"], p["d"], branch)
        w3, w4 = ref.fourbar_velocities(t2, t3, t4, w2, p["a"], p["b"], p["c"], p["d"])
        return (max(abs(ref.wrap(q["coupler"] + t2 - t3)), abs(ref.wrap(q["rocker"] - t4))),
                max(abs(u["coupler"] + w2 - w3), abs(u["rocker"] - w4)))
    if stem == "slider_crank":
        th, w = q["theta"], u["theta"]
        x, xd, _ = ref.slider_crank(th, w, 0.0, p["r"], p["l"], p["e"])
        phi, phid, _ = ref.slider_crank_rod(th, w, 0.0, p["r"], p["l"], p["e"])
        return (max(abs(q["xp"] - x), abs(ref.wrap(q["rod"] + th - phi))),
                max(abs(u["xp"] - xd), abs(u["rod"] + w - phid)))
    if stem == "andrews_squeezer":
        qa = np.array([q[n] for n in ref.ANDREWS_NAMES])
        ua = np.array([u[n] for n in ref.ANDREWS_NAMES])
        return (float(np.abs(ref.andrews_constraints(qa)).max()),
                float(np.abs(ref.andrews_constraint_jacobian(qa) @ ua).max()))
    if stem == "watt_governor":
        al, ald = q["alpha1"], u["alpha1"]
        return (max(abs(q["alpha2"] - al), abs(q["beta1"] + 2 * al), abs(q["beta2"] + 2 * al),
                    abs(q["zs"] - (p["H"] - 2 * p["a"] * math.cos(al)))),
                max(abs(u["alpha2"] - ald), abs(u["beta1"] + 2 * ald), abs(u["beta2"] + 2 * ald),
                    abs(u["zs"] - 2 * p["a"] * math.sin(al) * ald)))
    if stem == "bricard":
        qb = np.array([q[f"q{k}"] for k in range(1, 6)])
        ub = np.array([u[f"q{k}"] for k in range(1, 6)])
        dphi = ref.bricard_phi(qb[0])[1]
        return (float(np.abs(qb - ref.bricard_q(qb[0])).max()),
                float(np.abs(ub - ub[0] * np.array([1, dphi, 1, dphi, 1])).max()))
    return float("nan"), float("nan")


def gas_force_error(n=2001):
    """Largest difference (N) between slider_crank.toml's gas force and
    ``-A_p * gas_pressure(theta)`` over three cycles."""
    doc = load("slider_crank")
    p = parameters(doc)
    text = next(ld for ld in doc["loads"] if ld["name"] == "gas")["force"][0]
    worst = 0.0
    for th in np.linspace(-6 * math.pi, 6 * math.pi, n):
        f = value(text, {**p, "theta": th})
        worst = max(worst, abs(f + p["A_p"] * ref.gas_pressure(th)))
    return worst


def check_all(stems=LOOP_MODELS):
    """``{(stem, case): report}`` for every model and case."""
    out = {}
    for stem in stems:
        doc = load(stem)
        for case in cases(doc):
            m = LoopModel(apply_case(doc, case) if case else doc)
            rep = m.assemble()
            rep["closed_form_q"], rep["closed_form_u"] = closed_form_errors(stem, case, m, rep)
            out[(stem, case)] = rep
    return out


def main():
    print(f"{'model':18s} {'case':8s} {'loops':>5s} {'eqs':>4s} {'rank':>4s} {'mob':>3s} "
          f"{'gap(guess)':>10s} {'gap(solved)':>11s} {'|moved|':>8s} {'vel.res':>8s} "
          f"{'cf: q':>8s} {'cf: u':>8s}")
    for (stem, case), r in check_all().items():
        moved = max((abs(v) for v in r["moved"].values()), default=0.0)
        print(f"{stem:18s} {case or '-':8s} {len(r['after']):5d} {r['equations']:4d} "
              f"{r['rank']:4d} {r['mobility']:3d} {max(r['before'].values()):10.2e} "
              f"{max(r['after'].values()):11.2e} {moved:8.2e} "
              f"{r['velocity_residual']:8.1e} {r['closed_form_q']:8.1e} {r['closed_form_u']:8.1e}")
    print(f"slider_crank gas force vs the table: {gas_force_error():.2e} N")


if __name__ == "__main__":
    main()
