"""Estimators: combine physics functions over tables; results carry validity flags and honest
uncertainty (``docs/friction.md``).
"""

from gripsense.estimate.axle_window import (
    AxleBins,
    OnlineAxleWindow,
    WindowOptions,
    axle_bins,
    estimate_windows,
)
from gripsense.estimate.braking import BrakingResult, estimate_braking
from gripsense.estimate.conditions import condition_table, conditions
from gripsense.estimate.friction import (
    FLAGS,
    METHODS,
    NOT_STEADY_CORNERING,
    FrictionOptions,
    friction_from_motion,
    motion_from_epochs,
)
from gripsense.estimate.noise import NoiseModel, receiver_noise
from gripsense.estimate.results import (
    AxleFriction,
    FrictionResult,
    WheelFriction,
    read_result,
)
from gripsense.estimate.stiffness import GSweep, g_sweep, tread_stiffness

__all__ = [
    "FLAGS",
    "METHODS",
    "NOT_STEADY_CORNERING",
    "AxleBins",
    "AxleFriction",
    "BrakingResult",
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
    "motion_from_epochs",
    "read_result",
    "receiver_noise",
    "tread_stiffness",
]
