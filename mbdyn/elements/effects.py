"""Effects: every contribution to the equations of motion has a name a scene can switch.

``gravity``, ``gyroscopic`` (the velocity-product inertia terms: ``w x I w`` and the
Coriolis and centrifugal accelerations), each load and each force element by its name.
A compiled model holds only what is on; an effect off is the same as the element deleted.
"""
from __future__ import annotations

import warnings

from ..errors import ModelError, ModelWarning

GLOBAL = ("gravity", "gyroscopic")


def parse_effects(spec, known, where="effects", base=None):
    """``{name: on}`` for every name in ``known`` from a specification, starting from
    ``base`` (default: everything on):

    * ``None``: everything on;
    * a mapping ``{"gravity": False, "off": [...], "on": [...]}``;
    * a string ``"-gravity,-bearing_left"`` (``+name`` or ``name`` switches on);
    * a sequence of such strings.

    Unknown names are an error that lists the known ones.
    """
    state = {name: True for name in known} if base is None else dict(base)
    if spec is not None and not isinstance(spec, (str, dict, list, tuple, set)):
        raise ModelError(f"{where}: give effects as \"-gravity,-damper\", a list of such "
                         f"names or a mapping {{name: on}}, not {spec!r}")
    if spec is None:
        return state

    def set_(name, on):
        if not isinstance(name, str) or name not in state:
            raise ModelError(f"{where}: unknown effect {name!r}; the scene's effects are "
                             f"{', '.join(known)}")
        state[name] = bool(on)

    if isinstance(spec, dict):
        for key, value in spec.items():
            if key in ("off", "on"):
                names = [value] if isinstance(value, str) else list(value)
                for name in names:
                    set_(name, key == "on")
            elif isinstance(value, bool):
                set_(key, value)
            else:
                raise ModelError(f"{where}: {key} = {value!r}: give true or false (or lists "
                                 "under `off` / `on`)")
        return state
    items = spec.split(",") if isinstance(spec, str) else list(spec)
    for item in items:
        if not isinstance(item, str):
            raise ModelError(f"{where}: {item!r} is not an effect name")
        item = item.strip()
        if not item:
            continue
        if item[0] in "+-":
            set_(item[1:].strip(), item[0] == "+")
        else:
            set_(item, True)
    return state


def warn_if_unphysical(state, name):
    if not state.get("gyroscopic", True):
        warnings.warn(f"model {name!r}: the gyroscopic effect is off -- the velocity-product "
                      "inertia terms (w x I w, Coriolis, centrifugal) are dropped, so the "
                      "motion is no longer physical; use it only for comparison",
                      ModelWarning, stacklevel=3)
