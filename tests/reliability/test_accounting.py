"""Every byte range of a binary log and every line of a text log is parsed, ignored or rejected
with a reason: a UBX frame with a corrupted length field is one ``bad length`` and the scan
resynchronises; a BLF of garbage is not "0 frames, balanced"; a cut BLF or ASC says it is cut
(issue 40, "Inputs that vanish from the accounting").

The logs are real: a simulated drive written as UBX by ``gripsense simulate`` (pyubx2) and as
BLF/ASC by python-can with the tests' DBC, damaged here byte by byte.
"""

from __future__ import annotations

import re

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from gripsense.errors import InputError
from gripsense.io.logs import read_log
from gripsense.io.logs.ubx import BAD_LENGTH, scan_frames
from tests.conftest import DATA
from tests.io.simulated import simulated  # noqa: F401  (real files of `gripsense simulate`)

can = pytest.importorskip("can")
pytest.importorskip("cantools")

DBC = DATA / "formats" / "vehicle.dbc"
SETTINGS = settings(
    max_examples=40, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture]
)


def _ubx_units(rep) -> int:
    """UBX frames in a report: parsed, ignored or rejected as frames."""
    frames = sum(v for k, v in {**rep.parsed, **rep.ignored}.items() if k.startswith("UBX"))
    first = {r.reason for r in rep.first_rejects if "byte " in r.detail}
    return frames + sum(rep.rejected.get(k, 0) for k in first)


# --- UBX ----------------------------------------------------------------------------------


@pytest.fixture(scope="module")
def ubx(tmp_path_factory):
    from tests.io.simulated import simulate

    s = simulate(tmp_path_factory.mktemp("sim"), "ubx")
    data = s.log.read_bytes()
    clean = read_log(s.log)
    return data, scan_frames(data), clean


@pytest.mark.parametrize("length", [0, 8, 40, 91, 93, 300, 4096, 5000, 65535])
@pytest.mark.parametrize("which", [0, 101, -1])
def test_a_ubx_length_field_corrupted_is_one_bad_length(ubx, tmp_path, length, which):
    """The issue's case and its class: whatever the corrupted length (shorter, longer,
    impossible, past the end) and wherever the frame (first, middle, last), the frame is
    rejected as ``bad length`` with its offset, every other frame and line is read as before,
    and the accounting balances over as many units as the clean file."""
    data, frames, clean = ubx
    k = int(frames["start"].iloc[which])
    true_len = int(frames["length"].iloc[which])
    if length == true_len:
        pytest.skip("not a corruption")
    b = bytearray(data)
    b[k + 4 : k + 6] = length.to_bytes(2, "little")
    p = tmp_path / "bad.ubx"
    p.write_bytes(bytes(b))
    rep = read_log(p).report
    ref = clean.report
    assert rep.balanced
    assert rep.total_lines == ref.total_lines  # 2776 in, 2776 accounted (the 2775)
    assert rep.rejected.get(BAD_LENGTH, 0) + rep.rejected["bad checksum"] == 1
    assert rep.n_parsed == ref.n_parsed - 1
    assert rep.n_ignored == ref.n_ignored and rep.junk_prefix_lines == 0
    bad = [r for r in rep.first_rejects if r.reason in (BAD_LENGTH, "bad checksum")]
    assert bad and f"byte {k}" in bad[0].detail
    if length > 4096:
        assert rep.rejected[BAD_LENGTH] == 1
    with pytest.raises(InputError, match=rf"bad\.ubx: byte {k}: UBX frame: "):
        read_log(p, strict=True)


@SETTINGS
@given(data=st.data())
def test_ubx_damage_never_loses_a_unit(ubx, tmp_path_factory, data):
    """Random length fields corrupted in random frames: every frame of the clean file is still
    a unit of the report (parsed or rejected), no NMEA line disappears, and the count of
    rejected frames is the count of damaged ones."""
    raw, frames, clean = ubx
    idx = data.draw(st.lists(st.integers(0, len(frames) - 1), min_size=1, max_size=4,
                             unique=True))  # fmt: skip
    b = bytearray(raw)
    hit = 0
    for i in sorted(idx):
        k = int(frames["start"].iloc[i])
        new = data.draw(st.integers(0, 65535))
        if new == int(frames["length"].iloc[i]):
            continue
        b[k + 4 : k + 6] = new.to_bytes(2, "little")
        hit += 1
    p = tmp_path_factory.mktemp("ubx") / "bad.ubx"
    p.write_bytes(bytes(b))
    rep = read_log(p).report
    ref = clean.report
    assert rep.balanced and rep.total_lines == ref.total_lines
    assert rep.n_parsed == ref.n_parsed - hit
    assert rep.rejected.get(BAD_LENGTH, 0) + rep.rejected["bad checksum"] == hit


def test_ubx_garbage_between_frames_is_counted(ubx, tmp_path):
    """Random bytes between frames: no frame lost, the garbage accounted as lines."""
    data, frames, clean = ubx
    k = int(frames["start"].iloc[50])
    junk = np.random.default_rng(4).integers(0, 256, 3000, dtype=np.uint8).tobytes()
    junk = junk.replace(b"\xb5", b"\x00").replace(b"$", b"#") + b"\r\n"
    p = tmp_path / "junk.ubx"
    p.write_bytes(data[:k] + junk + data[k:])
    rep = read_log(p).report
    assert rep.balanced and rep.n_parsed == clean.report.n_parsed
    assert rep.n_rejected >= 1


# --- CAN BLF and ASC ----------------------------------------------------------------------


@pytest.fixture(scope="module")
def can_logs(tmp_path_factory):
    from gripsense.io.logs.canlog import CAN_SIGNALS, write_can
    from tests.io.simulated import simulate

    d = tmp_path_factory.mktemp("can")
    ep = read_log(simulate(d, "nmea").log).epochs
    write_can(ep, d / "drive.blf", DBC)
    write_can(ep, d / "drive.asc", DBC)
    cols = ",".join(f"{k}={v}" for k, v in CAN_SIGNALS.items())
    return d, cols, len(ep)


def _read(path, cols):
    return read_log(path, columns=cols, dbc=DBC)


def test_blf_of_garbage_after_its_signature_is_an_error(can_logs, tmp_path):
    """``LOGG`` then garbage: one line naming the file (the old code: "0 frames, balanced")."""
    _, cols, _ = can_logs
    rng = np.random.default_rng(1)
    for n, name in ((20000, "garbage.blf"), (40, "short.blf")):
        p = tmp_path / name
        p.write_bytes(b"LOGG" + rng.integers(0, 256, n, dtype=np.uint8).tobytes())
        with pytest.raises(InputError, match=re.escape(name) + ": not a readable BLF"):
            _read(p, cols)


def test_blf_garbage_after_its_header_is_rejected_not_balanced_away(can_logs, tmp_path):
    """A valid header, then garbage, then the log's objects: the garbage is one rejected
    range (``not a BLF object``, with its offset) and every frame after it is read."""
    d, cols, n_ep = can_logs
    data = (d / "drive.blf").read_bytes()
    ref = _read(d / "drive.blf", cols).report
    junk = np.random.default_rng(2).integers(0, 256, 5000, dtype=np.uint8).tobytes()
    junk = junk.replace(b"LOBJ", b"XXXX")
    p = tmp_path / "mid.blf"
    p.write_bytes(data[:144] + junk + data[144:])
    rep = _read(p, cols).report
    assert rep.balanced and rep.n_epochs == n_ep and rep.parsed == ref.parsed
    assert rep.rejected["not a BLF object"] == 1 and rep.total_lines == ref.total_lines + 1
    assert "bytes 144–5143" in rep.first_rejects[0].detail
    only = tmp_path / "only.blf"
    only.write_bytes(data[:144] + junk)
    rep = _read(only, cols).report
    assert rep.n_rejected == 1 and rep.n_parsed == 0 and rep.total_lines == 1


@pytest.mark.parametrize("frac", [0.2, 0.33, 0.5, 0.9])
def test_a_cut_blf_says_it_is_cut(can_logs, tmp_path, frac):
    """A BLF cut off (a recording that stopped): the frames before the cut are read, the
    object cut is rejected as ``truncated`` and the notes say the file is cut off (the old
    code: 101 of 347 epochs, no note)."""
    d, cols, n_ep = can_logs
    data = (d / "drive.blf").read_bytes()
    p = tmp_path / "cut.blf"
    p.write_bytes(data[: int(len(data) * frac)])
    rep = _read(p, cols).report
    assert rep.balanced and rep.rejected["truncated"] == 1
    assert any("cut off" in n for n in rep.notes)
    assert 0 < rep.n_epochs < n_ep


def test_a_cut_or_garbled_asc_accounts_every_line(can_logs, tmp_path):
    """ASC: every line is a frame, an event or header line, or rejected — garbage lines are
    ``not ASC``; a last line cut in the middle is ``truncated`` and said (the old code refused
    the whole log for its last line, and skipped garbage lines without a word)."""
    d, cols, _ = can_logs
    text = (d / "drive.asc").read_text()
    ref = _read(d / "drive.asc", cols).report
    lines = text.splitlines()
    assert ref.balanced and ref.total_lines == len(lines) and ref.n_rejected == 0
    garbled = [*lines[:200], "hello world", "\x00\x01garbage", *lines[200:]]
    p = tmp_path / "garbled.asc"
    p.write_text("\n".join(garbled) + "\n")
    rep = _read(p, cols).report
    assert rep.balanced and rep.total_lines == len(garbled)
    assert rep.rejected["not ASC"] == 2 and rep.parsed == ref.parsed
    assert [r.line for r in rep.first_rejects] == [201, 202]
    cut = tmp_path / "cut.asc"
    cut.write_text(text[: len(text) // 2 - 7])
    rep = _read(cut, cols).report
    assert rep.balanced and rep.total_lines == len(text[: len(text) // 2 - 7].splitlines())
    assert rep.n_epochs > 0 and rep.rejected["truncated"] + rep.rejected["malformed field"] >= 1
    assert any("cut off" in n for n in rep.notes)


# --- MDF4 ---------------------------------------------------------------------------------


@pytest.mark.parametrize("frac", [0.3, 0.6, 0.95])
def test_a_cut_mdf4_is_one_line_not_a_short_log(simulated, tmp_path, frac):  # noqa: F811
    """MDF4 cut off: one error naming the file (its records cannot be counted) — never a
    shorter log that says it is balanced."""
    s = simulated("mf4")
    data = s.log.read_bytes()
    p = tmp_path / "cut.mf4"
    p.write_bytes(data[: int(len(data) * frac)])
    with pytest.raises(InputError, match=r"cut\.mf4: "):
        read_log(p, columns=s.columns)


# --- VBOX ---------------------------------------------------------------------------------


@pytest.mark.parametrize("cut", [3, 9, 20])
def test_a_cut_vbox_row_is_not_read_as_data(simulated, tmp_path, cut):  # noqa: F811
    """A VBOX file cut inside its last row: the row (whose last value may have lost digits
    while keeping all its fields) is rejected as ``truncated`` and the notes say the file is
    cut off — never read as a row with other values."""
    s = simulated("vbo")
    data = s.log.read_bytes()
    ref = read_log(s.log).report
    p = tmp_path / "cut.vbo"
    p.write_bytes(data[:-cut])
    rep = read_log(p).report
    assert rep.balanced and rep.total_lines == ref.total_lines
    assert rep.parsed["VBO data"] == ref.parsed["VBO data"] - 1
    assert rep.rejected["truncated"] == 1 and any("cut off" in n for n in rep.notes)
