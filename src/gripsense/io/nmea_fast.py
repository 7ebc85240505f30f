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

import numpy as np
import pyarrow as pa
import pyarrow.compute as pc

from gripsense.io import nmea_schema as S
from gripsense.io.nmea_reference import MAX_ADDRESS, _type_key, classify_line
from gripsense.io.nmea_tokens import IGNORED, PARSED, REJECTED, Tokens, empty_raw

__all__ = ["tokenize_fast"]

_KEYW = 2 * MAX_ADDRESS + 2  # bytes gathered to name a sentence type


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


def _last_before(pos: np.ndarray, limit: np.ndarray, floor: np.ndarray) -> np.ndarray:
    """Largest element of sorted *pos* that is < limit and >= floor, else -1."""
    j = np.searchsorted(pos, limit, side="left") - 1
    out = np.full(limit.shape, -1, dtype=np.int64)
    ok = j >= 0
    v = pos[np.where(ok, j, 0)] if pos.size else np.zeros_like(limit)
    ok &= v >= floor
    out[ok] = v[ok]
    return out


def _count_in(cum: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Number of True in [a, b) given cum = concat([0], cumsum(mask))."""
    return cum[b] - cum[a]


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
    idx = np.repeat(a - offsets[:-1], lengths) + np.arange(total, dtype=np.int64)
    return buf[idx], offsets


def _valid_kind(kind: str, g: np.ndarray, off: np.ndarray) -> np.ndarray:
    """Whether each gathered field (non-empty) matches its kind's pattern."""
    n = off.size - 1
    ln = np.diff(off)
    dig = _DIGIT[g]
    dot = g == ord(".")
    cd, cdot = _cum(dig), _cum(dot)
    nd = cd[off[1:]] - cd[off[:-1]]
    ndot = cdot[off[1:]] - cdot[off[:-1]]
    first = g[np.minimum(off[:-1], max(g.size - 1, 0))] if g.size else np.zeros(n, np.uint8)
    if kind == S.INT:
        return nd == ln
    if kind == S.DATE:
        return (ln == 6) & (nd == 6)
    if kind == S.UNUM:
        return (nd >= 1) & (ndot <= 1) & (nd + ndot == ln)
    if kind == S.NUM:
        sign = (g == ord("+")) | (g == ord("-"))
        cs = _cum(sign)
        ns = cs[off[1:]] - cs[off[:-1]]
        lead = (first == ord("+")) | (first == ord("-"))
        ok_sign = (ns == 0) | ((ns == 1) & lead)
        return (nd >= 1) & (ndot <= 1) & (nd + ndot + ns == ln) & ok_sign
    if kind == S.TIME:
        p6 = np.minimum(off[:-1] + 6, max(g.size - 1, 0))
        c6 = g[p6] if g.size else np.zeros(n, np.uint8)
        base = (nd + ndot == ln) & (ndot <= 1) & (ln >= 6)
        return base & (((ln == 6) & (ndot == 0)) | ((ln > 6) & (c6 == ord("."))))
    raise ValueError(kind)


def _to_float(g: np.ndarray, off: np.ndarray) -> np.ndarray:
    n = off.size - 1
    if n == 0:
        return np.empty(0, dtype=np.float64)
    arr = pa.StringArray.from_buffers(
        n, pa.py_buffer(off.astype(np.int32) if off[-1] < 2**31 else off), pa.py_buffer(g)
    ) if off[-1] < 2**31 else pa.LargeStringArray.from_buffers(n, pa.py_buffer(off), pa.py_buffer(g))
    return pc.cast(arr, pa.float64()).to_numpy(zero_copy_only=False)


def tokenize_fast(data: bytes, *, n_details: int = 20) -> Tokens:
    """Tokenize a buffer with array operations (same results as the reference).

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
    nl = np.flatnonzero(buf == 10)
    starts = np.concatenate(([0], nl + 1)).astype(np.int64)
    ends = np.concatenate((nl, [nb])).astype(np.int64)
    if nb == 0 or data.endswith(b"\n"):
        starts, ends = starts[:-1], ends[:-1]
    n = starts.size
    outcome = np.full(n, -1, dtype=np.int8)
    label = np.empty(n, dtype=object)
    junk = np.zeros(n, dtype=bool)
    raw: dict[str, dict[str, np.ndarray]] = {}
    if n == 0:
        return Tokens(outcome.astype(np.int8), label, junk,
                      {k: empty_raw(s.fields) for k, s in S.SENTENCES.items()})

    # strip whitespace at both ends
    nonws = np.flatnonzero(~_WS[buf])
    j = np.searchsorted(nonws, starts)
    ls = np.where(j < nonws.size, nonws[np.minimum(j, max(nonws.size - 1, 0))] if nonws.size
                  else starts, ends)
    le = _last_before(nonws, ends, starts) + 1
    empty = (le <= 0) | (ls >= ends) | (le <= ls)
    ls = np.where(empty, starts, ls)
    le = np.where(empty, starts, le)

    outcome[empty] = IGNORED
    label[empty] = S.BLANK
    pending = ~empty
    comment = pending & (buf[np.minimum(ls, nb - 1)] == ord("#"))
    outcome[comment] = IGNORED
    label[comment] = S.COMMENT
    pending &= ~comment

    stars = np.flatnonzero(buf == ord("*"))
    star = _last_before(stars, le, ls)
    limit = np.where(star >= 0, star, le)
    dollars = np.flatnonzero((buf == ord("$")) | (buf == ord("!")))
    d = _last_before(dollars, limit, ls)
    nostart = pending & (d < 0)
    outcome[nostart] = REJECTED
    label[nostart] = S.NOT_NMEA
    pending &= ~nostart
    junk[pending] = d[pending] > ls[pending]

    # address and fields
    commas = np.flatnonzero(buf == ord(","))
    body0 = d + 1
    c0 = np.searchsorted(commas, body0)
    c1 = np.searchsorted(commas, limit)
    nf = np.where(pending, c1 - c0, 0)
    addr_end = np.where(nf > 0, commas[np.minimum(c0, max(commas.size - 1, 0))] if commas.size
                        else limit, limit)
    alen = addr_end - body0
    cbad = _cum(~_ALNUM[buf])
    nbad = _count_in(cbad, np.clip(body0, 0, nb), np.clip(addr_end, 0, nb))
    first = buf[np.clip(body0, 0, nb - 1)]
    is_p = first == ord("P")
    addr_ok = (alen >= 1) & (alen <= MAX_ADDRESS) & (nbad == 0)
    addr_ok &= np.where(is_p, alen >= 3, alen == 5)
    badaddr = pending & ~addr_ok
    outcome[badaddr] = REJECTED
    label[badaddr] = S.NOT_NMEA
    pending &= ~badaddr

    # type keys: standard -> formatter, proprietary -> address (+ first field for PSAT)
    idx = np.flatnonzero(pending)
    f1_end = np.where(nf >= 2, commas[np.minimum(c0 + 1, max(commas.size - 1, 0))] if commas.size
                      else limit, limit)
    ka = np.where(is_p, body0, body0 + 2)[idx]
    kb = np.where(is_p, np.minimum(f1_end, body0 + _KEYW), body0 + 5)[idx]
    kb = np.maximum(kb, ka)
    g, off = _gather(buf, ka, kb)
    width = int(np.diff(off).max()) if idx.size else 1
    mat = np.zeros((idx.size, max(width, 1)), dtype=np.uint8)
    if idx.size:
        ln = np.diff(off)
        rows = np.repeat(np.arange(idx.size), ln)
        cols = np.arange(g.size) - np.repeat(off[:-1], ln)
        mat[rows, cols] = g
    keys_u, inv = np.unique(mat.view(f"S{mat.shape[1]}").ravel(), return_inverse=True)
    key_names = []
    for u in keys_u.tolist():
        if u[:1] == b"P":
            addr, _, rest = u.partition(b",")
            key_names.append(_type_key(addr, rest) or "?")
        else:
            key_names.append(u.decode("ascii"))
    key_names_arr = np.array(key_names, dtype=object)
    keyv = np.empty(n, dtype=object)
    keyv[idx] = key_names_arr[inv]

    known = np.zeros(n, dtype=bool)
    minf = np.zeros(n, dtype=np.int64)
    for k, spec in S.SENTENCES.items():
        m = keyv[idx] == k
        known[idx[m]] = True
        minf[idx[m]] = spec.min_fields

    # checksum
    nostar = pending & (star < 0)
    trunc0 = nostar & known & (nf < minf)
    outcome[trunc0] = REJECTED
    label[trunc0] = S.TRUNCATED
    outcome[nostar & ~trunc0] = REJECTED
    label[nostar & ~trunc0] = S.MISSING_CHECKSUM
    pending &= ~nostar
    cslen = le - star - 1
    short = pending & (cslen < 2)
    outcome[short] = REJECTED
    label[short] = S.TRUNCATED
    pending &= ~short
    sp = np.clip(star, 0, nb - 3)
    h1 = _HEXVAL[buf[np.minimum(sp + 1, nb - 1)]]
    h2 = _HEXVAL[buf[np.minimum(sp + 2, nb - 1)]]
    cx = np.bitwise_xor.accumulate(buf)
    xor = cx[np.clip(star - 1, 0, nb - 1)] ^ cx[np.clip(d, 0, nb - 1)]
    csok = (cslen == 2) & (h1 >= 0) & (h2 >= 0) & ((h1 * 16 + h2) == xor)
    bad = pending & ~csok
    outcome[bad] = REJECTED
    label[bad] = S.BAD_CHECKSUM
    pending &= ~bad
    nonp = _count_in(_cum(~_PRINT[buf]), np.clip(body0, 0, nb), np.clip(limit, 0, nb))
    unprint = pending & (nonp > 0)
    outcome[unprint] = REJECTED
    label[unprint] = S.MALFORMED
    pending &= ~unprint
    ign = pending & ~known
    outcome[ign] = IGNORED
    label[ign] = keyv[ign]
    pending &= ~ign
    trunc = pending & (nf < minf)
    outcome[trunc] = REJECTED
    label[trunc] = S.TRUNCATED
    pending &= ~trunc

    # fields of known sentences
    for k, spec in S.SENTENCES.items():
        li = np.flatnonzero(pending & (keyv == k))
        if li.size == 0:
            raw[k] = empty_raw(spec.fields)
            continue
        ok = np.ones(li.size, dtype=bool)
        cols: dict[str, np.ndarray] = {}
        for f in spec.fields:
            kf = f.index
            has = nf[li] >= kf
            a = np.where(has, commas[np.minimum(c0[li] + kf - 1, commas.size - 1)] + 1, 0)
            b = np.where(has & (nf[li] > kf), commas[np.minimum(c0[li] + kf, commas.size - 1)],
                         limit[li])
            b = np.where(has, b, a)
            gg, oo = _gather(buf, a, b)
            ln = np.diff(oo)
            if f.kind == S.CHAR:
                val = np.zeros(li.size, dtype=np.uint8)
                one = ln == 1
                val[one] = gg[oo[:-1][one]]
                good = ln <= 1
                if f.allowed:
                    good &= (ln == 0) | _table(f.allowed.encode())[val]
                cols[f.name] = val
            else:
                val = np.full(li.size, np.nan)
                ne = ln > 0
                good = np.ones(li.size, dtype=bool)
                if ne.any():
                    sel = np.flatnonzero(ne)
                    g2, o2 = _gather(buf, a[sel], b[sel])
                    v = _valid_kind(f.kind, g2, o2)
                    good[sel] = v
                    sv = sel[v]
                    g3, o3 = _gather(buf, a[sv], b[sv])
                    val[sv] = _to_float(g3, o3)
                cols[f.name] = val
            ok &= good
        bad_lines = li[~ok]
        outcome[bad_lines] = REJECTED
        label[bad_lines] = S.MALFORMED
        outcome[li[ok]] = PARSED
        label[li[ok]] = k
        tab = {"line": li[ok].astype(np.int64)}
        for f in spec.fields:
            tab[f.name] = cols[f.name][ok]
        raw[k] = tab

    assert not (outcome < 0).any(), "every line must end in a bucket"
    details: dict[int, str] = {}
    for i in np.flatnonzero(outcome == REJECTED)[:n_details].tolist():
        details[i] = classify_line(data[starts[i] : ends[i]])[2]
    return Tokens(outcome, label, junk, raw, details)
