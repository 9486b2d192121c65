"""Analyses built on the model and on simulation: accuracy-versus-cost studies; equilibria,
linearisation, modes and Campbell diagrams (the textbook's vibration analysis)."""
from .accuracy import Study, accuracy_study
from .campbell import Campbell, campbell
from .equilibrium import Equilibrium, EquilibriumError, equilibrium
from .linearize import Linearization, linearize
from .modes import Mode, Modes, modes

__all__ = ["Study", "accuracy_study", "equilibrium", "Equilibrium", "EquilibriumError",
           "linearize", "Linearization", "modes", "Modes", "Mode", "campbell", "Campbell"]
