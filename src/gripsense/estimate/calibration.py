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

The drives must agree (§15.7, "Conflicts"): each drive's own slope, with the combined fit's
curvature held, is tested against the combination (χ² over the drives, N − 1 degrees of
freedom, failing beyond the 2σ level); where it fails the standard error of the drives' mean
slope is scaled by the Birge ratio R = √(χ²/(N − 1)) (the slope's error grows by
√(R² − 1) times it), and the learned stiffness's uncertainty is widened further where needed
so that no drive lies more than 2 combined σ from it. With ``--update`` the file's
earlier drives and the new ones are two learnings: where they differ beyond 2 combined σ the
uncertainty grows until both lie within 2σ of the combination. Either way one line says so.
A learned steering lever 2 combined σ from the one the vehicle file's ``[steering]`` declares
(:func:`declared_lever`) is said the same way, and the learned one is used
(:func:`use_learned_lever`; docs/calibration.md).
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pandas as pd
from scipy.stats import chi2 as chi2_dist

from gripsense.config import Vehicle
from gripsense.config.calibration import (
    CONFLICT_SIGMAS,
    AxleCalibration,
    DriveSums,
    SteeringCalibration,
)
from gripsense.constants import G0
from gripsense.estimate.bins import axle_bins, force_and_linear
from gripsense.estimate.noise import NoiseModel
from gripsense.estimate.torque import check_channel, torque_bins, trail_family

__all__ = [
    "CONSISTENCY_P",
    "DRIVE_FORM_REL",
    "FORCE_SCALE_REL",
    "GRIP_RANGE",
    "TRAIL_GRIP_RANGE",
    "declared_lever",
    "drive_sums",
    "lever_conflict",
    "solve_steering_sums",
    "solve_sums",
    "steering_sums",
    "use_learned_lever",
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


DRIVE_FORM_REL = 0.03
"""Relative 1σ by which one drive's slope may differ from another's on the same tyres beyond
its statistics [-]: the fit's form and the steering channel's scale error weigh differently at
different speeds and curves (at 40 km/h the front's kinematic steer is large). Measured on six
car/tyre/receiver combinations × six everyday drives of one tyre each (40–90 km/h, 0.8–3.5°
road-wheel angle): the front axle's drive slopes scattered 1.7–3.8 % beyond their standard
errors, the rear's within them. Part of each drive's σ in the consistency test."""
CONSISTENCY_P = 0.0455
"""The drives disagree when their χ² across drives exceeds its quantile at 1 − this (the
two-sided 2σ level of a normal variable) [-]."""


def _first_coefficient(
    sums: list[DriveSums], min_bins: int, second: list[float] | None = None
) -> tuple[float, float, int] | None:
    """The first coefficient of the drives' combined two-regressor fit, its standard error
    relative to it (scaled by the reduced χ² when above 1) and the bins; None with fewer than
    *min_bins* bins, a singular fit or a coefficient that is not positive. *second*, when
    given, receives the second coefficient.
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
    if second is not None:
        second.append(float(beta[1]))
    return first, float(np.sqrt(cov[0, 0] * red)) / first, n


def _per_drive(sums: list[DriveSums], second: float) -> tuple[np.ndarray, np.ndarray]:
    """Each drive's own first coefficient with the combined fit's second held, and its standard
    error (scaled by the drive's own reduced χ² when above 1, with :data:`DRIVE_FORM_REL`): the
    same normal equations as the combination.
    """
    val, sd = np.full(len(sums), np.nan), np.full(len(sums), np.nan)
    for i, d in enumerate(sums):
        a, b, yy = d.sums[:4].reshape(2, 2), d.sums[4:6], d.sums[6]
        if not (np.isfinite(d.sums).all() and a[0, 0] > 0):
            continue
        v = (b[0] - a[0, 1] * second) / a[0, 0]
        beta = np.array([v, second])
        chi2 = float(yy - 2 * beta @ b + beta @ a @ beta)
        red = max(chi2 / max(d.bins - 2, 1), 1.0)
        val[i], sd[i] = v, np.hypot(np.sqrt(red / a[0, 0]), DRIVE_FORM_REL * v)
    return val, sd


def _mean(val: np.ndarray, sd: np.ndarray) -> tuple[float, float]:
    """Weighted mean and its standard error."""
    w = 1.0 / sd**2
    return float(np.sum(w * val) / np.sum(w)), float(1.0 / np.sqrt(np.sum(w)))


def _agreement(
    sums: list[DriveSums],
    second: float,
    slope: float,
    se: float,
    other: float,
    declared: float,
    axle: str,
    earlier: frozenset[str],
) -> tuple[float, str]:
    """Whether the drives (and, with *earlier*, the file's earlier drives and the new ones)
    agree on the slope: the statistical relative error to use (*se*, Birge-scaled and widened
    where they disagree) and the line that says so (``""`` when they agree).

    *other* is the relative 1σ the learned stiffness has besides the statistical (the axle
    force's scale and the fit's form), *declared* the vehicle file's stiffness (the reference of
    the slopes) [N/rad].
    """
    val, sd = _per_drive(sums, second)
    ok = np.isfinite(val) & np.isfinite(sd) & (sd > 0)
    if ok.sum() < 2:
        return se, ""
    files = [d.file or d.sha256[:8] for d, k in zip(sums, ok, strict=True) if k]
    val, sd = val[ok], sd[ok]
    new = np.array([d.sha256 not in earlier for d, k in zip(sums, ok, strict=True) if k])
    m, m_sd = _mean(val, sd)
    chi2 = float(np.sum(((val - m) / sd) ** 2))
    dof = val.size - 1
    drives_fail = bool(chi2_dist.sf(chi2, dof) < CONSISTENCY_P)
    groups = None
    if earlier and new.any() and (~new).any():
        (m_e, s_e), (m_n, s_n) = _mean(val[~new], sd[~new]), _mean(val[new], sd[new])
        z = abs(m_e - m_n) / float(np.hypot(s_e, s_n))
        if z > CONFLICT_SIGMAS and m_e > 0 and m_n > 0:
            groups = (m_e, s_e, m_n, s_n, z)
    if not drives_fail and groups is None:
        return se, ""
    birge = float(np.sqrt(chi2 / dof))
    se_new = se
    if drives_fail and m > 0:
        # the Birge ratio scales the part of the error the drives' scatter measures (the mean
        # of their slopes with the curvature held); the curvature's part stays as it is
        se_new = float(np.sqrt(se**2 + (birge**2 - 1.0) * (m_sd / m) ** 2))
    # cover (in ln C, as apply_calibration reads the relative 1σ): no drive more than 2
    # combined σ from the combination, both learnings within its 2σ
    need = 0.0
    pos = val > 0
    z_i = np.abs(val - slope) / sd
    if pos.any():
        d_ln = np.abs(np.log(val[pos] / slope))
        s_ln = sd[pos] / val[pos]
        need = float(np.sqrt(np.maximum(d_ln**2 / 4.0 - s_ln**2, 0.0)).max())
    if groups is not None:
        need = max(need, abs(np.log(groups[0] / slope)) / 2, abs(np.log(groups[2] / slope)) / 2)
        for part in (
            [d for d in sums if d.sha256 in earlier],
            [d for d in sums if d.sha256 not in earlier],
        ):  # and each learning as it stands alone (its own curvature)
            alone = _first_coefficient(part, 6)
            if alone is not None:
                need = max(need, abs(np.log(alone[0] / slope)) / 2)
    u_need = float(np.expm1(need))
    if u_need**2 > se_new**2 + other**2:
        se_new = float(np.sqrt(u_need**2 - other**2))
    total = float(np.hypot(se_new, other))
    c = declared / slope
    order = np.argsort(-z_i)  # the drives that disagree most first
    # the drives beyond 2σ of the combination; none alone: the two that disagree most
    odd = [files[i] for i in order if z_i[i] > CONFLICT_SIGMAS] or [files[i] for i in order[:2]]
    plain = float(np.hypot(se, other))

    def used(cover: str) -> str:
        if total > plain + 5e-4:
            return (
                f"used: the combined {_n(c)} N/rad, its uncertainty widened from "
                f"± {100 * plain:.1f} % to ± {100 * total:.1f} % so that {cover}"
            )
        return f"used: the combined {_n(c)} N/rad ± {100 * total:.1f} % ({cover} already)"

    if groups is not None:
        m_e, s_e, m_n, s_n, z = groups
        return se_new, (
            f"{axle} axle: the new drives' learning {_n(declared / m_n)} N/rad "
            f"± {100 * s_n / m_n:.1f} % and the file's earlier drives' {_n(declared / m_e)} "
            f"N/rad ± {100 * s_e / m_e:.1f} % disagree ({z:.1f}σ apart; a tyre change? a new "
            f"calibration from the new drives alone keeps them apart); "
            f"{used('both lie within its 2σ')} (drives that disagree most: {', '.join(odd[:4])})"
        )
    parts = [
        f"{files[i]} {_n(declared / val[i])} N/rad ± {100 * sd[i] / val[i]:.0f} %"
        if val[i] > 0
        else f"{files[i]} (no value)"
        for i in order[: min(len(odd), 4)]
    ]
    return se_new, (
        f"{axle} axle: the drives disagree (χ² {chi2:.1f} on {dof} degrees of freedom, Birge "
        f"ratio {birge:.1f}): {'; '.join(parts)} against the combined {_n(c)} N/rad; "
        f"{used('every drive lies within 2 combined σ of it')}"
    )


def _n(x: float) -> str:
    """A stiffness for a message: whole N/rad with a thin space between thousands."""
    return f"{x:,.0f}".replace(",", " ")


def solve_sums(
    sums: list[DriveSums],
    declared_N_per_rad: float,
    *,
    earlier: frozenset[str] | set[str] = frozenset(),
    axle: str = "",
) -> AxleCalibration | None:
    """The learned stiffness from the combined sums of one axle's drives.

    Parameters
    ----------
    sums : list of DriveSums
        The drives' sums (one axle).
    declared_N_per_rad : float
        The vehicle file's stiffness of one wheel at the static load [N/rad].
    earlier : set of str
        SHA-256 of the drives an earlier calibration was learned from (``--update``): they and
        the new drives are two learnings, tested against each other.
    axle : str
        The axle's name, for the line that says the drives disagree (default: the sums').

    Returns
    -------
    AxleCalibration or None
        The learned stiffness at the static load and its relative 1σ (widened where the drives
        disagree, with ``drives_disagree`` saying so); None with fewer than six bins or
        without a change of the lateral force within a drive.
    """
    second: list[float] = []
    fit = _first_coefficient(sums, 6, second)
    if fit is None:
        return None
    slope, se, n = fit  # slope = 1 / s
    other = float(np.hypot(FORCE_SCALE_REL, FIT_FORM_REL))
    se, note = _agreement(
        sums, second[0], slope, se, other, declared_N_per_rad,
        axle or (sums[0].axle if sums else ""), frozenset(earlier),
    )  # fmt: skip
    return AxleCalibration(
        cornering_stiffness_N_per_rad=declared_N_per_rad / slope,
        stiffness_uncertainty=float(np.sqrt(se**2 + FORCE_SCALE_REL**2 + FIT_FORM_REL**2)),
        scale=1.0 / slope,
        bins=n,
        drives_disagree=note,
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


def declared_lever(vehicle: Vehicle) -> tuple[float, float] | None:
    """The steering lever the vehicle file declares, k (t_c + t₀) with k = 1, and its relative
    1σ (docs/physics.md §16.8): the caster trail and its 1σ, the zero-slip pneumatic trail
    (declared, the tyre file's, else a sixth of the contact length at the static load) with its
    relative 1σ, and the channel's scale (the torque's scale and the assist gain's share) — the
    priors the torque estimator gives a + b.

    Parameters
    ----------
    vehicle : Vehicle
        The vehicle (its ``[steering]``).

    Returns
    -------
    (float, float) or None
        The lever [m] and its relative 1σ [-]; None without a ``[steering]`` table.
    """
    s = vehicle.steering
    if s is None or "front" not in vehicle.tyres:
        return None
    t0 = s.pneumatic_trail_m
    if t0 is None and s.tyre_file:
        t0 = trail_family(vehicle).t0_m
    if t0 is None:
        tyre = vehicle.tyres["front"]
        t0 = float(tyre.contact_length(vehicle.static_load("front") / G0)) / 6.0
    lever = s.mechanical_trail_m + t0
    gain = s.assist_gain if s.assist == "linear" else 0.0
    scale = float(
        np.hypot(s.torque_scale_uncertainty, s.assist_gain_uncertainty * gain / (1 + gain))
    )
    sd = float(
        np.sqrt(
            s.mechanical_trail_uncertainty_m**2
            + (t0 * s.pneumatic_trail_uncertainty) ** 2
            + (lever * scale) ** 2
        )
    )
    return (lever, sd / lever) if lever > 0 else None


def lever_conflict(vehicle: Vehicle, learned: SteeringCalibration) -> str:
    """The line that says a declared and a learned steering lever conflict, or ``""``: more
    than 2 combined σ apart in ln S, as the stiffness
    (:func:`gripsense.config.calibration.stiffness_conflict`).

    Parameters
    ----------
    vehicle : Vehicle
        The vehicle as its file declares it.
    learned : SteeringCalibration
        The learned lever.

    Returns
    -------
    str
        One line naming both values with their σ and which is used.
    """
    d = declared_lever(vehicle)
    if d is None or not learned.lever_m > 0:
        return ""
    s_d, u_d = d
    sd = float(np.hypot(np.log1p(u_d), np.log1p(learned.lever_uncertainty)))
    z = abs(float(np.log(learned.lever_m / s_d))) / sd
    if not z > CONFLICT_SIGMAS:
        return ""
    return (
        f"steering lever: the vehicle file's [steering] declares {1e3 * s_d:.1f} mm "
        f"± {100 * u_d:.0f} % (caster + zero-slip pneumatic trail) and the learned "
        f"{1e3 * learned.lever_m:.1f} mm ± {100 * learned.lever_uncertainty:.1f} % disagree "
        f"({z:.1f}σ apart); used: the learned {1e3 * learned.lever_m:.1f} mm (the declared "
        "trails scaled to meet it, no blend)"
    )


def use_learned_lever(vehicle: Vehicle, notes: list[str] | None = None) -> Vehicle:
    """The vehicle whose declared trails meet its learned steering lever where the two
    conflict (:func:`lever_conflict`): the caster trail, its 1σ and the zero-slip pneumatic
    trail scaled by learned / declared, so that the torque estimator's trail priors and the
    learned constraint agree and the lever used is the learned one, not their blend.

    Parameters
    ----------
    vehicle : Vehicle
        The vehicle with its calibration applied (``[steering]`` with ``calibrated_lever_m``).
    notes : list of str, optional
        Receives the conflict's line.

    Returns
    -------
    Vehicle
        As given where there is no learned lever or no conflict.
    """
    s = vehicle.steering
    if s is None or s.calibrated_lever_m is None or s.calibrated_lever_uncertainty is None:
        return vehicle
    learned = SteeringCalibration(s.calibrated_lever_m, s.calibrated_lever_uncertainty, 0)
    line = lever_conflict(vehicle, learned)
    d = declared_lever(vehicle)
    if not line or d is None:
        return vehicle
    if notes is not None:
        notes.append(line)
    r = learned.lever_m / d[0]
    t0 = d[0] - s.mechanical_trail_m
    steering = dataclasses.replace(
        s,
        mechanical_trail_m=s.mechanical_trail_m * r,
        mechanical_trail_uncertainty_m=s.mechanical_trail_uncertainty_m * r,
        pneumatic_trail_m=t0 * r,
    )
    return dataclasses.replace(vehicle, steering=steering)
