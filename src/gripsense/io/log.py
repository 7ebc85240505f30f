"""One entry point for every log format: :func:`read_log` -> the epoch table and its accounting.

The format is recognised from the file's content (a suffix alone can lie: a ``.log`` may hold
UBX, a ``.txt`` a VBOX file); gzip is decompressed first, whatever the format:

==============  ===========================================  ====================================
format          recognised by                                read with
==============  ===========================================  ====================================
MDF4            ``MDF     `` identification block            asammdf (:mod:`gripsense.io.mdf`)
CAN BLF         ``LOGG`` signature                           python-can + cantools (``--dbc``)
CAN ASC         ``date``/``base hex`` header of a Vector ASC python-can + cantools (``--dbc``)
VBOX VBO        ``[column names]`` / ``File created on``     by hand (:mod:`gripsense.io.vbo`)
UBX (+ NMEA)    a UBX frame with a good checksum             compiled scan (:mod:`gripsense.io.ubx`)
NovAtel ASCII   ``#NAMEA,…;…*crc32`` lines, as many as NMEA  by hand (:mod:`gripsense.io.novatel`)
(+ NMEA)        sentences, or one read log with a good CRC
ROS bag         ``#ROSBAG V2.0``, MCAP or sqlite3 magic; a    rosbags (:mod:`gripsense.io.rosbag`)
                ROS 2 bag folder (``metadata.yaml``)
NMEA 0183       anything else                                :func:`gripsense.io.read_nmea`
==============  ===========================================  ====================================

Every reader returns the same :class:`~gripsense.io.nmea.reader.NmeaLog`: the epoch table
(``docs/ingest.md``), an :class:`~gripsense.io.nmea.accounting.IngestReport` whose
``format`` names the format, ``unit`` what it counted (lines, frames, records) and
``channels`` the rate of each channel it gave, and the decoded rows.
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path

from gripsense.errors import InputError
from gripsense.io.epoch_table import channel_rates
from gripsense.io.nmea.reader import NmeaLog, read_nmea
from gripsense.io.text import MAX_BYTES, MAX_LINES, InputStream

__all__ = [
    "FORMATS",
    "SUFFIXES",
    "WRITABLE",
    "LogOptions",
    "detect_format",
    "log_steer",
    "read_log",
    "write_log",
    "write_nmea_lines",
]

FORMATS = ("nmea", "ubx", "vbo", "mf4", "blf", "asc", "rosbag", "novatel")
"""Format names of :func:`detect_format` (and ``--format`` of ``gripsense simulate``)."""


@dataclass(frozen=True)
class LogOptions:
    """How to read a log beyond its own content.

    Parameters
    ----------
    columns : str or dict, optional
        Channels to map (``heading=…,steer=…:deg,torque=…:Nm``; :mod:`gripsense.io.channels`);
        needed for MDF4 and CAN logs, optional for VBOX.
    dbc : str or Path, optional
        The DBC database that decodes a CAN log.
    time_offset : float, optional
        Seconds added to a log's relative time to make it UTC seconds since 1970, for MDF4 or
        CAN logs without an absolute start time [s].
    strict : bool
        Stop at the first rejected line, frame or record.
    max_lines : int
        Largest number of lines read from a line-based log (NMEA, VBOX, ASC) [lines]: an NMEA
        file's further lines are counted, not read; a VBOX or ASC log or a pipe with more is an
        error naming the limit.
    max_bytes : int
        Largest (decompressed) size read [bytes], the same way.
    """

    columns: str | dict | None = None
    dbc: str | Path | None = None
    time_offset: float | None = None
    strict: bool = False
    max_lines: int = MAX_LINES
    max_bytes: int = MAX_BYTES


def detect_format(head: bytes) -> str:
    """The format of a log from its first bytes (decompressed).

    Parameters
    ----------
    head : bytes
        The first 64 KiB or so.

    Returns
    -------
    str
        One of :data:`FORMATS`.
    """
    from gripsense.io.novatel import is_novatel
    from gripsense.io.rosbag import is_rosbag
    from gripsense.io.ubx import is_ubx
    from gripsense.io.vbo import is_vbo

    if head.startswith(b"MDF     ") or head.startswith(b"UnFinMF "):
        return "mf4"
    if head.startswith(b"LOGG"):
        return "blf"
    if is_rosbag(head):
        return "rosbag"
    start = head[:4096].lstrip().lower()
    if start.startswith(b"date ") or b"\nbase hex" in start[:2048] or start.startswith(b"base "):
        return "asc"
    if is_vbo(head):
        return "vbo"
    if is_ubx(head):
        return "ubx"
    if is_novatel(head):
        return "novatel"
    return "nmea"


def _own_columns(fmt: str) -> str:
    """The ``--columns`` that read gripsense's own logs of *fmt*, as an example a user can try."""
    keys = ("heading", "course", "speed")
    if fmt == "mf4":
        from gripsense.io.mdf import MDF_CHANNELS

        cols = ",".join(f"{k}={MDF_CHANNELS[k][0]}" for k in keys)
        return f"--columns {cols} (the channels of gripsense simulate --format mf4)"
    from gripsense.io.canlog import CAN_SIGNALS

    cols = ",".join(f"{k}={CAN_SIGNALS[k]}" for k in keys)
    return f"--columns {cols} (the signals of gripsense's example DBC)"


def read_log(path: str | os.PathLike, options: LogOptions | None = None, **kw) -> NmeaLog:
    """Read a GNSS-compass or measurement log of any supported format (see the module
    documentation) into the epoch table.

    Parameters
    ----------
    path : str or Path
        The log (plain or gzip-compressed): a regular file or a pipe (``<(zcat log.gz)``, a
        FIFO, ``/dev/stdin``), read once; a device file is refused.
    options : LogOptions, optional
        Channel mapping, DBC, time offset, strict mode.
    **kw
        Fields of :class:`LogOptions` given directly (``columns=…``, ``strict=True``).

    Returns
    -------
    NmeaLog
        ``epochs``, ``report`` (with ``format``, ``unit`` and ``channels``) and the decoded
        rows.

    Examples
    --------
    >>> from gripsense.data import path
    >>> read_log(path("demo/case001.nmea.gz")).report.format
    'NMEA 0183'
    """
    o = options if options is not None else LogOptions(**kw)
    if options is not None and kw:
        raise TypeError("read_log: give options or keyword fields, not both")
    p = Path(path)
    if p.is_dir():
        from gripsense.io.rosbag import is_rosbag_dir, read_rosbag

        if not is_rosbag_dir(p):
            raise InputError(f"{p}: a folder, not a log (a ROS 2 bag folder holds metadata.yaml)")
        log = read_rosbag(p, columns=o.columns, time_offset=o.time_offset, strict=o.strict)
        log.report.channels = channel_rates(log.epochs)
        return log
    # one read: the format is recognised from the first bytes, which the reader continues
    # from (a pipe or FIFO is read once; a device is refused)
    src = InputStream(p, "file")
    try:
        head = src.peek(65536)
        if head.startswith(b"Generic File"):  # CSS Electronics' container of a CANedge MF4
            raise InputError(
                f"{p}: a CANedge compressed or encrypted MDF4 file (.MFC/.MFE, a 'Generic "
                "File' container): convert it to .MF4 first (CSS Electronics' mdf2finalized "
                "or MF4 decoders), then read the .MF4"
            )
        fmt = detect_format(head)
        if fmt in ("mf4", "blf", "asc") and o.columns is None:
            article = "a" if fmt == "blf" else "an"  # a BLF, an ASC, an MF4
            raise InputError(
                f"{p}: {article} {fmt.upper()} log carries named channels; say which give the "
                "heading, course and speed with --columns (in Python: columns=), e.g. "
                f"{_own_columns(fmt)}; docs/ingest.md"
            )
        if fmt in ("blf", "asc") and o.dbc is None:
            raise InputError(f"{p}: a CAN log needs its database: give --dbc FILE.dbc")
        by_path = (
            fmt in ("mf4", "rosbag") and not src.gzip and not src.stream
        )  # the library reads it
        inp = None
        if not by_path:
            lines = o.max_lines if fmt in ("nmea", "vbo", "asc", "novatel") else None
            inp = src.read(o.max_bytes, lines, count_rest=fmt == "nmea")
    finally:
        src.close()
    notes = list(inp.notes) if inp is not None else []
    data = inp.data if inp is not None else b""
    if fmt == "nmea":
        assert inp is not None
        log = read_nmea(inp, strict=o.strict, max_lines=o.max_lines, max_bytes=o.max_bytes)
    elif fmt == "ubx":
        from gripsense.io.ubx import parse_ubx

        log = parse_ubx(data, str(p), strict=o.strict)
        log.report.notes[:0] = notes
    elif fmt == "novatel":
        from gripsense.io.novatel import parse_novatel

        log = parse_novatel(data, str(p), strict=o.strict)
        log.report.notes[:0] = notes
    elif fmt == "vbo":
        from gripsense.io.vbo import decode_vbo, parse_vbo

        text = decode_vbo(data) if data else ""  # VBOX files are Latin-1
        log = parse_vbo(text, str(p), columns=o.columns, strict=o.strict)
        log.report.notes[:0] = notes
    elif fmt == "mf4":
        from gripsense.io.mdf import read_mdf

        log = read_mdf(p, None if by_path else data, columns=o.columns,
                       time_offset=o.time_offset, strict=o.strict, dbc=o.dbc)  # fmt: skip
        log.report.notes[:0] = notes
    elif fmt == "rosbag":
        from gripsense.io.rosbag import read_rosbag

        log = read_rosbag(p, None if by_path else data, columns=o.columns,
                          time_offset=o.time_offset, strict=o.strict)  # fmt: skip
        log.report.notes[:0] = notes
    else:
        from gripsense.io.canlog import read_can

        assert o.dbc is not None
        log = read_can(p, data, fmt, dbc=o.dbc, columns=o.columns, time_offset=o.time_offset,
                       strict=o.strict)  # fmt: skip
        log.report.notes[:0] = notes
    log.report.channels = channel_rates(log.epochs)
    unused = [
        flag
        for flag, given, used_by in (
            ("--columns", o.columns, ("vbo", "mf4", "blf", "asc", "rosbag")),
            ("--dbc", o.dbc, ("blf", "asc", "mf4")),  # MDF4: its raw CAN frames
            ("--time-offset", o.time_offset, ("mf4", "blf", "asc", "rosbag")),
        )
        if given is not None and fmt not in used_by
    ]
    if unused:
        log.report.notes.append(
            f"{' and '.join(unused)} not used: the log is {log.report.format} (docs/ingest.md)"
        )
    return log


def log_steer(epochs, steering_ratio: float | None, name: str = "log"):
    """The road-wheel steer angle per epoch that a log itself carries, if it does.

    Parameters
    ----------
    epochs : pandas.DataFrame
        Epoch table of :func:`read_log`.
    steering_ratio : float or None
        Steering-wheel / road-wheel angle [-], for a ``steering_wheel`` channel.
    name : str
        The log, for the message.

    Returns
    -------
    numpy.ndarray or None
        Road-wheel angle [rad] per epoch, or None when the log has no steering channel.
    """
    if "steer_rad" in epochs.columns:
        return epochs["steer_rad"].to_numpy(float)
    if "steering_wheel_rad" in epochs.columns:
        if not steering_ratio:
            raise InputError(
                f"{name}: the log's steering-wheel angle needs [vehicle] steering_ratio in the "
                "vehicle file (or map the road-wheel angle: --columns steer=…)"
            )
        return epochs["steering_wheel_rad"].to_numpy(float) / steering_ratio
    return None


WRITABLE = ("nmea", "vbo", "ubx", "mf4", "rosbag2")
"""Formats :func:`write_log` writes (``gripsense simulate --format``)."""
SUFFIXES = {"nmea": ".nmea.gz", "vbo": ".vbo", "ubx": ".ubx", "mf4": ".mf4", "rosbag2": "_rosbag2"}
"""File suffix of each writable format."""


def write_log(
    epochs,
    path: str | os.PathLike,
    fmt: str,
    *,
    nmea_lines: list[str] | None = None,
    steer=None,
) -> str | None:
    """Write a drive's epoch table in one of the field's formats.

    Parameters
    ----------
    epochs : pandas.DataFrame
        ``time_utc``, ``t_s``, ``lat_deg``, ``lon_deg``, ``alt_m``, ``speed_mps``,
        ``course_deg``, ``heading_deg``, ``yaw_rate_rps``.
    path : str or Path
        Output file.
    fmt : {"nmea", "vbo", "ubx", "mf4", "rosbag2"}
        Format: NMEA (the *nmea_lines*, gzip when the name ends in ``.gz``), VBOX ``.vbo``
        (written by hand), UBX (pyubx2; the NMEA lines interleaved as a receiver sends them) or
        MDF4 (asammdf) or a ROS 2 bag folder (rosbags' writer, MCAP storage).
    nmea_lines : list of str, optional
        The receiver's NMEA sentences (needed for ``nmea``; interleaved in ``ubx``).
    steer : pandas.DataFrame, optional
        ``t_s`` and ``road_wheel_deg``: a steering channel inside a VBOX or MDF4 file (and
        ``torque_Nm``, the column torque inside an MDF4 file; rows of several rates).

    Returns
    -------
    str or None
        The ``--columns`` that read the file back (VBOX with a steering channel, MDF4), else
        None.
    """
    if fmt == "nmea":
        if nmea_lines is None:
            raise ValueError("write_log: the nmea format needs nmea_lines")
        write_nmea_lines(nmea_lines, path)
        return None
    path = Path(path)
    if fmt == "vbo":
        from gripsense.io.vbo import write_vbo

        write_vbo(epochs, path, steer=steer)
        return "steer=RoadWheelAngle" if steer is not None else None
    if fmt == "ubx":
        from gripsense.io.ubx import write_ubx

        write_ubx(epochs, path, nmea_lines=nmea_lines)
        return None
    if fmt == "mf4":
        from gripsense.io.mdf import mdf_columns, write_mdf

        write_mdf(epochs, path, steer=steer)
        return mdf_columns(
            steering=steer is not None, torque=steer is not None and "torque_Nm" in steer
        )
    if fmt == "rosbag2":
        from gripsense.io.rosbag import ROSBAG2_COLUMNS, write_rosbag2

        write_rosbag2(epochs, path)
        return ROSBAG2_COLUMNS
    raise InputError(f"--format {fmt!r}: use one of {', '.join(WRITABLE)}")


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
    import gzip

    eol = "\r\n" if crlf else "\n"
    text = eol.join(lines) + eol
    if str(path).endswith(".gz"):
        with gzip.open(path, "wt", encoding="ascii", newline="") as f:
            f.write(text)
    else:
        with open(path, "w", encoding="ascii", newline="") as f:
            f.write(text)
