"""The force elements reach the kernels as a first-class function (``kernels.force_function``):
a model with force elements and one without pass their loads with the same numba types
(the function's address), so
that the kinematics, the routes, the loops and the adaptive stretches compiled for one
serve the other (before, a first model with force elements compiled them all again)."""
import warnings
from pathlib import Path

import pytest
from numba import typeof

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

