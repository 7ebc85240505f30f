"""NovAtel OEM ASCII logs (``#HEADING2A,…;…*crc32`` lines), as OEM6/OEM7 receivers
(PwrPak7D, SMART7, OEM7720 …) log them.

A line is ``#NAME,port,sequence,idle,time status,week,seconds,receiver status,reserved,
software build;field,field,…*xxxxxxxx``: the header, the body and the 32-bit CRC of everything
between ``#`` and ``*`` (NovAtel's CRC-32: reflected polynomial 0xEDB88320, register starting
at 0, no final inversion; OEM7 Commands and Logs Reference Manual, "32-Bit CRC"). A log with a
short header (``%NAME,week,seconds;…*crc``: INSPVAS …) is read the same way. gripsense reads:

===================  ======================================================================
log                  what is read
===================  ======================================================================
BESTPOS              latitude, longitude, height above mean sea level, satellites in the
                     solution, fix quality (from the position type) — ``SOL_COMPUTED`` only
BESTVEL              speed (``hor_spd``) and course over ground (``trk_gnd``) —
                     ``SOL_COMPUTED`` and a velocity type other than ``NONE``
HEADING, HEADING2,   true heading of the antenna baseline (``heading``) and its standard
DUALANTENNAHEADING   deviation — ``SOL_COMPUTED`` and a position type other than ``NONE``
INSPVA, INSPVAS,     the INS azimuth as the heading only when the log has no HEADING log, and
INSPVAX              position, speed and course only when it has no BESTPOS / BESTVEL —
                     INS status ``INS_SOLUTION_GOOD``, ``INS_SOLUTION_FREE`` or
                     ``INS_ALIGNMENT_COMPLETE``
===================  ======================================================================

Lines are grouped into epochs by the header's GPS week and seconds; UTC is GPS time less the
GPS−UTC leap seconds of that date (:func:`gps_to_utc`). Every line is accounted for: read
(``parsed``), a valid line not used (``ignored``: another log, a solution not computed, a
reply ``<OK`` or a port prompt ``[COM1]`` (a log after the prompt on the same line is
read), abbreviated ASCII ``<…`` lines, which carry no CRC), or rejected: ``bad checksum`` (a
bad CRC), ``missing checksum``, ``malformed field``, ``truncated`` (the file ends inside the
line) or ``not NovAtel ASCII``. NMEA sentences logged on the same port are read by
:func:`gripsense.io.read_nmea` (counted under their types) and fill what the NovAtel logs lack
at the same UTC time; their epochs at other times are epochs of their own.

``heading_source`` names the log that gave each epoch's heading (``HEADING``, ``HEADING2``,
``DUALANTENNAHEADING``, ``INSPVA``, ``INSPVAS``, ``INSPVAX``; :mod:`gripsense.io.logs.sources`), or
the NMEA sentence where the NMEA gave it.
"""

from __future__ import annotations

import re
import zlib
from pathlib import Path

import numpy as np
import pandas as pd

from gripsense.errors import InputError
from gripsense.io.logs.epoch_table import build_epochs
from gripsense.io.logs.nmea.accounting import IngestReport, RejectedLine
from gripsense.io.logs.nmea.reader import NmeaLog, read_nmea
from gripsense.io.logs.nmea.schema import (
    BAD_CHECKSUM,
    BLANK,
    MALFORMED,
    MISSING_CHECKSUM,
    REASONS,
    TRUNCATED,
)
from gripsense.io.logs.options import LogInput
from gripsense.io.logs.sources import HEADING_SOURCES
from gripsense.io.output_folder import write_file_atomic

__all__ = [
    "LEAP_SECONDS",
    "NOT_NOVATEL",
    "crc32",
    "gps_to_utc",
    "is_novatel",
    "parse_novatel",
    "read_novatel_log",
    "write_novatel",
]

NOT_NOVATEL = "not NovAtel ASCII"
"""Reject reason of a line that is neither a NovAtel log, a prompt nor an NMEA sentence."""

_GPS_EPOCH = np.datetime64("1980-01-06T00:00:00", "s")
_WEEK_S = 604_800.0

LEAP_SECONDS = (
    ("1981-07-01", 1),
    ("1982-07-01", 2),
    ("1983-07-01", 3),
    ("1985-07-01", 4),
    ("1988-01-01", 5),
    ("1990-01-01", 6),
    ("1991-01-01", 7),
    ("1992-07-01", 8),
    ("1993-07-01", 9),
    ("1994-07-01", 10),
    ("1996-01-01", 11),
    ("1997-07-01", 12),
    ("1999-01-01", 13),
    ("2006-01-01", 14),
    ("2009-01-01", 15),
    ("2012-07-01", 16),
    ("2015-07-01", 17),
    ("2017-01-01", 18),
)
"""(UTC date from which it holds, GPS − UTC [s]): IERS Bulletin C; none since 2017."""

# GPS seconds (since 1980-01-06) at which each offset starts: the UTC date + the new offset
_LEAP_AT = np.array(
    [(np.datetime64(d, "s") - _GPS_EPOCH).astype(float) + n for d, n in LEAP_SECONDS]
)
_LEAP_N = np.array([n for _, n in LEAP_SECONDS], dtype=float)


def gps_to_utc(week: np.ndarray, seconds: np.ndarray) -> np.ndarray:
    """UTC seconds since 1970 of a GPS week and time of week.

    GPS time runs without leap seconds from 1980-01-06 00:00 UTC; UTC = GPS − (GPS − UTC),
    the offset of :data:`LEAP_SECONDS` in force at that instant.

    Parameters
    ----------
    week : numpy.ndarray
        GPS week number (full, not modulo 1024) [week].
    seconds : numpy.ndarray
        Seconds of the week [s].

    Returns
    -------
    numpy.ndarray
        Seconds since 1970-01-01 UTC [s].
    """
    gps = np.asarray(week, float) * _WEEK_S + np.asarray(seconds, float)
    k = np.searchsorted(_LEAP_AT, gps, side="right")
    leap = np.where(k > 0, _LEAP_N[np.maximum(k - 1, 0)], 0.0)
    return gps - leap + float(_GPS_EPOCH.astype("datetime64[s]").astype(np.int64))


def crc32(data: bytes) -> int:
    """NovAtel's 32-bit CRC of a message (OEM7 Commands and Logs Reference Manual, "32-Bit
    CRC": reflected polynomial 0xEDB88320, register starting at 0, no final inversion).

    Parameters
    ----------
    data : bytes
        The bytes between ``#`` (or ``%``) and ``*`` of an ASCII log [bytes].

    Returns
    -------
    int
        The CRC [-].
    """
    # zlib's CRC-32 is the same register with the start and the end inverted: undo both
    return zlib.crc32(data, 0xFFFFFFFF) ^ 0xFFFFFFFF


_LINE = re.compile(rb"^([#%])([A-Z0-9_]+?)A,([^;]*);(.*)$")
_CRC = re.compile(rb"^(.*)\*([0-9A-Fa-f]{8})\s*$")
_PROMPT = re.compile(rb"^\[[A-Za-z0-9_]+\]")  # the port prompt a console puts before a log


def is_novatel(head: bytes) -> bool:
    """Whether the first bytes of a file are a NovAtel ASCII log: lines shaped as NovAtel logs
    (``#NAMEA,header;body*xxxxxxxx`` or ``%NAMEA,week,seconds;body*xxxxxxxx``) at least as many
    as the NMEA sentences — the CRCs not required, so that a damaged log is still read as
    NovAtel, its bad lines rejected one by one — or, among more NMEA sentences, one log gripsense
    reads (BESTPOS, HEADING2 …) with a good CRC: the NovAtel reader reads the NMEA too.

    Parameters
    ----------
    head : bytes
        The first 64 KiB or so.

    Returns
    -------
    bool
        True for a NovAtel ASCII log.
    """
    shaped = nmea = known = 0
    for raw in head.splitlines()[:400]:
        line = _PROMPT.sub(b"", raw.strip())
        if line[:1] in (b"$", b"!"):
            nmea += 1
            continue
        m = _CRC.match(line)
        lm = _LINE.match(m.group(1)) if m else None
        if m and lm:
            shaped += 1
            if lm.group(2).decode() in _MIN_FIELDS and crc32(m.group(1)[1:]) == int(m.group(2), 16):
                known += 1
    return shaped > 0 and (shaped >= nmea or known > 0)


# position type -> GGA fix quality (1 autonomous, 2 differential, 4 RTK fixed, 5 RTK float)
_FIX = {
    "SINGLE": 1,
    "PSRDIFF": 2,
    "WAAS": 2,
    "PROPAGATED": 1,
    "L1_FLOAT": 5,
    "IONOFREE_FLOAT": 5,
    "NARROW_FLOAT": 5,
    "PPP_CONVERGING": 5,
    "PPP": 5,
    "PPP_BASIC_CONVERGING": 5,
    "PPP_BASIC": 5,
    "L1_INT": 4,
    "WIDE_INT": 4,
    "NARROW_INT": 4,
    "RTK_DIRECT_INS": 4,
    "INS_SBAS": 2,
    "INS_PSRSP": 1,
    "INS_PSRDIFF": 2,
    "INS_RTKFLOAT": 5,
    "INS_RTKFIXED": 4,
    "INS_PPP_CONVERGING": 5,
    "INS_PPP": 5,
}
_INS_GOOD = ("INS_SOLUTION_GOOD", "INS_SOLUTION_FREE", "INS_ALIGNMENT_COMPLETE")
_HEADINGS = ("HEADING", "HEADING2", "DUALANTENNAHEADING")
# log -> fewest body fields
_MIN_FIELDS = {
    "BESTPOS": 15,
    "BESTVEL": 6,
    "HEADING": 8,
    "HEADING2": 8,
    "DUALANTENNAHEADING": 8,
    "INSPVA": 12,
    "INSPVAS": 12,
    "INSPVAX": 12,
}


_RANGES = {
    "lat_deg": (-90.0, 90.0),
    "lon_deg": (-180.0, 180.0),
    "alt_m": (-1e5, 1e7),
    "speed_mps": (0.0, 1e4),
    "course_deg": (-360.0, 360.0),
    "heading_deg": (-360.0, 360.0),
    "heading_acc_deg": (0.0, 360.0),
    "ins_lat": (-90.0, 90.0),
    "ins_lon": (-180.0, 180.0),
    "ins_speed": (0.0, 1e4),
    "ins_heading": (-360.0, 360.0),
}


def _check_ranges(vals: dict[str, float]) -> None:
    """Raise ValueError naming the first value that no receiver gives (NaN, ±inf, a latitude
    beyond ±90° …).
    """
    for k, v in vals.items():
        lo, hi = _RANGES.get(k, (-np.inf, np.inf))
        if not lo <= v <= hi:
            raise ValueError(f"{k.removeprefix('ins_')} {v} outside [{lo:g}, {hi:g}]")


def _body(name: str, f: list[str]) -> tuple[dict[str, float], str]:
    """The values a known log gives, or why it gives none ('' when it gives them).

    Raises ValueError on a field that is not a number.
    """
    if name == "BESTPOS":
        if f[0] != "SOL_COMPUTED" or f[1] == "NONE":
            return {}, f"solution {f[0]}, position {f[1]}"
        return {
            "lat_deg": float(f[2]),
            "lon_deg": float(f[3]),
            "alt_m": float(f[4]),
            "n_sats": float(int(f[14])),
            "fix_quality": float(_FIX.get(f[1], 1)),
        }, ""
    if name == "BESTVEL":
        if f[0] != "SOL_COMPUTED" or f[1] == "NONE":
            return {}, f"solution {f[0]}, velocity {f[1]}"
        return {"speed_mps": float(f[4]), "course_deg": float(f[5])}, ""
    if name in _HEADINGS:
        if f[0] != "SOL_COMPUTED" or f[1] == "NONE":
            return {}, f"solution {f[0]}, position {f[1]}"
        return {"heading_deg": float(f[3]), "heading_acc_deg": float(f[6])}, ""
    if name == "INSPVAX":  # INS status, position type, lat, lon, height, undulation, v_n, …
        status, vals = f[0], [float(x) for x in (*f[2:5], *f[6:12])]
    else:  # INSPVA(S): week, seconds, lat, lon, height, v_n, v_e, v_u, roll, pitch, azimuth
        status, vals = f[11], [float(x) for x in f[2:11]]
    if status not in _INS_GOOD:
        return {}, f"INS status {status}"
    vn, ve = vals[3], vals[4]
    return {
        "ins_lat": vals[0],
        "ins_lon": vals[1],
        "ins_speed": float(np.hypot(vn, ve)),
        "ins_course": float(np.mod(np.degrees(np.arctan2(ve, vn)), 360.0)),
        "ins_heading": vals[8],
    }, ""


def parse_novatel(data: bytes, name: str = "<novatel>", *, strict: bool = False) -> NmeaLog:
    """Read a NovAtel ASCII log into the epoch table.

    Parameters
    ----------
    data : bytes
        The log's bytes.
    name : str
        File name, for messages.
    strict : bool
        Raise at the first rejected line instead of counting it.

    Returns
    -------
    NmeaLog
        ``epochs``, ``report`` (lines) and ``sentences`` (per log read, its decoded rows with
        the 1-based ``line``, GPS ``week`` and ``seconds``).
    """
    parsed: dict[str, int] = {}
    ignored: dict[str, int] = {}
    rejected = dict.fromkeys(REASONS, 0)
    rejected[NOT_NOVATEL] = 0
    first: list[RejectedLine] = []

    prefixed = [False, 0]  # this line came after a port prompt; such lines read or ignored

    def reject(no: int, reason: str, detail: str) -> None:
        rejected[reason] += 1
        prefixed[1] -= prefixed[0]
        if strict:
            raise InputError(f"{name}: line {no}: {reason}: {detail} (strict mode)")
        if len(first) < 20:
            first.append(RejectedLine(no, reason, detail))

    def ignore(key: str) -> None:
        ignored[key] = ignored.get(key, 0) + 1

    rows: dict[str, list[dict[str, float]]] = {}
    nmea_lines: list[bytes] = []  # NMEA sentences the receiver logged on the same port
    nmea_no: list[int] = []
    if data.startswith(b"\xef\xbb\xbf"):  # a UTF-8 byte-order mark a Windows tool wrote
        data = data[3:]
    lines = data.split(b"\n")
    if lines and lines[-1] == b"":
        lines.pop()
    cut_last = bool(data) and not data.endswith(b"\n")
    for i, raw in enumerate(lines):
        no = i + 1
        prefixed[0] = False
        line = raw.strip()
        if not line:
            ignore(BLANK)
            continue
        if line[:1] == b"[" and (pm := _PROMPT.match(line)) is not None:
            if pm.end() == len(line):
                ignore("NovAtel port prompt")
                continue
            line = line[pm.end() :].lstrip()  # "[COM1]#BESTPOSA,…": the log after the prompt
            prefixed[:] = [True, prefixed[1] + 1]
        lead = line[:1]
        if lead == b"$" or lead == b"!":
            if b"\r" in line:  # two sentences on one line: the NMEA reader would split it
                ignore("NMEA sentence (not read: a carriage return inside the line)")
            else:
                nmea_lines.append(line)
                nmea_no.append(no)
            continue
        if lead == b"<":
            ignore("NovAtel abbreviated ASCII or reply (no CRC: log the ...A form)")
            continue
        if lead not in (b"#", b"%"):
            reject(no, NOT_NOVATEL, f"{line[:40]!r} is not a NovAtel ASCII log line")
            continue
        msg, why = _crc_checked(line, cut_last and i == len(lines) - 1)
        if msg is None:
            reject(no, *why)
            continue
        kind, what, row = _decoded(msg)
        if kind == "reject":
            reject(no, MALFORMED, what)
            continue
        if kind == "ignore":
            ignore(what)
            continue
        parsed[f"NovAtel {what}"] = parsed.get(f"NovAtel {what}", 0) + 1
        rows.setdefault(what, []).append({"line": no, **row})

    sentences = {f"NovAtel {k}": pd.DataFrame(v) for k, v in rows.items()}
    notes: list[str] = []
    nlog = _port_nmea(nmea_lines, ignored)
    if nlog is not None:
        rn = nlog.report
        prefixed[1] += rn.junk_prefix_lines
        for src, dst in ((rn.parsed, parsed), (rn.ignored, ignored), (rn.rejected, rejected)):
            for k, v in src.items():
                dst[k] = dst.get(k, 0) + v
        _nmea_rejects(rn.first_rejects, nmea_no, first, name, strict)
        notes += rn.notes
        sentences.update(
            {k: v.assign(line=np.asarray(nmea_no)[v["line"].to_numpy(int) - 1])
             for k, v in nlog.sentences.items() if len(v)}
        )  # fmt: skip
    epochs, more = _epochs(rows, nlog)
    notes += more
    report = IngestReport(
        source=name,
        total_lines=len(lines),
        parsed=dict(sorted(parsed.items())),
        ignored=dict(sorted(ignored.items())),
        rejected=rejected,
        first_rejects=first,
        junk_prefix_lines=prefixed[1],
        n_epochs=len(epochs),
        epochs_without_time=int(epochs["t_s"].isna().sum()),
        has_date=bool(len(epochs)),
        notes=notes,
        format="NovAtel ASCII" + (" + NMEA 0183" if nlog is not None else ""),
        unit="lines",
    )
    return NmeaLog(epochs=epochs, report=report, sentences=sentences)


def _crc_checked(line: bytes, cut: bool) -> tuple[bytes | None, tuple[str, str]]:
    """The line's message (``#…`` up to ``*``) when its CRC-32 checks, else None and the
    reason and detail of its rejection (*cut*: the file ends inside this line).
    """
    m = _CRC.match(line)
    if m is None:
        if cut:
            return None, (TRUNCATED, "the file ends inside the line")
        if b"*" in line:
            return None, (MALFORMED, "the CRC after '*' is not 8 hexadecimal digits")
        return None, (MISSING_CHECKSUM, "no '*' and 32-bit CRC at the end of the line")
    msg, want = m.group(1), int(m.group(2), 16)
    got = crc32(msg[1:])
    if got != want:
        return None, (BAD_CHECKSUM, f"bad CRC: the line says {want:08x}, its bytes give {got:08x}")
    return msg, ("", "")


def _port_nmea(nmea_lines: list[bytes], ignored: dict[str, int]) -> NmeaLog | None:
    """The NMEA sentences logged on the NovAtel port, read (None: none, or they are not one
    sentence per line — then counted in *ignored*, not read).
    """
    if not nmea_lines:
        return None
    nlog = read_nmea(b"\n".join(nmea_lines) + b"\n", decompress=False)
    if nlog.report.total_lines != len(nmea_lines):  # not one line each: count them, read none
        ignored["NMEA sentence (not read in a NovAtel log)"] = len(nmea_lines)
        return None
    return nlog


def _nmea_rejects(
    rejects: list[RejectedLine],
    nmea_no: list[int],
    first: list[RejectedLine],
    name: str,
    strict: bool,
) -> None:
    """The port's NMEA rejects among the log's first ones, at their lines in the log."""
    for r in rejects:
        at = nmea_no[r.line - 1]
        if strict:
            raise InputError(f"{name}: line {at}: {r.reason}: NMEA: {r.detail} (strict mode)")
        if len(first) < 20:
            first.append(RejectedLine(at, r.reason, f"NMEA: {r.detail}"))
    first[:] = sorted(first, key=lambda r: r.line)[:20]


def _decoded(msg: bytes) -> tuple[str, str, dict[str, float]]:
    """One line whose CRC checked: ``("reject", detail, {})``, ``("ignore", what, {})`` or
    ``("row", log, {week, seconds, values…})``.
    """
    lm = _LINE.match(msg)
    if lm is None:
        return "reject", "not NAME…A,header;body: no ';' after the header", {}
    short = lm.group(1) == b"%"
    log = lm.group(2).decode("ascii")
    header = lm.group(3).decode("ascii", "replace").split(",")
    if log not in _MIN_FIELDS:
        return "ignore", f"NovAtel {log}", {}
    body = lm.group(4).decode("ascii", "replace").split(",")
    try:
        if short:
            week, sec, tstat = int(header[0]), float(header[1]), "FINESTEERING"
        else:
            if len(header) < 9:
                raise ValueError(f"a header of {len(header)} fields, not 9 or more")
            week, sec, tstat = int(header[4]), float(header[5]), header[3]
        if not (0 <= week < 10_000 and 0.0 <= sec < _WEEK_S):
            raise ValueError(f"GPS week {week}, seconds {sec} out of range")
        if len(body) < _MIN_FIELDS[log]:
            raise ValueError(f"{len(body)} fields, {_MIN_FIELDS[log]} or more expected")
        vals, why = _body(log, body)
        _check_ranges(vals)
    except (ValueError, IndexError) as e:
        return "reject", f"{log}: {e}", {}
    if tstat == "UNKNOWN" or week <= 0:
        return "ignore", f"NovAtel {log} (receiver time unknown)", {}
    if why:
        return "ignore", f"NovAtel {log} (not used: {why.split(',')[0]})", {}
    return "row", log, {"week": week, "seconds": sec, **vals}


def _nmea_tod_ms(nlog: NmeaLog) -> np.ndarray:
    """UTC time of day of each NMEA epoch [ms] (from its timed sentences; −1 where none)."""
    tod = np.full(len(nlog.epochs), -1, dtype=np.int64)
    for df in nlog.sentences.values():
        if not len(df) or "tod_s" not in df.columns:
            continue
        ep = df["epoch"].to_numpy(float)
        t = df["tod_s"].to_numpy(float)
        ok = np.isfinite(ep) & np.isfinite(t) & (ep >= 0)
        k = ep[ok].astype(np.int64)
        ms = np.round(t[ok] * 1000).astype(np.int64)
        free = tod[k] < 0
        tod[k[free]] = ms[free]
    return tod


def _epochs(
    rows: dict[str, list[dict[str, float]]], nlog: NmeaLog | None = None
) -> tuple[pd.DataFrame, list[str]]:
    """One epoch per GPS (week, seconds) of the logs read, in time order, with what the NMEA
    sentences on the same port add at the same UTC time; and notes (where the heading came from
    when INSPVA gave it, NMEA epochs at other times).
    """
    if not rows:
        if nlog is not None and len(nlog.epochs):
            return nlog.epochs, []  # only the NMEA gave epochs
        return build_epochs({}, np.zeros(0), has_date=True, heading_source="channel"), []
    frames = {k: pd.DataFrame(v) for k, v in rows.items()}
    keys = np.concatenate(
        [
            np.round((f["week"] * _WEEK_S + f["seconds"]).to_numpy(float) * 1000)
            for f in frames.values()
        ]
    )
    order = np.unique(keys)
    n = order.size
    values: dict[str, np.ndarray] = {}

    def put(f: pd.DataFrame, src: str, dst: str) -> np.ndarray:
        """Fill *dst* where it is still NaN; the rows filled."""
        k = np.searchsorted(
            order, np.round((f["week"] * _WEEK_S + f["seconds"]).to_numpy(float) * 1000)
        )
        out = values.setdefault(dst, np.full(n, np.nan))
        v = f[src].to_numpy(float)
        fill = np.isnan(out[k])
        out[k[fill]] = v[fill]
        return k[fill]

    # the log that gave each row's heading (its HEADING_SOURCES code; NaN: none)
    head_src = np.full(n, np.nan)

    for log in ("BESTPOS",):
        if log in frames:
            for c in ("lat_deg", "lon_deg", "alt_m", "n_sats", "fix_quality"):
                put(frames[log], c, c)
    if "BESTVEL" in frames:
        put(frames["BESTVEL"], "speed_mps", "speed_mps")
        put(frames["BESTVEL"], "course_deg", "course_deg")
    has_heading = False
    for log in _HEADINGS:
        if log in frames:
            head_src[put(frames[log], "heading_deg", "heading_deg")] = HEADING_SOURCES.index(log)
            put(frames[log], "heading_acc_deg", "heading_acc_deg")
            has_heading = True
    notes = []
    for log in ("INSPVA", "INSPVAS", "INSPVAX"):
        if log not in frames:
            continue
        f = frames[log]
        if "BESTPOS" not in frames:
            put(f, "ins_lat", "lat_deg")
            put(f, "ins_lon", "lon_deg")
        if "BESTVEL" not in frames:
            put(f, "ins_speed", "speed_mps")
            put(f, "ins_course", "course_deg")
        if not has_heading:
            head_src[put(f, "ins_heading", "heading_deg")] = HEADING_SOURCES.index(log)
            has_heading = True
            notes.append(f"heading: the INS azimuth of {log} (the log has no HEADING/HEADING2)")
    seconds = gps_to_utc(np.floor(order / 1000 / _WEEK_S), np.mod(order / 1000, _WEEK_S))
    src = np.full(n, -1, dtype=np.int64)  # the NMEA epoch joined to each row
    from_nmea = np.zeros(n, dtype=bool)  # rows whose heading the NMEA gave
    yaw_src = None
    values["_heading_src"] = head_src
    if nlog is not None and len(nlog.epochs):
        values, seconds, src, more = _join_nmea(values, seconds, nlog)
        from_nmea = values.pop("_from_nmea_heading").astype(bool)
        notes += more
        if "yaw_rate_rps" in values:
            yaw_src = "ROT"
    head_src = values.pop("_heading_src")
    ep = build_epochs(values, seconds, has_date=True, heading_source="channel",
                      yaw_rate_source=yaw_src)  # fmt: skip
    known = ~np.isnan(head_src) & ep["heading_deg"].notna().to_numpy()
    codes = np.where(known, np.nan_to_num(head_src, nan=-1.0), -1).astype(np.int8)
    ep["heading_source"] = pd.Categorical.from_codes(codes, categories=HEADING_SOURCES)
    if nlog is not None and from_nmea.any():
        hsrc = nlog.epochs["heading_source"].to_numpy(object)
        col = ep["heading_source"].to_numpy(object)
        col[from_nmea] = hsrc[src[from_nmea]]
        ep["heading_source"] = pd.Categorical(col, categories=ep["heading_source"].cat.categories)
    return ep, notes


_FROM_NMEA = ("lat_deg", "lon_deg", "alt_m", "fix_quality", "n_sats", "hdop", "speed_mps",
              "course_deg", "heading_deg", "pitch_deg", "roll_deg")  # fmt: skip


def _join_nmea(
    values: dict[str, np.ndarray], seconds: np.ndarray, nlog: NmeaLog
) -> tuple[dict[str, np.ndarray], np.ndarray, np.ndarray, list[str]]:
    """The NovAtel rows filled from the NMEA epochs at the same UTC time (to the millisecond),
    then the NMEA epochs at other times as rows of their own (their date: the NMEA's own, else
    the NovAtel epochs' day that puts them nearest to one), in time order.

    Returns the values (with ``_from_nmea_heading``: rows whose heading the NMEA gave), the UTC
    seconds, the NMEA epoch of each row (−1: none) and notes.
    """
    ne = nlog.epochs
    n = seconds.size
    tod = _nmea_tod_ms(nlog)
    utc_n = ne["time_utc"]
    abs_n = np.full(len(ne), np.nan)
    known = utc_n.notna().to_numpy()
    if known.any():
        abs_n[known] = (
            (utc_n[known].dt.tz_convert(None) - pd.Timestamp("1970-01-01"))
            .dt.total_seconds()
            .to_numpy()
        )
    mine = np.mod(np.round(seconds * 1000).astype(np.int64), 86_400_000)
    srt = np.argsort(tod, kind="stable")
    k = np.clip(np.searchsorted(tod, mine, sorter=srt), 0, tod.size - 1)
    match = srt[k]
    has = (tod[match] == mine) & (mine >= 0)
    src = np.where(has, match, -1)
    used = np.zeros(len(ne), dtype=bool)
    used[match[has]] = True
    # the NMEA epochs at other times, dated
    rest = np.flatnonzero(~used)
    when = abs_n[rest]
    undated = np.isnan(when) & (tod[rest] >= 0)
    if undated.any():
        srt_s = np.sort(seconds)
        best = np.full(int(undated.sum()), np.nan)
        gap = np.full(best.size, np.inf)
        for day in np.unique(np.floor(seconds / 86400.0)):
            cand = day * 86400.0 + tod[rest[undated]] / 1000.0
            j = np.clip(np.searchsorted(srt_s, cand), 1, max(srt_s.size - 1, 1))
            d = np.minimum(
                np.abs(srt_s[j - 1] - cand), np.abs(srt_s[np.minimum(j, srt_s.size - 1)] - cand)
            )
            better = d < gap
            best[better], gap[better] = cand[better], d[better]
        when[undated] = best
    timed = ~np.isnan(when)
    extra = rest[timed]
    notes = []
    if (~timed).any():
        notes.append(f"{int((~timed).sum())} NMEA epochs not used: no time of day")
    m = n + extra.size
    out: dict[str, np.ndarray] = {}
    for c in set(values) | set(_FROM_NMEA):
        v = np.full(m, np.nan)
        if c in values:
            v[:n] = values[c]
        if c in _FROM_NMEA:
            nv = ne[c].to_numpy(float)
            fill = has & np.isnan(v[:n])
            v[:n][fill] = nv[match[fill]]
            v[n:] = nv[extra]
            if c == "heading_deg":
                out["_from_nmea_heading"] = np.concatenate(
                    [fill & ~np.isnan(v[:n]), ~np.isnan(v[n:])]
                )
        out[c] = v
    src = np.concatenate([src, extra])
    rot = np.zeros(m, dtype=bool)
    rot[src >= 0] = (ne["yaw_rate_source"] == "ROT").to_numpy()[src[src >= 0]]
    if rot.any():  # the receiver's own rate of turn beats the heading's difference
        for c in ("yaw_rate_rps", "rot_deg_per_min"):
            v = np.full(m, np.nan)
            v[rot] = ne[c].to_numpy(float)[src[rot]]
            out[c] = v
    secs = np.concatenate([seconds, when[timed]])
    order = np.argsort(secs, kind="stable")
    out = {c: v[order] for c, v in out.items()}
    nh = int(out["_from_nmea_heading"].sum())
    if nh:
        notes.append(f"heading: NMEA on {nh} epochs (no NovAtel heading at their time)")
    return out, secs[order], src[order], notes


def write_novatel(
    epochs: pd.DataFrame,
    path: str | Path | None,
    *,
    logs: tuple[str, ...] = ("BESTPOS", "BESTVEL", "HEADING2"),
    heading_acc_deg: float = 0.2,
) -> list[str]:
    """Write an epoch table as a NovAtel dual-antenna receiver logs it in ASCII: BESTPOS,
    BESTVEL and HEADING2 per epoch, each with its CRC-32.

    Parameters
    ----------
    epochs : pandas.DataFrame
        ``time_utc``, ``lat_deg``, ``lon_deg``, ``alt_m``, ``speed_mps``, ``course_deg``,
        ``heading_deg``.
    path : str or Path or None
        Output file (CR LF line ends; written atomically, never over a file gripsense did not
        write); None writes nothing.
    logs : tuple of str
        The logs of each epoch, in this order (of ``BESTPOS``, ``BESTVEL``, ``HEADING2``).
    heading_acc_deg : float
        The heading standard deviation the logs state [deg].

    Returns
    -------
    list of str
        The lines, without line ends.
    """
    t = pd.DatetimeIndex(epochs["time_utc"]).tz_convert(None)
    utc = (t - pd.Timestamp("1970-01-01")).total_seconds().to_numpy()
    # GPS time: UTC + the offset in force (the UTC instant + n is past the step's GPS time)
    epoch0 = float(_GPS_EPOCH.astype(np.int64))
    gps_guess = utc - epoch0
    k = np.searchsorted(_LEAP_AT - _LEAP_N, gps_guess, side="right")
    gps = gps_guess + np.where(k > 0, _LEAP_N[np.maximum(k - 1, 0)], 0.0)
    week = np.floor(gps / _WEEK_S).astype(int)
    sec = gps - week * _WEEK_S
    cols = [epochs[c].to_numpy(float) for c in ("lat_deg", "lon_deg", "alt_m", "speed_mps",
                                                "course_deg", "heading_deg")]  # fmt: skip
    out = []

    def line(log: str, w: int, s: float, body: str) -> str:
        msg = f"{log}A,COM1,0,80.0,FINESTEERING,{w},{s:.3f},02000000,b1f6,16809;{body}"
        return f"#{msg}*{crc32(msg.encode('ascii')):08x}"

    for i in range(len(t)):
        la, lo, alt, spd, crs, hdg = (c[i] for c in cols)
        w, s = int(week[i]), float(sec[i])
        body = {
            "BESTPOS": f"SOL_COMPUTED,NARROW_INT,{la:.11f},{lo:.11f},{alt:.4f},-17.0000,WGS84,"
            '0.0100,0.0100,0.0200,"0",1.000,0.000,20,18,18,18,00,06,33,33',
            "BESTVEL": f"SOL_COMPUTED,DOPPLER_VELOCITY,0.150,0.000,{spd:.4f},"
            f"{np.mod(crs, 360.0):.6f},0.0000,0.0",
            "HEADING2": f"SOL_COMPUTED,NARROW_INT,1.000000000,{np.mod(hdg, 360.0):.9f},"
            f'0.000000000,0,{heading_acc_deg:.9f},0.400000000,"R222","AAAA",18,17,17,16,0,01,'
            "0,33",
        }
        out += [line(log, w, s, body[log]) for log in logs]
    if path is not None:  # atomically, never over a file gripsense did not write
        text = "".join(s + "\r\n" for s in out)
        write_file_atomic(path, lambda p: p.write_text(text, encoding="ascii", newline=""))
    return out


def read_novatel_log(src: LogInput) -> NmeaLog:
    """Read a NovAtel ASCII log as :func:`gripsense.io.logs.read_log` hands it over (its
    registry entry).

    Parameters
    ----------
    src : gripsense.io.logs.options.LogInput
        The log's bytes, name and options (``strict``).

    Returns
    -------
    NmeaLog
        Epoch table and record accounting (:func:`parse_novatel`).
    """
    return parse_novatel(src.data, src.name, strict=src.options.strict)
