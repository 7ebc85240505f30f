"""Live UBX accounting = batch accounting on real u-blox captures (issue 43).

:class:`~gripsense.live.LiveUbxIngest` must account every frame and line of a stream as
:func:`gripsense.io.logs.read_log` does on the same bytes: read, rejected per reason (with the
same first rejects: byte offsets of frames, lines of the NMEA text), ignored per message type,
the NMEA text's notes and junk, whatever pieces the bytes arrive in. The captures are
pyubx2's real receiver logs (NAV-PVT and 30 other NAV messages, UBX mixed with NMEA, a frame
with a bad checksum, corrupted length fields, a stream cut inside a frame, broken headers) and
GPSD's ZED-F9P capture (RXM-RAWX, NAV-CLOCK among NMEA, junk before a sentence). Before this
test the live reader said ``from unit 1`` for every reject's place, missed the last line of the
text when it had no line end, counted RTCM3 frames' line ends as lines and dropped the NMEA
notes and junk count. pyubx2 is the independent decoder that counts the good frames.
"""

from __future__ import annotations

from io import BytesIO
from itertools import pairwise
from pathlib import Path

import pandas as pd
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from gripsense.io.logs import read_log
from gripsense.live import LiveUbxIngest

pyubx2 = pytest.importorskip("pyubx2")

DATA = Path(__file__).parents[1] / "data"
REAL = [
    *sorted((DATA / "formats" / "ubx").glob("pyubx2-*.log")),
    DATA / "formats" / "nmea" / "pyubx2-mixed-rtcm3.log",
    DATA / "formats" / "nmea" / "pyubx2-mixed-rtcm3-badcrc.log",
]
GPSD_F9P = DATA / "gpsd" / "ublox-zed-f9p_hpg1.11.log"


def _live(data: bytes, cuts, report_at=()):
    live = LiveUbxIngest(source="s")
    out = []
    for j, (a, b) in enumerate(pairwise([0, *sorted(set(cuts)), len(data)])):
        out.append(live.feed(data[a:b]))
        if j in report_at:
            _ = live.report  # as the display reads it: counting in between changes nothing
    out.append(live.finish())
    got = [o for o in out if len(o)]
    return (pd.concat(got, ignore_index=True) if got else pd.DataFrame()), live.report


def _assert_same(path: Path, ep: pd.DataFrame, rep) -> None:
    batch = read_log(path)
    b = batch.report
    nz = lambda d: {k: v for k, v in d.items() if v}  # noqa: E731
    assert (rep.total_lines, rep.parsed, rep.ignored, nz(rep.rejected)) == (
        b.total_lines,
        b.parsed,
        b.ignored,
        nz(b.rejected),
    )
    assert [(r.line, r.reason, r.detail) for r in rep.first_rejects] == [
        (r.line, r.reason, r.detail) for r in b.first_rejects
    ]
    assert (rep.junk_prefix_lines, rep.notes, rep.unit, rep.format) == (
        b.junk_prefix_lines,
        b.notes,
        b.unit,
        b.format,
    )
    assert rep.balanced
    timed = batch.epochs[batch.epochs["time_utc"].notna()].reset_index(drop=True)
    assert rep.n_epochs == len(timed)
    if len(timed):
        cols = [c for c in ("time_utc", "heading_deg", "speed_mps", "lat_deg") if c in ep]
        pd.testing.assert_frame_equal(ep[cols], timed[cols], check_exact=False, atol=1e-9)


def _pyubx2_good_frames(data: bytes) -> int:
    r = pyubx2.UBXReader(BytesIO(data), protfilter=pyubx2.UBX_PROTOCOL, quitonerror=0)
    return sum(1 for raw, msg in r if msg is not None and raw[:2] == b"\xb5\x62")


@pytest.mark.parametrize("path", [*REAL, GPSD_F9P], ids=lambda p: p.name)
def test_whole_and_byte_by_byte_equal_batch(path):
    data = path.read_bytes()
    _assert_same(path, *_live(data, []))
    if len(data) < 20_000:
        _assert_same(path, *_live(data, range(1, len(data))))


@pytest.mark.parametrize("path", REAL, ids=lambda p: p.name)
@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(data=st.data())
def test_random_chunks_equal_batch(path, data):
    raw = path.read_bytes()
    cuts = data.draw(st.lists(st.integers(1, len(raw) - 1), max_size=30))
    report_at = data.draw(st.sets(st.integers(0, 30), max_size=4))
    _assert_same(path, *_live(raw, cuts, report_at))


@settings(max_examples=8, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(data=st.data())
def test_gpsd_capture_random_chunks_equal_batch(data):
    raw = GPSD_F9P.read_bytes()
    cuts = data.draw(st.lists(st.integers(1, len(raw) - 1), min_size=50, max_size=400))
    _assert_same(GPSD_F9P, *_live(raw, cuts))


@pytest.mark.parametrize("path", [REAL[0], GPSD_F9P], ids=lambda p: p.name)
def test_good_frames_are_pyubx2s(path):
    """Every frame pyubx2 decodes is one read or ignored UBX unit, live as in batch."""
    data = path.read_bytes()
    _, rep = _live(data, range(0, len(data), 997))
    n_ubx = sum(v for k, v in {**rep.parsed, **rep.ignored}.items() if k.startswith("UBX "))
    assert n_ubx == _pyubx2_good_frames(data) > 0
