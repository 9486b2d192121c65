"""The ``mbdyn`` command: ``mbdyn run MODEL ...``, ``mbdyn info MODEL ...``.

Each command is a submodule ``mbdyn.cli.NAME`` listed in ``COMMANDS`` with a
``register(subparsers)`` function that adds its parser and sets ``func`` (called with the
parsed arguments, returns the exit code); ``common.add_command`` makes that parser.  To add a command, write the module and append
its name to ``COMMANDS`` and its one-line help to ``SUMMARIES``.  Only the module of the
command that runs is imported.  A command that will compile numeric kernels says so on
stderr first, within a second of its start (``compiling``).

Exit codes: 0 success; 1 a model file or input that cannot be used (one-line message on
stderr); 2 a bad command line; 3 a simulation that failed (NaN, singularity, integrator
failure, a budget reached); 130 interrupted (SIGINT), 143 terminated (SIGTERM) -- either
way no temporary or torn result file is left; 141 the reader of stdout went away (no
message).  70 is an internal error: a bug, to be reported.  No traceback unless
``MBDYN_DEBUG=1``.
"""
from __future__ import annotations

import argparse
import importlib
import os
import signal
import sys
import warnings

COMMANDS = ["run", "info", "eom", "accuracy", "equilibrium", "modes", "campbell", "plot",
            "animate", "sweep", "warmup"]
#: each command's one-line help, for ``mbdyn --help``: the parser lists every command from
#: here and imports only the module of the command that runs (importing all of them would
#: load sympy's printers, scipy and the analysis layer for any command)
SUMMARIES = {
    "run": "simulate a model file",
    "info": "describe a model file",
    "eom": "equations of motion in closed form",
    "accuracy": "work-precision study: error, energy drift and cost of integrators",
    "equilibrium": "static or steady equilibrium by Newton-Raphson",
    "modes": "natural frequencies, damping ratios and mode shapes",
    "campbell": "Campbell diagram: modes against a parameter (spin speed)",
    "plot": "plot a run's time series or a phase portrait",
    "animate": "animate a run: GIF, MP4 or a self-contained HTML view",
    "sweep": "run a model file over a grid of overrides (parameters, initial state, "
             "settings); one table row per member",
    "warmup": "compile the numeric kernels ahead of time (once per machine)",
}

EXIT_OK, EXIT_INPUT, EXIT_USAGE, EXIT_SIMULATION, EXIT_INTERRUPTED = 0, 1, 2, 3, 130
EXIT_TERMINATED, EXIT_BROKEN_PIPE = 143, 141


class ArgumentParser(argparse.ArgumentParser):
    """argparse with one-line errors on stderr (exit code 2)."""

    def error(self, message):
        self.exit(EXIT_USAGE, f"{self.prog}: error: {message} (see {self.prog} --help)\n")


def build_parser(command=None):
    """The ``mbdyn`` parser.  With ``command`` (a name in ``COMMANDS``), only that command's
    module is imported and its arguments added; the others are listed by their summary
    (they are never parsed then).  Without, every command is complete."""
    from .. import __version__
    parser = ArgumentParser(
        prog="mbdyn",
        description="Multibody dynamics after Dynamics of Machines II: run and inspect "
                    "model files (see docs/model-files.md).")
    parser.add_argument("--version", action="version", version=f"mbdyn {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", parser_class=ArgumentParser)
    for name in COMMANDS:
        if command is None or name == command:
            importlib.import_module(f"{__name__}.{name}").register(sub)
        else:
            sub.add_parser(name, help=SUMMARIES[name])
    return parser


def _command(argv):
    """The command the command line names (its first word that is not an option; the
    top-level parser takes no option values), or "" when it names none of ``COMMANDS``
    (``--help``, ``--version``, a usage error: no command module is needed)."""
    for word in argv:
        if not word.startswith("-"):
            return word if word in COMMANDS else ""
    return ""


def _one_line(text):
    """One line, control characters escaped (a name cannot drive the terminal)."""
    from ..names import shown
    return shown(" ".join(str(text).split()))


class Terminated(KeyboardInterrupt):
    """SIGTERM, raised in the main thread so that temporaries are removed on the way out."""


def _on_sigterm(signum, frame):
    raise Terminated()


def _quiet_stdout():
    """After the reader of stdout went away: send the rest to /dev/null (no "Broken
    pipe" message at exit)."""
    try:
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
    except (OSError, ValueError, AttributeError):
        pass


def _error(message):
    sys.stderr.write(f"mbdyn: error: {_one_line(message)}\n")


def main(argv=None):
    """Run the command line ``argv`` (default ``sys.argv[1:]``); returns the exit code."""
    # The command's matrices are small: an OpenBLAS thread pool would only spin (a tenth
    # of a second of CPU at start, and contention in sweeps).  Set before numpy loads; a
    # value the user set is kept.
    os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
    argv = sys.argv[1:] if argv is None else list(argv)
    from . import compiling
    compiling.announce_if_cold(_command(argv), argv)    # before the parser's imports
    parser = build_parser(_command(argv))
    try:
        args = parser.parse_args(argv)
    except SystemExit as exc:             # --help, --version, usage errors
        return exc.code if isinstance(exc.code, int) else EXIT_USAGE
    if not getattr(args, "command", None):
        parser.print_usage(sys.stderr)
        _error("give a command: " + ", ".join(COMMANDS) + " (see mbdyn --help)")
        return EXIT_USAGE
    from ..errors import ModelError, SimulationError
    debug = bool(os.environ.get("MBDYN_DEBUG"))
    try:
        previous = signal.signal(signal.SIGTERM, _on_sigterm)
    except ValueError:                # not the main thread (e.g. called from a test)
        previous = None
    try:
        with _watch(args.command) as watch:
            code = _dispatch(args, debug, ModelError, SimulationError)
        watch.close()
        sys.stdout.flush()              # a closed pipe shows here, not at exit
        return code
    except BrokenPipeError:
        _quiet_stdout()
        return EXIT_BROKEN_PIPE
    finally:
        if previous is not None:
            signal.signal(signal.SIGTERM, previous)


def _watch(command):
    """numba's compile events watched for the notice and the progress of a command that
    compiles (``compiling.Watch``), or a stand-in that watches nothing."""
    from . import compiling
    if command in compiling.COMPILING and compiling.enabled():
        return compiling.Watch()
    return _Unwatched()


class _Unwatched:
    def __enter__(self):
        return self

    def __exit__(self, *exc):
        return None

    def close(self):
        return None


def _dispatch(args, debug, ModelError, SimulationError):
    from ..kernels import ignore_pedantic_numba
    with warnings.catch_warnings():
        warnings.simplefilter("always")
        ignore_pedantic_numba()
        seen = set()

        def show(message, category, filename, lineno, file=None, line=None):
            text = _one_line(message)
            if text not in seen:
                seen.add(text)
                sys.stderr.write(f"mbdyn: warning: {text}\n")
        warnings.showwarning = show
        try:
            return args.func(args) or EXIT_OK
        except Terminated:
            sys.stderr.write("\nmbdyn: terminated (SIGTERM); no partial files were left\n")
            return EXIT_TERMINATED
        except KeyboardInterrupt:
            sys.stderr.write("\nmbdyn: interrupted; no partial files were left\n")
            return EXIT_INTERRUPTED
        except BrokenPipeError:
            raise
        except RecursionError as exc:
            if debug:
                raise
            _error(f"the input is nested too deeply to process ({exc}); simplify it")
            return EXIT_INPUT
        except MemoryError:
            if debug:
                raise
            _error("out of memory; the run or its results are too large -- shorten t_end, "
                   "give output_dt, or lower --max-samples")
            return EXIT_SIMULATION
        except SimulationError as exc:
            if debug:
                raise
            _error(f"simulation failed: {exc}")
            return EXIT_SIMULATION
        except ModelError as exc:
            if debug:
                raise
            _error(exc)
            return EXIT_INPUT
        except ArithmeticError as exc:     # NonFiniteError, SingularMassMatrixError at t0
            if debug:
                raise
            _error(f"simulation failed: {exc}")
            return EXIT_SIMULATION
        except OSError as exc:
            if debug:
                raise
            where = f"{exc.filename}: " if getattr(exc, "filename", None) else ""
            _error(f"{where}{exc.strerror or exc}")
            return EXIT_INPUT
        except Exception as exc:          # a bug: still one line, traceback on request
            if debug:
                raise
            _error(f"internal error ({type(exc).__name__}: {exc}); please report it -- "
                   "MBDYN_DEBUG=1 shows the traceback")
            return 70


__all__ = ["main", "COMMANDS", "SUMMARIES", "build_parser"]
