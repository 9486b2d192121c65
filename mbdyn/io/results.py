"""Results export: the ``--json`` summary, and CSV + JSON metadata files written atomically.

Every file is written through ``mbdyn.files``: to a temporary file in the target directory,
flushed to disk and then renamed over the final name -- an interrupted run never leaves a
half-written file behind (either the old file or the complete new one is there), and a
symbolic link at the final name is replaced, never written through.
"""
from __future__ import annotations

import csv
import datetime
import hashlib
import io
import json
import math
import os
import re

import numpy as np

from .. import files
from ..escape import spreadsheet_cell

AXES = ("x", "y", "z")
WRENCH = ("Fx", "Fy", "Fz", "Mx", "My", "Mz")


def _float(x):
    x = float(x)
    return x if math.isfinite(x) else None


def outputs_spec(scene):
    """The ``[outputs]`` a scene asked for, as plain JSON data."""
    out = scene.outputs
    return {"reactions": list(out["reactions"]), "reactions_frame": out["reactions_frame"],
            "energy": out["energy"],
            "points": {k: {"frame": f, "offset": list(o)} for k, (f, o) in out["points"].items()}}


def summary(scene, result, quality=None):
    """The ``mbdyn run --json`` object (``quality``: ``result.quality()`` unless given)::

        {"model": str, "case": str|null, "t_final": float, "q": {name: float},
         "u": {name: float}, "events": [{"name": str, "t": float}],
         "energy": {"initial": float, "final": float}|null,
         "reactions": {joint: [Fx, Fy, Fz, Mx, My, Mz]}|null,   (at t_final, as requested)
         "drive_efforts": {joint: float}|null, "points": {name: [x, y, z]}|null,
         "stats": {"integrator": str, "method": str, "steps": int,
                   "rhs_evaluations": int, "wall_time_s": float},
         "quality": {"energy_drift": float|null, "quaternion_drift": float|null,
                     "error_estimate": {"against": str, "difference": {name: float},
                                        "relative": float, "worst": str}
                                       |{"against": str|null, "failed": str}|null,
                     "threshold": float, "warnings": [str]},
         "loops": {...}}          (closed mechanisms only: ``loop_summary``)

    ``quality`` is what the run is worth (``mbdyn.integrate.quality.assess``): a figure
    is ``null`` where not available (no energy balance, no quaternion, no estimate asked
    for), and ``warnings`` has a sentence for each above the threshold.
    """
    model = scene.model
    energy = None
    if result.energy is not None and len(result.t):
        total = result.energy["total"]
        energy = {"initial": _float(total[0]), "final": _float(total[-1])}
    st = result.stats
    out = {
        "model": scene.name,
        "case": scene.case,
        "t_final": _float(result.t[-1]),
        "q": {n: _float(v) for n, v in zip(model.coordinates, result.q[-1])},
        "u": {n: _float(v) for n, v in zip(model.speeds, result.u[-1])},
        "events": [{"name": str(n), "t": _float(t)} for n, t in result.events],
        "energy": energy,
        "reactions": ({j: [_float(v) for v in arr[-1]]
                       for j, arr in reaction_series(scene, result).items()}
                      if result.reactions is not None and len(result.t) else None),
        "drive_efforts": ({j: _float(arr[-1]) for j, arr in result.drive_efforts.items()}
                          if result.drive_efforts and len(result.t) else None),
        "points": ({p: [_float(v) for v in arr[-1]] for p, arr in result.points.items()}
                   if result.points and len(result.t) else None),
        "stats": {"integrator": str(st.get("integrator")), "method": str(st.get("method")),
                  "steps": int(st.get("steps", 0)),
                  "rhs_evaluations": int(st.get("rhs_evaluations", 0)),
                  "wall_time_s": _float(st.get("wall_time_s", 0.0))},
        "quality": _jsonable(result.quality() if quality is None else quality),
    }
    if model.has_loops:
        out["loops"] = loop_summary(result)
    return out


def loop_summary(result):
    """What a closed mechanism's run kept: its constraints' drift, their rank and the
    mobility, the reactions that are not unique, a singular configuration passed."""
    st = result.stats
    out = {k: st[k] for k in ("constraint_rank", "mobility", "reactions_not_unique",
                              "singular_configuration") if k in st}
    for k in ("constraint_drift", "constraint_drift_velocity", "constraint_drift_unprojected",
              "constraint_conditioning_min"):
        if k in st:
            out[k] = _float(st[k])
    return out


def reaction_series(scene, result):
    """``{joint: (n, 6)}`` of the requested reactions (``[outputs] reactions``), in world
    components or, with ``reactions_frame = "child"``, in the child frame's components."""
    if result.reactions is None:
        return {}
    wanted = scene.outputs["reactions"]
    out = {j: np.array(result.reactions[j]) for j in wanted if j in result.reactions}
    if scene.outputs["reactions_frame"] == "child" and out:
        model = scene.model
        child = {j: model.frame_index(model.joint(j).child) for j in out
                 if model.joint(j).child != "ground"}
        for k in range(len(result.t)):
            kin = model.kinematics(result.q[k], result.u[k], t=result.t[k])
            for j, arr in out.items():
                if j not in child:          # a loop joint onto the ground: world axes
                    continue
                RT = kin.R[child[j]].T
                arr[k, :3] = RT @ arr[k, :3]
                arr[k, 3:] = RT @ arr[k, 3:]
    return out


def columns(scene, result):
    """``(names, table)``: the named columns of the results CSV."""
    names = ["t"] + list(result.coordinates) + list(result.speeds)
    cols = [result.t[:, None], result.q, result.u]
    if result.energy is not None:
        for key in ("kinetic", "potential", "total", "dissipated", "work", "balance"):
            if key in result.energy:
                names.append(f"energy_{key}")
                cols.append(np.asarray(result.energy[key])[:, None])
    for j, arr in reaction_series(scene, result).items():
        names.extend(f"reaction_{j}_{c}" for c in WRENCH)
        cols.append(arr)
    if result.drive_efforts:
        for j, arr in result.drive_efforts.items():
            names.append(f"effort_{j}")
            cols.append(np.asarray(arr)[:, None])
    if result.points:
        for p, arr in result.points.items():
            names.extend(f"point_{p}_{a}" for a in AXES)
            cols.append(np.asarray(arr))
    return names, np.hstack([np.asarray(c, dtype=float).reshape(len(result.t), -1)
                             for c in cols])


def atomic_write(path, text):
    """Write ``text`` to ``path`` via a temporary file and ``os.replace``: a reader sees
    the old file or the whole new one, never a part; the temporary is removed on any
    error or interruption (SIGINT, and SIGTERM under the ``mbdyn`` command)."""
    files.atomic_write(path, text)


remove_stale_temporaries = files.remove_stale_temporaries

#: a test's hook, called between the CSV's rename and the JSON's (None: nothing)
_between_renames = None


_UNSAFE = re.compile(r"[^A-Za-z0-9_.+-]")


def output_stem(scene):
    """``top_a`` for model file ``top.toml`` and case ``a``; characters other than
    letters, digits and ``_ . + -`` become ``_`` (a case named ``../x`` cannot write
    outside the output directory)."""
    stem = os.path.splitext(os.path.basename(str(scene.path)))[0]
    stem = f"{stem}_{scene.case}" if scene.case else stem
    stem = _UNSAFE.sub("_", stem).lstrip(".") or "results"
    return stem[:120]


def write_results(directory, scene, result, status="ok", error=None, extra=None):
    """Write ``STEM.csv`` (named columns) and ``STEM.json`` (metadata) into ``directory``
    (created if needed); returns the two paths.

    The pair is written as one unit: both are first written whole to temporaries; then
    the old JSON is removed, the CSV renamed into place and the JSON last, with SIGINT
    and SIGTERM held (``files.signals_held``): a Ctrl-C or SIGTERM at any point leaves
    the old pair or the new pair, never a temporary.  Only what cannot be caught (SIGKILL,
    a power cut) can stop between the renames; it leaves a CSV with no JSON, which a
    reader recognises as unfinished.  A JSON beside a CSV always describes it (it records
    the CSV's size, row count and SHA-256: ``verify_results``); the next write removes the
    temporaries of a killed one.
    """
    os.makedirs(directory, exist_ok=True)
    stem = output_stem(scene)
    csv_path = os.path.join(directory, stem + ".csv")
    json_path = os.path.join(directory, stem + ".json")
    remove_stale_temporaries(directory, (stem + ".csv", stem + ".json"))
    names, table = columns(scene, result)
    buf = io.StringIO()
    # the header is the one text row: quoted as CSV needs, no cell a spreadsheet formula
    csv.writer(buf, lineterminator="\n").writerow([spreadsheet_cell(n) for n in names])
    np.savetxt(buf, table, delimiter=",", fmt="%.15g")
    csv_text = buf.getvalue()
    csv_bytes = csv_text.encode("utf-8")
    meta = summary(scene, result)
    meta.update({
        "status": status,
        "error": error,
        "file": os.path.abspath(scene.path),
        "description": scene.description,
        "parameters": scene.parameters,
        "initial": scene.initial_state,
        "simulation": {k: v for k, v in scene.settings.items()},
        "outputs": outputs_spec(scene),
        "warnings": list(scene.warnings),
        "csv": os.path.basename(csv_path),
        "csv_bytes": len(csv_bytes),
        "csv_sha256": hashlib.sha256(csv_bytes).hexdigest(),
        "columns": names,
        "samples": int(len(result.t)),
        "stats_all": {k: _jsonable(v) for k, v in result.stats.items()},
        "created": datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds"),
    })
    if extra:
        meta.update(extra)
    json_text = json.dumps(meta, indent=2, default=_jsonable) + "\n"
    temporaries = []
    try:
        temporaries.append(files.write_temporary(csv_path, csv_text))
        temporaries.append(files.write_temporary(json_path, json_text))
        with files.signals_held():         # a Ctrl-C or SIGTERM acts after both renames
            files.remove(json_path)        # no old JSON may stand beside the new CSV
            files.replace(temporaries[0], csv_path)
            if _between_renames is not None:
                _between_renames()
            files.replace(temporaries[1], json_path)
    except BaseException:
        for tmp in temporaries:
            files.remove(tmp)
        raise
    return csv_path, json_path


def verify_results(json_path):
    """``True`` if the CSV that ``json_path`` names is the one it describes (size and
    SHA-256); a reader's check that the pair is whole."""
    with open(json_path, encoding="utf-8") as fh:
        meta = json.load(fh)
    csv_path = os.path.join(os.path.dirname(os.path.abspath(json_path)), meta["csv"])
    try:
        with open(csv_path, "rb") as fh:
            data = fh.read()
    except OSError:
        return False
    return (len(data) == meta.get("csv_bytes")
            and hashlib.sha256(data).hexdigest() == meta.get("csv_sha256"))


def _jsonable(v):
    if isinstance(v, dict):
        return {str(k): _jsonable(x) for k, x in v.items()}
    if isinstance(v, (list, tuple)):
        return [_jsonable(x) for x in v]
    if isinstance(v, (np.integer,)):
        return int(v)
    if isinstance(v, (float, np.floating)):
        return _float(v)
    if isinstance(v, np.ndarray):
        return _jsonable(v.tolist())
    if v is None or isinstance(v, (str, int, bool)):
        return v
    return str(v)
