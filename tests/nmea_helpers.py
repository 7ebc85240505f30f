"""Test helpers written independently of gripsense (checksums, GPSD .chk parsing)."""

from __future__ import annotations

import json
from functools import reduce
from pathlib import Path


def nmea_checksum(body: str) -> str:
    """XOR of the characters between '$' and '*', as two upper-case hex digits (NMEA 0183)."""
    return f"{reduce(lambda a, c: a ^ ord(c), body, 0):02X}"


def sentence(body: str, start: str = "$") -> str:
    """A complete sentence with a correct checksum."""
    return f"{start}{body}*{nmea_checksum(body)}"


def gpsd_reports(chk: Path, log: Path) -> list[tuple[int, str, dict]]:
    """(1-based line number in *log*, line text, JSON report) from a GPSD regression .chk file.

    GPSD prints its reports after the input line that completed them; the trigger is the most
    recent non-JSON line before the report. The .chk repeats the log's sentence lines in order,
    so each is matched to the next identical line of the log (repeated identical lines stay
    distinct).
    """
    log_lines = [r.rstrip(b"\r").decode("latin-1") for r in log.read_bytes().split(b"\n")]
    out = []
    last: tuple[int, str] | None = None
    pos = 0
    for raw in chk.read_bytes().split(b"\n"):
        line = raw.rstrip(b"\r").decode("latin-1")
        if line.startswith("{"):
            if last is not None:
                out.append((last[0], last[1], json.loads(line)))
        elif line.startswith(("$", "!")):
            j = pos
            while j < len(log_lines) and log_lines[j] != line:
                j += 1
            if j < len(log_lines):
                pos = j + 1
                last = (j + 1, line)
            else:
                last = None
    return out
