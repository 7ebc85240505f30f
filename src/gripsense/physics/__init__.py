"""Pure, vectorised physics: SI units in and out, every function cites its equation in
``docs/physics.md``. Nothing here reads files, keeps state or plots.
"""

from gripsense.physics.brush import (
    adhesion_parameter,
    aligning_moment,
    cornering_stiffness,
    force_ratio,
    invert,
    kappa_beta,
    lateral_force,
    mu_from_force,
    slide_point,
)
from gripsense.physics.contact import (
    contact_length_lm,
    edge_pressure_gradient,
    pressure_parabolic,
    pressure_quartic,
)
from gripsense.physics.kinematics import (
    antenna_sideslip,
    heading_offset_from_straight,
    path_radius,
    point_velocity,
    slip_angle,
    wrap_angle,
)
from gripsense.physics.load_transfer import (
    axle_lateral_force,
    lateral_load_transfer,
    static_axle_masses,
    thesis_load_transfer,
    wheel_loads,
)
from gripsense.physics.magic_formula import MFForces, MFTyre
from gripsense.physics.magic_formula.pac89 import magic_formula, pac89_lateral, pac89_longitudinal
from gripsense.physics.magic_formula.pac94 import pac94_lateral
from gripsense.physics.steering_balance import column_torque, dahl_friction, steering_moment
from gripsense.physics.surface import SURFACE_BANDS, surface_class, surface_class_interval

__all__ = [
    "SURFACE_BANDS",
    "MFForces",
    "MFTyre",
    "adhesion_parameter",
    "aligning_moment",
    "antenna_sideslip",
    "axle_lateral_force",
    "column_torque",
    "contact_length_lm",
    "cornering_stiffness",
    "dahl_friction",
    "edge_pressure_gradient",
    "force_ratio",
    "heading_offset_from_straight",
    "invert",
    "kappa_beta",
    "lateral_force",
    "lateral_load_transfer",
    "magic_formula",
    "mu_from_force",
    "pac89_lateral",
    "pac89_longitudinal",
    "pac94_lateral",
    "path_radius",
    "point_velocity",
    "pressure_parabolic",
    "pressure_quartic",
    "slide_point",
    "slip_angle",
    "static_axle_masses",
    "steering_moment",
    "surface_class",
    "surface_class_interval",
    "thesis_load_transfer",
    "wheel_loads",
    "wrap_angle",
]
