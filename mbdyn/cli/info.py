"""``mbdyn info MODEL``: what a model file holds -- bodies, joints, coordinates, speeds,
degrees of freedom, drives, loads, events, settings and every validation warning."""
from __future__ import annotations

import json
import sys

import numpy as np

from ..io.results import outputs_spec
from .common import add_command, fmt, load


def register(subparsers):
    p = add_command(subparsers, "info", "Describe a model file: bodies, joints, coordinates, "
                    "speeds, degrees of freedom, drives, loads, events and every validation "
                    "warning.", info)
    p.add_argument("--json", action="store_true", help="print one JSON object")


def _text(v):
    if isinstance(v, list):
        return "[" + ", ".join(_text(x) for x in v) + "]"
    if isinstance(v, float):
        return fmt(v)
    return str(v)


def describe(scene):
    """The ``mbdyn info --json`` object."""
    model = scene.model
    bodies = []
    for spec in scene.body_specs:
        b = model.body(spec["name"])
        bodies.append({"name": b.name, "mass": b.mass, "com": b.com.tolist(),
                       "inertia": b.inertia.tolist(),
                       "principal_moments": np.linalg.eigvalsh(b.inertia).tolist(),
                       "massless": not b.has_inertia})
    joints, drives = [], []
    for spec in scene.joint_specs:
        if spec["name"] in model.loop_joints:
            continue                       # described under "loops"
        j = model.joint(spec["name"])
        entry = {"name": j.name, "kind": j.kind, "parent": j.parent, "child": j.child,
                 "coordinates": list(j.coordinates), "speeds": list(j.speeds),
                 "driven": j.drive is not None}
        if j.kind in ("revolute", "prismatic"):
            entry["axis"] = j.axis.tolist()
        if j.kind == "euler":
            entry["sequence"] = "".join("XYZ"[k] for k in j.sequence)
        if np.any(j.position):
            entry["position"] = j.position.tolist()
        if np.abs(j.orientation - np.eye(3)).max() > 0:
            from ..elements.rotations import from_matrix
            entry["orientation"] = from_matrix(j.orientation).tolist()
        if j.drive is not None:
            entry["drive"] = str(spec["drive"])
            drives.append({"joint": j.name, "coordinate": j.coordinates[0],
                           "expression": str(spec["drive"])})
        joints.append(entry)
    loads = [{"name": ld["name"], "body": ld["body"], "force": ld.get("force"),
              "moment": ld.get("moment"), "point": ld.get("point", [0, 0, 0]),
              "frame": ld.get("frame", "world")} for ld in scene.load_specs]
    return {
        "model": scene.name, "file": scene.path, "description": scene.description,
        "case": scene.case, "cases": list(scene.cases), "default_case": scene.default_case,
        "parameters": scene.parameters, "gravity": model.gravity.tolist(),
        "bodies": bodies, "joints": joints,
        "coordinates": list(model.coordinates), "speeds": list(model.speeds),
        "dof": model.nu, "drives": drives, "loads": loads,
        "forces": [{"name": el.name, "kind": el.kind, "description": el.describe(),
                    "on": model.effects.get(el.name, True)}
                   for el in scene.system.forces.values()],
        "effects": dict(model.effects),
        "events": list(scene.event_specs), "initial": scene.initial_state,
        "simulation": dict(scene.settings),
        "route": _route(model, scene.settings.get("method") or "auto"),
        "outputs": outputs_spec(scene),
        "warnings": list(scene.warnings),
        "loops": describe_loops(scene) if model.has_loops else None,
        "urdf": scene.urdf,
    }


#: what each route solves, as ``mbdyn info`` says it
ROUTES = {"jourdain": "M u' = f by the mass matrix and its Cholesky factor",
          "articulated": "the articulated-body algorithm, O(n)",
          "newton-euler": "the Newton-Euler system with reactions, in tree order",
          "newton-euler-dense": "the Newton-Euler system with reactions, dense LU",
          "symbolic": "the derived equations, evaluated by sympy's lambdify"}
LOOP_ROUTES = {"jourdain": "M u' = f + G^T lam, G u' = gamma by the mass matrix",
               "articulated": "the articulated-body algorithm, one solve per independent "
                              "constraint row"}


def _route(model, method):
    """The route a run of ``method`` takes (``"auto"`` resolved by the model's size), and
    what it solves; None when the model has no choice to say (flexible bodies)."""
    try:
        route = model.formulation(method) if method != "symbolic" else method
    except Exception:               # noqa: BLE001 -- a method the run itself will refuse
        return None
    text = (LOOP_ROUTES if model.has_loops else ROUTES).get(route, ROUTES.get(route))
    if getattr(model, "flexible_bodies", ()):
        text = ("M u' = f + G^T lam, G u' = gamma with the flexible bodies' modal terms, "
                "in Python (numpy)" if model.has_loops else
                "M u' = f with the flexible bodies' modal terms, in Python (numpy)")
    return {"method": method, "route": route, "solves": text}


def describe_loops(scene):
    """The loop joints, the loops they close, the constraint equations, their rank at the
    initial state, the mobility and the reaction components that are not unique."""
    from ..integrate.result import REACTION_COMPONENTS
    model = scene.model
    rank, conditioning = model.constraint_rank(scene.q0)
    joints = []
    for name in model.loop_joints:
        j = model.joint(name)
        entry = {"name": name, "kind": j.kind, "equations": j.equations}
        if j.kind == "coupling":
            entry.update(follower=j.follower, leader=j.leader, ratio=j.ratio, offset=j.offset)
        else:
            entry.update(parent=j.parent, child=j.child, position=j.position.tolist(),
                         child_position=j.child_position.tolist(),
                         loop=list(model.loops.get(name, [])))
            if j.kind == "distance":
                entry["length"] = j.length
        joints.append(entry)
    unique = model.reaction_uniqueness(scene.q0)
    m = len(model.constraint_rows)
    return {"joints": joints, "equations": m, "rank": rank, "redundant": m - rank,
            "mobility": model.nu - rank, "grubler_mobility": model.nu - m,
            "conditioning": conditioning,
            "reactions_not_unique": {
                j: [c for c, ok in zip(REACTION_COMPONENTS, flags) if not ok]
                for j, flags in unique.items() if not flags.all()}}


def info(args):
    scene = load(args, record_warnings=True)      # listed in the report, not on stderr
    d = describe(scene)
    if args.json:
        sys.stdout.write(json.dumps(d) + "\n")
        return 0
    w = sys.stdout.write
    for section in (_model, _urdf, _bodies, _joints, _loops, _states, _loads, _run_settings,
                    _outputs):
        section(d, w)
    return 0


def _model(d, w):
    """The model, its file and description, its cases, parameters and gravity."""
    w(f"model        {d['model']}  ({d['file']})\n")
    if d["description"]:
        w(f"             {d['description']}\n")
    if d["cases"]:
        w(f"case         {d['case'] or '(none)'}   (cases: {', '.join(d['cases'])}"
          f"{'; default ' + d['default_case'] if d['default_case'] else ''})\n")
    if d["parameters"]:
        w("parameters   " + ", ".join(f"{k} = {fmt(v)}" for k, v in d["parameters"].items())
          + "\n")
    w(f"gravity      {_text(d['gravity'])}\n")


def _urdf(d, w):
    """What a URDF robot held beyond bodies and joints: massless links, limits, stops,
    dampers, friction, mimics, transmissions, renamed coordinates, tags not used."""
    u = d.get("urdf")
    if not u:
        return
    base = {"world": "the root link 'world' is the ground",
            "fixed": "base fixed to the ground (joint 'root')",
            "floating": "base floating (free joint 'root')"}[u["base"]]
    w(f"urdf         {u['file']}: robot {u['robot']}, root link {u['root']}; {base}\n")
    if u["massless"]:
        w(f"  massless links (no <inertial>): {', '.join(u['massless'])}\n")
    for j in u["joints"]:
        parts = [f"{k} {_text(v)}" for k, v in j.get("limit", {}).items()]
        parts += [f"{k} {_text(v)}" for k, v in j.get("dynamics", {}).items()]
        if "mimic" in j:
            m = j["mimic"]
            parts.append(f"mimics {m['joint']} (x {fmt(m.get('multiplier', 1.0))} + "
                         f"{fmt(m.get('offset', 0.0))})")
        if parts:
            w(f"  {j['name']:<14} {j['type']}: {', '.join(parts)}\n")
    for name, st in u["stops"].items():
        w(f"  stop {name}: {st['joint']} in [{fmt(st['lower'])}, {fmt(st['upper'])}], "
          f"stiffness {fmt(st['stiffness'])}, damping {fmt(st['damping'])}"
          f"{'' if d['effects'].get(name, True) else '  [off]'}\n")
    for what, names in u["effects"].items():
        if what != "limit":
            w(f"  {what}: {', '.join(names)}\n")
    for t in u["transmissions"]:
        acts = ", ".join(f"{a['name']}" + (f" (reduction {a['reduction']})" if a["reduction"]
                                           else "") for a in t["actuators"])
        w(f"  transmission {t['name']} ({t['type'] or 'no type'}): joints "
          f"{', '.join(j['name'] for j in t['joints']) or '(none)'}; actuators "
          f"{acts or '(none)'} -- read, not modelled\n")
    if u["renamed"]:
        w("  coordinates renamed: " + ", ".join(f"{a} -> {b}" for a, b in u["renamed"].items())
          + "\n")
    if u["not_used"]:
        w("  not used: " + ", ".join(f"<{k}> ({n})" for k, n in u["not_used"].items()) + "\n")


def _bodies(d, w):
    w(f"bodies ({len(d['bodies'])})\n")
    for b in d["bodies"]:
        if b["massless"]:
            w(f"  {b['name']:<14} massless frame\n")
            continue
        I = np.array(b["inertia"])      # noqa: E741  (the inertia tensor's usual name)
        inertia = (f"diag{_text(np.diag(I).tolist())}" if not np.any(I - np.diag(np.diag(I)))
                   else _text(I.tolist()))
        w(f"  {b['name']:<14} mass {fmt(b['mass'])}, com {_text(b['com'])}, "
          f"inertia about com {inertia}\n")


def _joints(d, w):
    w(f"joints ({len(d['joints'])})\n")
    for j in d["joints"]:
        extra = ""
        if "axis" in j:
            extra += f" axis {_text(j['axis'])}"
        if "sequence" in j:
            extra += f" {j['sequence']}"
        if "position" in j:
            extra += f" at {_text(j['position'])}"
        if "orientation" in j:
            extra += f", turned by quaternion {_text(j['orientation'])}"
        what = (f"driven: {j['coordinates'][0]} = {j['drive']}" if j["driven"]
                else ("coordinates " + ", ".join(j["coordinates"]) if j["coordinates"]
                      else "no coordinates"))
        w(f"  {j['name']:<14} {j['kind']}{extra}, {j['parent']} -> {j['child']}; {what}\n")


def _loops(d, w):
    """Loop joints, equations, rank (numerical, at the initial state), mobility."""
    lp = d["loops"]
    if not lp:
        return
    w(f"loops ({len(lp['joints'])} loop joints)\n")
    for j in lp["joints"]:
        if j["kind"] == "coupling":
            w(f"  {j['name']:<14} coupling: {j['follower']} = {fmt(j['ratio'])} * "
              f"{j['leader']} + {fmt(j['offset'])}; 1 equation\n")
            continue
        extra = f" length {fmt(j['length'])}" if "length" in j else ""
        w(f"  {j['name']:<14} {j['kind']}{extra}, {j['parent']} at {_text(j['position'])} "
          f"-> {j['child']} at {_text(j['child_position'])}; {j['equations']} equations; "
          f"closes {' - '.join(j['loop'])}\n")
    w(f"  constraint equations {lp['equations']}, rank {lp['rank']} "
      f"({lp['redundant']} redundant; rank from the singular values of G above 1e-9 of the "
      f"largest), mobility {lp['mobility']} degree(s) of freedom (Gruebler's count: "
      f"{lp['grubler_mobility']})\n")
    if lp["reactions_not_unique"]:
        w("  reactions not unique (minimum-norm values reported): "
          + "; ".join(f"{j} {', '.join(c)}" for j, c in lp["reactions_not_unique"].items())
          + "\n")


def _states(d, w):
    """Coordinates, speeds, degrees of freedom and drives."""
    w(f"coordinates  {', '.join(d['coordinates']) or '(none)'}\n")
    w(f"speeds       {', '.join(d['speeds']) or '(none)'}\n")
    if d.get("loops"):
        w(f"degrees of freedom  {d['loops']['mobility']} ({d['dof']} free speeds, less the "
          f"rank {d['loops']['rank']} of the loop constraints)\n")
    else:
        w(f"degrees of freedom  {d['dof']}\n")
    w("drives       " + ("; ".join(f"{x['joint']}: {x['coordinate']} = {x['expression']}"
                                   for x in d["drives"]) or "none") + "\n")


def _loads(d, w):
    """Point loads, force elements and the effects switched on or off."""
    w(f"loads ({len(d['loads'])})\n")
    for ld in d["loads"]:
        parts = [f"{k} {_text(ld[k])}" for k in ("force", "moment") if ld[k] is not None]
        w(f"  {ld['name']:<14} on {ld['body']}: {', '.join(parts)} ({ld['frame']} axes)\n")
    w(f"forces ({len(d['forces'])})\n")
    for fe in d["forces"]:
        w(f"  {fe['name']:<14} {fe['kind']}: {fe['description']}"
          f"{'' if fe['on'] else '  [off]'}\n")
    w("effects      " + ", ".join(f"{k} {'on' if on else 'OFF'}"
                                  for k, on in d["effects"].items()) + "\n")


def _run_settings(d, w):
    """Events, the initial state and the simulation settings."""
    w(f"events ({len(d['events'])})\n")
    for e in d["events"]:
        w(f"  {e['name']:<14} {e['condition']}  ({e['direction']}"
          f"{', terminal' if e['terminal'] else ''})\n")
    w("initial      " + (", ".join(f"{k} = {fmt(v)}" for k, v in d["initial"].items())
                         or "(none)") + "\n")
    s = d["simulation"]
    w("simulation   " + ", ".join(f"{k} = {fmt(v) if not isinstance(v, str) else v}"
                                  for k, v in s.items() if v is not None) + "\n")
    r = d.get("route")
    if r:
        w(f"route        {r['route']}" + (" (method auto)" if r["method"] == "auto" else "")
          + f": {r['solves']}\n")


def _outputs(d, w):
    """The outputs the file asks for, and the validation warnings."""
    o = d["outputs"]
    outs = []
    if o["reactions"]:
        outs.append(f"reactions of {', '.join(o['reactions'])} ({o['reactions_frame']} axes)")
    if o["energy"]:
        outs.append("energy")
    if o["points"]:
        outs.append("points " + ", ".join(o["points"]))
    w("outputs      " + ("; ".join(outs) or "state only") + "\n")
    w(f"warnings ({len(d['warnings'])})\n")
    for text in d["warnings"]:
        w(f"  - {text}\n")
