"""The parts of a parameter sweep, one job a module; ``mbdyn.analysis.sweep`` runs them
and is the interface (``sweep``, ``SweepResult`` and the names of these modules).

* ``grid``: the members -- grid axes from their texts, grids and lists of overrides;
* ``model_file``: the model file every member runs, read once and loaded per member;
* ``quantities``: what is kept of each member, its columns and its values from a result;
* ``member``: one member run by a worker;
* ``batched``: members that share one compiled model, advanced in one compiled call;
* ``table``: the CSV written as members finish, the values of its cells, Parquet;
* ``resume``: a table read back, every line and row checked;
* ``checks``: what is settled before any member runs (arguments, columns, paths);
* ``progress``: what a running sweep says on stderr.
"""
