"""Read and write Magic Formula tyre property files (``.tir``, MDI/ADAMS "TeimOrbit" format).

The format as found in real files (MFeval examples, TNO, Calspan/Goodyear, Project Chrono):

* ``[SECTION]`` headers (any case; trailing blanks allowed);
* ``KEY = value  $comment`` entries, separated by blanks or tabs; the value is a number (``1.5``,
  ``-3e-4``, Fortran ``1.0D+03``), a quoted string (``'meter'`` or ``"meter"``) or empty;
* whole-line comments starting with ``$`` or ``!``;
* tables without ``=`` (``[SHAPE]`` rows, ``{radial width}`` headers), kept verbatim;
* LF or CRLF line endings.

:class:`TirFile` keeps every line, so writing a file that was read gives the same bytes back, and a
changed value is re-written in place (shortest repr that round-trips). Lookups are
case-insensitive. :meth:`TirFile.parameters` returns a flat ``{KEY: value}`` dict converted to SI
using the ``[UNITS]`` section (only the keys with a physical dimension are converted: the
Magic Formula coefficients themselves are dimensionless by construction).
"""

from __future__ import annotations

import difflib
import math
import re
from dataclasses import dataclass
from pathlib import Path
from typing import IO

from gripsense.errors import InputError
from gripsense.io.text import InputStream
from gripsense.io.tyres.tir_keys import CHECKED_KEYS

__all__ = ["MAX_TIR_BYTES", "TirError", "TirFile", "read_tir", "write_tir"]

MAX_TIR_BYTES = 16 << 20
"""Largest (decompressed) ``.tir`` file read [bytes]: a tyre property file is a few tens of
kilobytes, so a ``.gz`` that expands beyond this (a gzip bomb) is refused, not decompressed."""
_TIR_LIMIT = "the most a .tir file may hold (a tyre property file is a few tens of kB)"


class TirError(InputError):
    """A ``.tir`` file that cannot be read or lacks a mandatory key."""


_SECTION = re.compile(r"^\s*\[\s*([A-Za-z0-9_ ]+?)\s*\]\s*$")
_ENTRY = re.compile(r"^\s*([A-Za-z_][A-Za-z0-9_]*)\s*=(.*)$")


@dataclass
class _Line:
    kind: str  # "entry" | "section" | "comment" | "other"
    text: str  # verbatim line without its line ending
    section: str = ""
    key: str = ""
    value: float | int | str | None = None
    # entry text split around the value so a changed value can be written in place
    prefix: str = ""
    raw_value: str = ""
    suffix: str = ""
    lineno: int = 0


def _parse_value(raw: str, where: str) -> float | int | str | None:
    s = raw.strip()
    if s == "":
        return None
    if s[0] in "'\"":
        if len(s) < 2 or s[-1] != s[0]:
            raise TirError(f"{where}: unterminated quoted string {s!r}; close it with {s[0]}")
        return s[1:-1]
    t = s.replace("D", "E").replace("d", "e")
    try:
        if re.fullmatch(r"[+-]?\d+", t):
            return int(t)
        return float(t)
    except ValueError:
        # bare words (e.g. LEFT without quotes) are kept as strings
        if re.fullmatch(r"[A-Za-z_][A-Za-z0-9_.]*", s):
            return s
        raise TirError(
            f"{where}: cannot read value {s!r}; expected a number or a quoted string"
        ) from None


def _split_entry(rest: str) -> tuple[str, str, str]:
    """Split the text after ``=`` into (leading blanks, value text, trailing blanks + comment)."""
    i = 0
    while i < len(rest) and rest[i] in " \t":
        i += 1
    lead = rest[:i]
    body = rest[i:]
    if body[:1] in ("'", '"'):
        q = body[0]
        end = body.find(q, 1)
        end = len(body) if end < 0 else end + 1
    else:
        m = re.search(r"[ \t$!]", body)
        end = len(body) if m is None else m.start()
    return lead, body[:end], body[end:]


def _format_number(value: float | int) -> str:
    if isinstance(value, bool):
        raise TypeError("booleans are not .tir values")
    if isinstance(value, int):
        return str(value)
    if not math.isfinite(value):
        raise ValueError(f"cannot write non-finite value {value!r} to a .tir file")
    return repr(float(value))


def _new_entry(section: str, key: str, value, comment: str | None) -> _Line:
    """A ``KEY = value  $comment`` line in the layout TNO and MFeval files use."""
    raw = _format_value(value)
    pre = f"{key:<25}= "
    suf = "" if comment is None else " " * max(1, 16 - len(raw)) + f"${comment}"
    return _Line(
        "entry",
        pre + raw + suf,
        section=section,
        key=key,
        value=value,
        prefix=pre,
        raw_value=raw,
        suffix=suf,
    )


def _format_value(value: float | int | str | None) -> str:
    if value is None:
        return ""
    if isinstance(value, str):
        return f"'{value}'"
    return _format_number(value)


class TirFile:
    """A parsed ``.tir`` file that remembers its layout.

    Use :func:`read_tir` to read one and :meth:`to_text` / :func:`write_tir` to write it.

    Parameters
    ----------
    lines : list
        Parsed lines (entries, comments, sections) in file order.
    newline : str
        Line ending written back.
    name : str
        Name used in messages.
    final_newline : bool
        Whether the file ended with a newline.
    """

    def __init__(
        self,
        lines: list[_Line],
        newline: str = "\n",
        name: str = "<tir>",
        final_newline: bool = True,
    ) -> None:
        self._lines = lines
        self.newline = newline
        self.name = name
        self._final_newline = final_newline
        self.encoding = "utf-8"
        self.warnings: list[str] = []  #: unknown keys read with ``lenient=True``
        self._reindex()

    def _reindex(self) -> None:
        # first occurrence wins for lookups, as in MFeval/TNO readers; duplicates are kept
        self._index: dict[str, int] = {}
        for i, ln in enumerate(self._lines):
            if ln.kind == "entry":
                self._index.setdefault(ln.key.upper(), i)

    # ------------------------------------------------------------------ construction
    @classmethod
    def from_sections(
        cls,
        sections: dict[str, dict[str, float | int | str | None]],
        *,
        comments: dict[str, str] | None = None,
        header: list[str] | None = None,
        name: str = "<tir>",
    ) -> TirFile:
        """Build a file from ``{SECTION: {KEY: value}}`` (values in the file's units).

        Parameters
        ----------
        sections : dict
            Ordered sections and entries.
        comments : dict, optional
            ``{KEY: comment}`` written after the value as ``$comment``.
        header : list of str, optional
            Comment lines written first (prefixed with ``!`` if not already a comment).
        name : str
            Name used in messages.
        """
        comments = {k.upper(): v for k, v in (comments or {}).items()}
        lines: list[_Line] = []
        for h in header or []:
            txt = h if h[:1] in ("!", "$") else f"! {h}"
            lines.append(_Line("comment", txt))
        for sec, entries in sections.items():
            sec_u = sec.upper()
            lines.append(_Line("comment", "$" + "-" * (70 - len(sec_u)) + sec_u.lower()))
            lines.append(_Line("section", f"[{sec_u}]", section=sec_u))
            for key, value in entries.items():
                key_u = key.upper()
                lines.append(_new_entry(sec_u, key_u, value, comments.get(key_u)))
        return cls(lines, "\n", name)

    # ------------------------------------------------------------------ access
    def prepend_comment(self, text: str) -> None:
        """Add a ``$`` comment line at the top of the file.

        Parameters
        ----------
        text : str
            The comment (one line).
        """
        self._lines.insert(0, _Line("comment", f"$ {text}"))

    def __contains__(self, key: object) -> bool:
        return isinstance(key, str) and key.upper() in self._index

    def __getitem__(self, key: str) -> float | int | str | None:
        try:
            return self._lines[self._index[key.upper()]].value
        except KeyError:
            raise TirError(f"{self.name}: no key {key.upper()} in the file") from None

    def get(self, key: str, default: float | int | str | None = None) -> float | int | str | None:
        """Value of ``key`` (any case) as written in the file, or ``default``.

        Parameters
        ----------
        key : str
            Key, any case.
        default : object
            Returned when the key is absent.
        """
        i = self._index.get(key.upper())
        return default if i is None else self._lines[i].value

    def section_of(self, key: str) -> str | None:
        """Section that holds ``key`` (upper case), or None.

        Parameters
        ----------
        key : str
            Key, any case.
        """
        i = self._index.get(key.upper())
        return None if i is None else self._lines[i].section

    def keys(self) -> list[str]:
        """All keys in file order (upper case, first occurrence)."""
        return list(self._index)

    @property
    def sections(self) -> dict[str, dict[str, float | int | str | None]]:
        """``{SECTION: {KEY: value}}`` in file order (values as written, not converted)."""
        out: dict[str, dict[str, float | int | str | None]] = {}
        for ln in self._lines:
            if ln.kind == "section":
                out.setdefault(ln.section, {})
            elif ln.kind == "entry":
                out.setdefault(ln.section, {}).setdefault(ln.key.upper(), ln.value)
        return out

    def table(self, section: str) -> list[str]:
        """Verbatim non-entry, non-comment lines of ``section`` (e.g. the ``[SHAPE]`` rows).

        Parameters
        ----------
        section : str
            Section name.
        """
        sec = section.upper()
        return [ln.text for ln in self._lines if ln.kind == "other" and ln.section == sec]

    def set(
        self,
        key: str,
        value: float | int | str | None,
        section: str | None = None,
        comment: str | None = None,
    ) -> None:
        """Set ``key`` to ``value`` (file units). Existing keys are changed in place; new keys are
        appended to ``section`` (created at the end when missing).

        Parameters
        ----------
        key : str
            Key, any case.
        value : float, int, str or None
            New value (in the file's units).
        section : str, optional
            Section for a new key.
        comment : str, optional
            Inline comment of a new entry.
        """
        key_u = key.upper()
        raw = _format_value(value)
        i = self._index.get(key_u)
        if i is not None:
            ln = self._lines[i]
            ln.value, ln.raw_value = value, raw
            ln.text = ln.prefix + raw + ln.suffix
            return
        if section is None:
            raise TirError(f"{self.name}: new key {key_u} needs a section")
        sec = section.upper()
        new = _new_entry(sec, key_u, value, comment)
        last = None
        for j, ln in enumerate(self._lines):
            if ln.section == sec and ln.kind in ("entry", "section", "other"):
                last = j
        if last is None:
            self._lines.append(_Line("section", f"[{sec}]", section=sec))
            last = len(self._lines) - 1
        self._lines.insert(last + 1, new)
        self._reindex()

    # ------------------------------------------------------------------ units
    def units(self) -> dict[str, str]:
        """The ``[UNITS]`` section, lower-cased; SI defaults for missing entries."""
        u = {
            "LENGTH": "meter",
            "FORCE": "newton",
            "ANGLE": "radian",
            "MASS": "kg",
            "TIME": "second",
        }
        for k, v in self.sections.get("UNITS", {}).items():
            if isinstance(v, str):
                u[k] = v
        return {k: v.strip().lower() for k, v in u.items()}

    def parameters(self) -> dict[str, float | int | str | None]:
        """Flat ``{KEY: value}`` with dimensional values converted to SI (see module doc)."""
        factors = _unit_factors(self.units(), self.name)
        out: dict[str, float | int | str | None] = {}
        for key in self._index:
            v = self.get(key)
            dim = _DIMENSION.get(key)
            if dim is not None and isinstance(v, (int, float)) and not isinstance(v, bool):
                f = _dimension_factor(dim, factors)
                v = v * f if f != 1.0 else v
            out[key] = v
        return out

    # ------------------------------------------------------------------ output
    def to_text(self) -> str:
        """The file as text, with the original line endings."""
        body = self.newline.join(ln.text for ln in self._lines)
        return body + (self.newline if self._final_newline else "")


# ---------------------------------------------------------------------- units
_UNIT_NAMES = {
    "LENGTH": {
        "meter": 1.0,
        "meters": 1.0,
        "metre": 1.0,
        "m": 1.0,
        "millimeter": 1e-3,
        "millimeters": 1e-3,
        "mm": 1e-3,
        "centimeter": 1e-2,
        "cm": 1e-2,
        "kilometer": 1e3,
        "km": 1e3,
        "inch": 0.0254,
        "in": 0.0254,
        "foot": 0.3048,
        "feet": 0.3048,
        "ft": 0.3048,
    },
    "FORCE": {
        "newton": 1.0,
        "newtons": 1.0,
        "n": 1.0,
        "kilonewton": 1e3,
        "kn": 1e3,
        "pound_force": 4.4482216152605,
        "lbf": 4.4482216152605,
        "kilogram_force": 9.80665,
        "kgf": 9.80665,
    },
    "ANGLE": {
        "radian": 1.0,
        "radians": 1.0,
        "rad": 1.0,
        "degree": math.pi / 180,
        "degrees": math.pi / 180,
        "deg": math.pi / 180,
    },
    "MASS": {
        "kg": 1.0,
        "kilogram": 1.0,
        "kilograms": 1.0,
        "gram": 1e-3,
        "g": 1e-3,
        "tonne": 1e3,
        "pound_mass": 0.45359237,
        "lbm": 0.45359237,
    },
    "TIME": {
        "second": 1.0,
        "seconds": 1.0,
        "sec": 1.0,
        "s": 1.0,
        "millisecond": 1e-3,
        "ms": 1e-3,
        "minute": 60.0,
        "min": 60.0,
        "hour": 3600.0,
        "h": 3600.0,
    },
    "PRESSURE": {
        "pascal": 1.0,
        "pa": 1.0,
        "kpa": 1e3,
        "kilopascal": 1e3,
        "bar": 1e5,
        "psi": 6894.757293168,
        "mpa": 1e6,
    },
}

# key -> exponents of (LENGTH, FORCE, ANGLE, MASS, TIME); "PRESSURE" handled separately
_DIMENSION: dict[str, tuple[int, int, int, int, int] | str] = {
    **{
        k: (1, 0, 0, 0, 0)
        for k in (
            "UNLOADED_RADIUS",
            "WIDTH",
            "RIM_RADIUS",
            "RIM_WIDTH",
            "BOTTOM_OFFST",
            "ROAD_INCREMENT",
        )
    },
    **{k: (1, 0, 0, 0, -1) for k in ("LONGVL", "VXLOW")},
    **{k: (0, 1, 0, 0, 0) for k in ("FNOMIN", "FZMIN", "FZMAX")},
    **{
        k: (-1, 1, 0, 0, 0)
        for k in (
            "VERTICAL_STIFFNESS",
            "LONGITUDINAL_STIFFNESS",
            "LATERAL_STIFFNESS",
            "BOTTOM_STIFF",
        )
    },
    "VERTICAL_DAMPING": (-1, 1, 0, 0, 1),
    **{k: (0, 0, 1, 0, 0) for k in ("ALPMIN", "ALPMAX", "CAMMIN", "CAMMAX")},
    **{k: (0, 0, 0, 1, 0) for k in ("MASS", "BELT_MASS")},
    **{k: (2, 0, 0, 1, 0) for k in ("IXX", "IYY", "BELT_IXX", "BELT_IYY")},
    **{k: "PRESSURE" for k in ("INFLPRES", "NOMPRES", "PRESMIN", "PRESMAX")},
}


def _unit_factors(units: dict[str, str], name: str) -> dict[str, float]:
    out: dict[str, float] = {}
    for dim, table in _UNIT_NAMES.items():
        if dim not in units:
            continue
        u = units[dim].replace(" ", "_")
        if u not in table:
            raise TirError(
                f"{name}: [UNITS] {dim} = '{units[dim]}' is not a known unit; "
                f"use one of {', '.join(sorted(table))}"
            )
        out[dim] = table[u]
    return out


def _dimension_factor(dim: tuple[int, int, int, int, int] | str, f: dict[str, float]) -> float:
    if dim == "PRESSURE":
        if "PRESSURE" in f:
            return f["PRESSURE"]
        return f["FORCE"] / f["LENGTH"] ** 2
    assert not isinstance(dim, str)
    names = ("LENGTH", "FORCE", "ANGLE", "MASS", "TIME")
    out = 1.0
    for n, e in zip(names, dim, strict=True):
        if e:
            out *= f[n] ** e
    return out


# ---------------------------------------------------------------------- read / write
_POSITIVE = ("FNOMIN", "UNLOADED_RADIUS", "NOMPRES", "LONGVL")


def _parse(text: str, name: str, lenient: bool = False) -> TirFile:
    newline = "\r\n" if "\r\n" in text else "\n"
    final_nl = text.endswith("\n")
    raw_lines = text.split("\n")
    if final_nl:
        raw_lines = raw_lines[:-1]
    lines: list[_Line] = []
    section = ""
    seen: dict[tuple[str, str], int] = {}
    warnings: list[str] = []
    for n, raw in enumerate(raw_lines, start=1):
        line = raw[:-1] if raw.endswith("\r") else raw
        stripped = line.strip()
        if stripped == "" or stripped[0] in "$!":
            lines.append(_Line("comment", line, section=section, lineno=n))
            continue
        m = _SECTION.match(line)
        if m:
            section = m.group(1).strip().upper().replace(" ", "_")
            lines.append(_Line("section", line, section=section, lineno=n))
            continue
        if stripped.startswith("["):
            raise TirError(
                f"{name} line {n}: {stripped[:40]!r} is not a section header; close it with ']'"
            )
        m = _ENTRY.match(line)
        if m:
            key = m.group(1).upper()
            where = f"{name} line {n} ({key})"
            if (section, key) in seen:
                raise TirError(
                    f"{where}: {key} is given twice in [{section}] (first on line "
                    f"{seen[section, key]}); keep one"
                )
            seen[section, key] = n
            rest = m.group(2)
            lead, val, suf = _split_entry(rest)
            prefix = line[: m.start(2)] + lead
            value = _parse_value(val, where)
            if isinstance(value, float) and not math.isfinite(value):
                raise TirError(f"{where}: {value!r} is not a finite number")
            if key in _POSITIVE and isinstance(value, int | float) and value <= 0:
                raise TirError(f"{where}: = {value} must be > 0")
            known = CHECKED_KEYS.get(section)
            if known is not None and key not in known:
                close = difflib.get_close_matches(key, sorted(known), n=1, cutoff=0.7)
                hint = f"did you mean {close[0]}?" if close else "not an MF-Tyre key"
                msg = f"{where}: unknown key in [{section}]; {hint}"
                if not lenient:
                    raise TirError(msg + " (--lenient reads it with a warning)")
                warnings.append(msg)
            lines.append(
                _Line(
                    "entry",
                    line,
                    section=section,
                    key=key,
                    value=value,
                    prefix=prefix,
                    raw_value=val,
                    suffix=suf,
                    lineno=n,
                )
            )
            continue
        if section:
            lines.append(_Line("other", line, section=section, lineno=n))
            continue
        raise TirError(
            f"{name} line {n}: cannot read {stripped[:60]!r}; expected [SECTION], "
            "KEY = value or a $/! comment"
        )
    if not any(ln.kind == "entry" for ln in lines):
        raise TirError(f"{name}: no KEY = value entries; is this a .tir file?")
    # table rows (no '=') belong to table sections such as [SHAPE]; in a section of entries a
    # line without '=' is a broken entry
    with_entries = {ln.section for ln in lines if ln.kind == "entry"}
    for ln in lines:
        if ln.kind == "other" and ln.section in with_entries:
            raise TirError(
                f"{name} line {ln.lineno}: {ln.text.strip()[:60]!r} in [{ln.section}] is not "
                "KEY = value"
            )
    tir = TirFile(lines, newline, name, final_nl)
    tir.warnings = warnings
    return tir


def read_tir(source: str | Path | IO[str] | IO[bytes], *, lenient: bool = False) -> TirFile:
    """Read a ``.tir`` property file.

    Parameters
    ----------
    source : path, or text/binary file object
        A path (plain or ``.gz``; a regular file or a pipe; at most :data:`MAX_TIR_BYTES`
        decompressed) or an open file. Text is decoded as UTF-8, falling back to
        Latin-1 (TNO files sometimes carry ``°`` in comments).
    lenient : bool
        Read unknown keys in the sections gripsense uses with a warning (``TirFile.warnings``)
        instead of an error — for vendor files with extra keys.

    Returns
    -------
    TirFile
    """
    if isinstance(source, (str, Path)):
        path = Path(source)
        # read once (a pipe too), gzip decompressed on the fly and bounded: a .gz that expands
        # beyond MAX_TIR_BYTES (a gzip bomb) is refused before it fills memory
        src = InputStream(path, "file")
        try:
            inp = src.read(MAX_TIR_BYTES, count_rest=False, flags=(_TIR_LIMIT, ""))
        except InputError as e:
            raise TirError(str(e)) from None
        if src.gzip and inp.notes:
            raise TirError(f"{path}: not a readable .gz file ({inp.notes[0]})")
        data: str | bytes = inp.data
        name = str(path)
    else:
        data = source.read()
        name = getattr(source, "name", "<stream>")
    encoding = "utf-8"
    if isinstance(data, bytes):
        try:
            text = data.decode("utf-8")
        except UnicodeDecodeError:
            encoding = "latin-1"
            text = data.decode(encoding)
    else:
        text = data
    tir = _parse(text, str(name), lenient)
    tir.encoding = encoding
    return tir


def write_tir(tir: TirFile, path: str | Path) -> Path:
    """Write ``tir`` to ``path`` exactly as :meth:`TirFile.to_text` gives it.

    Parameters
    ----------
    tir : TirFile
        The file.
    path : str or Path
        Output path.
    """
    path = Path(path)
    path.write_bytes(tir.to_text().encode(tir.encoding))
    return path
