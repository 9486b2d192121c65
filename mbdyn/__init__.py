"""mbdyn -- multibody dynamics after *Dynamics of Machines II* (DTU).

Assemble bodies, frames and joints into a tree (``System``), compile it to a ``Model``,
evaluate kinematics, Jacobians, the Newton-Euler-Jourdain form ``M(q) u' = f`` or the
Newton-Euler system with reactions, and integrate with ``simulate``.

``import mbdyn`` is cheap: it neither imports numpy, numba, scipy or sympy nor compiles
anything.  Each public name is imported from its module on first use (PEP 562), so
``mb.System``, ``mb.derive`` or ``mb.viz`` load only what they need.
"""
import importlib

__version__ = "0.1.0"

#: public name -> the module that defines it (relative to this package)
_PUBLIC = {
    "System": ".assembly.system", "GROUND": ".assembly.system",
    "Model": ".compiled.model", "Kinematics": ".algorithms.kinematics",
    "Result": ".integrate.result", "Event": ".integrate.events",
    "contact_event": ".integrate.contacts",
    "simulate": ".integrate.simulation", "INTEGRATORS": ".integrate.settings",
    "FIXED_STEP": ".integrate.settings",
    "t": ".elements.values", "deg": ".elements.values",
    "ModelError": ".errors", "ModelWarning": ".errors", "NonFiniteError": ".errors",
    "SimulationError": ".errors", "SingularityWarning": ".errors",
    "SingularMassMatrixError": ".errors",
    "load_model": ".io", "Scene": ".io", "ModelFileError": ".io",
    "derive": ".symbolic",
    "equilibrium": ".analysis", "linearize": ".analysis", "modes": ".analysis",
    "campbell": ".analysis", "Equilibrium": ".analysis", "EquilibriumError": ".analysis",
    "Linearization": ".analysis", "Modes": ".analysis", "Campbell": ".analysis",
    "sweep": ".analysis.sweep", "SweepResult": ".analysis.sweep",
}
__all__ = ["System", "Model", "Kinematics", "Result", "Event", "simulate", "inertia", "t", "deg",
           "GROUND", "INTEGRATORS", "FIXED_STEP", "ModelError", "ModelWarning",
           "NonFiniteError", "SimulationError", "SingularityWarning",
           "SingularMassMatrixError", "load_model", "Scene", "ModelFileError", "derive",
           "forces", "effects", "rotations", "equilibrium", "linearize", "modes", "campbell",
           "Equilibrium", "EquilibriumError", "Linearization", "Modes", "Campbell",
           "sweep", "SweepResult", "contact_event"]


#: public modules that live deeper in the package -> their module
_MODULES = {"inertia": ".elements.inertia", "forces": ".elements.forces",
            "effects": ".elements.effects", "rotations": ".elements.rotations"}


def __getattr__(name):
    """Import a public name (or a submodule such as ``viz``) on first use."""
    if name in _PUBLIC:
        value = getattr(importlib.import_module(_PUBLIC[name], __name__), name)
    elif name in _MODULES:
        value = importlib.import_module(_MODULES[name], __name__)
    else:
        try:
            value = importlib.import_module(f".{name}", __name__)
        except ModuleNotFoundError as exc:
            if exc.name != f"{__name__}.{name}":
                raise
            raise AttributeError(f"module {__name__!r} has no attribute {name!r}") from None
    globals()[name] = value
    return value


def __dir__():
    return sorted(set(globals()) | set(__all__))

