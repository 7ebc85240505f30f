"""RTCM 3 frames and Ashtech binary records between NMEA sentences (receivers that interleave
their corrections or raw data).

An RTCM 3 frame (RTCM 10403.3, §4) is the preamble ``0xD3``, 6 reserved zero bits, a 10-bit
payload length *L* (at most 1023), *L* payload bytes (the first 12 bits: the message number)
and a 24-bit CRC (CRC-24Q, polynomial ``0x1864CFB``, over preamble, length and payload). The
bytes of such a frame are binary — they hold line ends and ``$`` by chance — so they are cut
out of the stream before its lines are read:

* a frame whose CRC checks is counted as one unit, ignored under ``RTCM3 <message number>``;
* a frame whose structure fits (reserved bits zero, the stream resumes right after it with a
  sentence start or a good frame, and no line inside it starts a sentence) but whose CRC does
  not is counted as rejected (*bad checksum*);
* any other byte stays in the text and is read as NMEA (where it is *not NMEA*, as before).

Ashtech binary records (``$PASHR,MCA,`` + a fixed-length binary structure + CR LF;
:mod:`gripsense.io.logs.nmea.ashtech`) are found by the same scan and follow the same rules: a
good checksum is one unit, ignored under ``Ashtech binary <id>``; a structure whose CR LF is
in place but whose checksum fails, followed by a sentence, is rejected (*bad checksum*).

Pure NMEA holds no ``0xD3`` byte and no ``$PASHR,``, so the scan costs two ``bytes.find``
there.
"""

from __future__ import annotations

import re
from dataclasses import dataclass

import numpy as np
from numba import njit

from gripsense.io.logs.nmea.ashtech import (
    ASHTECH_IDS,
    HEADER,
    HEADER_LEN,
    ashtech_label,
    ashtech_size,
    checksum_ok,
    header_at,
    record_end,
)

__all__ = [
    "RtcmFrames",
    "RtcmStream",
    "binary_notes",
    "crc24q",
    "first_ashtech_header",
    "frame_detail",
    "split_rtcm",
]

PREAMBLE = 0xD3
_POLY = 0x1864CFB


def _table() -> np.ndarray:
    t = np.zeros(256, dtype=np.uint32)
    for i in range(256):
        c = i << 16
        for _ in range(8):
            c <<= 1
            if c & 0x1000000:
                c ^= _POLY
        t[i] = c & 0xFFFFFF
    return t


_CRC_TABLE = _table()


@njit(cache=True, nogil=True, inline="always")
def _crc(buf, a, b, table):
    c = np.uint32(0)
    for i in range(a, b):
        c = ((c << np.uint32(8)) & np.uint32(0xFFFFFF)) ^ table[
            ((c >> np.uint32(16)) ^ buf[i]) & 0xFF
        ]
    return c


def crc24q(data: bytes) -> int:
    """CRC-24Q of *data* (RTCM 10403.3 §4.2) [-]."""
    return int(_crc(np.frombuffer(data, dtype=np.uint8), 0, len(data), _CRC_TABLE))


@njit(cache=True, nogil=True, inline="always")
def _sentence_at(buf, i):
    """Whether an NMEA sentence seems to start at byte *i*: ``$`` or ``!`` and three upper-case
    letters or digits.
    """
    if i + 4 > buf.size or not (buf[i] == 36 or buf[i] == 33):
        return False
    for j in range(i + 1, i + 4):
        b = buf[j]
        if not ((48 <= b <= 57) or (65 <= b <= 90)):
            return False
    return True


@njit(cache=True, nogil=True)
def _good_at(buf, i, table):
    """Whether a frame with a good CRC starts at byte *i*."""
    n = buf.size
    if i + 6 > n or buf[i] != 0xD3 or (buf[i + 1] & 0xFC) != 0:
        return False
    e = i + 6 + (((buf[i + 1] & 3) << 8) | buf[i + 2])
    if e > n:
        return False
    want = (np.uint32(buf[e - 3]) << 16) | (np.uint32(buf[e - 2]) << 8) | np.uint32(buf[e - 1])
    return _crc(buf, i, e - 3, table) == want


@njit(cache=True, nogil=True)
def _good_undecided(buf, i):
    """Whether the bytes that tell if a good frame starts at *i* have not all arrived."""
    n = buf.size
    if i >= n:
        return True
    if buf[i] != 0xD3:
        return False
    if i + 2 > n:
        return True
    if (buf[i + 1] & 0xFC) != 0:
        return False
    if i + 3 > n:
        return True
    return i + 6 + (((buf[i + 1] & 3) << 8) | buf[i + 2]) > n


@njit(cache=True, nogil=True)
def _resumes(buf, e, table, final):
    """After a damaged frame or record ending at byte *e*: 1 the stream resumes there with a
    sentence or a good frame, 0 it does not, -1 undecided (bytes not yet arrived).
    """
    n = buf.size
    if not final and (e + 4 > n or (not _sentence_at(buf, e) and _good_undecided(buf, e))):
        return -1
    if e >= n or not (_sentence_at(buf, e) or _good_at(buf, e, table)):
        return 0
    return 1


@njit(cache=True, nogil=True)
def _starts_inside(buf, a, b):
    r"""Whether a line inside bytes ``a:b`` starts a sentence (``\n`` then ``$`` or ``!``)."""
    for j in range(a, b):
        if buf[j] == 10 and (buf[j + 1] == 36 or buf[j + 1] == 33):
            return True
    return False


@njit(cache=True, nogil=True)
def _scan_upto(buf, table, start, end, good, kind, final):
    """Frames and Ashtech binary records from the first candidate on: writes
    ``start``/``end`` (byte offsets), ``good`` (CRC or checksum checks) and ``kind`` (-1: an
    RTCM 3 frame, else the Ashtech type code); returns their number and the offset from which
    the bytes are undecided (``buf.size`` when *final*: the end of *buf* is the end of the
    stream; else the first byte whose reading needs bytes not yet arrived — a scan resumed
    there with more bytes decides every byte as one scan over the whole stream does).
    """
    n = buf.size
    k = 0
    i = 0
    while i < n:
        b0 = buf[i]
        if b0 == 0xD3:
            if i + 6 > n:
                if not final:
                    return k, i
                i += 1
                continue
            if (buf[i + 1] & 0xFC) != 0:
                i += 1
                continue
            ln = ((buf[i + 1] & 3) << 8) | buf[i + 2]
            e = i + 6 + ln
            if e > n:
                if not final:
                    return k, i
                i += 1
                continue
            want = (
                (np.uint32(buf[e - 3]) << 16) | (np.uint32(buf[e - 2]) << 8) | np.uint32(buf[e - 1])
            )
            ok = _crc(buf, i, e - 3, table) == want
            code = -1
            body = i + 3
        elif b0 == 36:  # "$": an Ashtech binary record?
            code = header_at(buf, i)
            if code == -2:
                if not final:
                    return k, i
                i += 1
                continue
            if code < 0:
                i += 1
                continue
            e = record_end(code, i)
            if e > n:
                if not final:
                    return k, i
                i += 1
                continue
            if buf[e - 2] != 13 or buf[e - 1] != 10:
                i += 1
                continue
            ok = checksum_ok(buf, code, i)
            body = i + 11
        else:
            i += 1
            continue
        if not ok:
            # damaged only where the stream resumes right after it with a sentence or a frame
            # and no line inside it starts a sentence (else these are other bytes)
            r = _resumes(buf, e, table, final)
            if r < 0:
                return k, i
            if r == 0 or _starts_inside(buf, body, e - 4):
                i += 1
                continue
        start[k] = i
        end[k] = e
        good[k] = ok
        kind[k] = code
        k += 1
        i = e
    return k, n


@dataclass
class RtcmFrames:
    """RTCM 3 frames found in a byte stream.

    Attributes
    ----------
    start, end : numpy.ndarray of int64
        Byte offsets of each frame (end exclusive).
    good : numpy.ndarray of bool
        Whether its CRC-24Q checks.
    message : numpy.ndarray of int64
        RTCM 3: message number (first 12 payload bits; -1 for an empty payload); Ashtech: the
        type code (:data:`~gripsense.io.logs.nmea.ashtech.ASHTECH_IDS`).
    ashtech : numpy.ndarray of bool
        Whether it is an Ashtech binary record (else an RTCM 3 frame).
    """

    start: np.ndarray
    end: np.ndarray
    good: np.ndarray
    message: np.ndarray
    ashtech: np.ndarray

    @property
    def size(self) -> int:
        """Number of frames and records."""
        return int(self.start.size)

    @property
    def n_ashtech(self) -> int:
        """Number of Ashtech binary records."""
        return int(self.ashtech.sum())

    def label(self, k: int) -> str:
        """What frame *k* is in the report: ``RTCM3 1005``, ``RTCM3 (empty)``,
        ``Ashtech binary MCA``.
        """
        m = int(self.message[k])
        if self.ashtech[k]:
            return ashtech_label(m)
        return f"RTCM3 {m}" if m >= 0 else "RTCM3 (empty)"

    def ignored_counts(self) -> dict[str, int]:
        """Good frames and records per :meth:`label` (the report's *ignored* entries)."""
        out: dict[str, int] = {}
        for k in np.flatnonzero(self.good).tolist():
            lab = self.label(k)
            out[lab] = out.get(lab, 0) + 1
        return out

    def text_to_input(self, pos: np.ndarray) -> np.ndarray:
        """Byte offsets in the text without the frames -> offsets in the input."""
        removed = np.concatenate([[0], np.cumsum(self.end - self.start)])
        text_at = self.start - removed[:-1]  # where each frame was cut, in text offsets
        return pos + removed[np.searchsorted(text_at, pos, side="right")]


_ASHTECH_HEADER = re.compile(re.escape(HEADER) + b"(?:" + "|".join(ASHTECH_IDS).encode() + b"),")


def first_ashtech_header(data: bytes, end: int | None = None) -> int:
    """Offset of the first Ashtech binary header (``$PASHR,MCA,`` …) in ``data[:end]``, -1 if
    none (one pass over those bytes).
    """
    a = data.find(HEADER, 0, end)  # ASCII $PASHR sentences are common: look for an id after it
    if a < 0:
        return -1
    m = _ASHTECH_HEADER.search(data, a, len(data) if end is None else end)
    return -1 if m is None else m.start()


def _split(data: bytes, final: bool, ashtech: bool = True) -> tuple[bytes, RtcmFrames | None, int]:
    """The frames and records of *data* cut out up to the first undecided byte (see
    :func:`_scan_upto`): the text before it, the frames and that offset. Without *ashtech*
    the scan starts at the first RTCM 3 preamble only (records after it are still cut; the
    batch reader looks for records before it only when a line is rejected).
    """
    found = [data.find(b"\xd3")]
    if ashtech:
        found.append(first_ashtech_header(data))
    found = [j for j in found if j >= 0]
    if not final:  # a header cut by the end of this piece
        j = data.find(b"$", max(len(data) - HEADER_LEN, 0))
        while j >= 0 and not HEADER.startswith(data[j : j + 7]):
            j = data.find(b"$", j + 1)
        if j >= 0:
            found.append(j)
    if not found:
        return data, None, len(data)
    first = min(found)
    buf = np.frombuffer(data, dtype=np.uint8)
    cap = (buf.size - first) // 6 + 1
    start = np.empty(cap, dtype=np.int64)
    end = np.empty(cap, dtype=np.int64)
    good = np.empty(cap, dtype=np.bool_)
    kind = np.empty(cap, dtype=np.int64)
    k, stop = _scan_upto(buf[first:], _CRC_TABLE, start, end, good, kind, final)
    k, stop = int(k), int(stop) + first
    if k == 0:
        return data[:stop], None, stop
    start, end, good, kind = start[:k] + first, end[:k] + first, good[:k], kind[:k]
    msg = np.where(
        kind >= 0,
        kind,
        np.where(
            end - start > 7,
            (buf[np.minimum(start + 3, buf.size - 1)].astype(np.int64) << 4)
            | (buf[np.minimum(start + 4, buf.size - 1)].astype(np.int64) >> 4),
            -1,
        ),
    )
    d = np.zeros(stop + 1, dtype=np.int64)
    np.add.at(d, start, 1)
    np.add.at(d, end, -1)
    keep = np.cumsum(d[:-1]) == 0
    return buf[:stop][keep].tobytes(), RtcmFrames(start, end, good, msg, kind >= 0), stop


def frame_detail(frames: RtcmFrames, k: int) -> str:
    """The words a reject gives a damaged RTCM3 frame (batch and live say the same).

    Parameters
    ----------
    frames : RtcmFrames
        Frames found in a stream (:func:`split_rtcm`, :class:`RtcmStream`).
    k : int
        Index of the frame [-].

    Returns
    -------
    str
        E.g. ``RTCM3 frame (message 1005, 19-byte payload): its CRC-24Q does not match``.
    """
    m = int(frames.message[k])
    if frames.ashtech[k]:
        return (
            f"Ashtech binary {ASHTECH_IDS[m]} record ({ashtech_size(m)}-byte structure): its "
            "checksum does not match"
        )
    what = f"message {m}, " if m >= 0 else ""
    n = int(frames.end[k] - frames.start[k] - 6)
    return f"RTCM3 frame ({what}{n}-byte payload): its CRC-24Q does not match"


def binary_notes(frames_total: int, ashtech: int) -> list[str]:
    """The report's notes on the binary units cut out of an NMEA stream (batch and live say
    the same).

    Parameters
    ----------
    frames_total : int
        RTCM 3 frames and Ashtech binary records cut out [-].
    ashtech : int
        Of which Ashtech binary records [-].

    Returns
    -------
    list of str
        One note per kind present.
    """
    out = []
    rtcm = frames_total - ashtech
    if rtcm:
        out.append(
            f"{rtcm} RTCM3 frames between the sentences (the receiver's corrections), "
            "each counted as one unit"
        )
    if ashtech:
        out.append(
            f"{ashtech} Ashtech binary records ($PASHR,MCA/PBN/…: raw measurements, positions, "
            "ephemerides) between the sentences, each counted as one unit, not used"
        )
    return out


def split_rtcm(data: bytes, ashtech: bool = True) -> tuple[bytes, RtcmFrames | None]:
    """Cut the RTCM 3 frames out of a byte stream.

    Parameters
    ----------
    data : bytes
        The stream.
    ashtech : bool
        Look for Ashtech binary records before the first RTCM 3 preamble too (one more pass
        over those bytes; records after it are always cut).

    Returns
    -------
    text : bytes
        The stream without the frames (*data* itself when it holds none).
    frames : RtcmFrames or None
        The frames cut out (None: none).
    """
    text, frames, _ = _split(data, final=True, ashtech=ashtech)
    return text, frames


class RtcmStream:
    """:func:`split_rtcm` on a stream that arrives in pieces (a receiver's socket or serial
    port): each :meth:`feed` returns the text and the frames decided so far and keeps the bytes
    whose reading needs more of the stream (a frame cut across two reads, at most two frames'
    bytes), so the frames and the text equal :func:`split_rtcm` on the whole stream however it
    is cut.

    Frame offsets are in the whole stream; per frame of the last :meth:`feed`, :attr:`line`
    is the 0-based line of the stream its first byte is on and :attr:`inner_newlines` the
    line ends among its bytes.
    """

    def __init__(self) -> None:
        self._held = b""
        self._offset = 0  # offset in the stream of the first held byte
        self._newlines = 0  # line ends in the stream before the first held byte
        self.line = np.zeros(0, dtype=np.int64)
        self.inner_newlines = np.zeros(0, dtype=np.int64)

    def feed(self, data: bytes, final: bool = False) -> tuple[bytes, RtcmFrames | None]:
        """Add bytes; return the text and the frames decided so far.

        Parameters
        ----------
        data : bytes
            The next bytes of the stream.
        final : bool
            The stream ends after *data*: every byte is decided.

        Returns
        -------
        text : bytes
            The stream's bytes decided by this call, without the frames.
        frames : RtcmFrames or None
            The frames completed by this call, offsets in the whole stream (None: none).
        """
        buf = self._held + data if self._held else data
        text, frames, stop = _split(buf, final)
        self._held = buf[stop:]
        if frames is not None:
            nl = np.flatnonzero(np.frombuffer(buf, dtype=np.uint8)[:stop] == 10)
            at = np.searchsorted(nl, frames.start, side="left")
            self.line = self._newlines + at
            self.inner_newlines = np.searchsorted(nl, frames.end, side="left") - at
            frames.start += self._offset
            frames.end += self._offset
        else:
            self.line = self.inner_newlines = np.zeros(0, dtype=np.int64)
        self._newlines += buf.count(b"\n", 0, stop)
        self._offset += stop
        return text, frames

    @property
    def held(self) -> int:
        """Bytes kept until more of the stream arrives [bytes]."""
        return len(self._held)
