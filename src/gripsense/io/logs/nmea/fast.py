"""Production NMEA 0183 tokenizer (the default path of :func:`gripsense.io.read_nmea`).

It implements exactly the rules of :mod:`gripsense.io.logs.nmea.reference`:

* compiled loops (:mod:`gripsense.io.logs.nmea.kernels`, numba) find each line's sentence start,
  checksum, address, fields and check every field's pattern;
* sentence types are named from the packed address bytes with one hash factorisation;
* numbers are converted in the same compiled pass, exactly: Clinger's fast path (the integer of
  the digits over an exact power of ten, one correctly rounded division) gives the double that
  Python's ``float`` gives for every field of at most ~16 significant digits — all that NMEA
  sends; longer ones are converted by ``float`` itself.

The buffer is cut at line ends into chunks, tokenized independently on up to two threads (the
compiled loops release the GIL), and joined. The test suite checks that this path and
the reference agree line by line on real logs and on fuzzed input.
"""

from __future__ import annotations

import itertools
from concurrent.futures import ThreadPoolExecutor
from typing import cast

import numba
import numpy as np
import pandas as pd

from gripsense.io.logs.nmea import kernels as K
from gripsense.io.logs.nmea import schema as S
from gripsense.io.logs.nmea.reference import MAX_ADDRESS, SUBTYPED, classify_line, type_key
from gripsense.io.logs.nmea.tokens import IGNORED, PARSED, REJECTED, Tokens, empty_raw, lines_at

__all__ = ["tokenize_fast"]

_SUBTYPED = {int.from_bytes(a.encode().ljust(8, b"\0"), "little"): a.encode() for a in SUBTYPED}
_SUBTYPED_WORDS = np.array(list(_SUBTYPED), dtype=np.uint64)


def _spec_arrays(spec: S.SentenceSpec):
    fidx = np.array([f.index for f in spec.fields], dtype=np.int64)
    fkind = np.array([K.KIND_CODES[f.kind] for f in spec.fields], dtype=np.int8)
    allowed = np.zeros((len(spec.fields), 257), dtype=np.bool_)
    for j, f in enumerate(spec.fields):
        if f.allowed:
            allowed[j, 256] = True
            allowed[j, np.frombuffer(f.allowed.encode(), dtype=np.uint8)] = True
    numeric = fkind != K.KIND_CODES[S.CHAR]
    numcol = np.where(numeric, np.cumsum(numeric) - 1, -1).astype(np.int64)
    slot = np.full(fidx.max() + 1, -1, dtype=np.int64)  # sentence field number -> spec field
    slot[fidx] = np.arange(fidx.size)
    return slot, fkind, allowed, numcol


_SPEC_ARRAYS = {k: _spec_arrays(s) for k, s in S.SENTENCES.items()}

# per line code of scan_buffer: the outcome and label it decides alone (PENDING: by the type)
_LC = {
    K.PENDING: (-1, None),
    K.BLANK: (IGNORED, S.BLANK),
    K.COMMENT: (IGNORED, S.COMMENT),
    K.NO_START: (REJECTED, S.NOT_NMEA),
    K.BAD_ADDRESS: (REJECTED, S.NOT_NMEA),
    K.NO_STAR: (REJECTED, S.MISSING_CHECKSUM),  # or truncated, by the type (below)
    K.CS_SHORT: (REJECTED, S.TRUNCATED),
    K.CS_BAD: (REJECTED, S.BAD_CHECKSUM),
    K.UNPRINTABLE: (REJECTED, S.MALFORMED),
    K.NO_STAR_BIN: (REJECTED, S.MISSING_CHECKSUM),  # or truncated, by the type (below)
}
_MIN_SPLIT = 1 << 20  # smaller inputs are tokenized in one piece [bytes]
_LC_OUTCOME = np.array([_LC[c][0] for c in range(len(_LC))], dtype=np.int8)
_LC_LABEL = [_LC[c][1] for c in range(len(_LC))]


def _tokenize_array(data, n: int | None = None, no_checksum: bool = False) -> Tokens:
    """Tokenize a buffer of whole lines (no chunking; reject details are added by the caller);
    *n*: its number of lines when already counted; *no_checksum*: read sentences without a
    checksum (a log whose talker sends none).
    """
    buf = np.frombuffer(data, dtype=np.uint8)
    n = K.count_lines(buf) if n is None else n
    NAME = {k: i for i, k in enumerate([*S.REASONS, S.BLANK, S.COMMENT])}
    raw = {k: empty_raw(s.fields) for k, s in S.SENTENCES.items()}
    if n == 0:
        z = np.zeros(0, dtype=np.int8)
        return Tokens(z, np.zeros(0, dtype=np.int32), list(NAME), np.zeros(0, dtype=bool), raw)

    lc = np.empty(n, dtype=np.int8)
    dpos = np.full(n, -1, dtype=np.int64)
    limit = np.empty(n, dtype=np.int64)
    nf = np.zeros(n, dtype=np.int64)
    junk = np.zeros(n, dtype=np.bool_)
    addr = np.zeros(n, dtype=np.uint64)
    sub = np.zeros(n, dtype=np.uint64)
    K.scan_buffer(buf, MAX_ADDRESS, lc, dpos, limit, nf, junk, addr, sub)
    # outcome and label of the line codes that decide alone (-1: decided below by the type)
    outcome = _LC_OUTCOME[lc]
    code = np.array([-1 if x is None else NAME.get(x, -1) for x in _LC_LABEL], dtype=np.int32)[lc]

    # sentence type keys of lines with a valid address (pending, no checksum, bad checksum...)
    typed = np.flatnonzero((lc == K.PENDING) | (lc >= K.NO_STAR))
    key_code = np.full(n, -1, dtype=np.int32)
    if typed.size:
        ta = addr[typed]
        inv, uniq = pd.factorize(ta, sort=False)
        ucode = np.empty(len(uniq), dtype=np.int32)
        for j, u in enumerate(uniq.tolist()):
            a = int(u).to_bytes(8, "little").rstrip(b"\0")
            # a valid address always has a key (type_key's None is for what is not one)
            key = cast(str, type_key(a, b"")) if a[:1] == b"P" else a[2:].decode()
            ucode[j] = NAME.setdefault(key, len(NAME))
        key_code[typed] = ucode[inv]
        for j in np.flatnonzero(np.isin(uniq, _SUBTYPED_WORDS)).tolist():
            name = _SUBTYPED[int(uniq[j])]
            sel = typed[inv == j]
            sinv, su = pd.factorize(sub[sel], sort=False)
            scode = np.empty(len(su), dtype=np.int32)
            for jj, u in enumerate(su.tolist()):
                key = type_key(name, int(u).to_bytes(8, "little").rstrip(b"\0")) or name.decode()
                scode[jj] = NAME.setdefault(key, len(NAME))
            key_code[sel] = scode[sinv]
    # fewest fields of the label's sentence type (-1: not a type gripsense reads); index + 1
    min_of = np.full(len(NAME) + 1, -1, dtype=np.int64)
    for k, spec in S.SENTENCES.items():
        if k in NAME:
            min_of[NAME[k] + 1] = spec.min_fields
    minf = min_of[key_code + 1]
    known = minf >= 0

    no_star = (lc == K.NO_STAR) | (lc == K.NO_STAR_BIN)
    trunc0 = no_star & known & (nf < minf)
    code[trunc0] = NAME[S.TRUNCATED]
    pending = lc == K.PENDING
    if no_checksum:
        bin_ = (lc == K.NO_STAR_BIN) & ~trunc0
        code[bin_] = NAME[S.MALFORMED]
        pending |= lc == K.NO_STAR
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
        slot, fkind, allowed, numcol = _SPEC_ARRAYS[k]
        m, nfld = li.size, fkind.size
        ok = np.empty(m, dtype=np.bool_)
        # column-major: each field's column is contiguous, a view when every line is valid
        cval = np.empty((m, nfld), dtype=np.uint8, order="F")
        vals = np.empty((m, int((numcol >= 0).sum())), dtype=np.float64, order="F")
        slow = np.empty((64, 4), dtype=np.int64)
        args = (buf, li, dpos, limit, slot, fkind, allowed, numcol, S.MAX_FIELD, ok, cval, vals)
        n_slow = K.read_fields(*args, slow)
        if n_slow > slow.shape[0]:
            slow = np.empty((n_slow, 4), dtype=np.int64)
            K.read_fields(*args, slow)
        for r, c, a, nb in slow[:n_slow].tolist():  # exact conversion of unusually long numbers
            vals[r, c] = float(bytes(buf[a : a + nb]))
        all_ok = bool(ok.all())
        if not all_ok:
            bad = li[~ok]
            outcome[bad] = REJECTED
            code[bad] = NAME[S.MALFORMED]
        okl = li if all_ok else li[ok]
        outcome[okl] = PARSED
        code[okl] = NAME[k]
        tab: dict[str, np.ndarray] = {"line": okl}
        for j, f in enumerate(spec.fields):
            col = cval[:, j] if f.kind == S.CHAR else vals[:, numcol[j]]
            tab[f.name] = col if all_ok else col[ok]
        raw[k] = tab

    if (outcome < 0).any():  # pragma: no cover - a bug, not bad input
        raise AssertionError("nmea fast tokenizer: a line was left without a bucket")
    return Tokens(outcome, code, list(NAME), junk, raw)


def _threads() -> int:
    """Threads of the tokenizer: numba's count for the calling thread (1 inside a fleet
    task), at most 4.
    """
    return min(numba.get_num_threads(), 4)


def _count(piece) -> int:
    return int(K.count_lines(np.frombuffer(piece, dtype=np.uint8)))


def tokenize_fast(
    data: bytes,
    *,
    n_details: int = 20,
    chunk_bytes: int = 8 << 20,
    workers: int | None = None,
    max_lines: int | None = None,
    no_checksum: bool = False,
) -> Tokens | None:
    """Tokenize a buffer (same results as :func:`~.reference.tokenize_reference`).

    The buffer is cut at line ends into chunks of about *chunk_bytes* (inputs above 1 MB into
    a multiple of *workers* equal chunks, so that the threads finish together), which are
    tokenized independently on up to *workers* threads and joined. Memory for intermediate arrays is
    bounded by the chunk size.

    Parameters
    ----------
    data : bytes
        The whole input.
    n_details : int
        Reject details are worded (by the reference classifier) for this many first rejects.
    chunk_bytes : int
        Target chunk size [bytes] (at most 1 GiB).
    workers : int or None
        Threads; default: numba's thread count for the calling thread (the number of CPUs
        unless set lower, e.g. 1 inside a fleet task), at most 4.
    max_lines : int or None
        Size guard: a buffer of more lines is not tokenized (its chunks' lines are counted
        first, and those counts size the work arrays).
    no_checksum : bool
        Read sentences without a ``*hh`` checksum instead of rejecting them (a log whose
        talker sends none; see :func:`~gripsense.io.logs.nmea.reference.classify_line`).

    Returns
    -------
    Tokens or None
        None when the buffer holds more than *max_lines* lines.
    """
    chunk_bytes = min(chunk_bytes, 1 << 30)
    nb = len(data)
    n_workers = workers or _threads()
    if n_workers > 1 and nb > _MIN_SPLIT:
        # as many equal chunks as fit the target size, a multiple of the threads (balanced)
        k = -(-nb // chunk_bytes)
        k = -(-k // n_workers) * n_workers
        chunk_bytes = -(-nb // k)
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
        counts = [_count(data)]
        if max_lines is not None and counts[0] > max_lines:
            return None
        parts = [_tokenize_array(data, counts[0], no_checksum)]
    else:
        with ThreadPoolExecutor(max_workers=n_workers) as ex:
            counts = list(ex.map(_count, pieces))
            if max_lines is not None and sum(counts) > max_lines:
                return None
            parts = list(ex.map(_tokenize_array, pieces, counts, [no_checksum] * len(pieces)))
    tok = _join(parts)
    if n_details:
        rej = np.flatnonzero(tok.outcome == REJECTED)[:n_details]
        if rej.size:
            for i, line in lines_at(data, rej.tolist()).items():
                tok.details[i] = classify_line(line, no_checksum)[2]
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
