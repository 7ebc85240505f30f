"""read_log: one epoch table from every format — the same drive in NMEA, VBOX, UBX, MDF4 and
CAN gives the same epochs (to each format's resolution) and the same friction result."""

from __future__ import annotations

import gzip

import numpy as np
import pytest

from gripsense.data import path as data_path
from gripsense.errors import InputError
from gripsense.io import read_nmea
from gripsense.io.logs import LogOptions, detect_format, read_log, write_log
from gripsense.io.logs.canlog import CAN_SIGNALS, write_can
from gripsense.pipeline import FrictionRun
from tests.conftest import DATA

DEMO = data_path("demo")
CASE = "case021"  # a Magic Formula tyre on a wet road near its limit: windows with values
DBC = DATA / "formats" / "vehicle.dbc"


@pytest.fixture(scope="module")
def drive(tmp_path_factory):
    """One simulated drive written in every format (as ``gripsense simulate --format`` does)."""
    import pandas as pd

    d = tmp_path_factory.mktemp("formats")
    nmea = DEMO / f"{CASE}.nmea.gz"
    lines = gzip.decompress(nmea.read_bytes()).decode().splitlines()
    ep = read_nmea(nmea).epochs
    steer = pd.read_csv(DEMO / f"{CASE}_steer.csv")
    files = {"nmea": (nmea, LogOptions())}
    for fmt, suffix in (("vbo", ".vbo"), ("ubx", ".ubx"), ("mf4", ".mf4")):
        cols = write_log(ep, d / f"drive{suffix}", fmt, nmea_lines=lines, steer=steer)
        files[fmt] = (d / f"drive{suffix}", LogOptions(columns=cols))
    write_can(ep, d / "drive.blf", DBC)
    cols = ",".join(f"{k}={v}" for k, v in CAN_SIGNALS.items())
    files["blf"] = (d / "drive.blf", LogOptions(columns=cols, dbc=DBC))
    return ep, files


def test_every_format_gives_the_same_epoch_table(drive):
    ref, files = drive
    tol = {"heading_deg": 0.006, "course_deg": 0.006, "speed_mps": 0.0015, "lat_deg": 2e-7,
           "lon_deg": 2e-7, "yaw_rate_rps": 1e-4}  # fmt: skip
    for fmt, (path, opts) in files.items():
        log = read_log(path, opts)
        assert detect_format(path.read_bytes()[:65536]) == ("nmea" if fmt == "nmea" else fmt)
        ep = log.epochs
        assert len(ep) == len(ref), fmt
        assert (ep["time_utc"] - ref["time_utc"]).abs().max().total_seconds() < 1e-3, fmt
        for c, atol in tol.items():
            a, b = ep[c].to_numpy(float), ref[c].to_numpy(float)
            d = (a - b + 180) % 360 - 180 if c.endswith("deg") and "lat" not in c else a - b
            assert np.nanmax(np.abs(d)) <= atol, (fmt, c, np.nanmax(np.abs(d)))
        assert log.report.balanced, fmt
        assert log.report.channels["heading_deg"] == pytest.approx(10.0), fmt


def test_every_format_gives_the_same_friction(drive):
    _, files = drive
    run = FrictionRun(DEMO / "vehicle_PacejkaBook_Defaults.toml", receiver="v100")
    steer_csv = DEMO / f"{CASE}_steer.csv"
    out = {}
    for fmt, (path, opts) in files.items():
        own = fmt in ("vbo", "mf4")  # these carry the steering channel inside
        res = run.run_log(path, steer_csv=None if own else steer_csv, log_options=opts)
        out[fmt] = res.estimates().round({"t_start": 3}).set_index(["unit", "t_start"])
    ref = out["nmea"]
    assert ref["mu"].notna().any()
    for fmt, e in out.items():
        assert e.index.equals(ref.index), fmt
        for c in ("mu", "mu_low", "mu_high", "grip_used_lower"):
            a, b = e[c].to_numpy(float), ref[c].to_numpy(float)
            assert np.array_equal(np.isnan(a), np.isnan(b)), (fmt, c)
            fin = np.isfinite(a) & np.isfinite(b)
            assert np.abs(a[fin] - b[fin]).max() <= 0.01, (fmt, c)


def test_the_formats_extra_is_named_when_missing(monkeypatch, tmp_path):
    import sys

    (tmp_path / "x.mf4").write_bytes(b"MDF     4.10    " + bytes(100))
    monkeypatch.setitem(sys.modules, "asammdf", None)  # as if not installed
    with pytest.raises(InputError, match=r"needs asammdf.*pip install 'gripsense\[formats\]'"):
        read_log(tmp_path / "x.mf4", columns="heading=H")


def test_unknown_key_and_missing_file_are_one_line(tmp_path):
    with pytest.raises(InputError, match="unknown key 'hdg' for a log; use heading"):
        read_log(DATA / "formats" / "sample.vbo", columns="hdg=True_Head")
    with pytest.raises(InputError, match="no such file"):
        read_log(tmp_path / "nothing.vbo")


def test_options_a_format_does_not_use_are_said():
    log = read_log(DATA / "formats" / "sample.vbo", dbc=DBC, time_offset=0.0)
    assert "--dbc and --time-offset not used: the log is VBOX VBO" in log.report.notes[-1]
    log = read_log(DEMO / "case001.nmea.gz", columns="heading=H")
    assert log.report.notes[-1].startswith("--columns not used: the log is NMEA 0183")
