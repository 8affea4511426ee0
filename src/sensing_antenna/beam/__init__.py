"""Contact-mode beam physics of the link (Sections 3.3 and 3.4 of the paper).

- :mod:`~sensing_antenna.beam.characteristic`: the non-dimensional frequency equation, derived
  from the boundary conditions of Eq. 4 (not the printed Eq. 6), Wittrick-Williams root counting
  and the eigenvalues beta_i l (xi, R_m).
- :mod:`~sensing_antenna.beam.modes`: natural frequencies in rad/s and mode shapes of a link, and
  how a contact held along the obstacle stiffens its first mode.
- :mod:`~sensing_antenna.beam.sensing`: the sensing curve omega_1(x_c) and its inverse.
- :mod:`~sensing_antenna.beam.statics`: static deflection, base force and torque (Eqs. 7 to 13).
- :mod:`~sensing_antenna.beam.free_plane`: how far a pushed link's fundamental out of its
  bending plane may leave the straight link's.
- :mod:`~sensing_antenna.beam.weight`: what the pushed, sagging link's weight adds to the moment
  the torque/force ratio reads.
"""

from sensing_antenna.beam._validate import MAX_MODES, BeamInputError
from sensing_antenna.beam.characteristic import (
    characteristic_function,
    eigenvalue_slopes,
    eigenvalues,
    mode_count,
)
from sensing_antenna.beam.free_plane import free_plane_shift, free_plane_shifts
from sensing_antenna.beam.modes import (
    contact_ratio,
    contact_to_base_shear,
    frequency_scale,
    held_contact_coupling,
    mode_shapes,
    natural_frequencies,
)
from sensing_antenna.beam.sensing import Candidate, Inversion, SensingCurve
from sensing_antenna.beam.statics import (
    base_force,
    base_torque,
    contact_deflection_from_force,
    static_deflection,
    torque_force_ratio,
)
from sensing_antenna.beam.weight import pushed_weight_moment, weight_residual

__all__ = [
    "MAX_MODES",
    "BeamInputError",
    "Candidate",
    "Inversion",
    "SensingCurve",
    "base_force",
    "base_torque",
    "characteristic_function",
    "contact_deflection_from_force",
    "contact_ratio",
    "contact_to_base_shear",
    "eigenvalue_slopes",
    "eigenvalues",
    "free_plane_shift",
    "free_plane_shifts",
    "frequency_scale",
    "held_contact_coupling",
    "mode_count",
    "mode_shapes",
    "natural_frequencies",
    "pushed_weight_moment",
    "static_deflection",
    "torque_force_ratio",
    "weight_residual",
]
