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

    Unknown names are an error that lists the known ones, and so is a specification that
    switches one name both on and off (``off = ["gravity"]`` with ``on = ["gravity"]`` or
    ``gravity = true``; ``"-damper,+damper"``): which one was meant cannot be told.
    """
    at = f"{where}: " if where else ""
    try:
        names = tuple(known) if not isinstance(known, str) else None
    except TypeError:
        names = None
    if names is None or not all(isinstance(n, str) for n in names):
        raise ModelError(f"{at}known must be a list of effect names, got {known!r}")
    known = names
    if base is not None and not isinstance(base, dict):
        raise ModelError(f"{at}base must be a mapping {{name: on}}, got {base!r}")
    state = {name: True for name in known} if base is None else dict(base)
    if spec is not None and not isinstance(spec, (str, dict, list, tuple, set)):
        raise ModelError(f"{at}give effects as \"-gravity,-damper\", a list of such "
                         f"names or a mapping {{name: on}}, not {spec!r}")
    if spec is None:
        return state
    switched = {}                       # name -> (on, how this specification said it)

    def set_(name, on, how):
        if not isinstance(name, str) or name not in state:
            raise ModelError(f"{at}unknown effect {name!r}; the scene's effects are "
                             f"{', '.join(known)}")
        if name in switched and switched[name][0] != bool(on):
            said = dict((switched[name], (bool(on), how)))
            raise ModelError(f"{at}effect {name!r} is switched both on ({said[True]}) "
                             f"and off ({said[False]}); keep one of the two")
        switched[name] = (bool(on), how)
        state[name] = bool(on)

    if isinstance(spec, dict):
        for key, value in spec.items():
            if key in ("off", "on"):
                if isinstance(value, str):
                    value = [value]
                if not isinstance(value, (list, tuple, set)):
                    raise ModelError(f"{at}{key} = {value!r}: give a list of effect "
                                     f"names, e.g. {key} = [\"gravity\"]")
                for name in value:
                    set_(name, key == "on", f"{key} = [{name!r}]")
            elif isinstance(value, bool):
                set_(key, value, f"{key} = {str(value).lower()}")
            else:
                raise ModelError(f"{at}{key} = {value!r}: give true or false (or lists "
                                 "under `off` / `on`)")
        return state
    items = spec.split(",") if isinstance(spec, str) else list(spec)
    for item in items:
        if not isinstance(item, str):
            raise ModelError(f"{at}{item!r} is not an effect name")
        item = item.strip()
        if not item:
            continue
        if item[0] in "+-":
            set_(item[1:].strip(), item[0] == "+", item)
        else:
            set_(item, True, item)
    return state


def warn_if_unphysical(state, name):
    if not state.get("gyroscopic", True):
        warnings.warn(f"model {name!r}: the gyroscopic effect is off -- the velocity-product "
                      "inertia terms (w x I w, Coriolis, centrifugal) are dropped, so the "
                      "motion is no longer physical; use it only for comparison",
                      ModelWarning, stacklevel=3)
