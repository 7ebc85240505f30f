"""``axle-window``: per axle, the friction the data prove (model-free) and an estimate of μ whose
interval includes the tyre model's own form uncertainty.

Two kinds of statement (``docs/physics.md`` §14, §15):

* **measured grip** — the friction the axle actually used, |F_axle| / Fz_axle, from the lateral
  acceleration with the yaw-acceleration term; the axle's load is known from statics, so
  ``grip_used_lower`` (a one-sided 99 % lower bound) holds for any tyre and any lateral load
  transfer; it assumes a level road without aerodynamic downforce;
* **estimated μ** — a profile-likelihood interval of μ under a tyre model with nuisances: the
  curve's shape (brush P2/P4 and Magic Formula curves, :data:`~gripsense.physics.tyre_curves.
  SHAPE_FAMILY`), a cornering-stiffness scale, a slip offset per bin that follows the receiver's
  slowly varying heading error (a Gauss–Markov process), a
  camber-thrust slip shift per g, an error of the lateral load transfer (CG height, roll split),
  of the load sensitivity of the stiffness and of the axle force. Nuisances enter linearly after
  linearisation and are profiled by a few Gauss–Newton steps (:mod:`._axle_kernel`), so the cost
  does not grow with their number; the shape is profiled over the family.

Data: bins of ``bin_s`` (means of the samples: slip angles lagged by the relaxation length,
loads, stiffnesses, axle force; white noise divided by n). A window is ``window_s`` of bins
sharing their nuisances; a window whose measured grip stays below ``screen_utilisation`` carries
no information on μ (its interval would be unbounded, ``docs/physics.md`` §1.4) and is not
analysed. The per-axle summary uses every analysed bin of the drive, nuisances shared. A value
is reported only when the ``point_level`` interval is bounded and narrower than ``max_width``;
otherwise the interval [mu_low, ∞) and the measured grip.
"""

from __future__ import annotations

import itertools
from collections import deque
from dataclasses import dataclass
from functools import cache

import numpy as np
import pandas as pd
from scipy.stats import chi2, norm

from gripsense.config import Vehicle
from gripsense.constants import CHI2_1_90, G0
from gripsense.estimate import _axle_kernel as K
from gripsense.estimate.noise import NoiseModel
from gripsense.physics.friction_limit import linear_explains
from gripsense.physics.tyre_curves import SHAPE_FAMILY, curve_tables

__all__ = [
    "BIN_COLUMNS",
    "WINDOW_COLUMNS",
    "AxleBins",
    "OnlineAxleWindow",
    "WindowOptions",
    "axle_bins",
    "estimate_windows",
    "force_and_linear",
    "measured_grip",
    "merge_steady",
]

# bin array columns (the kernel's layout)
BIN_COLUMNS = (
    "alpha_L",
    "alpha_R",
    "fz_L",
    "fz_R",
    "c_L",
    "c_R",
    "force",
    "force_sigma",
    "slip_sigma",
    "grip",
    "ay_g",
    "fz_static",
    "steer",
    "slip_spread",
    "force_model_sd",
)
FORCE_MODEL_REL = 0.04
"""Relative 1σ of a bin's force that no curve of the family reproduces (tyre-model fidelity)."""
STRAINED_REL = 0.02
"""A model interval whose upper end lies within this fraction above the measured-grip bound is
strained: its range would be (nearly) zero-width, narrower than the force model's own fidelity
(:data:`FORCE_MODEL_REL`), so the upper end is dropped and the fit flagged ``strained``."""
_OUT = ("low_speed", "not_cornering", "wheel_lifted")


@dataclass(frozen=True)
class WindowOptions:
    """Settings of the ``axle-window`` estimator.

    Attributes
    ----------
    window_s, step_s : float
        Window length and step [s].
    bin_s : float
        Bin length: the unit of data (means of the samples) [s].
    max_width : float
        Largest width of the ``point_level`` interval for which a value is given [-].
    point_level : float
        Confidence level of the interval that decides abstention.
    min_samples : int
        Fewest usable samples in a bin.
    screen_utilisation : float
        Windows whose measured grip stays below this are not analysed (bound only) [-].
    steady_tolerance : float
        Consecutive bins whose measured grip stays within this are merged into one point of the
        tyre curve (:func:`merge_steady`) [-].
    mu_min, mu_max : float
        μ grid range [-]; an interval reaching mu_max is unbounded.
    n_mu : int
        μ grid size (log-spaced).
    iterations : int
        Gauss–Newton steps per (μ, shape).
    bound_level : float
        One-sided confidence of the measured-grip bound (per window; the summary's bound holds
        at this level over all windows of the drive together).
    min_utilisation : float
        A value is given only when the measured-grip bound is at least this fraction of the
        interval's upper end (data near the limit) [-].
    """

    window_s: float = 3.0
    step_s: float = 1.0
    bin_s: float = 1.0
    max_width: float = 0.3
    point_level: float = 0.99
    min_samples: int = 5
    screen_utilisation: float = 0.15
    steady_tolerance: float = 0.03
    mu_min: float = 0.05
    mu_max: float = 3.0
    n_mu: int = 48
    iterations: int = 3
    bound_level: float = 0.99
    min_utilisation: float = 0.5


@cache
def _tables():
    x, f, df = curve_tables()
    return f, df, 1.0 / (x[1] - x[0])


SHAPE_PRIOR_PEAK = (2.9, 0.35)
"""Prior of a curve's peak position: ln x_peak ~ N(ln 2.9, 0.35²) — the nine example ``.tir``
files of ``tests/data/tyre/tir`` peak at x = 2.2–3.6 (brush P2 at 3, brush P4 at 5)."""


def _shape_ids(prior: str) -> np.ndarray:
    kinds = {"any": None, "brush": ("brush-2", "brush-4"), "magic-formula": ("magic-formula",)}
    allowed = kinds.get(prior)
    return np.array(
        [i for i, s in enumerate(SHAPE_FAMILY) if allowed is None or s.kind in allowed],
        dtype=np.int64,
    )


@cache
def _shape_penalty() -> np.ndarray:
    """−log prior weight of every shape of the family (:data:`SHAPE_PRIOR_PEAK`)."""
    x, f, _ = curve_tables()
    x_peak = x[np.argmax(f, axis=1)]
    z = (np.log(x_peak) - np.log(SHAPE_PRIOR_PEAK[0])) / SHAPE_PRIOR_PEAK[1]
    return 0.5 * z * z


@dataclass
class AxleBins:
    """The bins of one axle (see the module documentation).

    Attributes
    ----------
    axle : str
        ``front`` or ``rear``.
    t0, t1 : numpy.ndarray
        Bin start and end [s].
    n : numpy.ndarray
        Samples per bin.
    data : numpy.ndarray
        (n_bins, 14) in :data:`BIN_COLUMNS` order: slips [rad], loads [N], stiffnesses [N/rad],
        axle force [N] and its white 1σ [N], slip white 1σ [rad], measured grip [-], a_y/g
        [-], static wheel load [N], road-wheel steer angle [rad] (0 on the rear axle), the
        slip's spread within the bin beyond its white noise [rad], the 1σ of the force the
        model cannot represent [N] (:data:`FORCE_MODEL_REL` of it, the steered axle's
        (1 − cos δ), and the force's own spread within the bin beyond its noise — a transient).
    grip_sigma : numpy.ndarray
        1σ of the measured grip of each bin [-].
    p0 : float
        Local load-sensitivity exponent of the declared stiffness [-].
    """

    axle: str
    t0: np.ndarray
    t1: np.ndarray
    n: np.ndarray
    data: np.ndarray
    grip_sigma: np.ndarray
    p0: float


_PAIR_COLUMNS = (
    "t_s",
    "slip_angle_rad",
    "load_N",
    "cornering_stiffness_N_per_rad",
    "force_sigma_N",
    "slip_sigma_rad",
    "speed_mps",
    "axle_force_N",
    "grip_used",
    "grip_sigma",
    "lateral_accel_mps2",
)


def axle_pairs(wheels: pd.DataFrame, axle: str) -> dict[str, np.ndarray]:
    """The usable samples of one axle: left and right wheel joined on the epoch (both present,
    cornering, positive loads, every number finite), in time order.

    Parameters
    ----------
    wheels : pandas.DataFrame
        Wheel table (:func:`gripsense.estimate.friction.friction_from_motion`).
    axle : str
        ``front`` or ``rear``.

    Returns
    -------
    dict of numpy.ndarray
        ``<column>_L`` and ``<column>_R`` for the columns the bins use (``steer_rad_L`` on a
        front axle whose table has a steering channel), all of one length.
    """
    cols = list(_PAIR_COLUMNS)
    if "steer_rad" in wheels.columns and axle == "front":
        cols.append("steer_rad")
    wheel = wheels["wheel"]
    m_l = (wheel == f"{axle}_left").to_numpy()
    m_r = (wheel == f"{axle}_right").to_numpy()
    epoch = wheels["epoch"].to_numpy()
    _, i_l, i_r = np.intersect1d(epoch[m_l], epoch[m_r], return_indices=True)
    flag = wheels["flag"].to_numpy()
    ok = ~np.isin(flag[m_l][i_l], _OUT) & ~np.isin(flag[m_r][i_r], _OUT)
    out: dict[str, np.ndarray] = {}
    for c in cols:
        x = wheels[c].to_numpy(float)
        out[c + "_L"], out[c + "_R"] = x[m_l][i_l], x[m_r][i_r]
        ok &= np.isfinite(out[c + "_L"]) & np.isfinite(out[c + "_R"])
    order = np.argsort(out["t_s_L"][ok], kind="stable")
    return {c: x[ok][order] for c, x in out.items()}


def axle_bins(
    wheels: pd.DataFrame | dict[str, np.ndarray],
    axle: str,
    vehicle: Vehicle,
    noise: NoiseModel,
    bin_s: float = 1.0,
    min_samples: int = 5,
) -> AxleBins:
    """Bin the samples of one axle (both wheels present, cornering, positive loads).

    Parameters
    ----------
    wheels : pandas.DataFrame or dict of numpy.ndarray
        Wheel table (:func:`gripsense.estimate.friction.friction_from_motion`), or its usable
        samples of this axle from :func:`axle_pairs`.
    axle : str
        ``front`` or ``rear``.
    vehicle : Vehicle
        Vehicle description (static loads, tyre, relaxation length).
    noise : NoiseModel
        Measurement noise (slip and grip white noise).
    bin_s : float
        Bin length [s].
    min_samples : int
        Fewest samples in a bin.

    Returns
    -------
    AxleBins
        The bins.
    """
    b = axle_pairs(wheels, axle) if isinstance(wheels, pd.DataFrame) else wheels
    tyre = vehicle.tyres[axle]
    fzs = vehicle.static_load(axle)
    p0 = float(
        np.log(
            vehicle.cornering_stiffness(axle, 1.1 * fzs)
            / vehicle.cornering_stiffness(axle, 0.9 * fzs)
        )
        / np.log(1.1 / 0.9)
    )
    t = b["t_s_L"]
    if t.size == 0:
        return AxleBins(
            axle,
            np.zeros(0),
            np.zeros(0),
            np.zeros(0, int),
            np.zeros((0, len(BIN_COLUMNS))),
            np.zeros(0),
            p0,
        )
    # the tyre force lags the slip by σ/U: compare the force with the slip of σ/U earlier
    speed = b["speed_mps_L"]
    lag = tyre.relaxation_length_m / np.maximum(speed, 1.0)
    aL = np.interp(t - lag, t, b["slip_angle_rad_L"])
    aR = np.interp(t - lag, t, b["slip_angle_rad_R"])
    # bins on the data clock (not from the first sample): the live estimator forms the same
    k = np.floor(t / bin_s).astype(np.int64)
    # a gap in the data ends a bin
    k += np.concatenate([[0], np.cumsum(np.diff(t) > 0.5 * bin_s)])
    edges = np.flatnonzero(np.diff(k)) + 1
    starts = np.concatenate([[0], edges])
    n = np.diff(np.concatenate([starts, [t.size]]))

    def mean(x):
        return np.add.reduceat(x, starts) / n

    def rms_over_n(x):
        return np.sqrt(np.add.reduceat(x * x, starts) / n / n)

    force = b["axle_force_N_L"]
    steer = b["steer_rad_L"] if "steer_rad_L" in b else np.zeros(t.size)
    a_mid = 0.5 * (aL + aR)
    white = 0.5 * (b["slip_sigma_rad_L"] + b["slip_sigma_rad_R"])
    spread2 = np.add.reduceat(a_mid * a_mid, starts) / n - mean(a_mid) ** 2
    spread = np.sqrt(np.maximum(spread2 - np.add.reduceat(white * white, starts) / n, 0.0))
    # the axle force's spread within the bin beyond its white noise: in a transient the
    # yaw-acceleration term (ṙ from a ±0.5 s slope) and the tyre lag are resolved only roughly
    f_white = b["force_sigma_N_L"] + b["force_sigma_N_R"]
    f_spread2 = np.add.reduceat(force * force, starts) / n - mean(force) ** 2
    f_spread = np.sqrt(np.maximum(f_spread2 - np.add.reduceat(f_white**2, starts) / n, 0.0))
    ay = b["lateral_accel_mps2_L"] / G0
    data = np.column_stack(
        [
            mean(aL),
            mean(aR),
            mean(b["load_N_L"]),
            mean(b["load_N_R"]),
            mean(b["cornering_stiffness_N_per_rad_L"]),
            mean(b["cornering_stiffness_N_per_rad_R"]),
            mean(force),
            # white force noise only: the systematic axle-force error is the nuisance ε
            rms_over_n(f_white),
            rms_over_n(white),
            mean(b["grip_used_L"]),
            mean(ay),
            np.full(starts.size, fzs),
            mean(steer),
            spread,
            np.hypot(
                np.abs(mean(force)) * np.hypot(FORCE_MODEL_REL, 1.0 - np.cos(mean(steer))),
                f_spread,
            ),
        ]
    )
    # the measured grip's noise: white a_y noise / √n, and the lateral-velocity rate (a_y =
    # U r + V̇) whose noise is set by the side-slip noise v σ_ψ over the bin
    t_bin = np.maximum(np.maximum.reduceat(t, starts) - t[starts], 0.5 * bin_s)
    sig_v_lat = mean(speed) * np.deg2rad(noise.heading_white_deg)
    grip_sigma = np.hypot(
        rms_over_n(b["grip_sigma_L"]),
        2.0 * sig_v_lat / (t_bin + 1.0) / np.sqrt(np.maximum(n / 2, 1)) / G0,
    )
    keep = n >= min_samples
    t_end = np.maximum.reduceat(t, starts)
    return AxleBins(axle, t[starts][keep], t_end[keep], n[keep], data[keep], grip_sigma[keep], p0)


@dataclass(frozen=True)
class _Priors:
    mean: np.ndarray  # ln s, κ, λ, q, ε
    sd: np.ndarray
    delta: float  # slip offset [rad]
    tau_s: float  # its correlation time [s]


def _priors(vehicle: Vehicle, axle: str, noise: NoiseModel) -> _Priors:
    tyre = vehicle.tyres[axle]
    s_rel = max(noise.tread_stiffness_rel, 1e-3)
    # camber thrust: body roll (gradient, deg/g) leans the wheels (gain) and the thrust needs
    # a slip of |C_γ/C_α| × inclination to balance: an effective slip shift per g
    kap0 = np.deg2rad(
        tyre.camber_thrust_ratio * vehicle.roll_camber_gain * vehicle.roll_gradient_deg_per_g
    )
    lam_sd = max(noise.load_transfer_rel, 0.02)
    # slip offsets: what the heading calibration left (constant) and the slow error's drift
    # (a Gauss–Markov process, widened by slow_error_margin: real heading errors have heavier
    # tails than a Gaussian, and slip drift at constant force must not pass for saturation)
    floor = np.deg2rad(max(0.5 * noise.heading_white_deg, 0.02))
    # the calibration's own standard error when the offset was calibrated on straights (the
    # white noise averaged over them, and ~0.03° for straights that are not quite straight);
    # a longer straight or a better receiver then narrows the prior instead of a fixed floor
    cal = noise.heading_calibration_deg
    floor_cal = floor if cal is None else np.deg2rad(float(np.hypot(cal, 0.03)))
    sd_cal = max(np.deg2rad(noise.heading_slow_deg), floor_cal)
    # the drift is the declared slow error's (a receiver declared better than its data are is
    # caught by the fit check); a small floor for a receiver declared without one
    floor_drift = np.deg2rad(max(0.1 * noise.heading_white_deg, 0.02))
    sd_drift = max(np.deg2rad(noise.slow_error_margin * noise.heading_slow_deg), floor_drift)
    # a steered axle's body-axis force is F_y cos δ + F_x sin δ: undriven (F_x ≈ 0) F_y = F/cos δ,
    # driven, roughly F cos δ (the drive force balances the turn's drag); the drive force is not
    # measured, so the exponent d of cos^d δ is a nuisance around 0 (±1)
    d0, d_sd = (0.0, 1.0) if axle == "front" else (0.0, 1e-3)
    mean = np.array([0.0, kap0, 0.0, 0.0, 0.0, 0.0, 0.0, tyre.friction_load_sensitivity, d0])
    sd = np.array(
        [
            np.log1p(s_rel),
            max(kap0, np.deg2rad(0.2)),
            lam_sd,
            max(tyre.load_sensitivity_uncertainty, 1e-3),
            max(noise.axle_force_rel, 1e-3),
            sd_cal,
            max(noise.steer_scale_rel, 1e-3),
            max(tyre.friction_load_sensitivity_uncertainty, 1e-3),
            d_sd,
        ]
    )
    return _Priors(mean, sd, sd_drift, noise.heading_slow_tau_s)


def _crossing(x: np.ndarray, y: np.ndarray, level: float, i_from: int, step: int) -> float:
    i = i_from
    while 0 <= i + step < x.size:
        j = i + step
        if y[j] > level:
            f = (level - y[i]) / (y[j] - y[i])
            return float(np.exp(np.log(x[i]) + f * (np.log(x[j]) - np.log(x[i]))))
        i = j
    return float("inf") if step > 0 else float(x[0])


_NOISE_COLS = np.array([7, 8], dtype=np.int64)  # white-noise σ of a bin's slip and force


def merge_steady(
    t0: np.ndarray, t1: np.ndarray, n: np.ndarray, data: np.ndarray, tol: float
) -> tuple[np.ndarray, np.ndarray]:
    """Merge runs of consecutive bins whose measured grip stays within *tol* of the run's first
    bin into one bin (means weighted by the sample count; white noise combined).

    In steady cornering every bin shows the same force, so slip differences between its bins
    are measurement error: kept apart they would let a tyre at its limit (whose force does not
    depend on slip) explain them for free. Merged, a steady stretch is one point of the tyre
    curve, and only changes of utilisation (transients) trace the curve.

    Parameters
    ----------
    t0, t1 : numpy.ndarray
        Bin start and end [s].
    n : numpy.ndarray
        Samples per bin.
    data : numpy.ndarray
        Bins in :data:`BIN_COLUMNS` order.
    tol : float
        Largest change of measured grip within a merged run [-].

    Returns
    -------
    mid : numpy.ndarray
        Mid time of each merged bin [s].
    merged : numpy.ndarray
        The merged bins.
    """
    if data.shape[0] == 0:
        return np.zeros(0), data
    return K.merge_runs(
        np.ascontiguousarray(t0, dtype=float),
        np.ascontiguousarray(t1, dtype=float),
        np.ascontiguousarray(n, dtype=float),
        np.ascontiguousarray(data, dtype=float),
        float(tol),
        _NOISE_COLS,
    )


def _rho(t0: np.ndarray, tau_s: float) -> np.ndarray:
    """Correlation of the slow heading error between consecutive bins (0 after the last)."""
    rho = np.zeros(t0.size)
    if t0.size > 1:
        rho[:-1] = np.exp(-np.maximum(np.diff(t0), 1e-3) / tau_s)
    return rho


@cache
def _chi2_ppf(q: float, dof: int) -> float:
    """χ² quantile, computed once per (q, dof): scipy's ppf costs ~0.15 ms a call."""
    return float(chi2.ppf(q, dof))


@cache
def _mu_grid(mu_min: float, mu_max: float, n: int) -> np.ndarray:
    """The fine μ grid of the profile (read-only, shared between windows)."""
    g = np.geomspace(mu_min, mu_max, n)
    g.flags.writeable = False
    return g


def force_and_linear(data: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Per bin the axle force per load y = F / (Fz_L + Fz_R) and the declared stiffness's
    linear prediction k = −(C_L tan α_L + C_R tan α_R) / (Fz_L + Fz_R) (``docs/physics.md``
    §15.7; y = k for a linear tyre at the declared stiffness, ISO signs).

    Parameters
    ----------
    data : numpy.ndarray
        Bins in :data:`BIN_COLUMNS` order.

    Returns
    -------
    y, k : numpy.ndarray
        Force per load and linear prediction [-].
    """
    fz = data[:, 2] + data[:, 3]
    y = data[:, 6] / fz
    k = -(data[:, 4] * np.tan(data[:, 0]) + data[:, 5] * np.tan(data[:, 1])) / fz
    return y, k


def _linear_explains(bins: np.ndarray, pri: _Priors) -> bool:
    """Whether a linear tyre explains the bins within their 90 % noise (:func:`~gripsense.
    physics.friction_limit.linear_explains`): per bin the force per load, the declared linear
    prediction, and a tolerance from the force's noise and model fidelity and the slip's white
    noise, offset and drift.
    """
    if bins.shape[0] == 0:
        return False
    z = 1.645
    fz = bins[:, 2] + bins[:, 3]
    y, k = force_and_linear(bins)
    y, k = np.abs(y), np.abs(k)
    c_sum = bins[:, 4] + bins[:, 5]
    slip_sd = np.sqrt(bins[:, 8] ** 2 + pri.sd[5] ** 2 + pri.delta**2)
    tol = z * (np.hypot(bins[:, 7], bins[:, 14]) / fz + c_sum / fz * slip_sd)
    band = (float(np.exp(-z * pri.sd[0])), float(np.exp(z * pri.sd[0])))
    return linear_explains(y, k, band, tol)


def _profile(
    bins: np.ndarray,
    t0: np.ndarray,
    pri: _Priors,
    shapes: np.ndarray,
    p0: float,
    o: WindowOptions,
    grip_lower: float,
) -> dict:
    """The profile likelihood of μ and what it says."""
    f, df, inv_dx = _tables()
    fine = _mu_grid(float(o.mu_min), float(o.mu_max), int(o.n_mu))
    pen = np.ascontiguousarray(_shape_penalty()[shapes])
    b = np.ascontiguousarray(bins)
    n, m = b.shape[0], fine.size
    nll_f, th_f, dl_f = np.empty(m), np.empty((m, K.NG)), np.zeros((m, n))
    shp_f = np.empty(m, dtype=np.int64)
    # every μ of the grid, warm-started upwards (a coarser pass lets the nuisances fall behind:
    # docs/physics.md §15.3); the probe just above the measured grip bounds the minimum
    probe = float(np.clip(1.1 * b[:, 9].max(), fine[0], fine[-1])) if n else -1.0
    K.profile_grid(
        fine, shapes, pen, b, _rho(t0, pri.tau_s), pri.mean, pri.sd, pri.delta, f, df, inv_dx,
        p0, o.iterations, nll_f, th_f, dl_f, shp_f, np.inf, probe, K.STOP_ABOVE,
    )  # fmt: skip
    level = _chi2_ppf(float(o.point_level), 1)
    done = np.flatnonzero(np.isfinite(nll_f))
    mu_g, nll, th, dl, shp = fine[done], nll_f[done], th_f[done], dl_f[done], shp_f[done]
    n_mu = done.size
    dev = 2.0 * (nll - nll.min())
    im = int(np.argmin(nll))
    mu_hat = float(mu_g[im])
    if 0 < im < n_mu - 1:
        x0, x1, x2 = np.log(mu_g[im - 1 : im + 2])
        y0, y1, y2 = nll[im - 1 : im + 2]
        den = (x0 - x1) * (x0 - x2) * (x1 - x2)
        a = (x2 * (y1 - y0) + x1 * (y0 - y2) + x0 * (y2 - y1)) / den
        bq = (x2**2 * (y0 - y1) + x1**2 * (y2 - y0) + x0**2 * (y1 - y2)) / den
        if a > 0:
            mu_hat = float(np.exp(np.clip(-bq / (2 * a), x0, x2)))
    lo = _crossing(mu_g, dev, CHI2_1_90, im, -1)
    hi = _crossing(mu_g, dev, CHI2_1_90, im, +1)
    lo_p = _crossing(mu_g, dev, level, im, -1)
    hi_p = _crossing(mu_g, dev, level, im, +1)
    n_bins = bins.shape[0]
    z = (th[im] - pri.mean) / pri.sd
    fit = "ok"
    if 2.0 * nll[im] > _chi2_ppf(0.999, max(n_bins, 1)) + float(np.sum(z**2)):
        fit = "inconsistent"
    elif im == 0 or np.max(np.abs(z)) > 3.0 or np.max(np.abs(dl[im])) > 3.5 * pri.delta:
        fit = "edge"  # the data are explained only at the edge of what the priors allow
    observable = bool(fit == "ok" and np.isfinite(hi_p) and hi_p - lo_p <= o.max_width)
    # a value needs data near the limit: below utilisation ~0.5 every curve of the family is
    # nearly linear, so an interval bounded far above the measured grip comes from the model's
    # form (a nuisance degeneracy), not from the data
    far_from_limit = bool(
        np.isfinite(hi) and not (np.isfinite(grip_lower) and hi * o.min_utilisation <= grip_lower)
    )
    # no upper end where the physics allows none: a tyre still linear at every point, with a
    # stiffness inside the prior's 90 % band, explains the data within their noise (the
    # slip's white noise and offsets, the force's noise and the model's fidelity) — a finite
    # upper end there comes from a degeneracy of the other nuisances (docs/physics.md §15.8)
    if np.isfinite(hi) and _linear_explains(bins, pri):
        hi, hi_p, observable = np.inf, np.inf, False
        far_from_limit = False
    if far_from_limit:
        # no value: the interval's lower end is not trusted (far from the limit it can come
        # from a degeneracy of the nuisances), so the range starts at what the data prove; its
        # upper end stays — the data exclude a tyre that linear, and dropping it would say
        # less than the physics allows (docs/physics.md §15.5)
        lo, observable = (grip_lower if np.isfinite(grip_lower) else 0.0), False
    # a model interval that lies below what the data prove without a model contradicts itself
    strained = False
    if np.isfinite(grip_lower) and hi < grip_lower - 0.01:
        fit, observable = "inconsistent", False
    elif np.isfinite(grip_lower) and hi <= (1.0 + STRAINED_REL) * grip_lower:
        # the model's upper end reaches what the data prove: no curve of the family carries
        # the measured force with room to spare — the model is strained, its upper end is not
        # trusted (a zero-width or inverted range would be the result)
        strained, observable, hi, hi_p = True, False, np.inf, np.inf
        if fit == "ok":
            fit = "strained"
    names = (
        "stiffness",
        "camber",
        "load transfer",
        "load sensitivity",
        "axle force",
        "heading offset",
        "steering scale",
        "friction load sensitivity",
        "drive force on the steered axle",
    )
    limited = names[int(np.argmax(np.abs(z)))] if np.max(np.abs(z)) > 1.0 else "tyre shape"
    if strained:
        limited = "tyre model strained (its upper end reaches the measured grip)"
    elif not observable and fit == "ok" and far_from_limit:
        limited = (
            "too little lateral acceleration (the measured grip is below half of what the "
            "model would say: not near the limit)"
        )
    elif not observable and fit == "ok" and not np.isfinite(hi):
        limited = "too little lateral acceleration (shape and stiffness explain any μ above)"
    if np.isfinite(grip_lower):
        # the estimate never below what the data prove without a model
        mu_hat = max(mu_hat, float(grip_lower))
    return {
        "mu": mu_hat if observable else np.nan,
        "mu_low": float(max(lo, grip_lower)) if fit != "inconsistent" else np.nan,
        "mu_high": float(hi) if fit != "inconsistent" else np.nan,
        "observable": observable,
        "fit": fit,
        "mu_best": mu_hat,
        "stiffness_scale": float(np.exp(th[im, 0])),
        "heading_bias_deg": float(np.rad2deg(np.mean(dl[im]))),
        "camber_slip_deg_per_g": float(np.rad2deg(th[im, 1])),
        "load_transfer_error": float(th[im, 2]),
        "shape": SHAPE_FAMILY[int(shp[im])].name,
        "limited_by": limited,
    }


class _Reuse:
    """The previous window's answer, for a window whose merged data cannot be told apart from
    it: the same number of points, every slip within its white-noise 1σ, every force within
    its 1σ (a steady run seen through overlapping windows). Batch and online windows use it
    the same way, so they stay equal.
    """

    def __init__(self):
        self.data: np.ndarray | None = None
        self.est: dict | None = None

    def profile(self, merged, mid, pri, shapes, p0, o, lower) -> dict:
        d = self.data
        if (
            d is not None
            and d.shape == merged.shape
            and np.all(np.abs(d[:, :2] - merged[:, :2]) <= merged[:, 8:9])
            and np.all(np.abs(d[:, 6] - merged[:, 6]) <= merged[:, 7])
            and self.est["fit"] != "inconsistent"
        ):
            est = dict(self.est)
            if np.isfinite(lower):
                est["mu_low"] = max(est["mu_low"], lower)
                est["mu"] = max(est["mu"], lower) if est["observable"] else est["mu"]
            if not est["mu_high"] <= (1.0 + STRAINED_REL) * est["mu_low"]:
                return est
            # this window's bound strains the previous answer: its own profile decides
        est = _profile(merged, mid, pri, shapes, p0, o, lower)
        self.data, self.est = merged.copy(), est
        return dict(est)


def _bound(grip: np.ndarray, sigma: np.ndarray, z: float) -> float:
    """Largest one-sided lower bound over the bins (NaN without bins)."""
    if grip.size == 0:
        return np.nan
    return float(max(np.max(grip - z * sigma), 0.0))


def _drive_bound(ab: AxleBins, level: float) -> tuple[float, float]:
    """Largest bin mean of the measured grip and its bound over all bins of a drive (one-sided,
    Bonferroni over the bins so that the maximum holds at *level*).
    """
    n_b = ab.t0.size
    if n_b == 0:
        return np.nan, np.nan
    z_all = float(norm.ppf(1.0 - (1.0 - level) / n_b))
    return float(np.max(ab.data[:, 9])), _bound(ab.data[:, 9], ab.grip_sigma, z_all)


def measured_grip(
    wheels: pd.DataFrame,
    vehicle: Vehicle,
    *,
    noise: NoiseModel | None = None,
    options: WindowOptions | None = None,
) -> pd.DataFrame:
    """The friction each axle used, from measurements alone (``docs/physics.md`` §14).

    The axle's lateral force (m a_y share with the yaw-acceleration term) over its total load
    (statics: known for any lateral load transfer), in bins of ``bin_s``; ``grip_used_lower``
    is the largest bin's one-sided ``bound_level`` lower bound, corrected for the number of bins.
    It holds for any tyre; it assumes a level road without aerodynamic downforce.

    Parameters
    ----------
    wheels : pandas.DataFrame
        Wheel table of :func:`gripsense.estimate.friction.friction_from_motion`.
    vehicle : Vehicle
        Vehicle description.
    noise : NoiseModel, optional
        Measurement noise.
    options : WindowOptions, optional
        Bin length, fewest samples, bound level.

    Returns
    -------
    pandas.DataFrame
        Per axle: ``axle``, ``grip_used`` (largest bin mean) [-], ``grip_used_lower`` [-],
        ``n_bins``.
    """
    noise = noise or NoiseModel()
    o = options or WindowOptions()
    rows = []
    for axle in sorted({w.split("_")[0] for w in wheels["wheel"].astype(str).unique()}):
        ab = axle_bins(wheels, axle, vehicle, noise, o.bin_s, o.min_samples)
        g, lo = _drive_bound(ab, o.bound_level)
        rows.append({"axle": axle, "grip_used": g, "grip_used_lower": lo, "n_bins": ab.t0.size})
    return pd.DataFrame(rows, columns=["axle", "grip_used", "grip_used_lower", "n_bins"])


WINDOW_COLUMNS = {
    "axle": object,
    "t_start": float,
    "t_end": float,
    "n": np.int64,
    "grip_used": float,
    "grip_used_lower": float,
    "analysed": bool,
    "mu": float,
    "mu_low": float,
    "mu_high": float,
    "observable": bool,
    "fit": object,
    "mu_best": float,
    "stiffness_scale": float,
    "heading_bias_deg": float,
    "camber_slip_deg_per_g": float,
    "load_transfer_error": float,
    "shape": object,
    "limited_by": object,
    "cornering_stiffness_N_per_rad": float,
}
"""Columns of :func:`estimate_windows`' window table and their types, in order."""


def _window_table(
    ab: AxleBins, axle: str, o: WindowOptions, z_w: float
) -> tuple[dict[str, np.ndarray], np.ndarray]:
    """The window table of one axle before any profile: every window of contiguous bins, its
    measured grip and one-sided bound, whether it is analysed, and a screened window's answer
    (the profile's columns NaN); returns the columns and each window's first bin.
    """
    w = max(round(o.window_s / o.bin_s), 1)
    step = max(round(o.step_s / o.bin_s), 1)
    starts = np.arange(0, max(ab.t0.size - w + 1, 0), step)
    # windows whose bins are contiguous in time
    starts = starts[ab.t1[starts + w - 1] - ab.t0[starts] <= o.window_s + o.bin_s]
    k = starts.size

    def windows(x: np.ndarray) -> np.ndarray:
        return np.lib.stride_tricks.sliding_window_view(x, w)[starts] if k else np.zeros((0, w))

    g = windows(ab.data[:, 9])
    cols: dict[str, np.ndarray] = {c: np.full(k, np.nan) for c, t in WINDOW_COLUMNS.items()
                                   if t is float}  # fmt: skip
    cols["axle"] = np.full(k, axle, dtype=object)
    cols["t_start"] = ab.t0[starts].astype(float)
    cols["t_end"] = ab.t1[starts + w - 1].astype(float)
    cols["n"] = windows(ab.n).sum(axis=1).astype(np.int64)
    cols["grip_used"] = np.max(g, axis=1, initial=0.0)  # its largest bin, as the drive's
    cols["grip_used_lower"] = np.maximum(np.max(g - z_w * windows(ab.grip_sigma), axis=1), 0.0)
    cols["analysed"] = np.max(g, axis=1, initial=-np.inf) >= o.screen_utilisation
    cols["mu_low"] = cols["grip_used_lower"].copy()
    cols["mu_high"] = np.full(k, np.inf)
    cols["observable"] = np.zeros(k, dtype=bool)
    cols["fit"] = np.full(k, "screened", dtype=object)
    cols["shape"] = np.full(k, np.nan, dtype=object)
    cols["limited_by"] = np.full(k, "below the screening utilisation", dtype=object)
    # the declared stiffness of the window (times the fitted scale once there is one)
    cols["cornering_stiffness_N_per_rad"] = 0.5 * np.mean(windows(ab.data[:, 4] + ab.data[:, 5]),
                                                          axis=1)  # fmt: skip
    return cols, starts


def estimate_windows(
    wheels: pd.DataFrame,
    vehicle: Vehicle,
    *,
    noise: NoiseModel | None = None,
    options: WindowOptions | None = None,
) -> tuple[pd.DataFrame, pd.DataFrame]:
    """Windowed per-axle estimates and a per-axle summary.

    Parameters
    ----------
    wheels : pandas.DataFrame
        Wheel table of :func:`gripsense.estimate.friction.friction_from_motion`.
    vehicle : Vehicle
        Vehicle description.
    noise : NoiseModel
        Measurement and parameter uncertainty.
    options : WindowOptions
        Settings.

    Returns
    -------
    windows : pandas.DataFrame
        One row per axle and window, the columns of :data:`WINDOW_COLUMNS` in that order:
        ``axle``, ``t_start``, ``t_end``, ``n``, ``grip_used`` (largest 1 s measured grip),
        ``grip_used_lower`` (model-free one-sided bound), ``analysed``, ``mu`` (NaN unless
        ``observable``), ``mu_low``, ``mu_high`` (inf when unbounded), ``observable``, ``fit``,
        the profile's best μ, stiffness scale, heading bias, camber slip and load-transfer
        error (NaN where the window was screened), ``shape``, ``limited_by``,
        ``cornering_stiffness_N_per_rad``.
    summary : pandas.DataFrame
        One row per axle over the drive, the same columns plus ``n_windows`` and
        ``n_screened``.
    """
    noise = noise or NoiseModel()
    o = options or WindowOptions()
    z_w = float(norm.ppf(o.bound_level))
    tables, summ = [], []
    axles = sorted({w.split("_")[0] for w in wheels["wheel"].astype(str).unique()})
    for axle in axles:
        ab = axle_bins(wheels, axle, vehicle, noise, o.bin_s, o.min_samples)
        pri = _priors(vehicle, axle, noise)
        shapes = _shape_ids(vehicle.tyres[axle].shape)
        n_b = ab.t0.size
        cols, starts = _window_table(ab, axle, o, z_w)
        n_win = starts.size
        analysed = cols["analysed"]
        n_screened = int(n_win - analysed.sum())
        analysed_bins = np.zeros(n_b, bool)
        reuse = _Reuse()
        per_bin_win = max(round(o.window_s / o.bin_s), 1)
        for i in np.flatnonzero(analysed):
            sel = slice(starts[i], starts[i] + per_bin_win)
            analysed_bins[sel] = True
            mid, merged = merge_steady(
                ab.t0[sel], ab.t1[sel], ab.n[sel], ab.data[sel], o.steady_tolerance
            )
            est = reuse.profile(merged, mid, pri, shapes, ab.p0, o, cols["grip_used_lower"][i])
            for k, v in est.items():
                cols[k][i] = v
        cols["cornering_stiffness_N_per_rad"] *= cols["stiffness_scale"]
        tables.append(cols)
        # the drive: every analysed bin, nuisances shared, the slip offset a slow process
        g_max, g_lower = _drive_bound(ab, o.bound_level)
        base = {
            "axle": axle,
            "n": int(ab.n.sum()),
            "n_windows": n_win,
            "n_screened": n_screened,
            "grip_used": g_max,
            "grip_used_lower": g_lower,
        }
        if analysed_bins.any():
            mid, merged = merge_steady(
                ab.t0[analysed_bins],
                ab.t1[analysed_bins],
                ab.n[analysed_bins],
                ab.data[analysed_bins],
                o.steady_tolerance,
            )
            est = _profile(
                merged,
                mid,
                pri,
                shapes,
                ab.p0,
                o,
                base["grip_used_lower"],
            )
            c = 0.5 * (ab.data[analysed_bins, 4] + ab.data[analysed_bins, 5]).mean()
            est["cornering_stiffness_N_per_rad"] = est["stiffness_scale"] * c
            summ.append({**base, **est})
        else:
            summ.append(
                {
                    **base,
                    "mu": np.nan,
                    "mu_low": base["grip_used_lower"],
                    "mu_high": np.inf if n_b else np.nan,
                    "observable": False,
                    "fit": "screened" if n_b else "no data",
                    "limited_by": "no cornering above the screening utilisation"
                    if n_b
                    else "no steady or transient cornering",
                }
            )
    windows = {
        c: np.concatenate([t[c] for t in tables]) if tables else np.zeros(0, dtype=dt)
        for c, dt in WINDOW_COLUMNS.items()
    }
    return pd.DataFrame(windows), pd.DataFrame(summ)


class OnlineAxleWindow:
    """``axle-window`` for live use: bins are kept as running sums, so adding a sample costs
    O(1) and an update one window's profile (independent of how long the drive is).

    Feed it the wheel-table rows of one axle as they become final (:meth:`push`), ask for the
    newest window (:meth:`estimate`). The answers equal :func:`estimate_windows` on the same
    samples (the bins are formed the same way).

    Parameters
    ----------
    vehicle : Vehicle
        Vehicle description.
    axle : str
        ``front`` or ``rear``.
    noise : NoiseModel, optional
        Measurement and parameter uncertainty.
    options : WindowOptions, optional
        Settings.
    """

    def __init__(
        self,
        vehicle: Vehicle,
        axle: str,
        *,
        noise: NoiseModel | None = None,
        options: WindowOptions | None = None,
    ):
        self.vehicle = vehicle
        self.axle = axle
        self.noise = noise or NoiseModel()
        self.o = options or WindowOptions()
        self._rows: list[dict[str, np.ndarray]] = []  # usable samples of the current bin
        self._k: int | None = None  # the current bin's index on the data clock
        self._bins: deque = deque(maxlen=max(round(self.o.window_s / self.o.bin_s), 1))
        self._pri = _priors(vehicle, axle, self.noise)
        self._reuse = _Reuse()
        self._tail: dict[str, np.ndarray] | None = None
        self._shapes = _shape_ids(vehicle.tyres[axle].shape)

    def push(self, rows: pd.DataFrame) -> None:
        """Add final wheel-table rows (both wheels of this axle, any number of epochs).

        Parameters
        ----------
        rows : pandas.DataFrame
            Rows of :func:`gripsense.estimate.friction.friction_from_motion`.
        """
        p = axle_pairs(rows, self.axle)
        k = np.floor(p["t_s_L"] / self.o.bin_s).astype(np.int64)
        cuts = np.concatenate([[0], np.flatnonzero(np.diff(k)) + 1, [k.size]])
        for i0, i1 in itertools.pairwise(cuts):
            if i1 <= i0:
                continue
            if self._k is not None and k[i0] != self._k:
                self._close()
            self._k = int(k[i0])
            self._rows.append({c: x[i0:i1] for c, x in p.items()})

    def _close(self) -> None:
        rows = {c: np.concatenate([r[c] for r in self._rows]) for c in self._rows[0]}
        k = self._k
        self._rows = []
        # the previous bin's samples give the relaxation-lag interpolation its context at the
        # bin's start, as in the batch (they form their own bin, which is not kept here)
        frame = (
            rows
            if self._tail is None or self._tail.keys() != rows.keys()
            else {c: np.concatenate([self._tail[c], x]) for c, x in rows.items()}
        )
        self._tail = rows
        ab = axle_bins(frame, self.axle, self.vehicle, self.noise, self.o.bin_s, 1)
        mine = np.flatnonzero(np.floor(ab.t0 / self.o.bin_s) == k)
        if mine.size and ab.n[mine[-1]] >= self.o.min_samples:
            i = mine[-1]
            self._bins.append((ab.t0[i], ab.t1[i], ab.n[i], ab.data[i], ab.grip_sigma[i], ab.p0))

    def estimate(self) -> dict | None:
        """The newest complete window (None until there is one).

        Returns
        -------
        dict or None
            The window row (keys as :func:`estimate_windows`' windows).
        """
        if len(self._bins) < self._bins.maxlen:
            return None
        t0 = np.array([b[0] for b in self._bins])
        t1 = np.array([b[1] for b in self._bins])
        data = np.array([b[3] for b in self._bins])
        gsig = np.array([b[4] for b in self._bins])
        grip = data[:, 9]
        z_w = float(norm.ppf(self.o.bound_level))
        lower = _bound(grip, gsig, z_w)
        row = {
            "axle": self.axle,
            "t_start": float(t0[0]),
            "t_end": float(t1[-1]),
            "n": int(sum(b[2] for b in self._bins)),
            "grip_used": float(np.max(grip)),
            "grip_used_lower": lower,
            "analysed": bool(np.max(grip) >= self.o.screen_utilisation),
        }
        if row["analysed"]:
            n = np.array([b[2] for b in self._bins])
            mid, merged = merge_steady(t0, t1, n, data, self.o.steady_tolerance)
            row.update(
                self._reuse.profile(
                    merged,
                    mid,
                    self._pri,
                    self._shapes,
                    self._bins[-1][5],
                    self.o,
                    lower,
                )
            )
        else:
            row.update(
                {
                    "mu": np.nan,
                    "mu_low": lower,
                    "mu_high": np.inf,
                    "observable": False,
                    "fit": "screened",
                }
            )
        return row
