"""What gripsense reads from NMEA 0183: sentence layouts, field kinds and reject reasons.

Both tokenizers (the per-line reference in :mod:`gripsense.io.logs.nmea.reference` and the
vectorised production path in :mod:`gripsense.io.logs.nmea.fast`) read this one table, so they
cannot disagree about which field holds what.

Field numbers count the comma-separated fields after the address field (``$GPGGA`` is field 0,
the UTC time is field 1). For sub-typed proprietary sentences (``$PSAT,HPR``, ``$PSTI,036``,
``$PASHR,HPR``, ``$PTNL,AVR``, ``$PSSN,HRP``, ``$PFEC,GPatt``) the sub-type is field 1.
"""

from __future__ import annotations

from dataclasses import dataclass

__all__ = [
    "MODE_QUALITY",
    "REASONS",
    "SENTENCES",
    "FieldSpec",
    "SentenceSpec",
    "mode_quality",
]

# Reject reasons, in the words the report uses.
BAD_CHECKSUM = "bad checksum"
MISSING_CHECKSUM = "missing checksum"
MALFORMED = "malformed field"
TRUNCATED = "truncated"
NOT_NMEA = "not NMEA"
OVER_LIMIT = "over the size limit"  # lines beyond read_nmea's max_lines / max_bytes: counted only
REASONS = (BAD_CHECKSUM, MISSING_CHECKSUM, MALFORMED, TRUNCATED, NOT_NMEA, OVER_LIMIT)

# Pseudo sentence types for lines that are not sentences but not errors either.
BLANK = "(blank)"
COMMENT = "(comment)"

MAX_FIELD = 64  # a longer field is malformed (an NMEA sentence has at most 82 characters)

# Field kinds. Numeric kinds are stored as float64 (NaN when empty); "char" as the byte value
# (uint8, 0 when empty).
NUM = "num"  # signed decimal: [+-]?(d+.?d*|.d+)
UNUM = "unum"  # unsigned decimal (ddmm.mmmm lat/lon)
INT = "int"  # digits only
TIME = "time"  # hhmmss(.s*) as a number
DATE = "date"  # ddmmyy as a number
CHAR = "char"  # one character or empty
MODES = "modes"  # GNS mode letters, one per constellation (``AANN``): stored as a GGA quality
KINDS = (NUM, UNUM, INT, TIME, DATE, CHAR, MODES)

# NMEA mode indicator letter -> fix quality on GGA's scale (0 no fix, 1 autonomous, 2
# differential, 3 precise, 4 RTK fixed, 5 RTK float, 6 estimated, 7 manual, 8 simulator);
# NMEA 0183 4.11, GNS and GLL "mode indicator". A ``modes`` field is stored as the quality of
# its first letter that is not N (0 when every letter is N; NaN when the field is empty); a
# letter outside this table makes the field malformed.
MODE_QUALITY = {"N": 0, "A": 1, "D": 2, "P": 3, "R": 4, "F": 5, "E": 6, "M": 7, "S": 8}


def mode_quality(letters: bytes) -> float:
    """Fix quality on GGA's scale of a ``modes`` field (see :data:`MODE_QUALITY`).

    Parameters
    ----------
    letters : bytes
        The field's letters, at least one, each a key of :data:`MODE_QUALITY` [-].

    Returns
    -------
    float
        The quality of the first letter that is not ``N``; 0.0 when all are ``N`` [-].
    """
    for b in letters:
        q = MODE_QUALITY[chr(b)]
        if q:
            return float(q)
    return 0.0


@dataclass(frozen=True)
class FieldSpec:
    """One field read from a sentence.

    Parameters
    ----------
    index : int
        Field number after the address field (1 = first field) [-].
    name : str
        Name of the raw column.
    kind : str
        One of ``num``, ``unum``, ``int``, ``time``, ``date``, ``char``, ``modes``.
    allowed : str
        For ``char`` fields, the characters allowed (empty string: any printable character).
    """

    index: int
    name: str
    kind: str
    allowed: str = ""


@dataclass(frozen=True)
class SentenceSpec:
    """Layout of one sentence type.

    Parameters
    ----------
    key : str
        Type key: the formatter (``GGA``) for standard sentences, whatever the talker; the address
        for proprietary ones (``PASHR``), or address plus sub-type (``PSAT,HPR``, ``PSTI,036``).
    fields : tuple of FieldSpec
        Fields read.
    min_fields : int
        A sentence with fewer fields than this is *truncated* [-].
    timed : bool
        Whether the sentence carries a UTC time of day (field named ``time``).
    """

    key: str
    fields: tuple[FieldSpec, ...]
    min_fields: int
    timed: bool


def _spec(key: str, timed: bool, *fields: FieldSpec, min_fields: int | None = None) -> SentenceSpec:
    need = max(f.index for f in fields)
    return SentenceSpec(key, tuple(fields), need if min_fields is None else min_fields, timed)


F = FieldSpec
SENTENCES: dict[str, SentenceSpec] = {
    s.key: s
    for s in (
        # GGA: time, lat, N/S, lon, E/W, quality, satellites, HDOP, altitude (MSL), M, geoid sep...
        _spec(
            "GGA",
            True,
            F(1, "time", TIME),
            F(2, "lat", UNUM),
            F(3, "ns", CHAR, "NS"),
            F(4, "lon", UNUM),
            F(5, "ew", CHAR, "EW"),
            F(6, "quality", INT),
            F(7, "n_sats", INT),
            F(8, "hdop", NUM),
            F(9, "alt", NUM),
        ),
        # RMC: time, status A/V, lat, N/S, lon, E/W, SOG [kn], COG [deg true], date ddmmyy, ...
        _spec(
            "RMC",
            True,
            F(1, "time", TIME),
            F(2, "status", CHAR, "AV"),
            F(3, "lat", UNUM),
            F(4, "ns", CHAR, "NS"),
            F(5, "lon", UNUM),
            F(6, "ew", CHAR, "EW"),
            F(7, "sog_kn", NUM),
            F(8, "cog", NUM),
            F(9, "date", DATE),
        ),
        # GLL: lat, N/S, lon, E/W, time, status A/V, [mode A/D/E/M/S/N …] (NMEA 2.3+); the
        # position counts only with status A and a mode that is empty or a fix letter (not N).
        # Status and mode may be any letter (Magellan's eXplorist sends status N, mode V: no
        # fix). NMEA 1.5's GLL without time and status is truncated: nothing says it is valid.
        _spec(
            "GLL",
            True,
            F(1, "lat", UNUM),
            F(2, "ns", CHAR, "NS"),
            F(3, "lon", UNUM),
            F(4, "ew", CHAR, "EW"),
            F(5, "time", TIME),
            F(6, "status", CHAR),
            F(7, "mode", CHAR),
            min_fields=6,
        ),
        # GNS: time, lat, N/S, lon, E/W, mode letters (one per constellation, GP GL GA BD …),
        # satellites, HDOP, altitude (MSL) [m], geoid separation, age of corrections, station,
        # [navigational status]; no fix when every mode letter is N
        _spec(
            "GNS",
            True,
            F(1, "time", TIME),
            F(2, "lat", UNUM),
            F(3, "ns", CHAR, "NS"),
            F(4, "lon", UNUM),
            F(5, "ew", CHAR, "EW"),
            F(6, "mode", MODES),
            F(7, "n_sats", INT),
            F(8, "hdop", NUM),
            F(9, "alt", NUM),
        ),
        # VTG (NMEA 2.x+): COG true, T, COG magnetic, M, SOG kn, N, SOG km/h, K, [mode]
        _spec(
            "VTG",
            False,
            F(1, "cog", NUM),
            F(5, "sog_kn", NUM),
            F(7, "sog_kmh", NUM),
            F(9, "mode", CHAR),
            min_fields=8,
        ),
        # HDT: heading true [deg], T
        _spec("HDT", False, F(1, "heading", NUM)),
        # THS: heading true [deg], mode A/E/M/S/V
        _spec("THS", False, F(1, "heading", NUM), F(2, "mode", CHAR, "AEMSV")),
        # ROT: rate of turn [deg/min], negative = bow to port; status A/V
        _spec("ROT", False, F(1, "rot", NUM), F(2, "status", CHAR, "AV")),
        # ZDA: time, day, month, year, local zone hours, minutes
        _spec(
            "ZDA",
            True,
            F(1, "time", TIME),
            F(2, "day", INT),
            F(3, "month", INT),
            F(4, "year", INT),
        ),
        # Hemisphere $PSAT,HPR: time, heading, pitch, roll, type (N = GNSS, G = gyro)
        _spec(
            "PSAT,HPR",
            True,
            F(2, "time", TIME),
            F(3, "heading", NUM),
            F(4, "pitch", NUM),
            F(5, "roll", NUM),
            F(6, "type", CHAR),
            min_fields=5,
        ),
        # SkyTraq $PSTI,036 (PX1172RH heading receivers): time, date ddmmyy, heading, pitch,
        # roll, mode (heading valid only with mode R = fixed RTK, as GPSD reads it)
        _spec(
            "PSTI,036",
            True,
            F(2, "time", TIME),
            F(3, "date", DATE),
            F(4, "heading", NUM),
            F(5, "pitch", NUM),
            F(6, "roll", NUM),
            F(7, "mode", CHAR),
            min_fields=7,
        ),
        # $PASHR (Ashtech / OxTS / Trimble): time, heading, T, roll, pitch, heave, roll acc,
        # pitch acc, heading acc, GNSS quality, INS status
        _spec(
            "PASHR",
            True,
            F(1, "time", TIME),
            F(2, "heading", NUM),
            F(4, "roll", NUM),
            F(5, "pitch", NUM),
            min_fields=5,
        ),
        # Ashtech / Spectra $PASHR,HPR (dual-antenna attitude): time, heading, pitch, roll,
        # carrier-phase RMS, baseline RMS, ambiguity (0 = fixed, 1 = float), attitude status
        # (the sub-type HPR is field 1; an attitude counts only with fixed ambiguities)
        _spec(
            "PASHR,HPR",
            True,
            F(2, "time", TIME),
            F(3, "heading", NUM),
            F(4, "pitch", NUM),
            F(5, "roll", NUM),
            F(8, "ambiguity", INT),
            min_fields=5,
        ),
        # Trimble $PTNL,AVR (moving-baseline vector): time, yaw, "Yaw", tilt, "Tilt", roll,
        # "Roll", range, GPS quality (3 = fixed RTK), PDOP, satellites; the yaw is the true
        # heading of the antenna baseline, used only with a fixed-RTK vector (quality 3)
        _spec(
            "PTNL,AVR",
            True,
            F(2, "time", TIME),
            F(3, "heading", NUM),
            F(5, "pitch", NUM),
            F(7, "roll", NUM),
            F(10, "quality", INT),
            min_fields=10,
        ),
        # Furuno satellite compass $PFEC,GPatt: yaw (true heading), pitch, roll [deg]; no time
        _spec(
            "PFEC,GPatt",
            False,
            F(2, "heading", NUM),
            F(3, "pitch", NUM),
            F(4, "roll", NUM),
            min_fields=2,
        ),
        # Septentrio $PSSN,HRP: time, date ddmmyy, heading, roll, pitch, their standard
        # deviations, satellites, mode (0 none, 1/3 float, 2/4 fixed ambiguities), ...; used
        # only with fixed ambiguities (mode 2 or 4)
        _spec(
            "PSSN,HRP",
            True,
            F(2, "time", TIME),
            F(3, "date", DATE),
            F(4, "heading", NUM),
            F(5, "roll", NUM),
            F(6, "pitch", NUM),
            F(11, "mode", INT),
            min_fields=11,
        ),
    )
}
del F
