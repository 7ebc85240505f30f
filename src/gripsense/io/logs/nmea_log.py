"""NMEA 0183 in the log registry: the last format tried (anything no other format claims is
read as NMEA, its rejected lines accounted for), read by the NMEA room
(:mod:`gripsense.io.logs.nmea`) and written as lines.
"""

from __future__ import annotations

import gzip
import os
from pathlib import Path

import pandas as pd

from gripsense.io.logs.nmea.reader import NmeaLog, read_nmea
from gripsense.io.logs.options import LogInput

__all__ = ["is_nmea", "read_nmea_log", "write_nmea_lines", "write_nmea_log"]


def is_nmea(head: bytes) -> bool:
    """Whether a file is read as NMEA 0183: always (NMEA is the last format tried; what is not
    NMEA in it is rejected line by line, with the reason).

    Parameters
    ----------
    head : bytes
        The file's first bytes (decompressed).

    Returns
    -------
    bool
        True.
    """
    return True


def read_nmea_log(src: LogInput) -> NmeaLog:
    """Read an NMEA log as :func:`gripsense.io.logs.read_log` hands it over (its registry
    entry): :func:`gripsense.io.read_nmea` on the bounded read, whose notes and lines past the
    limit it reports itself.

    Parameters
    ----------
    src : gripsense.io.logs.options.LogInput
        The log's bounded read and options (``strict``, ``max_lines``, ``max_bytes``).

    Returns
    -------
    NmeaLog
        Epoch table, line accounting and decoded sentences.
    """
    assert src.read is not None  # NMEA is read from the stream, never by path
    o = src.options
    return read_nmea(src.read, strict=o.strict, max_lines=o.max_lines, max_bytes=o.max_bytes)


def write_nmea_lines(lines: list[str], path: str | os.PathLike, *, crlf: bool = True) -> None:
    """Write NMEA sentences to a file (gzip-compressed when the name ends in ``.gz``).

    Parameters
    ----------
    lines : list of str
        Sentences without line terminators.
    path : str or Path
        Output file.
    crlf : bool
        End lines with CR LF as NMEA does.
    """
    eol = "\r\n" if crlf else "\n"
    text = eol.join(lines) + eol
    if str(path).endswith(".gz"):
        with gzip.open(path, "wt", encoding="ascii", newline="") as f:
            f.write(text)
    else:
        with open(path, "w", encoding="ascii", newline="") as f:
            f.write(text)


def write_nmea_log(
    epochs: pd.DataFrame,
    path: Path,
    *,
    nmea_lines: list[str] | None = None,
    steer: pd.DataFrame | None = None,
) -> str | None:
    """Write a drive's NMEA sentences for :func:`gripsense.io.logs.write_log`.

    Parameters
    ----------
    epochs : pandas.DataFrame
        Unused: the sentences are the receiver's.
    path : Path
        Output file (gzip when its name ends in ``.gz``).
    nmea_lines : list of str
        The receiver's sentences (needed).
    steer : pandas.DataFrame, optional
        Unused.

    Returns
    -------
    None
        No ``--columns`` are needed to read it back.
    """
    if nmea_lines is None:
        raise ValueError("write_log: the nmea format needs nmea_lines")
    write_nmea_lines(nmea_lines, path)
    return None
