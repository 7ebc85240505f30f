"""Readers: everything that turns the outside world into gripsense tables."""

from gripsense.io.nmea import NmeaLog, read_nmea
from gripsense.io.report import IngestReport, RejectedLine

__all__ = ["IngestReport", "NmeaLog", "RejectedLine", "read_nmea"]
