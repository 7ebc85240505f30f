"""NMEA 0183 ingest: tokenizers, decoding, epoch assembly and line accounting.

``read_nmea`` is the entry point; ``docs/ingest.md`` describes the sentences, the epoch table and
the grouping rule.
"""

from gripsense.io.logs.nmea.accounting import IngestReport, RejectedLine
from gripsense.io.logs.nmea.align import Alignment, align_channels
from gripsense.io.logs.nmea.reader import NmeaLog, read_nmea

__all__ = ["Alignment", "IngestReport", "NmeaLog", "RejectedLine", "align_channels", "read_nmea"]
