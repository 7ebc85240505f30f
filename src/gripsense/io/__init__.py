"""Readers and writers: everything that turns the outside world into gripsense tables and back.

Nothing here imports the physics: io sits at the bottom of the one-way flow
(io → tables → physics → estimators → outputs; ``docs/architecture.md``).
"""

from gripsense.io.accel import read_accel_csv
from gripsense.io.laser import read_laser_csv
from gripsense.io.log import LogOptions, read_log
from gripsense.io.nmea import (
    Alignment,
    IngestReport,
    NmeaLog,
    RejectedLine,
    align_channels,
    read_nmea,
)
from gripsense.io.output_folder import read_result_folder, write_result_folder
from gripsense.io.pac89 import read_pac89_json
from gripsense.io.steer import read_steer_csv, steer_at
from gripsense.io.table import numeric_column, parse_columns, read_motion_table, read_table
from gripsense.io.text import read_text, read_toml
from gripsense.io.tir import TirError, TirFile, read_tir, write_tir
from gripsense.io.tyre_table import read_tyre_table

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
