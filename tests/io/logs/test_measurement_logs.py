"""MDF4 (asammdf) and CAN BLF/ASC (python-can + cantools): mapped channels, units from the
file, rates resampled onto the epochs, time bases, and the errors."""

from __future__ import annotations

import tempfile

import numpy as np
import pandas as pd
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from gripsense.errors import InputError
from gripsense.io.logs import read_log
from gripsense.io.logs.canlog import CAN_SIGNALS, write_can
from gripsense.io.logs.mdf import mdf_columns, write_mdf
from tests.conftest import DATA

asammdf = pytest.importorskip("asammdf")
can = pytest.importorskip("can")
cantools = pytest.importorskip("cantools")

DBC = DATA / "formats" / "vehicle.dbc"
CAN_COLUMNS = ",".join(f"{k}={v}" for k, v in CAN_SIGNALS.items())


def _epochs(n: int = 60, seed: int = 2) -> pd.DataFrame:
    rng = np.random.default_rng(seed)
    t = np.arange(n) * 0.1
    hdg = np.mod(350 + 4 * t * 10 + rng.normal(0, 0.1, n), 360)  # turning through north
    return pd.DataFrame(
        {
            "time_utc": pd.Timestamp("2026-05-04 12:00:00", tz="UTC") + pd.to_timedelta(t, "s"),
            "t_s": t,
            "lat_deg": 48.1 + 1e-5 * t,
            "lon_deg": 11.5 - 1e-5 * t,
            "alt_m": 520 + rng.normal(0, 0.5, n),
            "speed_mps": 15 + rng.normal(0, 0.2, n),
            "course_deg": np.mod(hdg - 2, 360),
            "heading_deg": hdg,
            "yaw_rate_rps": rng.normal(0.2, 0.01, n),
        }
    )


def _steer(ep: pd.DataFrame, rate: float = 100.0) -> pd.DataFrame:
    t = np.arange(0, ep["t_s"].iloc[-1] + 1e-9, 1 / rate)
    return pd.DataFrame({"t_s": t, "road_wheel_deg": 3 * np.sin(t)})


def test_mdf4_round_trip_and_resampling_equal_asammdf(tmp_path):
    ep = _epochs()
    st_ = _steer(ep)
    write_mdf(ep, tmp_path / "m.mf4", steer=st_)
    log = read_log(tmp_path / "m.mf4", columns=mdf_columns(steering=True))
    got = log.epochs
    assert log.report.format == "MDF4" and log.report.balanced
    np.testing.assert_allclose(got["speed_mps"], ep["speed_mps"], rtol=1e-12)  # km/h in file
    np.testing.assert_allclose(got["heading_deg"], ep["heading_deg"], atol=1e-9)
    np.testing.assert_allclose(got["yaw_rate_rps"], ep["yaw_rate_rps"], atol=1e-12)
    assert (got["time_utc"] - ep["time_utc"]).abs().max() < pd.Timedelta("1us")
    # the 100 Hz steering channel on the 10 Hz epochs: asammdf's own linear resampling
    with asammdf.MDF(str(tmp_path / "m.mf4")) as mdf:
        t_ep = mdf.get("GNSS_TrueHeading").timestamps
        ref = mdf.get("RoadWheelAngle").interp(t_ep, float_interpolation_mode=1).samples
    np.testing.assert_allclose(np.rad2deg(got["steer_rad"]), ref, atol=1e-9)
    assert log.report.channels["heading_deg"] == pytest.approx(10.0)


def test_mdf4_errors_name_the_channel(tmp_path):
    ep = _epochs(10)
    write_mdf(ep, tmp_path / "m.mf4")
    with pytest.raises(InputError, match=r"no channel 'GNSS_Heading'.*did you mean GNSS_True"):
        read_log(tmp_path / "m.mf4", columns="heading=GNSS_Heading")
    with pytest.raises(InputError, match=r"MF4 log carries named channels.*--columns"):
        read_log(tmp_path / "m.mf4")
    with pytest.raises(InputError, match="speed needs a unit of speed"):
        read_log(tmp_path / "m.mf4", columns="heading=GNSS_TrueHeading,speed=GNSS_Speed:deg")
    # a unit in --columns overrides the file's: speed logged in km/h read as m/s on purpose
    got = read_log(tmp_path / "m.mf4", columns="heading=GNSS_TrueHeading,speed=GNSS_Speed:mps")
    np.testing.assert_allclose(got.epochs["speed_mps"], ep["speed_mps"] * 3.6)
    with pytest.raises(InputError, match="its unit 'deg' is not one of torque"):
        read_log(tmp_path / "m.mf4", columns="heading=GNSS_TrueHeading,torque=GNSS_Course")
    (tmp_path / "broken.mf4").write_bytes((tmp_path / "m.mf4").read_bytes()[:300])
    with pytest.raises(InputError, match=r"broken\.mf4"):
        read_log(tmp_path / "broken.mf4", columns="heading=GNSS_TrueHeading")


@pytest.mark.parametrize("suffix", ["blf", "asc"])
def test_can_log_decoded_with_the_dbc(tmp_path, suffix):
    ep = _epochs()
    sw = _steer(ep, 50.0).rename(columns={"road_wheel_deg": "steering_wheel_deg"})
    write_can(ep, tmp_path / f"c.{suffix}", DBC, steering_wheel=sw)
    cols = CAN_COLUMNS + ",steering_wheel=SteeringWheelAngle"
    log = read_log(tmp_path / f"c.{suffix}", columns=cols, dbc=DBC)
    got, rep = log.epochs, log.report
    assert rep.format == f"CAN {suffix.upper()}" and rep.balanced
    assert rep.unit == {"blf": "frames", "asc": "lines"}[suffix]  # an ASC's every line counted
    assert rep.parsed == {"EPS_Steering": len(sw), "GNSS_Heading": 60, "GNSS_Position": 60,
                          "GNSS_Velocity": 60}  # fmt: skip
    # the DBC's resolutions: 0.01 deg, 0.01 km/h, 1e-7 deg, 0.01 deg/s
    np.testing.assert_allclose(got["heading_deg"], ep["heading_deg"], atol=0.005 + 1e-9)
    np.testing.assert_allclose(got["speed_mps"], ep["speed_mps"], atol=0.005 / 3.6 + 1e-9)
    np.testing.assert_allclose(got["lat_deg"], ep["lat_deg"], atol=5e-8 + 1e-12)
    np.testing.assert_allclose(got["yaw_rate_rps"], ep["yaw_rate_rps"], atol=np.deg2rad(0.005))
    # cantools' per-frame decode is the reference of the steering channel
    db = cantools.database.load_file(str(DBC))
    reader = can.BLFReader if suffix == "blf" else can.ASCReader
    kw = {} if suffix == "blf" else {"relative_timestamp": False}
    frames = [m for m in reader(str(tmp_path / f"c.{suffix}"), **kw) if m.arbitration_id == 384]
    t_ref = np.array([m.timestamp for m in frames])
    v_ref = np.array([db.decode_message(384, m.data)["SteeringWheelAngle"] for m in frames])
    t_ep = ep["time_utc"].map(pd.Timestamp.timestamp).to_numpy()
    np.testing.assert_allclose(np.rad2deg(got["steering_wheel_rad"]),
                               np.interp(t_ep, t_ref, v_ref), atol=1e-6)  # fmt: skip
    assert (got["time_utc"] - ep["time_utc"]).abs().max() < pd.Timedelta("1ms")


def test_can_frames_that_do_not_decode_are_counted(tmp_path):
    ep = _epochs(20)
    write_can(ep, tmp_path / "c.blf", DBC)
    frames = list(can.BLFReader(str(tmp_path / "c.blf")))
    frames[3] = can.Message(timestamp=frames[3].timestamp, arbitration_id=frames[3].arbitration_id,
                            data=b"\x01", is_extended_id=False)  # fmt: skip
    frames.append(can.Message(timestamp=frames[-1].timestamp, arbitration_id=0x7FF, data=b"\0"))
    w = can.BLFWriter(str(tmp_path / "bad.blf"))
    for f in frames:
        w.on_message_received(f)
    w.stop()
    log = read_log(tmp_path / "bad.blf", columns=CAN_COLUMNS, dbc=DBC)
    rep = log.report
    assert rep.rejected["malformed field"] == 1 and rep.ignored["(not in the DBC)"] == 1
    assert rep.balanced and rep.total_lines == len(frames)
    assert "does not decode" in rep.first_rejects[0].detail
    with pytest.raises(InputError, match=r"bad\.blf: malformed field: frame 4"):
        read_log(tmp_path / "bad.blf", columns=CAN_COLUMNS, dbc=DBC, strict=True)
    with pytest.raises(InputError, match="needs its database: give --dbc"):
        read_log(tmp_path / "bad.blf", columns=CAN_COLUMNS)
    with pytest.raises(InputError, match="no channel 'Heading' for heading"):
        read_log(tmp_path / "bad.blf", columns="heading=Heading", dbc=DBC)


def test_relative_times_need_the_offset(tmp_path):
    ep = _epochs(20)
    write_can(ep, tmp_path / "c.blf", DBC, absolute=False)
    log = read_log(tmp_path / "c.blf", columns=CAN_COLUMNS, dbc=DBC)
    assert log.epochs["time_utc"].isna().all() and not log.report.has_date
    assert log.epochs["t_s"].iloc[-1] == pytest.approx(1.9)
    t0 = ep["time_utc"].iloc[0].timestamp()
    log = read_log(tmp_path / "c.blf", columns=CAN_COLUMNS, dbc=DBC, time_offset=t0)
    assert (log.epochs["time_utc"] - ep["time_utc"]).abs().max() < pd.Timedelta("1ms")


@settings(max_examples=25, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(cut=st.integers(0, 4000), flips=st.lists(st.integers(0, 4000), max_size=5))
def test_fuzz_mdf_and_blf_never_a_traceback(tmp_path_factory, cut, flips):
    d = tmp_path_factory.mktemp("fz")
    ep = _epochs(20)
    write_mdf(ep, d / "m.mf4")
    write_can(ep, d / "c.blf", DBC)
    for name, kw in (("m.mf4", {"columns": mdf_columns()}),
                     ("c.blf", {"columns": CAN_COLUMNS, "dbc": DBC})):  # fmt: skip
        b = bytearray((d / name).read_bytes())
        for f in flips:
            if 8 <= f < len(b):  # keep the signature: the format is still recognised
                b[f] ^= 0x5A
        (d / ("x" + name)).write_bytes(bytes(b[: max(cut, 8)]))
        try:
            log = read_log(d / ("x" + name), **kw)
        except InputError:
            continue
        assert log.report.balanced


def test_an_unfinalised_mdf_leaves_nothing_in_the_temporary_folder(tmp_path, monkeypatch):
    """asammdf copies an unfinalised MDF4 into the temporary folder; a read that failed left
    the copy there (one per file, as large as the log)."""
    scratch = tmp_path / "tmp"
    scratch.mkdir()
    monkeypatch.setattr(tempfile, "tempdir", str(scratch))
    write_mdf(_epochs(20), tmp_path / "m.mf4")
    b = bytearray((tmp_path / "m.mf4").read_bytes())
    b[60] = 1  # id_unfin_flags: the recorder did not finalise the file
    (tmp_path / "u.mf4").write_bytes(bytes(b))
    (tmp_path / "cut.mf4").write_bytes(bytes(b[: len(b) // 2]))
    log = read_log(tmp_path / "u.mf4", columns=mdf_columns())
    assert len(log.epochs) == 20
    with pytest.raises(InputError, match=r"cut\.mf4"):
        read_log(tmp_path / "cut.mf4", columns=mdf_columns())
    assert list(scratch.iterdir()) == []
