"""Flexible bodies: a beam model, its modal reduction, reduced data from other programs,
and the inertia invariants of the floating frame of reference (docs/flexible.md).

Pure numpy and scipy; the engine's kernels will read a :class:`ReducedBody`'s arrays.
"""
from .beam import COMPONENTS, Attachment, Beam
from .modal import natural_frequencies, natural_modes, whirl
from .sections import Section, make_section
from .spec import beam_from_spec

__all__ = ["Attachment", "Beam", "COMPONENTS", "Section", "beam_from_spec", "make_section",
           "natural_frequencies", "natural_modes", "whirl"]
