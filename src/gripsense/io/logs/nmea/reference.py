"""Reference NMEA 0183 tokenizer: one line at a time, in plain Python.

It defines what a valid line is; the vectorised tokenizer (:mod:`gripsense.io.logs.nmea.fast`) must
give identical results, which the test suite checks on real logs and on fuzzed input. It is
also used to word the details of rejected lines.

Classification of one line (after stripping spaces, tabs and CR at both ends):

1. empty -> ignored ``(blank)``; starting with ``#`` -> ignored ``(comment)``.
2. The sentence starts at the last ``$`` or ``!`` before the last ``*`` (or before the end when
   there is no ``*``); bytes before it are junk (counted in ``junk_prefix``). None -> *not NMEA*.
3. The address (up to the first comma) must be 5 characters ``[A-Z0-9]`` not starting with ``P``
   (standard: talker + formatter) or ``P`` plus 2 to 7 such characters (proprietary);
   otherwise *not NMEA*. The type of a standard sentence is its formatter (``GGA`` whatever the
   talker); of a proprietary one its address, plus field 1 for the makers that put a sub-type
   there (``PSAT,HPR``, ``PASHR,POS``, ``PTNL,AVR``; :data:`SUBTYPED`).
4. Checksum: no ``*`` -> *truncated* if the known sentence has fewer fields than it needs, else
   *missing checksum* (in a log none of whose sentences has a checksum, the sentence is read
   on: ``no_checksum``); fewer than two characters after ``*`` -> *truncated*; anything but
   exactly two hex digits, or a mismatch of the XOR of the bytes between start and ``*`` ->
   *bad checksum*.
5. Bytes outside printable ASCII -> *malformed field*.
6. Unknown type -> ignored (by type; a proprietary one as ``KEY (proprietary, not used)``);
   known type with too few fields -> *truncated*; a field
   that does not match its kind, or is longer than 64 characters -> *malformed field*.
"""

from __future__ import annotations

import re

import numpy as np

from gripsense.io.logs.nmea import schema as S
from gripsense.io.logs.nmea.tokens import (
    IGNORED,
    PARSED,
    REJECTED,
    STRIP,
    Tokens,
    empty_raw,
    split_lines,
)

__all__ = ["classify_line", "tokenize_reference"]

_PATTERNS = {
    S.NUM: re.compile(rb"[+-]?(?:[0-9]+\.?[0-9]*|\.[0-9]+)"),
    S.UNUM: re.compile(rb"(?:[0-9]+\.?[0-9]*|\.[0-9]+)"),
    S.INT: re.compile(rb"[0-9]+"),
    S.TIME: re.compile(rb"[0-9]{6}(?:\.[0-9]*)?"),
    S.DATE: re.compile(rb"[0-9]{6}"),
    S.MODES: re.compile(b"[" + "".join(S.MODE_QUALITY).encode() + b"]+"),
}
_ADDR = re.compile(rb"[A-Z0-9]+")
_SUB = re.compile(rb"[A-Za-z0-9]+")  # a sub-type may be mixed case (Furuno $PFEC,GPatt)
MAX_ADDRESS = 8  # longest address (and proprietary sub-type) accepted [characters]
# proprietary addresses whose type includes field 1 (HPR, 036, POS …): Hemisphere, SkyTraq,
# Ashtech/Spectra, Trimble, u-blox, Septentrio, Furuno
SUBTYPED = ("PSAT", "PSTI", "PASHR", "PTNL", "PUBX", "PSSN", "PFEC")
# ... except where field 1 holds a time: $PASHR,hhmmss.ss,… (OxTS/Ashtech attitude) is PASHR
TIME_FIRST = ("PASHR",)
UNUSED = " (proprietary, not used)"  # label of a well-formed proprietary sentence not read
_HEX = re.compile(rb"[0-9A-Fa-f]{2}")


def type_key(addr: bytes, rest: bytes) -> str | None:
    """Type key of a valid address, or None when the address is not NMEA.

    A proprietary sentence gripsense does not read is labelled ``KEY (proprietary, not
    used)`` (it is counted as ignored, never as malformed).
    """
    if len(addr) > MAX_ADDRESS or not _ADDR.fullmatch(addr):
        return None
    if addr[:1] == b"P":
        if len(addr) < 3:
            return None
        key = addr.decode()
        if key in SUBTYPED:
            sub = rest.split(b",", 1)[0]
            if (
                sub
                and len(sub) <= MAX_ADDRESS
                and _SUB.fullmatch(sub)
                and not (key in TIME_FIRST and sub[:1].isdigit())
            ):
                key = key + "," + sub.decode()
        return key if key in S.SENTENCES else key + UNUSED
    if len(addr) != 5:
        return None
    return addr[2:].decode()


def classify_line(raw: bytes, no_checksum: bool = False) -> tuple[int, str, str, dict | None, bool]:
    r"""Classify one line.

    Parameters
    ----------
    raw : bytes
        The line without its ``\\n`` terminator.
    no_checksum : bool
        Read a sentence without ``*hh`` (bytes outside printable ASCII: *malformed field*)
        instead of rejecting it as *missing checksum* — for a log none of whose sentences
        carries a checksum.

    Returns
    -------
    outcome : int
        ``PARSED``, ``IGNORED`` or ``REJECTED``.
    label : str
        Type key (parsed, ignored) or reject reason.
    detail : str
        Human-readable detail for a reject ('' otherwise).
    values : dict or None
        Raw field values of a parsed sentence (float, or int byte value for ``char`` fields).
    junk : bool
        Whether bytes preceded the sentence start on this line.
    """
    s = raw.strip(STRIP)
    if not s:
        return IGNORED, S.BLANK, "", None, False
    if s[:1] == b"#":
        return IGNORED, S.COMMENT, "", None, False
    star = s.rfind(b"*")
    limit = star if star >= 0 else len(s)
    d = max(s.rfind(b"$", 0, limit), s.rfind(b"!", 0, limit))
    if d < 0:
        return REJECTED, S.NOT_NMEA, "no '$' or '!' sentence start", None, False
    junk = d > 0
    body = s[d + 1 : limit]
    addr, _, rest = body.partition(b",")
    key = type_key(addr, rest)
    if key is None:
        return REJECTED, S.NOT_NMEA, f"address {addr[:12]!r} is not an NMEA address", None, junk
    spec = S.SENTENCES.get(key)
    fields = rest.split(b",") if b"," in body else []
    if star < 0:
        if spec is not None and len(fields) < spec.min_fields:
            return (
                REJECTED,
                S.TRUNCATED,
                f"{key} has {len(fields)} fields, needs {spec.min_fields}",
                None,
                junk,
            )
        if not no_checksum:
            return REJECTED, S.MISSING_CHECKSUM, "no '*hh' checksum", None, junk
        if any(b < 0x20 or b > 0x7E for b in body):
            return REJECTED, S.MALFORMED, "bytes outside printable ASCII", None, junk
        return _fields(key, spec, fields, junk)
    cs = s[star + 1 :]
    if len(cs) < 2:
        return REJECTED, S.TRUNCATED, "line ends inside the checksum", None, junk
    if len(cs) != 2 or not _HEX.fullmatch(cs):
        return (
            REJECTED,
            S.BAD_CHECKSUM,
            f"checksum field {cs[:8]!r} is not two hex digits",
            None,
            junk,
        )
    x = 0
    for b in body:
        x ^= b
    want = int(cs, 16)
    if x != want:
        return REJECTED, S.BAD_CHECKSUM, f"checksum {want:02X}, computed {x:02X}", None, junk
    if any(b < 0x20 or b > 0x7E for b in body):
        return REJECTED, S.MALFORMED, "bytes outside printable ASCII", None, junk
    return _fields(key, spec, fields, junk)


def _fields(key: str, spec, fields: list, junk: bool) -> tuple[int, str, str, dict | None, bool]:
    """The outcome of a sentence with a valid structure: its type and field values."""
    if spec is None:
        return IGNORED, key, "", None, junk
    if len(fields) < spec.min_fields:
        detail = f"{key} has {len(fields)} fields, needs {spec.min_fields}"
        return REJECTED, S.TRUNCATED, detail, None, junk
    values: dict = {}
    for f in spec.fields:
        v = fields[f.index - 1] if f.index - 1 < len(fields) else b""
        if len(v) > S.MAX_FIELD:
            return REJECTED, S.MALFORMED, _bad(key, f, v), None, junk
        if f.kind == S.CHAR:
            if len(v) > 1 or (v and f.allowed and chr(v[0]) not in f.allowed):
                return REJECTED, S.MALFORMED, _bad(key, f, v), None, junk
            values[f.name] = v[0] if v else 0
        elif not v:
            values[f.name] = np.nan
        elif _PATTERNS[f.kind].fullmatch(v):
            values[f.name] = S.mode_quality(v) if f.kind == S.MODES else float(v)
        else:
            return REJECTED, S.MALFORMED, _bad(key, f, v), None, junk
    return PARSED, key, "", values, junk


def _bad(key: str, f: S.FieldSpec, v: bytes) -> str:
    return (
        f"{key} field {f.index} ({f.name}) = {v[:16].decode('ascii', 'replace')!r} is not {f.kind}"
    )


def tokenize_reference(data: bytes, *, no_checksum: bool = False) -> Tokens:
    """Tokenize a buffer line by line (reference implementation).

    Parameters
    ----------
    data : bytes
        The whole input.
    no_checksum : bool
        Read sentences without a checksum (:func:`classify_line`).

    Returns
    -------
    Tokens
    """
    lines = split_lines(data)
    n = len(lines)
    outcome = np.zeros(n, dtype=np.int8)
    names: dict[str, int] = {}
    code = np.zeros(n, dtype=np.int32)
    junk = np.zeros(n, dtype=bool)
    details: dict[int, str] = {}
    rows: dict[str, list[tuple[int, dict]]] = {k: [] for k in S.SENTENCES}
    for i, line in enumerate(lines):
        o, lab, det, vals, j = classify_line(line, no_checksum)
        outcome[i] = o
        code[i] = names.setdefault(lab, len(names))
        junk[i] = j
        if o == REJECTED:
            details[i] = det
        elif o == PARSED:
            assert vals is not None  # a parsed line has its values
            rows[lab].append((i, vals))
    raw: dict[str, dict[str, np.ndarray]] = {}
    for key, spec in S.SENTENCES.items():
        r = rows[key]
        if not r:
            raw[key] = empty_raw(spec.fields)
            continue
        tab: dict[str, np.ndarray] = {"line": np.array([i for i, _ in r], dtype=np.int64)}
        for f in spec.fields:
            dt = np.uint8 if f.kind == S.CHAR else np.float64
            tab[f.name] = np.array([v[f.name] for _, v in r], dtype=dt)
        raw[key] = tab
    return Tokens(outcome, code, list(names), junk, raw, details)
