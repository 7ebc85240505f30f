"""Per-wheel friction from a GNSS-compass motion table (thesis ch. 4, 6, 10; ``docs/physics.md``
§11): the wheel kinematics every estimator shares (:mod:`gripsense.estimate.wheels`), then the
chosen estimator's per-sample stage (:mod:`gripsense.estimate.estimators`).
"""

from __future__ import annotations

import pandas as pd

from gripsense.config import Vehicle
from gripsense.estimate.estimators import get_estimator
from gripsense.estimate.options import FrictionOptions
from gripsense.estimate.wheels import (
    FLAGS,
    NOT_STEADY_CORNERING,
    WHEEL_COLUMNS,
    motion_from_epochs,
    wheel_kinematics,
    wheel_table,
)

__all__ = [
    "FLAGS",
    "NOT_STEADY_CORNERING",
    "WHEEL_COLUMNS",
    "FrictionOptions",
    "friction_from_motion",
    "motion_from_epochs",
]


def friction_from_motion(
    motion: pd.DataFrame,
    vehicle: Vehicle,
    *,
    method: str = "brush-2",
    options: FrictionOptions | None = None,
) -> tuple[pd.DataFrame, dict]:
    """μ per wheel and sample from a motion table of the measurement point (body axes).

    Parameters
    ----------
    motion : pandas.DataFrame
        ``t_s``, ``epoch``, ``u_mps``, ``v_mps`` (body velocity of the measurement point — the
        antenna of the vehicle file), ``yaw_rate_rps`` (ISO), ``ay_mps2`` (measured lateral
        acceleration of the CG, or NaN: then U·r of the reference point), ``steer_rad``
        (road-wheel angle or NaN); optionally ``course_rad`` and ``heading_rad``
        (:func:`motion_from_epochs`).
    vehicle : Vehicle
        Vehicle description.
    method : str
        A key of :data:`gripsense.estimate.estimators.ESTIMATORS`: ``brush-2`` (default),
        ``brush-4``, ``thesis-2`` (eq. 4.15), ``thesis-4`` (ch. 10), ``brush``/``thesis``
        (pressure shape from the tyre description) or ``axle-window`` (the kinematics only,
        samples flagged ``per_axle``: μ is estimated per axle and window).
    options : FrictionOptions
        Gates and the noise model.

    Returns
    -------
    wheels : pandas.DataFrame
        One row per wheel and usable sample (columns :data:`WHEEL_COLUMNS`); ``mu`` is NaN
        unless ``flag == "ok"``.
    meta : dict
        Method, wheels analysed, and notes on wheels left out.
    """
    est = get_estimator(method)
    o = options or FrictionOptions()
    frames, meta = wheel_kinematics(motion, vehicle, o)
    est.sample_stage(frames, vehicle, o)
    return wheel_table(frames, vehicle), {"method": method, **meta}
