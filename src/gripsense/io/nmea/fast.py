"""Production NMEA 0183 tokenizer (the default path of :func:`gripsense.io.read_nmea`).

It implements exactly the rules of :mod:`gripsense.io.nmea.reference`:

* compiled loops (:mod:`gripsense.io.nmea.kernels`, numba) find each line's sentence start,
  checksum, address, fields and check every field's pattern;
* sentence types are named from the packed address bytes with one hash factorisation;
* numbers are converted by Arrow's string-to-float cast (correctly rounded, like Python's
  ``float``) from ``string_view`` structs that point into the input buffer — no copies of fields.

The buffer is cut at line ends into chunks, tokenized independently on up to two threads (the
compiled loops and Arrow release the GIL), and joined. The test suite checks that this path and
the reference agree line by line on real logs and on fuzzed input.
"""

from __future__ import annotations

import itertools
import os
from concurrent.futures import ThreadPoolExecutor

import numpy as np
import pandas as pd
import pyarrow as pa
import pyarrow.compute as pc

from gripsense.io.nmea import kernels as K
from gripsense.io.nmea import schema as S
from gripsense.io.nmea.reference import MAX_ADDRESS, SUBTYPED, _type_key, classify_line
from gripsense.io.nmea.tokens import IGNORED, PARSED, REJECTED, Tokens, empty_raw, split_lines

__all__ = ["tokenize_fast"]

_BYTE_MASK = np.array(
    [(1 << (8 * k)) - 1 if k < 8 else (1 << 64) - 1 for k in range(9)], dtype=np.uint64
)
_SUBTYPED = {int.from_bytes(a.encode().ljust(8, b"\0"), "little"): a.encode() for a in SUBTYPED}


def _spec_arrays(spec: S.SentenceSpec):
    fidx = np.array([f.index for f in spec.fields], dtype=np.int64)
    fkind = np.array([K.KIND_CODES[f.kind] for f in spec.fields], dtype=np.int8)
    allowed = np.zeros((len(spec.fields), 257), dtype=np.bool_)
    for j, f in enumerate(spec.fields):
        if f.allowed:
            allowed[j, 256] = True
            allowed[j, np.frombuffer(f.allowed.encode(), dtype=np.uint8)] = True
    return fidx, fkind, allowed


_SPEC_ARRAYS = {k: _spec_arrays(s) for k, s in S.SENTENCES.items()}


def _words(buf: np.ndarray) -> np.ndarray:
    """uint64 view whose element i is the 8 bytes of (zero-padded) buf at offset i."""
    n = (buf.size + 24) // 8 * 8 + 8
    pad = np.zeros(n, dtype=np.uint8)
    pad[: buf.size] = buf
    return np.lib.stride_tricks.as_strided(
        pad.view("<u8"), shape=(buf.size + 9,), strides=(1,), writeable=False
    )


def _tokenize_array(data) -> Tokens:
    """Tokenize a buffer of whole lines (no chunking; reject details are added by the caller)."""
    buf = np.frombuffer(data, dtype=np.uint8)
    nb = buf.size
    nl = np.flatnonzero(buf == 10)
    starts = np.empty(nl.size + 1, dtype=np.int64)
    starts[0] = 0
    starts[1:] = nl + 1
    ends = np.empty(nl.size + 1, dtype=np.int64)
    ends[:-1] = nl
    ends[-1] = nb
    if nb == 0 or buf[-1] == 10:
        starts, ends = starts[:-1], ends[:-1]
    n = starts.size
    NAME = {k: i for i, k in enumerate([*S.REASONS, S.BLANK, S.COMMENT])}
    outcome = np.full(n, -1, dtype=np.int8)
    code = np.zeros(n, dtype=np.int32)
    raw = {k: empty_raw(s.fields) for k, s in S.SENTENCES.items()}
    if n == 0:
        return Tokens(outcome, code, list(NAME), np.zeros(0, dtype=bool), raw)

    lc = np.zeros(n, dtype=np.int8)
    dpos = np.full(n, -1, dtype=np.int64)
    star = np.full(n, -1, dtype=np.int64)
    send = np.zeros(n, dtype=np.int64)
    nf = np.zeros(n, dtype=np.int64)
    alen = np.zeros(n, dtype=np.int64)
    junk = np.zeros(n, dtype=np.bool_)
    f1a = np.zeros(n, dtype=np.int64)
    f1b = np.zeros(n, dtype=np.int64)
    K.scan_lines(buf, starts, ends, MAX_ADDRESS, lc, dpos, star, send, nf, alen, junk, f1a, f1b)
    limit = np.where(star >= 0, star, send)
    fixed = {
        K.BLANK: (IGNORED, S.BLANK),
        K.COMMENT: (IGNORED, S.COMMENT),
        K.NO_START: (REJECTED, S.NOT_NMEA),
        K.BAD_ADDRESS: (REJECTED, S.NOT_NMEA),
        K.CS_SHORT: (REJECTED, S.TRUNCATED),
        K.CS_BAD: (REJECTED, S.BAD_CHECKSUM),
        K.UNPRINTABLE: (REJECTED, S.MALFORMED),
    }
    for c, (out, label) in fixed.items():
        m = lc == c
        outcome[m] = out
        code[m] = NAME[label]

    # sentence type keys of lines with a valid address (pending, no checksum, bad checksum...)
    typed = np.flatnonzero((lc == K.PENDING) | (lc >= K.NO_STAR))
    key_code = np.full(n, -1, dtype=np.int32)
    if typed.size:
        words = _words(buf)
        addr = words[dpos[typed] + 1] & _BYTE_MASK[alen[typed]]
        inv, uniq = pd.factorize(addr, sort=False)
        ucode = np.empty(len(uniq), dtype=np.int32)
        for j, u in enumerate(uniq.tolist()):
            a = int(u).to_bytes(8, "little").rstrip(b"\0")
            key = _type_key(a, b"") if a[:1] == b"P" else a[2:].decode()
            ucode[j] = NAME.setdefault(key, len(NAME))
        key_code[typed] = ucode[inv]
        for word, name in _SUBTYPED.items():
            sel = typed[addr == word]
            if not sel.size:
                continue
            sl = f1b[sel] - f1a[sel]
            fit = (sl >= 1) & (sl <= MAX_ADDRESS)
            sub = words[f1a[sel]] & _BYTE_MASK[np.where(fit, sl, 0)]
            sinv, su = pd.factorize(sub, sort=False)
            scode = np.empty(len(su), dtype=np.int32)
            for j, u in enumerate(su.tolist()):
                key = _type_key(name, int(u).to_bytes(8, "little").rstrip(b"\0")) or name.decode()
                scode[j] = NAME.setdefault(key, len(NAME))
            key_code[sel] = scode[sinv]
    minf = np.full(n, -1, dtype=np.int64)
    for k, spec in S.SENTENCES.items():
        if k in NAME:
            minf[key_code == NAME[k]] = spec.min_fields
    known = minf >= 0

    nostar = lc == K.NO_STAR
    trunc0 = nostar & known & (nf < minf)
    outcome[nostar] = REJECTED
    code[nostar] = NAME[S.MISSING_CHECKSUM]
    code[trunc0] = NAME[S.TRUNCATED]
    pending = lc == K.PENDING
    ign = pending & ~known
    outcome[ign] = IGNORED
    code[ign] = key_code[ign]
    trunc = pending & known & (nf < minf)
    outcome[trunc] = REJECTED
    code[trunc] = NAME[S.TRUNCATED]
    pending &= known & ~trunc

    for k, spec in S.SENTENCES.items():
        if k not in NAME:
            continue
        li = np.flatnonzero(pending & (key_code == NAME[k]))
        if li.size == 0:
            continue
        fidx, fkind, allowed = _SPEC_ARRAYS[k]
        m, nfld = li.size, fidx.size
        ok = np.zeros(m, dtype=np.bool_)
        fa = np.empty((m, nfld), dtype=np.int64)
        fl = np.empty((m, nfld), dtype=np.int64)
        cval = np.zeros((m, nfld), dtype=np.uint8)
        views = np.empty((m, nfld, 16), dtype=np.uint8)
        K.read_fields(
            buf, li, dpos, limit, fidx, fkind, allowed, S.MAX_FIELD, ok, fa, fl, cval, views
        )
        numeric = np.flatnonzero(fkind != K.KIND_CODES[S.CHAR])
        vals = None
        if numeric.size:
            vv = np.ascontiguousarray(views[:, numeric, :]).reshape(-1, 16)
            arr = pa.Array.from_buffers(
                pa.string_view(), vv.shape[0], [None, pa.py_buffer(vv), pa.py_buffer(buf)]
            )
            vals = pc.cast(arr, pa.float64()).to_numpy(zero_copy_only=False)
            vals = np.array(vals, dtype=np.float64).reshape(m, numeric.size)
            empty = fl[:, numeric] == 0
            if empty.any():
                vals[empty] = np.nan
        bad = li[~ok]
        outcome[bad] = REJECTED
        code[bad] = NAME[S.MALFORMED]
        okl = li[ok]
        outcome[okl] = PARSED
        code[okl] = NAME[k]
        tab = {"line": okl}
        c = 0
        for j, f in enumerate(spec.fields):
            if f.kind == S.CHAR:
                tab[f.name] = cval[ok, j]
            else:
                tab[f.name] = vals[ok, c]
                c += 1
        raw[k] = tab

    if (outcome < 0).any():  # pragma: no cover - a bug, not bad input
        raise AssertionError("nmea fast tokenizer: a line was left without a bucket")
    return Tokens(outcome, code, list(NAME), junk, raw)


def tokenize_fast(
    data: bytes, *, n_details: int = 20, chunk_bytes: int = 8 << 20, workers: int | None = None
) -> Tokens:
    """Tokenize a buffer (same results as :func:`~gripsense.io.nmea.reference.tokenize_reference`).

    The buffer is cut at line ends into chunks of about *chunk_bytes*, which are tokenized
    independently on up to *workers* threads and joined. Memory for intermediate arrays is
    bounded by the chunk size.

    Parameters
    ----------
    data : bytes
        The whole input.
    n_details : int
        Reject details are worded (by the reference classifier) for this many first rejects.
    chunk_bytes : int
        Target chunk size [bytes] (at most 1 GiB: views address the chunk with 32-bit offsets).
    workers : int or None
        Threads; default: the number of CPUs, at most 4.

    Returns
    -------
    Tokens
    """
    chunk_bytes = min(chunk_bytes, 1 << 30)
    nb = len(data)
    cuts = [0]
    while nb - cuts[-1] > chunk_bytes:
        j = data.find(b"\n", cuts[-1] + chunk_bytes)
        if j < 0 or j + 1 >= nb:
            break
        cuts.append(j + 1)
    cuts.append(nb)
    mv = memoryview(data)
    pieces = [mv[a:b] for a, b in itertools.pairwise(cuts)]
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
    shifts = np.cumsum([0] + [t.n_lines for t in parts[:-1]])
    for t in parts:
        remap = np.array([names.setdefault(nm, len(names)) for nm in t.names], dtype=np.int32)
        codes.append(remap[t.code] if t.code.size else t.code)
        outs.append(t.outcome)
        junks.append(t.junk_prefix)
    raw: dict[str, dict[str, np.ndarray]] = {}
    for k, spec in S.SENTENCES.items():
        tab = {
            "line": np.concatenate(
                [t.raw[k]["line"] + sh for sh, t in zip(shifts, parts, strict=True)]
            )
        }
        for f in spec.fields:
            tab[f.name] = np.concatenate([t.raw[k][f.name] for t in parts])
        raw[k] = tab
    return Tokens(
        np.concatenate(outs), np.concatenate(codes), list(names), np.concatenate(junks), raw
    )
