"""What a run watches beside the integration: Euler-angle joints approaching their
singularity (a warning near it, a stop at it), the conditioning of the mass matrix, and
the messages of a failed step (the time and the last good state).
"""
from __future__ import annotations

import warnings

import numpy as np

from ..algorithms.inputs import force_element_blame
from ..errors import (NonFiniteError, SingularityWarning, SingularMassMatrixError)


CONDITION_WARNING = 1e10      # warn when cond(M) exceeds this: ~10 digits are at stake


SINGULARITY_WARNING = 1e-2    # warn when an Euler joint comes this close to its singularity


class Monitor:
    """Watches accepted steps for Euler-angle joints approaching their singularity.

    Warns once per joint below ``SINGULARITY_WARNING``; stops the run (a failure message)
    below ``threshold`` or when a step crosses the singular configuration, before the angle
    rates blow up.
    """

    def __init__(self, model, threshold):
        self.model = model
        self.threshold = threshold
        self.warned = set()
        self.closest = {}
        self.last = {}

    def check_rows(self, ts, ys):
        """``check`` over the rows of a stretch of accepted steps, vectorized: returns
        ``(n, failure)`` -- the rows before the first failing one and the failure message
        (``None`` if every row is fine)."""
        if not self.model._euler_middle or not len(ts):
            return len(ts), None
        first_bad = len(ts)
        for joint, k, proper in self.model._euler_middle:
            signed = np.sin(ys[:, k]) if proper else np.cos(ys[:, k])
            previous = self.last.get(joint)
            before = np.concatenate([[previous[1] if previous else signed[0]], signed[:-1]])
            bad = np.flatnonzero((np.abs(signed) < self.threshold) | (before * signed < 0))
            if bad.size:
                first_bad = min(first_bad, int(bad[0]))
        # the rows up to the first failing one, through the one-row check (messages,
        # warnings and the closest approach exactly as step by step)
        if first_bad == len(ts):
            for joint, k, proper in self.model._euler_middle:
                signed = np.sin(ys[:, k]) if proper else np.cos(ys[:, k])
                dist = np.abs(signed)
                near = np.flatnonzero(dist < SINGULARITY_WARNING)
                if near.size and joint not in self.warned:
                    self.check(ts[near[0]], ys[near[0]])
                self.closest[joint] = min(self.closest.get(joint, np.inf), float(dist.min()))
                self.last[joint] = (ts[-1], signed[-1])
            return len(ts), None
        for i in range(first_bad + 1):
            failure = self.check(ts[i], ys[i])
            if failure:
                return i, failure
        return first_bad + 1, None          # not reached: row first_bad fails

    def check(self, t, y):
        if not self.model._euler_middle:
            return None
        for joint, k, proper in self.model._euler_middle:
            signed = np.sin(y[k]) if proper else np.cos(y[k])
            dist = abs(signed)
            previous = self.last.get(joint)
            self.last[joint] = (t, signed)
            self.closest[joint] = min(self.closest.get(joint, np.inf), dist)
            crossed = previous is not None and previous[1] * signed < 0
            if dist < self.threshold or crossed:
                where = (f"between t={previous[0]:.6g} and t={t:.6g}" if crossed
                         else f"at t={t:.6g} (distance {dist:.3g} < {self.threshold:g})")
                return (f"joint {joint!r}: its Euler angles reached their singular "
                        f"configuration {where}, where the angle rates are undefined and the "
                        "equations of motion singular.  Model the joint as 'spherical' (unit "
                        "quaternion), which has no singularity, or choose an Euler sequence "
                        "whose singularity the motion avoids")
            if dist < SINGULARITY_WARNING and joint not in self.warned:
                self.warned.add(joint)
                warnings.warn(f"joint {joint!r}: the Euler angles come close to their "
                              f"singularity at t={t:.6g} (distance {dist:.3g}); accuracy and step "
                              "size suffer -- a spherical (quaternion) joint avoids this",
                              SingularityWarning, stacklevel=4)
        return None


def conditioning(model, q, t, stats, key, stacklevel=3):
    """``stats[key]``: the condition number of ``M`` at ``q`` (``None`` where too large a
    model makes it cost more than the run); a ``SingularityWarning`` when it is large."""
    cond, weak = model.mass_matrix_condition(q, t)
    stats[key] = cond
    if cond is not None and cond > CONDITION_WARNING:
        warnings.warn(f"model {model.name!r} at t={t:.6g}: the mass matrix is nearly singular "
                      f"(condition number {cond:.3g}; about {np.log10(cond):.0f} of 16 digits "
                      f"are lost); speeds {', '.join(weak)} carry almost no inertia.  Check "
                      "the masses and inertias they move, or remove those degrees of freedom",
                      SingularityWarning, stacklevel=stacklevel)


def describe_failure(model, exc, t, y):
    """The message of a failed step: the error, where it stopped, the last good state, and
    for a non-finite result the force element that gives a huge force there, if one does."""
    names = model.coordinates + model.speeds
    state = ", ".join(f"{n}={v:.6g}" for n, v in zip(names, y))
    blame = ""
    if isinstance(exc, NonFiniteError) and "force element" not in str(exc):
        found = force_element_blame(model, y[:model.nq], y[model.nq:], t)
        blame = f"; {found}" if found else ""
    return f"{exc} (integration stopped at t={t:.6g}; last good state: {state}){blame}"


LOOP_STATUS = {
    1: lambda m: NonFiniteError("NaN or Inf appeared in the state or the accelerations"),
    2: lambda m: SingularMassMatrixError("the mass matrix is not positive definite"),
    3: lambda m: NonFiniteError("the implicit midpoint's Newton iteration did not converge; "
                                "reduce dt"),
    5: lambda m: NonFiniteError("the state could not be projected back onto the loop "
                                "constraints (the mechanism may be passing a singular "
                                "configuration, or the step is too large): reduce dt or the "
                                "tolerances"),
}
