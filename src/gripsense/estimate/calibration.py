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

With a steering-torque channel the same drives teach the steering's lever at low grip
(§16.8): per 1 s bin of :func:`~gripsense.estimate.torque.torque_bins` with measured grip in
:data:`TRAIL_GRIP_RANGE`, the moment at the steering axes is regressed as

    M = S F + f s + o_drive

(F the front axle force, s the steering friction's Dahl state, o_drive the drive's offset),
within each drive around its weighted means: S = k (t_c + t₀), the caster plus zero-slip
pneumatic trail times the channel's scale, the sum the torque estimator's nuisances a + b share
(:func:`gripsense.estimate.torque.torque_profile`).
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from gripsense.config import Vehicle
from gripsense.config.calibration import AxleCalibration, DriveSums, SteeringCalibration
from gripsense.estimate.bins import axle_bins, force_and_linear
from gripsense.estimate.noise import NoiseModel
from gripsense.estimate.torque import check_channel, torque_bins

__all__ = [
    "FORCE_SCALE_REL",
    "GRIP_RANGE",
    "TRAIL_GRIP_RANGE",
    "drive_sums",
    "solve_steering_sums",
    "solve_sums",
    "steering_sums",
]

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
    # within the drive, around its weighted means: the drive's own slip offset drops out
    sums = _centred_sums(np.column_stack([y, y * np.abs(y)]), k, w)
    return DriveSums(file, sha256, axle, int(use.sum()), sums)


def _centred_sums(x: np.ndarray, y: np.ndarray, w: np.ndarray) -> np.ndarray:
    """XᵀWX (row-major), XᵀWy and yᵀWy of a drive's bins centred on their weighted means (the
    drive's own offset drops out, so drives add exactly).
    """
    xc = x - (w @ x) / w.sum()
    yc = y - (w @ y) / w.sum()
    xtw = xc.T * w
    return np.concatenate([(xtw @ xc).ravel(), xtw @ yc, [float(np.sum(w * yc * yc))]])


def _first_coefficient(sums: list[DriveSums], min_bins: int) -> tuple[float, float, int] | None:
    """The first coefficient of the drives' combined two-regressor fit, its standard error
    relative to it (scaled by the reduced χ² when above 1) and the bins; None with fewer than
    *min_bins* bins, a singular fit or a coefficient that is not positive.
    """
    if not sums:
        return None
    tot = np.sum([s.sums for s in sums], axis=0)
    n = int(sum(s.bins for s in sums))
    a, b, yy = tot[:4].reshape(2, 2), tot[4:6], tot[6]
    if n < min_bins or not np.isfinite(a).all() or np.linalg.cond(a) > 1e12:
        return None
    cov = np.linalg.inv(a)
    beta = cov @ b
    chi2 = float(yy - 2 * beta @ b + beta @ a @ beta)
    red = max(chi2 / max(n - 2 - len(sums), 1), 1.0)
    first = float(beta[0])
    if not first > 0:
        return None
    return first, float(np.sqrt(cov[0, 0] * red)) / first, n


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
    fit = _first_coefficient(sums, 6)
    if fit is None:
        return None
    slope, se, n = fit  # slope = 1 / s
    return AxleCalibration(
        cornering_stiffness_N_per_rad=declared_N_per_rad / slope,
        stiffness_uncertainty=float(np.sqrt(se**2 + FORCE_SCALE_REL**2 + FIT_FORM_REL**2)),
        scale=1.0 / slope,
        bins=n,
    )


TRAIL_GRIP_RANGE = (0.04, 0.2)
"""Measured grip of the bins the steering lever's fit uses [-]: below 0.2 a wet road's tyres
(μ ≥ 0.5) are under 0.4 of their grip, where a real tyre keeps ≥ 0.9 of its trail
(docs/physics.md §16.5). A bend term (F g²) was tried: with few bins below 0.1 g it traded
against the lever and took it 20 % high."""
TRAIL_FIT_FORM_REL = 0.04
"""Relative 1σ of the lever's fit form (the trail's fall up to 0.2 g, the steering's friction
and inertia, the axle force's scale): on three Magic Formula truth tyres × two cars × two
receivers, three everyday drives each, the learned lever was 1.5–4.9 % high (median 3 %)
against the simulator's own lever, where its statistics said 1 % (docs/physics.md §16.8) [-]."""


def steering_sums(
    wheels: pd.DataFrame, vehicle: Vehicle, *, file: str = "", sha256: str = ""
) -> DriveSums | None:
    """One drive's least-squares sums of the steering lever's fit (docs/physics.md §16.8).

    Parameters
    ----------
    wheels : pandas.DataFrame
        Wheel table with a steering-torque channel on the front wheels.
    vehicle : Vehicle
        The vehicle (its ``[steering]`` turns the channel into the moment at the axes).
    file : str
        The drive's name, kept in the calibration file.
    sha256 : str
        Its content hash.

    Returns
    -------
    DriveSums or None
        ``axle = "steering"``: XᵀWX (2 × 2), XᵀWM (2) and MᵀWM of the centred bins; None
        without a torque channel or with fewer than six bins in :data:`TRAIL_GRIP_RANGE`.
    """
    tb = torque_bins(wheels, vehicle)
    if tb is None:
        return None
    check_channel(tb, vehicle)  # a flipped sign or a wrong unit: one clear error, as friction
    g = np.abs(tb.grip)
    use = (g >= TRAIL_GRIP_RANGE[0]) & (g <= TRAIL_GRIP_RANGE[1]) & np.isfinite(tb.moment)
    if use.sum() < 6:
        return None
    f, m = tb.force[use], tb.moment[use]
    x = np.column_stack([f, tb.friction_state[use]])
    # the bin's noise: the moment's own and the force's through a nominal lever; the bins'
    # spreads already carry the transients
    lever = float(np.sum(m * f) / max(np.sum(f * f), 1e-9))
    w = 1.0 / np.maximum(tb.moment_sigma[use] ** 2 + (lever * tb.force_sigma[use]) ** 2, 1e-12)
    return DriveSums(file, sha256, "steering", int(use.sum()), _centred_sums(x, m, w))


def solve_steering_sums(sums: list[DriveSums]) -> SteeringCalibration | None:
    """The learned steering lever from the combined sums of the drives.

    Parameters
    ----------
    sums : list of DriveSums
        The drives' ``steering`` sums.

    Returns
    -------
    SteeringCalibration or None
        S = k (t_c + t₀) and its relative 1σ (the fit's standard error scaled by the reduced χ²
        when above 1, and :data:`TRAIL_FIT_FORM_REL`); None with fewer than ten bins or a lever
        that is not positive.
    """
    fit = _first_coefficient(sums, 10)
    if fit is None:
        return None
    lever, se, n = fit
    return SteeringCalibration(
        lever_m=lever, lever_uncertainty=float(np.hypot(se, TRAIL_FIT_FORM_REL)), bins=n
    )
