"""Batch ingest of GNSS-compass NMEA logs: :func:`read_nmea` -> :class:`NmeaLog`.

Conventions of the epoch table (one row per receiver time instant; see
:mod:`gripsense.io.nmea.epochs` for the grouping rule):

=================  ==========================================================================
column             meaning
=================  ==========================================================================
time_utc           UTC time (tz-aware); NaT when the epoch has no time or the log no date
t_s                seconds from the first epoch with a time [s]
lat_deg, lon_deg   WGS-84 latitude, longitude [deg], north and east positive
alt_m              altitude above mean sea level (GGA) [m]
fix_quality        GGA fix quality (0 none, 1 GPS, 2 DGPS, 4 RTK fixed, 5 RTK float, ...)
n_sats, hdop       satellites used, horizontal dilution of precision (GGA)
speed_mps          speed over ground [m/s]
course_deg         course over ground, clockwise from true north [deg]
heading_deg        true heading, clockwise from true north [deg] (HDT, THS, HPR or PASHR)
heading_source     which sentence gave the heading: ``HPR``, ``PASHR``, ``THS``, ``HDT``
pitch_deg          pitch [deg] as sent by the receiver (HPR, PASHR)
roll_deg           roll [deg] as sent by the receiver (HPR, PASHR)
rot_deg_per_min    rate of turn as NMEA sends it: [deg/min], positive = turning to starboard
yaw_rate_rps       ISO 8855 yaw rate [rad/s], positive counter-clockwise seen from above:
                   -ROT·π/10800 when ROT is present, else -d(heading)/dt
yaw_rate_source    ``ROT`` or ``heading``
=================  ==========================================================================

Missing values are NaN (``<NA>`` in the two source columns), never 0. Numeric columns are
float64 (also ``fix_quality`` and ``n_sats``, so that missing stays NaN).
"""

from __future__ import annotations

import gzip
import os
from dataclasses import dataclass
from pathlib import Path
from typing import IO

import numpy as np
import pandas as pd

from gripsense.errors import InputError
from gripsense.io.nmea import schema as S
from gripsense.io.nmea.accounting import IngestReport, RejectedLine
from gripsense.io.nmea.decode import decode_all
from gripsense.io.nmea.epochs import assemble_epochs
from gripsense.io.nmea.fast import tokenize_fast
from gripsense.io.nmea.reference import classify_line, tokenize_reference
from gripsense.io.nmea.tokens import IGNORED, PARSED, REJECTED, split_lines

__all__ = ["NmeaLog", "read_nmea"]

N_FIRST_REJECTS = 20
_ENGINES = {"fast": tokenize_fast, "reference": tokenize_reference}

NmeaSource = str | os.PathLike | bytes | list | IO


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


def _read_source(source: NmeaSource) -> tuple[bytes, str]:
    """Turn any accepted source into (bytes, display name)."""
    if isinstance(source, str | os.PathLike):
        path = Path(source)
        try:
            with open(path, "rb") as fh:
                data = fh.read()
        except FileNotFoundError:
            raise InputError(f"{path}: no such file; give the path of an NMEA log") from None
        except IsADirectoryError:
            raise InputError(f"{path}: is a directory; give the path of an NMEA log") from None
        if data[:2] == b"\x1f\x8b":
            try:
                data = gzip.decompress(data)
            except (OSError, EOFError) as e:
                raise InputError(
                    f"{path}: looks gzip-compressed but cannot be decompressed ({e})"
                ) from None
        return data, str(path)
    if isinstance(source, bytes | bytearray | memoryview):
        return bytes(source), "<bytes>"
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
        return b"\n".join(out) + (b"\n" if out else b""), "<lines>"
    if hasattr(source, "read"):
        data = source.read()
        if isinstance(data, str):
            data = data.encode("utf-8", "surrogateescape")
        name = getattr(source, "name", "<stream>")
        if data[:2] == b"\x1f\x8b":
            data = gzip.decompress(data)
        return bytes(data), str(name)
    raise InputError(
        f"read_nmea: source of type {type(source).__name__} is not supported; give a path, a list "
        "of lines or a file object"
    )


def read_nmea(source: NmeaSource, *, strict: bool = False, engine: str = "fast") -> NmeaLog:
    """Read an NMEA 0183 log into an epoch table with full line accounting.

    Parameters
    ----------
    source : path, list of str/bytes, bytes or file object
        A log file (plain or gzip-compressed, detected from its content), its lines, or an open
        text or binary file.
    strict : bool
        Raise :class:`~gripsense.errors.InputError` naming the file, line and reason at the first
        rejected line, instead of counting it.
    engine : {"fast", "reference"}
        Tokenizer: the vectorised production path or the per-line reference (same results).

    Returns
    -------
    NmeaLog
        ``.epochs`` (DataFrame), ``.report``
        (:class:`~gripsense.io.nmea.accounting.IngestReport`) and
        ``.sentences`` (decoded sentences per type).

    Examples
    --------
    >>> log = read_nmea(["$GPHDT,274.07,T*03"])
    >>> float(log.epochs["heading_deg"].iloc[0])
    274.07
    """
    if engine not in _ENGINES:
        raise InputError(f"read_nmea: engine={engine!r}; use one of {sorted(_ENGINES)}")
    data, name = _read_source(source)
    tok = _ENGINES[engine](data)
    frames, malformed = decode_all(tok.raw)
    if malformed:
        lines = np.array([i for i, _ in malformed], dtype=np.int64)
        tok.reject(lines, S.MALFORMED, [d for _, d in malformed])
    rej = np.flatnonzero(tok.outcome == REJECTED)
    if strict and rej.size:
        i = int(rej[0])
        detail = tok.details.get(i) or classify_line(split_lines(data)[i])[2]
        raise InputError(
            f"{name}:{i + 1}: {tok.names[tok.code[i]]}: {detail} "
            "(strict mode; drop --strict to count such lines instead)"
        )
    epochs, epoch_of, notes = assemble_epochs(frames)

    sentences = frames
    for k, f in frames.items():
        f["line"] += 1
        f["epoch"] = epoch_of[k]

    parsed = tok.counts(PARSED)
    ignored = tok.counts(IGNORED)
    rejected_c = tok.counts(REJECTED)
    first = []
    for i in rej[:N_FIRST_REJECTS].tolist():
        detail = tok.details.get(i)
        if detail is None:
            detail = classify_line(split_lines(data)[i])[2]
        first.append(RejectedLine(i + 1, tok.names[tok.code[i]], detail))
    report = IngestReport(
        source=name,
        total_lines=tok.n_lines,
        parsed=dict(sorted(parsed.items())),
        ignored=dict(sorted(ignored.items())),
        rejected={r: int(rejected_c.get(r, 0)) for r in S.REASONS},
        first_rejects=first,
        junk_prefix_lines=int(tok.junk_prefix[tok.outcome != REJECTED].sum()),
        n_epochs=len(epochs),
        epochs_without_time=notes["epochs_without_time"],
        has_date=notes["has_date"],
    )
    return NmeaLog(epochs=epochs, report=report, sentences=sentences)
