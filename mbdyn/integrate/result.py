"""``Result``: the time series of a run (``t``, ``q``, ``u``, events, statistics), the outputs
computed along it (reactions, energies, momentum, points), CSV export, pictures.
"""
from __future__ import annotations


import numpy as np

from ..errors import ModelError
from .balance import energy_balance
from .quality import assess
from .settings import OUTPUTS


#: the six components of a reaction, in its columns' order
REACTION_COMPONENTS = ("Fx", "Fy", "Fz", "Mx", "My", "Mz")


class Result:
    """Time series of a simulation.

    ``t`` (n,), ``q`` (n, nq), ``u`` (n, nu); ``res["theta1"]`` gives a coordinate or speed
    by name; ``events`` is ``[(name, t), ...]`` (``EventRecord``s: each also carries the
    state there, ``.q``, ``.u``, ``.state``); ``stats`` the integrator's statistics;
    on request ``reactions`` ``{joint: (n, 6)}`` (force then moment, world components, at
    the joint origin), ``energy`` (see ``mbdyn.integrate.balance.energy_balance``: ``kinetic``,
    ``potential``, ``total`` = T + V, ``dissipated``, ``work``, ``balance``) and ``points``
    ``{name: (n, 3)}``.  With energies, ``stats["energy_drift"]`` is
    ``max |B(t) - B(0)|`` of the balance ``B = T + V + dissipated - work`` over the energy
    scale (the largest of its terms).
    """

    def __init__(self, model, t, q, u, events, stats):
        self.model = model
        self.t = np.asarray(t, dtype=float)
        self.q = np.asarray(q, dtype=float).reshape(len(self.t), model.nq)
        self.u = np.asarray(u, dtype=float).reshape(len(self.t), model.nu)
        self.events = list(events)
        self.stats = dict(stats)
        self.reactions = None
        self.energy = None
        self.points = None
        self.drive_efforts = None
        self.momentum = None

    @property
    def coordinates(self):
        return self.model.coordinates

    @property
    def speeds(self):
        return self.model.speeds

    def __len__(self):
        return len(self.t)

    def to_csv(self, path):
        """Write the results to ``path`` as CSV with named columns (``t``, coordinates,
        speeds, then the energies, reactions, drive efforts and points computed), the same
        columns as ``mbdyn run --out``; written whole or not at all."""
        import io as _io
        import os
        if not isinstance(path, (str, os.PathLike)) or not str(path):
            raise ModelError(f"to_csv: give a file name, got {path!r}")
        names = ["t"] + list(self.coordinates) + list(self.speeds)
        cols = [self.t[:, None], self.q, self.u]
        if self.energy is not None:
            for key, arr in self.energy.items():
                names.append(f"energy_{key}")
                cols.append(np.asarray(arr)[:, None])
        if self.reactions is not None:
            for j, arr in self.reactions.items():
                names += [f"reaction_{j}_{c}" for c in ("Fx", "Fy", "Fz", "Mx", "My", "Mz")]
                cols.append(np.asarray(arr))
        if self.drive_efforts:
            for j, arr in self.drive_efforts.items():
                names.append(f"effort_{j}")
                cols.append(np.asarray(arr)[:, None])
        if self.points:
            for p, arr in self.points.items():
                names += [f"point_{p}_{a}" for a in "xyz"]
                cols.append(np.asarray(arr))
        table = np.hstack([np.asarray(c, float).reshape(len(self.t), -1) for c in cols])
        import csv

        from .. import files
        from ..escape import spreadsheet_cell
        buf = _io.StringIO()
        csv.writer(buf, lineterminator="\n").writerow([spreadsheet_cell(n) for n in names])
        np.savetxt(buf, table, delimiter=",", fmt="%.17g")
        try:
            files.atomic_write(path, buf.getvalue())   # a link is replaced, never written through
        except OSError as exc:
            raise OSError(exc.errno, f"cannot write {path}: {exc.strerror}", str(path)) \
                from None
        return path

    def __getitem__(self, name):
        if name in self.model.coordinates:
            return self.q[:, self.model.coordinate_index(name)]
        if name in self.model.speeds:
            return self.u[:, self.model.speed_index(name)]
        if self.points and name in self.points:
            return self.points[name]
        raise KeyError(f"{name!r} is neither a coordinate ({', '.join(self.coordinates)}) nor a "
                       f"speed ({', '.join(self.speeds)}) of model {self.model.name!r}")

    def quality(self, threshold=None):
        """What the run is worth: its energy balance drift, quaternion drift and error
        estimate (``simulate(error_estimate=True)``), with a warning sentence for each
        above ``threshold`` (default ``mbdyn.limits.WARN_THRESHOLD``); see
        ``mbdyn.integrate.quality.assess``."""
        return assess(self, threshold)

    def plot(self, series=None, phase=None, out=None, title=None):
        """Time series or a phase portrait of this result: see ``mbdyn.viz.plot_result``
        (imported on call, as matplotlib is)."""
        from ..viz import plot_result
        return plot_result(self, series=series, phase=phase, out=out, title=title)

    def animate(self, out, speed=1.0, fps=30.0, title=None, **options):
        """An animation of this result written to ``out``: see ``mbdyn.viz.animate``
        (imported on call)."""
        from ..viz import animate
        return animate(self, out, speed=speed, fps=fps, title=title, **options)

    def __repr__(self):
        return (f"<Result {self.model.name!r}: {len(self.t)} samples, t = {self.t[0]:g} .. "
                f"{self.t[-1]:g}, events {self.events}>")

    def compute_outputs(self, outputs=(), points=None, method="auto", frame="world"):
        """Evaluate reactions (``frame``: ``"world"`` or ``"child"`` components), energies
        and point trajectories along the stored motion."""
        if (isinstance(outputs, str) or not isinstance(outputs, (list, tuple, set))
                or not all(isinstance(o, str) for o in outputs)):
            raise ModelError(f"outputs must be a list of names ({', '.join(OUTPUTS)}), got "
                             f"{outputs!r}")
        if points is not None and not isinstance(points, dict):
            raise ModelError(f"points must be {{name: (frame, offset)}}, got {points!r}")
        model = self.model
        unknown = set(outputs) - set(OUTPUTS)
        if unknown:
            raise ModelError(f"unknown outputs {sorted(unknown)}; choose from {OUTPUTS}")
        n = len(self.t)
        if "reactions" in outputs:
            reac = {j: np.empty((n, 6)) for j in model.reaction_joints}
            efforts = {j: np.empty(n) for j in model.driven_joints}
            for k in range(n):
                r = model.reactions(self.q[k], self.u[k], self.t[k], method=method,
                                    frame=frame)
                for j, (f, m) in r.items():
                    reac[j][k, :3] = f
                    reac[j][k, 3:] = m
                for j, val in model.drive_efforts(self.q[k], self.u[k], self.t[k]).items():
                    efforts[j][k] = val
            self.reactions = reac
            self.drive_efforts = efforts
            if model.has_loops and n:
                unique = model.reaction_uniqueness(self.q[0], self.t[0])
                self.stats["reactions_not_unique"] = {
                    j: [c for c, ok in zip(REACTION_COMPONENTS, flags) if not ok]
                    for j, flags in unique.items() if not flags.all()}
        if "energy" in outputs:
            self.energy = energy_balance(model, self.t, self.q, self.u)
            E = self.energy["balance"]
            scale = max(abs(E[0]), np.abs(self.energy["kinetic"]).max(),
                        np.abs(self.energy["potential"]).max(),
                        np.abs(self.energy["dissipated"]).max(),
                        np.abs(self.energy["work"]).max(), 1e-300)
            self.stats["energy_drift"] = float(np.abs(E - E[0]).max() / scale)
        if "momentum" in outputs:
            lin = np.empty((n, 3))
            ang = np.empty((n, 3))
            for k in range(n):
                lin[k], ang[k] = model.momentum(self.q[k], self.u[k], self.t[k])
            self.momentum = {"linear": lin, "angular": ang}
        if points:
            names = list(points)
            specs = [points[p] for p in names]
            traj = np.array([model.point_positions(self.q[k], specs, self.t[k])
                             for k in range(n)]).reshape(n, len(names), 3)
            self.points = {p: traj[:, k] for k, p in enumerate(names)}
        return self
