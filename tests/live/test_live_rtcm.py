"""Live = batch on NMEA streams with RTCM3 frames between the sentences (issue 43).

The live reader cuts the RTCM3 frames out of the byte stream before it splits lines, with the
batch reader's scanner (:class:`gripsense.io.logs.nmea.rtcm.RtcmStream`), so a frame whose bytes
hold a line end is one frame, and a frame cut across two reads is completed by the next. References:
the batch reader :func:`gripsense.io.read_nmea` on the same bytes, and pyrtcm / pyubx2 (whose
own CRC-24Q and frame layout build and decode the frames).
"""

from __future__ import annotations

import gzip
from io import BytesIO
from itertools import pairwise
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from gripsense.io import read_nmea
from gripsense.io.logs.nmea.rtcm import RtcmStream, split_rtcm
from gripsense.live import LiveIngest

pyrtcm = pytest.importorskip("pyrtcm")

NMEA = Path(__file__).parents[1] / "data" / "formats" / "nmea"
REAL = [
    NMEA / "pyubx2-mixed-rtcm3.log",
    NMEA / "pyubx2-mixed-rtcm3-badcrc.log",
    NMEA / "pyubx2-nmea-rtcm3.log",
]


def _live(data: bytes, cuts, *, report_at=(), max_lines: int = 3000):
    """Feed *data* split at the offsets *cuts* (in order); read the report after the pieces
    listed in *report_at* (as the display does); return the epochs and the final report."""
    live = LiveIngest(max_lines=max_lines)
    out = []
    edges = [0, *sorted(set(cuts)), len(data)]
    for j, (a, b) in enumerate(pairwise(edges)):
        out.append(live.feed(data[a:b]))
        if j in report_at:
            _ = live.report
    out.append(live.finish())
    got = [o for o in out if len(o)]
    ep = pd.concat(got, ignore_index=True) if got else pd.DataFrame()
    return ep, live.report


def _assert_same(data: bytes, ep: pd.DataFrame, rep) -> None:
    batch = read_nmea(data, decompress=False)
    b = batch.report
    assert (
        rep.total_lines,
        rep.parsed,
        rep.ignored,
        rep.rejected,
        rep.junk_prefix_lines,
        rep.n_epochs,
        rep.epochs_without_time,
        rep.unit,
    ) == (
        b.total_lines,
        b.parsed,
        b.ignored,
        b.rejected,
        b.junk_prefix_lines,
        b.n_epochs,
        b.epochs_without_time,
        b.unit,
    )
    assert [(r.line, r.reason, r.detail) for r in rep.first_rejects] == [
        (r.line, r.reason, r.detail) for r in b.first_rejects
    ]
    assert rep.balanced
    if batch.epochs.empty:
        assert ep.empty
    else:
        pd.testing.assert_frame_equal(ep, batch.epochs, check_exact=False, rtol=0, atol=1e-9)


def _pyrtcm_identities(data: bytes) -> list[str]:
    """Message numbers of the frames pyrtcm finds in *data* (its own parser and CRC)."""
    from pyrtcm import RTCMReader

    r = RTCMReader(BytesIO(data), quitonerror=0)
    return [p.identity for raw, p in r if p is not None]


# --- pyubx2's real u-blox stream ----------------------------------------------------------------


@pytest.mark.parametrize("path", REAL, ids=lambda p: p.name)
def test_real_stream_in_one_piece_and_byte_by_byte_equals_batch(path):
    """Before issue 43's live fix the live reader split the lines first: the frames' line-end
    bytes made 12 units of pyubx2's mixed stream where batch counts 10."""
    data = path.read_bytes()
    assert b"\n" in b"".join(data[s:e] for s, e in _frames(data))  # frames hold line ends
    _assert_same(data, *_live(data, []))
    _assert_same(data, *_live(data, range(1, len(data))))


def _frames(data: bytes) -> list[tuple[int, int]]:
    _, f = split_rtcm(data)
    assert f is not None
    return list(zip(f.start.tolist(), f.end.tolist(), strict=True))


@pytest.mark.parametrize("path", REAL, ids=lambda p: p.name)
@settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(data=st.data())
def test_real_stream_random_chunks_equal_batch(path, data):
    raw = path.read_bytes()
    cuts = data.draw(st.lists(st.integers(1, len(raw) - 1), max_size=40))
    report_at = data.draw(st.sets(st.integers(0, 40), max_size=5))
    _assert_same(raw, *_live(raw, cuts, report_at=report_at))


def test_real_stream_frames_are_pyubx2s():
    """The frames counted live are the ones pyubx2 decodes from the same bytes."""
    from pyubx2 import NMEA_PROTOCOL, RTCM3_PROTOCOL, UBX_PROTOCOL, UBXReader

    path = NMEA / "pyubx2-nmea-rtcm3.log"
    data = path.read_bytes()
    r = UBXReader(
        BytesIO(data), protfilter=UBX_PROTOCOL | NMEA_PROTOCOL | RTCM3_PROTOCOL, quitonerror=0
    )
    ref = [p.identity for raw, p in r if raw[:1] == b"\xd3"]
    _, rep = _live(data, range(7, len(data), 13))
    got = {k[6:]: v for k, v in rep.ignored.items() if k.startswith("RTCM3 ")}
    assert len(ref) == 7 and got == {m: ref.count(m) for m in ref}
    assert rep.total_lines == 9 and rep.n_rejected == 0  # 2 sentences + 7 frames


# --- a simulated drive with frames built by pyrtcm ------------------------------------------------


def _frame(msg: int, rng: np.random.Generator, n: int) -> bytes:
    """A valid RTCM3 frame (pyrtcm's serializer: preamble, length, CRC-24Q) of message *msg*
    with an *n*-byte payload of random fields."""
    from pyrtcm import RTCMMessage

    body = bytearray(rng.integers(0, 256, n, dtype=np.uint8).tobytes())
    body[0] = msg >> 4
    body[1] = ((msg & 0xF) << 4) | (body[1] & 0x0F)
    return RTCMMessage(payload=bytes(body)).serialize()


def _frames_with(rng, want: bytes, k: int) -> list[bytes]:
    out: list[bytes] = []
    while len(out) < k:
        f = _frame(1005, rng, 19)
        if want in f[3:]:
            out.append(f)
    return out


@pytest.fixture(scope="module")
def drive_with_rtcm(tmp_path_factory) -> tuple[bytes, dict[str, int]]:
    """A simulated drive's NMEA (``gripsense simulate``) with valid frames between its
    sentences: ones holding LF, CR, CR LF and "\\n$" among their bytes, others random, and one
    frame whose CRC was damaged."""
    from tests.io.simulated import simulate

    sim = simulate(tmp_path_factory.mktemp("simulated"))
    raw = sim.log.read_bytes()
    if raw[:2] == b"\x1f\x8b":
        raw = gzip.decompress(raw)
    lines = raw.splitlines(keepends=True)
    rng = np.random.default_rng(43)
    special = (
        _frames_with(rng, b"\n", 3)
        + _frames_with(rng, b"\r", 3)
        + _frames_with(rng, b"\r\n", 1)
        + [_frame(1230, rng, 4 + 10 * j) for j in range(3)]
    )
    # a frame whose bytes hold "\n$GPGGA": still one good frame
    f = bytearray(_frame(1005, rng, 19))
    f[8:15] = b"\n$GPGGA"
    body = bytes(f[3:-3])
    from pyrtcm import RTCMMessage

    special.append(RTCMMessage(payload=body).serialize())
    out = []
    pos = rng.choice(np.arange(1, len(lines)), size=len(special) + 60, replace=False)
    at = dict.fromkeys(pos.tolist())
    frames = iter(special + [_frame(1006, rng, 21) for _ in range(60)])
    bad_at = int(pos[-1])
    for i, line in enumerate(lines):
        if i in at:
            fr = next(frames)
            if i == bad_at:
                fr = fr[:-1] + bytes([fr[-1] ^ 0x55])  # CRC no longer matches
            out.append(fr)
        out.append(line)
    data = b"".join(out)
    assert any(b"\n" in s[3:] for s in special) and any(b"\r" in s[3:] for s in special)
    ids = _pyrtcm_identities(data)  # pyrtcm's reader: every good frame, not the damaged one
    return data, {m: ids.count(m) for m in set(ids)}


@pytest.mark.slow  # simulates a drive
def test_simulated_drive_with_frames_equals_batch(drive_with_rtcm):
    data, ref = drive_with_rtcm
    ep, rep = _live(data, [], max_lines=300)
    _assert_same(data, ep, rep)
    got = {k[6:]: v for k, v in rep.ignored.items() if k.startswith("RTCM3 ")}
    assert got == ref and sum(ref.values()) == 70  # 71 frames, one damaged
    assert rep.rejected["bad checksum"] == 1
    assert rep.rejected["not NMEA"] == 0
    # the epochs are the drive's: the same as without any frame
    clean = read_nmea(b"".join(_strip(data)), decompress=False).epochs
    pd.testing.assert_frame_equal(ep, clean, check_exact=False, rtol=0, atol=1e-9)


def _strip(data: bytes):
    text, _ = split_rtcm(data)
    yield text


@pytest.mark.slow  # simulates a drive
@settings(
    max_examples=25,
    deadline=None,
    suppress_health_check=[HealthCheck.too_slow, HealthCheck.function_scoped_fixture],
)
@given(data=st.data())
def test_simulated_drive_random_chunks_equal_batch(drive_with_rtcm, data):
    raw, _ = drive_with_rtcm
    cuts = data.draw(st.lists(st.integers(1, len(raw) - 1), min_size=50, max_size=400))
    report_at = data.draw(st.sets(st.integers(0, 400), max_size=5))
    _assert_same(raw, *_live(raw, cuts, report_at=report_at, max_lines=300))


# --- the scanner on its own -----------------------------------------------------------------------


@settings(max_examples=300, deadline=None)
@given(data=st.data())
def test_stream_scanner_equals_the_batch_scan(data):
    """Frames, damaged frames, truncated frames and preamble bytes between sentences, fed in
    random pieces: the text and frames equal one scan of the whole stream."""
    rng = np.random.default_rng(data.draw(st.integers(0, 2**32 - 1)))
    parts = []
    for _ in range(data.draw(st.integers(1, 12))):
        kind = data.draw(st.sampled_from(["nmea", "frame", "bad", "cut", "d3"]))
        if kind == "nmea":
            parts.append(b"$GPHDT,274.07,T*03\r\n")
        elif kind == "frame":
            parts.append(_frame(1005, rng, 19))
        elif kind == "bad":
            f = _frame(1006, rng, 21)
            parts.append(f[:-2] + bytes([f[-2] ^ 1]) + f[-1:])
        elif kind == "cut":
            f = _frame(1005, rng, 19)
            parts.append(f[: data.draw(st.integers(1, len(f) - 1))])
        else:
            parts.append(b"\xd3" + bytes([data.draw(st.integers(0, 255))]))
    raw = b"".join(parts)
    cuts = sorted(set(data.draw(st.lists(st.integers(1, max(len(raw) - 1, 1)), max_size=20))))
    s = RtcmStream()
    texts, starts, goods = [], [], []
    for a, b in zip([0, *cuts], [*cuts, len(raw)], strict=True):
        t, f = s.feed(raw[a:b])
        texts.append(t)
        if f is not None:
            starts += f.start.tolist()
            goods += f.good.tolist()
    t, f = s.feed(b"", final=True)
    texts.append(t)
    if f is not None:
        starts += f.start.tolist()
        goods += f.good.tolist()
    assert s.held == 0
    text, whole = split_rtcm(raw)
    assert b"".join(texts) == text
    assert starts == ([] if whole is None else whole.start.tolist())
    assert goods == ([] if whole is None else whole.good.tolist())
