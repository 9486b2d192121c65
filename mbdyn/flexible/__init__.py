"""Flexible bodies: a beam model, its modal reduction, reduced data from other programs,
and the inertia invariants of the floating frame of reference (docs/flexible.md).

Pure numpy and scipy; the engine's kernels will read a :class:`ReducedBody`'s arrays.
"""
from .beam import COMPONENTS, Attachment, Beam
from .data import load_reduced_body, read_reduced_data, reduced_body_from_data
from .invariants import (Invariants, MassPoints, floating_frame_mass_matrix,
                         inertia_invariants, lumped_mass_points, quadratic_velocity_vector)
from .modal import natural_frequencies, natural_modes, whirl
from .reduced import ReducedBody, modal_damping
from .reduction import craig_bampton, free_interface, rigid_body_modes
from .sections import Section, make_section
from .spec import beam_from_spec

__all__ = ["Attachment", "Beam", "COMPONENTS", "Invariants", "MassPoints", "ReducedBody",
           "Section", "beam_from_spec", "craig_bampton", "floating_frame_mass_matrix",
           "free_interface", "inertia_invariants", "load_reduced_body", "lumped_mass_points",
           "make_section", "read_reduced_data", "reduced_body_from_data",
           "modal_damping", "natural_frequencies", "natural_modes",
           "quadratic_velocity_vector", "rigid_body_modes", "whirl"]
