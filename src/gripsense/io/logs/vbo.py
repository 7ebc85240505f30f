"""Racelogic VBOX ``.vbo`` files: read into the epoch table, and write (for the simulator).

The format (Racelogic, "VBO file format"): a text file with an optional preamble line
(``File created on 31/07/2006 @ 09:55:20``), then sections ``[header]`` (one channel title per
line, e.g. ``velocity kmh``), ``[channel units]`` (the units of the module/CAN channels),
``[comments]``, ``[module information]``, ``[column names]`` (space separated; one line, or
several when a VBOX 3i / Video / Touch wraps a long list or a tool writes one name a line: the
words of every line, in order, matched to the rows' fields and ``[header]``'s channels) and
``[data]`` (one space-separated row per sample). Conventions of the standard channels:

===============  =========================================================================
column           meaning
===============  =========================================================================
sats             satellites; +64 brake trigger, +128 DGPS
time             UTC time of day, ``hhmmss.ss``
lat, long        minutes of arc; latitude north positive, **longitude west positive**
velocity         speed over ground, km/h (``velocity knots`` / ``velocity mph`` in the header)
heading          course over ground [deg]
height           altitude [m]
True_Head        dual-antenna true heading [deg] (``True_Heading`` in some firmware)
Yaw_Rate         dual-antenna yaw rate [deg/s], the rate of True_Head (clockwise positive)
Pitch_Ang        dual-antenna pitch [deg] (``Pitch_Angle``); Roll_Angle roll [deg]
Solution_Type    0 none, 1 GNSS, 2 DGNSS, 3 RTK float, 4 RTK fixed
Date             ``ddmmyy`` (some loggers); else the preamble's date
===============  =========================================================================

Other channels (slip angle, velocities, accelerations, CAN channels such as a steering angle)
are read only when ``--columns`` maps them (:mod:`gripsense.io.logs.channels`); their unit is the
one ``[channel units]`` gives or the one ``--columns`` states. Every line is accounted for:
the data rows are ``parsed`` (or rejected with a reason: a short row is ``truncated``, a
non-number ``malformed field``), the other lines ``ignored`` as ``(header)`` or ``(blank)``.
"""

from __future__ import annotations

import datetime as dt
import io
import re
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pandas as pd

from gripsense.errors import InputError
from gripsense.io.logs.channels import ChannelSpec, add_steering, parse_channel_spec
from gripsense.io.logs.epoch_table import build_epochs
from gripsense.io.logs.nmea.accounting import IngestReport, RejectedLine
from gripsense.io.logs.nmea.reader import NmeaLog
from gripsense.io.logs.nmea.schema import MALFORMED, REASONS, TRUNCATED
from gripsense.io.logs.options import LogInput

__all__ = [
    "VBO_SECTIONS",
    "decode_vbo",
    "is_vbo",
    "parse_vbo",
    "read_vbo",
    "read_vbo_log",
    "write_vbo",
    "write_vbo_log",
]

VBO_SECTIONS = ("column names", "data")
"""Sections a ``.vbo`` file must have (``[header]``, ``[channel units]`` and the others are
optional; ``[header]`` tells channel names that hold a space apart)."""

_SECTION = re.compile(r"^\s*\[([^\]]+)\]\s*$")
_CREATED = re.compile(
    r"File created on\s+(\d{1,2})/(\d{1,2})/(\d{4})"
    r"(?:\s*(?:@|at)\s*(\d{1,2}):(\d{2})(?::(\d{2}))?)?",
    re.IGNORECASE,
)
_MINUTES_TO_DEG = 1.0 / 60.0
_KMH = 1 / 3.6
_SPEED_HEADER = {"kmh": _KMH, "km/h": _KMH, "knots": 1852 / 3600, "mph": 0.44704, "m/s": 1.0}

# standard channel (lower-case column name) -> its role
_ALIASES = {
    "sats": "sats",
    "time": "time",
    "lat": "lat",
    "long": "long",
    "velocity": "velocity",
    "heading": "course",
    "height": "height",
    "true_head": "heading",
    "true_heading": "heading",
    "truehead": "heading",
    "yaw_rate": "yaw_rate",
    "pitch_ang": "pitch",
    "pitch_angle": "pitch",
    "roll_angle": "roll",
    "roll_ang": "roll",
    "solution_type": "solution",
    "date": "date",
}
_SOLUTION_TO_GGA = {0: 0, 1: 1, 2: 2, 3: 5, 4: 4}


def is_vbo(head: bytes) -> bool:
    """Whether the start of a file looks like a VBOX ``.vbo`` file.

    Parameters
    ----------
    head : bytes
        The first few kilobytes of the file.
    """
    low = head[:8192].lower()
    return b"[column names]" in low or (b"[header]" in low and b"file created on" in low)


def decode_vbo(data: bytes) -> str:
    """The text of a ``.vbo`` file: UTF-8 when it is valid UTF-8, else Latin-1 (what VBOX
    loggers and VBOX Tools write: ``°`` is the byte 0xB0, ``¬`` 0xAC).

    Parameters
    ----------
    data : bytes
        The file's bytes.

    Returns
    -------
    str
        The decoded text; every byte is a character, none is replaced.
    """
    try:
        return data.decode("utf-8-sig")
    except UnicodeDecodeError:
        return data.decode("latin-1")


@dataclass
class _Sections:
    lines: list[str]
    start: dict[str, int] = field(default_factory=dict)  # section -> index of its title line
    created: dt.date | None = None

    def body(
        self, name: str, *, blank: bool = False, trailing: bool = False
    ) -> list[tuple[int, str]]:
        """(0-based line index, text) of the non-blank lines of a section; with *blank* every
        line up to the last non-blank one (a blank line inside ``[channel units]`` is the unit
        of a unitless channel; the blank lines that end a section separate it from the next),
        with *trailing* too every line to the next section.
        """
        if name not in self.start:
            return []
        i0 = self.start[name] + 1
        later = [i for i in self.start.values() if i > self.start[name]]
        i1 = min(later) if later else len(self.lines)
        out = [(i, ln.strip()) for i, ln in enumerate(self.lines[i0:i1], i0)]
        if not blank:
            return [(i, t) for i, t in out if t]
        while out and not out[-1][1] and not trailing:
            out.pop()
        return out


def _sections(text: str) -> _Sections:
    lines = text.splitlines()
    sec = _Sections(lines)
    for i, ln in enumerate(lines):
        m = _SECTION.match(ln)
        if m:
            name = m.group(1).strip().lower()
            sec.start.setdefault(name, i)
            if name == "data":
                break  # the data rows follow; no section after them
        elif not sec.start and sec.created is None:
            c = _CREATED.search(ln)
            if c:
                d, mo, y = int(c.group(1)), int(c.group(2)), int(c.group(3))
                try:
                    sec.created = dt.date(y, mo, d)
                except ValueError:
                    sec.created = None
    return sec


def _units(sec: _Sections, names: list[str]) -> list[str]:
    """The unit of each column (``""`` when none) from ``[channel units]``: one line per
    column when the section has as many lines as there are columns (blank lines included: a
    Racebobo export's ``rpm`` is the 9th of 10), else one per trailing (module) column (VBOX:
    the lines up to the last unit). A blank line inside the section is the unit of a unitless
    channel and keeps its place.
    """
    every = [_unit_text(u) for _, u in sec.body("channel units", blank=True, trailing=True)]
    if len(every) >= len(names):  # a line per column (and the blank line that ends it)
        return every[: len(names)]
    units = [_unit_text(u) for _, u in sec.body("channel units", blank=True)]
    return [""] * (len(names) - len(units)) + units


_DEGREE_WORD = re.compile(r"^°[\s_]*\(?\s*deg", re.IGNORECASE)


def _unit_text(unit: str) -> str:
    """A unit as VBOX writes it, in the words of :func:`.channels.file_unit_factor`:
    ``(null)`` is no unit; VBOX cuts ``° (Degrees)`` to ``°_(Degree``.
    """
    u = unit.strip()
    if u.lower() == "(null)":
        return ""
    if _DEGREE_WORD.match(u):
        return "°"
    return u


def _join_spaced_names(
    words: list[str], titles: list[str], nfield: int
) -> tuple[list[str], list[str]] | None:
    """``[column names]`` split into *nfield* names when channel names hold spaces: a run of
    words that (joined by a space) begins the ``[header]`` title at the same place is one
    name (``battery vo`` for the title ``battery voltage``). None when that does not give
    *nfield* names.
    """
    if len(titles) != nfield or len(words) <= nfield:
        return None
    out: list[str] = []
    joined: list[str] = []
    p = 0
    for title in titles:
        if p >= len(words):
            return None
        t = " ".join(title.split()).lower()
        m = 1
        for k in range(len(title.split()), 1, -1):
            cand = " ".join(words[p : p + k])
            if len(words[p : p + k]) == k and t.startswith(cand.lower()):
                m = k
                break
        out.append(" ".join(words[p : p + m]))
        if m > 1:
            joined.append(out[-1])
        p += m
    return (out, joined) if p == len(words) and len(out) == nfield else None


_NTH = re.compile(r"^(.*)\[(\d+)\]$")


def _column_of(cols: list[str], channel: str) -> tuple[int | None, list[int]]:
    """Column index of a mapped channel: its name, or ``NAME[k]`` for the k-th column of that
    name (a name ``[column names]`` holds twice); and every column of that name.
    """
    same = [j for j, c in enumerate(cols) if c == channel]
    if same:
        return same[0], same
    m = _NTH.match(channel)
    if m:
        same = [j for j, c in enumerate(cols) if c == m.group(1).strip()]
        k = int(m.group(2))
        if 1 <= k <= len(same):
            return same[k - 1], [same[k - 1]]
    return None, []


def _same_values(a: np.ndarray, idx: list[int]) -> bool:
    x = a[:, idx]
    return bool(np.all((x == x[:, :1]) | (np.isnan(x) & np.isnan(x[:, :1]))))


def _speed_factor(sec: _Sections) -> float:
    for _, title in sec.body("header"):
        t = title.lower()
        if t.startswith("velocity") and "vertical" not in t:
            unit = t.split()[-1] if len(t.split()) > 1 else "kmh"
            return _SPEED_HEADER.get(unit, _KMH)
    return _KMH


def parse_vbo(
    text: str, name: str = "<vbo>", *, columns: str | dict | None = None, strict: bool = False
) -> NmeaLog:
    """Read the text of a ``.vbo`` file into the epoch table (see the module documentation).

    Parameters
    ----------
    text : str
        The file's text.
    name : str
        File name, for messages.
    columns : str or dict, optional
        Further channels (``steer=Steering_Angle:deg``, ``torque=TrqCol``) or overrides of the
        standard ones (:mod:`gripsense.io.logs.channels`).
    strict : bool
        Raise at the first rejected row instead of counting it.

    Returns
    -------
    NmeaLog
        ``epochs``, ``report`` (line accounting) and ``sentences`` (``{"VBO": rows}`` with the
        1-based ``line`` of each epoch).
    """
    sec = _sections(text)
    missing = [s for s in VBO_SECTIONS if s not in sec.start]
    if missing:
        raise InputError(
            f"{name}: not a complete VBOX file: no [{missing[0]}] section (a .vbo has "
            "[column names] and [data]); was the file cut off or edited?"
        )
    d0 = sec.start["data"] + 1
    rows = sec.lines[d0:]
    cols, names_line, structure_notes = _column_names(sec, rows, name)
    role, twice = _roles(cols, name, names_line)
    mapped = parse_channel_spec(columns)
    units = _channel_units(sec, cols, mapped, name)
    used = list(mapped)
    others = list(dict.fromkeys(c for c in cols if _ALIASES.get(c.lower()) is None))
    steering, steer_notes = add_steering(mapped, others, units.get)
    rd = _data_rows(text, rows, d0, cols, role["time"], name, strict, structure_notes)
    a = rd.values
    n = a.shape[0]
    values, yaw_src = _standard_values(a, role, sec)
    ctx = _Columns(a, cols, units, name, names_line, structure_notes)
    steering, yaw_src = _mapped_values(values, mapped, steering, yaw_src, ctx)
    for r, j in role.items():
        same = twice.get(cols[j], [])
        if len(same) > 1 and r != "date":
            where = " and ".join(str(i + 1) for i in same)
            agree = "the same values" if _same_values(a, same) else "different values"
            structure_notes.append(
                f"channel {cols[j]!r} is named {len(same)} times in [column names] (columns "
                f"{where}, {agree}): column {j + 1} read; map another with --columns "
                f"KEY={cols[j]}[2]"
            )
    seconds, has_date = _seconds(a, role, sec)
    hsrc = "channel" if "heading" in mapped else "VBOX"
    epochs = build_epochs(
        values, seconds, has_date=has_date, heading_source=hsrc, yaw_rate_source=yaw_src
    )
    pre_blank = _blank(sec.lines[:d0])
    cut = rd.cut
    report = IngestReport(
        source=name,
        total_lines=len(sec.lines),
        parsed={"VBO data": n} if n else {},
        ignored={
            k: c for k, c in (("(header)", d0 - pre_blank), ("(blank)", rd.blank + pre_blank)) if c
        },
        rejected=rd.rejected,
        first_rejects=rd.rejects,
        n_epochs=n,
        epochs_without_time=0,
        has_date=has_date,
        format="VBOX VBO",
        notes=structure_notes
        + ([f"mapped by --columns: {', '.join(used)}"] if used else [])
        + steer_notes
        + (
            [f"the file ends inside line {d0 + cut + 1} (cut off?): that row is not read"]
            if cut >= 0
            else []
        ),
        steering=steering,
    )
    rows_t = pd.DataFrame(
        {"line": np.asarray(rd.line_idx, dtype=np.int64) + 1, "epoch": np.arange(n)}
    )
    return NmeaLog(epochs=epochs, report=report, sentences={"VBO": rows_t})


def _column_names(sec: _Sections, rows: list[str], name: str) -> tuple[list[str], int, list[str]]:
    """The channel names of ``[column names]`` matched to the rows' field count (names with a
    space joined as ``[header]`` lists them), the section's first line (1-based), and the notes
    on what was read.
    """
    names_lines = sec.body("column names")
    if not names_lines:
        raise InputError(f"{name}:{sec.start['column names'] + 2}: [column names] is empty")
    # the names are the words of every line of the section: VBOX 3i / Video / Touch wrap a
    # long channel list, some tools write one name per line
    cols = [w for _, ln in names_lines for w in ln.split()]
    names_line = names_lines[0][0] + 1
    n_names_lines = len(names_lines)
    on_lines = f" on {n_names_lines} lines" if n_names_lines > 1 else ""
    # the rows' field count (the commonest of the first rows): [column names] must match it
    counts = [len(r.split()) for r in rows[:200] if r.strip()]
    nfield = max(set(counts), key=counts.count) if counts else len(cols)
    notes: list[str] = []
    if len(cols) != nfield:
        titles = [t for _, t in sec.body("header")]
        fixed = _join_spaced_names(cols, titles, nfield)
        if fixed is None:
            spaced = ", ".join(repr(t) for t in titles if " " in t.strip())
            raise InputError(
                f"{name}:{names_line}: [column names] has {len(cols)} names{on_lines} but the "
                f"rows have {nfield} fields"
                + (
                    f" and [header] lists {len(titles)} channels"
                    if titles
                    else " and there is no [header] to tell the channels apart"
                )
                + (f" (names with a space: {spaced})" if spaced else "")
                + "; correct [column names] to one name per field (a name with a space written "
                "with _)"
            )
        cols, joined = fixed
        one = len(joined) == 1
        notes.append(
            f"[column names]: {', '.join(repr(j) for j in joined)} "
            f"{'holds a space: read as one channel' if one else 'hold spaces: each read as one'}"
            f", as [header] lists {'it' if one else 'them'} ({nfield} channels)"
        )
    if n_names_lines > 1:
        titles = [t for _, t in sec.body("header")]
        notes.append(
            f"[column names] spans {n_names_lines} lines: read as one list of {len(cols)} "
            f"names (the rows' {nfield} fields"
            + (f", [header]'s {len(titles)} channels)" if titles else ")")
        )
    return cols, names_line, notes


def _channel_units(
    sec: _Sections, cols: list[str], mapped: dict[str, ChannelSpec], name: str
) -> dict[str, str]:
    """Each channel's unit (``[channel units]``; a ``NAME[k]`` of ``--columns`` takes its own
    column's), after checking that every mapped channel is a column of the file.
    """
    for spec in mapped.values():
        if _column_of(cols, spec.channel)[0] is None:
            raise InputError(
                f"{name}: --columns {spec.key}={spec.channel}: no such column; the file has "
                f"{', '.join(cols[:30])}"
            )
    unit_list = _units(sec, cols)
    units: dict[str, str] = {}
    for c, u in zip(cols, unit_list, strict=True):
        units.setdefault(c, u)
    for spec in mapped.values():  # a NAME[k] takes the unit of its own column
        jm = _column_of(cols, spec.channel)[0]
        assert jm is not None
        units[spec.channel] = unit_list[jm]
    return units


def _roles(
    cols: list[str], name: str, names_line: int
) -> tuple[dict[str, int], dict[str, list[int]]]:
    """Each standard channel's column (the first of its name) and the names given twice."""
    role: dict[str, int] = {}
    twice: dict[str, list[int]] = {}
    for j, c in enumerate(cols):
        r = _ALIASES.get(c.lower())
        if r and r not in role:
            role[r] = j
        if cols.count(c) > 1:
            twice.setdefault(c, []).append(j)
    if "time" not in role:
        raise InputError(f"{name}:{names_line}: [column names] has no 'time' column ({cols[:12]})")
    return role, twice


@dataclass
class _Rows:
    """The data rows read: their values, 0-based line of each, the accounting."""

    values: np.ndarray
    line_idx: list[int]
    rejects: list[RejectedLine]
    rejected: dict[str, int]
    blank: int
    cut: int  # the row the file ends inside (index in the rows; −1: none)


def _data_rows(
    text: str,
    rows: list[str],
    d0: int,
    cols: list[str],
    j_time: int,
    name: str,
    strict: bool,
    notes: list[str],
) -> _Rows:
    """Every line after ``[data]``: one row of numbers, blank, or rejected with its reason."""
    ncol = len(cols)
    blank = 0
    good_idx: list[int] = []
    good_text: list[str] = []
    rejects: list[RejectedLine] = []
    rej_count = dict.fromkeys(REASONS, 0)

    def reject(line: int, reason: str, detail: str) -> None:
        rej_count[reason] += 1
        if strict:
            raise InputError(f"{name}:{line}: {reason}: {detail} (strict mode)")
        if len(rejects) < 20:
            rejects.append(RejectedLine(line, reason, detail))

    cut = _cut_row(text, rows)
    for k, ln in enumerate(rows):
        s = ln.strip()
        if not s:
            blank += 1
            continue
        if k == cut:
            reject(d0 + k + 1, TRUNCATED, "the file ends inside this row (cut off?)")
            continue
        nf = s.count(" ") + 1 if "  " not in s and "\t" not in s else len(s.split())
        if nf != ncol:
            reason = TRUNCATED if nf < ncol else MALFORMED
            reject(d0 + k + 1, reason, f"{nf} fields, [column names] has {ncol}")
            continue
        good_idx.append(d0 + k)
        good_text.append(s)
    if good_text:
        body = "\n".join(good_text)
        if "," in good_text[0] and "." not in good_text[0]:  # decimal commas (a converter's)
            body = body.replace(",", ".")
            notes.append("the rows write decimal commas: read as decimal points")
        try:  # every field a number (the usual file): one parse to floats
            num = pd.read_csv(io.StringIO(body), sep=r"\s+", header=None, dtype=np.float64,
                              engine="c")  # fmt: skip
            bad = np.isnan(num.iloc[:, j_time].to_numpy(float))
        except ValueError:  # a field that is not a number: find the rows
            raw = pd.read_csv(io.StringIO(body), sep=r"\s+", header=None, dtype=str, engine="c")
            num = raw.apply(pd.to_numeric, errors="coerce")
            bad = (num.isna() & raw.notna()).any(axis=1).to_numpy().copy()
            bad |= np.isnan(num.iloc[:, j_time].to_numpy(float))
    else:
        num = pd.DataFrame(np.empty((0, ncol)))
        bad = np.zeros(0, dtype=bool)
    if bad.any():
        for row in np.flatnonzero(bad):
            jj = int(np.flatnonzero(num.iloc[row].isna().to_numpy())[0])
            reject(good_idx[row] + 1, MALFORMED, f"column {cols[jj]!r} is not a number")
        keep = ~bad
        num = num[keep].reset_index(drop=True)
        good_idx = [i for i, k in zip(good_idx, keep, strict=True) if k]
    rejects.sort(key=lambda r: r.line)
    return _Rows(num.to_numpy(float), good_idx, rejects, rej_count, blank, cut)


def _cut_row(text: str, rows: list[str]) -> int:
    """The last row when the file ends inside it (−1 otherwise).

    A last row without its line end and shorter than the rows before it: the file was cut
    inside it (a value cut to fewer digits still has all its fields), so it is rejected, and
    said (fewer fields, or a last field shorter than in the rows before it; a field elsewhere
    written one character shorter — 000.072 after +000.000 — is not a cut).
    """
    if rows and rows[-1].strip() and not text.endswith(("\n", "\r")):
        last = rows[-1].split()
        before = [r.split() for r in rows[-11:-1] if r.strip()]
        if before and (
            len(last) < min(len(b) for b in before)
            or len(last[-1].lstrip("+-")) < min(len(b[-1].lstrip("+-")) for b in before)
        ):
            return len(rows) - 1
    return -1


def _standard_values(
    a: np.ndarray, role: dict[str, int], sec: _Sections
) -> tuple[dict[str, np.ndarray], str | None]:
    """The epoch table's columns from the standard VBOX channels, and the yaw rate's source."""

    def col(r: str) -> np.ndarray | None:
        return a[:, role[r]] if r in role else None

    n = a.shape[0]
    values: dict[str, np.ndarray] = {}
    sats = col("sats")
    if sats is not None:
        s_int = sats.astype(np.int64) if n else np.zeros(0, np.int64)
        values["n_sats"] = (s_int & 63).astype(float)
        fix = np.where(s_int & 63 == 0, 0, np.where(s_int & 128, 2, 1)).astype(float)
        values["fix_quality"] = fix
    sol = col("solution")
    if sol is not None:
        values["fix_quality"] = np.array([_SOLUTION_TO_GGA.get(int(v), np.nan) for v in sol])
    lat, lon = col("lat"), col("long")
    if lat is not None:
        values["lat_deg"] = lat * _MINUTES_TO_DEG
    if lon is not None:
        values["lon_deg"] = -lon * _MINUTES_TO_DEG  # the file's longitude is west positive
    v = col("velocity")
    if v is not None:
        values["speed_mps"] = v * _speed_factor(sec)
    for r, c in (("course", "course_deg"), ("heading", "heading_deg"), ("height", "alt_m")):
        x = col(r)
        if x is not None:
            values[c] = x
    for r in ("pitch", "roll"):
        x = col(r)
        if x is not None:
            values[f"{r}_deg"] = x
    yaw_src = None
    yr = col("yaw_rate")
    if yr is not None:
        values["yaw_rate_rps"] = -np.deg2rad(yr)  # clockwise (compass) -> ISO
        yaw_src = "VBOX"
    return values, yaw_src


@dataclass
class _Columns:
    """What the mapped channels are read against: the rows' values, the names, units, file
    name, the names' line and the notes.
    """

    a: np.ndarray
    cols: list[str]
    units: dict[str, str]
    name: str
    names_line: int
    notes: list[str]


def _mapped_values(
    values: dict[str, np.ndarray],
    mapped: dict,
    steering: dict,
    yaw_src: str | None,
    c: _Columns,
) -> tuple[dict, str | None]:
    """The ``--columns`` channels (and a steering channel found by its name) into *values*; a
    name given twice is read when its columns agree, else said or refused. Returns the steering
    record and the yaw rate's source.
    """
    for spec in list(mapped.values()):
        jm, same = _column_of(c.cols, spec.channel)
        assert jm is not None
        if len(same) > 1:
            where = " and ".join(str(i + 1) for i in same)
            found = steering.get("source") == "name and unit" and steering["key"] == spec.key
            if found and not _same_values(c.a, same):  # found by its name: not used, said
                del mapped[spec.key]
                steering = {}
                c.notes.append(
                    f"steering channel {spec.channel!r} is named {len(same)} times in [column "
                    f"names] (columns {where}) with different values: not used; map one with "
                    f"--columns {spec.key}={spec.channel}[1] (or [2])"
                )
                continue
            if not _same_values(c.a, same):
                options = " or ".join(
                    f"{spec.key}={spec.channel}[{k}]" for k in range(1, len(same) + 1)
                )
                raise InputError(
                    f"{c.name}:{c.names_line}: channel {spec.channel!r} ({spec.key}) is named "
                    f"{len(same)} times in [column names] (columns {where}) and their values "
                    f"differ; say which with --columns {options}"
                )
            c.notes.append(
                f"channel {spec.channel!r} ({spec.key}) is named {len(same)} times in [column "
                f"names] (columns {where}) with the same values: column {jm + 1} read"
            )
        _mapped_channel(values, spec, c.a[:, jm], c.units, c.name)
        if spec.key == "yaw_rate":
            yaw_src = "channel"
    return steering, yaw_src


def _seconds(a: np.ndarray, role: dict[str, int], sec: _Sections) -> tuple[np.ndarray, bool]:
    """Seconds of each row: hhmmss.ss of day, rolled over at midnight, on the file's date (of
    the ``date`` channel or the file's creation; without one, of day 0). Also: whether a date
    was known.
    """
    n = a.shape[0]
    hms = a[:, role["time"]]
    tod = (hms // 10000) * 3600 + ((hms // 100) % 100) * 60 + hms % 100
    roll = np.concatenate([[0], np.cumsum(np.diff(tod) < -43200)]) if n else np.zeros(0)
    tod = tod + 86400.0 * roll
    day = _day(a[:, role["date"]] if "date" in role else None, sec.created)
    return tod + (day if day is not None else 0.0), day is not None


def _blank(lines: list[str]) -> int:
    return sum(1 for ln in lines if not ln.strip())


def _day(date_col: np.ndarray | None, created: dt.date | None) -> float | None:
    """Seconds since 1970 of the log's first day (``Date`` column ddmmyy, else the preamble)."""
    if date_col is not None and date_col.size and np.isfinite(date_col[0]) and date_col[0] > 0:
        d = int(date_col[0])
        try:
            day = dt.date(2000 + d % 100, (d // 100) % 100, d // 10000)
        except ValueError:
            day = None
        if day is not None:
            return float((day - dt.date(1970, 1, 1)).days * 86400)
    if created is not None:
        return float((created - dt.date(1970, 1, 1)).days * 86400)
    return None


def _mapped_channel(
    values: dict, spec: ChannelSpec, raw: np.ndarray, units: dict[str, str], name: str
) -> None:
    from gripsense.io.logs.channels import CHANNEL_KEYS

    column = CHANNEL_KEYS[spec.key].column
    values[column] = spec.column_values(raw, units.get(spec.channel), f"{name} [channel units]")


def read_vbo(
    path: str | Path, *, columns: str | dict | None = None, strict: bool = False
) -> NmeaLog:
    """Read a Racelogic VBOX ``.vbo`` file (see the module documentation).

    Parameters
    ----------
    path : str or Path
        The file (plain text; gzip is decompressed by :func:`gripsense.io.logs.read_log`).
    columns : str or dict, optional
        Further channels to read (:mod:`gripsense.io.logs.channels`).
    strict : bool
        Raise at the first rejected row.

    Returns
    -------
    NmeaLog
        Epoch table and line accounting.
    """
    from gripsense.io.text import read_bytes

    return parse_vbo(decode_vbo(read_bytes(path, "VBOX file")), str(path), columns=columns,
                     strict=strict)  # fmt: skip


def _minutes(deg: np.ndarray) -> list[str]:
    return [f"{m:+014.8f}" for m in deg * 60.0]


def write_vbo(
    epochs: pd.DataFrame,
    path: str | Path,
    *,
    steer: pd.DataFrame | None = None,
    created: str = "VBOX 3i dual antenna (emulated by gripsense)",
) -> None:
    """Write an epoch table as a VBOX 3i dual-antenna ``.vbo`` file.

    Parameters
    ----------
    epochs : pandas.DataFrame
        ``time_utc``, ``lat_deg``, ``lon_deg``, ``alt_m``, ``speed_mps``, ``course_deg``,
        ``heading_deg``, ``yaw_rate_rps`` (ISO) and optionally ``n_sats``.
    path : str or Path
        Output file.
    steer : pandas.DataFrame, optional
        ``t_s`` (the epochs' clock) and ``road_wheel_deg`` (ISO, left positive): interpolated
        onto the rows as the module channel ``RoadWheelAngle``, its unit in
        ``[channel units]``.
    created : str
        The ``[comments]`` line naming the device.
    """
    t = pd.DatetimeIndex(epochs["time_utc"])
    first = t[0]
    sats = epochs["n_sats"].fillna(12).to_numpy(int) if "n_sats" in epochs else np.full(len(t), 12)
    tod = (t - t.normalize()).total_seconds().to_numpy()
    hms = [f"{int(s // 3600):02d}{int(s // 60 % 60):02d}{s % 60:06.3f}" for s in np.round(tod, 3)]
    cols = {
        "sats": [f"{s:03d}" for s in sats],
        "time": hms,
        "lat": _minutes(epochs["lat_deg"].to_numpy(float)),
        "long": _minutes(-epochs["lon_deg"].to_numpy(float)),
        "velocity": [f"{v:07.3f}" for v in epochs["speed_mps"].to_numpy(float) * 3.6],
        "heading": [f"{h:06.2f}" for h in epochs["course_deg"].to_numpy(float)],
        "height": [f"{h:+08.2f}" for h in epochs["alt_m"].to_numpy(float)],
        "True_Head": [f"{h:07.3f}" for h in np.mod(epochs["heading_deg"].to_numpy(float), 360)],
        "Yaw_Rate": [f"{r:+08.3f}" for r in -np.rad2deg(epochs["yaw_rate_rps"].to_numpy(float))],
    }
    header = ["satellites", "time", "latitude", "longitude", "velocity kmh", "heading", "height",
              "True Heading", "Yaw Rate"]  # fmt: skip
    units = []
    if steer is not None:
        ok = steer["road_wheel_deg"].notna().to_numpy()  # a table of several rates
        a = np.interp(epochs["t_s"].to_numpy(float), steer["t_s"].to_numpy(float)[ok],
                      steer["road_wheel_deg"].to_numpy(float)[ok])  # fmt: skip
        cols["RoadWheelAngle"] = [f"{x:+.6E}" for x in a]
        header.append("RoadWheelAngle")
        units.append("deg")
    rows = [" ".join(r) for r in zip(*cols.values(), strict=True)]
    text = "\n".join(
        [
            f"File created on {first.day:02d}/{first.month:02d}/{first.year} @ "
            f"{first.hour:02d}:{first.minute:02d}:{first.second:02d}",
            "",
            "[header]",
            *header,
            "",
            "[channel units]",
            *units,
            "",
            "[comments]",
            created,
            f"Log Rate (Hz) : {1 / np.median(np.diff(tod)):.2f}"
            if len(tod) > 1
            else "Log Rate (Hz) : 0",
            "",
            "[column names]",
            " ".join(cols),
            "",
            "[data]",
            *rows,
            "",
        ]
    )
    Path(path).write_text(text, encoding="ascii", newline="\r\n")


def read_vbo_log(src: LogInput) -> NmeaLog:
    """Read a VBOX file as :func:`gripsense.io.logs.read_log` hands it over (its registry
    entry): its bytes decoded (:func:`decode_vbo`: VBOX files are Latin-1), then
    :func:`parse_vbo`.

    Parameters
    ----------
    src : gripsense.io.logs.options.LogInput
        The log's bytes, name and options (``columns``, ``strict``).

    Returns
    -------
    NmeaLog
        Epoch table and line accounting.
    """
    text = decode_vbo(src.data) if src.data else ""
    return parse_vbo(text, src.name, columns=src.options.columns, strict=src.options.strict)


def write_vbo_log(
    epochs: pd.DataFrame,
    path: Path,
    *,
    nmea_lines: list[str] | None = None,
    steer: pd.DataFrame | None = None,
) -> str | None:
    """Write a drive as a VBOX file for :func:`gripsense.io.logs.write_log` (:func:`write_vbo`).

    Parameters
    ----------
    epochs : pandas.DataFrame
        The drive's epoch table.
    path : Path
        Output file.
    nmea_lines : list of str, optional
        Unused.
    steer : pandas.DataFrame, optional
        ``t_s`` and ``road_wheel_deg``: the steering channel written inside.

    Returns
    -------
    str or None
        The ``--columns`` that read the steering channel back, or None without one.
    """
    write_vbo(epochs, path, steer=steer)
    return "steer=RoadWheelAngle" if steer is not None else None
