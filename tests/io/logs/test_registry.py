"""The one table of log formats (gripsense.io.logs.registry.LOG_FORMATS): every registered
format recognises real files of its format, and no format tried before it claims them.

The files are the bundled real ones under tests/data/formats (tests/data/formats/README.md:
what each is and where it comes from). No Vector BLF or ASC file is bundled: those two are
written by python-can's own BLF and ASC writers (``write_can``), the library's reference
encoding of the formats."""

from __future__ import annotations

import gzip
from pathlib import Path

import pytest

from gripsense.io.logs import LOG_FORMATS, WRITABLE, detect_format, read_log, write_log
from gripsense.io.logs.dispatch import write_log as _dispatch_write_log
from tests.conftest import DATA

F = DATA / "formats"

REAL = {
    "mf4": [F / "mdf/ASAP2_Demo_V171.mf4.gz", *sorted((F / "can").glob("*.mf4.gz"))],
    "rosbag": [*sorted((F / "ros").glob("*.bag")), *sorted((F / "ros").glob("*.db3")),
               F / "ros/talker.mcap", F / "ros/robot_localization_test1_10s.bag.gz"],
    "vbo": [F / "sample.vbo", F / "vbox/vb3i_imu_can.vbo"],
    # UBX frames with NMEA between them (nmea/pyubx2-mixed-*: NMEA, RTCM3 and UBX) read as UBX
    "ubx": [*sorted((F / "ubx").glob("*.log")), *sorted((F / "nmea").glob("pyubx2-mixed-*.log"))],
    "novatel": sorted((F / "novatel").glob("*.asc")),
    "nmea": [p for p in sorted((F / "nmea").glob("*.log")) if "mixed" not in p.name],
}  # fmt: skip
REAL = {k: [p for p in v if p.exists()] for k, v in REAL.items()}  # GPL files: repository only


def _head(path: Path) -> bytes:
    data = path.read_bytes()
    if data[:2] == b"\x1f\x8b":  # read_log decompresses first, whatever the format
        data = gzip.decompress(data)
    return data[:65536]


def _can_logs(tmp_path: Path) -> dict[str, list[Path]]:
    pytest.importorskip("can")
    pytest.importorskip("cantools")
    from gripsense.io.logs.canlog import write_can
    from tests.io.logs.test_measurement_logs import DBC, _epochs

    out = {}
    for fmt in ("blf", "asc"):
        p = tmp_path / f"drive.{fmt}"
        write_can(_epochs(), p, DBC)
        out[fmt] = [p]
    return out


def test_every_format_claims_its_real_files_and_none_before_it_does(tmp_path):
    files = {**REAL, **_can_logs(tmp_path)}
    assert set(files) == set(LOG_FORMATS), "a registered format without a real file to test"
    order = list(LOG_FORMATS)
    for name, paths in files.items():
        f = LOG_FORMATS[name]
        assert paths
        for p in paths:
            head = _head(p)
            assert f.is_format(head), f"{p.name}: {name} does not recognise it"
            earlier = [e for e in order[: order.index(name)] if LOG_FORMATS[e].is_format(head)]
            assert not earlier, f"{p.name} ({name}) is claimed first by {earlier}"
            assert detect_format(head) == name


def test_every_format_but_the_last_refuses_the_other_formats_files(tmp_path):
    """A format's test is specific: it claims no real file of another format (NMEA, tried last,
    takes anything)."""
    files = {**REAL, **_can_logs(tmp_path)}
    for name, f in LOG_FORMATS.items():
        if name == list(LOG_FORMATS)[-1]:
            continue
        for other, paths in files.items():
            if other == name:
                continue
            claimed = [p.name for p in paths if f.is_format(_head(p))]
            assert not claimed, f"{name} claims {other} files {claimed}"


def test_the_table_is_the_order_of_detection():
    """MDF4, BLF, ROS bag, ASC, VBOX, UBX, NovAtel, NMEA last (docs/architecture.md)."""
    assert list(LOG_FORMATS) == ["mf4", "blf", "rosbag", "asc", "vbo", "ubx", "novatel", "nmea"]
    assert LOG_FORMATS["nmea"].is_format(b"\x00 anything")


def test_live_streams_exactly_the_byte_stream_formats():
    """Live mode replays NMEA and UBX as bytes paced by their own times; the others' epochs."""
    assert {n for n, f in LOG_FORMATS.items() if f.streams} == {"nmea", "ubx"}


def test_writers_come_from_the_table_and_read_back_as_their_format(tmp_path):
    from tests.io.logs.test_measurement_logs import _epochs

    pytest.importorskip("pyubx2")
    pytest.importorskip("asammdf")
    pytest.importorskip("rosbags")
    assert WRITABLE == ("nmea", "vbo", "ubx", "mf4", "rosbag2")
    assert _dispatch_write_log is write_log
    ep = _epochs()
    for fmt in WRITABLE:
        if fmt == "nmea":
            continue  # the receiver's sentences, not the epochs: tests/io/logs/test_read_log.py
        p = tmp_path / f"drive.{fmt}"
        cols = write_log(ep, p, fmt)
        log = read_log(p, columns=cols)
        assert len(log.epochs) == len(ep), fmt
        read_as = "rosbag" if fmt == "rosbag2" else fmt
        if p.is_file():
            assert detect_format(_head(p)) == read_as
