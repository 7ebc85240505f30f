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
  linearisation and are profiled (:mod:`gripsense.estimate.profile`).

Data: bins of ``bin_s`` (:mod:`gripsense.estimate.bins`). A window is ``window_s`` of bins
sharing their nuisances; a window without cornering the compass resolves — a slip angle and a
lateral acceleration both ``screen_z`` σ above their noise
(:func:`~gripsense.estimate.screen.resolvable`), whatever the grip — carries no information on
μ and is not analysed. The per-axle summary uses every analysed bin of the drive, nuisances
shared. A value is reported only when the ``point_level`` interval is bounded and narrower than
``max_width``; otherwise the interval [mu_low, ∞) and the measured grip.
"""

from __future__ import annotations

import numpy as np
import pandas as pd
from scipy.stats import norm

from gripsense.config import Vehicle
from gripsense.estimate.bins import AxleBins, axle_bins
from gripsense.estimate.grip import drive_bound, grip_bins
from gripsense.estimate.noise import NoiseModel
from gripsense.estimate.options import NOT_PROFILED, WindowOptions
from gripsense.estimate.profile import (
    UNCHANGED,
    ProfileCache,
    axle_priors,
    merge_bins,
    mu_grid,
    profile_learned,
    torque_only,
)
from gripsense.estimate.screen import resolvable, resolvable_bins, resolvable_steady
from gripsense.estimate.torque import check_channel, torque_bins, torque_profile, torque_read

__all__ = ["WINDOW_COLUMNS", "estimate_windows"]


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
    "mu_deviance": object,
}
"""Columns of :func:`estimate_windows`' window table and their types, in order."""


def _window_table(
    ab: AxleBins, axle: str, o: WindowOptions, z_w: float, noise: NoiseModel
) -> tuple[dict[str, np.ndarray], np.ndarray]:
    """The window table of one axle before any profile: every window of contiguous bins, its
    measured grip and one-sided bound, whether it is analysed (resolved cornering,
    :func:`~gripsense.estimate.screen.resolvable`), and a screened window's answer (the
    profile's columns NaN); returns the columns and each window's first bin.
    """
    w = max(round(o.window_s / o.bin_s), 1)
    step = max(round(o.step_s / o.bin_s), 1)
    starts = np.arange(0, max(ab.t0.size - w + 1, 0), step)
    # windows whose bins are contiguous in time
    starts = starts[ab.t1[starts + w - 1] - ab.t0[starts] <= o.window_s + o.bin_s]
    k = starts.size

    def windows(x: np.ndarray) -> np.ndarray:
        return np.lib.stride_tricks.sliding_window_view(x, w)[starts] if k else np.zeros((0, w))

    # the bound's grip: the split with the yaw moment it leaves out (docs/physics.md §14.1), as
    # the drive's bound takes it
    gp = windows(ab.grip_proven)
    cols: dict[str, np.ndarray] = {c: np.full(k, np.nan) for c, t in WINDOW_COLUMNS.items()
                                   if t is float}  # fmt: skip
    cols["axle"] = np.full(k, axle, dtype=object)
    cols["t_start"] = ab.t0[starts].astype(float)
    cols["t_end"] = ab.t1[starts + w - 1].astype(float)
    cols["n"] = windows(ab.n).sum(axis=1).astype(np.int64)
    cols["grip_used"] = np.max(gp, axis=1, initial=0.0)  # its largest bin, as the drive's
    cols["grip_used_lower"] = np.maximum(np.max(gp - z_w * windows(ab.grip_sigma), axis=1), 0.0)
    idx = starts[:, None] + np.arange(w)  # each window's bins
    cols["analysed"] = resolvable(
        ab.data[idx], ab.grip_sigma[idx], noise, o.screen_z, o.screen_utilisation
    )
    cols["mu_low"] = cols["grip_used_lower"].copy()
    cols["mu_high"] = np.full(k, np.inf)
    cols["observable"] = np.zeros(k, dtype=bool)
    cols["fit"] = np.full(k, "screened", dtype=object)
    cols["shape"] = np.full(k, np.nan, dtype=object)
    cols["limited_by"] = np.full(k, "no cornering the compass resolves", dtype=object)
    cols["mu_deviance"] = np.full(k, None, dtype=object)  # a screened window says nothing
    # the declared stiffness of the window (times the fitted scale once there is one)
    cols["cornering_stiffness_N_per_rad"] = 0.5 * np.mean(windows(ab.data[:, 4] + ab.data[:, 5]),
                                                          axis=1)  # fmt: skip
    return cols, starts


def _profile_windows(
    ab: AxleBins, cols: dict[str, np.ndarray], starts: np.ndarray, pri, tyre, o: WindowOptions
) -> np.ndarray:
    """Profile each analysed window into *cols* (in place); returns the bins they cover."""
    analysed_bins = np.zeros(ab.t0.size, bool)
    reuse = ProfileCache()
    per_bin_win = max(round(o.window_s / o.bin_s), 1)
    for i in np.flatnonzero(cols["analysed"]):
        sel = slice(starts[i], starts[i] + per_bin_win)
        analysed_bins[sel] = True
        mid, merged = merge_bins(ab.t0[sel], ab.t1[sel], ab.n[sel], ab.data[sel], pri, o)
        est = reuse.profile(merged, mid, pri, tyre, ab.p0, o, cols["grip_used_lower"][i])
        for k, v in est.items():
            cols[k][i] = v
    cols["cornering_stiffness_N_per_rad"] *= cols["stiffness_scale"]
    return analysed_bins


def _drive_bins(
    ab: AxleBins, analysed_bins: np.ndarray, noise: NoiseModel, o: WindowOptions
) -> np.ndarray:
    """The bins the drive takes: the analysed windows', a resolved steady stretch's, else the
    bins that pass the screen themselves.
    """
    if o.drive:
        # a steady stretch resolved over its whole length (its white slip noise averaged, on
        # ice the slip is below a window's noise): its bins join the drive (§15.2)
        analysed_bins |= resolvable_steady(
            ab.data, ab.grip_sigma, ab.t0, ab.t1, noise, o.screen_z, o.steady_tolerance,
            o.bin_s, max(round(o.window_s / o.bin_s), 1),
        )  # fmt: skip
    if not analysed_bins.any():
        # cornering shorter than a window (a sine with dwell's 2 s): the drive takes the
        # bins that pass the screen themselves rather than say it saw no cornering
        analysed_bins = resolvable_bins(
            ab.data, ab.grip_sigma, noise, o.screen_z, o.screen_utilisation
        )
    return analysed_bins


def _torque(wheels: pd.DataFrame, vehicle: Vehicle, o: WindowOptions) -> tuple:
    """The front axle's steering-torque profile on the μ grid (docs/physics.md §16) and what
    the channel was; (None, "") without one.
    """
    torque, read = None, ""
    tb = torque_bins(wheels, vehicle, o.bin_s, o.min_samples)
    if tb is not None and tb.t0.size:
        check_channel(tb, vehicle)
    if tb is not None and tb.t0.size and o.drive:  # the torque speaks to the drive only
        grid = mu_grid(float(o.mu_min), float(o.mu_max), int(o.n_mu))
        torque = torque_profile(tb, vehicle, grid, tol=o.steady_tolerance)
        read = torque_read(tb, torque)
    return torque, read


def _drive_summary(
    ab: AxleBins, bins: np.ndarray, base: dict, pri, tyre, o: WindowOptions, torque
) -> dict:
    """The axle's row over the drive: every analysed bin, nuisances shared, the slip offset a
    slow process (a ``torque_note`` entry says what a steering-torque channel did).
    """
    n_b = ab.t0.size
    if bins.any() and not o.drive:  # the windows' statements only (the fleet)
        return {
            **base,
            "mu": np.nan,
            "mu_low": base["grip_used_lower"],
            "mu_high": np.inf,
            "observable": False,
            "fit": NOT_PROFILED,
            "limited_by": "the drive was not profiled (its windows were)",
            "torque_note": "",
        }
    if bins.any():
        mid, merged = merge_bins(ab.t0[bins], ab.t1[bins], ab.n[bins], ab.data[bins], pri, o)
        est = profile_learned(
            merged, mid, pri, tyre, ab.p0, o, base["grip_used_lower"], torque=torque
        )
        est.pop("mu_deviance", None)  # a window's statement for the fleet, not the drive's
        c = 0.5 * (ab.data[bins, 4] + ab.data[bins, 5]).mean()
        est["cornering_stiffness_N_per_rad"] = est["stiffness_scale"] * c
        return {**base, **est}
    if torque is not None and (only := torque_only(torque, o, base["grip_used_lower"])):
        return {**base, **only}
    return {
        **base,
        "mu": np.nan,
        "mu_low": base["grip_used_lower"],
        "mu_high": np.inf if n_b else np.nan,
        "observable": False,
        "fit": "screened" if n_b else "no data",
        "limited_by": "no cornering the compass resolves"
        if n_b
        else "no steady or transient cornering",
        "torque_note": UNCHANGED if torque is not None else "",
    }


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
        ``cornering_stiffness_N_per_rad``, ``mu_deviance`` (the window's statement as a curve
        on the μ grid, :func:`~gripsense.estimate.profile.deviance_curve`: what a fleet cell
        combines; None where the window was screened or its fit is inconsistent).
    summary : pandas.DataFrame
        One row per axle over the drive, the same columns plus ``n_windows``, ``n_screened``
        and ``steering_torque`` (what a steering-torque channel was and what it did to the
        range, :func:`~gripsense.estimate.torque.torque_read`; empty where none was read).
    """
    noise = noise or NoiseModel()
    o = options or WindowOptions()
    z_w = float(norm.ppf(o.bound_level))
    tables, summ = [], []
    axles = sorted({w.split("_")[0] for w in wheels["wheel"].astype(str).unique()})
    for axle in axles:
        ab = axle_bins(wheels, axle, vehicle, noise, o.bin_s, o.min_samples)
        pri = axle_priors(vehicle, axle, noise)
        tyre = vehicle.tyres[axle]
        cols, starts = _window_table(ab, axle, o, z_w, noise)
        n_screened = int(starts.size - cols["analysed"].sum())
        analysed_bins = _profile_windows(ab, cols, starts, pri, tyre, o)
        tables.append(cols)
        analysed_bins = _drive_bins(ab, analysed_bins, noise, o)
        g_max, g_lower = drive_bound(grip_bins(wheels, axle, vehicle, noise, o), o.bound_level)
        # a steering-torque channel: the trail's fall (docs/physics.md §16)
        torque, read = _torque(wheels, vehicle, o) if axle == "front" else (None, "")
        base = {
            "axle": axle,
            "n": int(ab.n.sum()),
            "n_windows": starts.size,
            "n_screened": n_screened,
            "grip_used": g_max,
            "grip_used_lower": g_lower,
        }
        summ.append(_drive_summary(ab, analysed_bins, base, pri, tyre, o, torque))
        # what a steering-torque channel was and did ("" where none was read)
        note = summ[-1].pop("torque_note", "")
        summ[-1]["steering_torque"] = f"{read}: {note}" if read else ""
    windows = {
        c: np.concatenate([t[c] for t in tables]) if tables else np.zeros(0, dtype=dt)
        for c, dt in WINDOW_COLUMNS.items()
    }
    return pd.DataFrame(windows), pd.DataFrame(summ)
