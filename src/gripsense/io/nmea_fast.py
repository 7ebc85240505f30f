"""Vectorised NMEA 0183 tokenizer (the production path of :func:`gripsense.io.read_nmea`).

It implements exactly the rules of :mod:`gripsense.io.nmea_reference` with numpy array
operations over the whole buffer instead of a loop over lines:

* line bounds, whitespace stripping, sentence start and checksum delimiter are found with
  ``searchsorted`` on the positions of ``\\n``, ``$``/``!``, ``*`` and ``,``;
* the XOR checksum of every line comes from one cumulative XOR of the buffer;
* fields are gathered into contiguous byte buffers, validated with character-class counts and
  converted to float by Arrow's string-to-float cast (correctly rounded, like Python's ``float``).

The test suite checks that both tokenizers agree line by line on real logs and on fuzzed input.
"""

from __future__ import annotations

import os
from concurrent.futures import ThreadPoolExecutor

import numpy as np
import pandas as pd
import pyarrow as pa
import pyarrow.compute as pc

from gripsense.io import nmea_schema as S
from gripsense.io.nmea_reference import MAX_ADDRESS, _type_key, classify_line
from gripsense.io.nmea_tokens import IGNORED, PARSED, REJECTED, Tokens, empty_raw, split_lines

assert MAX_ADDRESS == 8, "addresses are packed into one uint64"

__all__ = ["tokenize_fast"]



def _table(chars: bytes) -> np.ndarray:
    t = np.zeros(256, dtype=bool)
    t[np.frombuffer(chars, dtype=np.uint8)] = True
    return t


_DIGIT = _table(b"0123456789")
_ALNUM = _table(b"ABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789")
_WS = _table(b" \t\r")
_HEXVAL = np.full(256, -1, dtype=np.int16)
for _i, _c in enumerate(b"0123456789ABCDEF"):
    _HEXVAL[_c] = _i
for _i, _c in enumerate(b"abcdef"):
    _HEXVAL[_c] = 10 + _i
_PRINT = np.zeros(256, dtype=bool)
_PRINT[0x20:0x7F] = True
# one pass over the buffer finds every byte that matters for the structure of a line
_C_NL, _C_STAR, _C_START, _C_COMMA, _C_NONPRINT = 1, 2, 3, 4, 5
_CLASS = np.zeros(256, dtype=np.uint8)
_CLASS[~_PRINT] = _C_NONPRINT
_CLASS[ord("\n")] = _C_NL
_CLASS[ord("*")] = _C_STAR
_CLASS[ord("$")] = _C_START
_CLASS[ord("!")] = _C_START
_CLASS[ord(",")] = _C_COMMA
# per-byte counters packed in 16-bit lanes: digits | dots << 16 | signs << 32 | others << 48
_PACK = np.full(256, 1 << 48, dtype=np.uint64)
_PACK[np.frombuffer(b"0123456789", dtype=np.uint8)] = 1
_PACK[ord(".")] = 1 << 16
_PACK[ord("+")] = 1 << 32
_PACK[ord("-")] = 1 << 32


def _last_before(pos: np.ndarray, limit: np.ndarray, floor: np.ndarray) -> np.ndarray:
    """Largest element of sorted *pos* that is < limit and >= floor, else -1."""
    out = np.full(limit.shape, -1, dtype=np.int64)
    if pos.size == 0:
        return out
    j = np.searchsorted(pos, limit, side="left") - 1
    ok = j >= 0
    v = pos[np.where(ok, j, 0)]
    ok &= v >= floor
    out[ok] = v[ok]
    return out


def _count_between(pos: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Number of elements of sorted *pos* in [a, b)."""
    if pos.size == 0:
        return np.zeros(a.shape, dtype=np.int64)
    return np.searchsorted(pos, b) - np.searchsorted(pos, a)


def _cum(mask: np.ndarray) -> np.ndarray:
    out = np.zeros(mask.size + 1, dtype=np.int64)
    np.cumsum(mask, out=out[1:])
    return out


def _gather(buf: np.ndarray, a: np.ndarray, b: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Concatenate buf[a_i:b_i] for every i; return (bytes, offsets)."""
    lengths = b - a
    offsets = np.zeros(lengths.size + 1, dtype=np.int64)
    np.cumsum(lengths, out=offsets[1:])
    total = int(offsets[-1])
    if total == 0:
        return np.empty(0, dtype=np.uint8), offsets
    idx = np.repeat(a - offsets[:-1], lengths)
    idx += np.arange(total, dtype=np.int64)
    return buf[idx], offsets


def _xor_segments(buf: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """XOR of buf[a_i:b_i] for sorted, non-overlapping segments (a_i <= b_i < len(buf))."""
    if a.size == 0:
        return np.zeros(0, dtype=np.uint8)
    idx = np.empty(2 * a.size, dtype=np.int64)
    idx[0::2] = a
    idx[1::2] = b
    r = np.bitwise_xor.reduceat(buf, idx)[0::2]
    return np.where(b > a, r, 0).astype(np.uint8)


def _pack8(buf: np.ndarray, a: np.ndarray, length: np.ndarray) -> np.ndarray:
    """Pack up to 8 bytes buf[a:a+length] per row into one uint64 (zero padded)."""
    nb = buf.size
    cols = np.arange(8)
    mat = buf[np.minimum(a[:, None] + cols, nb - 1)]
    mat[cols[None, :] >= length[:, None]] = 0
    return np.ascontiguousarray(mat).view("<u8").ravel()


def _unpack8(v: int) -> bytes:
    return int(v).to_bytes(8, "little").rstrip(b"\x00")


_HI = np.uint64(0x8080808080808080)
_LO7 = np.uint64(0x7F7F7F7F7F7F7F7F)
_BYTE_MASK = np.array([(1 << (8 * k)) - 1 if k < 8 else (1 << 64) - 1 for k in range(9)],
                      dtype=np.uint64)
_HI_MASK = _BYTE_MASK & _HI


def _rep(c: int) -> np.uint64:
    return np.uint64(int.from_bytes(bytes([c]) * 8, "little"))


_C0, _CDOT, _CPLUS, _CMINUS, _C76 = _rep(0x30), _rep(0x2E), _rep(0x2B), _rep(0x2D), _rep(0x76)


def _eq_hi(w: np.ndarray, c: np.uint64) -> np.ndarray:
    """High bit of each byte set where the byte of *w* equals the byte of *c* (exact SWAR)."""
    v = w ^ c
    return ~(((v & _LO7) + _LO7) | v | _LO7)


def _digit_hi(w: np.ndarray) -> np.ndarray:
    """High bit of each byte set where the byte is an ASCII digit (exact SWAR)."""
    t = w ^ _C0
    return ~(((t & _LO7) + _C76) | t) & _HI


def _rows16(buf: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(padded copy of buf, view whose row i is padded[i:i+16])."""
    pad = np.zeros(buf.size + 16, dtype=np.uint8)
    pad[: buf.size] = buf
    rows = np.lib.stride_tricks.as_strided(pad, shape=(buf.size + 1, 16), strides=(1, 1),
                                           writeable=False)
    return pad, rows


def _fields16(pad: np.ndarray, rows: np.ndarray, a: np.ndarray, ln: np.ndarray, kind: str):
    """Validate and convert fields of 1..16 bytes starting at *a* (see :func:`_valid_kind`).

    Each field is read as one 16-byte row (two little-endian uint64 words); the character
    classes are counted with exact SWAR byte tests and ``bitwise_count``; the numbers are cast
    by Arrow from a ``string_view`` array whose views hold the field inline (<= 12 bytes) or
    point into *pad*.
    """
    w = np.ascontiguousarray(rows[a]).view("<u8")
    w0, w1 = w[:, 0], w[:, 1]
    m0 = _HI_MASK[np.minimum(ln, 8)]
    m1 = _HI_MASK[np.clip(ln - 8, 0, 8)]

    def count(h0, h1):
        return (np.bitwise_count(h0 & m0) + np.bitwise_count(h1 & m1)).astype(np.int64)

    nd = count(_digit_hi(w0), _digit_hi(w1))
    ndot = count(_eq_hi(w0, _CDOT), _eq_hi(w1, _CDOT))
    ns = count(_eq_hi(w0, _CPLUS) | _eq_hi(w0, _CMINUS), _eq_hi(w1, _CPLUS) | _eq_hi(w1, _CMINUS))
    nother = ln - nd - ndot - ns
    first = (w0 & np.uint64(0xFF)).astype(np.uint8)
    c6 = ((w0 >> np.uint64(48)) & np.uint64(0xFF)).astype(np.uint8)
    ok = _kind_ok(kind, ln, nd, ndot, ns, nother, first, c6)
    # string_view: [length:u32][12 inline bytes] or [length][4-byte prefix][buffer 0][offset]
    views = np.zeros((a.size, 4), dtype="<u4")
    views[:, 0] = ln
    long = ln > 12
    inl = w.copy()
    inl[:, 0] &= _BYTE_MASK[np.minimum(ln, 8)]
    inl[:, 1] &= _BYTE_MASK[np.clip(ln - 8, 0, 8)]
    inl32 = inl.view("<u4")
    views[:, 1:4] = inl32[:, 0:3]
    views[long, 2] = 0
    views[long, 3] = a[long]
    bad = ~ok
    if bad.any():  # cast a harmless "0" there, then mask
        views[bad] = (1, ord("0"), 0, 0)
    arr = pa.Array.from_buffers(pa.string_view(), a.size, [None, pa.py_buffer(views),
                                                          pa.py_buffer(pad)])
    vals = pc.cast(arr, pa.float64()).to_numpy(zero_copy_only=False)
    if bad.any():
        vals = np.where(ok, vals, np.nan)
    return ok, vals


def _kind_ok(kind, ln, nd, ndot, ns, nother, first, c6) -> np.ndarray:
    """The field patterns of :mod:`gripsense.io.nmea_reference` from character-class counts."""
    if kind == S.INT:
        return nd == ln
    if kind == S.DATE:
        return (ln == 6) & (nd == 6)
    if kind == S.UNUM:
        return (nd >= 1) & (ndot <= 1) & (ns == 0) & (nother == 0)
    if kind == S.NUM:
        lead = (first == ord("+")) | (first == ord("-"))
        ok_sign = (ns == 0) | ((ns == 1) & lead)
        return (nd >= 1) & (ndot <= 1) & (nother == 0) & ok_sign
    if kind == S.TIME:
        base = (ns == 0) & (nother == 0) & (ndot <= 1) & (ln >= 6)
        return base & (((ln == 6) & (ndot == 0)) | ((ln > 6) & (c6 == ord("."))))
    raise ValueError(kind)


def _valid_kind(kind: str, g: np.ndarray, off: np.ndarray) -> np.ndarray:
    """Whether each gathered field (non-empty, <= MAX_FIELD bytes) matches its kind's pattern.

    Used for fields longer than 16 bytes; the character classes of each field are counted with
    one ``reduceat`` over packed 16-bit counters.
    """
    a = off[:-1]
    ln = np.diff(off)
    packed = np.add.reduceat(_PACK[g], a)
    nd = (packed & 0xFFFF).astype(np.int64)
    ndot = ((packed >> 16) & 0xFFFF).astype(np.int64)
    ns = ((packed >> 32) & 0xFFFF).astype(np.int64)
    nother = (packed >> 48).astype(np.int64)
    first = g[a]
    c6 = g[np.minimum(a + 6, g.size - 1)]
    return _kind_ok(kind, ln, nd, ndot, ns, nother, first, c6)


def _to_float(g: np.ndarray, off: np.ndarray) -> np.ndarray:
    """Arrow string -> float64 cast of the gathered fields."""
    n = off.size - 1
    if n == 0:
        return np.empty(0, dtype=np.float64)
    if off[-1] < 2**31:
        arr = pa.StringArray.from_buffers(n, pa.py_buffer(off.astype(np.int32)), pa.py_buffer(g))
    else:
        arr = pa.LargeStringArray.from_buffers(n, pa.py_buffer(off), pa.py_buffer(g))
    return pc.cast(arr, pa.float64()).to_numpy(zero_copy_only=False)


def _strip(buf: np.ndarray, starts: np.ndarray, ends: np.ndarray, data: bytes):
    """Bounds of each line without leading/trailing spaces, tabs and CR."""
    ls, le = starts.copy(), ends.copy()
    nb = buf.size
    for _ in range(8):
        m = ls < le
        m[m] = _WS[buf[ls[m]]]
        if not m.any():
            break
        ls[m] += 1
    for _ in range(8):
        m = le > ls
        m[m] = _WS[buf[le[m] - 1]]
        if not m.any():
            break
        le[m] -= 1
    # rare: more than 8 whitespace characters at an end -> per line
    m = ls < le
    m[m] = _WS[buf[ls[m]]] | _WS[buf[np.minimum(le[m] - 1, nb - 1)]]
    for i in np.flatnonzero(m).tolist():
        seg = data[ls[i] : le[i]]
        st = seg.strip(b" \t\r")
        if st:
            ls[i] += len(seg) - len(seg.lstrip(b" \t\r"))
            le[i] = ls[i] + len(st)
        else:
            le[i] = ls[i]
    return ls, le


def _tokenize_chunk(data: bytes) -> Tokens:
    """Tokenize one chunk of whole lines (see :func:`tokenize_fast`)."""
    return _tokenize_array(data)


def tokenize_fast(
    data: bytes, *, n_details: int = 20, chunk_bytes: int = 4 << 20, workers: int | None = None
) -> Tokens:
    """Tokenize a buffer with array operations (same results as the reference).

    The buffer is cut at line ends into chunks of about *chunk_bytes*, which are tokenized
    independently (on up to *workers* threads; numpy and Arrow release the GIL) and joined.
    Chunks keep the working set in cache and memory bounded by the chunk size.

    Parameters
    ----------
    data : bytes
        The whole input.
    n_details : int
        Reject details are worded (by the reference classifier) for this many first rejects.
    chunk_bytes : int
        Target chunk size [bytes].
    workers : int or None
        Threads; default: the number of CPUs (at most 4).

    Returns
    -------
    Tokens
    """
    nb = len(data)
    cuts = [0]
    while nb - cuts[-1] > chunk_bytes:
        j = data.find(b"\n", cuts[-1] + chunk_bytes)
        if j < 0 or j + 1 >= nb:
            break
        cuts.append(j + 1)
    cuts.append(nb)
    mv = memoryview(data)
    pieces = [mv[a:b] for a, b in zip(cuts[:-1], cuts[1:], strict=True)]
    if len(pieces) == 1:
        parts = [_tokenize_array(data)]
    else:
        n_workers = workers or min(os.cpu_count() or 1, 4)
        with ThreadPoolExecutor(max_workers=n_workers) as ex:
            parts = list(ex.map(_tokenize_array, pieces))
    tok = _join(parts)
    if n_details:
        rej = np.flatnonzero(tok.outcome == REJECTED)[:n_details]
        if rej.size:
            lines = split_lines(data)
            for i in rej.tolist():
                tok.details[i] = classify_line(lines[i])[2]
    return tok


def _join(parts: list[Tokens]) -> Tokens:
    """Concatenate chunk tokens (line indices shifted, label codes mapped to one name list)."""
    if len(parts) == 1:
        return parts[0]
    names: dict[str, int] = {}
    codes, outs, junks = [], [], []
    raw: dict[str, dict[str, np.ndarray]] = {}
    shift = 0
    shifted: list[tuple[int, Tokens]] = []
    for t in parts:
        remap = np.array([names.setdefault(nm, len(names)) for nm in t.names], dtype=np.int32)
        codes.append(remap[t.code] if t.code.size else t.code)
        outs.append(t.outcome)
        junks.append(t.junk_prefix)
        shifted.append((shift, t))
        shift += t.n_lines
    for k, spec in S.SENTENCES.items():
        tab = {}
        for f in ("line", *(f.name for f in spec.fields)):
            arrs = [t.raw[k][f] + sh if f == "line" else t.raw[k][f] for sh, t in shifted]
            tab[f] = np.concatenate(arrs)
        raw[k] = tab
    return Tokens(np.concatenate(outs), np.concatenate(codes), list(names), np.concatenate(junks),
                  raw)


def _tokenize_array(data) -> Tokens:
    """Tokenize a buffer with array operations (no chunking, no reject details).

    Parameters
    ----------
    data : bytes
        The whole input.
    n_details : int
        Reject details are worded (by the reference classifier) for this many first rejects.

    Returns
    -------
    Tokens
    """
    buf = np.frombuffer(data, dtype=np.uint8)
    nb = buf.size
    data = bytes(data) if isinstance(data, memoryview) else data
    special = (buf == 10) | (buf == 42) | (buf == 36) | (buf == 33) | (buf == 44)
    special |= (buf < 32) | (buf > 126)
    sp = np.flatnonzero(special)
    del special
    cv = _CLASS[buf[sp]]
    pad, rows = _rows16(buf)
    nl = sp[cv == _C_NL]
    starts = np.concatenate(([0], nl + 1)).astype(np.int64)
    ends = np.concatenate((nl, [nb])).astype(np.int64)
    if nb == 0 or buf[-1] == 10:
        starts, ends = starts[:-1], ends[:-1]
    n = starts.size
    names: list[str] = list(S.REASONS) + [S.BLANK, S.COMMENT]
    NAME = {k: i for i, k in enumerate(names)}
    outcome = np.full(n, -1, dtype=np.int8)
    code = np.zeros(n, dtype=np.int32)
    junk = np.zeros(n, dtype=bool)
    raw: dict[str, dict[str, np.ndarray]] = {k: empty_raw(s.fields) for k, s in S.SENTENCES.items()}
    if n == 0:
        return Tokens(outcome, code, names, junk, raw)

    def put(mask: np.ndarray, out: int, label: str) -> None:
        outcome[mask] = out
        code[mask] = NAME[label]

    ls, le = _strip(buf, starts, ends, data)
    empty = le <= ls
    put(empty, IGNORED, S.BLANK)
    pending = ~empty
    comment = pending & (buf[np.minimum(ls, nb - 1)] == ord("#"))
    put(comment, IGNORED, S.COMMENT)
    pending &= ~comment

    stars = sp[cv == _C_STAR]
    star = _last_before(stars, le, ls)
    limit = np.where(star >= 0, star, le)
    dollars = sp[cv == _C_START]
    d = _last_before(dollars, limit, ls)
    nostart = pending & (d < 0)
    put(nostart, REJECTED, S.NOT_NMEA)
    pending &= ~nostart
    junk[pending] = d[pending] > ls[pending]

    # address: up to the first comma (or the end of the body)
    commas = sp[cv == _C_COMMA]
    body0 = d + 1
    c0 = np.searchsorted(commas, body0)
    c1 = np.searchsorted(commas, limit)
    nf = np.where(pending, c1 - c0, 0)
    last_comma = max(commas.size - 1, 0)
    addr_end = np.where(nf > 0, commas[np.minimum(c0, last_comma)] if commas.size else limit, limit)
    alen = np.where(pending, addr_end - body0, 0)
    idx = np.flatnonzero(pending & (alen >= 1) & (alen <= MAX_ADDRESS))
    addr = np.ascontiguousarray(rows[body0[idx]]).view("<u8")[:, 0] & _BYTE_MASK[alen[idx]]
    mat = addr.view(np.uint8).reshape(-1, 8)
    pos_ok = np.arange(8)[None, :] < alen[idx][:, None]
    alnum_ok = np.where(pos_ok, _ALNUM[mat], True).all(axis=1)
    is_p = mat[:, 0] == ord("P")
    ok = alnum_ok & np.where(is_p, alen[idx] >= 3, alen[idx] == 5)
    addr_ok = np.zeros(n, dtype=bool)
    addr_ok[idx[ok]] = True
    badaddr = pending & ~addr_ok
    put(badaddr, REJECTED, S.NOT_NMEA)
    pending &= ~badaddr
    idx, addr, is_p = idx[ok], addr[ok], is_p[ok]

    # type keys: standard -> formatter, proprietary -> address (+ first field for $PSAT)
    key_code = np.full(n, -1, dtype=np.int32)
    inv, uniq = pd.factorize(addr, sort=False)
    psat = int.from_bytes(b"PSAT".ljust(8, b"\0"), "little")
    ucode = np.empty(uniq.size, dtype=np.int32)
    for j, u in enumerate(uniq.tolist()):
        a = _unpack8(u)
        ucode[j] = NAME.setdefault(_type_key(a, b"") if a[:1] == b"P" else a[2:].decode(),
                                   len(NAME))
    key_code[idx] = ucode[inv]
    sel = idx[addr == psat]
    if sel.size:
        has1 = nf[sel] >= 1
        f1a = np.where(has1, addr_end[sel] + 1, 0)
        f1b = np.where(nf[sel] >= 2, commas[np.minimum(c0[sel] + 1, last_comma)], limit[sel])
        f1len = np.where(has1, f1b - f1a, 0)
        fit = (f1len >= 1) & (f1len <= MAX_ADDRESS)
        sub = _pack8(buf, f1a, np.where(fit, f1len, 0))
        sinv, su = pd.factorize(sub, sort=False)
        scode = np.empty(su.size, dtype=np.int32)
        for j, u in enumerate(su.tolist()):
            key = _type_key(b"PSAT", _unpack8(u)) or "PSAT"
            scode[j] = NAME.setdefault(key, len(NAME))
        key_code[sel] = scode[sinv]
    names = list(NAME)
    known = np.zeros(n, dtype=bool)
    minf = np.zeros(n, dtype=np.int64)
    for k, spec in S.SENTENCES.items():
        if k in NAME:
            m = key_code == NAME[k]
            known |= m
            minf[m] = spec.min_fields

    # checksum
    nostar = pending & (star < 0)
    trunc0 = nostar & known & (nf < minf)
    put(trunc0, REJECTED, S.TRUNCATED)
    put(nostar & ~trunc0, REJECTED, S.MISSING_CHECKSUM)
    pending &= ~nostar
    cslen = le - star - 1
    short = pending & (cslen < 2)
    put(short, REJECTED, S.TRUNCATED)
    pending &= ~short
    pi = np.flatnonzero(pending)
    spi = star[pi]
    h1 = _HEXVAL[buf[np.minimum(spi + 1, nb - 1)]]
    h2 = _HEXVAL[buf[np.minimum(spi + 2, nb - 1)]]
    xor = _xor_segments(buf, d[pi] + 1, spi)
    csok = (cslen[pi] == 2) & (h1 >= 0) & (h2 >= 0) & ((h1 * 16 + h2) == xor)
    bad = np.zeros(n, dtype=bool)
    bad[pi[~csok]] = True
    put(bad, REJECTED, S.BAD_CHECKSUM)
    pending &= ~bad
    nonprint = sp[(cv == _C_NONPRINT) | (cv == _C_NL)]
    unprint = pending & (_count_between(nonprint, body0, limit) > 0)
    put(unprint, REJECTED, S.MALFORMED)
    pending &= ~unprint
    ign = pending & ~known
    outcome[ign] = IGNORED
    code[ign] = key_code[ign]
    pending &= ~ign
    trunc = pending & (nf < minf)
    put(trunc, REJECTED, S.TRUNCATED)
    pending &= ~trunc

    # fields of known sentences
    for k, spec in S.SENTENCES.items():
        if k not in NAME:
            continue
        li = np.flatnonzero(pending & (key_code == NAME[k]))
        if li.size == 0:
            continue
        good_all = np.ones(li.size, dtype=bool)
        cols: dict[str, np.ndarray] = {}
        c0l, nfl, liml = c0[li], nf[li], limit[li]
        for f in spec.fields:
            kf = f.index
            has = nfl >= kf
            a = np.where(has, commas[np.minimum(c0l + kf - 1, last_comma)] + 1, 0)
            b = np.where(has & (nfl > kf), commas[np.minimum(c0l + kf, last_comma)], liml)
            b = np.where(has, b, a)
            ln = b - a
            if f.kind == S.CHAR:
                val = np.zeros(li.size, dtype=np.uint8)
                one = ln == 1
                val[one] = buf[a[one]]
                good = ln <= 1
                if f.allowed:
                    good &= (ln == 0) | _table(f.allowed.encode())[val]
            else:
                val = np.full(li.size, np.nan)
                good = ln <= S.MAX_FIELD
                short = np.flatnonzero((ln > 0) & (ln <= 16))
                if short.size:
                    v, x = _fields16(pad, rows, a[short], ln[short], f.kind)
                    good[short] = v
                    val[short] = x
                sel = np.flatnonzero((ln > 16) & good)
                if sel.size:
                    g2, o2 = _gather(buf, a[sel], b[sel])
                    v = _valid_kind(f.kind, g2, o2)
                    good[sel] = v
                    if v.all():
                        val[sel] = _to_float(g2, o2)
                    else:
                        sv = sel[v]
                        g3, o3 = _gather(buf, a[sv], b[sv])
                        val[sv] = _to_float(g3, o3)
            cols[f.name] = val
            good_all &= good
        bad_lines = li[~good_all]
        outcome[bad_lines] = REJECTED
        code[bad_lines] = NAME[S.MALFORMED]
        okl = li[good_all]
        outcome[okl] = PARSED
        code[okl] = NAME[k]
        tab = {"line": okl.astype(np.int64)}
        for f in spec.fields:
            tab[f.name] = cols[f.name][good_all]
        raw[k] = tab

    if (outcome < 0).any():  # pragma: no cover - a bug, not bad input
        raise AssertionError("nmea_fast: a line was left without a bucket")
    return Tokens(outcome, code, names, junk, raw)
