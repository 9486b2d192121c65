"""Analyses built on simulation: accuracy-versus-cost studies (later: equilibria, modes)."""
from .accuracy import Study, accuracy_study

__all__ = ["Study", "accuracy_study"]
