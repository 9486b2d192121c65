"""Exceptions and warnings of mbdyn; every message names the element and the remedy."""


class ModelError(ValueError):
    """A model that cannot be built as given (bad element, bad tree, bad value)."""


class SingularMassMatrixError(ArithmeticError):
    """The mass matrix is not positive definite at the state where it was evaluated."""

    def __init__(self, message, coordinates=()):
        super().__init__(message)
        self.coordinates = tuple(coordinates)


class NonFiniteError(ArithmeticError):
    """NaN or Inf appeared in an evaluation; the message says where and in what."""


class SimulationError(RuntimeError):
    """An integration that could not go on; ``result`` keeps what was computed before."""

    def __init__(self, message, result=None):
        super().__init__(message)
        self.result = result


class ModelWarning(UserWarning):
    """A model that runs but deserves a second look (e.g. physically odd inertia)."""


class SingularityWarning(UserWarning):
    """The model is at or near a configuration where its equations become singular."""
