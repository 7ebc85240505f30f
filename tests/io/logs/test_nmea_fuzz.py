"""Property tests: corrupted real lines never break ingest; both tokenizers agree exactly."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from gripsense.io import read_nmea
from gripsense.io.logs.nmea.epochs import epoch_boundaries, epoch_boundaries_loop
from gripsense.io.logs.nmea.fast import tokenize_fast
from gripsense.io.logs.nmea.reference import tokenize_reference
from tests.conftest import GPSD_LOGS

FORMATS = Path(__file__).resolve().parents[2] / "data" / "formats" / "nmea"
REAL = []
ASHTECH_BINARY = re.compile(rb"\$PASHR,(MCA|MPC|PBN|SNV|SAL|SNG|SNW),")
# GPSD's logs, and the proprietary sentences, RTCM-mixed and checksum-less logs of issue 43
for p in [*GPSD_LOGS, *sorted(FORMATS.glob("*.log"))]:
    for ln in p.read_bytes().split(b"\n"):
        ln = ln.rstrip(b"\r")
        # an Ashtech binary record is a frame, not a line: junk before one is a line of its own
        # (test_nmea_ashtech_binary.py), so a line's edits would not keep one unit per line
        if ln.startswith((b"$", b"!")) and len(ln) < 200 and not ASHTECH_BINARY.match(ln):
            REAL.append(ln)
REAL = sorted(set(REAL))


def assert_same_tokens(a, b) -> None:
    """Line-by-line equality of two tokenizations (outcome, label, junk flag, every value)."""
    np.testing.assert_array_equal(a.outcome, b.outcome)
    np.testing.assert_array_equal(a.labels, b.labels)
    np.testing.assert_array_equal(a.junk_prefix, b.junk_prefix)
    for k in a.raw:
        for c in a.raw[k]:
            np.testing.assert_array_equal(a.raw[k][c], b.raw[k][c])


@st.composite
def corrupted_line(draw):
    line = bytearray(draw(st.sampled_from(REAL)))
    op = draw(
        st.sampled_from(
            [
                "keep",
                "flip",
                "truncate",
                "checksum",
                "junk",
                "empty_field",
                "crlf",
                "insert",
                "delete",
            ]
        )
    )
    if op == "flip" and line:
        i = draw(st.integers(0, len(line) - 1))
        line[i] ^= 1 << draw(st.integers(0, 7))
    elif op == "truncate":
        line = line[: draw(st.integers(0, len(line)))]
    elif op == "checksum" and b"*" in line:
        j = line.rfind(b"*")
        line[j + 1 :] = draw(st.binary(min_size=0, max_size=3))
    elif op == "junk":
        line = bytearray(draw(st.binary(max_size=20))) + line
    elif op == "empty_field":
        parts = bytes(line).split(b",")
        k = draw(st.integers(0, len(parts) - 1))
        parts[k] = b""
        line = bytearray(b",".join(parts))
    elif op == "crlf":
        i = draw(st.integers(0, len(line)))
        line[i:i] = draw(st.sampled_from([b"\r", b"\r\n", b"\n", b"\n\r", b"  "]))
    elif op == "insert":
        i = draw(st.integers(0, len(line)))
        line[i:i] = draw(st.binary(min_size=1, max_size=4))
    elif op == "delete" and line:
        i = draw(st.integers(0, len(line) - 1))
        del line[i]
    return bytes(line)


@settings(max_examples=300, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.lists(corrupted_line(), min_size=1, max_size=40), st.sampled_from([b"\n", b"\r\n"]))
def test_fuzz_never_raises_and_accounts(lines, eol):
    data = eol.join(lines)
    n_lines = data.count(b"\n") + (0 if data.endswith(b"\n") or not data else 1)
    for engine in ("fast", "reference"):
        log = read_nmea(data, engine=engine)
        rep = log.report
        assert rep.total_lines == n_lines
        assert rep.balanced
        assert sum(len(f) for f in log.sentences.values()) == rep.n_parsed
    a, b = tokenize_fast(data), tokenize_reference(data)
    assert_same_tokens(a, b)


@settings(max_examples=200, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.lists(corrupted_line(), min_size=1, max_size=40), st.sampled_from([b"\n", b"\r\n"]))
def test_fuzz_without_checksums_both_tokenizers_agree(lines, eol):
    """Sentences read without checksums (a talker that sends none): the same line by line."""
    data = eol.join(re.sub(rb"\*[0-9A-Fa-f]{2}$", b"", ln) for ln in lines)
    a = tokenize_fast(data, no_checksum=True)
    b = tokenize_reference(data, no_checksum=True)
    assert_same_tokens(a, b)
    assert a.details == {i: d for i, d in b.details.items() if i in a.details}


@settings(max_examples=300, deadline=None)
@given(
    st.lists(
        st.tuples(st.integers(0, 4), st.one_of(st.none(), st.integers(0, 3).map(float))),
        max_size=60,
    )
)
def test_epoch_rule_compiled_equals_loop(seq):
    kind = np.array([k for k, _ in seq], dtype=np.int64)
    tod = np.array([np.nan if t is None else t for _, t in seq], dtype=float)
    np.testing.assert_array_equal(epoch_boundaries(kind, tod), epoch_boundaries_loop(kind, tod))


def test_chunked_threaded_equals_reference():
    """Many small chunks on several threads give the same tokens as one pass of the reference."""
    data = b"".join(p.read_bytes() for p in GPSD_LOGS)
    a = tokenize_fast(data, chunk_bytes=4096, workers=3)
    b = tokenize_reference(data)
    assert_same_tokens(a, b)
    assert a.details == {i: d for i, d in b.details.items() if i in a.details}
    assert len(a.details) == min(20, int((b.outcome == 2).sum()))


def test_real_logs_fast_equals_reference():
    for p in GPSD_LOGS:
        a, b = read_nmea(p, engine="fast"), read_nmea(p, engine="reference")
        assert a.report == b.report
        assert a.epochs.equals(b.epochs)


def _sentence(body: bytes) -> bytes:
    cs = 0
    for b in body:
        cs ^= b
    return b"$" + body + b"*%02X" % cs


number_text = st.builds(
    lambda sign, digits, dot: (
        sign
        + (
            digits
            if dot is None
            else digits[: dot % (len(digits) + 1)] + "." + digits[dot % (len(digits) + 1) :]
        )
    ),
    st.sampled_from(["", "-", "+"]),
    st.text(alphabet="0123456789", min_size=1, max_size=28),
    st.one_of(st.none(), st.integers(0, 30)),
)


@settings(max_examples=400, deadline=None)
@given(st.lists(number_text, min_size=1, max_size=20))
def test_numbers_are_pythons_float_to_the_bit(texts):
    """Every numeric field gives exactly the double of Python's ``float`` — short ones on the
    compiled fast path, long ones (> 16 significant digits, > 22 decimals) on the exact one."""
    data = b"\n".join(_sentence(b"GPHDT," + t.encode() + b",T") for t in texts)
    tok = tokenize_fast(data)
    got = tok.raw["HDT"]["heading"]
    want = np.array([float(t) for t in texts])
    assert got.size == len(texts)
    np.testing.assert_array_equal(got.view(np.int64), want.view(np.int64))
    assert_same_tokens(tok, tokenize_reference(data))


@settings(max_examples=200, deadline=None)
@given(st.lists(st.floats(allow_nan=True, allow_infinity=True), min_size=1, max_size=30))
def test_heading_wrap_is_numpys_mod_to_the_bit(values):
    """The wrap that skips in-range headings gives np.mod(h, 360)'s doubles, sign of 0 included."""
    from gripsense.io.logs.nmea.decode import _wrap360

    h = np.array([*values, -0.0, 360.0, -1e-300])
    with np.errstate(invalid="ignore"):
        want = np.mod(h, 360.0)
        got = _wrap360(h)
    nan = np.isnan(want)
    np.testing.assert_array_equal(np.isnan(got), nan)
    np.testing.assert_array_equal(got[~nan].view(np.int64), want[~nan].view(np.int64))


@settings(max_examples=300, deadline=None)
@given(st.floats(allow_nan=False, allow_infinity=False, min_value=-1e6, max_value=1e6))
def test_heading_change_wrap_is_the_modulo_formula_to_the_bit(d):
    """The yaw kernel's wrap skips the modulo in range and gives (d + 180) % 360 − 180."""
    from gripsense.io.logs.nmea.epochs import _wrap180

    want = (d + 180.0) % 360.0 - 180.0
    got = _wrap180(d)  # the compiled function
    assert np.float64(got).view(np.int64) == np.float64(want).view(np.int64)


def test_tokenizer_threads_follow_numbas_thread_count(monkeypatch):
    """With numba's thread count at 1 (a fleet task) a large input is tokenized in one piece
    on the calling thread, so fleet workers do not start threads on each other's cores."""
    import numba

    import gripsense.io.logs.nmea.fast as F

    data = b"".join(p.read_bytes() for p in GPSD_LOGS) * 3
    assert len(data) > F._MIN_SPLIT
    seen = []
    orig = F._tokenize_array
    monkeypatch.setattr(
        F, "_tokenize_array", lambda piece, *n: seen.append(len(piece)) or orig(piece, *n)
    )
    threads = numba.get_num_threads()
    numba.set_num_threads(1)
    try:
        one = F.tokenize_fast(data)
    finally:
        numba.set_num_threads(threads)
    assert seen == [len(data)]
    seen.clear()
    two = F.tokenize_fast(data, workers=2)
    assert len(seen) == 2 and sum(seen) == len(data)
    assert_same_tokens(one, two)


def test_epoch_columns_filled_on_threads_equal_the_calling_threads(monkeypatch):
    """A long log's epoch columns are filled on the tokenizer's threads; the table is the one
    the calling thread alone builds (every column, to the bit)."""
    import numba
    import pandas as pd

    import gripsense.io.logs.nmea.epochs as E

    data = b"".join(p.read_bytes() for p in GPSD_LOGS)
    monkeypatch.setattr(E, "_MIN_PARALLEL_EPOCHS", 0)
    threaded = read_nmea(data).epochs
    threads = numba.get_num_threads()
    numba.set_num_threads(1)
    try:
        alone = read_nmea(data).epochs
    finally:
        numba.set_num_threads(threads)
    assert len(alone) > 1000
    pd.testing.assert_frame_equal(threaded, alone, check_exact=True)


@pytest.mark.parametrize(
    ("engine", "size"), [("fast", "small"), ("fast", "chunked"), ("reference", "small")]
)
def test_size_guard_reads_the_first_max_lines_and_counts_the_rest(engine, size):
    """Past ``max_lines`` the lines are counted as over the size limit and not read: the report
    covers every line and the epochs are those of the first ``max_lines`` lines; at the limit
    nothing is cut. (The fast tokenizer counts its chunks' lines first and only then cuts.)"""
    import pandas as pd

    from gripsense.io.logs.nmea import schema as S
    from gripsense.io.logs.nmea.fast import _MIN_SPLIT
    from gripsense.io.logs.nmea.tokens import split_lines

    base = b"".join(p.read_bytes() for p in GPSD_LOGS)
    data = base if size == "small" else base * (_MIN_SPLIT // len(base) + 2)
    lines = split_lines(data)
    n, k = len(lines), len(lines) // 3
    log = read_nmea(data, engine=engine, max_lines=k)
    head = read_nmea(b"\n".join(lines[:k]) + b"\n", engine=engine)
    assert log.report.total_lines == n
    assert log.report.rejected[S.OVER_LIMIT] == n - k
    assert sum(log.report.parsed.values()) == sum(head.report.parsed.values())
    pd.testing.assert_frame_equal(log.epochs, head.epochs, check_exact=True)
    full = read_nmea(data, engine=engine, max_lines=n)
    assert full.report.rejected[S.OVER_LIMIT] == 0 and full.report.total_lines == n
