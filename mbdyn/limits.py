"""The resource policy: every bound mbdyn puts on what an input may cost.

A model file, an expression or a run that would exceed one of these is refused (or
stopped) with a message that names the limit, the value that hit it and how to raise it
where it can be raised.  ``docs/reliability.md`` lists them with their reasons.

Limits on *inputs* (file size, nesting, expression size) are fixed: a model that needs
more is better written differently.  Limits on *work* (stored samples, integrator steps,
wall-clock time) are defaults a user raises per run: ``simulate(max_samples=...,
max_steps=..., max_wall_time=...)``, the same keys in ``[simulation]``, or
``mbdyn run --max-samples/--max-steps/--max-wall-time``.
"""
from __future__ import annotations

# -- inputs
#: bytes of one model file (the largest model in models/ is ~4 kB; a generated 5,000-body
#: chain is ~0.7 MB); raised for a run by the environment variable MBDYN_MAX_FILE_BYTES
MAX_FILE_BYTES = 1_000_000
#: the most MBDYN_MAX_FILE_BYTES may ask for
MAX_FILE_BYTES_SETTABLE = 1_000_000_000
#: nesting of arrays and tables in a model file (the deepest legitimate use is 3)
MAX_NESTING = 16
#: magnitude of any number written in a model file or given as a value (beyond it,
#: products overflow double precision; no SI quantity of a mechanism comes near)
MAX_MAGNITUDE = 1e100
#: the smallest non-zero magnitude (below it, squares underflow to zero)
MIN_MAGNITUDE = 1e-100
#: decimal digits of an integer literal (a float holds ~17)
MAX_INTEGER_DIGITS = 40
#: characters of one expression, its parse-tree nodes and the depth of its nesting
MAX_EXPRESSION_LENGTH = 2000
MAX_EXPRESSION_NODES = 1000
MAX_EXPRESSION_DEPTH = 60
#: |exponent| of a power
MAX_EXPONENT = 1000
#: magnitude of any constant part of an expression (beyond it, sympy's exact arithmetic
#: on huge numbers costs time and memory without meaning)
MAX_CONSTANT = 1e300
#: terms an expression would have once expanded (the symbolic layer expands)
MAX_EXPANDED_TERMS = 20_000
#: parse-tree nodes of equations of motion written out (``mbdyn eom``; a shared part
#: counted where it occurs): a chain's grow by 2 to 5 per link, and printing takes about
#: 10 us per node -- 2 000 000 is an 11-link planar chain by Jourdain, about 15 s
MAX_EQUATION_NODES = 2_000_000
#: characters of a name (element, coordinate, parameter, case)
MAX_NAME_LENGTH = 100

#: values of one range (START:STOP:N of a sweep axis or of a Campbell diagram)
MAX_RANGE_POINTS = 100_000
#: members of one sweep (the product of its axes, times its cases)
MAX_SWEEP_MEMBERS = 1_000_000
#: bytes of one line of a sweep table read back to resume it (a row of a 10 000-column
#: table is ~250 kB; a longer line is not a table mbdyn wrote)
MAX_TABLE_LINE = 1_000_000

#: bytes of one mesh file a picture reads (a URDF ``<visual>`` mesh; the UR5's largest
#: DAE is ~2 MB, a finely scanned part ~30 MB); a larger one is left out, with a warning
MAX_MESH_FILE_BYTES = 50_000_000
#: triangles of one mesh in the pictures: a finer one is decimated (vertex clustering,
#: ``viz.mesh_files.decimate``); the HTML page carries every mesh once at ~25 bytes a
#: triangle, and matplotlib draws each triangle as a polygon every frame
MAX_MESH_TRIANGLES = 3000


def max_file_bytes():
    """Bytes a model file may have: ``MAX_FILE_BYTES``, or the environment variable
    ``MBDYN_MAX_FILE_BYTES`` (a whole number up to ``MAX_FILE_BYTES_SETTABLE``), read at
    each use so that sweep workers and subprocesses inherit it."""
    import os
    from .errors import ModelError
    text = os.environ.get("MBDYN_MAX_FILE_BYTES")
    if text is None or not text.strip():
        return MAX_FILE_BYTES
    try:
        value = int(text.strip())
    except ValueError:
        value = 0
    if not 1 <= value <= MAX_FILE_BYTES_SETTABLE:
        raise ModelError(f"MBDYN_MAX_FILE_BYTES={text!r}: give a whole number of bytes from 1 "
                         f"to {MAX_FILE_BYTES_SETTABLE}")
    return value


def magnitude_problem(value):
    """Why a number a model gives is outside ``MIN_MAGNITUDE .. MAX_MAGNITUDE`` (``None``
    if it is inside, or zero)."""
    if value != 0 and abs(value) < MIN_MAGNITUDE:
        return (f"{value:g} is below the range mbdyn accepts (0 or |x| >= {MIN_MAGNITUDE:g}; "
                "its square underflows); check the units, or write 0")
    if abs(value) > MAX_MAGNITUDE:
        return (f"{value:g} is beyond the range mbdyn accepts (|x| <= {MAX_MAGNITUDE:g}; "
                "products of such numbers overflow); check the units")
    return None


# -- what a run is worth (``mbdyn.integrate.quality``)
#: a run's energy balance drift (over its energy scale), its quaternions' drift off unit
#: length, or its error estimate (over its coordinate's scale) above this is a warning
#: that names the figure and the remedy (``mbdyn run --warn-threshold``,
#: ``Result.quality(threshold=...)``)
WARN_THRESHOLD = 0.01

# -- work (defaults a user can raise)
#: stored samples of one run (rows of t, q, u); beyond it give output_dt to decimate
MAX_SAMPLES = 2_000_000
#: integrator steps of one run (an adaptive run that, at its pace, could not finish
#: within them stops early: see ``simulate.PROJECTION_STEPS``)
MAX_STEPS = 5_000_000
#: wall-clock seconds of one run (None: no limit)
MAX_WALL_TIME = None
#: seconds of any one wait on a Dask scheduler at an address: the connection and its
#: handshake, a finished member's result, the scheduler's answer to a check while members
#: run (``sweep(scheduler_timeout=...)``, ``mbdyn sweep --scheduler-timeout``)
SCHEDULER_TIMEOUT = 30.0

# -- flexible bodies (mbdyn/flexible; docs/flexible.md)
#: elements of one beam model (its eigenproblems are dense: 1,000 elements are 6,006 DoFs,
#: some 20 s); a reduced body rarely needs more than a few dozen
MAX_BEAM_ELEMENTS = 1000
#: modal coordinates of one reduced body, and nodes of user-supplied reduced data
MAX_MODES = 500
MAX_FLEXIBLE_NODES = 100_000
#: modes of one flexible body the symbolic layer writes in closed form (``mbdyn eom``):
#: each mode adds a row and column of named invariants (J1, J2's pairs, Cr1), and the
#: expressions grow with their products
MAX_SYMBOLIC_MODES = 4
