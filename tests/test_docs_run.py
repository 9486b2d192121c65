"""Docs that run (issue 27, item 4): every code block of README.md and docs/*.md is
executed, so that a broken example fails here and not in a reader's hands.

* ```python blocks run as scripts (``python block.py``, a process of their own: a guard
  ``if __name__ == "__main__":`` matters there, as in a reader's file), in a temporary
  folder that holds a link ``models`` to the repository's models, so that files the
  examples write (``top.png``, ``results/``) land there.  A block of ``>>>`` lines is a
  doctest: it must be on a page ``tests/test_api_docs.py`` runs (``DOCTEST_PAGES``).
* ```sh and ```bash blocks: each command (``\\``-continued lines joined, ``# ...``
  comments dropped, ``a && b`` split) runs as ``mbdyn.cli.main(argv)`` in such a folder
  (the ``mbdyn`` command is that function; in-process saves a second of imports each)
  and must exit with 0; ``> FILE`` writes its stdout to FILE.  Commands that are not
  ``mbdyn`` are listed in ``SKIPPED`` with the reason, or the test fails.
* ```console blocks: ``$ COMMAND`` lines, each followed by the output it shows; the
  shown lines must appear in that order in the command's output (stdout, then stderr),
  ``...`` standing for any text and each number for the actual one to the digits shown.

A block that is deliberately not runnable has an HTML comment ``<!-- not run: REASON -->``
on the line before its fence (the reason is required).  Other languages (```toml, ```json,
```text) are not run.  Commands that take more than 20 s are marked ``slow`` (``SLOW``).
"""
from __future__ import annotations

import contextlib
import io
import os
import re
import shlex
import subprocess
import sys
import warnings
from dataclasses import dataclass
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
PAGES = [ROOT / "README.md"] + sorted((ROOT / "docs").glob("*.md"))
RUN = {"python", "sh", "bash", "console"}
#: pages whose ``>>>`` examples run as doctests, and the test that runs them
DOCTEST_PAGES = {"docs/api.md": "tests/test_api_docs.py"}
#: commands of shell blocks that are not run: (how the command starts, why)
SKIPPED = (
    ("pip install", "installs the package; the tests run on this checkout"),
    ("python -m pytest", "the test suite itself"),
    ("apt-get", "installs system packages"),
    ("git ", "a repository operation"),
    ("dask scheduler", "starts a Dask scheduler: a network service that runs until stopped"),
    ("dask worker", "starts Dask workers that connect to a scheduler over the network"),
)
#: commands (or Python blocks) that take more than 20 s on a 2-core machine, by the
#: start of the command or the block's page and line (accuracy studies: 54 s and 20 s)
SLOW = ("mbdyn accuracy models/double_pendulum.toml --case 45_45 --t-end 4",
        "mbdyn accuracy models/double_pendulum.toml --t-end 1")
FENCE = re.compile(r"^(\s*)(`{3,})\s*([\w+-]*)\s*$")
NOT_RUN = re.compile(r"<!--\s*not run:\s*(.*?)\s*-->")


@dataclass
class Block:
    page: str
    line: int               # of the opening fence, 1-based
    lang: str
    text: str
    not_run: str | None     # the reason, when marked


def read_blocks(path):
    return parse_blocks(path.read_text(encoding="utf-8"), str(path.relative_to(ROOT)))


def parse_blocks(text, page):
    """The fenced blocks of a markdown page; raises ``ValueError`` on a fence that is
    never closed (or one opened inside another block, which markdown would show as
    text of the first)."""
    lines = text.splitlines()
    out, k = [], 0
    while k < len(lines):
        m = FENCE.match(lines[k])
        if not m:
            k += 1
            continue
        start, ticks, lang = k, m.group(2), m.group(3).lower()
        k += 1
        while k < len(lines) and lines[k].strip() != ticks:
            inner = FENCE.match(lines[k])
            if inner and inner.group(3):
                raise ValueError(f"{page}:{start + 1}: fence not closed before the "
                                 f"fence at line {k + 1}")
            k += 1
        if k == len(lines):
            raise ValueError(f"{page}:{start + 1}: fence never closed")
        before = lines[start - 1] if start else ""
        reason = NOT_RUN.search(before)
        out.append(Block(page, start + 1, lang, "\n".join(lines[start + 1:k]),
                         reason.group(1) if reason else None))
        k += 1
    return out


def all_blocks():
    return [b for p in PAGES for b in read_blocks(p)]


def commands(text):
    """The commands of a shell block: continued lines joined, comments dropped, ``&&``
    chains split; each a list of words (shell quoting, comments removed)."""
    joined = re.sub(r"\\\n", " ", text)
    out = []
    for line in joined.splitlines():
        words = shlex.split(line, comments=True)
        part = []
        for w in words + ["&&"]:
            if w == "&&":
                if part:
                    out.append(part)
                part = []
            else:
                part.append(w)
    return out


def skipped(words):
    """The reason a command is not run, or None."""
    line = " ".join(words)
    for start, reason in SKIPPED:
        if line.startswith(start):
            return reason
    return None


def console_steps(text):
    """``[(words, [expected output lines])]`` of a console block."""
    steps = []
    for line in text.splitlines():
        if line.startswith("$ "):
            steps.append((shlex.split(line[2:], comments=True), []))
        elif steps and line.strip():
            steps[-1][1].append(line.strip())
        elif line.strip():
            raise ValueError(f"output before any command: {line!r}")
    return steps


NUMBER = r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?"


def line_matches(expected, actual):
    """Whether an output line shows ``expected``: the text the same (``...`` any text),
    each number the same to the digits shown (half a unit of its last digit)."""
    parts = re.split(rf"(\.\.\.|{NUMBER})", expected)
    pattern, shown = "", []
    for k, part in enumerate(parts):
        if k % 2 == 0:
            pattern += re.escape(part)
        elif part == "...":
            pattern += ".*?"
        else:
            pattern += f"({NUMBER})"
            shown.append(part)
    m = re.fullmatch(pattern, actual.strip())
    if not m:
        return False
    for text, got in zip(shown, m.groups()):
        mantissa = re.split("[eE]", text)[0]
        decimals = len(mantissa.split(".")[1]) if "." in mantissa else 0
        exponent = int(re.split("[eE]", text)[1]) if re.search("[eE]", text) else 0
        if abs(float(got) - float(text)) > 0.5001 * 10.0 ** (exponent - decimals):
            return False
    return True


def shows(expected, output):
    """Whether ``output``'s lines contain ``expected`` in order (``...`` lines skipped)."""
    lines = [ln for ln in output.splitlines() if ln.strip()]
    k = 0
    for want in expected:
        if want == "...":
            continue
        while k < len(lines) and not line_matches(want, lines[k]):
            k += 1
        if k == len(lines):
            return False
        k += 1
    return True


def run_mbdyn(words, folder):
    """``mbdyn WORDS`` in ``folder`` as the command runs it; ``(exit code, output)``."""
    from mbdyn.cli import main
    target = None
    if ">" in words:
        k = words.index(">")
        words, target = words[:k], words[k + 1]
    assert words[0] == "mbdyn", f"not an mbdyn command: {' '.join(words)}"
    out, err = io.StringIO(), io.StringIO()
    cwd = os.getcwd()
    os.chdir(folder)
    try:
        with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err), \
                warnings.catch_warnings():
            code = main(words[1:])
    finally:
        os.chdir(cwd)
    if target:
        (Path(folder) / target).write_text(out.getvalue(), encoding="utf-8")
    return code, out.getvalue() + err.getvalue()


def _slow(key):
    return [pytest.mark.slow] if any(key.startswith(s) for s in SLOW) else []


def _cases():
    """One test per Python block, per shell command (a command shown on two pages runs
    once, under its first place) and per console block."""
    cases, seen = [], set()
    for b in all_blocks():
        where = f"{b.page}:{b.line}"
        if b.lang not in RUN or b.not_run is not None or ">>>" in b.text:
            continue
        if b.lang in ("python", "console"):
            cases.append(pytest.param(b, None, id=where, marks=_slow(where)))
            continue
        for words in commands(b.text):
            line = " ".join(words)
            if skipped(words) is None and line not in seen:
                seen.add(line)
                cases.append(pytest.param(b, words, id=f"{where} {line[:60]}",
                                          marks=_slow(line)))
    return cases


@pytest.fixture
def folder(tmp_path):
    (tmp_path / "models").symlink_to(ROOT / "models", target_is_directory=True)
    return tmp_path


@pytest.mark.parametrize("block,words", _cases())
def test_block_runs(block, words, folder):
    if block.lang == "python":
        script = folder / "block.py"
        script.write_text(block.text + "\n", encoding="utf-8")
        env = dict(os.environ, PYTHONPATH=str(ROOT), MPLBACKEND="Agg")
        done = subprocess.run([sys.executable, str(script)], cwd=folder, env=env,
                              capture_output=True, text=True, timeout=600)
        assert done.returncode == 0, done.stderr[-3000:]
    elif block.lang == "console":
        for words, expected in console_steps(block.text):
            code, output = run_mbdyn(words, folder)
            assert code == 0, output[-3000:]
            assert shows(expected, output), (expected, output[-3000:])
    else:
        code, output = run_mbdyn(words, folder)
        assert code == 0, output[-3000:]


def test_fences_are_closed_and_blocks_marked():
    """Every fence closes; every not-run block says why; every command that is not
    ``mbdyn`` is skipped for a stated reason."""
    blocks = all_blocks()
    assert len([b for b in blocks if b.lang in RUN]) > 20
    for b in blocks:
        if b.not_run is not None:
            assert b.not_run, f"{b.page}:{b.line}: 'not run' without a reason"
        if b.lang == "python" and ">>>" in b.text:
            assert b.page in DOCTEST_PAGES, f"{b.page}:{b.line}: a doctest no test runs"
        if b.lang in ("sh", "bash") and b.not_run is None:
            for words in commands(b.text):
                assert words[0] == "mbdyn" or skipped(words), (b.page, b.line, words)
    assert len([b for b in blocks if b.not_run is not None]) <= 3


def test_the_checks_of_outputs():
    assert line_matches("drifted by 0.624 (62.4 %)", "drifted by 0.62431 (62.43 %)")
    assert not line_matches("drifted by 0.624 (62.4 %)", "drifted by 0.625 (62.4 %)")
    assert line_matches("t = ... s, 7473 steps", "t = 0 .. 2.49 s, 7473 steps")
    assert not line_matches("7473 steps", "7474 steps")
    assert line_matches("rtol 1e-10", "rtol 1e-10") and line_matches("a 1.5e-3", "a 0.0015")
    assert shows(["b 1", "...", "d"], "a\nb 1.04\nc\nd\n")
    assert not shows(["d", "b"], "b\nd\n")
    assert commands("mbdyn a \\\n  --b c  # note\npip install . && mbdyn x") == [
        ["mbdyn", "a", "--b", "c"], ["pip", "install", "."], ["mbdyn", "x"]]
    with pytest.raises(ValueError, match="not closed"):
        parse_blocks("```python\nx = 1\n\n```python\ny\n```\n", "page.md")
    with pytest.raises(ValueError, match="never closed"):
        parse_blocks("text\n```sh\nmbdyn run\n", "page.md")
    (block,) = parse_blocks("<!-- not run: a sketch -->\n```python\nf(x)\n```\n", "p")
    assert block.not_run == "a sketch" and block.lang == "python" and block.line == 2
