"""Learning an axle's cornering stiffness from everyday driving (``docs/physics.md`` §15.7).

In the linear range of the tyres the axle force per load is the declared stiffness's linear
prediction times a scale s, bent a little by the start of the curve's saturation. Per 1 s bin of
:func:`~gripsense.estimate.bins.axle_bins` (slips lagged by the relaxation length, loads
with transfer, the axle force):

    y = F / (Fz_L + Fz_R),   k = −(C_L tan α_L + C_R tan α_R) / (Fz_L + Fz_R)
    k = y / s + d y |y| + b_drive + e

with C_L, C_R the vehicle file's stiffness at each wheel's load. The force per load comes from
the lateral acceleration and is precise; the slip carries the heading error, so k is regressed
on y (errors in the regressor would bias s towards zero). Each drive has its own slip offset
b_drive (what its heading calibration left): the sums are formed within the drive around its
weighted means, so drives combine exactly without a common offset. Bins whose measured grip is
in :data:`GRIP_RANGE` (well inside the linear range of any road from wet upward) enter with
weights from the slip's white noise and the receiver's slow heading error; the slow error is
correlated over τ (20 s), so the weights are divided by 1 + 2τ/bin × its share of the variance
(fewer independent bins than bins). s's relative standard error (scaled by the reduced χ² when
above 1), the axle force's own scale error (3 %) and the fit's form (5 %) make the learned
stiffness's uncertainty.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from gripsense.config import Vehicle
from gripsense.config.calibration import AxleCalibration, DriveSums
from gripsense.estimate.bins import axle_bins, force_and_linear
from gripsense.estimate.noise import NoiseModel

__all__ = ["FORCE_SCALE_REL", "GRIP_RANGE", "drive_sums", "solve_sums"]

GRIP_RANGE = (0.04, 0.3)
"""Measured grip of the bins the linear-range fit uses [-]: above the noise, below where any
road from wet upward bends the curve by more than the fit's curvature term absorbs."""
FORCE_SCALE_REL = 0.03
"""Relative 1σ of the axle force's scale (mass, a_y calibration): a floor of the learned
stiffness's uncertainty [-]."""
FIT_FORM_REL = 0.05
"""Relative 1σ of the linear-range fit's own form (the curve's bend and the load sensitivity
of other tyres than the fit assumes): measured on three Magic Formula truth tyres × three
vehicles with a 0.3° white-noise receiver, the learned stiffness was off by 5 % (median) and
11 % (worst) where the fit's statistics alone said 2–3 % (``benchmarks/calibration.py``) [-]."""


def drive_sums(
    wheels: pd.DataFrame,
    vehicle: Vehicle,
    axle: str,
    noise: NoiseModel,
    *,
    file: str = "",
    sha256: str = "",
) -> DriveSums | None:
    """One drive's least-squares sums of the linear-range fit of one axle.

    Parameters
    ----------
    wheels : pandas.DataFrame
        Wheel table (:func:`gripsense.estimate.friction.friction_from_motion`).
    vehicle : Vehicle
        The vehicle file's description (its declared stiffness is the reference).
    axle : str
        ``front`` or ``rear``.
    noise : NoiseModel
        Measurement noise.
    file : str
        The drive's name, kept in the calibration file.
    sha256 : str
        Its content hash.

    Returns
    -------
    DriveSums or None
        The sums; None when the drive has no bin of this axle in :data:`GRIP_RANGE`.
    """
    if not wheels["wheel"].astype(str).str.startswith(axle).any():
        return None
    ab = axle_bins(wheels, axle, vehicle, noise)
    d = ab.data
    if d.shape[0] == 0:
        return None
    fz = d[:, 2] + d[:, 3]
    y, k = force_and_linear(d)
    g = np.abs(d[:, 9])
    use = (g >= GRIP_RANGE[0]) & (g <= GRIP_RANGE[1]) & np.isfinite(y) & np.isfinite(k)
    if use.sum() < 3:
        return None
    y, k = y[use], k[use]
    c_per_load = (d[use, 4] + d[use, 5]) / fz[use]
    slow = np.deg2rad(noise.heading_slow_deg)
    var_white = (c_per_load * d[use, 8]) ** 2
    var_slow = (c_per_load * slow) ** 2
    share = float(np.mean(var_slow / np.maximum(var_white + var_slow, 1e-30)))
    inflate = 1.0 + 2.0 * noise.heading_slow_tau_s * share  # bins of 1 s
    w = 1.0 / np.maximum((var_white + var_slow) * inflate, 1e-30)
    x = np.column_stack([y, y * np.abs(y)])
    # within the drive, around its weighted means: the drive's own slip offset drops out
    xc = x - (w @ x) / w.sum()
    kc = k - (w @ k) / w.sum()
    xtw = xc.T * w
    sums = np.concatenate([(xtw @ xc).ravel(), xtw @ kc, [float(np.sum(w * kc * kc))]])
    return DriveSums(file, sha256, axle, int(use.sum()), sums)


def solve_sums(sums: list[DriveSums], declared_N_per_rad: float) -> AxleCalibration | None:
    """The learned stiffness from the combined sums of one axle's drives.

    Parameters
    ----------
    sums : list of DriveSums
        The drives' sums (one axle).
    declared_N_per_rad : float
        The vehicle file's stiffness of one wheel at the static load [N/rad].

    Returns
    -------
    AxleCalibration or None
        The learned stiffness at the static load and its relative 1σ; None with fewer than
        six bins or without a change of the lateral force within a drive.
    """
    if not sums:
        return None
    tot = np.sum([s.sums for s in sums], axis=0)
    n = int(sum(s.bins for s in sums))
    a, b, kk = tot[:4].reshape(2, 2), tot[4:6], tot[6]
    if n < 6 or not np.isfinite(a).all() or np.linalg.cond(a) > 1e12:
        return None
    cov = np.linalg.inv(a)
    beta = cov @ b
    chi2 = float(kk - 2 * beta @ b + beta @ a @ beta)
    red = max(chi2 / max(n - 2 - len(sums), 1), 1.0)
    slope = float(beta[0])  # 1 / s
    if not slope > 0:
        return None
    se = float(np.sqrt(cov[0, 0] * red)) / slope
    return AxleCalibration(
        cornering_stiffness_N_per_rad=declared_N_per_rad / slope,
        stiffness_uncertainty=float(np.sqrt(se**2 + FORCE_SCALE_REL**2 + FIT_FORM_REL**2)),
        scale=1.0 / slope,
        bins=n,
    )
