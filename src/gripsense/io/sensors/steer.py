"""Steering channels: a CSV with time and road-wheel (or steering-wheel) angle, and optionally
the steering torque — column torque, the power steering's assist torque, a rack force — each at
its own rate (a row may carry some channels and leave the others empty).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from gripsense.errors import InputError
from gripsense.io.table import ROAD_WHEEL_LIMIT, Quantity, channel_rows, map_table, read_table

__all__ = [
    "STEERING_TORQUE",
    "STEER_QUANTITIES",
    "TORQUE_COLUMNS",
    "channel_at",
    "channel_mean_at",
    "read_steer_csv",
    "steer_at",
    "steer_overlap",
    "with_torque",
]


STEERING_WHEEL_LIMIT = 20.0
"""The largest steering-wheel angle [rad] (1146°: more than 3 turns from the centre)."""
TORQUE_LIMIT = 200.0
"""The largest steering torque at the steering wheel, column or assist [N m]."""
RACK_LIMIT = 1e5
"""The largest rack force [N]."""

STEER_QUANTITIES = {
    "t": Quantity("time", ("t", "time")),
    "road_wheel": Quantity("angle", ("road_wheel", "steer", "delta"), ROAD_WHEEL_LIMIT,
                           meaning="a road-wheel angle"),
    "steering_wheel": Quantity("angle", ("steering_wheel", "handwheel", "swa"),
                               STEERING_WHEEL_LIMIT, meaning="a steering-wheel angle"),
    "torque": Quantity("torque", ("torque", "column_torque", "steering_torque"), TORQUE_LIMIT,
                       meaning="a steering torque"),
    "assist": Quantity("torque", ("assist", "assist_torque"), TORQUE_LIMIT,
                       meaning="a steering torque"),
    "rack": Quantity("force", ("rack", "rack_force"), RACK_LIMIT, meaning="a rack force"),
}  # fmt: skip
"""The keys of a steering channel, the header names mapped without being told, and the
largest |value| each can plausibly have (:class:`gripsense.io.table.Quantity`)."""

TORQUE_COLUMNS = {"torque": "torque_nm", "assist": "assist_nm", "rack": "rack_n"}
"""Steering-torque keys -> the columns they fill (the epoch table's names): column torque and
assist torque at the steering wheel [N m], rack force [N]."""
STEERING_TORQUE = (*TORQUE_COLUMNS.values(), "torque_samples")
"""The steering-torque columns an epoch, motion or wheel table may carry (``torque_samples``:
how many of the channel's samples each epoch averages, :func:`channel_mean_at`)."""


def read_steer_csv(
    path: str | Path, *, steering_ratio: float | None = None, columns: str | dict | None = None
) -> pd.DataFrame:
    """Read a steering channel.

    The table needs a time column (seconds on the same clock as the epoch table's ``t_s``)
    and either the road-wheel steer angle (ISO: positive to the left) or the steering-wheel
    angle (divided by the vehicle's ``steering_ratio``). It may also carry the steering torque:
    ``torque`` (column torque at the steering wheel, ISO: positive steers left), ``assist`` (the
    power steering's torque, at the steering wheel) and ``rack`` (rack force, positive steers
    left) — ``docs/physics.md`` §16.3. Headers with a unit suffix are mapped by themselves
    (``t_s``, ``road_wheel_deg``, ``steering_wheel_deg``, ``torque_Nm``, ``assist_Nm``,
    ``rack_N``; the one column convention, :func:`gripsense.io.table.map_table`).

    Channels at different rates share the table (``gripsense simulate`` writes the angle at its
    rate and the torque at 100 Hz): a row carries the channels sampled at its time and leaves
    the others empty, and any subset of the channels may be mapped, as long as each mapped
    channel has samples of its own. A row that carries none of the mapped channels (e.g. a
    torque row when only the angle is mapped) is counted in ``attrs`` and not used; a row whose
    values have no time, a cell that is not a number, or a mapped column without any value is
    an error naming the file, line and column (:func:`gripsense.io.table.channel_rows`).

    Parameters
    ----------
    path : str or Path
        Steering channel CSV.
    steering_ratio : float, optional
        Steering-wheel angle / road-wheel angle [-], needed for a steering-wheel angle.
    columns : str or dict, optional
        ``t=HEADER[:unit],road_wheel=…`` or ``steering_wheel=…``, and ``torque=…:Nm``,
        ``assist=…:Nm``, ``rack=…:N``; default by header names.

    Returns
    -------
    pandas.DataFrame
        ``t_s`` [s], ``steer_rad`` (road-wheel angle) [rad] and the torque channels mapped
        (``torque_nm``, ``assist_nm`` [N m], ``rack_n`` [N]; NaN where a row leaves a channel
        empty), one row per row of the file that carries a mapped channel, sorted by time;
        ``attrs["columns"]`` the mapping used, ``attrs["rows"]`` the accounting of the file's
        rows (``rows``, ``rows_used``, ``rows_without_channel``, ``note``).
    """
    path = Path(path)
    df = read_table(path)
    rejected: dict[str, np.ndarray] = {}
    v, spec = map_table(
        df,
        path,
        STEER_QUANTITIES,
        columns,
        required=("t", (("road_wheel",), ("steering_wheel",))),
        example="t=time:s,road_wheel=delta:deg",
        rejected=rejected,
    )
    if "road_wheel" in v and "steering_wheel" in v:
        v.pop("steering_wheel")  # the road-wheel angle needs no ratio
        spec = {k: x for k, x in spec.items() if k != "steering_wheel"}
    if "road_wheel" in v:
        angle = v["road_wheel"]
    else:
        if not steering_ratio:
            raise InputError(
                f"{path}: a steering-wheel angle needs [vehicle] steering_ratio in the "
                "vehicle file (or give the road-wheel angle, e.g. road_wheel_deg)"
            )
        angle = v["steering_wheel"] / steering_ratio
        if np.nanmax(np.abs(angle), initial=0.0) > ROAD_WHEEL_LIMIT:
            raise InputError(
                f"{path}: the steering-wheel angle {np.nanmax(np.abs(v['steering_wheel'])):.4g} "
                f"rad over steering_ratio {steering_ratio:g} is a road-wheel angle of "
                f"{np.nanmax(np.abs(angle)):.4g} rad, more than a road wheel turns "
                f"({ROAD_WHEEL_LIMIT:g} rad); check [vehicle] steering_ratio and the column's unit"
            )
    rejected.pop("steering_wheel" if "road_wheel" in v else "road_wheel", None)
    keep, acc = channel_rows(df, path, v, spec, flag="--steer-columns", rejected=rejected)
    extra = {col: v[key][keep] for key, col in TORQUE_COLUMNS.items() if key in v}
    out = pd.DataFrame({"t_s": v["t"][keep], "steer_rad": angle[keep], **extra})
    out = out.sort_values("t_s", kind="stable").reset_index(drop=True)
    out.attrs["columns"] = spec
    out.attrs["rows"] = acc
    return out


def channel_at(steer: pd.DataFrame, column: str, t_s: np.ndarray) -> np.ndarray:
    """One channel of a steering table at times t_s, interpolated linearly between the rows
    that carry it (NaN outside them).

    Parameters
    ----------
    steer : pandas.DataFrame
        Table of :func:`read_steer_csv`.
    column : str
        ``steer_rad``, ``torque_nm``, ``assist_nm`` or ``rack_n``.
    t_s : array_like
        Times [s] on the channel's clock.

    Returns
    -------
    numpy.ndarray
        The channel [its unit].
    """
    t = np.asarray(t_s, dtype=float)
    tc = steer["t_s"].to_numpy(float)
    x = steer[column].to_numpy(float)
    ok = np.isfinite(x)
    tc, x = tc[ok], x[ok]
    if tc.size == 0:
        return np.full(t.shape, np.nan)
    out = np.interp(t, tc, x)
    out[(t < tc[0]) | (t > tc[-1]) | np.isnan(t)] = np.nan
    return out


def channel_mean_at(
    steer: pd.DataFrame, column: str, t_s: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """One channel of a steering table averaged over each epoch's interval, at the channel's
    own rate: every sample between the midpoints to the neighbouring epochs (half the median
    step on the side of a gap of more than 1.5 steps) counts once, so a 100 Hz channel read at
    10 Hz epochs keeps all its samples and its white noise falls by √10. An epoch whose interval
    holds no sample (a channel slower than the epochs) takes the linear interpolation.

    Parameters
    ----------
    steer : pandas.DataFrame
        Table of :func:`read_steer_csv`.
    column : str
        ``torque_nm``, ``assist_nm``, ``rack_n`` or ``steer_rad``.
    t_s : array_like
        Epoch times, ascending [s] on the channel's clock.

    Returns
    -------
    values : numpy.ndarray
        The channel per epoch [its unit] (NaN outside the channel).
    samples : numpy.ndarray
        The channel's samples averaged into each epoch (0: interpolated or none) [-].
    """
    t = np.asarray(t_s, dtype=float)
    interp = channel_at(steer, column, t)
    n = np.zeros(t.shape, dtype=np.int64)
    tc = steer["t_s"].to_numpy(float)
    x = steer[column].to_numpy(float)
    ok = np.isfinite(x) & np.isfinite(tc)
    tc, x = tc[ok], x[ok]
    fin = np.flatnonzero(np.isfinite(t))
    if tc.size == 0 or fin.size < 2:
        return interp, n
    order = np.argsort(tc, kind="stable")
    tc, x = tc[order], x[order]
    te = t[fin]
    gaps = np.diff(te)
    half = 0.5 * float(np.median(gaps[gaps > 0])) if (gaps > 0).any() else 0.0
    # one boundary between neighbours (the same number for both: no sample falls between
    # them, whatever the epochs' jitter), or half a step on either side of a gap (a missing
    # epoch: more than 1.5 steps)
    mid = 0.5 * (te[:-1] + te[1:])
    close = gaps <= 3.0 * half
    hi = np.append(np.where(close, mid, te[:-1] + half), te[-1] + half)
    lo = np.insert(np.where(close, mid, te[1:] - half), 0, te[0] - half)
    i0 = np.searchsorted(tc, lo, side="left")
    i1 = np.searchsorted(tc, hi, side="left")
    csum = np.concatenate([[0.0], np.cumsum(x)])
    cnt = np.maximum(i1 - i0, 0)
    with np.errstate(invalid="ignore", divide="ignore"):
        mean = (csum[i1] - csum[i0]) / cnt
    has = cnt > 0
    out = interp.copy()
    out[fin[has]] = mean[has]
    n[fin] = cnt
    return out, n


def steer_at(steer: pd.DataFrame, t_s: np.ndarray) -> np.ndarray:
    """Road-wheel angle [rad] at times t_s by linear interpolation (NaN outside the channel).

    Parameters
    ----------
    steer : pandas.DataFrame
        Channel of :func:`read_steer_csv`.
    t_s : array_like
        Times [s] on the channel's clock.
    """
    return channel_at(steer, "steer_rad", t_s)


COVERAGE_NOTE = 0.95
"""Share of the log's epochs a steering channel must cover to pass without a note [-]."""


def steer_overlap(steer: pd.DataFrame, t_s: np.ndarray, path: str | Path = "steering CSV") -> str:
    """Whether a steering channel covers the log it was given for.

    A channel whose times never overlap the log's (another clock: seconds of the day against
    seconds from the log's start) would leave the front axle without a steer angle and without
    a word; it is an error that names both time spans and the shift that would align their
    starts. A channel that covers less than :data:`COVERAGE_NOTE` of the epochs gives a note.

    Parameters
    ----------
    steer : pandas.DataFrame
        Table of :func:`read_steer_csv`.
    t_s : array_like
        The log's epoch times [s] (``t_s`` of the epoch table).
    path : str or Path
        The steering CSV, for messages.

    Returns
    -------
    str
        A note when the channel covers only part of the log, else ``""``.

    Raises
    ------
    InputError
        When no epoch of the log falls within the channel's time span.
    """
    t = np.asarray(t_s, dtype=float)
    t = t[np.isfinite(t)]
    tc = steer["t_s"].to_numpy(float)[np.isfinite(steer["steer_rad"].to_numpy(float))]
    tc = tc[np.isfinite(tc)]
    if t.size == 0 or tc.size == 0:
        return ""
    inside = (t >= tc.min()) & (t <= tc.max())
    spans = (
        f"its times {tc.min():.6g}–{tc.max():.6g} s, the log's t_s {t.min():.6g}–{t.max():.6g} s "
        "(seconds from the log's first epoch)"
    )
    name = Path(path).name
    if not inside.any():
        raise InputError(
            f"{path}: the steering channel never overlaps the log ({spans}); put its time "
            f"column on the log's clock (adding {t.min() - tc.min():.6g} s to it aligns the "
            "starts), or leave --steer-csv out to estimate the rear axle only"
        )
    share = float(inside.mean())
    if share < COVERAGE_NOTE:
        return (
            f"{name} covers {100 * share:.0f} % of the log's epochs ({spans}): the front axle "
            "has a steer angle only there"
        )
    return ""


def with_torque(epochs: pd.DataFrame, steer: pd.DataFrame) -> pd.DataFrame:
    """The epoch table with the steering table's torque channels at its times (a channel the
    log itself carries is replaced by the table's, which was given for it).

    Parameters
    ----------
    epochs : pandas.DataFrame
        Epoch table (``t_s`` on the steering table's clock).
    steer : pandas.DataFrame
        Table of :func:`read_steer_csv`.

    Returns
    -------
    pandas.DataFrame
        *epochs* itself when the table has no torque channel, else a copy with ``torque_nm``,
        ``assist_nm``, ``rack_n`` as the table has them, each averaged over the epoch's
        interval at its own rate (:func:`channel_mean_at`), and ``torque_samples``: the first
        channel's samples per epoch.
    """
    cols = [c for c in TORQUE_COLUMNS.values() if c in steer.columns]
    if not cols:
        return epochs
    out = epochs.copy()
    t = out["t_s"].to_numpy(float)
    for c in cols:
        out[c], n = channel_mean_at(steer, c, t)
        if c == cols[0]:
            out["torque_samples"] = n
    return out
