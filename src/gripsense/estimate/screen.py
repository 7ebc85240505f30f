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

__all__ = ["offset_residual_rad", "resolvable", "resolvable_bins"]


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

    Returns
    -------
    numpy.ndarray
        bool per window.
    """
    data = np.asarray(data, dtype=float)
    if data.shape[0] == 0:
        return np.zeros(0, dtype=bool)
    m = data.shape[1]
    slip = np.mean(np.abs(data[..., 6]) / (data[..., 4] + data[..., 5]), axis=1)
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
