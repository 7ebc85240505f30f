"""Real ROS 2 bags of NovAtel's OEM7 driver (issue 43): ``.db3`` bags recorded by ROS 2 Humble,
which stores no message definitions, with ``novatel_oem7_msgs`` HEADING2, BESTVEL and INSPVA
(``tests/data/formats/README.md``). Before: ``AttributeError: 'numpy.ndarray' object has no
attribute 'status'`` (a traceback): rosbags could not decode a message and the reader went on.

References: rosbags' own deserialisation with the driver's own ``.msg`` files (bundled beside
the bags), the same receiver logs in the driver's ROS 1 bags (``align.bag``, ``bestpos.bag``,
whose connection headers carry their definitions), and the receiver's binary HEADING2 logs
(``align.gps``) decoded from NovAtel's published layout.
"""

from __future__ import annotations

import shutil
import sqlite3
import struct
from pathlib import Path

import numpy as np
import pytest

from gripsense.io.logs import read_log

pytest.importorskip("rosbags")

ROS = Path(__file__).resolve().parents[2] / "data" / "formats" / "ros"
MSGS = ROS / "novatel_oem7_msgs"
ALIGN2, BESTPOS2 = ROS / "novatel_align.db3", ROS / "novatel_bestpos.db3"


def _rosbags(path: Path, topic: str, get):
    """(header stamp [s], value, message) of each message of *topic*, decoded by rosbags with
    the driver's own message files registered."""
    from rosbags.highlevel import AnyReader
    from rosbags.typesys import Stores, get_types_from_msg, get_typestore

    ts = get_typestore(Stores.ROS2_HUMBLE)
    types: dict = {}
    for f in MSGS.glob("*.msg"):
        types.update(get_types_from_msg(f.read_text(), f"novatel_oem7_msgs/msg/{f.stem}"))
    ts.register(types)
    out = []
    with AnyReader([path], default_typestore=ts) as r:
        conns = [c for c in r.connections if c.topic == topic]
        for c, _, raw in r.messages(connections=conns):
            m = r.deserialize(raw, c.msgtype)
            out.append((m.header.stamp.sec + m.header.stamp.nanosec * 1e-9, get(m), m))
    return out


def _stamps(ep) -> np.ndarray:
    return (ep["time_utc"] - ep["time_utc"].iloc[0]).dt.total_seconds().to_numpy() + (
        ep["time_utc"].iloc[0].timestamp()
    )


def test_heading2_reads_as_rosbags_decodes_it_with_the_drivers_definitions():
    ref = _rosbags(ALIGN2, "/novatel/oem7/heading2", lambda m: m.heading)
    ok = [(t, h) for t, h, m in ref if m.sol_status.status == 0]  # SOL_COMPUTED
    assert len(ref) == 12 and len(ok) == 12
    log = read_log(ALIGN2)
    rep, ep = log.report, log.epochs
    assert rep.format == "ROS 2 bag" and rep.parsed == {"/novatel/oem7/heading2 (heading)": 12}
    assert sum(rep.rejected.values()) == 0 and rep.balanced
    t, h = np.array(ok).T
    np.testing.assert_allclose(ep["heading_deg"], h, rtol=0, atol=1e-12)
    np.testing.assert_allclose(_stamps(ep), t, rtol=0, atol=2e-6)


def _gps_headings(path: Path) -> list[float]:
    """HEADING2 (message 1335) headings of a NovAtel binary log: 28-byte header (its length at
    byte 3, message id at bytes 4–5), body: solution status, position type, length, heading
    (float32 at body offset 12) — the OEM7 manual's layout."""
    data = path.read_bytes()
    out, i = [], data.find(b"\xaa\x44\x12")
    while 0 <= i < len(data) - 28:
        hlen = data[i + 3]
        msg_id, blen = struct.unpack_from("<HxxH", data, i + 4)
        if msg_id == 1335:
            out.append(struct.unpack_from("<f", data, i + hlen + 12)[0])
        i = data.find(b"\xaa\x44\x12", i + hlen + blen + 4)
    return out


def test_the_same_receiver_logs_as_the_ros1_bag_and_the_gps_log():
    """The ROS 2 and the ROS 1 bag of the driver were published from the same receiver log
    (align.gps): the same 12 headings, in order."""
    ros2 = read_log(ALIGN2).epochs["heading_deg"].to_numpy()
    ros1 = read_log(ROS / "align.bag").epochs["heading_deg"].to_numpy()
    np.testing.assert_array_equal(ros2, ros1)
    np.testing.assert_allclose(ros2, _gps_headings(ROS / "align.gps"), rtol=0, atol=1e-5)


def test_bestvel_inspva_and_navsatfix_as_rosbags_decodes_them():
    log = read_log(BESTPOS2)
    rep, ep = log.report, log.epochs
    assert sum(rep.rejected.values()) == 0 and rep.balanced and rep.total_lines == 55
    vel = _rosbags(BESTPOS2, "/novatel/oem7/bestvel", lambda m: (m.hor_speed, m.trk_gnd))
    good = [(t, v) for t, v, m in vel if m.sol_status.status == 0]
    assert rep.parsed["/novatel/oem7/bestvel (course, speed)"] == len(good) == 5
    ins = _rosbags(BESTPOS2, "/novatel/oem7/inspva", lambda m: m.azimuth)
    aligned = [(t, a) for t, a, m in ins if m.status.status in (3, 6, 7)]
    assert rep.parsed["/novatel/oem7/inspva (heading)"] == len(aligned) == 8
    assert rep.ignored["/novatel/oem7/inspva (no valid value: no fix or flagged invalid)"] == 2
    # the heading epochs are the valid azimuths (the epochs' time base), course and speed the
    # good BESTVEL values, as rosbags decodes them and as the ROS 1 bag of the same receiver
    # log gives them
    np.testing.assert_allclose(ep["heading_deg"], [a % 360 for _, a in aligned], atol=1e-9)
    np.testing.assert_allclose(_stamps(ep), [t for t, _ in aligned], rtol=0, atol=2e-6)
    assert set(ep["heading_source"].astype(str)) == {"channel"}
    rows = log.sentences
    np.testing.assert_allclose(rows["speed"]["value"], [v[0] for _, v in good], atol=1e-12)
    np.testing.assert_allclose(rows["course"]["value"], [v[1] for _, v in good], atol=1e-12)
    ros1 = read_log(ROS / "bestpos.bag")
    for key in ("speed", "course"):
        np.testing.assert_array_equal(rows[key]["value"], ros1.sentences[key]["value"])
    np.testing.assert_array_equal(ep["heading_deg"], ros1.epochs["heading_deg"])


@pytest.mark.parametrize("change", ["cut", "longer"])
def test_bytes_the_definition_does_not_fit_are_malformed_never_misread(tmp_path, change):
    """A bag of another driver version (its HEADING2 a different length): every message is
    rejected with the reason, nothing is read with a wrong layout, no traceback."""
    bad = tmp_path / "bad.db3"
    shutil.copy(ALIGN2, bad)
    with sqlite3.connect(bad) as c:
        for i, d in list(c.execute("select id, data from messages")):
            d = d[:-4] if change == "cut" else d + b"\0\0\0\0"
            c.execute("update messages set data=? where id=?", (d, i))
    log = read_log(bad)
    rep = log.report
    assert rep.rejected["malformed field"] == 12 and rep.balanced
    assert log.epochs["heading_deg"].notna().sum() == 0
    if change == "longer":
        assert "does not fit its bytes" in rep.first_rejects[0].detail
