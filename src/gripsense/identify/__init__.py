"""Identification of model parameters from measurements: tyre coefficients (seed 002), the
steering system (seed 003) and the contact-length model (thesis eq. 6.23).
"""

from gripsense.identify.constrained_lsq import LSQResult, solve_constrained_lsq
from gripsense.identify.contact_fit import fit_contact_length
from gripsense.identify.steering import (
    CsResult,
    KsResult,
    SteeringIdentification,
    identify_cs,
    identify_ks,
    identify_steering,
    normalise_yaw_gain,
    tyre_lateral_stiffness,
)
from gripsense.identify.steering_metrics import (
    release_onset,
    release_settling_time,
    settling_time,
    step_metrics,
    yaw_gain,
)
from gripsense.identify.tyre_fit import (
    FITTERS,
    TyreFit,
    fit_from_wheel_table,
    fit_mf61_lateral,
    fit_pac94,
)

__all__ = [
    "FITTERS",
    "CsResult",
    "KsResult",
    "LSQResult",
    "SteeringIdentification",
    "TyreFit",
    "fit_contact_length",
    "fit_from_wheel_table",
    "fit_mf61_lateral",
    "fit_pac94",
    "identify_cs",
    "identify_ks",
    "identify_steering",
    "normalise_yaw_gain",
    "release_onset",
    "release_settling_time",
    "settling_time",
    "solve_constrained_lsq",
    "step_metrics",
    "tyre_lateral_stiffness",
    "yaw_gain",
]
