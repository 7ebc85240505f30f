"""Compiled (numba) loops of the production NMEA tokenizer.

They implement, byte for byte, the rules of :mod:`gripsense.io.nmea.reference` for a whole
buffer at once; :mod:`gripsense.io.nmea.fast` wires them together and converts the numbers with
Arrow. The test suite checks line-by-line equality with the reference on real and fuzzed logs.
"""

from __future__ import annotations

from numba import njit

from gripsense.io.nmea import schema as S

__all__ = ["KIND_CODES", "read_fields", "scan_lines"]

# line codes written by scan_lines
PENDING = 0  # valid sentence structure and checksum: the type decides the rest
BLANK = 1
COMMENT = 2
NO_START = 3  # not NMEA: no '$' or '!'
BAD_ADDRESS = 4  # not NMEA: address
NO_STAR = 5  # no checksum: missing or truncated, by type
CS_SHORT = 6  # truncated inside the checksum
CS_BAD = 7  # bad checksum
UNPRINTABLE = 8  # malformed field: bytes outside printable ASCII

KIND_CODES = {S.NUM: 0, S.UNUM: 1, S.INT: 2, S.TIME: 3, S.DATE: 4, S.CHAR: 5}


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
def scan_lines(
    buf, starts, ends, max_address, code, dpos, star, stripped_end, nfields, alen, junk, f1a, f1b
):
    """Structure of every line: start, checksum, address, field count (see the reference)."""
    for i in range(starts.size):
        a = starts[i]
        e = ends[i]
        while a < e and _ws(buf[a]):
            a += 1
        while e > a and _ws(buf[e - 1]):
            e -= 1
        stripped_end[i] = e
        if a == e:
            code[i] = BLANK
            continue
        if buf[a] == 35:
            code[i] = COMMENT
            continue
        st = -1
        for p in range(e - 1, a - 1, -1):
            if buf[p] == 42:
                st = p
                break
        lim = st if st >= 0 else e
        star[i] = st
        d = -1
        for p in range(lim - 1, a - 1, -1):
            if buf[p] == 36 or buf[p] == 33:
                d = p
                break
        if d < 0:
            code[i] = NO_START
            continue
        dpos[i] = d
        junk[i] = d > a
        p = d + 1
        ok = True
        while p < lim and buf[p] != 44:
            if not _alnum(buf[p]):
                ok = False
            p += 1
        al = p - d - 1
        alen[i] = al
        if not ok or al < 1 or al > max_address:
            code[i] = BAD_ADDRESS
            continue
        if buf[d + 1] == 80:
            if al < 3:
                code[i] = BAD_ADDRESS
                continue
        elif al != 5:
            code[i] = BAD_ADDRESS
            continue
        n = 0
        fa = lim
        fb = lim
        for q in range(p, lim):
            if buf[q] == 44:
                n += 1
                if n == 1:
                    fa = q + 1
                elif n == 2:
                    fb = q
        if n == 1:
            fb = lim
        nfields[i] = n
        f1a[i] = fa
        f1b[i] = fb
        if st < 0:
            code[i] = NO_STAR
            continue
        cl = e - st - 1
        if cl < 2:
            code[i] = CS_SHORT
            continue
        h1 = _hex(buf[st + 1]) if cl == 2 else -1
        h2 = _hex(buf[st + 2]) if cl == 2 else -1
        if h1 < 0 or h2 < 0:
            code[i] = CS_BAD
            continue
        x = 0
        bad = False
        for q in range(d + 1, st):
            b = buf[q]
            x ^= b
            if b < 32 or b > 126:
                bad = True
        if x != h1 * 16 + h2:
            code[i] = CS_BAD
            continue
        if bad:
            code[i] = UNPRINTABLE
            continue
        code[i] = PENDING


@njit(cache=True, nogil=True)
def _field_ok(buf, a, n, kind, allowed):
    """Whether buf[a:a+n] (n >= 1) matches the pattern of its kind."""
    if kind == 5:  # char
        return n <= 1 and (not allowed[256] or allowed[buf[a]])
    nd = 0
    ndot = 0
    ns = 0
    for q in range(a, a + n):
        b = buf[q]
        if 48 <= b <= 57:
            nd += 1
        elif b == 46:
            ndot += 1
        elif b == 43 or b == 45:
            ns += 1
        else:
            return False
    if kind == 0:  # num
        return nd >= 1 and ndot <= 1 and (ns == 0 or (ns == 1 and (buf[a] == 43 or buf[a] == 45)))
    if kind == 1:  # unum
        return nd >= 1 and ndot <= 1 and ns == 0
    if kind == 2:  # int
        return nd == n
    if kind == 3:  # time hhmmss(.s*)
        if ns != 0 or ndot > 1 or n < 6:
            return False
        if n == 6:
            return ndot == 0
        return buf[a + 6] == 46
    if kind == 4:  # date ddmmyy
        return n == 6 and nd == 6
    return False


@njit(cache=True, nogil=True)
def read_fields(buf, lines, dpos, limit, fidx, fkind, allowed, max_field, ok, fa, fl, cval, views):
    """Fields of one sentence type for the given lines.

    Writes per line ``ok`` (all fields valid), per field the start ``fa`` and length ``fl``
    (empty when the sentence has fewer fields), the byte of ``char`` fields (``cval``), and for
    numeric fields an Arrow ``string_view`` struct (16 bytes: length, then 12 inline bytes or a
    4-byte prefix, buffer 0 and the offset) in ``views`` — "0" where the field is empty or bad,
    so that the cast never fails (the caller masks those).
    """
    nfld = fidx.size
    maxidx = 0
    for j in range(nfld):
        if fidx[j] > maxidx:
            maxidx = fidx[j]
    for r in range(lines.size):
        i = lines[r]
        lim = limit[i]
        for j in range(nfld):
            fa[r, j] = lim
            fl[r, j] = 0
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
            for j in range(nfld):
                if fidx[j] == k:
                    fa[r, j] = s
                    fl[r, j] = q - s
            p = q
        good = True
        for j in range(nfld):
            n = fl[r, j]
            if n > max_field:
                good = False
            elif n > 0 and not _field_ok(buf, fa[r, j], n, fkind[j], allowed[j]):
                good = False
            if fkind[j] == 5:
                cval[r, j] = buf[fa[r, j]] if n == 1 else 0
        ok[r] = good
        for j in range(nfld):
            if fkind[j] == 5:
                continue
            n = fl[r, j]
            v = views[r, j]
            for t in range(16):
                v[t] = 0
            if not good or n == 0 or n > max_field:
                v[0] = 1
                v[4] = 48
                continue
            a = fa[r, j]
            v[0] = n & 0xFF
            v[1] = (n >> 8) & 0xFF
            if n <= 12:
                for t in range(n):
                    v[4 + t] = buf[a + t]
            else:
                for t in range(4):
                    v[4 + t] = buf[a + t]
                v[12] = a & 0xFF
                v[13] = (a >> 8) & 0xFF
                v[14] = (a >> 16) & 0xFF
                v[15] = (a >> 24) & 0xFF
