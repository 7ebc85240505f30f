"""Sentences -> epochs: one row per receiver time instant.

The grouping rule
-----------------
A receiver sends a burst of sentences per measurement epoch. Sentences with a UTC time (GGA,
RMC, ZDA, ``$PSAT,HPR``, ``$PASHR``, ``$PSTI,036``) say which epoch they belong to; HDT, THS, ROT
and VTG (and a timed sentence whose time field is empty) do not. Receivers order their bursts
differently: Hemisphere sends ``HDT, GGA, VTG, ZDA`` (heading *before* the position), Saab and
SkyTraq send the heading *after* RMC. gripsense therefore reads the log in order and starts a new
epoch when

(a) a sentence carries a time different from the current epoch's time (an epoch with no time yet
    takes the first time that arrives), or
(b) a sentence of a type that the current epoch already holds arrives (a burst holds each type
    once).

Rule (b) puts Hemisphere's HDT into the epoch of the GGA that follows it, and rule (a) keeps
Saab's HDT with the RMC before it. Sentences between bursts that carry no time at all (no fix:
empty GGA time) form epochs without time (``time_utc`` NaT, ``t_s`` NaN); nothing is dropped.
A low-rate untimed sentence among high-rate timed ones (1 Hz HDT among 25 Hz PASHR) joins the
epoch it follows.

The rule is sequential: :func:`epoch_boundaries` runs it as a compiled loop, and the plain Python
loop :func:`epoch_boundaries_loop` is its reference in the tests.

Merging an epoch's sentences
----------------------------
* position, altitude, fix quality, satellites, HDOP: GGA (if its fix quality is not 0), else RMC
  (if its status is ``A``);
* speed and course over ground: RMC (status ``A``), else VTG (mode not ``N``);
* heading: ``$PSAT,HPR`` > ``$PASHR`` > ``$PSTI,036`` (mode ``R``) > THS (mode not ``V``) > HDT —
  ``heading_source`` says which;
* pitch and roll: ``$PSAT,HPR`` > ``$PASHR`` > ``$PSTI,036`` (degrees, as the receiver sends them);
* date: RMC or ZDA in the epoch, else carried from the nearest dated epoch, counting midnight
  roll-overs of the time of day.
"""

from __future__ import annotations

import numpy as np
import pandas as pd
from numba import njit

from gripsense.io.nmea.schema import SENTENCES

__all__ = ["EPOCH_COLUMNS", "assemble_epochs", "epoch_boundaries", "epoch_boundaries_loop"]

EPOCH_COLUMNS = [
    "time_utc",
    "t_s",
    "lat_deg",
    "lon_deg",
    "alt_m",
    "fix_quality",
    "n_sats",
    "hdop",
    "speed_mps",
    "course_deg",
    "heading_deg",
    "heading_source",
    "pitch_deg",
    "roll_deg",
    "rot_deg_per_min",
    "yaw_rate_rps",
    "yaw_rate_source",
]

ROT_TO_RPS = np.pi / (180.0 * 60.0)  # (deg/min) -> (rad/s)
HEADING_PRIORITY = ("PSAT,HPR", "PASHR", "PSTI,036", "THS", "HDT")
# categories of ``heading_source``, by priority
HEADING_SOURCES = ["HPR", "PASHR", "PSTI", "THS", "HDT"]
YAW_RATE_SOURCES = ["ROT", "heading"]  # categories of ``yaw_rate_source``


def epoch_boundaries_loop(kind: np.ndarray, tod: np.ndarray) -> np.ndarray:
    """Reference: the grouping rule as a plain loop.

    Parameters
    ----------
    kind : array of int
        Sentence type code per sentence, in line order.
    tod : array of float
        Time of day [s], NaN for sentences without a time.

    Returns
    -------
    numpy.ndarray of bool
        True where a sentence starts a new epoch.
    """
    n = kind.size
    out = np.zeros(n, dtype=bool)
    seen: set[int] = set()
    cur_t = np.nan
    for i in range(n):
        k, t = int(kind[i]), tod[i]
        new = i == 0 or k in seen or (not np.isnan(t) and not np.isnan(cur_t) and t != cur_t)
        if new:
            out[i] = True
            seen = set()
            cur_t = np.nan
        seen.add(k)
        if not np.isnan(t):
            cur_t = t
    return out


@njit(cache=True, nogil=True)
def _boundaries_kernel(kind, tod, out):
    seen = np.uint64(0)
    cur_t = np.nan
    for i in range(kind.size):
        bit = np.uint64(1) << np.uint64(kind[i])
        t = tod[i]
        new = i == 0 or (seen & bit) != 0 or (t == t and cur_t == cur_t and t != cur_t)
        if new:
            out[i] = True
            seen = np.uint64(0)
            cur_t = np.nan
        seen |= bit
        if t == t:
            cur_t = t


def epoch_boundaries(kind: np.ndarray, tod: np.ndarray) -> np.ndarray:
    """The grouping rule, compiled (same result as :func:`epoch_boundaries_loop`).

    Parameters
    ----------
    kind : array of int
        Sentence type code per sentence (0..63), in line order.
    tod : array of float
        Time of day [s], NaN for sentences without a time.

    Returns
    -------
    numpy.ndarray of bool
        True where a sentence starts a new epoch.
    """
    kind = np.asarray(kind, dtype=np.int64)
    if kind.size and (kind.min() < 0 or kind.max() > 63):
        raise ValueError("epoch_boundaries: type codes must be in 0..63")
    out = np.zeros(kind.size, dtype=np.bool_)
    _boundaries_kernel(kind, np.asarray(tod, dtype=np.float64), out)
    return out


def _rollovers(tod: np.ndarray) -> np.ndarray:
    """Cumulative count of midnight roll-overs along the epochs (time of day falling > 12 h)."""
    valid = ~np.isnan(tod)
    if not valid.any():
        return np.zeros(tod.size, dtype=np.int64)
    last_idx = np.maximum.accumulate(np.where(valid, np.arange(tod.size), -1))
    prev = np.full(tod.size, np.nan)
    ok = last_idx[:-1] >= 0
    prev[1:][ok] = tod[last_idx[:-1][ok]]
    jump = valid & (tod < prev - 43200.0)
    return np.cumsum(jump)


@njit(cache=True, nogil=True)
def _yaw_kernel(tt, hh, max_gap, out):
    n = tt.size
    for i in range(n):
        num = 0.0
        den = 0.0
        if i > 0:
            dt = tt[i] - tt[i - 1]
            if dt > 0 and dt <= max_gap:
                dh = (hh[i] - hh[i - 1] + 180.0) % 360.0 - 180.0
                num += dh
                den += dt
        if i < n - 1:
            dt = tt[i + 1] - tt[i]
            if dt > 0 and dt <= max_gap:
                dh = (hh[i + 1] - hh[i] + 180.0) % 360.0 - 180.0
                num += dh
                den += dt
        out[i] = -np.deg2rad(num / den) if den > 0 else np.nan


def _yaw_from_heading(t: np.ndarray, hdg: np.ndarray) -> np.ndarray:
    """ISO yaw rate [rad/s] from compass heading [deg] by central differences.

    Uses (ψ[i+1] − ψ[i−1]) / (t[i+1] − t[i−1]) over the epochs that have a heading, with each
    heading change wrapped to [−180°, 180°); one-sided at the ends and next to gaps (intervals
    longer than 2.5 × the median interval — taken over at most ~20 000 evenly spaced
    intervals — or not positive). Compass headings turn clockwise, so the ISO 8855 yaw rate is
    minus their rate.
    """
    out = np.full(t.shape, np.nan)
    idx = np.flatnonzero(~(np.isnan(t) | np.isnan(hdg)))
    if idx.size < 2:
        return out
    tt, hh = t[idx], hdg[idx]
    dt = np.diff(tt)
    pos = dt[dt > 0]
    if pos.size == 0:
        return out
    step = max(1, pos.size // 20000)  # the median of a regular subsample is enough here
    max_gap = 2.5 * float(np.median(pos[::step]))
    r = np.empty(idx.size)
    _yaw_kernel(tt, hh, max_gap, r)
    out[idx] = r
    return out


def assemble_epochs(
    frames: dict[str, pd.DataFrame],
) -> tuple[pd.DataFrame, dict[str, np.ndarray], dict]:
    """Group decoded sentences into epochs.

    Parameters
    ----------
    frames : dict
        Type key -> decoded sentence frame (see :func:`gripsense.io.nmea.decode.decode_all`).

    Returns
    -------
    epochs : pandas.DataFrame
        One row per epoch, columns :data:`EPOCH_COLUMNS`.
    epoch_of : dict
        Type key -> epoch index of each of its sentences.
    notes : dict
        ``epochs_without_time``, ``has_date``.
    """
    keys = list(SENTENCES)
    parts_line, parts_kind, parts_tod = [], [], []
    for code, k in enumerate(keys):
        f = frames[k]
        parts_line.append(f["line"].to_numpy())
        parts_kind.append(np.full(len(f), code, dtype=np.int64))
        parts_tod.append(f["tod_s"].to_numpy() if "tod_s" in f else np.full(len(f), np.nan))
    line = np.concatenate(parts_line)
    order = np.argsort(line, kind="stable")
    line, kind, tod = (
        line[order],
        np.concatenate(parts_kind)[order],
        np.concatenate(parts_tod)[order],
    )
    start = epoch_boundaries(kind, tod)
    eid = np.cumsum(start) - 1
    n_ep = int(start.sum())

    epoch_of: dict[str, np.ndarray] = {}
    for k in keys:
        pos = np.searchsorted(line, frames[k]["line"].to_numpy())
        epoch_of[k] = eid[pos] if pos.size else np.empty(0, dtype=np.int64)

    def col(k: str, name: str, use: np.ndarray | None = None) -> np.ndarray | None:
        """Per-epoch values of one column of one sentence type (None if the type is absent)."""
        if not len(frames[k]):
            return None
        out = np.full(n_ep, np.nan)
        v = frames[k][name].to_numpy(dtype=float)
        out[epoch_of[k]] = v if use is None else np.where(use, v, np.nan)
        return out

    def first_of(*arrays: np.ndarray | None) -> np.ndarray:
        """Element-wise first non-NaN of the arrays, in priority order."""
        out = None
        for a in arrays:
            if a is None:
                continue
            if out is None:
                out = a
            else:
                gap = np.isnan(out)
                out[gap] = a[gap]
        return np.full(n_ep, np.nan) if out is None else out

    gga_ok = frames["GGA"]["fix_quality"].to_numpy() != 0 if len(frames["GGA"]) else None
    rmc_ok = (frames["RMC"]["status"].to_numpy() == "A") if len(frames["RMC"]) else None
    tod_e = np.full(n_ep, np.nan)
    has_t = ~np.isnan(tod)
    tod_e[eid[has_t]] = tod[has_t]

    ep: dict[str, object] = {}
    gga_lat = col("GGA", "lat_deg", gga_ok)
    rmc_lat = col("RMC", "lat_deg", rmc_ok)
    if gga_lat is not None and rmc_lat is not None:
        use_gga = ~np.isnan(gga_lat)
        ep["lat_deg"] = np.where(use_gga, gga_lat, rmc_lat)
        ep["lon_deg"] = np.where(
            use_gga, col("GGA", "lon_deg", gga_ok), col("RMC", "lon_deg", rmc_ok)
        )
    else:
        ep["lat_deg"] = first_of(gga_lat, rmc_lat)
        ep["lon_deg"] = first_of(col("GGA", "lon_deg", gga_ok), col("RMC", "lon_deg", rmc_ok))
    ep["alt_m"] = first_of(col("GGA", "alt_m", gga_ok))
    ep["fix_quality"] = first_of(col("GGA", "fix_quality"))
    ep["n_sats"] = first_of(col("GGA", "n_sats"))
    ep["hdop"] = first_of(col("GGA", "hdop"))
    ep["speed_mps"] = first_of(col("RMC", "speed_mps", rmc_ok), col("VTG", "speed_mps"))
    ep["course_deg"] = first_of(col("RMC", "course_deg", rmc_ok), col("VTG", "course_deg"))

    heading = np.full(n_ep, np.nan)
    source = np.full(n_ep, -1, dtype=np.int8)
    for code, k in enumerate(HEADING_PRIORITY):
        h = col(k, "heading_deg")
        if h is None:
            continue
        take = np.isnan(heading) & ~np.isnan(h)
        heading[take] = h[take]
        source[take] = code
    ep["heading_deg"] = heading
    ep["heading_source"] = pd.Categorical.from_codes(source, categories=HEADING_SOURCES)
    ep["pitch_deg"] = first_of(
        col("PSAT,HPR", "pitch_deg"), col("PASHR", "pitch_deg"), col("PSTI,036", "pitch_deg")
    )
    ep["roll_deg"] = first_of(
        col("PSAT,HPR", "roll_deg"), col("PASHR", "roll_deg"), col("PSTI,036", "roll_deg")
    )
    rot = first_of(col("ROT", "rot_deg_per_min"))
    ep["rot_deg_per_min"] = rot

    # dates and times
    day = first_of(col("RMC", "day"), col("ZDA", "day"), col("PSTI,036", "day"))
    timed = ~np.isnan(tod_e)
    day = np.where(timed, day, np.nan)
    rc = _rollovers(tod_e).astype(float)
    has_date = bool((~np.isnan(day)).any())
    abs_s = np.full(n_ep, np.nan)
    if has_date:
        anchor = np.where(~np.isnan(day), np.arange(n_ep), -1)
        fw = np.maximum.accumulate(anchor)
        bw_src = np.where(anchor >= 0, anchor, n_ep)
        bw = np.minimum.accumulate(bw_src[::-1])[::-1]
        a = np.where(fw >= 0, fw, bw)
        a_ok = (a >= 0) & (a < n_ep)
        a_c = np.clip(a, 0, n_ep - 1)
        d_est = day[a_c] + rc - rc[a_c]
        abs_s = np.where(timed & a_ok, d_est * 86400.0 + tod_e, np.nan)
        ns = np.where(np.isnan(abs_s), np.iinfo(np.int64).min, np.round(abs_s * 1e9)).astype(
            np.int64
        )
        time_utc = pd.to_datetime(ns, unit="ns", utc=True)
        time_utc = time_utc.where(~np.isnan(abs_s))
    else:
        abs_s = np.where(timed, rc * 86400.0 + tod_e, np.nan)
        time_utc = pd.to_datetime(np.full(n_ep, np.iinfo(np.int64).min), unit="ns", utc=True)
    first = np.flatnonzero(~np.isnan(abs_s))
    t_s = abs_s - abs_s[first[0]] if first.size else abs_s
    ep["time_utc"] = time_utc
    ep["t_s"] = t_s

    yaw = -rot * ROT_TO_RPS
    has_rot = ~np.isnan(rot)
    ysrc = np.where(has_rot, 0, -1).astype(np.int8)
    if not has_rot.all():
        dyaw = _yaw_from_heading(t_s, heading)
        fill = ~has_rot & ~np.isnan(dyaw)
        yaw[fill] = dyaw[fill]
        ysrc[fill] = 1
    ep["yaw_rate_rps"] = yaw
    ep["yaw_rate_source"] = pd.Categorical.from_codes(ysrc, categories=YAW_RATE_SOURCES)

    df = pd.DataFrame({c: ep[c] for c in EPOCH_COLUMNS}, copy=False)
    notes = {"epochs_without_time": int((~timed).sum()), "has_date": has_date}
    return df, epoch_of, notes
