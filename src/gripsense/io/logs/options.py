"""What a log reader is given: the user's :class:`LogOptions` and, per file, a :class:`LogInput`.

Every format's read function (:mod:`gripsense.io.logs.registry`) takes one :class:`LogInput`
and returns the epoch table and its accounting.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from gripsense.io.text import MAX_BYTES, MAX_LINES, ReadInput

__all__ = ["LogInput", "LogOptions"]


@dataclass(frozen=True)
class LogOptions:
    """How to read a log beyond its own content.

    Parameters
    ----------
    columns : str or dict, optional
        Channels to map (``heading=…,steer=…:deg,torque=…:Nm``; :mod:`gripsense.io.logs.channels`);
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


@dataclass(frozen=True)
class LogInput:
    """One log as :func:`gripsense.io.logs.read_log` hands it to its format's read function.

    Parameters
    ----------
    path : Path
        The log (a file, a pipe or a folder), for messages and for readers that open it by path.
    data : bytes
        Its bytes (decompressed); empty when the reader opens the file by path.
    read : gripsense.io.text.ReadInput or None
        The bounded read the bytes come from (its notes, the lines past the limit); None when
        the reader opens the file by path (a plain MDF4 file, a ROS bag or bag folder).
    options : LogOptions
        Channel mapping, DBC, time offset, strict mode, limits.
    """

    path: Path
    data: bytes
    read: ReadInput | None
    options: LogOptions

    @property
    def name(self) -> str:
        """The log's name, for messages."""
        return str(self.path)
