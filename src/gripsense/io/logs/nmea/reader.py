"""Batch ingest of GNSS-compass NMEA logs: :func:`read_nmea` -> :class:`NmeaLog`.

Conventions of the epoch table (one row per receiver time instant; see
:mod:`gripsense.io.logs.nmea.epochs` for the grouping rule):

=================  ==========================================================================
column             meaning
=================  ==========================================================================
time_utc           UTC time (tz-aware); NaT when the epoch has no time or the log no date
t_s                seconds from the first epoch with a time [s]
lat_deg, lon_deg   WGS-84 latitude, longitude [deg], north and east positive
alt_m              altitude above mean sea level (GGA, else GNS) [m]
fix_quality        GGA fix quality (0 none, 1 GPS, 2 DGPS, 4 RTK fixed, 5 RTK float, ...);
                   else GNS's or GLL's mode letter on that scale (A 1, D 2, R 4, F 5, ...)
n_sats, hdop       satellites used, horizontal dilution of precision (GGA, else GNS)
speed_mps          speed over ground [m/s]
course_deg         course over ground, clockwise from true north [deg]
heading_deg        true heading, clockwise from true north [deg] (HDT, THS and the proprietary
                   attitude sentences: PSAT,HPR, PASHR, PASHR,HPR, PTNL,AVR, PSSN,HRP,
                   PSTI,036, PFEC,GPatt)
heading_source     which sentence gave the heading: ``HPR``, ``PASHR``, ``AVR``, ``PSSN``,
                   ``PSTI``, ``GPatt``, ``THS``, ``HDT``
pitch_deg          pitch [deg] as sent by the receiver (the proprietary attitude sentences)
roll_deg           roll [deg] as sent by the receiver (the proprietary attitude sentences)
rot_deg_per_min    rate of turn as NMEA sends it: [deg/min], positive = turning to starboard
yaw_rate_rps       ISO 8855 yaw rate [rad/s], positive counter-clockwise seen from above:
                   -ROT·π/10800 when ROT is present, else -d(heading)/dt
yaw_rate_source    ``ROT`` or ``heading``
=================  ==========================================================================

Missing values are NaN (``<NA>`` in the two source columns), never 0. Numeric columns are
float64 (also ``fix_quality`` and ``n_sats``, so that missing stays NaN).
"""

from __future__ import annotations

import os
import re
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import IO

import numpy as np
import pandas as pd

from gripsense.errors import InputError
from gripsense.io.logs.nmea import schema as S
from gripsense.io.logs.nmea.accounting import IngestReport, RejectedLine
from gripsense.io.logs.nmea.ashtech import ASHTECH_IDS
from gripsense.io.logs.nmea.decode import decode_all
from gripsense.io.logs.nmea.epochs import assemble_epochs
from gripsense.io.logs.nmea.fast import tokenize_fast
from gripsense.io.logs.nmea.kernels import count_lines
from gripsense.io.logs.nmea.reference import classify_line, tokenize_reference
from gripsense.io.logs.nmea.rtcm import (
    RtcmFrames,
    binary_notes,
    first_ashtech_header,
    frame_detail,
    split_rtcm,
)
from gripsense.io.logs.nmea.tokens import IGNORED, PARSED, REJECTED, Tokens, lines_at
from gripsense.io.text import MAX_BYTES, MAX_LINES, InputStream, ReadInput

__all__ = ["MAX_BYTES", "MAX_LINES", "NmeaLog", "read_log_bytes", "read_nmea"]

N_FIRST_REJECTS = 20
_ENGINES: dict[str, Callable[[bytes], Tokens | None]] = {
    "fast": tokenize_fast,
    "reference": tokenize_reference,
}

NmeaSource = str | os.PathLike | bytes | list | IO | ReadInput


@dataclass
class NmeaLog:
    """An ingested NMEA log.

    Attributes
    ----------
    epochs : pandas.DataFrame
        One row per receiver time instant (columns in the module documentation).
    report : IngestReport
        Line accounting.
    sentences : dict
        Sentence type -> DataFrame of the decoded sentences, with ``line`` (1-based line number)
        and ``epoch`` (row of :attr:`epochs`) — to trace any value back to its input line.
    """

    epochs: pd.DataFrame
    report: IngestReport
    sentences: dict[str, pd.DataFrame]


def _read_source(
    source: NmeaSource, max_bytes: int, max_lines: int | None = None, decompress: bool = True
) -> ReadInput:
    """Turn any accepted source into bytes and a display name, read once and bounded
    (:class:`~gripsense.io.text.InputStream`).
    """
    if isinstance(source, ReadInput):
        return source
    if isinstance(source, str | os.PathLike | bytes | bytearray | memoryview):
        what = (
            "file; give the path of an NMEA log" if isinstance(source, str | os.PathLike) else "log"
        )
        src = InputStream(source, what, decompress=decompress)
        return src.read(max_bytes, max_lines)
    if isinstance(source, list | tuple):
        out = []
        for i, ln in enumerate(source):
            if isinstance(ln, str):
                ln = ln.encode("utf-8", "surrogateescape")
            elif not isinstance(ln, bytes | bytearray):
                raise InputError(
                    f"<lines>: item {i} is {type(ln).__name__}; give str or bytes lines"
                )
            out.append(bytes(ln).rstrip(b"\r\n"))
        return ReadInput(b"\n".join(out) + (b"\n" if out else b""), "<lines>")
    if hasattr(source, "read"):
        return InputStream(source, "log", decompress=decompress).read(max_bytes, max_lines)
    raise InputError(
        f"read_nmea: source of type {type(source).__name__} is not supported; give a path, a list "
        "of lines or a file object"
    )


def read_log_bytes(
    path: str | os.PathLike, *, max_bytes: int = MAX_BYTES
) -> tuple[bytes, list[str]]:
    """The bytes of a log file, decompressed when it is gzip (detected from its content).

    Parameters
    ----------
    path : str or Path
        Log file (a regular file or a pipe, read once).
    max_bytes : int
        Largest decompressed size kept [bytes] (beyond it, the lines of a file are counted
        and said in the notes; a pipe is an error).

    Returns
    -------
    data : bytes
        The log's bytes.
    notes : list of str
        What happened on the way (a cut-off gzip stream, the size limit).
    """
    inp = InputStream(Path(path), "log").read(max_bytes)
    return inp.data, list(inp.notes)


def _cap_lines(inp: ReadInput, max_lines: int) -> None:
    """Keep the first *max_lines* lines; count the rest."""
    data = inp.data
    if len(data) <= max_lines:  # every line has at least one byte
        return
    n = count_lines(np.frombuffer(data, dtype=np.uint8))
    if n <= max_lines:
        return
    cut = -1
    for _ in range(max_lines):
        cut = data.index(b"\n", cut + 1)
    inp.data = data[: cut + 1]
    inp.extra_lines += n - max_lines
    inp.notes = [*(inp.notes or []), f"more than {max_lines} lines: the rest counted, not read"]


_CR_SENTENCE = re.compile(rb"[$!][A-Z0-9]{3,8},[^\r]{0,100}\*[0-9A-Fa-f]{2}\r")


def _cr_lines(data: bytes) -> bool:
    """Whether a buffer without any LF ends its lines with CR alone: at least two sentences
    with a checksum end with CR.
    """
    if b"\r" not in data:
        return False
    it = _CR_SENTENCE.finditer(data)
    return next(it, None) is not None and next(it, None) is not None


def _without_checksums(tok) -> bool:
    """Whether no sentence of a tokenized log has a checksum while some lack one: nothing
    parsed or ignored but blank lines and comments, nothing rejected for its checksum's value
    or form, and at least two *missing checksum* (one line alone is no evidence).
    """
    if not tok.n_lines:
        return False
    rejected = tok.counts(REJECTED)
    if rejected.get(S.MISSING_CHECKSUM, 0) < 2 or rejected.get(S.BAD_CHECKSUM):
        return False
    if tok.counts(PARSED):
        return False
    return set(tok.counts(IGNORED)) <= {S.BLANK, S.COMMENT}


def _tokenize(inp: ReadInput, original: bytes, engine: str, max_lines: int):
    """Tokenize the text of *inp* (its frames cut out): the tokens, whether the log carries
    no checksums, and *original* with the line ends the text was read with (the line
    numbers of the frames).
    """
    if b"\n" not in inp.data and _cr_lines(inp.data):
        # a logger that ends its lines with CR alone (classic Mac, some instruments)
        inp.data = inp.data.replace(b"\r", b"\n")
        original = original.replace(b"\r", b"\n")
    # the fast tokenizer counts its chunks' lines before anything else and stops over the
    # limit; then (rare) the size guard counts, cuts and the kept lines are read
    tok = tokenize_fast(inp.data, max_lines=max_lines) if engine == "fast" else None
    if tok is None:
        _cap_lines(inp, max_lines)
        tok = _ENGINES[engine](inp.data)
    no_checksum = _without_checksums(tok)
    if no_checksum:  # the talker sends none: read its sentences unverified
        tok = (
            tokenize_fast(inp.data, no_checksum=True)
            if engine == "fast"
            else tokenize_reference(inp.data, no_checksum=True)
        )
    return tok, no_checksum, original


_ASHTECH_KEYS = tuple(f"PASHR,{i} " for i in ASHTECH_IDS)


def _may_hold_ashtech(tok) -> bool:
    """Whether an Ashtech binary record may be left in the lines: one is rejected, or named
    like a record (a record's bytes that happen to read as a sentence).
    """
    if (tok.outcome == REJECTED).any():
        return True
    if not any(k.startswith(_ASHTECH_KEYS) for k in tok.names):  # (no count needed)
        return False
    return any(k.startswith(_ASHTECH_KEYS) for k in tok.counts(IGNORED))


def _input_line(original: bytes, pos: np.ndarray) -> np.ndarray:
    """0-based line of the input holding each byte offset *pos*."""
    nl = np.flatnonzero(np.frombuffer(original, dtype=np.uint8) == 10)
    return np.searchsorted(nl, pos, side="left")


def _line_numbers(text: bytes, original: bytes, rtcm: RtcmFrames) -> np.ndarray:
    """0-based line of the input of each line of *text* (the input without its RTCM
    frames, whose bytes may hold line ends).
    """
    tb = np.frombuffer(text, dtype=np.uint8)
    starts = np.concatenate([[0], np.flatnonzero(tb == 10) + 1])
    if starts[-1] >= tb.size:  # a final line end starts no line
        starts = starts[:-1]
    return _input_line(original, rtcm.text_to_input(starts))


def read_nmea(
    source: NmeaSource,
    *,
    strict: bool = False,
    engine: str = "fast",
    max_lines: int = MAX_LINES,
    max_bytes: int = MAX_BYTES,
    decompress: bool = True,
) -> NmeaLog:
    """Read an NMEA 0183 log into an epoch table with full line accounting.

    Parameters
    ----------
    source : path, list of str/bytes, bytes or file object
        A log file (plain or gzip-compressed, detected from its content; a regular file or a
        pipe, read once; a device is refused), its lines, or an open text or binary file.
    strict : bool
        Raise :class:`~gripsense.errors.InputError` naming the file, line and reason at the first
        rejected line, instead of counting it.
    engine : {"fast", "reference"}
        Tokenizer: the vectorised production path or the per-line reference (same results).
    max_lines : int
        Largest number of lines read [lines]; further lines of a file are counted as rejected
        (``over the size limit``), so memory stays bounded whatever the input; from a pipe
        (whose rest may never end) more lines are an error naming the limit.
    max_bytes : int
        Largest (decompressed) size read [bytes]; beyond it the same as *max_lines* (a small
        ``.gz`` can expand enormously).
    decompress : bool
        Detect gzip input by its magic bytes and decompress it (off for a raw byte stream such
        as a receiver's, which may start with any bytes).

    Returns
    -------
    NmeaLog
        ``.epochs`` (DataFrame), ``.report``
        (:class:`~gripsense.io.logs.nmea.accounting.IngestReport`) and
        ``.sentences`` (decoded sentences per type).

    Examples
    --------
    >>> log = read_nmea(["$GPHDT,274.07,T*03"])
    >>> float(log.epochs["heading_deg"].iloc[0])
    274.07
    """
    if engine not in _ENGINES:
        raise InputError(f"read_nmea: engine={engine!r}; use one of {sorted(_ENGINES)}")
    inp = _read_source(source, max_bytes, max_lines, decompress)
    # RTCM 3 corrections and Ashtech binary records interleaved by the receiver: cut out and
    # counted as frames; records before the first RTCM 3 preamble are looked for only when a
    # line is rejected or named like one (a record left in the text always is; pure NMEA
    # costs no pass)
    original = inp.data
    extra_lines, read_notes = inp.extra_lines, inp.notes
    for ashtech in (False, True):
        inp.data, rtcm = split_rtcm(original, ashtech=ashtech)
        inp.extra_lines, inp.notes = extra_lines, read_notes
        tok, no_checksum, original_lines = _tokenize(inp, original, engine, max_lines)
        if ashtech or not _may_hold_ashtech(tok):
            break
        d3 = original.find(b"\xd3")
        if first_ashtech_header(original, None if d3 < 0 else d3) < 0:
            break
    original = original_lines
    data, name = inp.data, inp.name
    line_no = _line_numbers(data, original, rtcm) if rtcm is not None else None

    def no(i):  # 1-based line number in the input of 0-based line(s) i of the text
        return i + 1 if line_no is None else line_no[i] + 1

    tables, malformed = decode_all(tok.raw)
    if malformed:
        lines = np.array([i for i, _ in malformed], dtype=np.int64)
        tok.reject(lines, S.MALFORMED, [d for _, d in malformed])
    rej = np.flatnonzero(tok.outcome == REJECTED)
    bad_frames = np.flatnonzero(~rtcm.good) if rtcm is not None else np.zeros(0, dtype=np.int64)
    if strict:
        _stop_at_first_reject(name, data, tok, rej, rtcm, bad_frames, no_checksum, no)
    epochs, epoch_of, notes = assemble_epochs(tables)

    sentences: dict[str, pd.DataFrame] = {}
    for key, cols in tables.items():
        cols["line"] = no(cols["line"])
        cols["epoch"] = epoch_of[key]
        sentences[key] = pd.DataFrame(cols, copy=False)

    parsed = tok.counts(PARSED)
    ignored = tok.counts(IGNORED)
    rejected_c = tok.counts(REJECTED)
    if inp.extra_lines:
        rejected_c[S.OVER_LIMIT] = rejected_c.get(S.OVER_LIMIT, 0) + inp.extra_lines
        if strict:
            raise InputError(f"{name}: {inp.notes[-1]} (strict mode)")
    first = []
    shown = rej[:N_FIRST_REJECTS].tolist()
    unworded = lines_at(data, [i for i in shown if i not in tok.details])
    for i in shown:
        detail = tok.details.get(i)
        if detail is None:
            detail = classify_line(unworded[i], no_checksum)[2]
        first.append(RejectedLine(int(no(i)), tok.names[tok.code[i]], detail))
    if rtcm is not None:
        for lab, c in rtcm.ignored_counts().items():
            ignored[lab] = ignored.get(lab, 0) + c
        ignored = dict(sorted(ignored.items()))
        if bad_frames.size:
            rejected_c[S.BAD_CHECKSUM] = rejected_c.get(S.BAD_CHECKSUM, 0) + int(bad_frames.size)
            at = _input_line(original, rtcm.start[bad_frames[:N_FIRST_REJECTS]])
            first += [
                RejectedLine(int(ln) + 1, S.BAD_CHECKSUM, f"byte {rtcm.start[k]}: "
                             + frame_detail(rtcm, int(k)))
                for ln, k in zip(at.tolist(), bad_frames[:N_FIRST_REJECTS].tolist(), strict=True)
            ]  # fmt: skip
            first = sorted(first, key=lambda r: r.line)[:N_FIRST_REJECTS]
    if inp.extra_lines and len(first) < N_FIRST_REJECTS:
        first.append(RejectedLine(tok.n_lines + 1, S.OVER_LIMIT, inp.notes[-1]))
    n_frames = rtcm.size if rtcm is not None else 0
    report = IngestReport(
        source=name,
        total_lines=tok.n_lines + inp.extra_lines + n_frames,
        parsed=dict(sorted(parsed.items())),
        ignored=dict(sorted(ignored.items())),
        rejected={r: int(rejected_c.get(r, 0)) for r in S.REASONS},
        first_rejects=first,
        junk_prefix_lines=int(tok.junk_prefix[tok.outcome != REJECTED].sum()),
        n_epochs=len(epochs),
        epochs_without_time=notes["epochs_without_time"],
        has_date=notes["has_date"],
        notes=list(inp.notes or [])
        + _assembly_notes(notes, no_checksum, int(sum(parsed.values())))
        + binary_notes(n_frames, rtcm.n_ashtech if rtcm is not None else 0),
        unit="lines and frames" if n_frames else "lines",
    )
    return NmeaLog(epochs=epochs, report=report, sentences=sentences)


def _stop_at_first_reject(name, data, tok, rej, rtcm, bad_frames, no_checksum, no) -> None:
    """Strict mode: raise at the first bad binary frame, else at the first rejected line (its
    number in the input, its reason and detail); nothing when there is none.
    """
    if rtcm is not None and bad_frames.size:
        k = int(bad_frames[0])
        raise InputError(
            f"{name}: byte {rtcm.start[k]}: {frame_detail(rtcm, k)} (strict mode; drop "
            "--strict to count such frames instead)"
        )
    if rej.size:
        i = int(rej[0])
        detail = tok.details.get(i) or classify_line(lines_at(data, [i])[i], no_checksum)[2]
        raise InputError(
            f"{name}:{no(i)}: {tok.names[tok.code[i]]}: {detail} "
            "(strict mode; drop --strict to count such lines instead)"
        )


def _assembly_notes(notes: dict, no_checksum: bool, n_parsed: int) -> list[str]:
    """The report's notes on how the epochs were assembled: repeated sentences counted once, a
    log without checksums read unverified, epochs of one instant joined.
    """
    out = []
    if notes.get("repeated_sentences"):
        out.append(
            f"{notes['repeated_sentences']} sentences repeat the line before them exactly "
            "(a logger writing each twice): each counted once"
        )
    if no_checksum:
        out.append(
            "no sentence of the log carries a '*hh' checksum (its talker sends none): "
            f"{n_parsed} sentences read unverified — a line cut short "
            "cannot be told from a whole one"
        )
    if notes.get("same_time_merged"):
        out.append(
            f"{notes['same_time_merged']} epochs had the time of the epoch before them "
            "(several talkers reporting one instant, $GP…/$GN…/$GA…, or a logger writing "
            "an epoch twice): joined to it, each instant counts once"
        )
    return out
