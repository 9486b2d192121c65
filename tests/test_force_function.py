"""The force elements reach the kernels through a compiled function's address
(``kernels.force_function``):
a model with force elements and one without pass their loads with the same numba types
(the function's address), so
that the kinematics, the routes, the loops and the adaptive stretches compiled for one
serve the other (before, a first model with force elements compiled them all again)."""
import warnings
from pathlib import Path

import numpy as np
import pytest
from numba import cfunc, njit, typeof

import mbdyn as mb
from mbdyn.kernels import force_function as kff

MODELS = Path(__file__).resolve().parent.parent / "models"


def _model(name):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return mb.load_model(MODELS / name).model


@pytest.mark.parametrize("name, kind", [("mass_spring_damper.toml", kff.PLAIN),
                                        ("quarter_car.toml", kff.PLAIN)])
def test_loads_have_one_type_with_and_without_force_elements(name, kind):
    plain, forced = _model("double_pendulum.toml"), _model(name)
    assert plain._force_int.shape[0] == 0 and forced._force_int.shape[0] > 0
    for attribute in ("_loads_arrays", "_packed", "_dynamics", "_dynamics_full"):
        assert typeof(getattr(plain, attribute)) == typeof(getattr(forced, attribute)), \
            attribute
    assert plain._packed[3][1] == kff.address(kff.NONE) == 0
    assert forced._packed[3][1] == kff.address(kind) != 0
    assert kff.NONE not in kff._MADE


def _failing(force_int, force_data, parent, axis, com, qfull, ufull, R, r, w, v, F, N, acc,
             work):
    """A force function as the module makes them: what the kernel raises becomes FAILED."""
    try:
        F[0, 0] = force_data[0] / force_data[1]
    except Exception:
        return kff.FAILED
    return 0


@njit
def _loads(where, force_int, force_data, parent, axis, com, qfull, ufull, R, r, w, v, F, N,
           acc, work):
    kff.apply_forces(where, force_int, force_data, parent, axis, com, qfull, ufull, R, r, w,
                     v, F, N, acc, work)
    return F[0, 0]


def test_a_force_function_that_fails_raises_in_its_caller():
    """A C function cannot raise (numba's wrapper prints the exception and returns): the
    caller raises ``ZeroDivisionError`` again, which the evaluations report as before."""
    failing = cfunc(kff.SIGNATURE)(_failing)
    arrays = (np.zeros((1, 10), np.int64), np.array([1.0, 0.0]), np.zeros(1, np.int64),
              np.zeros((1, 3)), np.zeros((1, 3)), np.zeros(1), np.zeros(1), np.zeros((1, 3, 3)),
              np.zeros((1, 3)), np.zeros((1, 3)), np.zeros((1, 3)), np.zeros((1, 3)),
              np.zeros((1, 3)), np.zeros(0), np.zeros(10))
    with pytest.raises(ZeroDivisionError, match="force element"):
        _loads(failing.address, *arrays)
    arrays[1][1] = 4.0                              # no division by zero: 1 / 4
    assert _loads(failing.address, *arrays) == 0.25
