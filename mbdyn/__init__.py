"""mbdyn -- multibody dynamics after *Dynamics of Machines II* (DTU).

Assemble bodies, frames and joints into a tree (``System``), compile it to a ``Model``,
evaluate kinematics, Jacobians, the Newton-Euler-Jourdain form ``M(q) u' = f`` or the
Newton-Euler system with reactions, and integrate with ``simulate``.
"""
from . import effects, forces, inertia, rotations
from .compile import Kinematics, Model
from .elements import t
from .errors import (ModelError, ModelWarning, NonFiniteError, SimulationError,
                     SingularityWarning, SingularMassMatrixError)
from .model import GROUND, System
from .simulate import FIXED_STEP, INTEGRATORS, Event, Result, simulate
from .io import ModelFileError, Scene, load_model
from .symbolic import derive
from .analysis import (Campbell, Equilibrium, EquilibriumError, Linearization, Modes,
                       campbell, equilibrium, linearize, modes)
from .analysis.sweep import SweepResult, sweep

from . import viz

#: ``Result.plot(series=None, phase=None, out=None)``: see ``mbdyn.viz.plot_result``
Result.plot = viz.plot_result
#: ``Result.animate(out, speed=1.0, fps=30.0)``: see ``mbdyn.viz.animate``
Result.animate = viz.animate

__version__ = "0.1.0"

__all__ = ["System", "Model", "Kinematics", "Result", "Event", "simulate", "inertia", "t",
           "GROUND", "INTEGRATORS", "FIXED_STEP", "ModelError", "ModelWarning",
           "NonFiniteError", "SimulationError", "SingularityWarning",
           "SingularMassMatrixError", "load_model", "Scene", "ModelFileError", "derive",
           "forces", "effects", "rotations", "equilibrium", "linearize", "modes", "campbell",
           "Equilibrium", "EquilibriumError", "Linearization", "Modes", "Campbell",
           "sweep", "SweepResult"]
