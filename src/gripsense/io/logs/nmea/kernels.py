"""Compiled (numba) loops of the production NMEA tokenizer.

They implement, byte for byte, the rules of :mod:`gripsense.io.logs.nmea.reference` for a whole
buffer at once, numbers converted exactly to Python's ``float`` (:func:`_numeric`);
:mod:`gripsense.io.logs.nmea.fast` wires them together. The test suite checks line-by-line equality
with the reference on real and fuzzed logs, and every converted number to the bit.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from gripsense.io.logs.nmea import schema as S

__all__ = ["KIND_CODES", "count_lines", "read_fields", "scan_buffer"]

# line codes written by scan_buffer
PENDING = 0  # valid sentence structure and checksum: the type decides the rest
BLANK = 1
COMMENT = 2
NO_START = 3  # not NMEA: no '$' or '!'
BAD_ADDRESS = 4  # not NMEA: address
NO_STAR = 5  # no checksum: missing or truncated, by type
CS_SHORT = 6  # truncated inside the checksum
CS_BAD = 7  # bad checksum
UNPRINTABLE = 8  # malformed field: bytes outside printable ASCII
NO_STAR_BIN = 9  # no checksum, and bytes outside printable ASCII

KIND_CODES = {S.NUM: 0, S.UNUM: 1, S.INT: 2, S.TIME: 3, S.DATE: 4, S.CHAR: 5, S.MODES: 6}
# byte -> fix quality of a mode letter (schema.MODE_QUALITY), -1: not a mode letter
_MODE_Q = np.full(256, -1.0)
for _k, _q in S.MODE_QUALITY.items():
    _MODE_Q[ord(_k)] = _q
del _k, _q


@njit(cache=True, nogil=True, inline="always")
def _modes(buf, a, n, table):
    """A ``modes`` field buf[a:a+n] (n >= 1): ``(1, quality of its first letter that is not N,
    0 when all are N)``, or ``(0, 0.0)`` when a byte is not a mode letter (see
    :func:`gripsense.io.logs.nmea.schema.mode_quality`).
    """
    v = 0.0
    for q in range(a, a + n):
        x = table[buf[q]]
        if x < 0:
            return 0, 0.0
        if v == 0.0:
            v = x
    return 1, v


@njit(cache=True, nogil=True, inline="always")
def _ws(b):
    return b == 32 or b == 9 or b == 13


@njit(cache=True, nogil=True, inline="always")
def _alnum(b):
    return (48 <= b <= 57) or (65 <= b <= 90)


@njit(cache=True, nogil=True, inline="always")
def _hex(b):
    if 48 <= b <= 57:
        return b - 48
    if 65 <= b <= 70:
        return b - 55
    if 97 <= b <= 102:
        return b - 87
    return -1


@njit(cache=True, nogil=True)
def count_lines(buf):
    """Number of lines of a buffer (see :func:`~gripsense.io.logs.nmea.tokens.split_lines`)."""
    c = 0
    for i in range(buf.size):
        c += buf[i] == 10
    if buf.size and buf[buf.size - 1] != 10:
        c += 1
    return c


@njit(cache=True, nogil=True)
def scan_buffer(buf, max_address, code, dpos, limit, nfields, junk, addr, sub):
    """Structure of every line of a buffer (see the reference).

    Per line (arrays sized by :func:`count_lines`): ``code`` (the line codes above), ``dpos``
    (the sentence start: the last ``$``/``!`` before the last ``*``), ``limit`` (the ``*`` or
    the stripped end), ``nfields`` (commas in the body), ``junk`` (bytes before the start),
    ``addr`` (the address bytes packed little-endian in a uint64) and ``sub`` (the first field
    packed the same way when it is 1..max_address bytes long — the sub-type of
    ``$PSAT``/``$PSTI`` — else 0).

    One forward pass finds the line end, the last ``*`` and the sentence start; the body is
    read again (checksum, printable bytes, commas) only when the address and the checksum's
    form are valid — binary lines stop before that.

    One function of 117 lines of code on purpose (issue 44 allows a compiled kernel over 100
    when splitting costs speed): split into inlined helpers (the line end, the address, the
    first field, the checksum's form) it gave the same arrays on every bundled NMEA log and
    fuzzed copies, but scanned 1 M lines (``rst39.log`` replicated, 71 MB) 5–15 % slower at
    best of 31 alternated runs (143 → 165 ms and 172 → 181 ms; medians 4–7 %), 2026-11-27.
    """
    nb = buf.size
    i = 0
    q = 0
    while i < code.size:
        start = q
        last_d = -1  # last '$' or '!'
        st = -1  # last '*'
        d_st = -1  # last '$' or '!' before it
        while q < nb:
            b = buf[q]
            if b == 10:
                break
            if b == 36 or b == 33:
                last_d = q
            elif b == 42:
                st = q
                d_st = last_d
            q += 1
        e = q  # stripped line: [a, e)
        q += 1  # past the '\n'
        while e > start and _ws(buf[e - 1]):
            e -= 1
        if e == start:
            code[i] = BLANK
            i += 1
            continue
        a = start
        while _ws(buf[a]):
            a += 1
        if buf[a] == 35:
            code[i] = COMMENT
            i += 1
            continue
        d = d_st if st >= 0 else last_d
        lim = st if st >= 0 else e
        if d < 0 or d >= lim:  # (a '$' after the last '*' only: no start before it)
            code[i] = NO_START
            i += 1
            continue
        dpos[i] = d
        limit[i] = lim
        junk[i] = d > a
        p = d + 1
        ok = True
        w = np.uint64(0)
        while p < lim and buf[p] != 44 and p - d <= max_address:
            c = buf[p]
            if not _alnum(c):
                ok = False
            if p - d <= 8:
                w |= np.uint64(c) << np.uint64(8 * (p - d - 1))
            p += 1
        al = p - d - 1  # max_address + 1: too long (not read further)
        if not ok or al < 1 or al > max_address or (p < lim and buf[p] != 44):
            code[i] = BAD_ADDRESS
            i += 1
            continue
        if buf[d + 1] == 80:
            if al < 3:
                code[i] = BAD_ADDRESS
                i += 1
                continue
        elif al != 5:
            code[i] = BAD_ADDRESS
            i += 1
            continue
        addr[i] = w
        if p < lim:  # first field: p is the comma after the address
            s0 = p + 1
            r = s0
            w = np.uint64(0)
            while r < lim and buf[r] != 44 and r - s0 <= max_address:
                if r - s0 < 8:
                    w |= np.uint64(buf[r]) << np.uint64(8 * (r - s0))
                r += 1
            fl = r - s0
            if fl >= 1 and fl <= max_address:
                sub[i] = w
        h = -1
        if st >= 0:
            cl = e - st - 1
            if cl < 2:
                code[i] = CS_SHORT
                i += 1
                continue
            if cl == 2:
                h1 = _hex(buf[st + 1])
                h2 = _hex(buf[st + 2])
                if h1 >= 0 and h2 >= 0:
                    h = h1 * 16 + h2
            if h < 0:
                code[i] = CS_BAD
                i += 1
                continue
        x = 0  # the body after the address: checksum, printable bytes, commas
        u = 0
        nc = 0
        for r in range(p, lim):
            b = buf[r]
            x ^= b
            u += (b < 32) | (b > 126)
            nc += b == 44
        nfields[i] = nc
        if st < 0:
            code[i] = NO_STAR if u == 0 else NO_STAR_BIN
            i += 1
            continue
        for r in range(d + 1, p):
            x ^= buf[r]
        if x != h:
            code[i] = CS_BAD
        elif u:
            code[i] = UNPRINTABLE
        else:
            code[i] = PENDING
        i += 1


# exact powers of ten: 10**k is a double without rounding for k <= 22
_POW10 = np.array([10.0**k for k in range(23)])
_MAX_EXACT = 1 << 53  # integers up to 2**53 are exact doubles
_MAX_DIGITS = 18  # significant digits accumulated (int64 holds 18 decimal digits)


@njit(cache=True, nogil=True, inline="always")
def _char_ok(buf, a, n, allowed, j):
    """Whether a ``char`` field buf[a:a+n] (n >= 1) is one allowed letter."""
    return n <= 1 and (not allowed[j, 256] or allowed[j, buf[a]])


@njit(cache=True, nogil=True, inline="always")
def _numeric(buf, a, n, kind, pow10):
    """Check a numeric field buf[a:a+n] (n >= 1) against its kind's pattern and convert it.

    Returns ``(status, value)``: status 0 = bad pattern, 1 = value exact, 2 = pattern good but
    the value needs the caller's exact conversion. Patterns: ``num`` digits with at most one
    dot and an optional leading sign, ``unum`` the same without sign, ``int`` digits only,
    ``time`` hhmmss with optional .s*, ``date`` ddmmyy; ``modes`` (code 6) mode letters
    (:func:`_modes`).

    The value is Clinger's fast path: with the integer m of the significant digits at most
    2**53 and at most 22 decimals d, m and 10**d are exact doubles and IEEE division rounds
    m / 10**d correctly — the double Python's ``float`` gives for the text. Longer fields
    (more than ~16 significant digits, which NMEA does not send) get status 2.
    """
    if kind == 6:
        return _modes(buf, a, n, _MODE_Q)
    p = a
    e = a + n
    neg = False
    b0 = buf[p]
    if b0 == 45 or b0 == 43:
        if kind != 0:
            return 0, 0.0
        neg = b0 == 45
        p += 1
    m = 0
    nd = 0
    sig = 0
    frac = 0
    dot = -1
    for q in range(p, e):
        b = buf[q]
        if b == 46:
            if dot >= 0:
                return 0, 0.0
            dot = q
            continue
        d = b - 48
        if d < 0 or d > 9:
            return 0, 0.0
        nd += 1
        if dot >= 0:
            frac += 1
        if sig > 0 or d != 0:
            sig += 1
            if sig <= _MAX_DIGITS:
                m = m * 10 + d
    if nd == 0:
        return 0, 0.0
    if kind == 2 or kind == 4:  # int, date: digits only
        if dot >= 0 or (kind == 4 and n != 6):
            return 0, 0.0
    elif kind == 3:  # time: hhmmss(.s*)
        if n < 6 or (n == 6 and dot >= 0) or (n > 6 and dot != a + 6):
            return 0, 0.0
    if sig > _MAX_DIGITS or m > _MAX_EXACT or frac > 22:
        return 2, 0.0
    v = m / pow10[frac]
    return 1, (-v if neg else v)


@njit(cache=True, nogil=True)
def read_fields(
    buf, lines, dpos, limit, slot, fkind, allowed, numcol, max_field, ok, cval, vals, slow
):
    """Fields of one sentence type for the given lines.

    ``slot[k]`` is the spec's field number of the sentence's k-th field (-1: not read). Writes
    per line ``ok`` (all fields valid), the byte of ``char`` fields (``cval``, 0 when empty)
    and the value of numeric fields in column ``numcol[j]`` of ``vals`` (NaN when empty;
    undefined when the line is not ok). A numeric field outside the exact fast path of
    :func:`_numeric` is recorded in ``slow`` as (row, column, start, length) for the caller to
    convert; returns how many there were (only the first ``slow.shape[0]`` are recorded).
    """
    nfld = fkind.size
    maxidx = slot.size - 1
    pow10 = _POW10
    n_slow = 0
    for r in range(lines.size):
        i = lines[r]
        lim = limit[i]
        good = True
        for j in range(nfld):
            c = numcol[j]
            if c >= 0:
                vals[r, c] = np.nan
            else:
                cval[r, j] = 0
        p = dpos[i] + 1
        while p < lim and buf[p] != 44:
            p += 1
        k = 0
        while p < lim and k < maxidx:
            k += 1
            s = p + 1
            q = s
            while q < lim and buf[q] != 44:
                q += 1
            p = q
            j = slot[k]
            n = q - s
            if j < 0 or n == 0:
                continue
            if n > max_field:
                good = False
                break
            c = numcol[j]
            if c < 0:
                if not _char_ok(buf, s, n, allowed, j):
                    good = False
                    break
                cval[r, j] = buf[s]
                continue
            status, v = _numeric(buf, s, n, fkind[j], pow10)
            if status == 0:
                good = False
                break
            vals[r, c] = v
            if status == 2:
                if n_slow < slow.shape[0]:
                    slow[n_slow, 0] = r
                    slow[n_slow, 1] = c
                    slow[n_slow, 2] = s
                    slow[n_slow, 3] = n
                n_slow += 1
        ok[r] = good
    return n_slow
