r"""Ashtech (Magellan, Thales, Spectra) binary records between NMEA sentences.

Ashtech receivers send their raw data on the NMEA port as ``$PASHR,<id>,`` followed by a
binary structure of fixed length per message type and CR LF (Ashtech Z-Family Technical
Reference Manual, "Raw data"; DG14/DG16 Reference Manual, "Message Structure"). The structure's
bytes are binary — they hold ``\r``, ``\n`` and ``$`` by chance — so a record is cut out of the
stream before its lines are read, as RTCM 3 frames are (:mod:`gripsense.io.logs.nmea.rtcm`, whose
scanner finds both). The last one or two bytes of the structure are its checksum, most
significant byte first:

=====  ====================  ===========  ===============================================
id     what                  structure    checksum
=====  ====================  ===========  ===============================================
MCA    C/A measurements      37 bytes     XOR of the bytes before it (1 byte)
MPC    C/A + P measurements  95 bytes     XOR of the bytes before it (1 byte)
PBN    position (PBEN)       56 bytes     sum of the 16-bit words before it (2 bytes)
SNV    GPS ephemeris         132 bytes    sum of the 16-bit words before it (2 bytes)
SAL    GPS almanac           70 bytes     sum of the 16-bit words before it (2 bytes)
SNG    GLONASS ephemeris     82 bytes     sum of the 16-bit words before it (2 bytes)
SNW    SBAS ephemeris        76 bytes     sum of the 16-bit words before it (2 bytes)
=====  ====================  ===========  ===============================================

(MPC: the XOR with or without the comma before the structure, which the manual's wording
leaves open.) MCA and PBN are checked on a real receiver's output (GPSD's AC12 capture,
``tests/data/formats/nmea/ashtech-ac12.log``: every checksum matches); the other lengths
and checksums are the manuals'. The same ids in ASCII form (``$PASHR,PBN,…*hh``) are
sentences and stay in the text.
"""

from __future__ import annotations

import numpy as np
from numba import njit

__all__ = ["ASHTECH_IDS", "ashtech_label", "ashtech_size", "checksum_ok", "header_at", "record_end"]

ASHTECH_IDS = ("MCA", "MPC", "PBN", "SNV", "SAL", "SNG", "SNW")
"""Ashtech binary message ids (index = the record's type code)."""

HEADER = b"$PASHR,"
_MPC = ASHTECH_IDS.index("MPC")
_IDS = np.array([[ord(c) for c in s] for s in ASHTECH_IDS], dtype=np.uint8)
_SIZE = np.array([37, 95, 56, 132, 70, 82, 76], dtype=np.int64)  # structure incl. checksum
_XOR = np.array([True, True, False, False, False, False, False])  # else 16-bit word sum
_HEAD = np.frombuffer(HEADER, dtype=np.uint8).copy()
HEADER_LEN = len(HEADER) + 4  # "$PASHR," + id + ","


def ashtech_label(code: int) -> str:
    """Name of an Ashtech binary record type in the report, e.g. ``Ashtech binary MCA``."""
    return f"Ashtech binary {ASHTECH_IDS[code]}"


def ashtech_size(code: int) -> int:
    """Length of the binary structure of record type *code*, checksum included [bytes]."""
    return int(_SIZE[code])


@njit(cache=True, nogil=True)
def header_at(buf, i, ids=_IDS, head=_HEAD):
    """Type code of the Ashtech binary header at byte *i* of *buf*: -1 none, -2 cut by the end
    of *buf* (all its bytes so far match a header: more bytes may make it one).
    """
    n = buf.size
    m = min(n - i, HEADER_LEN)
    for j in range(min(m, 7)):
        if buf[i + j] != head[j]:
            return -1
    if m < HEADER_LEN:
        for t in range(ids.shape[0]):
            ok = True
            for j in range(7, min(m, 10)):
                if buf[i + j] != ids[t, j - 7]:
                    ok = False
                    break
            if ok:
                return -2
        return -1
    if buf[i + 10] != 44:  # ","
        return -1
    for t in range(ids.shape[0]):
        if buf[i + 7] == ids[t, 0] and buf[i + 8] == ids[t, 1] and buf[i + 9] == ids[t, 2]:
            return t
    return -1


@njit(cache=True, nogil=True)
def record_end(code, i, size=_SIZE):
    """Offset just past the record of type *code* starting at *i* (header, structure, CR LF)."""
    return i + 11 + size[code] + 2


@njit(cache=True, nogil=True)
def checksum_ok(buf, code, i, size=_SIZE, xor=_XOR):
    """Whether the checksum of the record of type *code* at byte *i* matches (its bytes are
    all in *buf*).
    """
    a = i + 11
    s = size[code]
    if xor[code]:
        c = 0
        for j in range(a, a + s - 1):
            c ^= buf[j]
        # MPC: the Z-Family manual's checksum "includes the last comma" (the one before the
        # structure); either reading is taken
        return c == buf[a + s - 1] or (code == _MPC and (c ^ 44) == buf[a + s - 1])
    c = 0
    for j in range(a, a + s - 2, 2):
        c += (np.int64(buf[j]) << 8) | np.int64(buf[j + 1])
    want = (np.int64(buf[a + s - 2]) << 8) | np.int64(buf[a + s - 1])
    return (c & 0xFFFF) == want
