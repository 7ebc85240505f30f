"""u-blox UBX: the compiled decoder against pyubx2 frame by frame, mixed NMEA streams, every
frame accounted for, and corrupt streams."""

from __future__ import annotations

import io

import numpy as np
import pandas as pd
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from gripsense.errors import InputError
from gripsense.io.logs import read_log
from gripsense.io.logs.ubx import parse_ubx, scan_frames, write_ubx
from gripsense.sim.gnss import format_sentence

pyubx2 = pytest.importorskip("pyubx2")


def _frames(n: int = 40, seed: int = 3) -> tuple[bytes, dict]:
    """A moving-base rover stream built with pyubx2: NAV-PVT, NAV-RELPOSNED (some not fixed or
    heading-invalid), NAV-ATT and a message gripsense does not read, with random values."""
    rng = np.random.default_rng(seed)
    out = bytearray()
    why = {"float": 0, "invalid": 0}
    for k in range(n):
        itow = 345_600_000 + 100 * k
        pvt = pyubx2.UBXMessage(
            "NAV", "NAV-PVT", pyubx2.GET, iTOW=itow, year=2026, month=11, day=26, hour=4,
            min=0, second=k // 10, validDate=1, validTime=1, fullyResolved=1,
            nano=int((k % 10) * 1e8), fixType=3, gnssFixOk=1, diffSoln=int(k % 2),
            carrSoln=int(k % 3), numSV=int(rng.integers(5, 30)),
            lon=float(rng.uniform(-180, 180)), lat=float(rng.uniform(-89, 89)),
            height=int(rng.integers(-1000, 100000)), hMSL=int(rng.integers(-1000, 100000)),
            gSpeed=int(rng.integers(0, 60000)), headMot=float(rng.uniform(0, 359.99)),
            sAcc=int(rng.integers(1, 500)), pDOP=float(rng.uniform(0.5, 5)),
        )  # fmt: skip
        carr = 1 if k % 7 == 3 else 2
        hv = 0 if k % 11 == 5 else 1
        why["float"] += carr == 1
        why["invalid"] += carr == 2 and hv == 0
        rel = pyubx2.UBXMessage(
            "NAV", "NAV-RELPOSNED", pyubx2.GET, version=1, iTOW=itow,
            relPosHeading=float(rng.uniform(0, 359.99)), accHeading=float(rng.uniform(0, 2)),
            gnssFixOK=1, diffSoln=1, relPosValid=1, carrSoln=carr, relPosHeadingValid=hv,
        )  # fmt: skip
        att = pyubx2.UBXMessage(
            "NAV", "NAV-ATT", pyubx2.GET, iTOW=itow, roll=float(rng.uniform(-10, 10)),
            pitch=float(rng.uniform(-10, 10)), heading=float(rng.uniform(0, 359.99)),
        )  # fmt: skip
        clk = pyubx2.UBXMessage("NAV", "NAV-CLOCK", pyubx2.GET, iTOW=itow, clkB=k, clkD=-k)
        out += pvt.serialize() + rel.serialize() + att.serialize() + clk.serialize()
    return bytes(out), why


def _reference(data: bytes) -> dict[str, list]:
    """Every frame parsed by pyubx2."""
    got: dict[str, list] = {}
    for _, msg in pyubx2.UBXReader(io.BytesIO(data), protfilter=pyubx2.UBX_PROTOCOL):
        got.setdefault(msg.identity, []).append(msg)
    return got


def test_decode_equals_pyubx2_on_every_frame():
    data, why = _frames()
    ref = _reference(data)
    log = parse_ubx(data, "rover.ubx")
    pvt = log.sentences["UBX NAV-PVT"]
    assert len(pvt) == len(ref["NAV-PVT"])
    np.testing.assert_allclose(pvt["lat_deg"], [m.lat for m in ref["NAV-PVT"]], atol=1e-12)
    np.testing.assert_allclose(pvt["lon_deg"], [m.lon for m in ref["NAV-PVT"]], atol=1e-12)
    np.testing.assert_allclose(pvt["alt_m"], [m.hMSL / 1000 for m in ref["NAV-PVT"]])
    np.testing.assert_allclose(pvt["speed_mps"], [m.gSpeed / 1000 for m in ref["NAV-PVT"]])
    np.testing.assert_allclose(pvt["course_deg"], [m.headMot for m in ref["NAV-PVT"]], atol=1e-9)
    np.testing.assert_allclose(pvt["speed_acc_mps"], [m.sAcc / 1000 for m in ref["NAV-PVT"]])
    np.testing.assert_array_equal(pvt["n_sats"], [m.numSV for m in ref["NAV-PVT"]])
    gga = [
        4 if m.carrSoln == 2 else 5 if m.carrSoln == 1 else 2 if m.diffSoln else 1
        for m in ref["NAV-PVT"]
    ]
    np.testing.assert_array_equal(pvt["fix_quality"], gga)
    rel = log.sentences["UBX NAV-RELPOSNED"]
    used = np.array(
        [m.carrSoln == 2 and m.relPosHeadingValid == 1 for m in ref["NAV-RELPOSNED"]], bool
    )
    hdg = np.array([m.relPosHeading for m in ref["NAV-RELPOSNED"]])
    np.testing.assert_allclose(rel["heading_deg"][used], hdg[used], atol=1e-9)
    assert rel["heading_deg"][~used].isna().all()
    acc = np.array([m.accHeading for m in ref["NAV-RELPOSNED"]])
    np.testing.assert_allclose(rel["heading_acc_deg"][used], acc[used], atol=1e-9)
    att = log.sentences["UBX NAV-ATT"]
    for c, f in (("roll_deg", "roll"), ("pitch_deg", "pitch"), ("att_heading_deg", "heading")):
        np.testing.assert_allclose(att[c], [getattr(m, f) for m in ref["NAV-ATT"]], atol=1e-9)
    # the accounting: every frame in one bucket, the unused headings with their reason
    rep = log.report
    assert rep.balanced and rep.total_lines == sum(len(v) for v in ref.values())
    assert rep.ignored["UBX NAV-RELPOSNED (carrier solution not fixed)"] == why["float"]
    assert rep.ignored["UBX NAV-RELPOSNED (heading not valid)"] == why["invalid"]
    assert rep.ignored["UBX NAV-0x22"] == len(ref["NAV-CLOCK"])
    assert rep.parsed["UBX NAV-RELPOSNED"] == int(used.sum())
    # epochs: one per iTOW, UTC from NAV-PVT, the heading only where RELPOSNED is usable
    ep = log.epochs
    assert len(ep) == len(ref["NAV-PVT"])
    assert ep["time_utc"].iloc[12] == pd.Timestamp("2026-11-26 04:00:01.2", tz="UTC")
    assert ep["heading_deg"].notna().sum() == int(used.sum())
    assert (ep["heading_source"].dropna() == "RELPOSNED").all()


def test_mixed_with_nmea_and_corrupt_frames_are_each_counted():
    data, _ = _frames(10)
    good = parse_ubx(data)
    nmea = "".join(format_sentence(b) + "\r\n" for b in ("GPHDT,123.456,T", "GPROT,12.5,A"))
    nmea = nmea.encode()
    fr = scan_frames(data)
    starts = fr["start"].to_numpy()
    # flip a payload byte of the 5th frame (bad checksum) and cut the stream in the last one
    bad = bytearray(data)
    bad[starts[4] + 10] ^= 0xFF
    stream = nmea + bytes(bad[: starts[-1] + 12])
    log = parse_ubx(stream, "mixed.log")
    rep = log.report
    assert rep.rejected["bad checksum"] == 1 and rep.rejected["truncated"] == 1
    assert rep.parsed["HDT"] == 1 and rep.parsed["ROT"] == 1
    assert rep.balanced and rep.total_lines == len(fr) + 2
    assert rep.unit == "lines and frames" and rep.format == "u-blox UBX + NMEA 0183"
    assert rep.first_rejects[0].detail.startswith(f"byte {len(nmea) + starts[4]}:")
    assert len(log.epochs) >= len(good.epochs) - 1
    with pytest.raises(InputError, match=r"mixed.log: byte \d+: UBX frame: bad checksum"):
        parse_ubx(stream, "mixed.log", strict=True)


def test_a_wrong_length_is_malformed():
    msg = pyubx2.UBXMessage("NAV", "NAV-ATT", pyubx2.GET, iTOW=1, roll=1.0)
    raw = bytearray(msg.serialize())
    payload = bytes(raw[6:-2]) + b"\x00\x00"  # 34 bytes
    body = bytes([0x01, 0x05]) + len(payload).to_bytes(2, "little") + payload
    a = b = 0
    for x in body:
        a = (a + x) & 0xFF
        b = (b + a) & 0xFF
    frame = b"\xb5\x62" + body + bytes([a, b])
    rep = parse_ubx(frame).report
    assert rep.rejected["malformed field"] == 1 and rep.balanced


def test_the_same_drive_as_nmea(tmp_path):
    """write_ubx (pyubx2) interleaved with the receiver's NMEA → the NMEA epoch table."""
    import gzip

    from gripsense.data import path as data_path
    from gripsense.io import read_nmea

    path = data_path("demo/case001.nmea.gz")
    lines = gzip.decompress(path.read_bytes()).decode().splitlines()
    ref = read_nmea(path).epochs
    write_ubx(ref, tmp_path / "d.bin", nmea_lines=lines)
    log = read_log(tmp_path / "d.bin")
    ep = log.epochs
    assert len(ep) == len(ref) and log.report.balanced
    np.testing.assert_allclose(ep["heading_deg"], ref["heading_deg"], atol=1e-5)
    np.testing.assert_allclose(ep["lat_deg"], ref["lat_deg"], atol=1.5e-7)
    np.testing.assert_allclose(ep["speed_mps"], ref["speed_mps"], atol=5e-4)
    np.testing.assert_allclose(ep["yaw_rate_rps"], ref["yaw_rate_rps"])  # NMEA ROT kept
    assert (ep["time_utc"] == ref["time_utc"]).all()


@settings(max_examples=80, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(
    cuts=st.lists(st.integers(0, 2000), max_size=4),
    flips=st.lists(st.tuples(st.integers(0, 2000), st.integers(1, 255)), max_size=6),
    junk=st.binary(max_size=40),
)
def test_fuzz_never_a_traceback_and_every_unit_counted(cuts, flips, junk):
    data, _ = _frames(8, seed=1)
    b = bytearray(data)
    for pos, x in flips:
        if pos < len(b):
            b[pos] ^= x
    for c in sorted(cuts, reverse=True):
        b = b[:c] + junk + b[c:]
    try:
        log = parse_ubx(bytes(b), "fuzz.ubx")
    except InputError:
        return
    rep = log.report
    assert rep.balanced
    n_frames = len(scan_frames(bytes(b)))
    assert rep.total_lines >= n_frames


def test_a_real_zed_f9p_stream_frame_for_frame_as_pyubx2():
    """GPSD's ZED-F9P capture (UBX RXM-RAWX/MEASX and NAV-CLOCK between NMEA sentences): the
    frame scan finds exactly the frames pyubx2 parses, each is accounted for, and the NMEA
    between them gives the epochs it gives alone."""
    from tests.conftest import DATA

    data = (DATA / "gpsd" / "ublox-zed-f9p_hpg1.11.log").read_bytes()
    ref: dict[str, int] = {}
    for _, msg in pyubx2.UBXReader(io.BytesIO(data), protfilter=pyubx2.UBX_PROTOCOL):
        ref[msg.identity] = ref.get(msg.identity, 0) + 1
    fr = scan_frames(data)
    assert (fr["status"] == 0).all() and len(fr) == sum(ref.values())
    log = parse_ubx(data, "f9p.log")
    rep = log.report
    names = {"NAV-CLOCK": "UBX NAV-0x22", "RXM-RAWX": "UBX RXM-0x15", "RXM-MEASX": "UBX RXM-0x14"}
    assert {names[k]: v for k, v in ref.items()} == {
        k: v for k, v in rep.ignored.items() if k.startswith("UBX")
    }
    assert rep.balanced
    from gripsense.io import read_nmea

    text = np.frombuffer(data, np.uint8)[~fr.attrs["mask"]].tobytes()
    text_only = read_nmea(text, decompress=False)
    pd.testing.assert_frame_equal(log.epochs, text_only.epochs)
