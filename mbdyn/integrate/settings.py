"""The integrators by name (scipy's adaptive solvers, the compiled RK45 and DOP853, the
fixed-step schemes), the outputs a run can compute, and the defaults of every run.
"""
from __future__ import annotations

import collections

import scipy                # its submodules load on first use (scipy.integrate: 0.2 s)



class ScipySolvers(collections.abc.Mapping):
    """scipy's ``OdeSolver`` classes by name, ``scipy.integrate`` imported on the first
    look-up of a class (a fixed-step run does not need it).  ``scipy-RK45`` and
    ``scipy-DOP853`` always take scipy's solver; ``RK45`` and ``DOP853`` run compiled
    (``kernels.adaptive``) where the model allows."""
    NAMES = ("RK45", "RK23", "DOP853", "Radau", "BDF", "LSODA", "scipy-RK45", "scipy-DOP853")

    def __getitem__(self, name):
        if name not in self.NAMES:
            raise KeyError(name)
        return getattr(scipy.integrate, name.removeprefix("scipy-"))

    def __iter__(self):
        return iter(self.NAMES)

    def __len__(self):
        return len(self.NAMES)


ADAPTIVE = ScipySolvers()


#: adaptive pairs that also run as compiled stretches (``kernels.adaptive``); their
#: ``scipy-`` names always take scipy's solver
COMPILED_ADAPTIVE = ("RK45", "DOP853")


FIXED_STEP = ("euler", "semi-implicit-euler", "rk4", "implicit-midpoint")


INTEGRATORS = tuple(ADAPTIVE) + FIXED_STEP


OUTPUTS = ("reactions", "energy", "momentum")


#: The defaults of every run -- Python, model files and the command line: DOP853 at
#: rtol 1e-9, atol 1e-12 (docs/accuracy.md says why).
DEFAULTS = {"integrator": "DOP853", "rtol": 1e-9, "atol": 1e-12, "method": "auto"}
