"""Real MDF4 and CAN files nobody here wrote (issue 43): a CANape MDF4 with a 256-byte string
channel, a CANedge MDF4 bus log of raw CAN frames with its GNSS DBC (each message defined
twice, at ids 1–9 and 0x11–0x19). References: asammdf's own reader and its own bus-logging
decoder (``MDF.extract_bus_logging``, canmatrix), never numbers gripsense produced.
Origins and licences: ``tests/data/formats/README.md``.
"""

from __future__ import annotations

import gzip
import json

import numpy as np
import pandas as pd
import pytest

from gripsense.errors import InputError
from gripsense.io.logs import read_log
from tests.cli.inprocess import cli
from tests.conftest import DATA

asammdf = pytest.importorskip("asammdf")
can = pytest.importorskip("can")
cantools = pytest.importorskip("cantools")

CANAPE = DATA / "formats" / "mdf" / "ASAP2_Demo_V171.mf4.gz"
CANEDGE = DATA / "formats" / "can" / "canedge_gnss_00000001-63BEF5CD.mf4.gz"
GNSS_DBC = DATA / "formats" / "can" / "canedge_gnss.dbc"
HYPERBOLIC = "ASAM.M.SCALAR.UBYTE.HYPERBOLIC"


@pytest.fixture(scope="module")
def plain(tmp_path_factory):
    """The bundled files decompressed (asammdf then reads them by path, as a user's file)."""
    d = tmp_path_factory.mktemp("real")
    out = {}
    for src in (CANAPE, CANEDGE):
        if not src.exists():  # the LGPL CANape file: in the repository, not in the sdist
            continue
        p = d / src.name.removesuffix(".gz")
        p.write_bytes(gzip.decompress(src.read_bytes()))
        out[src.name.split("_")[0]] = p
    return out


@pytest.fixture(scope="module")
def asammdf_gnss(plain):
    """asammdf's own decoding of the CANedge log with the DBC: heading and speed."""
    with asammdf.MDF(str(plain["canedge"])) as mdf:
        n_frames = sum(
            int(g.channel_group.cycles_nr)
            for g in mdf.groups
            if any(c.name.startswith("CAN_") for c in g.channels)
        )
        start = mdf.header.start_time.timestamp()
        dec = mdf.extract_bus_logging({"CAN": [(str(GNSS_DBC), 0)]})
        hdg = dec.get("Heading", *dec.channels_db["Heading"][0])
        spd = dec.get("Speed", *dec.channels_db["Speed"][0])
        return {
            "n_frames": n_frames,
            "start": start,
            "heading": (np.asarray(hdg.timestamps, float), np.asarray(hdg.samples, float)),
            "speed": (np.asarray(spd.timestamps, float), np.asarray(spd.samples, float)),
        }


@pytest.mark.skipif(not CANAPE.exists(), reason="copyleft test file not shipped here")
@pytest.mark.parametrize("by_path", [True, False])
def test_a_canape_mdf4_with_a_256_byte_string_channel_reads_as_asammdf_reads_it(plain, by_path):
    """The CANape file (group 6: ``$CalibrationLog``, a 256-byte string in a 265-byte record)
    is valid — asammdf reads every channel of it — so it is read, not refused as damaged; the
    mapped channel equals asammdf's samples at asammdf's times (was: "damaged MDF file")."""
    path = plain["ASAP2"] if by_path else CANAPE
    log = read_log(path, columns=f"heading={HYPERBOLIC}:deg")
    with asammdf.MDF(str(plain["ASAP2"])) as mdf:
        assert mdf.get("$CalibrationLog").samples.dtype.itemsize == 256  # read by asammdf
        ref = mdf.get(HYPERBOLIC)
        start = mdf.header.start_time.timestamp()
    ok = np.isfinite(ref.samples.astype(float))  # the hyperbolic conversion's poles: inf
    ep = log.epochs
    assert log.report.balanced and len(ep) == ok.sum() > 10_000
    assert log.report.rejected["malformed field"] == (~ok).sum() > 0
    np.testing.assert_allclose(ep["heading_deg"], np.mod(ref.samples[ok].astype(float), 360.0))
    t = (ep["time_utc"] - pd.Timestamp(start, unit="s", tz="UTC")).dt.total_seconds()
    np.testing.assert_allclose(t, ref.timestamps[ok], atol=1e-5)


def test_a_byte_array_channel_is_one_line(plain):
    """A byte-array channel mapped by the user: one line "holds byte arrays, not numbers"
    pointing at --dbc (was: "internal error: ValueError: operands could not be broadcast"),
    and asammdf's "Multiple occurrences" lines stay off stderr."""
    with pytest.raises(InputError, match=r"'CAN_DataFrame\.DataBytes' \(heading\) holds byte "
                       r"arrays, not numbers.*--dbc"):  # fmt: skip
        read_log(plain["canedge"], columns="heading=CAN_DataFrame.DataBytes:deg")
    r = cli("ingest", plain["canedge"], "--columns", "heading=CAN_DataFrame.DataBytes:deg")
    assert r.returncode != 0 and "Traceback" not in r.stderr
    assert len(r.stderr.strip().splitlines()) == 1 and "holds byte arrays" in r.stderr
    assert "Multiple occurrences" not in r.stderr


def test_raw_can_inside_mdf4_without_dbc_says_give_dbc(plain):
    with pytest.raises(InputError, match=r"raw CAN frames \(4024 frames.*--dbc"):
        read_log(plain["canedge"], columns="heading=Heading,speed=Speed")


@pytest.mark.parametrize("by_path", [True, False])
def test_raw_can_inside_mdf4_decoded_with_the_dbc_as_asammdf_decodes_it(
    plain, asammdf_gnss, by_path
):
    """CANedge ``CAN_DataFrame`` groups decoded with --dbc; the DBC defines gnss_attitude at 5
    and 0x15, the log holds 0x15: its 168 headings and speeds equal asammdf's bus-logging
    decoding (was: --dbc unused, "no channel 'Heading'"); every frame is accounted for."""
    path = plain["canedge"] if by_path else CANEDGE
    log = read_log(path, columns="heading=Heading,speed=Speed", dbc=GNSS_DBC)
    rep = log.report
    t_ref, h_ref = asammdf_gnss["heading"]
    assert rep.balanced and rep.total_lines == asammdf_gnss["n_frames"]
    assert rep.parsed == {"gnss_attitude": h_ref.size, "gnss_speed": asammdf_gnss["speed"][1].size}
    assert len(log.epochs) == h_ref.size == 168
    np.testing.assert_allclose(log.epochs["heading_deg"], h_ref, atol=1e-9)
    t = log.epochs["time_utc"].map(pd.Timestamp.timestamp).to_numpy() - asammdf_gnss["start"]
    np.testing.assert_allclose(t, t_ref, atol=1e-5)
    rows = log.sentences["speed"]
    np.testing.assert_allclose(rows["value"], asammdf_gnss["speed"][1], atol=1e-9)
    np.testing.assert_allclose(rows["t_s"], asammdf_gnss["speed"][0], atol=1e-9)
    assert any("0x15" in n and "the one the log holds" in n for n in rep.notes)


@pytest.mark.parametrize("heading", ["0x15.Heading", "21.Heading", "gnss_attitude.Heading"])
def test_columns_can_name_one_copy_of_a_message(plain, asammdf_gnss, heading):
    log = read_log(plain["canedge"], columns=f"heading={heading},speed=Speed", dbc=GNSS_DBC)
    np.testing.assert_allclose(log.epochs["heading_deg"], asammdf_gnss["heading"][1], atol=1e-9)


def test_columns_naming_a_copy_the_log_does_not_hold_reads_nothing_of_the_other(plain):
    log = read_log(plain["canedge"], columns="heading=0x5.Heading,speed=Speed", dbc=GNSS_DBC)
    assert len(log.epochs) == 0 and log.report.balanced
    assert log.report.ignored["(no mapped signal)"] > 168  # the 0x15 frames: not mapped
    assert any("holds no frame of gnss_attitude (id 0x5)" in n for n in log.report.notes)
    with pytest.raises(InputError, match=r"no message 'gnss_pos' carries signal 'Heading'"):
        read_log(plain["canedge"], columns="heading=gnss_pos.Heading", dbc=GNSS_DBC)


def _asc_with_both_copies(tmp_path, ids=(0x5, 0x15)):
    """An ASC log (python-can's writer) holding gnss_attitude frames at both identifiers,
    encoded with cantools from the real DBC."""
    db = cantools.database.load_file(str(GNSS_DBC), strict=False)
    msg = next(m for m in db.messages if m.frame_id == 0x15)
    p = tmp_path / "both.asc"
    w = can.ASCWriter(str(p))
    for k in range(10):
        for fid in ids:
            data = msg.encode({s.name: 0 for s in msg.signals} | {"Heading": 10.0 + k})
            w.on_message_received(can.Message(timestamp=1.7e9 + k + fid * 1e-3,
                                              arbitration_id=fid, data=data,
                                              is_extended_id=False))  # fmt: skip
    w.stop()
    return p


def test_a_log_holding_both_copies_is_one_line_naming_both_ids(tmp_path):
    p = _asc_with_both_copies(tmp_path)
    with pytest.raises(
        InputError,
        match=r"'Heading' \(heading\) is in 2 messages.*id 0x5\): 10 frames and "
        r"gnss_attitude \(id 0x15\): 10 frames.*--columns heading=0x5\.Heading",
    ):
        read_log(p, columns="heading=Heading", dbc=GNSS_DBC)
    log = read_log(p, columns="heading=0x15.Heading", dbc=GNSS_DBC)
    np.testing.assert_allclose(log.epochs["heading_deg"], 10.0 + np.arange(10))
    assert log.report.parsed == {"gnss_attitude": 10} and log.report.balanced


def test_a_log_holding_the_second_copy_decodes_it(tmp_path):
    """The same DBC on an ASC log of the 0x15 frames only (was: signals bound to id 5, every
    frame ignored, "parsed 0")."""
    p = _asc_with_both_copies(tmp_path, ids=(0x15,))
    log = read_log(p, columns="heading=Heading", dbc=GNSS_DBC)
    np.testing.assert_allclose(log.epochs["heading_deg"], 10.0 + np.arange(10))


def test_no_library_noise_on_stderr(plain, tmp_path):
    """cantools' "Overwriting message" and asammdf's lines stay off stderr; no "nan Hz" line
    when no course is mapped."""
    r = cli(
        "ingest", plain["canedge"], "--dbc", GNSS_DBC, "--columns", "heading=Heading,speed=Speed"
    )
    assert r.returncode == 0, r.stderr
    assert "Overwriting" not in r.stderr and "asammdf" not in r.stderr, r.stderr
    assert "nan Hz" not in r.stdout and "no epoch has course and speed" in r.stdout
    assert "--dbc not used" not in r.stdout


def test_friction_without_a_course_channel_says_which_and_how_to_map_it(plain, tmp_path):
    """A CAN log with heading and speed only: console, summary.json (explain) and the report
    name the missing course over ground and the --columns that maps it (was: "0 of 168
    epochs usable", an empty table and nothing else)."""
    out = tmp_path / "fr"
    r = cli("friction", plain["canedge"], "--dbc", GNSS_DBC, "--columns",
            "heading=Heading,speed=Speed", "--vehicle", DATA.parent.parent / "src" /
            "gripsense" / "data" / "corolla_sim.toml", "-o", out, "--report")  # fmt: skip
    assert r.returncode == 0, r.stderr
    said = "the log gives no course over ground (course_deg)"
    assert said in r.stdout and "--columns course=CHANNEL" in r.stdout
    explain = json.loads((out / "summary.json").read_text())["explain"]
    assert said in explain and "--columns course=CHANNEL" in explain
    assert said in (out / "report.html").read_text()


J1939 = DATA / "formats" / "can" / "canedge_j1939_00000001-60B621D9.mf4.gz"
J1939_DBC = DATA / "formats" / "can" / "css_j1939_demo.dbc"


def test_a_j1939_dbc_matches_frames_by_pgn_as_asammdf_does(tmp_path):
    """A J1939 DBC (``ProtocolType "J1939"``) names a message by one identifier (CCVS1
    0x18FEF1FE, source address 0xFE); the truck's frames come from other source addresses:
    matched by the PGN (was: every frame "no mapped signal", parsed 0), as asammdf's
    bus-logging decoder matches them."""
    p = tmp_path / "j1939.mf4"
    p.write_bytes(gzip.decompress(J1939.read_bytes()))
    log = read_log(p, columns="speed=WheelBasedVehicleSpeed", dbc=J1939_DBC)
    with asammdf.MDF(str(p)) as mdf:
        dec = mdf.extract_bus_logging({"CAN": [(str(J1939_DBC), 0)]})
        ref = dec.get("WheelBasedVehicleSpeed", *dec.channels_db["WheelBasedVehicleSpeed"][0])
    rows = log.sentences["speed"]
    assert (
        log.report.balanced
        and log.report.parsed == {"CCVS1": len(ref.samples)}
        and len(ref.samples) > 100
    )
    np.testing.assert_allclose(rows["t_s"], ref.timestamps, atol=1e-9)
    np.testing.assert_allclose(rows["value"], ref.samples, atol=1e-9)


def test_a_canedge_compressed_file_is_one_line(tmp_path):
    """A CANedge ``.MFC`` (compressed MF4 in a 'Generic File' container) was read as NMEA:
    "parsed 0", exit 0; now one line saying what it is and how to convert it."""
    mfc = DATA / "formats" / "can" / "canedge_compressed_head.mfc"
    with pytest.raises(InputError, match=r"compressed or encrypted MDF4.*convert it to \.MF4"):
        read_log(mfc, columns="heading=Heading", dbc=GNSS_DBC)
    r = cli("ingest", mfc)
    assert r.returncode != 0 and len(r.stderr.strip().splitlines()) == 1, r.stderr


def _cn_byte_offset_at(mdf_path, channel: str) -> int:
    """File offset of a channel's ``cn_byte_offset`` (MDF 4 CN block: 24-byte header, the
    links, then cn_type, cn_sync_type, cn_data_type, cn_bit_offset [1 byte each],
    cn_byte_offset [4 bytes])."""
    with asammdf.MDF(str(mdf_path)) as mdf:
        (g, i), *_ = mdf.channels_db[channel]
        ch = mdf.groups[g].channels[i]
        return int(ch.address) + 24 + 8 * int(ch.links_nr) + 4


def test_only_the_channels_read_are_judged(tmp_path):
    """A channel pointing outside its record in a group nobody maps does not refuse the file
    (was: "damaged MDF file" whatever was mapped); mapped, it is still refused in one line
    before asammdf's compiled reader would read past its buffer."""
    import struct

    from gripsense.io.logs.mdf import mdf_columns, write_mdf
    from tests.io.logs.test_measurement_logs import _epochs, _steer

    ep = _epochs(20)
    st = _steer(ep)
    st["torque_Nm"] = 1.0
    p = tmp_path / "m.mf4"
    write_mdf(ep, p, steer=st)
    at = _cn_byte_offset_at(p, "SteeringTorque")
    raw = bytearray(p.read_bytes())
    assert struct.unpack_from("<I", raw, at)[0] == 8  # after the 8-byte time stamp
    struct.pack_into("<I", raw, at, 4096)  # bytes 4096–4103 of a 16-byte record
    p.write_bytes(bytes(raw))
    log = read_log(p, columns=mdf_columns(steering=True))
    assert log.report.balanced and len(log.epochs) == 20
    with pytest.raises(InputError, match=r"damaged MDF file: channel 'SteeringTorque' of group"):
        read_log(p, columns=mdf_columns(steering=True, torque=True))


_ODD_DBC = """VERSION ""
BS_:
BU_: ECU
BO_ 256 Motorola: 8 ECU
 SG_ m_u12 : 7|12@0+ (0.5,-10) [0|0] "deg" ECU
 SG_ m_s9 : 11|9@0- (0.25,0) [0|0] "deg" ECU
 SG_ m_s1 : 18|1@0- (1,0) [0|0] "" ECU
 SG_ m_u26 : 33|26@0+ (1e-3,5) [0|0] "m" ECU
BO_ 257 Intel: 8 ECU
 SG_ i_s13 : 3|13@1- (0.1,0) [0|0] "deg" ECU
 SG_ i_f32 : 16|32@1- (1,0) [0|0] "m" ECU
 SG_ i_u7 : 57|7@1+ (2,1) [0|0] "" ECU
BO_ 258 Wide: 8 ECU
 SG_ w_u64 : 0|64@1+ (1,0) [0|0] "" ECU
BO_ 259 Short: 3 ECU
 SG_ s_s16 : 7|16@0- (0.01,0) [0|0] "deg" ECU
 SG_ s_u8 : 16|8@1+ (1,0) [0|0] "" ECU
BO_ 260 Double: 8 ECU
 SG_ d_f64 : 0|64@1- (1,0) [0|0] "" ECU
SIG_VALTYPE_ 257 i_f32 : 1;
SIG_VALTYPE_ 260 d_f64 : 2;
"""


def test_the_vectorised_decoder_equals_cantools_on_every_bit_layout(tmp_path):
    """Intel and Motorola, signed and unsigned, 1 to 64 bits, IEEE float 32/64, a 3-byte
    message: the vectorised decode of random payloads equals cantools' own decode of each
    frame (the reference); frames of another length go through cantools and are rejected as
    it rejects them."""
    from gripsense.io.logs.canlog import FrameColumns, _decode_rows, _vectorisable

    p = tmp_path / "odd.dbc"
    p.write_text(_ODD_DBC)
    db = cantools.database.load_file(str(p))
    rng = np.random.default_rng(43)
    for msg in db.messages:
        assert all(_vectorisable(s) for s in msg.signals)  # the vectorised path is the one tested
        n = 500
        data = [bytes(rng.integers(0, 256, msg.length, dtype=np.uint8)) for _ in range(n)]
        data[7] = data[7][:-1]  # one frame too short: cantools rejects it
        frames = [(k + 1, can.Message(timestamp=float(k), arbitration_id=msg.frame_id, data=d))
                  for k, d in enumerate(data)]  # fmt: skip
        sigs = [s.name for s in msg.signals]
        ok, values, failed = _decode_rows(msg, FrameColumns.of(frames), np.arange(n), sigs)
        assert [r for r, _ in failed] == [7] and ok.tolist() == [k for k in range(n) if k != 7]
        for s in sigs:
            ref = [float(msg.decode(data[k], decode_choices=False)[s]) for k in ok.tolist()]
            got, has = values[s]
            assert has.all()
            np.testing.assert_array_equal(got, np.asarray(ref), err_msg=f"{msg.name}.{s}")
