"""The states of a committed Pinocchio reference (``tests/data/*_reference.json``) in
mbdyn's order: the reference lists its coordinates and speeds by name."""
import numpy as np


def indices(model, entry):
    """``(qi, ui)``: where each of the reference's coordinates and speeds sits in
    ``model``'s vectors (every one of the model's, once)."""
    qi = [model.coordinates.index(n) for n in entry["coordinates"]]
    ui = [model.speeds.index(n) for n in entry["speeds"]]
    assert sorted(qi) == list(range(model.nq)) and sorted(ui) == list(range(model.nu))
    return qi, ui


def states(model, entry, qi, ui):
    """``(state record, q, u)`` of every state of the reference, in ``model``'s order."""
    for st in entry["states"]:
        q, u = np.zeros(model.nq), np.zeros(model.nu)
        q[qi], u[ui] = st["q"], st["u"]
        yield st, q, u
