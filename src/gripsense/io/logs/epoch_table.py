"""The epoch table from any log format: columns, time base, sources and channel rates.

Every reader (NMEA in :mod:`gripsense.io.logs.nmea`, VBOX, UBX, MDF4, CAN) returns the same table,
one row per receiver time instant, with the columns of :data:`EPOCH_COLUMNS`
(``docs/ingest.md``). The NMEA reader builds it from its sentences; the other readers hand
their decoded channels to :func:`build_epochs`, which fills what a format does not carry with
NaN, derives the ISO yaw rate from the heading where the log has no rate channel (as for NMEA
without ROT) and converts the time base.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from gripsense.io.logs.nmea.epochs import EPOCH_COLUMNS, yaw_from_heading
from gripsense.io.logs.sources import HEADING_SOURCES, YAW_RATE_SOURCES

__all__ = ["EPOCH_COLUMNS", "EXTRA_COLUMNS", "build_epochs", "channel_rates"]

EXTRA_COLUMNS = {
    "steer_rad": "road-wheel steer angle, ISO (left positive) [rad]",
    "steering_wheel_rad": "steering-wheel angle, ISO (left positive) [rad]",
    "torque_nm": "steering (column) torque, ISO (positive steers left) [N·m]",
    "assist_nm": "power-steering assist torque at the steering wheel, ISO [N·m]",
    "rack_n": "rack force, ISO (positive steers left) [N]",
    "torque_samples": "samples of the steering-torque channel averaged into the epoch [-]",
    "heading_acc_deg": "the receiver's stated heading accuracy (1 σ) [deg]",
    "speed_acc_mps": "the receiver's stated speed accuracy (1 σ) [m/s]",
}
"""Columns a format may add after :data:`EPOCH_COLUMNS` (only when it carries them)."""

_RATE_COLUMNS = (
    "lat_deg",
    "speed_mps",
    "course_deg",
    "heading_deg",
    "pitch_deg",
    "roll_deg",
    "yaw_rate_rps",
    *EXTRA_COLUMNS,
)


def build_epochs(
    values: dict[str, np.ndarray],
    seconds: np.ndarray,
    *,
    has_date: bool,
    heading_source: str,
    yaw_rate_source: str | None = None,
) -> pd.DataFrame:
    """The epoch table from decoded channels.

    Parameters
    ----------
    values : dict
        Column name (of :data:`EPOCH_COLUMNS` or :data:`EXTRA_COLUMNS`) -> values per epoch
        [the column's unit]; absent columns are NaN.
    seconds : numpy.ndarray
        Time of each epoch: seconds since 1970-01-01 UTC when *has_date*, else seconds since
        midnight UTC or any other origin [s]; NaN where unknown.
    has_date : bool
        Whether *seconds* are absolute (then ``time_utc`` is set, else NaT).
    heading_source : str
        Category of ``heading_source`` for the epochs with a heading (of
        ``HEADING_SOURCES``).
    yaw_rate_source : str, optional
        Category of ``yaw_rate_source`` for the epochs whose ``yaw_rate_rps`` is given; the
        others get the heading's central difference (source ``heading``), as NMEA without ROT.

    Returns
    -------
    pandas.DataFrame
        :data:`EPOCH_COLUMNS`, then the extra columns present in *values*.
    """
    abs_s = np.asarray(seconds, dtype=float)
    n = abs_s.size
    unknown = set(values) - set(EPOCH_COLUMNS) - set(EXTRA_COLUMNS)
    if unknown:
        raise ValueError(f"build_epochs: unknown columns {sorted(unknown)}")
    cols: dict[str, object] = {}
    for c in EPOCH_COLUMNS:
        if c in ("time_utc", "t_s", "heading_source", "yaw_rate_source"):
            continue
        v = values.get(c)
        cols[c] = np.full(n, np.nan) if v is None else np.asarray(v, dtype=float)
    # to the microsecond: float seconds since 1970 hold ~0.2 µs, and t_s from the rounded
    # stamps is exact to it (0.1 s steps stay 0.1 s)
    finite = ~np.isnan(abs_s)
    us = np.zeros(n, dtype=np.int64)
    us[finite] = np.round(abs_s[finite] * 1e6).astype(np.int64)
    nat = ~finite | (not has_date)
    stamp = us * 1000
    stamp[nat] = np.iinfo(np.int64).min
    cols["time_utc"] = pd.DatetimeIndex(stamp.view("M8[ns]")).tz_localize("UTC")
    first = np.flatnonzero(finite)
    t_s = np.full(n, np.nan)
    if first.size:
        t_s[finite] = (us[finite] - us[first[0]]) * 1e-6
    cols["t_s"] = t_s
    heading = np.asarray(cols["heading_deg"], dtype=float)
    hcode = np.where(np.isnan(heading), -1, HEADING_SOURCES.index(heading_source))
    cols["heading_source"] = pd.Categorical.from_codes(
        hcode.astype(np.int8), categories=HEADING_SOURCES
    )
    yaw = np.array(cols["yaw_rate_rps"], dtype=float)
    ysrc = np.full(n, -1, dtype=np.int8)
    if yaw_rate_source is not None:
        ysrc[~np.isnan(yaw)] = YAW_RATE_SOURCES.index(yaw_rate_source)
    else:
        yaw[:] = np.nan
    if np.isnan(yaw).any():
        yaw_from_heading(np.asarray(cols["t_s"], dtype=float), heading, yaw, ysrc)
    cols["yaw_rate_rps"] = yaw
    cols["yaw_rate_source"] = pd.Categorical.from_codes(ysrc, categories=YAW_RATE_SOURCES)
    out = {c: cols[c] for c in EPOCH_COLUMNS}
    for c in EXTRA_COLUMNS:
        if c in values:
            out[c] = np.asarray(values[c], dtype=float)
    return pd.DataFrame(out, copy=False)


def channel_rates(epochs: pd.DataFrame) -> dict[str, float]:
    """The rate each channel of an epoch table came at.

    Parameters
    ----------
    epochs : pandas.DataFrame
        Epoch table.

    Returns
    -------
    dict
        Column -> 1 / median interval between the rows that have it [Hz] (columns with at
        least two timed values).
    """
    t = epochs["t_s"].to_numpy(float)
    out = {}
    for c in _RATE_COLUMNS:
        if c not in epochs.columns:
            continue
        tc = t[epochs[c].notna().to_numpy() & np.isfinite(t)]
        if tc.size < 2:
            continue
        step = max(1, tc.size // 20_000)  # the median of ≤ 20 000 evenly spread intervals
        i = np.arange(step, tc.size, step)
        dt = tc[i] - tc[i - 1]
        dt = dt[dt > 0]
        if dt.size:
            out[c] = round(float(1.0 / np.median(dt)), 3)
    return out
