"""The fleet's front axles (issue 46 item 5d): a steering CSV per log by the naming rule
``<log stem>_steer.csv``, or the steering channel inside the log; the front axles that could not
be estimated are counted. On the files `gripsense simulate` writes."""

from __future__ import annotations

import shutil

import pandas as pd
import pytest

from gripsense.fleet.run import expand_logs, steer_csv_for
from gripsense.fleet.tasks import process_batch
from gripsense.pipeline import NO_STEERING


@pytest.mark.parametrize(
    ("log", "steer"),
    [
        ("LOGS/car1/drive1.nmea.gz", "LOGS/car1/drive1_steer.csv"),
        ("drive1.nmea", "drive1_steer.csv"),
        ("drive1.vbo", "drive1_steer.csv"),
        ("drive1.mf4.GZ", "drive1_steer.csv"),
        ("2026-05-04.a.ubx", "2026-05-04.a_steer.csv"),
        ("drive1", "drive1_steer.csv"),
        ("drive1.gz", "drive1_steer.csv"),
    ],
)
def test_the_naming_rule(log, steer):
    assert steer_csv_for(log).as_posix() == steer


def _folder(simulated, tmp_path):
    """drive1 (NMEA + its steering CSV), drive2 (NMEA alone), drive3 (VBOX, channel inside)."""
    nmea, vbo = simulated("nmea"), simulated("vbo")
    d = tmp_path / "car1"
    d.mkdir()
    shutil.copy(nmea.log, d / "drive1.nmea.gz")
    shutil.copy(nmea.steer, d / "drive1_steer.csv")
    shutil.copy(nmea.log, d / "drive2.nmea.gz")
    shutil.copy(vbo.log, d / "drive3.vbo")
    return d, nmea.vehicle


def test_each_log_finds_its_steering(simulated, tmp_path):
    d, vehicle = _folder(simulated, tmp_path)
    logs = expand_logs([str(d / "*")])
    assert [p.split("/")[-1] for p in logs] == ["drive1.nmea.gz", "drive2.nmea.gz", "drive3.vbo"]
    items = [(p, str(vehicle), "car1") for p in logs]
    recs = {
        r["log"].split("/")[-1]: r
        for r in process_batch(items, str(tmp_path / "out"), method="axle-window", h3_res=11,
                               since=None, steer_columns="t=t_s,road_wheel=road_wheel_deg:deg")
    }  # fmt: skip
    assert all(r["problem"] == "" for r in recs.values()), recs
    assert recs["drive1.nmea.gz"]["steering"].startswith("--steer-csv drive1_steer.csv")
    assert recs["drive1.nmea.gz"]["front_axle"] == ""
    assert recs["drive2.nmea.gz"]["front_axle"] == NO_STEERING
    assert "RoadWheelAngle" in recs["drive3.vbo"]["steering"]
    units = {
        name: set(pd.read_parquet(next((tmp_path / "out" / "epochs" / "vehicle=car1").glob(
            f"{name}-*.parquet")))["unit"])
        for name in recs
    }  # fmt: skip
    assert units == {
        "drive1.nmea.gz": {"front", "rear"},
        "drive2.nmea.gz": {"rear"},
        "drive3.vbo": {"front", "rear"},
    }


@pytest.mark.slow  # a LocalCluster
def test_the_summary_counts_the_front_axles_not_estimated(simulated, tmp_path):
    from tests.cli.test_commands import run

    d, vehicle = _folder(simulated, tmp_path)
    out = tmp_path / "fleet"
    r = run("fleet", str(d / "*"), "--vehicle", str(vehicle), "--workers", "1", "-o", str(out))
    assert r.returncode == 0, r.stderr
    assert "3 logs: 3 used, 0 with problems" in r.stdout
    assert "1 log without a steering channel: front axle not estimated" in r.stdout
    logs = pd.read_csv(out / "logs.csv", keep_default_na=False)
    assert dict(zip(logs["log"].str.split("/").str[-1], logs["front_axle"], strict=True)) == {
        "drive1.nmea.gz": "",
        "drive2.nmea.gz": NO_STEERING,
        "drive3.vbo": "",
    }
