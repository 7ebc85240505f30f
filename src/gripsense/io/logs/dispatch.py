"""One entry point for every log format: :func:`read_log` -> the epoch table and its accounting.

The format is recognised from the file's content (a suffix alone can lie: a ``.log`` may hold
UBX, a ``.txt`` a VBOX file); gzip is decompressed first, whatever the format. The formats,
in the order they are tried (:data:`gripsense.io.logs.registry.LOG_FORMATS`, the one table
this module consults):

==============  ===========================================  ====================================
format          recognised by                                read with
==============  ===========================================  ====================================
MDF4            ``MDF     `` identification block            asammdf (:mod:`.mdf`)
CAN BLF         ``LOGG`` signature                           python-can + cantools (``--dbc``)
ROS bag         ``#ROSBAG V2.0``, MCAP or sqlite3 magic; a    rosbags (:mod:`.rosbag`)
                ROS 2 bag folder (``metadata.yaml``)
CAN ASC         ``date``/``base hex`` header of a Vector ASC python-can + cantools (``--dbc``)
VBOX VBO        ``[column names]`` / ``File created on``     by hand (:mod:`.vbo`)
UBX (+ NMEA)    a UBX frame with a good checksum             compiled scan (:mod:`.ubx`)
NovAtel ASCII   ``#NAMEA,…;…*crc32`` lines, as many as NMEA  by hand (:mod:`.novatel`)
(+ NMEA)        sentences, or one read log with a good CRC
NMEA 0183       anything else                                :func:`gripsense.io.read_nmea`
==============  ===========================================  ====================================

Every reader returns the same :class:`~gripsense.io.logs.nmea.reader.NmeaLog`: the epoch table
(``docs/ingest.md``), an :class:`~gripsense.io.logs.nmea.accounting.IngestReport` whose
``format`` names the format, ``unit`` what it counted (lines, frames, records) and
``channels`` the rate of each channel it gave, and the decoded rows.
"""

from __future__ import annotations

import os
from pathlib import Path

from gripsense.errors import InputError
from gripsense.io.logs.epoch_table import channel_rates
from gripsense.io.logs.nmea.reader import NmeaLog
from gripsense.io.logs.options import LogInput, LogOptions
from gripsense.io.logs.registry import LOG_FORMATS, WRITABLE, WRITERS, LogFormat
from gripsense.io.text import InputStream

__all__ = ["detect_format", "log_steer", "read_log", "write_log"]


def detect_format(head: bytes) -> str:
    """The format of a log from its first bytes (decompressed): the first of
    :data:`~gripsense.io.logs.registry.LOG_FORMATS` that claims them.

    Parameters
    ----------
    head : bytes
        The first 64 KiB or so.

    Returns
    -------
    str
        One of :data:`~gripsense.io.logs.registry.FORMATS`.
    """
    return next(f.name for f in LOG_FORMATS.values() if f.is_format(head))


def _read_folder(p: Path, o: LogOptions) -> NmeaLog:
    """A log that is a folder (a ROS 2 bag), read by the format whose folder it is."""
    for f in LOG_FORMATS.values():
        if f.is_folder is not None and f.is_folder(p):
            log = f.read(LogInput(p, b"", None, o))
            log.report.channels = channel_rates(log.epochs)
            return log
    hints = "; ".join(f.folder_hint for f in LOG_FORMATS.values() if f.folder_hint)
    raise InputError(f"{p}: a folder, not a log ({hints})")


def _check_needs(p: Path, f: LogFormat, o: LogOptions) -> None:
    """One line naming what a format needs that was not given (``--columns``, ``--dbc``)."""
    if f.needs_columns and o.columns is None:
        example = f.example_columns() if f.example_columns is not None else "--columns …"
        raise InputError(
            f"{p}: {f.article} {f.name.upper()} log carries named channels; say which give the "
            "heading, course and speed with --columns (in Python: columns=), e.g. "
            f"{example}; docs/ingest.md"
        )
    if f.needs_dbc and o.dbc is None:
        raise InputError(f"{p}: a CAN log needs its database: give --dbc FILE.dbc")


def _note_unused(log: NmeaLog, f: LogFormat, o: LogOptions) -> None:
    """Report the options given that the log's format does not use."""
    given = (("--columns", o.columns), ("--dbc", o.dbc), ("--time-offset", o.time_offset))
    unused = [flag for flag, value in given if value is not None and flag not in f.uses]
    if unused:
        log.report.notes.append(
            f"{' and '.join(unused)} not used: the log is {log.report.format} (docs/ingest.md)"
        )


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
        return _read_folder(p, o)
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
        f = LOG_FORMATS[detect_format(head)]
        _check_needs(p, f, o)
        inp = None
        if not (f.by_path and not src.gzip and not src.stream):  # else the library reads it
            lines = o.max_lines if f.line_based else None
            inp = src.read(o.max_bytes, lines, count_rest=f.counts_rest)
    finally:
        src.close()
    log = f.read(LogInput(p, inp.data if inp is not None else b"", inp, o))
    if inp is not None and not f.counts_rest:  # a counting reader reports the read's notes
        log.report.notes[:0] = inp.notes
    log.report.channels = channel_rates(log.epochs)
    _note_unused(log, f, o)
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
        Format (:data:`~gripsense.io.logs.registry.WRITABLE`): NMEA (the *nmea_lines*, gzip
        when the name ends in ``.gz``), VBOX ``.vbo`` (written by hand), UBX (pyubx2; the NMEA
        lines interleaved as a receiver sends them) or MDF4 (asammdf) or a ROS 2 bag folder
        (rosbags' writer, MCAP storage).
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
    w = WRITERS.get(fmt)
    if w is None:
        raise InputError(f"--format {fmt!r}: use one of {', '.join(WRITABLE)}")
    return w.write(epochs, Path(path), nmea_lines=nmea_lines, steer=steer)
