"""Where an epoch's heading and yaw rate came from: the categories of the epoch table's
``heading_source`` and ``yaw_rate_source`` columns, shared by every reader (``docs/ingest.md``).

A leaf module: the NMEA reader (:mod:`gripsense.io.logs.nmea`), the table builder
(:mod:`gripsense.io.logs.epoch_table`) and the other readers import it, and it imports none of them.
Categories are only ever appended (stored tables keep their codes).
"""

from __future__ import annotations

__all__ = ["HEADING_SOURCES", "NOVATEL_HEADING_SOURCES", "YAW_RATE_SOURCES"]

NOVATEL_HEADING_SOURCES = (
    "HEADING",
    "HEADING2",
    "DUALANTENNAHEADING",
    "INSPVA",
    "INSPVAS",
    "INSPVAX",
)
"""NovAtel OEM logs that give a heading, named as the log (as UBX names its messages): the
dual-antenna headings, and the INS azimuth of INSPVA / INSPVAS / INSPVAX."""

HEADING_SOURCES = [
    # the NMEA sentences
    "HPR",
    "PASHR",
    "PSTI",
    "THS",
    "HDT",
    # the other formats: VBOX True_Head, UBX NAV-RELPOSNED / NAV-ATT, a mapped MDF4/CAN channel
    "VBOX",
    "RELPOSNED",
    "NAV-ATT",
    "channel",
    # appended later: NMEA attitude sentences, NovAtel logs
    "AVR",
    "PSSN",
    "GPatt",
    *NOVATEL_HEADING_SOURCES,
]
"""Categories of ``heading_source`` (the NMEA sentence, the log or message that gave the
heading, or ``channel``: a channel the user mapped)."""

YAW_RATE_SOURCES = ["ROT", "heading", "VBOX", "channel"]
"""Categories of ``yaw_rate_source``: NMEA ROT, the heading's rate, VBOX Yaw_Rate, a mapped
channel."""
