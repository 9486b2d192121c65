"""docs/api.md's examples are executed, so the reference cannot drift from the code."""
import doctest
import os
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent


def test_api_reference_examples_run(monkeypatch):
    monkeypatch.chdir(ROOT)
    result = doctest.testfile(str(ROOT / "docs" / "api.md"), module_relative=False,
                              optionflags=doctest.ELLIPSIS | doctest.NORMALIZE_WHITESPACE,
                              verbose=False)
    assert result.attempted > 30
    assert result.failed == 0
