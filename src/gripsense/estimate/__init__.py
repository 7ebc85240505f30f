"""Estimators: combine physics functions over tables; results carry validity flags and honest
uncertainty (``docs/friction.md``).
"""

from gripsense.estimate.axle_window import estimate_windows
from gripsense.estimate.bins import AxleBins, axle_bins
from gripsense.estimate.braking import BrakingResult, estimate_braking
from gripsense.estimate.conditions import condition_table, conditions
from gripsense.estimate.estimators import ESTIMATORS, Estimator, get_estimator
from gripsense.estimate.friction import friction_from_motion
from gripsense.estimate.grip import measured_grip
from gripsense.estimate.noise import NoiseModel, receiver_noise
from gripsense.estimate.online import OnlineAxleWindow
from gripsense.estimate.options import FrictionOptions, WindowOptions
from gripsense.estimate.results import (
    AxleFriction,
    FrictionResult,
    WheelFriction,
    read_result,
)
from gripsense.estimate.stiffness import GSweep, g_sweep, tread_stiffness
from gripsense.estimate.wheels import FLAGS, NOT_STEADY_CORNERING, motion_from_epochs

__all__ = [
    "ESTIMATORS",
    "FLAGS",
    "NOT_STEADY_CORNERING",
    "AxleBins",
    "AxleFriction",
    "BrakingResult",
    "Estimator",
    "FrictionOptions",
    "FrictionResult",
    "GSweep",
    "NoiseModel",
    "OnlineAxleWindow",
    "WheelFriction",
    "WindowOptions",
    "axle_bins",
    "condition_table",
    "conditions",
    "estimate_braking",
    "estimate_windows",
    "friction_from_motion",
    "g_sweep",
    "get_estimator",
    "measured_grip",
    "motion_from_epochs",
    "read_result",
    "receiver_noise",
    "tread_stiffness",
]
