"""Sentences -> epochs: one row per receiver time instant.

The grouping rule
-----------------
A receiver sends a burst of sentences per measurement epoch. Sentences with a UTC time (GGA,
RMC, GNS, GLL, ZDA and the proprietary attitude sentences) say which epoch they belong to;
HDT, THS, ROT and VTG (and a timed sentence whose time field is empty) do not. Receivers order
their bursts differently: Hemisphere sends ``HDT, GGA, VTG, ZDA`` (heading *before* the
position), Saab and SkyTraq send the heading *after* RMC. gripsense therefore reads the log in
order and starts a new epoch when

(a) a sentence carries a time different from the current epoch's time (an epoch with no time yet
    takes the first time that arrives), or
(b) a sentence of a type that the current epoch already holds arrives (a burst holds each type
    once).

A sentence without any value (every field empty, or invalidated by its own flag: the
``$IIHDT,,T`` an instrument sends twice per cycle without a heading) takes part in the rule like
any other — it may lead the next burst, as Hemisphere's empty HDT before each GGA does — but a
split it made is undone when nothing conflicts: an epoch whose first sentence is empty joins
the epoch before it when no type has a non-empty sentence in both and their times do not differ
(an instrument's ``HDT, VTG, HDT, ZDA`` stays one epoch). An epoch with the same time as the
one before joins it: several talkers report one instant (``$GPGGA``, ``$GAGGA``, ``$GPRMC``,
``$GARMC`` …; the report counts such joins). A line repeated verbatim joins its original's
epoch.

The rule is sequential: :func:`epoch_boundaries` runs it as a compiled loop, and the plain Python
loop :func:`epoch_boundaries_loop` is its reference in the tests.

Merging an epoch's sentences
----------------------------
* position: from one sentence, the first of GGA (fix quality not 0), RMC (status ``A``), GNS
  (a mode letter other than ``N``), GLL (status ``A``, a fix mode or none) that has one —
  receivers that send only GLL (instrument buses, yachts) or GNS (multi-constellation
  receivers) are placed too;
* altitude: GGA (fix quality not 0), else GNS (with a fix); satellites, HDOP: GGA, else GNS;
  fix quality: GGA's, else GNS's or GLL's mode letter on GGA's scale (A 1, D 2, P 3, R 4,
  F 5, E 6, M 7, S 8; N 0);
* speed and course over ground: RMC (status ``A``), else VTG (mode not ``N``);
* heading: ``$PSAT,HPR`` > ``$PASHR`` > ``$PASHR,HPR`` (fixed ambiguities) > ``$PTNL,AVR``
  (fixed RTK) > ``$PSSN,HRP`` (mode 2, 4) > ``$PSTI,036`` (mode ``R``) > ``$PFEC,GPatt`` > THS
  (mode not ``V``) > HDT — ``heading_source`` says which;
* pitch and roll: the same proprietary sentences in the same order (degrees, as the receiver
  sends them);
* date: RMC or ZDA in the epoch, else carried from the nearest dated epoch, counting midnight
  roll-overs of the time of day.
"""

from __future__ import annotations

from concurrent.futures import ThreadPoolExecutor

import numba
import numpy as np
import pandas as pd
from numba import njit

from gripsense.io.logs.nmea.schema import SENTENCES
from gripsense.io.logs.sources import HEADING_SOURCES, YAW_RATE_SOURCES

__all__ = [
    "EPOCH_COLUMNS",
    "HEADING_SOURCES",
    "YAW_RATE_SOURCES",
    "assemble_epochs",
    "epoch_boundaries",
    "epoch_boundaries_loop",
    "yaw_from_heading",
]

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

_MIN_PARALLEL_EPOCHS = 100_000  # shorter logs fill their columns on the calling thread
ROT_TO_RPS = np.pi / (180.0 * 60.0)  # (deg/min) -> (rad/s)
# the NMEA sentences that give a heading, by priority, and the ``heading_source`` they set
HEADING_PRIORITY = (
    "PSAT,HPR",
    "PASHR",
    "PASHR,HPR",
    "PTNL,AVR",
    "PSSN,HRP",
    "PSTI,036",
    "PFEC,GPatt",
    "THS",
    "HDT",
)
_HEADING_LABEL = {
    "PSAT,HPR": "HPR",
    "PASHR,HPR": "PASHR",
    "PTNL,AVR": "AVR",
    "PSSN,HRP": "PSSN",
    "PFEC,GPatt": "GPatt",
}
ATTITUDE_PRIORITY = tuple(s for s in HEADING_PRIORITY if s not in ("THS", "HDT"))


def epoch_boundaries_loop(
    kind: np.ndarray, tod: np.ndarray, empty: np.ndarray | None = None
) -> np.ndarray:
    """Reference: the grouping rule as a plain loop.

    Parameters
    ----------
    kind : array of int
        Sentence type code per sentence, in line order.
    tod : array of float
        Time of day [s], NaN for sentences without a time.
    empty : array of bool, optional
        Sentences without any value (see the module documentation).

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
    if empty is None:
        return out
    # undo the splits made by an empty sentence where nothing conflicts, and those between
    # sentences of the same time
    g_types: set[int] = set()
    g_t = np.nan
    starts = [*np.flatnonzero(out).tolist(), n]
    for j in range(len(starts) - 1):
        a, b = starts[j], starts[j + 1]
        types = {int(kind[i]) for i in range(a, b) if not empty[i]}
        times = [tod[i] for i in range(a, b) if not np.isnan(tod[i])]
        t = times[0] if times else np.nan
        clash = not np.isnan(t) and not np.isnan(g_t) and t != g_t
        same_t = not np.isnan(t) and t == g_t
        if j > 0 and (same_t or (empty[a] and not (types & g_types) and not clash)):
            out[a] = False
            g_types |= types
        else:
            g_types = types
            g_t = np.nan
        if not np.isnan(t):
            g_t = t
    return out


@njit(cache=True, nogil=True)
def _group_kernel(kind_at, tod_at, tod_e):
    """The grouping rule in one pass over the lines: ``kind_at`` (type code per line, −1 where
    the line holds no decoded sentence) is overwritten with each sentence's epoch index,
    ``tod_e`` receives each epoch's time of day (NaN without one); returns the epoch count.
    """
    seen = np.uint64(0)
    cur_t = np.nan
    e = -1
    for i in range(kind_at.size):
        k = kind_at[i]
        if k < 0:
            continue
        bit = np.uint64(1) << np.uint64(k)
        t = tod_at[i]
        if e < 0 or (seen & bit) != 0 or (t == t and cur_t == cur_t and t != cur_t):
            e += 1
            seen = np.uint64(0)
            cur_t = np.nan
            tod_e[e] = np.nan
        seen |= bit
        if t == t:
            cur_t = t
            tod_e[e] = t  # every timed sentence of an epoch has the same time
        kind_at[i] = e
    return e + 1


@njit(cache=True, nogil=True)
def _merge_kernel(eid_at, kind_at, empty_at, tod_e, n_ep, n_same):
    """Undo the splits rule (b) made where they part no measurements: an epoch whose first
    sentence is empty joins the (merged) epoch before it when no type has a non-empty sentence
    in both and their times do not differ; an epoch with the same time as the one before joins
    it (``$GPGGA`` and ``$GAGGA`` of one instant; counted in ``n_same[0]``). ``eid_at`` (epoch
    per line, −1 without a sentence) and ``tod_e`` are rewritten; returns the new epoch count.
    """
    mask = np.zeros(n_ep, dtype=np.uint64)
    first_empty = np.zeros(n_ep, dtype=np.bool_)
    has_first = np.zeros(n_ep, dtype=np.bool_)
    for i in range(eid_at.size):
        e = eid_at[i]
        if e < 0:
            continue
        if not has_first[e]:
            has_first[e] = True
            first_empty[e] = empty_at[i]
        if not empty_at[i]:
            mask[e] |= np.uint64(1) << np.uint64(kind_at[i])
    new = np.empty(n_ep, dtype=np.int64)
    g = -1
    g_mask = np.uint64(0)
    g_t = np.nan
    for e in range(n_ep):
        t = tod_e[e]
        clash = t == t and g_t == g_t and t != g_t
        same_t = t == t and t == g_t
        if g >= 0 and (same_t or (first_empty[e] and (mask[e] & g_mask) == 0 and not clash)):
            g_mask |= mask[e]
            n_same[0] += same_t
        else:
            g += 1
            g_mask = mask[e]
            g_t = np.nan
        if t == t:
            g_t = t
        new[e] = g
        tod_e[g] = g_t
    for i in range(eid_at.size):
        if eid_at[i] >= 0:
            eid_at[i] = new[eid_at[i]]
    return g + 1


def epoch_boundaries(
    kind: np.ndarray, tod: np.ndarray, empty: np.ndarray | None = None
) -> np.ndarray:
    """The grouping rule, compiled (same result as :func:`epoch_boundaries_loop`).

    Parameters
    ----------
    kind : array of int
        Sentence type code per sentence (0..63), in line order.
    tod : array of float
        Time of day [s], NaN for sentences without a time.
    empty : array of bool, optional
        Sentences without any value (see the module documentation).

    Returns
    -------
    numpy.ndarray of bool
        True where a sentence starts a new epoch.
    """
    kind = np.asarray(kind, dtype=np.int64)
    if kind.size and (kind.min() < 0 or kind.max() > 63):
        raise ValueError("epoch_boundaries: type codes must be in 0..63")
    eid = kind.copy()
    tod_e = np.empty(kind.size)
    n_ep = _group_kernel(eid, np.asarray(tod, dtype=np.float64), tod_e)
    if empty is not None:
        n_same = np.zeros(1, dtype=np.int64)
        _merge_kernel(eid, kind, np.asarray(empty, dtype=np.bool_), tod_e, n_ep, n_same)
    out = np.ones(kind.size, dtype=np.bool_)
    out[1:] = eid[1:] != eid[:-1]
    return out


@njit(cache=True, nogil=True)
def _scatter_kernel(out, ep, v, use, has_use):
    for r in range(ep.size):
        x = v[r]
        if x == x and (not has_use or use[r]):
            out[ep[r]] = x


@njit(cache=True, nogil=True)
def _fill_kernel(out, ep, v, use, has_use, src, code, has_src):
    for r in range(ep.size):
        e = ep[r]
        x = v[r]
        if x == x and out[e] != out[e] and (not has_use or use[r]):
            out[e] = x
            if has_src:
                src[e] = code


_NONE_B = np.zeros(0, dtype=np.bool_)
_NONE_I8 = np.zeros(0, dtype=np.int8)


def _scatter(out: np.ndarray, ep: np.ndarray, v: np.ndarray, use: np.ndarray | None) -> None:
    """out[ep] = v where v is a number and *use* is True (*out* starts NaN; one sentence of a
    type per epoch, apart from empty ones, whose NaN leaves the value alone).
    """
    _scatter_kernel(out, ep, v, _NONE_B if use is None else use, use is not None)


def _fill(
    out: np.ndarray,
    ep: np.ndarray,
    v: np.ndarray,
    use: np.ndarray | None,
    src: np.ndarray | None = None,
    code: int = 0,
) -> None:
    """Where out[ep] is still NaN, take v (where *use*, when v is not NaN) and note *code* in
    src — the next source in priority order fills what the earlier ones left open.
    """
    _fill_kernel(
        out,
        ep,
        v,
        _NONE_B if use is None else use,
        use is not None,
        _NONE_I8 if src is None else src,
        code,
        src is not None,
    )


@njit(cache=True, nogil=True)
def _seconds_kernel(tod, day, abs_s):
    """Seconds since 1970 of each epoch from its time of day and the dates of the log.

    Midnight roll-overs are counted along the epochs (the time of day falling by more than
    12 h from the last epoch with a time); an epoch's date is its own (RMC, ZDA) or carried
    from the nearest earlier dated epoch — the nearest later one before the first date —
    plus the roll-overs in between. Without any date the count of roll-overs is the day.
    Returns whether the log has a date; ``abs_s`` is NaN for epochs without a time.
    """
    n = tod.size
    rc = np.empty(n)
    cnt = 0.0
    prev = np.nan
    first_dated = -1
    for i in range(n):
        t = tod[i]
        if t == t:
            if t < prev - 43200.0:
                cnt += 1.0
            prev = t
            if first_dated < 0 and day[i] == day[i]:
                first_dated = i
        rc[i] = cnt
    if first_dated < 0:
        for i in range(n):
            abs_s[i] = rc[i] * 86400.0 + tod[i] if tod[i] == tod[i] else np.nan
        return False
    a = first_dated  # the anchor: nearest dated epoch at or before i, else the first one
    for i in range(n):
        t = tod[i]
        if t == t and day[i] == day[i]:
            a = i
        abs_s[i] = (day[a] + rc[i] - rc[a]) * 86400.0 + t if t == t else np.nan
    return True


@njit(cache=True, nogil=True, inline="always")
def _wrap180(d):
    """(d + 180) mod 360 − 180 [deg], the modulo only when needed (same doubles)."""
    x = d + 180.0
    if not (x >= 0.0 and x < 360.0):
        x = x % 360.0
    return x - 180.0


@njit(cache=True, nogil=True)
def _step_sample(t, hdg):
    """The epochs with a time and a heading: how many, and every k-th of the positive time
    steps between consecutive ones (k = max(1, their number // 20 000): the median's
    subsample), without gathering them.
    """
    n = 0
    m = 0
    prev = np.nan
    for i in range(t.size):
        if t[i] == t[i] and hdg[i] == hdg[i]:
            if n > 0 and t[i] - prev > 0:
                m += 1
            prev = t[i]
            n += 1
    k = max(1, m // 20000)
    out = np.empty((m + k - 1) // k)
    j = 0
    c = 0
    first = True
    for i in range(t.size):
        if t[i] == t[i] and hdg[i] == hdg[i]:
            if not first and t[i] - prev > 0:
                if c % k == 0:
                    out[j] = t[i] - prev
                    j += 1
                c += 1
            prev = t[i]
            first = False
    return n, out


@njit(cache=True, nogil=True, inline="always")
def _next_valid(t, hdg, i):
    """The first epoch at or after i with a time and a heading (−1: none)."""
    while i < t.size:
        if t[i] == t[i] and hdg[i] == hdg[i]:
            return i
        i += 1
    return -1


@njit(cache=True, nogil=True)
def _fill_yaw(t, hdg, max_gap, yaw, src):
    """Where the ROT yaw rate is missing (NaN in *yaw*) take the heading's central difference
    over the neighbouring epochs with a heading (source 1), else mark source −1; a non-positive
    max_gap fills nothing.
    """
    p = -1
    c = _next_valid(t, hdg, 0) if max_gap > 0 else -1
    while c >= 0:
        q = _next_valid(t, hdg, c + 1)
        if yaw[c] != yaw[c]:
            num = 0.0
            den = 0.0
            if p >= 0:
                dt = t[c] - t[p]
                if dt > 0 and dt <= max_gap:
                    num += _wrap180(hdg[c] - hdg[p])
                    den += dt
            if q >= 0:
                dt = t[q] - t[c]
                if dt > 0 and dt <= max_gap:
                    num += _wrap180(hdg[q] - hdg[c])
                    den += dt
            if den > 0:
                yaw[c] = -np.deg2rad(num / den)
                src[c] = 1
        p = c
        c = q
    for i in range(yaw.size):
        if yaw[i] != yaw[i]:
            src[i] = -1


def yaw_from_heading(t: np.ndarray, hdg: np.ndarray, yaw: np.ndarray, src: np.ndarray) -> None:
    """Fill the missing ISO yaw rate [rad/s] from compass heading [deg] by central differences.

    Uses (ψ[i+1] − ψ[i−1]) / (t[i+1] − t[i−1]) over the epochs that have a heading, with each
    heading change wrapped to [−180°, 180°); one-sided at the ends and next to gaps (intervals
    longer than 2.5 × the median interval — taken over at most ~20 000 evenly spaced
    intervals — or not positive). Compass headings turn clockwise, so the ISO 8855 yaw rate is
    minus their rate. Epochs whose *yaw* is NaN get it (*src* 1) or keep NaN (*src* −1).
    """
    n, sample = _step_sample(t, hdg)
    max_gap = 2.5 * float(np.median(sample)) if n >= 2 and sample.size else 0.0
    _fill_yaw(t, hdg, max_gap, yaw, src)


def _repeats(cols: dict[str, np.ndarray]) -> np.ndarray:
    """Which sentences of one type repeat the sentence on the line before them exactly (every
    decoded field equal, NaN equal to NaN).
    """
    line = np.asarray(cols["line"])
    n = line.size
    out = np.zeros(n, dtype=bool)
    if n < 2:
        return out
    same = line[1:] == line[:-1] + 1
    for name, a in cols.items():
        if name == "line" or not same.any():
            continue
        a = np.asarray(a)
        eq = a[1:] == a[:-1]
        if a.dtype.kind == "f":
            eq |= np.isnan(a[1:]) & np.isnan(a[:-1])
        same &= eq
    out[1:] = same
    return out


def _empty(cols: dict[str, np.ndarray]) -> np.ndarray:
    """Which sentences of one type carry no value: every decoded number NaN (an empty field,
    or a value the sentence's own flag invalidates), GGA's fix quality 0 (no fix) included;
    status and mode letters are not values.
    """
    out = np.ones(np.asarray(cols["line"]).size, dtype=bool)
    for name, a in cols.items():
        if name == "line" or not out.any():
            continue
        a = np.asarray(a)
        if name == "fix_quality":  # GGA's "no fix" (0) says nothing either
            out &= np.isnan(a) | (a == 0)
        elif a.dtype.kind == "f":
            out &= np.isnan(a)
    return out


def assemble_epochs(
    tables: dict[str, dict[str, np.ndarray]],
) -> tuple[pd.DataFrame, dict[str, np.ndarray], dict]:
    """Group decoded sentences into epochs.

    Parameters
    ----------
    tables : dict
        Type key -> column name -> array of the decoded sentences (see
        :func:`gripsense.io.logs.nmea.decode.decode_all`).

    Returns
    -------
    epochs : pandas.DataFrame
        One row per epoch, columns :data:`EPOCH_COLUMNS`.
    epoch_of : dict
        Type key -> epoch index of each of its sentences.
    notes : dict
        ``epochs_without_time``, ``has_date``, ``repeated_sentences`` (sentences that repeat
        the line before them exactly: joined to their original's epoch).
    """
    keys = list(SENTENCES)
    size = {k: tables[k]["line"].size for k in keys}
    n_ep, tod_e, epoch_of, n_repeated, n_same = _group_lines(tables, keys, size)

    def col(k: str, name: str, use: np.ndarray | None = None) -> np.ndarray | None:
        """Per-epoch values of one column of one sentence type (None if the type is absent)."""
        if not size[k]:
            return None
        out = np.full(n_ep, np.nan)
        _scatter(out, epoch_of[k], np.asarray(tables[k][name], dtype=float), use)
        return out

    def first_of(*sources: tuple) -> np.ndarray:
        """Per epoch the first non-NaN value of the (type, column[, use]) sources, in order."""
        out = np.full(n_ep, np.nan)
        for k, name, *use in sources:
            if size[k]:
                v = np.asarray(tables[k][name], dtype=float)
                _fill(out, epoch_of[k], v, use[0] if use else None)
        return out

    gga_ok = tables["GGA"]["fix_quality"] != 0 if size["GGA"] else None
    rmc_ok = (tables["RMC"]["status"] == "A") if size["RMC"] else None

    # GLL and GNS carry NaN where they say they have no fix (decode.py)
    pos_sources = [
        (k, ok)
        for k, ok in (("GGA", gga_ok), ("RMC", rmc_ok), ("GNS", None), ("GLL", None))
        if size[k]
    ]

    def position() -> tuple[np.ndarray, np.ndarray]:
        if len(pos_sources) > 1:
            # the position comes from one sentence: the first source (GGA, RMC, GNS, GLL)
            # where it has a latitude
            k, ok = pos_sources[0]
            lat, lon = col(k, "lat_deg", ok), col(k, "lon_deg", ok)
            assert lat is not None and lon is not None
            for k, ok in pos_sources[1:]:
                la, lo = col(k, "lat_deg", ok), col(k, "lon_deg", ok)
                assert la is not None and lo is not None  # the sources are types present
                take = np.isnan(lat) & ~np.isnan(la)
                lat[take] = la[take]
                lon[take] = lo[take]
            return lat, lon
        return (
            first_of(*((k, "lat_deg", ok) for k, ok in pos_sources)),
            first_of(*((k, "lon_deg", ok) for k, ok in pos_sources)),
        )

    def headings() -> tuple[np.ndarray, np.ndarray]:
        heading = np.full(n_ep, np.nan)
        source = np.full(n_ep, -1, dtype=np.int8)
        for k in HEADING_PRIORITY:
            if size[k]:
                v = np.asarray(tables[k]["heading_deg"], dtype=float)
                code = HEADING_SOURCES.index(_HEADING_LABEL.get(k, k.split(",")[0]))
                _fill(heading, epoch_of[k], v, None, source, code)
        return heading, source

    attitude = ATTITUDE_PRIORITY
    jobs = {
        "position": position,
        "alt_m": lambda: first_of(("GGA", "alt_m", gga_ok), ("GNS", "alt_m")),
        "fix_quality": lambda: first_of(
            ("GGA", "fix_quality"), ("GNS", "fix_quality"), ("GLL", "fix_quality")
        ),
        "n_sats": lambda: first_of(("GGA", "n_sats"), ("GNS", "n_sats")),
        "hdop": lambda: first_of(("GGA", "hdop"), ("GNS", "hdop")),
        "speed_mps": lambda: first_of(("RMC", "speed_mps", rmc_ok), ("VTG", "speed_mps")),
        "course_deg": lambda: first_of(("RMC", "course_deg", rmc_ok), ("VTG", "course_deg")),
        "heading": headings,
        "pitch_deg": lambda: first_of(*((k, "pitch_deg") for k in attitude)),
        "roll_deg": lambda: first_of(*((k, "roll_deg") for k in attitude)),
        "rot_deg_per_min": lambda: first_of(("ROT", "rot_deg_per_min")),
        "day": lambda: first_of(
            ("RMC", "day"), ("ZDA", "day"), ("PSTI,036", "day"), ("PSSN,HRP", "day")
        ),
    }
    # the columns are independent: on a long log they are filled on the tokenizer's threads
    # (the compiled fills release the GIL)
    n_workers = min(numba.get_num_threads(), 4) if n_ep >= _MIN_PARALLEL_EPOCHS else 1
    if n_workers > 1:
        with ThreadPoolExecutor(max_workers=n_workers) as ex:
            done = dict(zip(jobs, ex.map(lambda f: f(), jobs.values()), strict=True))
    else:
        done = {k: f() for k, f in jobs.items()}
    ep: dict[str, object] = {}
    ep["lat_deg"], ep["lon_deg"] = done.pop("position")
    heading, source = done.pop("heading")
    rot, day = done["rot_deg_per_min"], done.pop("day")
    ep.update(done)
    ep["heading_deg"] = heading
    ep["heading_source"] = pd.Categorical.from_codes(source, categories=HEADING_SOURCES)

    timed = ~np.isnan(tod_e)
    ep["time_utc"], t_s, has_date = _epoch_times(tod_e, day)
    ep["t_s"] = t_s
    ep["yaw_rate_rps"], ysrc = _yaw_rate(rot, t_s, heading)
    ep["yaw_rate_source"] = pd.Categorical.from_codes(ysrc, categories=YAW_RATE_SOURCES)

    df = pd.DataFrame({c: ep[c] for c in EPOCH_COLUMNS}, copy=False)
    notes = {
        "epochs_without_time": int((~timed).sum()),
        "has_date": has_date,
        "repeated_sentences": n_repeated,
        "same_time_merged": n_same,
    }
    return df, epoch_of, notes


def _group_lines(
    tables: dict[str, dict[str, np.ndarray]], keys: list[str], size: dict[str, int]
) -> tuple[int, np.ndarray, dict[str, np.ndarray], int, int]:
    """Decoded sentences grouped into epochs, in line order (:func:`assemble_epochs`).

    Returns
    -------
    tuple
        Number of epochs, time of day of each [s], the epoch of each sentence per type, the
        number of sentences that repeat the line before them, the number of epochs joined to
        the one before them for having its time.
    """
    # sentences in line order: a counting sort by line (lines are distinct and < n_lines)
    n_lines = 1 + max((int(t["line"].max()) for t in tables.values() if t["line"].size), default=-1)
    kind_at = np.full(n_lines, -1, dtype=np.int64)
    tod_at = np.full(n_lines, np.nan)
    lines_of = {k: tables[k]["line"] for k in keys}
    repeated = np.zeros(n_lines, dtype=bool)
    empty_at = np.zeros(n_lines, dtype=bool)
    for code, k in enumerate(keys):
        kind_at[lines_of[k]] = code
        if "tod_s" in tables[k]:
            tod_at[lines_of[k]] = tables[k]["tod_s"]
        repeated[lines_of[k][_repeats(tables[k])]] = True
        empty_at[lines_of[k][_empty(tables[k])]] = True
    # a sentence that repeats the line before it verbatim (a logger writing each sentence
    # twice) is the same measurement: it joins its original's epoch instead of starting one
    kind_at[repeated] = -1
    # a sentence without any value (``$IIHDT,,T`` sent twice per cycle) must not split a cycle
    tod_e = np.empty(sum(size.values()))
    kind0 = kind_at.copy()
    n_ep = int(_group_kernel(kind_at, tod_at, tod_e))
    n_same = np.zeros(1, dtype=np.int64)
    n_ep = int(_merge_kernel(kind_at, kind0, empty_at, tod_e, n_ep, n_same))
    tod_e = tod_e[:n_ep]
    eid_at = np.maximum.accumulate(kind_at) if n_lines else kind_at  # line -> epoch

    epoch_of: dict[str, np.ndarray] = {k: eid_at[lines_of[k]] for k in keys}
    return n_ep, tod_e, epoch_of, int(repeated.sum()), int(n_same[0])


def _yaw_rate(
    rot: np.ndarray, t_s: np.ndarray, heading: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """ISO yaw rate per epoch [rad/s] and its source code (:data:`YAW_RATE_SOURCES`): the
    receiver's ROT, else differenced from the heading (:func:`assemble_epochs`).
    """
    yaw = -rot * ROT_TO_RPS
    ysrc = np.zeros(rot.size, dtype=np.int8)
    if np.isnan(rot).any():
        yaw_from_heading(t_s, heading, yaw, ysrc)
    return yaw, ysrc


def _epoch_times(tod_e: np.ndarray, day: np.ndarray) -> tuple[pd.DatetimeIndex, np.ndarray, bool]:
    """UTC time and seconds from the first timed epoch, from each epoch's time of day and day
    number (:func:`assemble_epochs`); without any date every UTC time is NaT.

    Returns
    -------
    tuple
        ``time_utc``, ``t_s`` [s] and whether the log carries a date.
    """
    abs_s = np.empty(tod_e.size)
    has_date = bool(_seconds_kernel(tod_e, day, abs_s))
    ns = np.round(abs_s * 1e9)
    ns[np.isnan(abs_s) | (not has_date)] = np.iinfo(np.int64).min  # NaT (without a date: all)
    time_utc = pd.DatetimeIndex(ns.astype(np.int64).view("M8[ns]")).tz_localize("UTC")
    first = np.flatnonzero(~np.isnan(abs_s))
    t_s = abs_s - abs_s[first[0]] if first.size else abs_s
    return time_utc, t_s, has_date
