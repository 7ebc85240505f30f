"""Logs: one module per format, one table of them, one entry point.

:func:`read_log` reads a log of any format (recognised from its content by
:func:`detect_format`), :func:`write_log` writes one (``gripsense simulate --format``); both,
and live mode, consult the one table :data:`~gripsense.io.logs.registry.LOG_FORMATS`. The
formats: NMEA 0183 (its own room, :mod:`gripsense.io.logs.nmea`; :mod:`~.nmea_log` registers
it), u-blox UBX (:mod:`~.ubx`), Racelogic VBOX (:mod:`~.vbo`), MDF4 (:mod:`~.mdf`), Vector
CAN BLF/ASC (:mod:`~.canlog`), NovAtel ASCII (:mod:`~.novatel`), ROS bags (:mod:`~.rosbag`).
What only logs use sits beside them: the channel mapping of named-channel logs
(:mod:`~.channels`, :mod:`~.measurement`), the epoch builder (:mod:`~.epoch_table`), the
heading-source categories (:mod:`~.sources`) and the optional format libraries
(:mod:`~.formats`). Adding a format: :mod:`gripsense.io.logs.registry`.
"""

from gripsense.io.logs.dispatch import detect_format, log_steer, read_log, write_log
from gripsense.io.logs.nmea_log import write_nmea_lines
from gripsense.io.logs.options import LogInput, LogOptions
from gripsense.io.logs.registry import FORMATS, LOG_FORMATS, SUFFIXES, WRITABLE, LogFormat

__all__ = [
    "FORMATS",
    "LOG_FORMATS",
    "SUFFIXES",
    "WRITABLE",
    "LogFormat",
    "LogInput",
    "LogOptions",
    "detect_format",
    "log_steer",
    "read_log",
    "write_log",
    "write_nmea_lines",
]
