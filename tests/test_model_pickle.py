"""A compiled model pickles as what it was compiled from and is compiled again when
unpickled (``Model.__reduce__``): its arrays are views of two buffers whose addresses its
kernels hold, and the address of its force elements' compiled function; a copy of its
attributes kept none of them, and its first evaluation in another process crashed it."""
import pickle
import subprocess
import sys
import warnings
from pathlib import Path

import numpy as np
import pytest

import mbdyn as mb

MODELS = Path(__file__).resolve().parent.parent / "models"
CHILD = """
import pickle, sys
import numpy as np
model = pickle.loads(sys.stdin.buffer.read())
q = model.default_coordinates() + 0.05
u = np.linspace(-0.3, 0.4, model.nu)
sys.stdout.write(repr(model.forward_dynamics(q, u).tolist()))
"""


def _model(name):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return mb.load_model(MODELS / name).model


@pytest.mark.parametrize("name", ["mass_spring_damper.toml", "slider_crank.toml",
                                  "pd_arm.toml", "double_pendulum.toml"])
def test_unpickled_in_another_process_evaluates_as_the_original(name):
    model = _model(name)
    q = model.default_coordinates() + 0.05
    u = np.linspace(-0.3, 0.4, model.nu)
    expected = model.forward_dynamics(q, u)        # its fast calls frozen: still pickles
    child = subprocess.run([sys.executable, "-c", CHILD], input=pickle.dumps(model),
                           capture_output=True, timeout=600)
    assert child.returncode == 0, child.stderr.decode()[-2000:]
    assert np.array_equal(np.array(eval(child.stdout.decode())), expected)  # noqa: S307


def test_unpickled_model_keeps_what_compile_added():
    model = _model("slider_crank.toml")
    copy = pickle.loads(pickle.dumps(model))
    assert copy is not model and copy.loops == model.loops
    assert copy.coordinates == model.coordinates and copy.forces == model.forces
