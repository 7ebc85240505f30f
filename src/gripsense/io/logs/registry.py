"""The one table of log formats: :data:`LOG_FORMATS`, which :func:`gripsense.io.logs.read_log`,
:func:`~gripsense.io.logs.detect_format`, :func:`~gripsense.io.logs.write_log` and live mode
(:func:`gripsense.live.sources.open_replay`) consult; none of them names a format.

Each format lives in its own module of :mod:`gripsense.io.logs` (NMEA in its own room,
:mod:`gripsense.io.logs.nmea`) and exposes "is this my format?" (``is_<format>(head: bytes)
-> bool``) and a read function that takes a :class:`~gripsense.io.logs.options.LogInput`
(``read_<format>_log``). The table is ordered: :func:`~gripsense.io.logs.detect_format` asks
the formats in this order and the first that claims the bytes wins — the binary signatures
first (MDF4, BLF, ROS bags), then the text formats with a recognisable header (ASC, VBOX),
UBX frames, NovAtel records, and NMEA last (it takes anything).

**Adding a format** is one new module (``is_<format>``, ``read_<format>_log``, optionally a
writer) and one :class:`LogFormat` entry below, at the place in the order where its signature
is tested; ``docs/ingest.md`` then gets its row.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

from gripsense.io.logs import canlog, mdf, novatel, rosbag, ubx, vbo
from gripsense.io.logs.nmea.reader import NmeaLog
from gripsense.io.logs.nmea_log import is_nmea, read_nmea_log, write_nmea_log
from gripsense.io.logs.options import LogInput

__all__ = ["FORMATS", "LOG_FORMATS", "SUFFIXES", "WRITABLE", "WRITERS", "LogFormat", "LogWriter"]

Writer = Callable[..., str | None]
"""``write(epochs, path, *, nmea_lines=None, steer=None) -> --columns or None``."""


@dataclass(frozen=True)
class LogWriter:
    """How :func:`gripsense.io.logs.write_log` writes a format (``gripsense simulate --format``).

    Parameters
    ----------
    name : str
        The ``--format`` name (``rosbag2`` for the ROS 2 bags written).
    suffix : str
        File suffix of a written log (a folder's name ending for a ROS 2 bag).
    write : callable
        ``write(epochs, path, *, nmea_lines=None, steer=None)`` -> the ``--columns`` that read
        the file back, or None.
    order : int
        Place in the list of writable formats (:data:`WRITABLE`, the order ``--format`` and its
        error message name them).
    """

    name: str
    suffix: str
    write: Writer
    order: int


@dataclass(frozen=True)
class LogFormat:
    """One log format: how to recognise it, read it and write it, and what it needs.

    Parameters
    ----------
    name : str
        Name :func:`~gripsense.io.logs.detect_format` returns.
    is_format : callable
        ``is_format(head: bytes) -> bool``: whether the first 64 KiB (decompressed) are this
        format's.
    read : callable
        ``read(src: LogInput) -> NmeaLog``.
    needs_columns : bool
        Reading it needs ``--columns`` (its channels carry names, none of which is known to be
        the heading); an error names an example from *example_columns*.
    example_columns : callable, optional
        ``() -> str``: the ``--columns`` that read gripsense's own files of the format.
    article : str
        ``"a"`` or ``"an"`` before the format's upper-case name in messages.
    needs_dbc : bool
        Reading it needs ``--dbc`` (raw CAN frames).
    line_based : bool
        ``--max-lines`` bounds it (a file or pipe with more lines is an error naming the limit,
        unless *counts_rest*).
    counts_rest : bool
        Lines past ``--max-lines`` are counted, not read (the reader gets the bounded read
        itself and reports its notes).
    by_path : bool
        A plain (not gzip, not piped) file is opened by its path, by the format's library.
    uses : frozenset of str
        The options it uses of ``--columns``, ``--dbc``, ``--time-offset``; another one given
        is reported as not used.
    is_folder : callable, optional
        ``is_folder(path: Path) -> bool``: a folder that holds a log of this format.
    folder_hint : str
        What such a folder holds, for the message when a folder is none of them.
    writer : LogWriter, optional
        How to write it (``gripsense simulate --format``).
    streams : bool
        Live mode replays it as a byte stream, paced by its own times (NMEA, UBX); else its
        epochs are read whole and handed out as their time comes.
    """

    name: str
    is_format: Callable[[bytes], bool]
    read: Callable[[LogInput], NmeaLog]
    needs_columns: bool = False
    example_columns: Callable[[], str] | None = None
    article: str = "a"
    needs_dbc: bool = False
    line_based: bool = False
    counts_rest: bool = False
    by_path: bool = False
    uses: frozenset[str] = frozenset()
    is_folder: Callable[[Path], bool] | None = None
    folder_hint: str = ""
    writer: LogWriter | None = None
    streams: bool = False


_CHANNELS = frozenset({"--columns", "--time-offset"})

LOG_FORMATS: dict[str, LogFormat] = {
    f.name: f
    for f in (
        LogFormat(
            "mf4", mdf.is_mdf, mdf.read_mdf_log, needs_columns=True,
            example_columns=mdf.mdf_example_columns, article="an", by_path=True,
            uses=_CHANNELS | {"--dbc"},  # --dbc: its raw CAN frames
            writer=LogWriter("mf4", ".mf4", mdf.write_mdf_log, 3),
        ),
        LogFormat(
            "blf", canlog.is_blf, canlog.read_blf_log, needs_columns=True,
            example_columns=canlog.can_example_columns, needs_dbc=True,
            uses=_CHANNELS | {"--dbc"},
        ),
        LogFormat(
            "rosbag", lambda head: rosbag.is_rosbag(head) is not None, rosbag.read_rosbag_log,
            by_path=True, uses=_CHANNELS, is_folder=rosbag.is_rosbag_dir,
            folder_hint="a ROS 2 bag folder holds metadata.yaml",
            writer=LogWriter("rosbag2", "_rosbag2", rosbag.write_rosbag2_log, 4),
        ),
        LogFormat(
            "asc", canlog.is_asc, canlog.read_asc_log, needs_columns=True,
            example_columns=canlog.can_example_columns, article="an", needs_dbc=True,
            line_based=True, uses=_CHANNELS | {"--dbc"},
        ),
        LogFormat(
            "vbo", vbo.is_vbo, vbo.read_vbo_log, line_based=True, uses=frozenset({"--columns"}),
            writer=LogWriter("vbo", ".vbo", vbo.write_vbo_log, 1),
        ),
        LogFormat(
            "ubx", ubx.is_ubx, ubx.read_ubx_log, streams=True,
            writer=LogWriter("ubx", ".ubx", ubx.write_ubx_log, 2),
        ),
        LogFormat("novatel", novatel.is_novatel, novatel.read_novatel_log, line_based=True),
        LogFormat(
            "nmea", is_nmea, read_nmea_log, line_based=True, counts_rest=True, streams=True,
            writer=LogWriter("nmea", ".nmea.gz", write_nmea_log, 0),
        ),
    )
}  # fmt: skip
"""Every log format, in the order :func:`~gripsense.io.logs.detect_format` tries them."""

FORMATS = tuple(LOG_FORMATS)
"""Format names of :func:`~gripsense.io.logs.detect_format`, in the order it tries them."""

_WRITERS = sorted(
    (f.writer for f in LOG_FORMATS.values() if f.writer is not None), key=lambda w: w.order
)
WRITERS: dict[str, LogWriter] = {w.name: w for w in _WRITERS}
"""Writable formats by ``--format`` name."""
WRITABLE = tuple(WRITERS)
"""Formats :func:`~gripsense.io.logs.write_log` writes (``gripsense simulate --format``)."""
SUFFIXES = {w.name: w.suffix for w in _WRITERS}
"""File suffix of each writable format."""
