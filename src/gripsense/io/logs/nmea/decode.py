"""Raw NMEA field values -> physical values per sentence (shared by both tokenizers).

Conversions done here, once, for every sentence type:

* ``hhmmss.sss`` -> seconds of the UTC day; ``ddmmyy`` / ZDA day, month, year -> days since
  1970-01-01 (two-digit years: 80-99 -> 19xx, 00-79 -> 20xx);
* ``ddmm.mmmm`` + N/S, ``dddmm.mmmm`` + E/W -> signed decimal degrees; GLL's and GNS's
  position is NaN where the sentence itself says it is no fix (GLL status not A, or a mode
  that is not a fix letter; GNS mode letters all N), and their mode becomes ``fix_quality``
  on GGA's scale (A 1, D 2, …);
* speed over ground: knots x 1852/3600 -> m/s (VTG falls back to its km/h field);
* headings are kept in compass degrees (clockwise from true north), wrapped to [0, 360);
* rate of turn is kept as NMEA sends it: degrees per minute, positive = turning to starboard.

Values that have the right syntax but are out of range (minute 61, latitude 95°, month 13, a
value without its hemisphere letter) make the line *malformed*; the caller moves it to the
rejected bucket.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from gripsense.io.logs.nmea.schema import MODE_QUALITY, SENTENCES

__all__ = ["KNOT", "decode_all"]

KNOT = 1852.0 / 3600.0  # [m/s] per knot (exact)
_EPOCH_DAY0 = np.datetime64("1970-01-01", "D")


def _tod(x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """hhmmss.sss -> seconds of day [s]; also the mask of impossible times."""
    hh = np.floor(x / 10000.0)
    mm = np.floor(x / 100.0) - hh * 100.0
    ss = x - np.floor(x / 100.0) * 100.0
    bad = (hh >= 24) | (mm >= 60) | (ss >= 61)
    return hh * 3600.0 + mm * 60.0 + ss, bad & ~np.isnan(x)


def _latlon(v: np.ndarray, hemi: np.ndarray, neg: str, pos: str, lim: float):
    """ddmm.mmmm + hemisphere letter -> signed degrees [deg]; mask of malformed values."""
    deg = np.floor(v / 100.0)
    minutes = v - deg * 100.0
    out = deg + minutes / 60.0
    has = ~np.isnan(v)
    letter_ok = (hemi == ord(neg)) | (hemi == ord(pos))
    bad = has & ((minutes >= 60.0) | (out > lim) | ~letter_ok)
    out = np.where(hemi == ord(neg), -out, out)
    return out, bad


def _days(day: np.ndarray, month: np.ndarray, year: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Calendar date -> days since 1970-01-01 (float, NaN when missing); mask of invalid dates."""
    has = ~(np.isnan(day) | np.isnan(month) | np.isnan(year))
    out = np.full(day.shape, np.nan)
    bad = np.zeros(day.shape, dtype=bool)
    if has.any():
        d, m, y = day[has], month[has], year[has]
        ok = (m >= 1) & (m <= 12) & (d >= 1) & (y >= 1900) & (y <= 2200)
        yi = np.where(ok, y, 1970).astype(np.int64)
        mi = np.where(ok, m, 1).astype(np.int64)
        first = (yi - 1970) * 12 + (mi - 1)
        start = np.datetime64("1970-01", "M") + first.astype("timedelta64[M]")
        ndays = ((start + 1).astype("datetime64[D]") - start.astype("datetime64[D]")).astype(int)
        ok &= d <= ndays
        days = (start.astype("datetime64[D]") - _EPOCH_DAY0).astype(np.int64) + d - 1
        vals = np.where(ok, days, np.nan)
        out[has] = vals
        bad[np.flatnonzero(has)[~ok]] = True
    return out, bad


def _ddmmyy(x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    day = np.floor(x / 10000.0)
    month = np.floor(x / 100.0) - day * 100.0
    yy = x - np.floor(x / 100.0) * 100.0
    year = np.where(yy >= 80, 1900.0 + yy, 2000.0 + yy)
    return _days(day, month, year)


def _wrap360(h: np.ndarray) -> np.ndarray:
    """Heading wrapped to [0, 360) [deg]: ``np.mod(h, 360)``, computed only where needed
    (``np.mod`` is slow and almost every heading is in range already; ``+ 0.0`` turns -0.0
    into 0.0 as ``np.mod`` does).
    """
    out = h + 0.0
    off = ~((h >= 0.0) & (h < 360.0)) & ~np.isnan(h)  # (np.mod is slowest on NaN)
    if off.any():
        out[off] = np.mod(h[off], 360.0)
    return out


# byte of a mode letter -> fix quality on GGA's scale (schema.MODE_QUALITY); NaN: no letter
_MODE_Q = np.full(256, np.nan)
for _k, _q in MODE_QUALITY.items():
    _MODE_Q[ord(_k)] = _q
del _k, _q
_CHARS = np.array([None] + [chr(i) for i in range(1, 256)], dtype=object)


def _char(c: np.ndarray) -> np.ndarray:
    """uint8 byte values -> object array of one-letter strings (None when empty; a table
    lookup, ~4× faster than building the strings one by one).
    """
    return _CHARS[c]


def _decode_one(
    key: str, r: dict[str, np.ndarray]
) -> tuple[dict[str, np.ndarray], np.ndarray, dict[int, str]]:
    """Decode one raw table. Returns (columns, malformed mask, row -> its first bad field)."""
    n = r["line"].size
    bad = np.zeros(n, dtype=bool)
    checks: list[tuple[np.ndarray, str]] = []

    def flag(mask: np.ndarray, name: str) -> None:
        checks.append((mask, name))
        bad[:] |= mask

    c: dict[str, np.ndarray] = {"line": r["line"]}
    if "time" in r:
        c["tod_s"], b = _tod(r["time"])
        flag(b, "time")
    no_fix = _position(key, r, c, flag)
    if key == "GGA":
        c["fix_quality"] = r["quality"]
        c["n_sats"] = r["n_sats"]
        c["hdop"] = r["hdop"]
        c["alt_m"] = r["alt"]
    elif key == "RMC":
        c["status"] = _char(r["status"])
        c["speed_mps"] = r["sog_kn"] * KNOT
        c["course_deg"] = _wrap360(r["cog"])
        c["day"], b = _ddmmyy(r["date"])
        flag(b, "date")
    elif key == "GNS":
        c["n_sats"] = r["n_sats"]
        c["hdop"] = r["hdop"]
        c["alt_m"] = np.where(no_fix, np.nan, r["alt"])
    elif key == "GLL":
        c["status"] = _char(r["status"])
        c["mode"] = _char(r["mode"])
    elif key == "VTG":
        sp = np.where(np.isnan(r["sog_kn"]), r["sog_kmh"] / 3.6, r["sog_kn"] * KNOT)
        invalid = r["mode"] == ord("N")
        c["speed_mps"] = np.where(invalid, np.nan, sp)
        c["course_deg"] = np.where(invalid, np.nan, _wrap360(r["cog"]))
        c["mode"] = _char(r["mode"])
    elif key == "HDT":
        c["heading_deg"] = _wrap360(r["heading"])
    elif key == "THS":
        c["heading_deg"] = np.where(r["mode"] == ord("V"), np.nan, _wrap360(r["heading"]))
        c["mode"] = _char(r["mode"])
    elif key == "ROT":
        c["rot_deg_per_min"] = np.where(r["status"] == ord("V"), np.nan, r["rot"])
    elif key == "ZDA":
        c["day"], b = _days(r["day"], r["month"], r["year"])
        flag(b, "date")
    elif key in ("PSAT,HPR", "PASHR"):
        c["heading_deg"] = _wrap360(r["heading"])
        c["pitch_deg"] = r["pitch"]
        c["roll_deg"] = r["roll"]
        if key == "PSAT,HPR":
            c["type"] = _char(r["type"])
    elif key == "PFEC,GPatt":
        c["heading_deg"] = _wrap360(r["heading"])
        c["pitch_deg"] = r["pitch"]
        c["roll_deg"] = r["roll"]
    elif key == "PASHR,HPR":
        # an attitude from float ambiguities (flag 1) is not used; an empty flag is read
        invalid = r["ambiguity"] > 0
        c["heading_deg"] = np.where(invalid, np.nan, _wrap360(r["heading"]))
        c["pitch_deg"] = np.where(invalid, np.nan, r["pitch"])
        c["roll_deg"] = np.where(invalid, np.nan, r["roll"])
    elif key == "PTNL,AVR":
        # the baseline's yaw is a heading only from a fixed-RTK vector (quality 3)
        invalid = r["quality"] != 3
        c["heading_deg"] = np.where(invalid, np.nan, _wrap360(r["heading"]))
        c["pitch_deg"] = np.where(invalid, np.nan, r["pitch"])
        c["roll_deg"] = np.where(invalid, np.nan, r["roll"])
    elif key == "PSSN,HRP":
        # fixed ambiguities only: mode 2 (heading, pitch) or 4 (heading, pitch, roll)
        invalid = (r["mode"] != 2) & (r["mode"] != 4)
        c["heading_deg"] = np.where(invalid, np.nan, _wrap360(r["heading"]))
        c["pitch_deg"] = np.where(invalid, np.nan, r["pitch"])
        c["roll_deg"] = np.where(invalid, np.nan, r["roll"])
        c["day"], b = _ddmmyy(r["date"])
        flag(b, "date")
    elif key == "PSTI,036":
        # attitude valid only with a fixed-RTK baseline (mode R), as GPSD reads it
        invalid = r["mode"] != ord("R")
        c["heading_deg"] = np.where(invalid, np.nan, _wrap360(r["heading"]))
        c["pitch_deg"] = np.where(invalid, np.nan, r["pitch"])
        c["roll_deg"] = np.where(invalid, np.nan, r["roll"])
        c["mode"] = _char(r["mode"])
        c["day"], b = _ddmmyy(r["date"])
        flag(b, "date")
    # row -> the field of its first failed check
    why = {i: next(nm for m, nm in checks if m[i]) for i in np.flatnonzero(bad).tolist()}
    return c, bad, why


def _position(
    key: str, r: dict[str, np.ndarray], c: dict[str, np.ndarray], flag: Callable
) -> np.ndarray:
    """The position columns of a GGA, RMC, GLL or GNS table into *c* (a field that does not
    read is flagged through *flag*, unless the sentence says it has no fix); returns which
    rows say they have no fix (:func:`_decode_one`).
    """
    n = r["line"].size
    no_fix = np.zeros(n, dtype=bool)
    if key == "GLL":
        # a position only with status A and a mode that is a fix letter (not N) or absent
        # (NMEA before 2.3); an unknown letter is no fix
        quality = _MODE_Q[r["mode"]]
        no_fix = (r["status"] != ord("A")) | (quality == 0) | ((r["mode"] > 0) & np.isnan(quality))
        c["fix_quality"] = np.where(no_fix, 0.0, quality)
    elif key == "GNS":
        # no fix when every mode letter is N (or the mode field is empty)
        no_fix = ~(r["mode"] > 0)
        c["fix_quality"] = r["mode"]
    if key in ("GGA", "RMC", "GLL", "GNS"):
        # a receiver without a fix (GGA quality 0, RMC status V …) may send a placeholder
        # position (MediaTek: 8960.000000,N — minute 60): not a malformed sentence, no position
        if key in ("GGA", "RMC"):
            no_fix = r["quality"] == 0 if key == "GGA" else r["status"] == ord("V")
        for name, f, neg, pos, lim in (
            ("lat", "lat", "S", "N", 90.0),
            ("lon", "lon", "W", "E", 180.0),
        ):
            hemi = r["ns"] if f == "lat" else r["ew"]
            c[f"{name}_deg"], b = _latlon(r[f], hemi, neg, pos, lim)
            c[f"{name}_deg"][b & no_fix] = np.nan
            flag(b & ~no_fix, name)
            if key in ("GLL", "GNS"):  # GGA's and RMC's flags are applied per epoch
                c[f"{name}_deg"][no_fix] = np.nan
    return no_fix


def decode_all(
    raw: dict[str, dict[str, np.ndarray]],
) -> tuple[dict[str, dict[str, np.ndarray]], list[tuple[int, str]]]:
    """Decode every raw table.

    Parameters
    ----------
    raw : dict
        Type key -> raw field table of a tokenizer (:class:`~gripsense.io.logs.nmea.tokens.Tokens`).

    Returns
    -------
    tables : dict
        Type key -> column name -> array of the decoded sentences (column ``line`` = 0-based
        line index); :func:`~gripsense.io.logs.nmea.reader.read_nmea` makes DataFrames of them.
    malformed : list of (line index, detail)
        Lines whose values are out of range (to be rejected as *malformed field*).
    """
    tables: dict[str, dict[str, np.ndarray]] = {}
    malformed: list[tuple[int, str]] = []
    for key in SENTENCES:
        cols, bad, why = _decode_one(key, raw[key])
        if bad.any():
            for i in np.flatnonzero(bad).tolist():
                malformed.append((int(cols["line"][i]), f"{key} {why[i]} out of range"))
            cols = {k: v[~bad] for k, v in cols.items()}
        tables[key] = cols
    malformed.sort()
    return tables, malformed
