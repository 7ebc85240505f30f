"""Readers and writers: everything that turns the outside world into gripsense tables and back.

Nothing here imports the physics: io sits at the bottom of the one-way flow
(io → tables → physics → estimators → outputs; ``docs/architecture.md``).

Rooms by kind:

- :mod:`gripsense.io.logs` — GNSS-compass and measurement logs, one module per format (NMEA
  0183 in its own room :mod:`gripsense.io.logs.nmea`, UBX, VBOX, MDF4, CAN, NovAtel, ROS
  bags), registered in one table (:mod:`gripsense.io.logs.registry`) that :func:`read_log`
  and live mode consult; with what only logs use (channel mapping, epoch builder,
  heading-source categories, the optional format libraries).
- :mod:`gripsense.io.tyres` — tyre files: ``.tir`` (and its key table), PAC89 JSON, tyre
  measurement tables.
- :mod:`gripsense.io.sensors` — sensor tables beside a log: steering, accelerometer, laser
  and motion tables.
- :mod:`gripsense.io.output_folder` — the result folder, on its own.

Two shared leaves stay at the top because every room reads through them and they import no
room: :mod:`gripsense.io.text` (bounded reading of files and pipes, gzip, TOML; config and
the simulator use it too) and :mod:`gripsense.io.table` (the one column convention of every
table: ``--columns``, units, plausibility limits — the named channels of logs, tyre tables
and sensor tables all map columns with it). The rooms do not import each other
(``tests/test_architecture.py``); a log reader may also use the output folder's atomic write.
"""

from gripsense.io.logs import LogOptions, read_log
from gripsense.io.logs.nmea import (
    Alignment,
    IngestReport,
    NmeaLog,
    RejectedLine,
    align_channels,
    read_nmea,
)
from gripsense.io.output_folder import read_result_folder, write_result_folder
from gripsense.io.sensors.accel import read_accel_csv
from gripsense.io.sensors.laser import read_laser_csv
from gripsense.io.sensors.motion import read_motion_table
from gripsense.io.sensors.steer import read_steer_csv, steer_at
from gripsense.io.table import numeric_column, parse_columns, read_table
from gripsense.io.text import read_text, read_toml
from gripsense.io.tyres.pac89 import read_pac89_json
from gripsense.io.tyres.tir import TirError, TirFile, read_tir, write_tir
from gripsense.io.tyres.tyre_table import read_tyre_table

__all__ = [
    "Alignment",
    "IngestReport",
    "LogOptions",
    "NmeaLog",
    "RejectedLine",
    "TirError",
    "TirFile",
    "align_channels",
    "numeric_column",
    "parse_columns",
    "read_accel_csv",
    "read_laser_csv",
    "read_log",
    "read_motion_table",
    "read_nmea",
    "read_pac89_json",
    "read_result_folder",
    "read_steer_csv",
    "read_table",
    "read_text",
    "read_tir",
    "read_toml",
    "read_tyre_table",
    "steer_at",
    "write_result_folder",
    "write_tir",
]
