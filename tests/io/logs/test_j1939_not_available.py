"""J1939 "not available" and "error" raw values (issue 43): a real truck's J1939 bus log
(CANedge MDF4) with its real J1939 DBC, the frames read by python-can's own MF4 reader and
written as an ASC log with a few CCVS1/EEC1 payloads set to the reserved ranges. References:
cantools' decode of each frame, and the ranges of SAE J1939-71 §5.1.4 written out below (not
gripsense's table). Origins and licences: ``tests/data/formats/README.md``.
"""

from __future__ import annotations

import gzip

import numpy as np
import pytest

from gripsense.io.logs import read_log
from tests.conftest import DATA

can = pytest.importorskip("can")
cantools = pytest.importorskip("cantools")
pytest.importorskip("asammdf")  # python-can's MF4 reader

LOG = DATA / "formats" / "can" / "canedge_j1939_00000001-60B621D9.mf4.gz"
DBC = DATA / "formats" / "can" / "css_j1939_demo.dbc"

# SAE J1939-71 §5.1.4, transmitted signal ranges of a 2-byte parameter (inclusive):
VALID_2 = (0x0000, 0xFAFF)
RESERVED_2 = (0xFB00, 0xFDFF)  # parameter-specific indicator and reserved
ERROR_2 = (0xFE00, 0xFEFF)
NOT_AVAILABLE_2 = (0xFF00, 0xFFFF)
# of a 1-byte parameter:
VALID_1, RESERVED_1, ERROR_1, NOT_AVAILABLE_1 = (
    (0x00, 0xFA),
    (0xFB, 0xFD),
    (0xFE, 0xFE),
    (0xFF, 0xFF),
)
# of a 4-byte parameter:
VALID_4, NOT_AVAILABLE_4 = (0, 0xFAFFFFFF), (0xFF000000, 0xFFFFFFFF)
# of a 2-bit discrete parameter: 00 disabled, 01 enabled, 10 error, 11 not available

# raw WheelBasedVehicleSpeed (bytes 2-3 of CCVS1, Intel, 1/256 km/h) put into CCVS1 frames k
SPEEDS = {3: 0xFFFF, 10: 0xFF00, 20: 0xFE00, 30: 0xFEFF, 40: 0xFB00, 50: 0xFDFF, 60: 0xFAFF,
          70: 0x1234}  # fmt: skip
ENGINE = {5: 0xFFFF, 6: 0xFE80, 7: 0xFAFF}  # raw EngineSpeed (bytes 4-5 of EEC1, 1/8 rpm)


def _in(raw: int, rng: tuple[int, int]) -> bool:
    return rng[0] <= raw <= rng[1]


def _pgn(fid: int) -> int:
    return (fid >> 8) & 0x3FFFF


def _frames(tmp_path):
    """The real log's frames (python-can's MF4 reader), CCVS1 and EEC1 payloads patched."""
    p = tmp_path / "j1939.mf4"
    p.write_bytes(gzip.decompress(LOG.read_bytes()))
    frames = list(can.io.mf4.MF4Reader(str(p)))
    k_ccvs = k_eec = 0
    for fr in frames:
        if fr.is_error_frame or fr.is_remote_frame:
            continue
        if _pgn(fr.arbitration_id) == 0xFEF1:  # CCVS1
            if k_ccvs in SPEEDS:
                fr.data[1:3] = SPEEDS[k_ccvs].to_bytes(2, "little")
            k_ccvs += 1
        elif _pgn(fr.arbitration_id) == 0xF004:  # EEC1
            if k_eec in ENGINE:
                fr.data[3:5] = ENGINE[k_eec].to_bytes(2, "little")
            k_eec += 1
    return frames


def _asc(tmp_path, frames, *, rename: dict[int, int] | None = None):
    p = tmp_path / "j1939.asc"
    w = can.ASCWriter(str(p))
    for fr in frames:
        if rename and fr.arbitration_id in rename:
            fr = can.Message(timestamp=fr.timestamp, arbitration_id=rename[fr.arbitration_id],
                             data=fr.data, is_extended_id=True)  # fmt: skip
        w.on_message_received(fr)
    w.stop()
    return p


def _cantools(frames, dbc_path, name, signal, pgn):
    db = cantools.database.load_file(str(dbc_path))
    msg = db.get_message_by_name(name)
    rows = [fr for fr in frames if _pgn(fr.arbitration_id) == pgn and not fr.is_error_frame]
    return np.array([msg.decode(bytes(fr.data))[signal] for fr in rows]), rows


def test_j1939_not_available_and_error_values_are_nan_and_counted(tmp_path):
    """Before: a CCVS1 frame whose speed is 0xFFFF gave 255.996 km/h (cantools' number, used
    as a speed); 0xFE00 gave 254 km/h. Now every raw value outside J1939-71's valid range is
    NaN, counted in the notes, and never used; the rest equals cantools."""
    frames = _frames(tmp_path)
    asc = _asc(tmp_path, frames)
    ref, rows = _cantools(frames, DBC, "CCVS1", "WheelBasedVehicleSpeed", 0xFEF1)
    raw = np.array([int.from_bytes(fr.data[1:3], "little") for fr in rows])
    valid = np.array([_in(r, VALID_2) for r in raw])
    kinds = {
        "na": sum(_in(r, NOT_AVAILABLE_2) for r in raw),
        "err": sum(_in(r, ERROR_2) for r in raw),
        "res": sum(_in(r, RESERVED_2) for r in raw),
    }
    assert kinds == {"na": 2, "err": 2, "res": 2} and len(rows) > 100

    log = read_log(asc, columns="speed=WheelBasedVehicleSpeed", dbc=DBC)
    got = log.sentences["speed"]["value"].to_numpy()
    assert got.size == len(rows) and log.report.balanced
    np.testing.assert_allclose(got[valid], ref[valid], rtol=0, atol=1e-9)
    assert np.isnan(got[~valid]).all()
    assert got[valid].max() == pytest.approx(0xFAFF / 256)  # the top valid value is kept
    n_bad = int((~valid).sum())
    note = f"{n_bad} frames with 'not available' values of WheelBasedVehicleSpeed"
    hits = [n for n in log.report.notes if n.startswith(note)]
    assert len(hits) == 1, log.report.notes
    assert f"{kinds['na']} not available, {kinds['err']} error" in hits[0]
    assert f"{kinds['res']} reserved" in hits[0]
    # never used: no epoch speed near 251 km/h (0xFFFF * 1/256 km/h = 69.9 m/s)
    speed = log.epochs["speed_mps"].to_numpy()
    assert np.nanmax(speed) < 0xFB00 / 256 / 3.6
    # strict mode: a "not available" value is a J1939 statement, not a malformed frame
    strict = read_log(asc, columns="speed=WheelBasedVehicleSpeed", dbc=DBC, strict=True)
    assert np.isnan(strict.sentences["speed"]["value"].to_numpy()[~valid]).all()


def test_j1939_engine_speed_out_of_range_values_are_nan(tmp_path):
    """The other signal of the real DBC (EEC1 EngineSpeed, 1/8 rpm): 0xFFFF and 0xFE80 NaN,
    0xFAFF (8031.875 rpm, the top of the valid range) kept, as cantools decodes it."""
    frames = _frames(tmp_path)
    asc = _asc(tmp_path, frames)
    ref, rows = _cantools(frames, DBC, "EEC1", "EngineSpeed", 0xF004)
    raw = np.array([int.from_bytes(fr.data[3:5], "little") for fr in rows])
    valid = np.array([_in(r, VALID_2) for r in raw])
    log = read_log(asc, columns="alt=EngineSpeed:m", dbc=DBC)  # a key with no limit
    got = log.sentences["alt"]["value"].to_numpy()
    assert got.size == len(rows) and int((~valid).sum()) == 2
    np.testing.assert_allclose(got[valid], ref[valid], rtol=0, atol=1e-9)
    assert np.isnan(got[~valid]).all() and 8031.875 in got


def test_a_non_j1939_dbc_keeps_cantools_numbers(tmp_path):
    """The same DBC as an ordinary one (no ``ProtocolType "J1939"``, frame format
    ``ExtendedCAN`` not ``J1939PG``, CCVS1 at the identifier the truck sends it under): so
    0xFFFF is cantools' 255.996 km/h, as before."""
    text = DBC.read_text()
    assert 'BA_ "ProtocolType" "J1939";' in text
    lines = [ln for ln in text.splitlines() if not ln.startswith('BA_ "VFrameFormat" BO_')]
    text = "\n".join(lines).replace('"VFrameFormat" "J1939PG"', '"VFrameFormat" "ExtendedCAN"')
    plain = tmp_path / "plain.dbc"
    frames = _frames(tmp_path)
    fid = next(fr.arbitration_id for fr in frames if _pgn(fr.arbitration_id) == 0xFEF1)
    plain.write_text(
        text.replace('BA_ "ProtocolType" "J1939";', "").replace(
            str(0x98FEF1FE), str(0x80000000 | fid)
        )
    )
    asc = _asc(tmp_path, frames, rename={f.arbitration_id: fid for f in frames
                                         if _pgn(f.arbitration_id) == 0xFEF1})  # fmt: skip
    ref, _ = _cantools(frames, plain, "CCVS1", "WheelBasedVehicleSpeed", 0xFEF1)
    log = read_log(asc, columns="speed=WheelBasedVehicleSpeed", dbc=plain)
    got = log.sentences["speed"]["value"].to_numpy()
    np.testing.assert_allclose(got, ref, rtol=0, atol=1e-9)
    assert 0xFFFF / 256 in got
    assert not any("not available" in n for n in log.report.notes)
    db = cantools.database.load_file(str(plain))
    assert all(m.protocol is None for m in db.messages)


_1 = [RESERVED_1[0], RESERVED_1[1], ERROR_1[0], NOT_AVAILABLE_1[0]]
_2 = [RESERVED_2[0], RESERVED_2[1], ERROR_2[0], ERROR_2[1], *NOT_AVAILABLE_2]
_4 = [0xFB000000, 0xFDFFFFFF, 0xFE000000, 0xFEFFFFFF, *NOT_AVAILABLE_4]


@pytest.mark.parametrize(
    ("length", "valid", "invalid"),
    [
        (8, [VALID_1[0], 0x80, VALID_1[1]], _1),
        (16, [VALID_2[0], 0x1234, VALID_2[1]], _2),
        (32, [VALID_4[0], 0x12345678, VALID_4[1]], _4),
        (2, [0b00, 0b01], [0b10, 0b11]),
    ],
)
def test_the_j1939_71_ranges(length, valid, invalid):
    from gripsense.io.logs.canlog import j1939_range

    assert not j1939_range(np.array(valid, np.uint64), length).any()
    assert j1939_range(np.array(invalid, np.uint64), length).all()
