"""Runs of models with contacts between shapes: events at a contact's onset and release
(``contact_event``), and the step-size hint for adaptive integrators (``warn_contact_step``).
"""
from __future__ import annotations

import warnings

import numpy as np

from ..algorithms.contacts import impact_durations
from ..errors import ModelWarning
from .events import Event
from .settings import ADAPTIVE

#: steps per impact the hint asks an adaptive integrator for
STEPS_PER_IMPACT = 10


def contact_event(model, which, name=None, terminal=False, direction=-1):
    """An ``Event`` on the signed gap of a contact (``Model.contact_gap``): ``which`` a
    contact element's name or two shape names; ``direction`` -1 (the default) fires at the
    onset (the gap falls through zero), +1 at the release, 0 at both.  ``name`` defaults to
    ``"contact"`` and the names joined by ``-``."""
    model.contact_gap(which, model.default_coordinates())     # refuse an unknown contact now
    label = name or "contact-" + (which if isinstance(which, str) else "-".join(which))
    return Event(label, ContactGap(model, which), terminal, direction)


class ContactGap:
    """``g(t, q, u)``: the signed gap of a contact (``Model.contact_gap``), an event's
    condition."""

    def __init__(self, model, which):
        self.model, self.which = model, which

    def __call__(self, t, q, u):
        return self.model.contact_gap(self.which, q, t)

    def __repr__(self):
        return f"<gap of contact {self.which!r}>"


def warn_contact_step(model, integrator, max_step, stacklevel=3):
    """Warn when a run of a model with contacts between shapes uses an adaptive
    ``integrator`` without ``max_step``: its first trial steps may jump through an impact.
    The hint: a tenth of the shortest impact (``algorithms.contacts.impact_durations``)."""
    if (integrator not in ADAPTIVE or np.isfinite(max_step)
            or not any(el.kind == "shape-contact" for el in model._force_elements)):
        return
    found = impact_durations(model)
    if not found:
        return
    name, duration, mass = min(found, key=lambda x: x[1])
    warnings.warn(f"contact {name!r}: an impact at its impact_speed lasts about "
                  f"{duration:.2g} s (stiffness {model.force_element(name).params['stiffness']:g}"
                  f", mass {mass:.3g} kg); an adaptive integrator without max_step may step "
                  f"over its onset -- give max_step <= {duration / STEPS_PER_IMPACT:.2g} "
                  "(docs/contact.md)", ModelWarning, stacklevel=stacklevel)
