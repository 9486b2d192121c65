"""Time integration: ``simulate`` and its ``Result``, the integrator families behind one
interface (``plan``), events, budgets, the singularity monitor, the energy balance.

| module | job |
|---|---|
| ``simulation`` | ``simulate()``: checks the request, builds the ``Plan``, picks the route |
| ``plan`` | ``Plan`` in, ``Outcome`` out: the interface of every route; the right-hand side |
| ``scipy_solvers`` | scipy's ``OdeSolver`` classes stepped from Python |
| ``compiled_adaptive`` | RK45 and DOP853 in compiled stretches of steps |
| ``fixed_step``, ``python_steps``, ``samples`` | the fixed-step schemes, compiled or in Python |
| ``events``, ``event_search`` | ``Event``, its conditions, their crossings |
| ``budget``, ``monitor`` | steps, samples, time; singularities and conditioning |
| ``result``, ``balance``, ``settings`` | ``Result``; the energy balance; names and defaults |
"""
from .events import Event
from .result import Result
from .settings import DEFAULTS, FIXED_STEP, INTEGRATORS
from .simulation import simulate

__all__ = ["simulate", "Result", "Event", "DEFAULTS", "INTEGRATORS", "FIXED_STEP"]
