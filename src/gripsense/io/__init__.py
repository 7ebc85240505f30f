"""Readers and writers: everything that turns the outside world into gripsense tables and back.

Nothing here imports the physics: io sits at the bottom of the one-way flow
(io → tables → physics → estimators → outputs; ``docs/architecture.md``).
"""

from gripsense.io.nmea import IngestReport, NmeaLog, RejectedLine, read_nmea

__all__ = ["IngestReport", "NmeaLog", "RejectedLine", "read_nmea"]
