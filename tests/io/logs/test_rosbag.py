"""ROS bags (issue 43): real public bags (NovAtel's OEM7 driver test bags, ROS 2's own test
bags), bags written with rosbags' writers, and ``simulate --format rosbag2``.

References are independent of gripsense's reader: the NovAtel receiver's own binary log from
which the driver made each bag (``.gps``, decoded here from NovAtel's published message
layouts), rosbags' own reader, and gripsense's NMEA reader on the same drive's NMEA file.
"""

from __future__ import annotations

import gzip
import shutil
import struct
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

pytest.importorskip("rosbags")

from rosbags.highlevel import AnyReader

from gripsense.errors import InputError
from gripsense.io.logs import detect_format, read_log
from gripsense.io.logs.rosbag import is_rosbag
from tests.cli.inprocess import cli

ROS = Path(__file__).resolve().parents[2] / "data" / "formats" / "ros"


def _novatel(path: Path, msg_id: int) -> list[bytes]:
    """The bodies of one message of a NovAtel OEM7 binary log (long header: sync AA 44 12,
    header length at byte 3, message id at 4, body length at 8; short header: AA 44 13, body
    length at 3, id at 4, 12 bytes; CRC-32 after the body)."""
    raw = path.read_bytes()
    out, i = [], 0
    while (i := raw.find(b"\xaa\x44", i)) >= 0:
        if raw[i + 2] == 0x13:
            hlen, blen = 12, raw[i + 3]
        elif raw[i + 2] == 0x12:
            hlen, blen = raw[i + 3], struct.unpack_from("<H", raw, i + 8)[0]
        else:
            i += 2
            continue
        mid = struct.unpack_from("<H", raw, i + 4)[0]
        if mid == msg_id:
            out.append(raw[i + hlen : i + hlen + blen])
        i += hlen + blen + 4
    return out


def _rosbags(path: Path, topic: str, get) -> tuple[np.ndarray, np.ndarray]:
    """(header stamps [s], values) of a topic as rosbags' own reader gives them."""
    t, v = [], []
    with AnyReader([path]) as r:
        conns = [c for c in r.connections if c.topic == topic]
        for c, _, raw in r.messages(connections=conns):
            m = r.deserialize(raw, c.msgtype)
            t.append(m.header.stamp.sec + m.header.stamp.nanosec * 1e-9)
            v.append(get(m))
    return np.array(t), np.array(v, float)


def test_the_formats_are_recognised_by_content():
    assert is_rosbag((ROS / "align.bag").read_bytes()[:64]) == "bag"
    assert is_rosbag((ROS / "talker.mcap").read_bytes()[:64]) == "mcap"
    assert is_rosbag((ROS / "talker.db3").read_bytes()[:64]) == "db3"
    for f in ("align.bag", "talker.mcap", "talker.db3"):
        assert detect_format((ROS / f).read_bytes()[:65536]) == "rosbag"
    assert detect_format(b"$GPRMC,,V,,,,,,,,,,N*53\r\n") == "nmea"


def test_novatel_heading2_is_the_receivers_heading():
    """align.bag: NovAtel's driver turned the receiver's HEADING2 logs (align.gps) into
    novatel_oem7_msgs/HEADING2; read with no --columns, every heading is the receiver's."""
    bodies = _novatel(ROS / "align.gps", 1335)  # HEADING2
    # sol_stat, pos_type (u32), length, heading (f32) …
    ref = np.array([struct.unpack_from("<IIff", b)[3] for b in bodies])
    log = read_log(ROS / "align.bag")
    assert log.report.format == "ROS 1 bag" and log.report.unit == "messages"
    got = log.epochs["heading_deg"].to_numpy(float)
    assert len(ref) == 12 and len(got) == 12
    np.testing.assert_allclose(got, ref, atol=1e-4)  # float32 in both
    t, _ = _rosbags(ROS / "align.bag", "/novatel/oem7/heading2", lambda m: m.heading)
    np.testing.assert_allclose(log.epochs["time_utc"].astype("int64").to_numpy() / 1e9, t,
                               rtol=0, atol=1e-6)  # fmt: skip
    assert log.report.parsed == {"/novatel/oem7/heading2 (heading)": 12}


def test_novatel_bestvel_inspva_and_navsatfix_and_every_message_counted():
    """bestpos.bag: course and speed from BESTVEL, heading from INSPVA (as the receiver's
    bestpos.gps logs them), position from NavSatFix (as rosbags reads it); the topics not
    read are counted, none lost."""
    log = read_log(ROS / "bestpos.bag")
    rows = log.sentences
    vel = [struct.unpack_from("<IIffddd", b) for b in _novatel(ROS / "bestpos.gps", 99)]
    np.testing.assert_allclose(rows["course"]["value"], [v[5] for v in vel], atol=1e-9)
    np.testing.assert_allclose(rows["speed"]["value"], [v[4] for v in vel], atol=1e-9)
    # INSPVAS (508): week, seconds, lat, lon, height, v_n, v_e, v_u, roll, pitch, azimuth,
    # INS status; an azimuth while the INS aligns (status 1: azimuth 0) is not a heading
    pva = [struct.unpack_from("<Id9dI", b) for b in _novatel(ROS / "bestpos.gps", 508)]
    assert len(pva) == 10 and {p[11] for p in pva} >= {1, 7}
    good = [p[10] % 360 for p in pva if p[11] in (3, 6, 7)]
    np.testing.assert_allclose(log.epochs["heading_deg"], good, atol=1e-9)
    assert log.report.ignored[
        "/novatel/oem7/inspva (no valid value: no fix or flagged invalid)"
    ] == 10 - len(good)
    _, lat = _rosbags(ROS / "bestpos.bag", "/gps/fix", lambda m: m.latitude)
    np.testing.assert_allclose(rows["lat"]["value"], lat, rtol=0, atol=0)
    with AnyReader([ROS / "bestpos.bag"]) as r:
        n = {c.topic: c.msgcount for c in r.connections}
    rep = log.report
    assert rep.total_lines == sum(n.values()) == 58
    assert sum(rep.parsed.values()) + sum(rep.ignored.values()) + sum(rep.rejected.values()) == 58
    assert rep.ignored["/novatel/oem7/odom (nav_msgs/Odometry, not mapped)"] == 12
    assert rep.parsed["/novatel/oem7/bestvel (course, speed)"] == n["/novatel/oem7/bestvel"]


def test_imu_gives_the_yaw_rate():
    log = read_log(ROS / "ins1.bag")
    _, wz = _rosbags(ROS / "ins1.bag", "/gps/imu", lambda m: m.angular_velocity.z)
    np.testing.assert_allclose(log.epochs["yaw_rate_rps"], wz, rtol=0, atol=0)
    assert log.report.ignored["/novatel/oem7/insstdev (novatel_oem7_msgs/INSSTDEV, not mapped)"]


def test_a_gzip_bag_reads_as_the_bag(tmp_path):
    gz = tmp_path / "align.bag.gz"
    gz.write_bytes(gzip.compress((ROS / "align.bag").read_bytes()))
    a, b = read_log(gz).epochs, read_log(ROS / "align.bag").epochs
    pd.testing.assert_frame_equal(a, b)


@pytest.mark.parametrize("name", ["talker.mcap", "talker.db3"])
def test_a_bag_without_gnss_topics_is_one_line(name, tmp_path):
    """ROS 2's own test bags (std_msgs/String, rcl_interfaces): one line naming the topics
    and the --columns that would map one, non-zero exit."""
    r = cli("ingest", ROS / name)
    assert r.returncode != 0 and "Traceback" not in r.stderr
    assert (
        "no topic of a GNSS type known here" in r.stderr and "/topic (std_msgs/String)" in r.stderr
    )
    assert len(r.stderr.strip().splitlines()) == 1
    r = cli("ingest", ROS / name, "--columns", "heading=/topic.data:deg")
    assert r.returncode != 0 and "holds text, not numbers" in r.stderr
    r = cli("ingest", ROS / name, "--columns", "heading=/topik.data:deg")
    assert r.returncode != 0 and "did you mean /topic?" in r.stderr
    r = cli("ingest", ROS / name, "--columns", "heading=/topic.dta:deg")
    assert r.returncode != 0 and "has no field 'dta'" in r.stderr and "fields: data" in r.stderr
    # a ROS 2 bag folder, and a folder that is not one
    bag = tmp_path / "bag"
    bag.mkdir()
    shutil.copy(ROS / name, bag / name)
    (bag / "metadata.yaml").write_text("rosbag2_bagfile_information: {}\n")
    r = cli("ingest", bag)
    assert r.returncode != 0 and "Traceback" not in r.stderr and str(bag) in r.stderr
    r = cli("ingest", tmp_path)
    assert r.returncode != 0 and "a folder, not a log" in r.stderr


def _write_ros1(path: Path, topics: dict[str, tuple[str, str, list]]) -> None:
    """A ROS 1 bag with rosbags' writer: topic -> (msgtype, definition or "", [(t_ns, msg)])."""
    from rosbags.rosbag1 import Writer
    from rosbags.typesys import Stores, get_types_from_msg, get_typestore

    ts = get_typestore(Stores.ROS1_NOETIC)
    for msgtype, msgdef, _ in topics.values():
        if msgdef:
            ts.register(get_types_from_msg(msgdef, msgtype))
    with Writer(path) as w:
        for topic, (msgtype, _, msgs) in topics.items():
            conn = w.add_connection(topic, msgtype, typestore=ts)
            for t, make in msgs:
                w.write(conn, t, ts.serialize_ros1(make(ts.types), msgtype))


SENTENCE = "std_msgs/Header header\nstring sentence\n"


def _header(T, t_ns: int):
    stamp = T["builtin_interfaces/msg/Time"](t_ns // 10**9, t_ns % 10**9)
    return T["std_msgs/msg/Header"](0, stamp, "gps")


def test_nmea_sentences_in_a_bag_read_as_the_nmea_file(tmp_path):
    """nmea_msgs/Sentence messages go through the NMEA reader: the same epochs as the file."""
    from gripsense.data import path as data_path

    nmea = data_path("demo/case001.nmea.gz")
    lines = gzip.decompress(Path(nmea).read_bytes()).decode().splitlines()
    t0 = 1_700_000_000 * 10**9

    def sentence(i, s):
        return lambda T: T["nmea_msgs/msg/Sentence"](_header(T, t0 + i * 10**7), s)

    def vel(i):
        def make(T):
            lin = T["geometry_msgs/msg/Vector3"](1.0, 2.0, 0.0)
            twist = T["geometry_msgs/msg/Twist"](lin, T["geometry_msgs/msg/Vector3"](0, 0, 0))
            return T["geometry_msgs/msg/TwistStamped"](_header(T, t0 + i * 10**8), twist)

        return make

    msgs = [(t0 + i * 10**7, sentence(i, s)) for i, s in enumerate(lines)]
    bag = tmp_path / "nmea.bag"
    # as nmea_navsat_driver records: the sentences, and the velocity it made of them
    vels = [(t0 + i * 10**8, vel(i)) for i in range(3)]
    _write_ros1(bag, {
        "/nmea_sentence": ("nmea_msgs/msg/Sentence", SENTENCE, msgs),
        "/vel": ("geometry_msgs/msg/TwistStamped", "", vels),
    })  # fmt: skip
    a, b = read_log(bag), read_log(nmea)
    pd.testing.assert_frame_equal(a.epochs, b.epochs)
    assert a.report.format == "ROS 1 bag (nmea_msgs/Sentence)"
    assert a.report.total_lines == len(lines) + 3 and a.report.unit == "messages"
    assert a.report.ignored["/vel (geometry_msgs/TwistStamped, not mapped)"] == 3


NAVSATFIX = """std_msgs/Header header
NavSatStatus status
float64 latitude
float64 longitude
float64 altitude
float64[9] position_covariance
uint8 position_covariance_type
"""

RELPOSNED9 = """uint8 version
uint8 reserved0
uint16 refStationId
uint32 iTOW
int32 relPosN
int32 relPosE
int32 relPosD
int32 relPosLength
int32 relPosHeading
uint32 reserved1
int8 relPosHPN
int8 relPosHPE
int8 relPosHPD
int8 relPosHPLength
uint32 accN
uint32 accE
uint32 accD
uint32 accLength
uint32 accHeading
uint32 reserved2
uint32 flags
"""


def test_ublox_relposned_heading_flags_and_no_fix_counted(tmp_path):
    """ublox_msgs/NavRELPOSNED9 (ublox driver definition): relPosHeading in 1e-5 deg when its
    valid flag (0x100) is set; a flagged-invalid heading and a NavSatFix without fix are
    counted as ignored, not lost. The bag has no header on NavRELPOSNED9: record time."""
    t0 = 1_700_000_000 * 10**9
    heads = [12_345_678, 35_999_999, 100]
    flags = [0x137, 0x137, 0x037]  # the third: relPosHeadingValid clear

    def rel(h, f):
        def make(T):
            return T["ublox_msgs/msg/NavRELPOSNED9"](0, 0, 0, 0, 0, 0, 0, 0, h, 0, 0, 0, 0, 0,
                                                     0, 0, 0, 0, 0, 0, f)  # fmt: skip

        return make

    def fix(status):
        def make(T):
            return T["sensor_msgs/msg/NavSatFix"](
                _header(T, t0), T["sensor_msgs/msg/NavSatStatus"](status, 1), 48.0, 11.0, 500.0,
                np.zeros(9), 0,
            )  # fmt: skip

        return make

    bag = tmp_path / "ublox.bag"
    rels = [(t0 + i * 10**8, rel(h, f)) for i, (h, f) in enumerate(zip(heads, flags, strict=True))]
    _write_ros1(bag, {
        "/ublox/navrelposned": ("ublox_msgs/msg/NavRELPOSNED9", RELPOSNED9, rels),
        "/ublox/fix": ("sensor_msgs/msg/NavSatFix", "", [(t0, fix(0)), (t0 + 10**8, fix(-1))]),
    })  # fmt: skip
    log = read_log(bag)
    np.testing.assert_allclose(log.epochs["heading_deg"], [123.45678, 359.99999], atol=1e-9)
    rep = log.report
    assert rep.ignored == {
        "/ublox/fix (no valid value: no fix or flagged invalid)": 1,
        "/ublox/navrelposned (no valid value: no fix or flagged invalid)": 1,
    }
    assert rep.total_lines == 5 and sum(rep.parsed.values()) == 3


def test_simulate_rosbag2_reads_back_as_the_nmea_log_and_as_rosbags_reads_it(tmp_path):
    """simulate --format rosbag2 writes a ROS 2 bag folder with rosbags' writer: read back with
    the case index's --columns it gives the epochs of the same drive's NMEA log, the values
    rosbags' own reader gives, and nothing on stderr."""
    from tests.cli.test_formats_cli import SCENARIO

    sc = tmp_path / "sc.toml"
    sc.write_text(SCENARIO)
    outs = {}
    for fmt in ("nmea", "rosbag2"):
        r = cli("simulate", sc, "-o", tmp_path / fmt, "--format", fmt)
        assert r.returncode == 0, r.stderr
        outs[fmt] = pd.read_csv(tmp_path / fmt / "cases.csv").iloc[0]
    c = outs["rosbag2"]
    bag = tmp_path / "rosbag2" / c["log"]
    assert (bag / "metadata.yaml").is_file() and c["columns"] == "heading=/gps/heading:deg"
    r = cli("ingest", bag, "--columns", c["columns"])
    assert r.returncode == 0 and r.stderr == "", r.stderr
    assert "balanced: yes" in r.stdout
    n_msgs = int(r.stdout.split(" messages; balanced")[0].rsplit("= ", 1)[1])
    # the bag folder replayed by live as any epoch log
    vehicle = tmp_path / "rosbag2" / "vehicle.toml"
    r = cli("live", "--replay", bag, "--columns", c["columns"], "--vehicle", vehicle,
            "--speed", "0")  # fmt: skip
    assert r.returncode == 0, r.stderr
    assert f"{n_msgs} messages ({n_msgs} parsed, 0 ignored, 0 rejected)" in r.stdout
    a = read_log(bag, columns=c["columns"]).epochs
    b = read_log(tmp_path / "nmea" / outs["nmea"]["log"]).epochs
    assert len(a) == len(b) > 100
    assert (a["time_utc"].to_numpy() == b["time_utc"].to_numpy()).all()
    for col, tol in (("lat_deg", 1e-8), ("lon_deg", 1e-8), ("speed_mps", 1e-3),
                     ("course_deg", 1e-2), ("heading_deg", 1e-2)):  # fmt: skip
        d = np.abs(a[col].to_numpy(float) - b[col].to_numpy(float))
        if col.endswith("_deg") and col not in ("lat_deg", "lon_deg"):
            d = np.minimum(d, 360 - d)
        assert np.nanmax(d) < tol, col
    t, lat = _rosbags(bag, "/gps/fix", lambda m: m.latitude)
    np.testing.assert_allclose(a["lat_deg"], lat, rtol=0, atol=0)
    _, wz = _rosbags(bag, "/imu/data", lambda m: m.angular_velocity.z)
    np.testing.assert_allclose(a["yaw_rate_rps"], wz, rtol=0, atol=0)
    np.testing.assert_allclose(a["time_utc"].astype("int64").to_numpy() / 1e9, t, atol=1e-6)


def test_a_damaged_bag_is_one_line(tmp_path):
    cut = tmp_path / "cut.bag"
    cut.write_bytes((ROS / "align.bag").read_bytes()[:3000])
    with pytest.raises(InputError, match=r"cut\.bag"):
        read_log(cut)
    r = cli("ingest", cut)
    assert r.returncode != 0 and "Traceback" not in r.stderr and "cut.bag" in r.stderr


def test_messages_of_varying_length_decode_one_by_one_to_the_same_values(tmp_path):
    """Fixed-length messages are read from their bytes at each field's offset; messages
    whose length varies (a frame_id that changes) are decoded one by one: both give what
    rosbags' reader gives for every message."""
    t0 = 1_700_000_000 * 10**9
    lat = 48.0 + np.arange(40) * 1e-6

    def fix(i, frame):
        def make(T):
            h = T["std_msgs/msg/Header"](
                0, T["builtin_interfaces/msg/Time"](1_700_000_000, i), frame
            )
            status = T["sensor_msgs/msg/NavSatStatus"](-1 if i == 7 else 0, 1)
            return T["sensor_msgs/msg/NavSatFix"](h, status, lat[i], 11.0, 500.0, np.zeros(9), 0)

        return make

    for name, frames in (("same", ["gps"] * 40), ("varying", ["gps", "gps_antenna_1"] * 20)):
        bag = tmp_path / f"{name}.bag"
        msgs = [(t0 + i * 10**8, fix(i, f)) for i, f in enumerate(frames)]
        _write_ros1(bag, {"/fix": ("sensor_msgs/msg/NavSatFix", "", msgs)})
        log = read_log(bag)
        np.testing.assert_array_equal(log.sentences["lat"]["value"], np.delete(lat, 7))
        t, ref = _rosbags(bag, "/fix", lambda m: m.latitude)
        np.testing.assert_array_equal(log.sentences["lat"]["t_s"], np.delete(t, 7))
        np.testing.assert_array_equal(ref, lat)
        assert log.report.ignored == {"/fix (no valid value: no fix or flagged invalid)": 1}


def test_an_mcap_file_not_from_ros_is_one_line(tmp_path):
    """MCAP with JSON messages (Foxglove's own profile-less files): one line, no traceback."""
    from mcap import writer as mcap_writer  # a test dependency: the format's own writer

    path = tmp_path / "json.mcap"
    with path.open("wb") as f:
        w = mcap_writer.Writer(f)
        w.start()
        sid = w.register_schema(name="Pos", encoding="jsonschema", data=b'{"type":"object"}')
        cid = w.register_channel(topic="/pos", message_encoding="json", schema_id=sid)
        w.add_message(channel_id=cid, log_time=0, data=b'{"lat": 48}', publish_time=0)
        w.finish()
    r = cli("ingest", path)
    assert r.returncode != 0 and "Traceback" not in r.stderr
    assert (
        "an MCAP file not recorded by ROS" in r.stderr and len(r.stderr.strip().splitlines()) == 1
    )


def test_a_real_bag_leaves_stderr_empty():
    r = cli("ingest", ROS / "bestpos.bag")
    assert r.returncode == 0 and r.stderr == "", r.stderr
    assert "balanced: yes" in r.stdout


NAVPVT = """uint32 iTOW
uint16 year
uint8 month
uint8 day
uint8 hour
uint8 min
uint8 sec
uint8 valid
uint32 tAcc
int32 nano
uint8 fixType
uint8 flags
uint8 flags2
uint8 numSV
int32 lon
int32 lat
int32 height
int32 hMSL
uint32 hAcc
uint32 vAcc
int32 velN
int32 velE
int32 velD
int32 gSpeed
int32 heading
uint32 sAcc
uint32 headAcc
uint16 pDOP
uint8[6] reserved1
int32 headVeh
int16 magDec
uint16 magAcc
"""


def test_ublox_navpvt_in_its_units_and_flags(tmp_path):
    """ublox_msgs/NavPVT (the ublox driver's definition): 1e-7 deg, mm, mm/s, 1e-5 deg as the
    u-blox interface description gives them; headVeh only with headVehValid (0x20), nothing
    without gnssFixOK (0x01)."""
    t0 = 1_700_000_000 * 10**9
    rows = [  # lon, lat, hMSL, gSpeed, heading (of motion), headVeh, flags
        (113_456_789, 481_234_567, 512_345, 12_345, 9_000_000, 9_100_000, 0x21),
        (113_456_799, 481_234_577, 512_300, 12_400, 9_010_000, 9_110_000, 0x21),
        (0, 0, 0, 0, 0, 0, 0x00),
    ]

    def pvt(r, fl):
        lon, lat, hmsl, gs, hd, hv, _ = r
        return lambda T: T["ublox_msgs/msg/NavPVT"](
            0, 2023, 11, 14, 22, 13, 20, 0, 0, 0, 3, fl, 0, 12, lon, lat, hmsl + 48_000, hmsl,
            0, 0, 0, 0, 0, gs, hd, 0, 0, 0, np.zeros(6, np.uint8), hv, 0, 0,
        )  # fmt: skip

    # a dual-antenna (headVehValid) receiver, then a single antenna (headVeh never valid)
    for name, valid in (("dual", 0x21), ("single", 0x01)):
        bag = tmp_path / f"{name}.bag"
        msgs = [(t0 + i * 10**8, pvt(r, r[6] and valid)) for i, r in enumerate(rows)]
        _write_ros1(bag, {"/ublox/navpvt": ("ublox_msgs/msg/NavPVT", NAVPVT, msgs)})
        log = read_log(bag)
        ep = log.epochs
        assert len(ep) == 2
        np.testing.assert_allclose(ep["lat_deg"], [48.1234567, 48.1234577], atol=1e-12)
        np.testing.assert_allclose(ep["lon_deg"], [11.3456789, 11.3456799], atol=1e-12)
        np.testing.assert_allclose(ep["alt_m"], [512.345, 512.300], atol=1e-9)
        np.testing.assert_allclose(ep["speed_mps"], [12.345, 12.400], atol=1e-9)
        np.testing.assert_allclose(ep["course_deg"], [90.0, 90.1], atol=1e-9)
        if name == "dual":
            np.testing.assert_allclose(ep["heading_deg"], [91.0, 91.1], atol=1e-9)
        else:
            assert ep["heading_deg"].isna().all()
            assert any("heading: /ublox/navpvt gives none" in x for x in log.report.notes)
        assert log.report.ignored == {
            "/ublox/navpvt (no valid value: no fix or flagged invalid)": 1
        }


def test_gps_common_gpsfix_track_and_speed():
    """bestpos.bag's gps_common/GPSFix mapped by topic: track and speed as rosbags reads them."""
    log = read_log(ROS / "bestpos.bag", columns="course=/gps/gps,speed=/gps/gps")
    _, track = _rosbags(ROS / "bestpos.bag", "/gps/gps", lambda m: m.track)
    _, speed = _rosbags(ROS / "bestpos.bag", "/gps/gps", lambda m: m.speed)
    np.testing.assert_allclose(log.sentences["course"]["value"], np.mod(track, 360), atol=0)
    np.testing.assert_allclose(log.sentences["speed"]["value"], speed, atol=0)
    assert "/gps/gps (course, speed)" in log.report.parsed


def test_a_real_outdoor_bag_takes_the_gnss_time_base_not_the_imus(tmp_path):
    """robot_localization's Husky test bag (cut to its first 10 s, gzip): 100 Hz IMU, 2.5 Hz
    NavSatFix, Odometry. The epochs are the fixes; the IMU's yaw rate is interpolated onto
    them (np.interp on rosbags' own values), the odometry counted as not read."""
    gz = ROS / "robot_localization_test1_10s.bag.gz"
    plain = tmp_path / "rl.bag"
    plain.write_bytes(gzip.decompress(gz.read_bytes()))
    log = read_log(gz)
    t_fix, lat = _rosbags(plain, "/fix", lambda m: m.latitude)
    t_imu, wz = _rosbags(plain, "/imu/data", lambda m: m.angular_velocity.z)
    ep = log.epochs
    assert len(ep) == len(t_fix) == 25
    np.testing.assert_allclose(ep["time_utc"].astype("int64").to_numpy() / 1e9, t_fix, atol=1e-6)
    np.testing.assert_array_equal(ep["lat_deg"], lat)
    # (times of 1.4e9 s hold ~0.2 µs: the interpolation agrees to ~1e-7 rad/s)
    np.testing.assert_allclose(ep["yaw_rate_rps"], np.interp(t_fix, t_imu, wz), atol=1e-6)
    assert np.abs(ep["yaw_rate_rps"]).max() > 0.02  # a rate, not zeros
    rep = log.report
    assert rep.total_lines == 426 and rep.parsed == {
        "/fix (lat, lon, alt)": 25,
        "/imu/data (yaw_rate)": 301,
    }
    assert rep.ignored == {"/husky_velocity_controller/odom (nav_msgs/Odometry, not mapped)": 100}
