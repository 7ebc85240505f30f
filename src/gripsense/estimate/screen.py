"""The cornering screen of ``axle-window``: which bins show cornering the compass resolves.

A window is analysed when its slip angle and its lateral acceleration both stand clear of their
noise (``docs/physics.md`` §15.2), whatever the grip they amount to: on ice (μ 0.1) a car at
its limit corners at 0.1 g with slip angles of 0.4–1.5°, which a compass resolves over a
window, while a straight driven with a noisy receiver shows neither. The batch
(:mod:`gripsense.estimate.axle_window`) and the online estimator
(:mod:`gripsense.estimate.online`) use the same rule.
"""

from __future__ import annotations

import numpy as np

from gripsense.estimate.noise import NoiseModel

__all__ = [
    "offset_residual_rad",
    "resolvable",
    "resolvable_bins",
    "resolvable_steady",
    "steady_runs",
]


def offset_residual_rad(noise: NoiseModel) -> float:
    """1σ of the heading offset that the calibration leaves in every slip angle [rad]: the
    calibration's own standard error with 0.03° for straights that are not quite straight, or,
    uncalibrated, half the receiver's white heading noise (at least 0.02°) — the floor of the
    profile's slip-offset prior (``docs/physics.md`` §15.3).

    Parameters
    ----------
    noise : NoiseModel
        The run's noise model (``heading_calibration_deg`` set by the run's calibration).

    Returns
    -------
    float
        The residual's 1σ [rad].
    """
    cal = noise.heading_calibration_deg
    if cal is None:
        return float(np.deg2rad(max(0.5 * noise.heading_white_deg, 0.02)))
    return float(np.deg2rad(np.hypot(cal, 0.03)))


def resolvable(
    data: np.ndarray,
    grip_sigma: np.ndarray,
    noise: NoiseModel,
    z: float,
    grip_floor: float = np.inf,
    *,
    signed: bool = False,
) -> np.ndarray:
    """Windows of bins whose cornering the compass resolves, whatever the grip.

    The screen (``docs/physics.md`` §15.2):

    ᾱ_lin ≥ z √(Σ σ_α,i² / m² + σ_cal²)  and  |ā_y| / g ≥ z √(Σ σ_grip,i²) / m,

    over the window's m bins: ᾱ_lin is the mean of |F| / (C_L + C_R), the slip angle the
    measured axle force needs at the declared stiffness — the least slip of any tyre curve
    below its tangent, so a window passes only where the true slip clears the noise; σ_α,i
    a bin's white slip noise (heading and course noise over √n: the course noise σ_v / U grows
    at low speed), σ_cal the heading calibration's residual (:func:`offset_residual_rad`),
    ā_y the mean lateral acceleration and σ_grip,i a bin's measured-grip noise. The slip test
    reads the force, not the measured slip: selecting windows on their noisy slip would keep
    those whose noise enlarged it. The receiver's slow heading error is not counted: the
    profile fits it as a nuisance.

    Parameters
    ----------
    data : numpy.ndarray
        Bins, (n_windows, m, n_columns) in :data:`~gripsense.estimate.bins.BIN_COLUMNS` order
        (a single bin per window: m = 1) [SI].
    grip_sigma : numpy.ndarray
        1σ of each bin's measured grip, (n_windows, m) [-].
    noise : NoiseModel
        The run's noise model.
    z : float
        How many 1σ the slip and the lateral acceleration must clear [-].
    grip_floor : float
        A window whose largest measured grip reaches this passes too
        (``WindowOptions.screen_utilisation``) [-].
    signed : bool
        ᾱ_lin from the window's mean signed force, |mean(F / (C_L + C_R))|, instead of the mean
        of each bin's |F|: for a steady stretch (one sign), whose many bins would otherwise
        sum the force noise's rectified mean, which does not average away.

    Returns
    -------
    numpy.ndarray
        bool per window.
    """
    data = np.asarray(data, dtype=float)
    if data.shape[0] == 0:
        return np.zeros(0, dtype=bool)
    m = data.shape[1]
    lin = data[..., 6] / (data[..., 4] + data[..., 5])
    slip = np.abs(np.mean(lin, axis=1)) if signed else np.mean(np.abs(lin), axis=1)
    sig_slip = np.hypot(np.sqrt(np.sum(data[..., 8] ** 2, axis=1)) / m, offset_residual_rad(noise))
    sig_ay = np.sqrt(np.sum(np.asarray(grip_sigma, dtype=float) ** 2, axis=1)) / m
    ok = (slip >= z * sig_slip) & (np.abs(np.mean(data[..., 10], axis=1)) >= z * sig_ay)
    return ok | (np.max(data[..., 9], axis=1) >= grip_floor)


def resolvable_bins(
    data: np.ndarray,
    grip_sigma: np.ndarray,
    noise: NoiseModel,
    z: float,
    grip_floor: float = np.inf,
) -> np.ndarray:
    """:func:`resolvable` of each bin on its own (a window of one bin).

    Parameters
    ----------
    data : numpy.ndarray
        Bins, (n_bins, n_columns) [SI].
    grip_sigma : numpy.ndarray
        1σ of each bin's measured grip [-].
    noise : NoiseModel
        The run's noise model.
    z : float
        How many 1σ the slip and the lateral acceleration must clear [-].
    grip_floor : float
        A bin whose measured grip reaches this passes too [-].

    Returns
    -------
    numpy.ndarray
        bool per bin.
    """
    data = np.asarray(data, dtype=float)
    gs = np.asarray(grip_sigma, dtype=float)[:, None]
    return resolvable(data[:, None, :], gs, noise, z, grip_floor)


def steady_runs(
    t0: np.ndarray, t1: np.ndarray, grip: np.ndarray, tol: float, gap_s: float
) -> list[np.ndarray]:
    """Runs of consecutive bins that are one steady state: each bin starts within *gap_s* of
    the previous one's end and its measured grip stays within *tol* of the run's first bin
    (the rule of :func:`~gripsense.estimate.bins.merge_steady`, on the grip alone: selecting
    on the slip would keep the runs whose noise enlarged it).

    Parameters
    ----------
    t0, t1 : numpy.ndarray
        Bin start and end [s].
    grip : numpy.ndarray
        Each bin's measured grip [-].
    tol : float
        Largest change of measured grip within a run [-].
    gap_s : float
        Largest gap between a bin's end and the next one's start [s].

    Returns
    -------
    list of numpy.ndarray
        The bin indices of each run, in time order (every bin in exactly one run).
    """
    t0, t1, grip = (np.asarray(x, dtype=float) for x in (t0, t1, grip))
    runs: list[np.ndarray] = []
    start = 0
    for i in range(1, t0.size + 1):
        if i == t0.size or t0[i] - t1[i - 1] > gap_s or not abs(grip[i] - grip[start]) <= tol:
            runs.append(np.arange(start, i))
            start = i
    return runs


def resolvable_steady(
    data: np.ndarray,
    grip_sigma: np.ndarray,
    t0: np.ndarray,
    t1: np.ndarray,
    noise: NoiseModel,
    z: float,
    tol: float,
    gap_s: float,
    min_bins: int,
) -> np.ndarray:
    """Bins of steady stretches whose cornering the compass resolves over the whole stretch.

    A steady stretch (:func:`steady_runs`) is one point of the tyre curve, and its bins' white
    slip noise averages over all of them: :func:`resolvable` of the stretch as one window of m
    bins, σ_α,white / √m against the calibration's residual (``docs/physics.md`` §15.2). On ice
    (μ 0.1, 0.08 g) a car's slip of 0.2–0.3° is below 3σ of a 3 s window's noise with a 0.3°
    compass, and resolved over a 25 s circle once the mounting offset is known.

    Parameters
    ----------
    data : numpy.ndarray
        Bins, (n_bins, n_columns) in :data:`~gripsense.estimate.bins.BIN_COLUMNS` order [SI].
    grip_sigma : numpy.ndarray
        1σ of each bin's measured grip [-].
    t0, t1 : numpy.ndarray
        Bin start and end [s].
    noise : NoiseModel
        The run's noise model.
    z : float
        How many 1σ the slip and the lateral acceleration must clear [-].
    tol : float
        Largest change of measured grip within a stretch (``WindowOptions.steady_tolerance``) [-].
    gap_s : float
        Largest gap between consecutive bins of a stretch [s].
    min_bins : int
        Fewest bins of a stretch (a window's: shorter ones are the windows' and bins' business)
        [-].

    Returns
    -------
    numpy.ndarray
        bool per bin: in a stretch that passes.
    """
    data = np.asarray(data, dtype=float)
    gs = np.asarray(grip_sigma, dtype=float)
    ok = np.zeros(data.shape[0], dtype=bool)
    if data.shape[0] == 0:
        return ok
    for run in steady_runs(t0, t1, data[:, 9], tol, gap_s):
        if (
            run.size >= max(min_bins, 1)
            and resolvable(data[run][None], gs[run][None], noise, z, signed=True)[0]
        ):
            ok[run] = True
    return ok
