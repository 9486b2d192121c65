"""The error of model files: names the file, the key path, what is wrong and the remedy."""
from __future__ import annotations

from ..errors import ModelError
from ..names import shown


class ModelFileError(ModelError):
    """A model file (or an override of it) that cannot be used as given.

    ``str(err)`` is one line: ``FILE: KEY.PATH: what is wrong; what to change``.
    ``file``, ``key`` and ``problem`` hold the parts.
    """

    def __init__(self, file, key, problem):
        self.file = shown(file)
        self.key = shown(key or "")
        self.problem = shown(" ".join(str(problem).split()))     # one line, always
        where = f"{self.file}: {self.key}: " if self.key else f"{self.file}: "
        super().__init__(where + self.problem)
