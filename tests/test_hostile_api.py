"""Hostile input, second round (issue 29): names that matplotlib reads as math, outputs
checked before the work, raw errors of the Python interface, contradictory effects, work
that grows without bound (sympy expansion, closed-form equations of long chains, a long
Campbell diagram).

Table-driven like ``tests/test_hostile.py``: a new case is one row.  Every test runs under
a time limit (``time_limit``, SIGALRM): a hang fails, it does not stall the suite.
"""
from __future__ import annotations

import os
import re
import signal
import subprocess
import sys

import numpy as np
import pytest

import mbdyn as mb
from mbdyn import limits
from test_hostile import BASE, in_process, model_text

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))

#: seconds a test may take unless it says otherwise (numba's first compilation included)
LIMIT_S = 150


class TimeLimit(BaseException):
    """A test ran past its time limit: a BaseException, so that the command's own handlers
    cannot turn it into an exit code."""


@pytest.fixture(autouse=True)
def time_limit():
    """Every test under ``LIMIT_S`` seconds; ``time_limit(s)`` sets another limit."""
    def arm(seconds):
        signal.alarm(int(seconds))

    def expire(signum, frame):
        raise TimeLimit("the test ran past its time limit")
    previous = signal.signal(signal.SIGALRM, expire)
    arm(LIMIT_S)
    yield arm
    signal.alarm(0)
    signal.signal(signal.SIGALRM, previous)


def run_cli(argv, tmp_path, text=None, timeout=120):
    """``mbdyn ARGV`` in a subprocess (its own memory, a time limit); ``{model}`` is a file
    holding ``text``, ``{tmp}`` the test's directory."""
    path = tmp_path / "model.toml"
    if text is not None:
        path.write_text(text, encoding="utf-8")
    argv = [a.replace("{model}", str(path)).replace("{tmp}", str(tmp_path)) for a in argv]
    env = dict(os.environ, PYTHONPATH=ROOT)
    env.pop("MBDYN_DEBUG", None)
    return subprocess.run([sys.executable, "-m", "mbdyn"] + argv, capture_output=True,
                          text=True, timeout=timeout, cwd=tmp_path, env=env)


def clean(err):
    """No traceback, no internal error, no escape character reached the user."""
    assert "Traceback" not in err and "internal error" not in err, err
    assert "\x1b" not in err


def chain(n, kind="revolute"):
    """A model file of an ``n``-link planar chain."""
    parts = ['[model]\nname = "chain"\ngravity = [0, "-g", 0]\n\n'
             '[parameters]\nm = 1.0\nl = 0.5\ng = 9.81\n']
    for k in range(n):
        parts.append(f'[[bodies]]\nname = "b{k}"\nmass = "m"\ncom = ["l", 0, 0]\n'
                     'inertia = [0.01, 0.01, 0.01]\n')
    for k in range(n):
        parent = "ground" if k == 0 else f"b{k - 1}"
        position = "[0, 0, 0]" if k == 0 else '["l", 0, 0]'
        parts.append(f'[[joints]]\nname = "j{k}"\nkind = "{kind}"\nparent = "{parent}"\n'
                     f'child = "b{k}"\naxis = "z"\nposition = {position}\n')
    parts.append("[simulation]\nt_end = 1.0\n")
    return "\n".join(parts)


# -- 8: closed-form equations of long chains ------------------------------------------------
# id, links, extra options, pattern of the refusal (None: it must print the equations)
EOM_CASES = [
    ("chain-20", 20, [], r"frames down to 'b\d+' alone would have [\d.e+]+ parts.*more "
                         r"than 2000000 \(limits.MAX_EQUATION_NODES.*fewer links"),
    ("chain-8-newton-euler", 8, ["--method", "newton-euler"],
     r"M and f by newton-euler would have 3.06e\+06 parts.*jourdain method without solving"),
    ("chain-6-solve", 6, ["--solve"], r"solved accelerations would have .* parts"),
    ("chain-2", 2, [], None),
    ("chain-3-solve-steps", 3, ["--method", "newton-euler", "--solve", "--steps"], None),
]


@pytest.mark.parametrize("case_id, links, options, pattern", EOM_CASES,
                         ids=[c[0] for c in EOM_CASES])
def test_eom_of_a_long_chain_is_refused_quickly_with_its_size(case_id, links, options,
                                                               pattern, tmp_path):
    proc = run_cli(["eom", "{model}"] + options, tmp_path, chain(links), timeout=60)
    clean(proc.stderr)
    if pattern is None:
        assert proc.returncode == 0, proc.stderr
        assert "j0_dot" in proc.stdout and "derived in" in proc.stdout
    else:
        assert proc.returncode == 1, proc.stderr
        assert re.search(pattern, proc.stderr), proc.stderr


def test_derive_in_python_keeps_a_long_chain_and_skips_only_the_slow_count(tmp_path):
    (tmp_path / "c.toml").write_text(chain(14))
    d = mb.derive(mb.load_model(tmp_path / "c.toml").model)      # seconds, not minutes
    assert "operations" not in d.stats                           # count_ops is exponential
    assert 0 < d.stats["operations_after_cse"] < 10_000
    with pytest.raises(mb.ModelError, match=r"M and f by jourdain would have"):
        mb.derive(mb.load_model(tmp_path / "c.toml").model, max_nodes=10**6)
