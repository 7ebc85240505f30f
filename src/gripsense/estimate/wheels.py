"""The first stage of every friction estimator: wheel kinematics (``docs/physics.md`` §3, §4, §11).

The chain, per epoch and wheel:

1. antenna side-slip β_A = wrap(ψ − ψ₀ − χ) with the heading offset ψ₀ calibrated on straights;
   antenna velocity (U, V) = v (cos β_A, sin β_A); ISO yaw rate r (§3.1) —
   :func:`motion_from_epochs`;
2. each wheel's velocity U_i = U − r dy_i, V_i = V + r dx_i, slip angle α_i = atan2(V_i, U_i) − δ_i,
   speed and path radius v_i/|r| (§3.1);
3. lateral acceleration of the reference point a_y = U_ref r; static axle masses, the
   steady-state lateral load transfer (§4.2; rigid = the thesis model, §4.3) and, with a
   wheelbase, the longitudinal transfer m a_x h/L (a_x = U̇ − V r) give each wheel's load;
4. contact length from the l–m model (§5), cornering stiffness C = G w l²/2 (eq. 9.1);
5. each wheel carries its load's share of the axle force m_i⁰ a_y (equal friction utilisation on
   both wheels of an axle, the thesis's assumption, §4.4);
6. the model-free measured grip of each axle (:func:`gripsense.estimate.grip.axle_grip`);
7. a flag says why a sample is not steady cornering: ``low_speed``, ``not_cornering``,
   ``not_steady``, ``wheel_lifted`` — the estimators add their own (:data:`FLAGS`).

:func:`wheel_kinematics` computes this once; an estimator's per-sample stage adds μ or marks the
samples it estimates per axle (:mod:`gripsense.estimate.estimators`), and :func:`wheel_table`
makes the table.
"""

from __future__ import annotations

import numpy as np
import pandas as pd
from scipy.linalg import solve_banded

from gripsense.config import AXLE_OF, Vehicle
from gripsense.constants import G0
from gripsense.errors import InputError
from gripsense.estimate._resample_kernel import hat_score
from gripsense.estimate.grip import axle_grip
from gripsense.estimate.options import FrictionOptions
from gripsense.io.logs.nmea.align import align_channels
from gripsense.io.sensors.steer import STEERING_TORQUE
from gripsense.physics.kinematics import (
    antenna_sideslip,
    heading_offset_from_straight,
    path_radius,
    point_velocity,
    slip_angle,
)
from gripsense.physics.load_transfer import lateral_load_transfer, wheel_loads

__all__ = [
    "FLAGS",
    "NOT_STEADY_CORNERING",
    "WHEEL_COLUMNS",
    "motion_from_epochs",
    "wheel_kinematics",
    "wheel_table",
]

NOT_STEADY_CORNERING = ("low_speed", "not_cornering", "not_steady")
"""Flags of samples that are not steady cornering: they carry no information on μ and no bound."""
FLAGS = (
    "ok",
    "low_speed",
    "not_cornering",
    "not_steady",
    "no_solution",
    "full_sliding",
    "ill_conditioned",
    "wheel_lifted",
    "per_axle",
)
"""Why a wheel sample has no μ (``ok``: it has one). ``wheel_lifted``: the load-transfer model
puts no load on the wheel; ``per_axle``: an ``axle-window`` sample (μ is in the windows)."""
WHEEL_COLUMNS = [
    "t_s",
    "epoch",
    "wheel",
    "speed_mps",
    "slip_angle_rad",
    "steer_rad",
    "radius_m",
    "mass_kg",
    "contact_length_m",
    "load_N",
    "force_N",
    "slide_point_m",
    "force_ratio",
    "mu",
    "kappa_beta",
    "mu_sigma",
    "flag",
    "lateral_accel_mps2",
    "utilisation",
    "steady",
    "cornering_stiffness_N_per_rad",
    "slip_sigma_rad",
    "force_sigma_N",
    "axle_force_N",
    "axle_load_N",
    "grip_used",
    "grip_proven",
    "grip_sigma",
]


_REQUIRED = ("t_s", "heading_deg", "course_deg", "speed_mps", "yaw_rate_rps")


def _steady(t: np.ndarray, speed: np.ndarray, yaw: np.ndarray, o: FrictionOptions) -> np.ndarray:
    """Samples whose centred window has steady speed and yaw rate."""
    if t.size == 0:
        return np.zeros(0, dtype=bool)
    idx = pd.to_timedelta(t - t[0], unit="s")
    df = pd.DataFrame({"v": speed, "r": yaw}, index=idx)
    win = pd.Timedelta(seconds=o.steady_window_s)
    roll = df.rolling(win, center=True, min_periods=3)
    sd = roll.std()
    n = roll.count()["v"].to_numpy()
    return (
        (sd["v"].to_numpy() <= o.steady_speed_std_mps)
        & (sd["r"].to_numpy() <= np.deg2rad(o.steady_yaw_rate_std_dps))
        & (n >= 3)
    )


def motion_from_epochs(
    epochs: pd.DataFrame,
    vehicle: Vehicle,
    *,
    options: FrictionOptions | None = None,
    steer_rad: np.ndarray | None = None,
) -> tuple[pd.DataFrame, dict]:
    """GNSS-compass epochs -> motion table of the antenna point (body axes).

    The heading offset is calibrated on straight driving (or taken from the vehicle file);
    β_A = wrap(ψ − ψ₀ − χ), (U, V) = v (cos β_A, sin β_A) (docs/physics.md §3.1).

    Parameters
    ----------
    epochs : pandas.DataFrame
        Epoch table of :func:`gripsense.io.read_nmea`.
    vehicle : Vehicle
        Vehicle description (antenna position, heading offset).
    options : FrictionOptions, optional
        Gates and the heading calibration switch.
    steer_rad : numpy.ndarray, optional
        Road-wheel angle per epoch row [rad].

    Returns
    -------
    motion : pandas.DataFrame
        ``t_s``, ``epoch`` (row of *epochs*), ``u_mps``, ``v_mps``, ``yaw_rate_rps``,
        ``ay_mps2`` (NaN: computed from U·r downstream), ``steer_rad`` (NaN without a channel).
    meta : dict
    """
    o = options or FrictionOptions()
    missing = [c for c in _REQUIRED if c not in epochs.columns]
    if missing:
        raise InputError(
            f"epochs: missing columns {missing}; read the log with gripsense.io.read_nmea"
        )
    # course/speed and heading at different rates (OxTS: PASHR 25 Hz, RMC 1 Hz): the course
    # and speed are interpolated onto the heading epochs by the side slip where that is safe
    epochs, alignment = align_channels(epochs)
    have = np.ones(len(epochs), dtype=bool)
    for c in _REQUIRED:
        have &= epochs[c].notna().to_numpy()
    rows = np.flatnonzero(have)
    n_have = rows.size
    ep, source, counts = receiver_epochs(epochs.iloc[rows])
    rows = rows[source]
    ts = ep["t_s"].to_numpy(float)
    ts = ts[np.isfinite(ts)]
    back = np.flatnonzero(np.diff(ts) < 0)
    if back.size:
        raise InputError(
            f"epochs: time goes backwards after t = {ts[back[0]]:.2f} s (to {ts[back[0] + 1]:.2f} s"
            f"; {back.size} such jumps): the log holds several sessions or the receiver clock was"
            " reset; split the log into sessions (gripsense live restarts its window instead)"
        )
    psi = np.deg2rad(ep["heading_deg"].to_numpy(float))
    chi = np.deg2rad(ep["course_deg"].to_numpy(float))
    v = ep["speed_mps"].to_numpy(float)
    r = ep["yaw_rate_rps"].to_numpy(float)
    meta: dict = {
        "vehicle": vehicle.name,
        "epochs_total": len(epochs),
        "epochs_used": int(rows.size),
        "epochs_missing_inputs": int(len(epochs) - n_have),
        "epochs_aligned": alignment.n_aligned,
        **{k: v for k, v in counts.items() if k != "receiver_rate_hz"},
    }
    if np.isfinite(counts["receiver_rate_hz"]):
        meta["receiver_rate_hz"] = counts["receiver_rate_hz"]
    n_same_time, n_held = counts["epochs_duplicate"], counts["epochs_held"]
    n_interp, n_res = counts["epochs_interpolated"], counts["epochs_resampled"]
    if n_same_time or n_held or n_interp or n_res:
        said = (
            f"{n_same_time + n_held + n_interp + n_res} epochs collapsed (a logger's duplicates "
            f"or resampling; each measurement counts once): {n_same_time} repeat an earlier "
            f"epoch's time stamp, {n_held} its measurements at a new one, {n_interp} lie on the "
            "line between their neighbours"
        )
        rate = counts["receiver_rate_hz"]
        if n_res:
            said += (
                f", {n_res} more are a resampling of a {rate:g} Hz receiver, replaced by its "
                "epochs (the knots of the piecewise-linear curve they lie on)"
            )
        elif n_held and np.isfinite(rate):
            said += f"; the values held moved to the {rate:g} Hz receiver's epochs"
        meta["epochs_collapsed"] = said
    offset = vehicle.heading_offset_rad
    meta["heading_offset_source"] = "vehicle file"
    if o.calibrate_heading:
        cal, n_straight, spread = heading_offset_from_straight(psi, chi, r, v)
        meta["straight_samples"] = n_straight
        if np.isfinite(cal):
            offset = cal
            meta["heading_offset_source"] = f"straight driving ({n_straight} samples)"
            meta["heading_offset_spread_deg"] = float(np.rad2deg(spread))
    meta["heading_offset_deg"] = float(np.rad2deg(offset))
    beta_a = antenna_sideslip(psi, chi, offset)
    steer = (
        np.full(rows.size, np.nan)
        if steer_rad is None
        else np.asarray(steer_rad, dtype=float)[rows]
    )
    motion = pd.DataFrame(
        {
            "t_s": ep["t_s"].to_numpy(float),
            "epoch": rows,
            "u_mps": v * np.cos(beta_a),
            "v_mps": v * np.sin(beta_a),
            "yaw_rate_rps": r,
            "ay_mps2": np.full(rows.size, np.nan),
            "steer_rad": steer,
            # the velocity direction and the vehicle's heading (clockwise from north): the
            # model-free grip differentiates the velocity in the earth frame (_axle_grip)
            "course_rad": chi,
            "heading_rad": psi - offset,
        }
    )
    for c in STEERING_TORQUE:  # a steering-torque channel rides along (docs/physics.md §16)
        if c in ep.columns:
            motion[c] = ep[c].to_numpy(float)
    return motion, meta


_HELD_COLUMNS = ("lat_deg", "lon_deg", "speed_mps", "course_deg", "heading_deg")
"""The measurements that, all repeated bit for bit at a new time stamp, make a held epoch; all
on the straight line in time between their neighbours, an interpolated one."""
_ANGLE_COLUMNS = ("course_deg", "heading_deg")
"""Of :data:`_HELD_COLUMNS`, the angles (compared modulo 360°)."""
_QUANTUM_CAP = {"lat_deg": 1e-6, "lon_deg": 1e-6, "speed_mps": 0.05, "course_deg": 0.1,
                "heading_deg": 0.1}  # fmt: skip
"""The coarsest output resolution taken from the data (a sparse column's smallest step is not
its resolution): 0.1 m of position, 0.05 m/s, 0.1° [deg, m/s]."""


_UNIT_SCALES = (1.0, 60.0, 3600.0 / 1852.0, 3.6)
"""The units a log may write a column in, per the table's: itself, minutes of a degree,
knots and km/h of a m/s [-]."""


def _quantum(x: np.ndarray, cap: float) -> float:
    """The output resolution of a column: the coarsest decimal step (in one of the units of
    :data:`_UNIT_SCALES`) whose multiples hold every value, at most *cap*; 0 for a column on no
    such step (numbers at float precision: only an exact line counts) or without two distinct
    values.
    """
    v = x[np.isfinite(x)]
    if v.size < 2 or v.min() == v.max():
        return 0.0
    big = v[np.argmax(np.abs(v))]  # the largest |y| below (scaling keeps the order)
    head = v[:64]  # a step its first values miss is no step of all of them
    grid = 0.0
    for s in _UNIT_SCALES:
        for k in range(13):
            tol = 64 * EPS * abs(float(big * s * 10.0**k))
            if tol > 0.01:
                break
            yh = head * s * 10.0**k
            if not np.all(np.abs(yh - np.round(yh)) <= tol + 1e-12):
                continue
            y = v * s * 10.0**k
            if np.all(np.abs(y - np.round(y)) <= tol + 1e-12):
                grid = max(grid, 10.0**-k / s)
                break
    return min(grid, cap)


EPS = float(np.finfo(float).eps)
LATE_COPY_S = 1.0
"""How far behind the newest epoch a copy of an earlier one may be written (a logger's buffer)
and still be a copy [s]."""
MAX_RESAMPLE = 10
"""The most epochs a resampling logger writes per receiver epoch (a 10 Hz compass at 100 Hz):
more on one line are a stretch smoother than the output's resolution [-]."""
STAMP_ERROR_S = 1e-6
"""The time stamps' own rounding error: seconds since 1970 in float64 carry 2.4e-7 s [s]."""


def _line_residual(t: np.ndarray, x: np.ndarray, a, i, b, angle: bool) -> tuple:
    """x[i] minus the straight line in time through (t[a], x[a]) and (t[b], x[b]) (angles
    modulo 360°: the shorter way round), and what the stamps' rounding error
    (:data:`STAMP_ERROR_S`) moves the line by.
    """
    w = (t[i] - t[a]) / (t[b] - t[a])
    d = x[b] - x[a]
    if angle:
        d = np.mod(d + 180.0, 360.0) - 180.0
    r = x[i] - (x[a] + w * d)
    slack = 2.0 * STAMP_ERROR_S * np.abs(d) / (t[b] - t[a])
    return (np.mod(r + 180.0, 360.0) - 180.0 if angle else r), slack


def interpolated_epochs(epochs: pd.DataFrame) -> np.ndarray:
    """The epochs a logger made by linear interpolation between the receiver's: every
    measurement (position, speed, course and heading, all five known) on the straight line in
    time between the epochs kept before and after it, within its output resolution (the logger
    rounds what it interpolates to the format's digits: half a resolution off the true line,
    which the rounded ends move by at most as much). A receiver's own epochs carry noise far
    above that resolution; the line is the longest from each kept epoch over which every epoch
    between lies on it, so a ×5 resampling keeps the receiver's epochs; a line through
    :data:`MAX_RESAMPLE` or more epochs is not a resampling (``docs/physics.md`` §14.2).

    Parameters
    ----------
    epochs : pandas.DataFrame
        Epoch rows in time order (increasing ``t_s`` [s]) with the columns of
        :data:`_HELD_COLUMNS` (without one of them: none is interpolated).

    Returns
    -------
    numpy.ndarray of bool
        The interpolated epochs (the first and the last epoch never are).
    """
    n = len(epochs)
    drop = np.zeros(n, dtype=bool)
    cols = list(_HELD_COLUMNS)
    if n < 3 or not all(c in epochs.columns for c in cols):
        return drop
    t = epochs["t_s"].to_numpy(float)
    if not np.all(np.diff(t) > 0):
        return drop
    xs = [epochs[c].to_numpy(float) for c in cols]
    angle = [c in _ANGLE_COLUMNS for c in cols]
    tol = []
    for c, x in zip(cols, xs, strict=True):
        scale = float(np.nanmax(np.abs(x))) if np.isfinite(x).any() else 1.0
        tol.append(0.5 * _quantum(x, _QUANTUM_CAP[c]) * (1 + 1e-6) + 64 * EPS * max(scale, 1.0))

    def on_line(a, i, b, k: float) -> np.ndarray:
        """Whether every column of epochs *i* lies within k × its tolerance of the line a–b
        (a column without a value there: not on it).
        """
        ok = np.ones(np.size(i), dtype=bool)
        for x, ang, tl in zip(xs, angle, tol, strict=True):
            with np.errstate(invalid="ignore"):
                r, slack = _line_residual(t, x, a, i, b, ang)
                ok &= np.abs(r) <= k * tl + slack  # NaN: False
        return ok

    # candidates: on the line between their neighbours within twice the lines' tolerance
    # below (an epoch off it cannot lie between a kept epoch and a later one); a line's ends
    # may be interpolated epochs themselves, rounded: an epoch within half a resolution of the
    # true line is within a whole one of theirs
    mid = np.arange(1, n - 1)
    cand = np.zeros(n, dtype=bool)
    cand[mid] = on_line(mid - 1, mid, mid + 1, 4.0)
    if not cand.any():
        return drop
    idx = np.flatnonzero(cand)
    breaks = np.flatnonzero(np.diff(idx) > 1)
    for s, e in zip(idx[np.r_[0, breaks + 1]], idx[np.r_[breaks, idx.size - 1]], strict=True):
        a, last = int(s) - 1, int(e) + 1  # the firm epochs around the run of candidates
        while a < last:
            b = a + 1
            while b < last and on_line(a, np.arange(a + 1, b + 1), b + 1, 2.0).all():
                b += 1
            # more epochs on one line than a logger adds between two of the receiver's: a
            # stretch smoother than the resolution (driving straight at a constant speed with no
            # noise), not a resampling
            drop[a + 1 : b] = b - a - 1 < MAX_RESAMPLE
            a = b
    return drop


def unique_epochs(epochs: pd.DataFrame) -> tuple[np.ndarray, int, int, int]:
    """The epochs that each carry a measurement of their own: a logger that writes an epoch
    twice (or each sentence twice) or resamples its input — holding the last value or
    interpolating between values — makes copies that are not new data; counted as independent
    they would shrink the measured grip's noise and raise its bound (``docs/physics.md``
    §14.2).

    An epoch whose time stamp equals the previous epoch's is a copy, and so is one that repeats
    an earlier epoch's time stamp and measurements up to :data:`LATE_COPY_S` behind the newest
    (a copy written late; further back the log starts again: a second session); so is one whose
    position, speed, course and heading all equal the previous kept epoch's bit for bit (a
    held value: a moving receiver never repeats all five), and one whose measurements all lie
    on the line between the kept epochs around it (:func:`interpolated_epochs`).

    Parameters
    ----------
    epochs : pandas.DataFrame
        Epoch rows with ``t_s`` [s] and the columns of :data:`_HELD_COLUMNS`.

    Returns
    -------
    keep : numpy.ndarray of bool
        The epochs kept (the first of each run of copies).
    same_time : int
        Epochs dropped for repeating a time stamp.
    held : int
        Epochs dropped for repeating every measurement at a new time stamp.
    interpolated : int
        Epochs dropped for lying on the line between their neighbours.
    """
    keep, same, held = _copies(epochs)
    rest = np.flatnonzero(keep)
    interp = np.zeros(len(epochs), dtype=bool)
    interp[rest] = interpolated_epochs(epochs.iloc[rest])
    keep &= ~interp
    return keep, int(same.sum()), int(held.sum()), int(interp.sum())


def _copies(epochs: pd.DataFrame) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The epochs kept, and those that repeat a time stamp (also late) or hold every
    measurement at a new one (:func:`unique_epochs`).
    """
    n = len(epochs)
    keep = np.ones(n, dtype=bool)
    if n < 2:
        return keep, ~keep, ~keep
    t = epochs["t_s"].to_numpy(float)
    same = np.zeros(n, dtype=bool)
    same[1:] = t[1:] == t[:-1]
    have = all(c in epochs.columns for c in _HELD_COLUMNS)
    if have:  # a copy written late: an earlier epoch's time stamp and measurements, at most
        # LATE_COPY_S behind the newest (a log that starts again is a second session)
        newest = np.concatenate([[-np.inf], np.fmax.accumulate(t)[:-1]])
        late = epochs.duplicated(subset=["t_s", *_HELD_COLUMNS]).to_numpy()
        same |= late & (t >= newest - LATE_COPY_S)
    held = np.zeros(n, dtype=bool)
    rest = np.flatnonzero(~same)
    if have and rest.size > 1:
        vals = np.column_stack([epochs[c].to_numpy(float)[rest] for c in _HELD_COLUMNS])
        held[rest[1:]] = np.all(vals[1:] == vals[:-1], axis=1)  # NaN never equal
    return ~(same | held), same, held


RECEIVER_RATES_HZ = (1.0, 2.0, 4.0, 5.0, 8.0, 10.0, 16.0, 20.0, 25.0, 40.0, 50.0, 100.0)
"""The epoch rates a GNSS receiver runs at: its epochs lie on a grid of whole fractions of the
GPS second (``docs/physics.md`` §14.2) [Hz]."""
RESAMPLE_RATIOS = (1.05, 25.0)
"""The ratios of a log's rate to its receiver's that :func:`receiver_epochs` looks for: below
1.05 a resampling adds too few epochs to tell, above 25 the logger writes faster than any
format's time stamps hold [-]."""
_SEARCH_SAMPLES = 150
"""Epochs of each stretch the receiver's grid is searched on [-]."""
_CHUNK_KNOTS = 20
"""Receiver epochs per stretch on which a found grid is checked before it replaces the log's
epochs [-]."""
_SMOOTH = 1e-6
"""Weight of the knots' second differences in the piecewise-linear fit (in units of half the
resolution): it only settles knots the epochs do not determine (a ×1.1 resampling with every
epoch half-way between two knots) [-]."""


def _hat_fit(t: np.ndarray, y: np.ndarray, period: float, phase: float) -> tuple:
    """Least-squares piecewise-linear fit of the columns *y* (n × m, in their tolerances'
    units) with knots at ``phase + k period``.

    Returns the knots' times and values (K × m), whether each knot is determined by the epochs
    (its weight at least 0.2), each epoch's knot index k (it lies between knots k and k+1) and
    the residuals (n × m) and segment slopes (n × m, per second) at the epochs.
    """
    s = (t - phase) / period
    k = np.floor(s).astype(np.int64)
    w = s - k
    k0 = int(k[0])
    k = k - k0
    n_k = int(k[-1]) + 2
    a, b = 1.0 - w, w
    d0 = np.bincount(k, a * a, n_k) + np.bincount(k + 1, b * b, n_k)
    d1 = np.bincount(k, a * b, n_k)[: n_k - 1]
    rhs = np.column_stack(
        [np.bincount(k, a * c, n_k) + np.bincount(k + 1, b * c, n_k) for c in y.T]
    )
    ab = np.zeros((5, n_k))
    ab[2] = d0
    ab[1, 1:] = d1
    ab[3, :-1] = d1
    if n_k >= 3:  # the second differences' penalty D^T D (rows 1, −2, 1)
        p0 = np.zeros(n_k)
        for off, c in enumerate((1.0, 4.0, 1.0)):
            p0[off : n_k - 2 + off] += c
        p1 = np.zeros(n_k - 1)
        p1[: n_k - 2] -= 2.0
        p1[1:] -= 2.0
        ab[2] += _SMOOTH * p0
        ab[1, 1:] += _SMOOTH * p1
        ab[3, :-1] += _SMOOTH * p1
        ab[0, 2:] += _SMOOTH
        ab[4, :-2] += _SMOOTH
    ab[2] += 1e-12 * max(float(d0.max()), 1.0)  # a knot no epoch touches
    x = solve_banded((2, 2), ab, rhs, check_finite=False)
    fitted = a[:, None] * x[k] + b[:, None] * x[k + 1]
    # a stamp's error moves the fit by its segment's slope and, through the knots, by its
    # neighbours': the largest of the three
    seg = np.abs(np.diff(x, axis=0)) / period
    seg = np.maximum(
        seg, np.maximum(np.vstack([seg[:1], seg[:-1]]), np.vstack([seg[1:], seg[-1:]]))
    )
    slope = seg[np.minimum(k, seg.shape[0] - 1)]
    knots_t = phase + (np.arange(n_k) + k0) * period
    return knots_t, x, d0 >= 0.2, k, y - fitted, slope


def _fit_score(t, y, e_t, period, phase, chunks: bool = False):
    """How well the epochs lie on a piecewise-linear curve with knots on the grid: per column
    the mean of r²/v, v = 1 (half the resolution, the units of *y*) + (slope e_t)² (a time
    stamp off by up to e_t); the largest over the columns (per stretch of
    :data:`_CHUNK_KNOTS` knots with *chunks*), and the fit.
    """
    fit = _hat_fit(t, y, period, phase)
    _, _, support, k, r, slope = fit
    z = r * r / (1.0 + (slope * e_t) ** 2)
    # the knots the epochs touch are the curve's free parameters
    touched = np.bincount(np.r_[k, k + 1], minlength=support.size) > 0
    if not chunks:
        n_free = t.size - int(touched.sum())
        return (float(z.mean(axis=0).max()) if n_free > 0 else np.inf), n_free, fit
    c = k // _CHUNK_KNOTS
    n_c = int(c[-1]) + 1
    cnt = np.bincount(c, minlength=n_c)
    score = np.max([np.bincount(c, zc, n_c) for zc in z.T], axis=0) / np.maximum(cnt, 1)
    kn = np.arange(support.size)
    n_free = cnt - np.bincount(np.minimum(kn // _CHUNK_KNOTS, n_c - 1), touched, n_c)
    return score, n_free, fit


def _grid_phases(period: float, score) -> tuple[float, float]:
    """The phase of the grid (period *period*) with the smallest *score*: 40 steps over the
    period, then twice 20 steps around the best (not where the best of the 40 is far off: a
    receiver's noise).
    """
    step = period / 40.0
    phases = np.arange(40) * step
    for level in range(3):
        vals = [score(p) for p in phases]
        best = float(phases[int(np.argmin(vals))])
        if level == 0 and not np.min(vals) < 0.05 * np.median(vals):
            break  # no phase stands out: no knots here
        phases = best + np.linspace(-step, step, 21)
        step /= 10.0
    return best, float(np.min(vals))


def _linear_grid(t: np.ndarray, y: np.ndarray, e_t: float) -> tuple[float, float] | None:
    """The receiver's grid (period, phase) [s] if the epochs (strictly increasing *t* [s])
    lie on a piecewise-linear curve whose knots are a grid of one of
    :data:`RECEIVER_RATES_HZ`, within the columns' resolution, in a stretch of
    :data:`_SEARCH_SAMPLES` epochs: the coarsest such grid, and never one where a grid twice as
    coarse fits too (a stretch smoother than any receiver: a straight line at a constant speed
    without noise). None otherwise.
    """
    p_log = float(np.median(np.diff(t)))
    lo, hi = RESAMPLE_RATIOS
    periods = sorted((1.0 / f for f in RECEIVER_RATES_HZ if lo * p_log < 1.0 / f <= hi * p_log),
                     reverse=True)  # fmt: skip
    n = t.size
    if not periods or n < 20:
        return None
    m = _SEARCH_SAMPLES
    starts = sorted({max(0, min(n - m, int(f * n) - m // 2)) for f in (0.5, 0.25, 0.75)})
    for s in starts:
        tw = np.ascontiguousarray(t[s : s + m], dtype=np.float64)
        yw = np.ascontiguousarray(y[s : s + m], dtype=np.float64)
        for p in periods:
            if tw[-1] - tw[0] < 4 * p:
                continue

            def score(phase: float, p: float = p, tw=tw, yw=yw) -> float:
                # compiled: ~200 grids a log (the same fit as _fit_score's, to 1e-13)
                sc, n_free = hat_score(tw, yw, p, phase, e_t, _SMOOTH)
                return sc if n_free >= max(4, 0.04 * tw.size) else np.inf

            phase, best = _grid_phases(p, score)
            if best > 1.0:
                continue
            if _grid_phases(2.0 * p, lambda ph, tw=tw, yw=yw, p=p: score(ph, 2.0 * p))[1] <= 1.0:
                break  # smoother than any receiver here: another stretch decides
            return p, phase
        else:
            return None  # no grid fits the receiver's noise here
    return None


def _hold_grid(t: np.ndarray, change: np.ndarray) -> np.ndarray | None:
    """The receiver's epochs behind a logger that holds the last (or writes the nearest)
    receiver epoch at its own time stamps: the measurements change exactly when the epochs
    (strictly increasing *t* [s]) cross a knot of a grid of one of :data:`RECEIVER_RATES_HZ`
    (*change*: the epoch's measurements differ from the one before), within the stamps'
    rounding (:func:`_stamp_error`), at 98 % of the changes and of the values held. Returns per
    changing epoch its knot (the grid at the latest phase the changes allow), or None.
    """
    n = t.size
    if n < 20:
        return None
    e = max(_stamp_error(t), 4 * STAMP_ERROR_S)
    p_log = float(np.median(np.diff(t)))
    lo, hi = RESAMPLE_RATIOS
    periods = sorted((1.0 / f for f in RECEIVER_RATES_HZ if lo * p_log < 1.0 / f <= hi * p_log),
                     reverse=True)  # fmt: skip
    s = max(0, n // 2 - 1000)
    tw, cw = t[s : s + 2000], change[s + 1 : s + 2000]
    if cw.sum() < 3 or (~cw).sum() < 3:
        return None
    for p in periods:
        if tw[-1] - tw[0] < 4 * p:
            continue
        ph = np.arange(400) * (p / 400.0)

        def cell(x: np.ndarray, ph: np.ndarray = ph, p: float = p) -> np.ndarray:
            """Per epoch and phase the grid's step it lies in."""
            return np.floor((x[:, None] - ph) / p)

        # a change: a knot in (t[i-1] - e, t[i] + e]; a value held: none in (t[i-1] + e, t[i] - e]
        g = e + p / 400.0  # and the phase grid's step
        crossed = cell(tw[1:] + g) - cell(tw[:-1] - g) >= 1
        clear = cell(tw[1:] - g) == cell(tw[:-1] + g)
        ok_c = (crossed & cw[:, None]).sum(axis=0) / cw.sum()
        ok_h = (clear & ~cw[:, None]).sum(axis=0) / (~cw).sum()
        j = int(np.argmax(np.minimum(ok_c, ok_h)))
        if min(ok_c[j], ok_h[j]) < 0.98:
            continue
        idx = np.flatnonzero(change)
        k = np.floor((t[idx] + e - ph[j]) / p)
        theta = float(np.min(t[idx[1:]] - k[1:] * p))  # the latest phase the changes allow
        # else (stamps rounded across a knot) the middle of the phases that agree
        run = np.minimum(ok_c, ok_h) >= 0.98
        a, b = j, j
        while a > 0 and run[a - 1]:
            a -= 1
        while b < run.size - 1 and run[b + 1]:
            b += 1
        mid = 0.5 * float(ph[a] + ph[b])
        for th in (_snap(theta, t), theta, _snap(mid, t), mid):
            k = np.floor((t[idx] + e - th) / p + 1e-9)
            knots = np.round(th + k * p, 9)
            before = np.concatenate([[-np.inf], t[idx[1:] - 1]])
            # each change its own knot (a knot within e of two changes is not a grid)
            if np.all((knots > before - e) & (knots <= t[idx] + e)) and np.all(np.diff(knots) > 0):
                return knots
    return None


def _snap(phase: float, t: np.ndarray) -> float:
    """*phase* [s] on the time stamps' resolution (a receiver stamps its epochs at it, the log
    at the same): a phase off by a fraction of a millisecond moves an epoch at a whole second
    into the bin before.
    """
    q = _time_quantum(t)
    return float(np.round(phase / q) * q) if q > 0 else phase


def _logger_clock(t: np.ndarray) -> tuple[np.ndarray, float] | None:
    """The times a logger writing at a steady rate made its epochs at, behind stamps rounded
    to their resolution q: the least-squares line of the stamps over the epochs' count, when
    every step is n or n + 1 stamp units and every stamp lies within q/2 of the line but not
    all on it (stamps that hold the rate need no clock); and their uncertainty, three standard
    deviations of the line's ends, q/√(3n)·3 [s]. None otherwise (a gap, a jitter).
    """
    n = t.size
    q = _time_quantum(t) if n > 2 else 0.0
    if q == 0:
        return None
    steps = np.round(np.diff(t) / q)
    if steps.min() < 1 or steps.max() - steps.min() > 1:
        return None
    i = np.arange(n) - 0.5 * (n - 1)
    slope = float(np.dot(i, t - t.mean()) / np.dot(i, i))
    line = t.mean() + slope * i
    dev = np.abs(line - t)
    err = 3.0 * q / np.sqrt(3.0 * n)
    if dev.max() <= 4 * STAMP_ERROR_S or dev.max() > 0.5 * q + err + 4 * STAMP_ERROR_S:
        return None
    return line, err


def _time_quantum(t: np.ndarray) -> float:
    """The time stamps' resolution: the coarsest of 1, 0.1, 0.01 and 0.001 s whose multiples
    hold every stamp within :data:`STAMP_ERROR_S` (relative to the first; 0 if none) [s].
    """
    x = t - t[0]
    for q in (1.0, 0.1, 0.01, 0.001):
        if np.all(np.abs(x / q - np.round(x / q)) * q <= 4 * STAMP_ERROR_S):
            return q
    return 0.0


def _unwrapped(x: np.ndarray) -> np.ndarray:
    """Angles [deg] made continuous by whole turns (exactly: the values' own digits stay)."""
    d = np.diff(x)
    return x + 360.0 * np.concatenate([[0.0], np.cumsum(-np.round(d / 360.0))])


def _stamp_error(t: np.ndarray) -> float:
    """How far a time stamp may lie from the time its values were made [s]: half the stamps'
    resolution where the log's steps are rounded to it (their lengths in stamp units differ and
    share no factor: 15 Hz in 0.01 s stamps steps 0.06 and 0.07 s, 60 Hz 0.01 and 0.02 s),
    else :data:`STAMP_ERROR_S` (one step, or whole multiples of one: a receiver's dropouts).
    Taking half the resolution for every log would let a grid slower than a 10 Hz receiver's
    (8 Hz) pass its noise.
    """
    d = np.diff(t)
    q = _time_quantum(t) if t.size > 1 else 0.0
    if d.size == 0 or d.min() <= 0 or q == 0:
        return STAMP_ERROR_S
    n = np.unique(np.round(d / q).astype(np.int64))
    if n.size > 1 and np.gcd.reduce(n) == 1:
        return 0.5 * q
    return STAMP_ERROR_S


def receiver_epochs(epochs: pd.DataFrame) -> tuple[pd.DataFrame, np.ndarray, dict]:
    """The receiver's own epochs behind a log a logger copied or resampled at any rate
    (``docs/physics.md`` §14.2): copies and held values collapsed and epochs on the line
    between their neighbours dropped (:func:`unique_epochs`); held values at a rate that is not
    a whole multiple of the receiver's moved to the receiver's epochs (the grid their changes
    cross, :func:`_hold_grid`); and a linear resampling at any ratio — whose epochs lie on a
    piecewise-linear curve with the receiver's epochs as knots, within the format's resolution
    and the time stamps' rounding — replaced by those knots, fitted (:func:`_linear_grid`,
    checked per stretch of :data:`_CHUNK_KNOTS` knots; a stretch that is off keeps its epochs).

    Parameters
    ----------
    epochs : pandas.DataFrame
        Epoch rows in time order with ``t_s`` [s] and the columns of :data:`_HELD_COLUMNS`.

    Returns
    -------
    out : pandas.DataFrame
        The epochs kept or reconstructed (``t_s`` [s], the measurements; a reconstructed
        epoch's other columns are those of the nearest epoch), index reset.
    source : numpy.ndarray of int
        Per row of *out* the row of *epochs* it is, or the nearest one.
    counts : dict
        ``epochs_duplicate``, ``epochs_held``, ``epochs_interpolated`` (:func:`unique_epochs`),
        ``epochs_resampled`` (epochs a resampling at another ratio added: the log's less the
        receiver's) and ``receiver_rate_hz`` (the rate found, NaN if none).
    """
    keep, same, held = _copies(epochs)
    counts: dict = {"epochs_duplicate": int(same.sum()), "epochs_held": int(held.sum()),
                    "epochs_interpolated": 0, "epochs_resampled": 0,
                    "receiver_rate_hz": float("nan")}  # fmt: skip
    t_all = epochs["t_s"].to_numpy(float)
    have = all(c in epochs.columns for c in _HELD_COLUMNS)
    new_t = None
    if have and held.any():  # held at a rate that is not a whole multiple: re-time
        rest = np.flatnonzero(~same)
        tr = t_all[rest]
        if np.all(np.diff(tr) > 0):
            knots = _hold_grid(tr, ~held[rest])
            if knots is not None and np.all(np.diff(knots) > 0):
                kept = tr[~held[rest]]
                new_t = np.where(np.abs(knots - kept) > 4 * STAMP_ERROR_S, knots, kept)
                counts["receiver_rate_hz"] = round(float(1.0 / np.median(np.diff(knots))), 6)
    rest = np.flatnonzero(keep)
    interp = np.zeros(len(epochs), dtype=bool)
    if new_t is None:
        interp[rest] = interpolated_epochs(epochs.iloc[rest])
        counts["epochs_interpolated"] = int(interp.sum())
    source = np.flatnonzero(keep & ~interp)
    out = epochs.iloc[source].reset_index(drop=True)
    if interp.any() and source.size > 1:  # the receiver's epochs, kept: their rate
        counts["receiver_rate_hz"] = round(float(1.0 / np.median(np.diff(t_all[source]))), 6)
    if new_t is not None:
        out["t_s"] = new_t
        return out, source, counts
    if not have or len(out) < 20:
        return out, source, counts
    t = out["t_s"].to_numpy(float)
    raw = [out[c].to_numpy(float) for c in _HELD_COLUMNS]
    if not (np.all(np.diff(t) > 0) and all(np.isfinite(x).all() for x in raw)):
        return out, source, counts
    units = []
    cols = []
    for c, x in zip(_HELD_COLUMNS, raw, strict=True):
        u = max(0.5 * _quantum(x, _QUANTUM_CAP[c]), 64 * EPS * max(float(np.max(np.abs(x))), 1.0))
        xu = _unwrapped(x) if c in _ANGLE_COLUMNS else x
        units.append(u)
        cols.append((xu - xu[0]) / u)
    y = np.column_stack(cols)
    # the stamps' rounding is seen in the log's own steps, before any epoch was dropped; a
    # logger writing at a steady rate gives its own times back (tf: the times the fit uses)
    tf, e_t = t, _stamp_error(t)
    log_rows = np.flatnonzero(~same)
    if np.all(np.diff(t_all[log_rows]) > 0):
        e_t = _stamp_error(t_all[log_rows])
        clock = _logger_clock(t_all[log_rows])
        if clock is not None:
            t_clock = np.full(t_all.size, np.nan)
            t_clock[log_rows] = clock[0]
            if np.all(np.diff(t_clock[source]) > 0):
                tf, e_t = t_clock[source], clock[1]
    grid = _linear_grid(tf, y, e_t)
    if grid is None:
        return out, source, counts
    p, phase = grid
    score, n_free, fit = _fit_score(tf, y, e_t, p, phase, chunks=True)
    good = (score <= 1.0) & (n_free >= 2)
    knots_t, _, support, k, _, _ = fit
    # the receiver stamps its epochs on the stamps' resolution: a phase within half of it is
    # the logger's rounding of its own times
    q = _time_quantum(t)
    snapped = _snap(phase, t)
    if abs(snapped - phase) <= 0.5 * q + 4 * STAMP_ERROR_S:
        knots_t = knots_t + (snapped - phase)
    knots_t = np.round(knots_t, 9)
    if not good.any():
        return out, source, counts
    # the knots of the stretches that fit, each the receiver's epoch; the other stretches keep
    # the log's epochs; every float measurement fitted by the same curve
    kn = np.arange(knots_t.size)
    chunk_of_knot = np.minimum(kn // _CHUNK_KNOTS, good.size - 1)
    use_knot = support & good[chunk_of_knot] & (knots_t >= t[0] - p) & (knots_t <= t[-1] + p)
    keep_epoch = ~good[k // _CHUNK_KNOTS]
    t_new = np.concatenate([knots_t[use_knot], t[keep_epoch]])
    order = np.argsort(t_new, kind="stable")
    t_new = t_new[order]
    if not np.all(np.diff(t_new) > 0):
        return out, source, counts
    nearest = np.clip(np.searchsorted(t, t_new), 1, t.size - 1)
    nearest -= (t_new - t[nearest - 1]) < (t[nearest] - t_new)
    # each row names an epoch of its own (the wheel table pairs the wheels by it): a knot whose
    # nearest epoch is one kept beside it (at a stretch's edge) is left out
    fresh = np.concatenate([[True], np.diff(nearest) != 0])
    order, t_new, nearest = order[fresh], t_new[fresh], nearest[fresh]
    rec = out.iloc[nearest].reset_index(drop=True)
    rec["t_s"] = t_new
    num = [c for c in out.columns if c != "t_s" and pd.api.types.is_float_dtype(out[c])
           and np.isfinite(out[c].to_numpy(float)).all()]  # fmt: skip
    vals = np.column_stack(
        [_unwrapped(out[c].to_numpy(float)) if c in _ANGLE_COLUMNS else out[c].to_numpy(float)
         for c in num]
    )  # fmt: skip
    _, xk, _, _, _, _ = _hat_fit(tf, vals - vals[0], p, phase)
    fitted = np.concatenate([xk[use_knot] + vals[0], vals[keep_epoch]])[order]
    for j, c in enumerate(num):
        rec[c] = np.mod(fitted[:, j], 360.0) if c in _ANGLE_COLUMNS else fitted[:, j]
    counts["epochs_resampled"] = int(len(out) - len(rec))
    counts["receiver_rate_hz"] = 1.0 / p
    return rec, source[nearest], counts


_ESTIMATED = ("slide_point_m", "force_ratio", "mu", "kappa_beta", "mu_sigma")
"""Columns a per-sample estimator fills (NaN after the kinematics)."""


def _loads(
    vehicle: Vehicle,
    t: np.ndarray,
    u_a: np.ndarray,
    v_a: np.ndarray,
    r: np.ndarray,
    ay: np.ndarray,
) -> tuple[np.ndarray, dict]:
    """The quasi-static longitudinal load transfer per wheel and each axle's lateral one."""
    # quasi-static longitudinal load transfer m a_x h / L (needs the wheelbase): in a steady
    # turn the body-axis a_x = U̇ − V r is not zero, because the CG moves sideways (V ≠ 0)
    dfz_x = np.zeros(t.size)
    if vehicle.wheelbase_m is not None and vehicle.cg_offset is not None and t.size > 1:
        u_cg = u_a - r * vehicle.cg_offset[1]
        v_cg = v_a + r * vehicle.cg_offset[0]
        ax = np.gradient(u_cg, t) - v_cg * r if np.all(np.diff(t) > 0) else -v_cg * r
        dfz_x = vehicle.mass_kg * ax * vehicle.cg_height_m / vehicle.wheelbase_m / 2.0
    dfz = dict(
        zip(
            ("front", "rear"),
            lateral_load_transfer(
                ay,
                vehicle.mass_kg,
                vehicle.cg_height_m,
                vehicle.axle_masses_kg,
                (vehicle.track_front_m, vehicle.track_rear_m),
                vehicle.roll_centre_heights_m,
                vehicle.roll_stiffness_front_fraction,
                np.deg2rad(vehicle.roll_gradient_deg_per_g),
            ),
            strict=True,
        )
    )
    return dfz_x, dfz


def _grips(
    motion: pd.DataFrame,
    vehicle: Vehicle,
    o: FrictionOptions,
    t: np.ndarray,
    u_a: np.ndarray,
    v_a: np.ndarray,
    r: np.ndarray,
    ay: np.ndarray,
    ay_meas: np.ndarray,
    steer: np.ndarray | None,
) -> tuple:
    """The axles' force, load, grip the bound takes (with the yaw moment the split leaves out),
    the model's grip (without it) and the grip's noise (docs/physics.md §14.1).
    """
    earth = None
    if "course_rad" in motion.columns and "heading_rad" in motion.columns:
        earth = (motion["course_rad"].to_numpy(float), motion["heading_rad"].to_numpy(float))
    axle_force, axle_load, grip, grip_sig = axle_grip(
        vehicle, t, u_a, v_a, r, ay, ay_measured=np.isfinite(ay_meas), noise=o.noise, earth=earth,
        steer=steer,
    )  # fmt: skip
    # the model's grip: the split without the yaw moment it leaves out (within the model's
    # force error); the bound takes it (docs/physics.md §14.1)
    grip_proven = grip
    _, _, grip, _ = axle_grip(
        vehicle, t, u_a, v_a, r, ay, ay_measured=np.isfinite(ay_meas), noise=o.noise, earth=earth,
        unseen=False,
    )  # fmt: skip
    return axle_force, axle_load, grip_proven, grip, grip_sig


def _flags(
    fz: np.ndarray,
    steady: np.ndarray,
    ay: np.ndarray,
    r: np.ndarray,
    spd: np.ndarray,
    alpha: np.ndarray,
    o: FrictionOptions,
) -> np.ndarray:
    """A wheel's flag per sample: codes of :data:`FLAGS`, 0 where it is steady cornering."""
    flag = np.zeros(fz.size, dtype=np.int8)  # codes of FLAGS: 0 = steady cornering
    conds = [
        ("wheel_lifted", ~(fz > 0)),
        ("not_steady", ~steady),
        (
            "not_cornering",
            (np.abs(ay) < o.min_lateral_accel_mps2) | (np.abs(r) < np.deg2rad(o.min_yaw_rate_dps)),
        ),
        ("low_speed", (spd < o.min_speed_mps) | np.isnan(alpha)),
    ]
    for name, m in conds:  # later entries take precedence
        flag[m] = FLAGS.index(name)
    return flag


def _wheel_frame(
    motion: pd.DataFrame,
    vehicle: Vehicle,
    o: FrictionOptions,
    wname: str,
    body: dict,
    loads: tuple[np.ndarray, dict, dict],
    grips: tuple,
) -> dict:
    """One wheel's arrays of :data:`WHEEL_COLUMNS` (but the estimated ones) and what a
    per-sample estimator needs besides (keys starting with ``_``).
    """
    t, ay, r, steer = body["t_s"], body["lateral_accel_mps2"], body["_r"], body["_steer"]
    dfz_x, m_axle, dfz = loads
    axle_force, axle_load, grip_proven, grip, _ = grips
    dx, dy = vehicle.wheel_offsets[wname]
    axle = AXLE_OF[wname]
    tyre = vehicle.tyres[axle]
    delta: np.ndarray | float = steer if axle == "front" and steer is not None else 0.0
    u_i, v_i = point_velocity(body["_u_a"], body["_v_a"], r, dx, dy)
    alpha = slip_angle(u_i, v_i, delta)
    spd = np.hypot(u_i, v_i)
    radius = path_radius(spd, r)
    left, right = wheel_loads(m_axle[axle], dfz[axle])
    fz = (left if wname.endswith("left") else right) + (dfz_x if axle == "rear" else -dfz_x)
    mass = fz / G0
    length = tyre.contact_length(mass)
    c = vehicle.cornering_stiffness(axle, fz)
    force = mass * ay  # the wheel's load share of the axle force m⁰ a_y
    sig_alpha_white = np.sqrt(
        np.deg2rad(o.noise.heading_white_deg) ** 2
        + body["_sig_v_rel"] ** 2
        + (body["_sig_r"] * dx / np.maximum(np.abs(u_i), 1e-9)) ** 2
    )
    with np.errstate(invalid="ignore"):
        force_sigma = np.abs(force) * body["_sig_f_rel"]
    with np.errstate(divide="ignore", invalid="ignore"):
        utilisation = np.where(fz > 0, np.abs(force) / fz, np.nan)
    flag = _flags(fz, body["steady"], ay, r, spd, alpha, o)
    frame = {
        "t_s": t,
        "epoch": body["epoch"],
        "wheel": np.full(t.size, list(vehicle.wheel_offsets).index(wname), np.int8),
        "speed_mps": spd,
        "slip_angle_rad": alpha,
        "steer_rad": np.broadcast_to(delta, t.shape).astype(float),
        "radius_m": radius,
        "mass_kg": mass,
        "contact_length_m": length,
        "load_N": fz,
        "force_N": force,
        "flag": flag,
        "lateral_accel_mps2": ay,
        "utilisation": utilisation,
        "steady": body["steady"],
        "cornering_stiffness_N_per_rad": c,
        "slip_sigma_rad": sig_alpha_white,
        "force_sigma_N": force_sigma,
        "axle_force_N": axle_force[axle],
        "axle_load_N": axle_load[axle],
        "grip_used": grip[axle],
        "grip_proven": grip_proven[axle],
        "grip_sigma": body["grip_sigma"],
        # for a per-sample estimator
        "_axle": axle,
        "_dx": dx,
        "_u": u_i,
        "_sig_v_rel": body["_sig_v_rel"],
        "_sig_f_rel": body["_sig_f_rel"],
    }
    if axle == "front":
        frame |= {c: motion[c].to_numpy(float) for c in STEERING_TORQUE if c in motion}
    return frame


def wheel_kinematics(
    motion: pd.DataFrame, vehicle: Vehicle, options: FrictionOptions | None = None
) -> tuple[list[dict], dict]:
    """Per wheel and sample: velocity, slip angle, load, stiffness, force share, their noise,
    the axle's measured grip and the flags of samples that are not steady cornering.

    Parameters
    ----------
    motion : pandas.DataFrame
        Motion table of the measurement point (:func:`motion_from_epochs`; columns as
        :func:`gripsense.estimate.friction.friction_from_motion` describes).
    vehicle : Vehicle
        Vehicle description.
    options : FrictionOptions, optional
        Gates and the noise model.

    Returns
    -------
    frames : list of dict
        One per analysed wheel: the arrays of :data:`WHEEL_COLUMNS` (the estimated columns NaN,
        ``flag`` as codes of :data:`FLAGS`, 0 where the sample is steady cornering) and what a
        per-sample estimator needs besides (keys starting with ``_``).
    meta : dict
        Wheels analysed, and notes on wheels left out.
    """
    o = options or FrictionOptions()
    meta: dict = {}
    t = motion["t_s"].to_numpy(float)
    rows = motion["epoch"].to_numpy()
    u_a = motion["u_mps"].to_numpy(float)
    v_a = motion["v_mps"].to_numpy(float)
    r = motion["yaw_rate_rps"].to_numpy(float)
    v = np.hypot(u_a, v_a)
    st = motion["steer_rad"].to_numpy(float)
    steer = None if np.isnan(st).all() else st
    # reference point for a_y: the CG if known, else the middle of the known wheels (lateral)
    if vehicle.cg_offset is not None:
        dy_ref = vehicle.cg_offset[1]
    else:
        dy_ref = float(np.mean([o_[1] for o_ in vehicle.wheel_offsets.values()]))
    ay_meas = motion["ay_mps2"].to_numpy(float)
    ay = np.where(np.isfinite(ay_meas), ay_meas, (u_a - r * dy_ref) * r)
    steady = _steady(t, v, r, o)
    dfz_x, dfz = _loads(vehicle, t, u_a, v_a, r, ay)
    loads = (dfz_x, dict(zip(("front", "rear"), vehicle.axle_masses_kg, strict=True)), dfz)
    grips = _grips(motion, vehicle, o, t, u_a, v_a, r, ay, ay_meas, steer)
    sig_v_rel = o.noise.velocity_mps / np.maximum(v, 1e-9)
    sig_r = np.deg2rad(o.noise.yaw_rate_dps)
    with np.errstate(divide="ignore", invalid="ignore"):
        sig_f_rel = np.sqrt(sig_v_rel**2 + (sig_r / np.abs(r)) ** 2)
    body = {  # the body's arrays every wheel shares (keys starting with "_": not columns)
        "t_s": t, "epoch": rows, "lateral_accel_mps2": ay, "steady": steady,
        "grip_sigma": grips[4], "_u_a": u_a, "_v_a": v_a, "_r": r, "_steer": steer,
        "_sig_v_rel": sig_v_rel, "_sig_r": sig_r, "_sig_f_rel": sig_f_rel,
    }  # fmt: skip
    wheels_done, frames = [], []
    nan = np.full(t.size, np.nan)
    for wname in vehicle.wheel_offsets:
        if AXLE_OF[wname] == "front" and steer is None:
            continue
        frame = _wheel_frame(motion, vehicle, o, wname, body, loads, grips)
        frames.append(frame | dict.fromkeys(_ESTIMATED, nan))
        wheels_done.append(wname)
    meta["wheels"] = wheels_done
    if not wheels_done:
        meta["note"] = "no wheel could be analysed (front wheels need a steering channel)"
    if steer is None and any(AXLE_OF[w] == "front" for w in vehicle.wheel_offsets):
        meta["front_wheels"] = "skipped: no steering channel (--steer-csv)"
    return frames, meta


def wheel_table(frames: list[dict], vehicle: Vehicle) -> pd.DataFrame:
    """The wheel table of :func:`wheel_kinematics`' frames (after an estimator's stage).

    Parameters
    ----------
    frames : list of dict
        Per wheel the arrays of :data:`WHEEL_COLUMNS`.
    vehicle : Vehicle
        Vehicle description (the wheel names).

    Returns
    -------
    pandas.DataFrame
        One row per wheel and sample, columns :data:`WHEEL_COLUMNS` (then the steering-torque
        columns of :data:`STEERING_TORQUE` the front wheels carry, NaN on the rear),
        ``wheel`` and ``flag`` categorical.
    """
    if not frames:
        wheels = pd.DataFrame({c: [] for c in WHEEL_COLUMNS})
        wheels["wheel"] = pd.Categorical(wheels["wheel"], categories=list(vehicle.wheel_offsets))
        wheels["flag"] = pd.Categorical(wheels["flag"], categories=list(FLAGS))
        return wheels[WHEEL_COLUMNS]
    # one table from the wheels' columns (one DataFrame, categories from their codes: the
    # per-wheel frames, their concatenation and the string → category conversion cost ~4 ms
    # of a 75 s log)
    extra = [c for c in STEERING_TORQUE if any(c in f for f in frames)]
    cols = {
        c: np.concatenate(
            [np.broadcast_to(f.get(c, np.nan), f["t_s"].shape).astype(float, copy=False)
             if c in extra else np.broadcast_to(f[c], f["t_s"].shape) for f in frames]
        )
        for c in (*WHEEL_COLUMNS, *extra)
    }  # fmt: skip
    cols["wheel"] = pd.Categorical.from_codes(cols["wheel"], categories=list(vehicle.wheel_offsets))
    cols["flag"] = pd.Categorical.from_codes(cols["flag"], categories=list(FLAGS))
    return pd.DataFrame(cols)
