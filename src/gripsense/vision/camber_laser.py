"""Camber to the ground from two laser displacement sensors (seed 002 §2.1, Fig. 3).

Two sensors on a bar fixed to the wheel carrier, perpendicular to the wheel plane, measure
their vertical distance to the road a known lateral distance apart (``spacing``). When the wheel
leans, the bar tilts with it, and the camber to the ground follows from the tangent of the
difference: γ = atan(((d_outer − d_outer,0) − (d_inner − d_inner,0)) / spacing) + γ₀, with the
readings d₀ taken on a flat floor at a known camber γ₀ (calibration).

Sign: ``camber_rad`` is positive when the top of the wheel leans **outward** (away from the
vehicle's centre) — the usual "positive camber". For the ISO 8855 inclination angle of a left
wheel (positive rolling to the right about the x axis) use −γ on the left and +γ on the right.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from gripsense._arrays import as_float_array, restore
from gripsense.errors import InputError

__all__ = ["CAMBER_COLUMNS", "calibration_offsets", "camber_from_lasers"]

SPACING_RANGE_M = (0.005, 5.0)
"""Plausible spacing of the two sensors along the bar [m]."""
REFERENCE_LIMIT_RAD = np.deg2rad(30.0)
"""Largest |camber| of a calibration pose [rad]."""

CAMBER_COLUMNS = ["t_s", "d_outer_m", "d_inner_m", "camber_deg"]
"""Columns of ``gripsense camber -o``: the laser readings [s], [m] and the camber [deg]."""


def camber_from_lasers(
    d_outer,
    d_inner,
    spacing_m: float,
    *,
    offset_outer: float = 0.0,
    offset_inner: float = 0.0,
    reference_camber_rad: float = 0.0,
):
    """Camber angle from two laser distances.

    Parameters
    ----------
    d_outer, d_inner : array_like
        Distances from the outer and inner sensor to the road [m].
    spacing_m : float
        Lateral distance between the two sensors along the bar [m].
    offset_outer, offset_inner : float
        Readings at the calibration pose [m].
    reference_camber_rad : float
        Camber at the calibration pose [rad].

    Returns
    -------
    array_like
        Camber [rad], positive = top of the wheel outward; NaN where a distance (or an
        offset) is not finite — an ``inf`` reading is not a 90° camber.

    References
    ----------
    Seed 002 (Mizuno et al. 1999) §2.1, Fig. 3: "二つのレーザー変位計の正接により計測".
    """
    if not SPACING_RANGE_M[0] <= spacing_m <= SPACING_RANGE_M[1]:
        raise InputError(
            f"spacing_m = {spacing_m:g}: the sensors' spacing along the bar is "
            f"{SPACING_RANGE_M[0]:g}–{SPACING_RANGE_M[1]:g} m; give it in metres"
        )
    if not abs(reference_camber_rad) <= REFERENCE_LIMIT_RAD:
        raise InputError(
            f"reference camber {np.rad2deg(reference_camber_rad):g}°: a calibration pose is "
            f"within ±{np.rad2deg(REFERENCE_LIMIT_RAD):.0f}°; give it in degrees (--reference-deg)"
        )
    o = as_float_array(d_outer, "d_outer") - offset_outer
    i = as_float_array(d_inner, "d_inner") - offset_inner
    diff = o - i
    gamma = np.arctan2(np.where(np.isfinite(diff), diff, np.nan), spacing_m)
    return restore(gamma + reference_camber_rad, d_outer)


def calibration_offsets(lasers: pd.DataFrame, seconds: float) -> tuple[float, float]:
    """Zero readings of the two lasers from the first *seconds* of a recording made on a flat
    floor at the reference camber (the calibration of seed 002 Fig. 3).

    Parameters
    ----------
    lasers : pandas.DataFrame
        ``t_s``, ``d_outer_m``, ``d_inner_m`` (:func:`gripsense.io.sensors.laser.read_laser_csv`).
    seconds : float
        Length of the calibration stretch at the start [s].

    Returns
    -------
    tuple of float
        Median outer and inner reading over the stretch [m].
    """
    cal = lasers[lasers["t_s"] < lasers["t_s"].iloc[0] + seconds]
    if cal.empty:
        raise InputError(f"camber calibration: no samples in the first {seconds} s")
    return float(cal["d_outer_m"].median()), float(cal["d_inner_m"].median())
