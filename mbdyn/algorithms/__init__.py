"""The numeric algorithms on a compiled model, one job a module, as functions of the
``Model`` (whose methods they are: ``Model.mass_matrix`` is ``jourdain.mass_matrix``):

* ``inputs``: the state and inputs an evaluation starts from; what made a result non-finite
* ``kinematics``: motion of every frame, Jacobians of rotation and translation, ``q' = N(q) u``
* ``jourdain``: the mass matrix and forcing of ``M u' = f``
* ``forward_dynamics``: ``u'`` by each route, and which route ``"auto"`` takes
* ``newton_euler``: the Newton-Euler system with reaction unknowns
* ``reactions``: joint reactions, inverse dynamics, drive efforts
* ``energy``: energies, momentum, powers
* ``diagnosis``: singular and ill-conditioned configurations, named

They read and write the model's arrays (``compiled.layout``) and call the numba kernels
(``mbdyn.kernels``); they never import the ``Model`` class.
"""
