"""Accounting of an ingest: every input line (or binary frame, or data record) is in exactly one
bucket — the same report for NMEA, VBOX, UBX, MDF4 and CAN logs (``docs/ingest.md``).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import pandas as pd

from gripsense.io.logs.nmea.schema import REASONS

__all__ = ["IngestReport", "RejectedLine"]


@dataclass(frozen=True)
class RejectedLine:
    """One rejected input line: 1-based line number, reason and detail.

    Attributes
    ----------
    line : int
        1-based line number in the input.
    reason : str
        Reject reason (:data:`gripsense.io.logs.nmea.schema.REASONS`).
    detail : str
        What exactly was wrong.
    """

    line: int
    reason: str
    detail: str


@dataclass
class IngestReport:
    """Where every line (or frame, or record) of an input went.

    Attributes
    ----------
    source : str
        File name (or ``<lines>`` / ``<stream>``).
    total_lines : int
        Input units: lines of a text log; lines plus frames of a mixed UBX/NMEA stream;
        records of an MDF4 or CAN log (:attr:`unit` says which).
    parsed : dict
        Sentence, message or channel type -> number of units read into the epoch table.
    ignored : dict
        Type -> number of valid units not used (other sentence types, ``(blank)``, ``(comment)``,
        UBX messages gripsense does not read, CAN frames of unmapped messages).
    rejected : dict
        Reason -> number of units rejected (all NMEA reasons, zeros included, and any
        format-specific reason).
    first_rejects : list of RejectedLine
        The first rejected lines (up to 20), with line number and detail.
    junk_prefix_lines : int
        Parsed or ignored lines whose sentence was recovered after other bytes on the same line.
    n_epochs, epochs_without_time : int
        Rows of the epoch table, and those without a UTC time.
    has_date : bool
        Whether a date (RMC, ZDA) was found; without one ``time_utc`` is NaT.
    notes : list of str
        What else happened to the input (a cut-off gzip stream, lines beyond the size limits).
    format : str
        The log format (``NMEA 0183``, ``VBOX VBO``, ``u-blox UBX``, ``MDF4``, ``CAN BLF`` …).
    unit : str
        What :attr:`total_lines` counts (``lines``, ``lines and frames``, ``records``).
    channels : dict
        Epoch-table channel -> the rate it came at [Hz] (median interval of the rows that have
        it).
    steering : dict
        The log's own steering channel, if it has one: ``key`` (``steer`` or
        ``steering_wheel``), ``channel``, ``unit`` (the file's) and ``source`` (``--columns``,
        or ``name and unit``: found without being mapped, :func:`gripsense.io.logs.channels.
        recognise_steering`); empty when the log carries none.
    """

    source: str
    total_lines: int
    parsed: dict[str, int]
    ignored: dict[str, int]
    rejected: dict[str, int]
    first_rejects: list[RejectedLine] = field(default_factory=list)
    junk_prefix_lines: int = 0
    n_epochs: int = 0
    epochs_without_time: int = 0
    has_date: bool = False
    notes: list[str] = field(default_factory=list)
    format: str = "NMEA 0183"
    unit: str = "lines"
    channels: dict[str, float] = field(default_factory=dict)
    steering: dict[str, str] = field(default_factory=dict)

    @property
    def n_parsed(self) -> int:
        """Lines parsed into sentences."""
        return sum(self.parsed.values())

    @property
    def n_ignored(self) -> int:
        """Lines recognised but not used (other sentence types, blanks, comments)."""
        return sum(self.ignored.values())

    @property
    def n_rejected(self) -> int:
        """Lines rejected with a reason."""
        return sum(self.rejected.values())

    @property
    def balanced(self) -> bool:
        """True when parsed + ignored + rejected = total lines."""
        return self.n_parsed + self.n_ignored + self.n_rejected == self.total_lines

    def to_frame(self) -> pd.DataFrame:
        """The accounting as a table: bucket, kind (type or reason), lines."""
        rows = [("parsed", k, v) for k, v in sorted(self.parsed.items())]
        rows += [("ignored", k, v) for k, v in sorted(self.ignored.items())]
        reasons = [*REASONS, *(k for k in self.rejected if k not in REASONS)]
        rows += [("rejected", k, self.rejected.get(k, 0)) for k in reasons]
        return pd.DataFrame(rows, columns=["bucket", "kind", "lines"])

    def to_dict(self) -> dict:
        """Plain-data form (for JSON)."""
        return {
            "source": self.source,
            "total_lines": self.total_lines,
            "parsed": dict(self.parsed),
            "ignored": dict(self.ignored),
            "rejected": dict(self.rejected),
            "first_rejects": [r.__dict__ for r in self.first_rejects],
            "junk_prefix_lines": self.junk_prefix_lines,
            "n_epochs": self.n_epochs,
            "epochs_without_time": self.epochs_without_time,
            "notes": list(self.notes),
            "has_date": self.has_date,
            "format": self.format,
            "unit": self.unit,
            "channels": dict(self.channels),
            "steering": dict(self.steering),
        }
