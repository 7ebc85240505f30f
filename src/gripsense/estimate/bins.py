"""Bins of one axle: the unit of data of the window estimator and of the model-free measured
grip (``docs/physics.md`` §14, §15).

A bin holds the means of ``bin_s`` of samples in which both wheels of the axle are present and
cornering: slip angles lagged by the relaxation length, loads, stiffnesses, the axle force and
its white noise divided by n, the measured grip and the spread within the bin beyond its noise.
Bins are formed on the data clock, so the batch and the online estimator form the same bins.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pandas as pd

from gripsense.config import Vehicle
from gripsense.constants import G0
from gripsense.estimate import _axle_kernel as K
from gripsense.estimate.noise import NoiseModel
from gripsense.io.sensors.steer import STEERING_TORQUE

__all__ = [
    "BIN_COLUMNS",
    "FORCE_MODEL_REL",
    "AxleBins",
    "axle_bins",
    "axle_pairs",
    "bin_starts",
    "force_and_linear",
    "merge_steady",
    "on_the_curve",
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
SPIN_SLIP_RAD = float(np.deg2rad(30.0))
"""A bin's mean slip beyond which its axle spins [rad]: past the peak of every tyre of the
library (the latest, a PAC89 file's, at ~28°), where the force is set by the drive's
longitudinal slip and the car's rotation, not by the lateral curve (``docs/physics.md``
§15.8)."""
SWEEP_SPREAD_RAD = float(np.deg2rad(5.0))
"""A bin's slip spread beyond which it is a spin's onset or recovery, not a point of the curve
[rad]: a slip sweeping ±5° (1σ) within 1 s — a car rotating through it — is faster than the
measured force (slopes over ±0.5 s) and the tyre's lag resolve."""

_OUT = ("low_speed", "not_cornering", "wheel_lifted")
_OUT_AXLE = ("low_speed", "not_cornering")  # the measured grip's samples (no wheel load needed)
_AXLE_COLUMNS = ("t_s", "speed_mps", "axle_force_N", "grip_used", "grip_sigma",
                 "lateral_accel_mps2")  # fmt: skip


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
        (n_bins, 15) in :data:`BIN_COLUMNS` order: slips [rad], loads [N], stiffnesses [N/rad],
        axle force [N] and its white 1σ [N], slip white 1σ [rad], measured grip [-], a_y/g
        [-], static wheel load [N], road-wheel steer angle [rad] (0 on the rear axle), the
        slip's spread within the bin beyond its white noise [rad], the 1σ of the force the
        model cannot represent [N] (:data:`FORCE_MODEL_REL` of it, the steered axle's
        (1 − cos δ), and the force's own spread within the bin beyond its noise — a transient).
    grip_sigma : numpy.ndarray
        1σ of the measured grip of each bin [-].
    p0 : float
        Local load-sensitivity exponent of the declared stiffness [-].
    proven : numpy.ndarray or None
        The bound's measured grip of each bin (the wheel table's ``grip_proven``: the split
        with the yaw moment it leaves out, ``docs/physics.md`` §14.1) [-]; None: column 9.
    """

    axle: str
    t0: np.ndarray
    t1: np.ndarray
    n: np.ndarray
    data: np.ndarray
    grip_sigma: np.ndarray
    p0: float
    proven: np.ndarray | None = None

    @property
    def grip_proven(self) -> np.ndarray:
        """The bound's measured grip of each bin [-] (:attr:`proven`, else column 9)."""
        return self.data[:, 9] if self.proven is None else self.proven


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


def axle_pairs(
    wheels: pd.DataFrame, axle: str, *, keep_lifted: bool = False
) -> dict[str, np.ndarray]:
    """The usable samples of one axle: left and right wheel joined on the epoch (both present,
    cornering, positive loads, every number finite), in time order.

    Parameters
    ----------
    wheels : pandas.DataFrame
        Wheel table (:func:`gripsense.estimate.friction.friction_from_motion`).
    axle : str
        ``front`` or ``rear``.
    keep_lifted : bool
        Keep the samples where the load-transfer model lifts a wheel, with only the axle's
        columns (time, speed, force, measured grip) required finite: the measured grip of the
        axle needs no wheel load (``docs/physics.md`` §14).

    Returns
    -------
    dict of numpy.ndarray
        ``<column>_L`` and ``<column>_R`` for the columns the bins use (``steer_rad_L`` on a
        front axle whose table has a steering channel, and its steering-torque columns, NaN
        where the channel has no sample), all of one length.
    """
    cols = list(_PAIR_COLUMNS)
    optional = []  # carried along, never required finite: a channel of its own rate
    if "steer_rad" in wheels.columns and axle == "front":
        cols.append("steer_rad")
    if axle == "front":
        optional = [c for c in STEERING_TORQUE if c in wheels.columns]
    if "grip_proven" in wheels.columns:  # the bound's grip (a table of an earlier version: none)
        optional.append("grip_proven")
    wheel = wheels["wheel"]
    m_l = (wheel == f"{axle}_left").to_numpy()
    m_r = (wheel == f"{axle}_right").to_numpy()
    epoch = wheels["epoch"].to_numpy()
    _, i_l, i_r = np.intersect1d(epoch[m_l], epoch[m_r], return_indices=True)
    flag = wheels["flag"].to_numpy()
    out_flags = _OUT_AXLE if keep_lifted else _OUT
    ok = ~np.isin(flag[m_l][i_l], out_flags) & ~np.isin(flag[m_r][i_r], out_flags)
    out: dict[str, np.ndarray] = {}
    for c in (*cols, *optional):
        x = wheels[c].to_numpy(float)
        out[c + "_L"], out[c + "_R"] = x[m_l][i_l], x[m_r][i_r]
        if c in optional:
            continue
        if not keep_lifted or c in _AXLE_COLUMNS:
            ok &= np.isfinite(out[c + "_L"]) & np.isfinite(out[c + "_R"])
    order = np.argsort(out["t_s_L"][ok], kind="stable")
    return {c: x[ok][order] for c, x in out.items()}


def bin_starts(t: np.ndarray, bin_s: float) -> tuple[np.ndarray, np.ndarray]:
    """Where the bins of samples at times *t* start, and their sizes: bins on the data clock
    (floor(t / bin_s), not from the first sample, so the live estimator forms the same), a gap
    of more than half a bin ending one.

    Parameters
    ----------
    t : numpy.ndarray
        Sample times, increasing [s].
    bin_s : float
        Bin length [s].

    Returns
    -------
    starts : numpy.ndarray
        Index of each bin's first sample.
    n : numpy.ndarray
        Samples per bin.
    """
    k = np.floor(t / bin_s).astype(np.int64)
    k += np.concatenate([[0], np.cumsum(np.diff(t) > 0.5 * bin_s)])
    edges = np.flatnonzero(np.diff(k)) + 1
    starts = np.concatenate([[0], edges])
    return starts, np.diff(np.concatenate([starts, [t.size]]))


def axle_bins(
    wheels: pd.DataFrame | dict[str, np.ndarray],
    axle: str,
    vehicle: Vehicle,
    noise: NoiseModel,
    bin_s: float = 1.0,
    min_samples: int = 5,
    *,
    grip: str = "grip_used",
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
    grip : str
        The column of the measured grip binned (column 9): ``grip_used`` (the model's) or
        ``grip_proven`` (the bound's, :func:`gripsense.estimate.grip.axle_grip`); the bins'
        :attr:`AxleBins.grip_proven` is the bound's either way.

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
            np.zeros(0),
        )
    # the tyre force lags the slip by σ/U: compare the force with the slip of σ/U earlier
    speed = b["speed_mps_L"]
    lag = tyre.relaxation_length_m / np.maximum(speed, 1.0)
    aL = np.interp(t - lag, t, b["slip_angle_rad_L"])
    aR = np.interp(t - lag, t, b["slip_angle_rad_R"])
    starts, n = bin_starts(t, bin_s)

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
            mean(b[f"{grip}_L"] if f"{grip}_L" in b else b["grip_used_L"]),
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
    # the bound's grip (a table of an earlier version has none: the model's), a sample without
    # one counting as none used
    proven = (
        mean(np.nan_to_num(b["grip_proven_L"], nan=0.0)) if "grip_proven_L" in b else data[:, 9]
    )
    keep = n >= min_samples
    t_end = np.maximum.reduceat(t, starts)
    return AxleBins(axle, t[starts][keep], t_end[keep], n[keep], data[keep], grip_sigma[keep], p0,
                    proven[keep])  # fmt: skip


_NOISE_COLS = np.array([7, 8], dtype=np.int64)  # white-noise σ of a bin's slip and force


def merge_steady(
    t0: np.ndarray,
    t1: np.ndarray,
    n: np.ndarray,
    data: np.ndarray,
    tol: float,
    *,
    slip_z: float = np.inf,
    drift_sd: float = 0.0,
    tau_s: float = 20.0,
) -> tuple[np.ndarray, np.ndarray]:
    """Merge runs of consecutive bins whose measured grip stays within *tol* of the run's first
    bin, and whose slip stays within its noise, into one bin (means weighted by the sample
    count; white noise combined).

    In steady cornering every bin shows the same force, so slip differences between its bins
    are measurement error: kept apart they would let a tyre at its limit (whose force does not
    depend on slip) explain them for free. Merged, a steady stretch is one point of the tyre
    curve, and only changes of utilisation (transients) trace the curve. A run whose slip moves
    by more than *slip_z* times its noise while the force stays is not steady: a tyre past its
    peak (a front axle ploughing through a ramp steer) holds its force while the slip grows by
    degrees — the plateau that proves saturation, kept as points (``docs/physics.md`` §15.9).

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
    slip_z : float
        Largest change of the axle's mean slip within a merged run, in units of its 1σ (the
        bins' white noise and the drift's change between them) [-]; inf: the slip is not looked
        at.
    drift_sd : float
        1σ of the slow slip error (a Gauss–Markov drift) [rad].
    tau_s : float
        Its correlation time [s].

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
        float(slip_z),
        float(drift_sd),
        float(max(tau_s, 1e-3)),
        BIN_COLUMNS.index("force_model_sd"),
    )


def on_the_curve(data: np.ndarray) -> np.ndarray:
    """Which bins are points of the tyre's lateral curve: not a spinning axle's (a wheel's mean
    slip beyond :data:`SPIN_SLIP_RAD`), nor one whose slip sweeps beyond
    :data:`SWEEP_SPREAD_RAD` within it. Each bin on its own (the online estimator decides as
    the batch one does, bin by bin).

    Parameters
    ----------
    data : numpy.ndarray
        Bins in :data:`BIN_COLUMNS` order.

    Returns
    -------
    numpy.ndarray
        True for a bin the tyre curve models [-].
    """
    slip = np.maximum(np.abs(data[:, 0]), np.abs(data[:, 1]))
    return (slip <= SPIN_SLIP_RAD) & (data[:, 13] <= SWEEP_SPREAD_RAD)


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
