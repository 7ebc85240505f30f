"""u-blox UBX binary logs (mixed with NMEA on one stream, as receivers send them).

A ZED-F9P moving-base rover gives its heading only in UBX: ``NAV-RELPOSNED`` carries the
heading of the base→rover baseline with its accuracy and validity flags. gripsense reads:

=================  =========================================================================
message            what is read
=================  =========================================================================
NAV-PVT (01 07)    UTC date and time (when valid), fix type, carrier solution, satellites,
                   position, height above MSL, ground speed and its accuracy (``sAcc``),
                   course (``headMot``) — position and speed only with ``gnssFixOK``
NAV-RELPOSNED      true heading of the baseline (``relPosHeading``) and its accuracy — only
(01 3C, v1)        when ``gnssFixOK``, ``relPosValid``, ``relPosHeadingValid`` and the carrier
                   solution is fixed (``carrSoln`` = 2); other frames are counted as ignored
                   with the reason
NAV-ATT (01 05)    roll, pitch and vehicle heading (dead-reckoning receivers); the heading
                   is used where RELPOSNED gives none
=================  =========================================================================

Frames are grouped into epochs by ``iTOW`` (GPS time of week); UTC comes from NAV-PVT (the
offset of UTC from ``iTOW`` includes the leap seconds). Every frame is accounted for: read
(``parsed``), a message gripsense does not use (``ignored``), or rejected: ``bad checksum``
(the Fletcher checksum of the frame does not match), ``truncated`` (the stream ends inside the
frame), ``malformed field`` (a known message with the wrong length), ``bad length`` (a length
field that does not fit what follows: impossible, past the stream's end, or a good frame or
NMEA sentence starts inside the length it claims — the scan resynchronises there, so one
corrupted length costs one frame). The bytes that are not
UBX frames are read as NMEA (:func:`gripsense.io.read_nmea`), and the NMEA epochs fill what
the UBX epochs lack at the same UTC time.

The frame scan is one compiled pass over the bytes and the fields are decoded with vectorised
reads of the frame payloads (``benchmarks/bench_ingest.py`` compares it with pyubx2, which
the tests use as the reference decoder).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd
from numba import njit

from gripsense.io.logs.epoch_table import build_epochs
from gripsense.io.logs.nmea.accounting import IngestReport, RejectedLine
from gripsense.io.logs.nmea.reader import NmeaLog, read_nmea
from gripsense.io.logs.nmea.schema import BAD_CHECKSUM, MALFORMED, REASONS, TRUNCATED
from gripsense.io.logs.options import LogInput

__all__ = [
    "MESSAGES",
    "FrameAccount",
    "account_frames",
    "is_ubx",
    "parse_ubx",
    "read_ubx_log",
    "scan_frames",
    "write_ubx",
    "write_ubx_log",
]

SYNC = b"\xb5\x62"
MAX_PAYLOAD = 4096
"""Longest payload taken as a frame [bytes]; a longer length field means the sync bytes were
data (the messages gripsense reads are at most 92 bytes)."""

MESSAGES = {
    (0x01, 0x07): ("NAV-PVT", (92,)),
    (0x01, 0x3C): ("NAV-RELPOSNED", (64, 40)),
    (0x01, 0x05): ("NAV-ATT", (32,)),
}
"""(class, id) -> name and accepted payload lengths of the messages read."""

_NAMES = {
    0x01: "NAV",
    0x02: "RXM",
    0x04: "INF",
    0x05: "ACK",
    0x06: "CFG",
    0x09: "UPD",
    0x0A: "MON",
    0x0D: "TIM",
    0x10: "ESF",
    0x13: "MGA",
    0x21: "LOG",
    0x27: "SEC",
    0x28: "HNR",
}

# frame status codes of the scan
OK, BAD_CK, CUT, BAD_LEN = 0, 1, 2, 3
BAD_LENGTH = "bad length"
"""Reject reason of a frame whose length field does not fit what follows it (the scan
resynchronises at the next good frame or NMEA sentence)."""


@njit(cache=True, nogil=True)
def _good_frame_at(d, j, max_payload):
    """Whether a UBX frame with a good checksum starts at byte *j*."""
    n = d.size
    if j + 8 > n or d[j] != 0xB5 or d[j + 1] != 0x62:
        return False
    ln = np.int64(d[j + 4]) | (np.int64(d[j + 5]) << 8)
    if ln > max_payload or j + 8 + ln > n:
        return False
    a = np.uint8(0)
    b = np.uint8(0)
    for k in range(j + 2, j + 6 + ln):
        a = np.uint8(a + d[k])
        b = np.uint8(b + a)
    return a == d[j + 6 + ln] and b == d[j + 7 + ln]


@njit(cache=True, nogil=True)
def _sentence_at(d, j):
    """Whether a whole NMEA sentence with a good checksum starts at byte *j* (``$`` or ``!``,
    printable characters, ``*`` and two hex digits within 82 bytes): binary payload bytes
    are never taken for one.
    """
    n = d.size
    if d[j] != 0x24 and d[j] != 0x21:
        return False
    x = np.uint8(0)
    k = j + 1
    while k < n and k - j < 82:
        c = d[k]
        if c == 0x2A:
            if k + 2 >= n:
                return False
            v = np.int64(0)
            for h in (d[k + 1], d[k + 2]):
                if 0x30 <= h <= 0x39:
                    v = v * 16 + (h - 0x30)
                elif 0x41 <= h <= 0x46:
                    v = v * 16 + (h - 0x41 + 10)
                elif 0x61 <= h <= 0x66:
                    v = v * 16 + (h - 0x61 + 10)
                else:
                    return False
            return v == x and k > j + 3
        if c < 0x20 or c > 0x7E:
            return False
        x ^= c
        k += 1
    return False


@njit(cache=True, nogil=True)
def _fits(d, end, max_payload):
    """Whether a frame can end at *end*: the stream ends there, or a sync pair, a good frame or
    a whole NMEA sentence (after line ends) starts there.
    """
    n = d.size
    j = end
    while j < n and (d[j] == 0x0D or d[j] == 0x0A):
        j += 1
    if j >= n:
        return True
    if j == end and j + 1 < n and d[j] == 0xB5 and d[j + 1] == 0x62:
        return True
    return _good_frame_at(d, j, max_payload) or _sentence_at(d, j)


@njit(cache=True, nogil=True)
def _resync(d, i, stop, max_payload, weak):
    """The first byte after the frame header at *i* (before *stop*) where a good UBX frame or
    a whole NMEA sentence starts — or, when *weak*, any sync pair (a damaged frame is then
    rejected on its own, not swallowed); -1 when none does.
    """
    n = d.size
    for j in range(i + 2, min(stop, n)):
        if d[j] == 0xB5:
            if weak and j + 1 < n and d[j + 1] == 0x62:
                return j
            if _good_frame_at(d, j, max_payload):
                return j
        if (d[j] == 0x24 or d[j] == 0x21) and _sentence_at(d, j):
            return j
    return -1


@njit(cache=True, nogil=True)
def _scan(d, max_payload):
    """Find UBX frames: start, payload length and status (OK / BAD_CK / CUT / BAD_LEN) of
    each, and a mask of the bytes that belong to frames (good or rejected).

    A frame whose checksum fails is rejected as a bad length when another frame (a sync pair)
    or a whole NMEA sentence starts inside the length it claims, or when its claimed end is not
    followed by what can follow a frame (:func:`_fits`) and one starts soon after (or its
    length is impossible, over *max_payload*); the scan resumes there: a corrupted length field
    costs one frame, not the frames after it. Otherwise it is a bad checksum, or cut off by the
    stream's end (then only a good frame or sentence inside it says otherwise: a stream may
    stop inside a frame).
    """
    n = d.size
    starts = np.empty(n // 8 + 1, dtype=np.int64)
    ends = np.empty(n // 8 + 1, dtype=np.int64)
    lengths = np.empty(n // 8 + 1, dtype=np.int64)
    status = np.empty(n // 8 + 1, dtype=np.int8)
    mask = np.zeros(n, dtype=np.bool_)
    k = 0
    i = 0
    while i + 1 < n:
        if d[i] != 0xB5 or d[i + 1] != 0x62:
            i += 1
            continue
        if i + 6 > n:  # header cut off
            starts[k] = i
            ends[k] = n
            lengths[k] = -1
            status[k] = CUT
            mask[i:n] = True
            k += 1
            break
        ln = np.int64(d[i + 4]) | (np.int64(d[i + 5]) << 8)
        end = i + 8 + ln
        ok = False
        if ln <= max_payload and end <= n:
            a = np.uint8(0)
            b = np.uint8(0)
            for j in range(i + 2, i + 6 + ln):
                a = np.uint8(a + d[j])
                b = np.uint8(b + a)
            ok = a == d[end - 2] and b == d[end - 1]
        starts[k] = i
        lengths[k] = ln
        if ok:
            status[k] = OK
        else:
            # past the stream's end with a possible length, only a good frame or sentence
            # says the length is wrong (the stream may just stop inside the frame); otherwise
            # a sync pair does too (a damaged frame after it is then rejected on its own)
            weak = not (ln <= max_payload and end > n)
            j = _resync(d, i, min(end, n), max_payload, weak)
            if j >= 0:  # a frame or sentence starts inside it: the length is wrong
                status[k] = BAD_LEN
                end = j
            elif ln <= max_payload and end <= n and _fits(d, end, max_payload):
                status[k] = BAD_CK  # the length fits what follows: the payload is damaged
            else:
                stop = n if ln > max_payload else min(n, end + max_payload + 8)
                j = _resync(d, i, stop, max_payload, weak)
                if j >= 0:
                    status[k] = BAD_LEN
                    end = j
                elif ln > max_payload:  # nothing to resynchronise on: the rest is this frame's
                    status[k] = BAD_LEN
                    end = n
                elif end > n:
                    status[k] = CUT
                    end = n
                else:
                    status[k] = BAD_CK
        ends[k] = end
        mask[i:end] = True
        k += 1
        i = end
    return starts[:k], ends[:k], lengths[:k], status[:k], mask


def scan_frames(data: bytes | np.ndarray) -> pd.DataFrame:
    """The UBX frames of a byte stream.

    Parameters
    ----------
    data : bytes or numpy.ndarray
        The stream.

    Returns
    -------
    pandas.DataFrame
        One row per frame: ``start`` (byte offset), ``cls``, ``id``, ``length`` (payload
        bytes as the length field says; −1 when the header is cut off), ``status`` (0
        checksum good, 1 bad checksum, 2 cut off, 3 bad length) and ``end`` (the byte after
        the frame, or after the bytes a rejected frame spans up to where the scan
        resynchronised); ``attrs["mask"]`` marks the bytes that belong to frames.
    """
    d = np.frombuffer(data, dtype=np.uint8) if isinstance(data, bytes | bytearray) else data
    starts, ends, lengths, status, mask = _scan(d, MAX_PAYLOAD)
    cls = np.where(starts + 2 < d.size, d[np.minimum(starts + 2, d.size - 1)], 0)
    mid = np.where(starts + 3 < d.size, d[np.minimum(starts + 3, d.size - 1)], 0)
    out = pd.DataFrame(
        {"start": starts, "cls": cls, "id": mid, "length": lengths, "status": status, "end": ends}
    )
    out.attrs["mask"] = mask
    return out


def is_ubx(head: bytes) -> bool:
    """Whether the start of a stream holds a UBX frame with a good checksum.

    Parameters
    ----------
    head : bytes
        The first few kilobytes.
    """
    if SYNC not in head[:65536]:
        return False
    fr = scan_frames(head[:65536])
    return bool((fr["status"] == OK).any())


def _u(d: np.ndarray, off: np.ndarray, size: int, signed: bool = False) -> np.ndarray:
    """Little-endian integers of *size* bytes at offsets *off*."""
    v = np.zeros(off.size, dtype=np.int64)
    for b in range(size):
        v |= d[off + b].astype(np.int64) << (8 * b)
    if signed:
        top = np.int64(1) << (8 * size - 1)
        v = np.where(v >= top, v - (top << 1), v)
    return v


def _msg_name(cls: int, mid: int) -> str:
    return f"UBX {_NAMES.get(cls, f'0x{cls:02X}')}-0x{mid:02X}"


def _pvt(d: np.ndarray, p: np.ndarray) -> dict[str, np.ndarray]:
    """Decode NAV-PVT payloads at offsets *p* (u-blox interface description, UBX-NAV-PVT)."""
    itow = _u(d, p, 4)
    year, month, day = _u(d, p + 4, 2), d[p + 6].astype(int), d[p + 7].astype(int)
    hour, minute, sec = d[p + 8].astype(int), d[p + 9].astype(int), d[p + 10].astype(int)
    valid = d[p + 11].astype(int)
    nano = _u(d, p + 16, 4, True)
    fix_type = d[p + 20].astype(int)
    flags = d[p + 21].astype(int)
    ok = (flags & 1).astype(bool) & (fix_type >= 2) & (fix_type != 5)
    carr = (flags >> 6) & 3
    gga = np.where(~ok, 0, np.where(carr == 2, 4, np.where(carr == 1, 5, np.where(
        flags & 2, 2, np.where(fix_type == 1, 6, 1)))))  # fmt: skip
    good_t = ((valid & 3) == 3) & (year >= 1980) & (month >= 1) & (month <= 12) & (day >= 1)
    good_t &= (day <= 31) & (hour < 24) & (minute < 60) & (sec <= 60)
    days = _days_from_civil(year, month, day)
    utc = days * 86400.0 + hour * 3600 + minute * 60 + sec + nano * 1e-9
    utc[~good_t] = np.nan
    nan_unless = np.where(ok, 1.0, np.nan)
    return {
        "itow": itow,
        "utc": utc,
        "fix_quality": gga.astype(float),
        "n_sats": d[p + 23].astype(float),
        "lon_deg": _u(d, p + 24, 4, True) * 1e-7 * nan_unless,
        "lat_deg": _u(d, p + 28, 4, True) * 1e-7 * nan_unless,
        "alt_m": _u(d, p + 36, 4, True) * 1e-3 * nan_unless,
        "speed_mps": _u(d, p + 60, 4, True) * 1e-3 * nan_unless,
        "course_deg": np.mod(_u(d, p + 64, 4, True) * 1e-5, 360.0) * nan_unless,
        "speed_acc_mps": _u(d, p + 68, 4) * 1e-3 * nan_unless,
        "hdop": _u(d, p + 76, 2) * 0.01 * nan_unless,  # pDOP: the nearest UBX has
    }


def _days_from_civil(y: np.ndarray, m: np.ndarray, d: np.ndarray) -> np.ndarray:
    """Days since 1970-01-01 of proleptic Gregorian dates (H. Hinnant's ``days_from_civil``)."""
    y = y - (m <= 2)
    era = np.floor_divide(y, 400)
    yoe = y - era * 400
    doy = (153 * (m + np.where(m > 2, -3, 9)) + 2) // 5 + d - 1
    doe = yoe * 365 + yoe // 4 - yoe // 100 + doy
    return era * 146097 + doe - 719468


def _relposned(d: np.ndarray, p: np.ndarray) -> tuple[dict[str, np.ndarray], np.ndarray]:
    """Decode NAV-RELPOSNED v1 payloads; the second value says why a heading is not used
    (0 used, 1 no fix / relative position invalid, 2 carrier not fixed, 3 heading invalid).
    """
    flags = _u(d, p + 60, 4)
    fix_ok = ((flags & 1) != 0) & ((flags & 4) != 0)
    fixed = ((flags >> 3) & 3) == 2
    hdg_ok = (flags & (1 << 8)) != 0
    why = np.where(~fix_ok, 1, np.where(~fixed, 2, np.where(~hdg_ok, 3, 0)))
    use = np.where(why == 0, 1.0, np.nan)
    return {
        "itow": _u(d, p + 4, 4),
        "heading_deg": np.mod(_u(d, p + 24, 4, True) * 1e-5, 360.0) * use,
        "heading_acc_deg": _u(d, p + 52, 4) * 1e-5 * use,
    }, why


def _att(d: np.ndarray, p: np.ndarray) -> dict[str, np.ndarray]:
    """Decode NAV-ATT payloads (roll, pitch, heading [1e-5 deg])."""
    return {
        "itow": _u(d, p, 4),
        "roll_deg": _u(d, p + 8, 4, True) * 1e-5,
        "pitch_deg": _u(d, p + 12, 4, True) * 1e-5,
        "att_heading_deg": np.mod(_u(d, p + 16, 4, True) * 1e-5, 360.0),
    }


_WHY = {
    1: "UBX NAV-RELPOSNED (no fix or relative position invalid)",
    2: "UBX NAV-RELPOSNED (carrier solution not fixed)",
    3: "UBX NAV-RELPOSNED (heading not valid)",
}
_WEEK_MS = 604_800_000


@dataclass
class FrameAccount:
    """What the UBX frames of a stream count for (:func:`account_frames`).

    Attributes
    ----------
    parsed, ignored, rejected : dict
        Label -> number of frames (``rejected``: every reason of the NMEA schema, 0 included).
    rejects : list of (int, str, str)
        The first 20 rejected frames in stream order: byte offset, reason, detail.
    tables : dict
        Message name -> column -> array of the frames read (``start``: byte offset).
    """

    parsed: dict[str, int]
    ignored: dict[str, int]
    rejected: dict[str, int]
    rejects: list[tuple[int, str, str]]
    tables: dict[str, dict[str, np.ndarray]]


def account_frames(
    d: np.ndarray,
    starts: np.ndarray,
    ends: np.ndarray,
    lengths: np.ndarray,
    status: np.ndarray,
    cls: np.ndarray,
    mid: np.ndarray,
    *,
    at: np.ndarray | None = None,
    strict: bool = False,
    name: str = "<ubx>",
) -> FrameAccount:
    """Count and decode UBX frames found by the scan: read, ignored (with the message name or
    the reason a frame is not used) or rejected (with the reason) — the batch reader and the
    live reader (which keeps the frames of a stream as they arrive) count with this.

    Parameters
    ----------
    d : numpy.ndarray of uint8
        Bytes holding the frames.
    starts, ends, lengths, status : numpy.ndarray
        Per frame: offset in *d*, offset after it, payload length field (−1: header cut off)
        and scan status (``OK``, ``BAD_CK``, ``CUT``, ``BAD_LEN``).
    cls, mid : numpy.ndarray
        Per frame: class and id bytes (as read from the stream).
    at : numpy.ndarray of int64, optional
        Per frame: its byte offset in the stream, for messages and ``start`` (default
        *starts*).
    strict : bool
        Raise :class:`~gripsense.errors.InputError` at the first rejected frame.
    name : str
        Source name, for messages.

    Returns
    -------
    FrameAccount
    """
    from gripsense.errors import InputError

    at = starts if at is None else at
    parsed: dict[str, int] = {}
    ignored: dict[str, int] = {}
    rejected = dict.fromkeys(REASONS, 0)
    bad: list[tuple[int, str, str]] = []
    malformed: list[tuple[int, str, str]] = []

    def reject(into: list, k: int, reason: str, detail: str) -> None:
        start = int(at[k])
        rejected[reason] = rejected.get(reason, 0) + 1
        if strict:
            raise InputError(f"{name}: byte {start}: UBX frame: {reason}: {detail} (strict mode)")
        if len(into) < 20:
            into.append((start, reason, detail))

    for k in np.flatnonzero(status != OK).tolist():
        ln = int(lengths[k])
        what = _msg_name(int(cls[k]), int(mid[k])) if ln >= 0 else "UBX frame"
        if status[k] == BAD_CK:
            reject(bad, k, BAD_CHECKSUM, f"{what}, {ln}-byte payload")
        elif status[k] == BAD_LEN:
            last = int(at[k] + ends[k] - starts[k] - 1)
            reject(bad, k, BAD_LENGTH, f"{what}: its length field says {ln} bytes, which "
                   f"do not fit what follows; bytes {at[k]}–{last} skipped, read on "
                   "from the next frame or sentence")  # fmt: skip
        else:
            reject(bad, k, TRUNCATED, f"{what}: the stream ends inside the frame")
    good = status == OK
    tables: dict[str, dict[str, np.ndarray]] = {}
    why_counts: dict[str, int] = {}
    for (c, i), (mname, accepted) in MESSAGES.items():
        sel = good & (cls == c) & (mid == i)
        if not sel.any():
            continue
        ln_ok = sel & (lengths == accepted[0])
        for k in np.flatnonzero(sel & ~ln_ok).tolist():
            ln = int(lengths[k])
            if mname == "NAV-RELPOSNED" and ln == 40:
                key = "UBX NAV-RELPOSNED v0 (no heading)"
                ignored[key] = ignored.get(key, 0) + 1
                continue
            reject(malformed, k, MALFORMED, f"UBX {mname} with a {ln}-byte payload "
                   f"(expected {accepted[0]})")  # fmt: skip
        if not ln_ok.any():
            continue
        p = starts[ln_ok] + 6
        unused = 0
        if mname == "NAV-PVT":
            cols = _pvt(d, p)
        elif mname == "NAV-RELPOSNED":
            cols, why = _relposned(d, p)
            unused = int((why != 0).sum())
            for code, label in _WHY.items():
                nw = int((why == code).sum())
                if nw:
                    why_counts[label] = nw
        else:
            cols = _att(d, p)
        tables[mname] = {"start": at[ln_ok], **cols}
        if p.size > unused:
            parsed[f"UBX {mname}"] = int(p.size - unused)
    ignored.update(why_counts)
    other = good.copy()
    for c, i in MESSAGES:
        other &= ~((cls == c) & (mid == i))
    if other.any():
        key2 = cls[other].astype(np.int64) * 256 + mid[other]
        for v, nk in zip(*np.unique(key2, return_counts=True), strict=True):
            ignored[_msg_name(int(v) // 256, int(v) % 256)] = int(nk)
    # each list is in stream order: the first 20 of both, in stream order
    rejects = sorted(bad + malformed, key=lambda r: r[0])[:20]
    return FrameAccount(parsed, ignored, rejected, rejects, tables)


def parse_ubx(data: bytes, name: str = "<ubx>", *, strict: bool = False) -> NmeaLog:
    """Read a UBX (or mixed UBX and NMEA) byte stream into the epoch table.

    Parameters
    ----------
    data : bytes
        The stream.
    name : str
        File name, for messages.
    strict : bool
        Raise at the first rejected frame or line instead of counting it.

    Returns
    -------
    NmeaLog
        ``epochs``, ``report`` (lines and frames) and ``sentences`` (the NMEA sentences, and
        per UBX message its decoded rows with the byte offset ``start`` of each frame).
    """
    d = np.frombuffer(data, dtype=np.uint8)
    starts, ends, lengths, status, mask = _scan(d, MAX_PAYLOAD)
    cls = np.where(starts + 2 < d.size, d[np.minimum(starts + 2, max(d.size - 1, 0))], 0)
    mid = np.where(starts + 3 < d.size, d[np.minimum(starts + 3, max(d.size - 1, 0))], 0)
    fr = account_frames(d, starts, ends, lengths, status, cls, mid, strict=strict, name=name)
    parsed, ignored, rejected, rejects, tables = (
        fr.parsed,
        fr.ignored,
        fr.rejected,
        fr.rejects,
        fr.tables,
    )

    # the NMEA part: the bytes outside the frames
    text = d[~mask].tobytes()
    nlog = read_nmea(text, strict=strict, decompress=False) if text.strip() else None
    epochs = _ubx_epochs(tables)
    if nlog is not None and len(nlog.epochs):
        epochs = _merge_nmea(epochs, nlog.epochs)
    rep_n = nlog.report if nlog is not None else None
    first = [RejectedLine(s + 1, r, f"byte {s}: {det}") for s, r, det in rejects]
    if rep_n is not None:
        for kind, v in rep_n.parsed.items():
            parsed[kind] = parsed.get(kind, 0) + v
        for kind, v in rep_n.ignored.items():
            ignored[kind] = ignored.get(kind, 0) + v
        for kind, v in rep_n.rejected.items():
            rejected[kind] = rejected.get(kind, 0) + v
        first += [
            RejectedLine(r.line, r.reason, f"line {r.line} of the NMEA text: {r.detail}")
            for r in rep_n.first_rejects
        ]
    n_frames = int(starts.size)
    n_lines = rep_n.total_lines if rep_n is not None else 0
    has_date = bool(epochs["time_utc"].notna().any()) if len(epochs) else False
    sentences = dict(nlog.sentences) if nlog is not None else {}
    sentences.update({f"UBX {k}": pd.DataFrame(v) for k, v in tables.items()})
    report = IngestReport(
        source=name,
        total_lines=n_frames + n_lines,
        parsed=dict(sorted(parsed.items())),
        ignored=dict(sorted(ignored.items())),
        rejected=rejected,
        first_rejects=first[:20],
        junk_prefix_lines=rep_n.junk_prefix_lines if rep_n is not None else 0,
        n_epochs=len(epochs),
        epochs_without_time=int(epochs["t_s"].isna().sum()),
        has_date=has_date,
        notes=list(rep_n.notes) if rep_n is not None else [],
        format="u-blox UBX" + (" + NMEA 0183" if n_lines else ""),
        unit="lines and frames" if n_lines else "frames",
    )
    return NmeaLog(epochs=epochs, report=report, sentences=sentences)


def _ubx_epochs(tables: dict[str, dict[str, np.ndarray]]) -> pd.DataFrame:
    """One epoch per iTOW of the UBX navigation messages, in stream order."""
    if not tables:
        return build_epochs({}, np.zeros(0), has_date=False, heading_source="RELPOSNED")
    st = np.concatenate([t["start"] for t in tables.values()])
    it = np.concatenate([t["itow"] for t in tables.values()])
    it = it[np.argsort(st, kind="stable")]
    _, first = np.unique(it, return_index=True)
    order = it[np.sort(first)]
    n = order.size
    by_itow = np.argsort(order, kind="stable")
    values: dict[str, np.ndarray] = {}

    def put(t: dict[str, np.ndarray], src: str, dst: str | None = None) -> None:
        k = np.searchsorted(order, t["itow"], sorter=by_itow)
        rows = by_itow[k]
        out = values.setdefault(dst or src, np.full(n, np.nan))
        v = np.asarray(t[src], dtype=float)
        fill = np.isnan(out[rows])
        out[rows[fill]] = v[fill]

    pvt = tables.get("NAV-PVT")
    utc = np.full(n, np.nan)
    if pvt is not None:
        for c in ("fix_quality", "n_sats", "lat_deg", "lon_deg", "alt_m", "speed_mps",
                  "course_deg", "speed_acc_mps", "hdop"):  # fmt: skip
            put(pvt, c)
        put(pvt, "utc", "utc")
        utc = values.pop("utc")
    rel = tables.get("NAV-RELPOSNED")
    if rel is not None:
        put(rel, "heading_deg")
        put(rel, "heading_acc_deg")
    att = tables.get("NAV-ATT")
    hsrc = "RELPOSNED"
    if att is not None:
        put(att, "roll_deg")
        put(att, "pitch_deg")
        if rel is None:
            put(att, "att_heading_deg", "heading_deg")
            hsrc = "NAV-ATT"
    # UTC of every epoch: iTOW + the UTC−GPS offset that NAV-PVT shows (leap seconds included)
    has_date = bool(np.isfinite(utc).any())
    if has_date:
        off = utc - order / 1000.0
        off0 = float(np.nanmedian(off))
        seconds = np.where(np.isfinite(utc), utc, order / 1000.0 + off0)
    else:
        seconds = order / 1000.0
    # a week rollover of iTOW inside the log
    back = np.concatenate([[0], np.cumsum(np.diff(order) < -_WEEK_MS // 2)])
    if not has_date:
        seconds = seconds + back * (_WEEK_MS / 1000.0)
    ep = build_epochs(values, seconds, has_date=has_date, heading_source=hsrc)
    return ep


def _merge_nmea(ubx: pd.DataFrame, nmea: pd.DataFrame) -> pd.DataFrame:
    """Fill the UBX epochs' missing values from NMEA epochs at the same UTC time (to the
    millisecond), and add the NMEA epochs at other times.
    """
    if not len(ubx):
        return nmea
    if not ubx["time_utc"].notna().any() or not nmea["time_utc"].notna().any():
        return ubx
    ms = np.iinfo(np.int64).min
    key_u = _ms(ubx["time_utc"])
    key_n = _ms(nmea["time_utc"])
    srt = np.argsort(key_n, kind="stable")
    k = np.clip(np.searchsorted(key_n, key_u, sorter=srt), 0, key_n.size - 1)
    match = srt[k]
    has = (key_n[match] == key_u) & (key_u != ms)
    rows = match[has]
    # a receiver's own rate of turn (NMEA ROT) beats the rate differenced from the heading
    rot = np.zeros(len(ubx), dtype=bool)
    n_src = nmea["yaw_rate_source"].to_numpy(object)
    rot[has] = (n_src[rows] == "ROT") & (ubx["yaw_rate_source"].to_numpy(object)[has] != "ROT")
    cols: dict[str, object] = {}
    for c in ubx.columns:
        col = ubx[c]
        if c in ("time_utc", "t_s") or c not in nmea.columns:
            cols[c] = col
            continue
        categorical = isinstance(col.dtype, pd.CategoricalDtype)
        vals = np.array(col.to_numpy(object if categorical else float), copy=True)
        fill = pd.isna(vals) & has
        if c in ("yaw_rate_rps", "yaw_rate_source"):
            fill |= rot
        if fill.any():
            src = nmea[c].to_numpy(object if categorical else float)
            vals[fill] = src[match[fill]]
        cols[c] = pd.Categorical(vals, categories=col.cat.categories) if categorical else vals
    out = pd.DataFrame(cols)
    used = np.zeros(len(nmea), dtype=bool)
    used[rows] = True
    rest = nmea[~used & nmea["time_utc"].notna().to_numpy()]
    if len(rest):
        out = pd.concat([out, rest], ignore_index=True)
        out = out.sort_values("time_utc", kind="stable").reset_index(drop=True)
        t = out["time_utc"]
        out["t_s"] = (t - t.dropna().iloc[0]).dt.total_seconds()
    return out


def _ms(t: pd.Series) -> np.ndarray:
    """Milliseconds since 1970 of a UTC time column (NaT: the int64 minimum)."""
    v = t.dt.tz_convert("UTC").dt.tz_localize(None).to_numpy("M8[ns]").view(np.int64)
    out = np.where(v == np.iinfo(np.int64).min, v, np.round(v / 1e6).astype(np.int64))
    return out


def write_ubx(
    epochs: pd.DataFrame,
    path: str | Path,
    *,
    nmea_lines: list[str] | None = None,
    heading_acc_deg: float = 0.2,
) -> None:
    """Write an epoch table as a u-blox moving-base rover would send it (NAV-PVT and
    NAV-RELPOSNED per epoch, encoded with pyubx2), optionally interleaved with NMEA lines.

    Parameters
    ----------
    epochs : pandas.DataFrame
        ``time_utc``, ``lat_deg``, ``lon_deg``, ``alt_m``, ``speed_mps``, ``course_deg``,
        ``heading_deg``.
    path : str or Path
        Output file.
    nmea_lines : list of str, optional
        NMEA sentences written after each epoch's frames, in equal shares per epoch.
    heading_acc_deg : float
        The heading accuracy the frames state [deg].
    """
    from gripsense.io.logs.formats import require

    pyubx2 = require("pyubx2", "writing UBX")
    t = pd.DatetimeIndex(epochs["time_utc"])
    gps = (t.tz_convert(None) - pd.Timestamp("1980-01-06")).total_seconds().to_numpy() + 18.0
    itow = np.round(np.mod(gps, 604800.0) * 1000).astype(np.int64)
    lat = epochs["lat_deg"].to_numpy(float)
    lon = epochs["lon_deg"].to_numpy(float)
    alt = epochs["alt_m"].to_numpy(float)
    spd = epochs["speed_mps"].to_numpy(float)
    crs = epochs["course_deg"].to_numpy(float)
    hdg = np.mod(epochs["heading_deg"].to_numpy(float), 360.0)
    per = (len(nmea_lines) // len(t)) if nmea_lines and len(t) else 0
    out = bytearray()
    for k, when in enumerate(t):
        ns = round(when.microsecond * 1e3)
        whole = when.replace(microsecond=0)
        pvt = pyubx2.UBXMessage(
            "NAV", "NAV-PVT", pyubx2.GET, iTOW=int(itow[k]), year=whole.year, month=whole.month,
            day=whole.day, hour=whole.hour, min=whole.minute, second=whole.second, validDate=1,
            validTime=1, fullyResolved=1, tAcc=20, nano=ns, fixType=3, gnssFixOk=1, diffSoln=1,
            carrSoln=2, numSV=14, lon=float(lon[k]), lat=float(lat[k]),
            height=round(alt[k] * 1000 + 30000), hMSL=round(alt[k] * 1000), hAcc=14,
            vAcc=20, velN=round(spd[k] * np.cos(np.deg2rad(crs[k])) * 1000),
            velE=round(spd[k] * np.sin(np.deg2rad(crs[k])) * 1000), velD=0,
            gSpeed=round(spd[k] * 1000), headMot=float(crs[k]), sAcc=50, headAcc=0.5,
            pDOP=1.2,
        )  # fmt: skip
        rel = pyubx2.UBXMessage(
            "NAV", "NAV-RELPOSNED", pyubx2.GET, version=1, iTOW=int(itow[k]),
            relPosN=round(100 * np.cos(np.deg2rad(hdg[k]))),
            relPosE=round(100 * np.sin(np.deg2rad(hdg[k]))), relPosLength=100,
            relPosHeading=float(hdg[k]), accHeading=heading_acc_deg, gnssFixOK=1, diffSoln=1,
            relPosValid=1, carrSoln=2, isMoving=1, relPosHeadingValid=1,
        )  # fmt: skip
        out += pvt.serialize() + rel.serialize()
        if per and nmea_lines is not None:
            out += "".join(s + "\r\n" for s in nmea_lines[k * per : (k + 1) * per]).encode()
    Path(path).write_bytes(bytes(out))


def read_ubx_log(src: LogInput) -> NmeaLog:
    """Read a UBX log as :func:`gripsense.io.logs.read_log` hands it over (its registry entry).

    Parameters
    ----------
    src : gripsense.io.logs.options.LogInput
        The log's bytes, name and options (``strict``).

    Returns
    -------
    NmeaLog
        Epoch table and frame accounting (:func:`parse_ubx`).
    """
    return parse_ubx(src.data, src.name, strict=src.options.strict)


def write_ubx_log(
    epochs: pd.DataFrame,
    path: Path,
    *,
    nmea_lines: list[str] | None = None,
    steer: pd.DataFrame | None = None,
) -> str | None:
    """Write a drive as UBX for :func:`gripsense.io.logs.write_log` (:func:`write_ubx`; no
    steering channel: UBX carries none).

    Parameters
    ----------
    epochs : pandas.DataFrame
        The drive's epoch table.
    path : Path
        Output file.
    nmea_lines : list of str, optional
        NMEA sentences interleaved as a receiver sends them.
    steer : pandas.DataFrame, optional
        Unused.

    Returns
    -------
    None
        No ``--columns`` are needed to read it back.
    """
    write_ubx(epochs, path, nmea_lines=nmea_lines)
    return None
