"""The formats on the command line: simulate --format, then ingest and friction read the files
with the --columns the case index names; bad input is one line.

The commands run in the test's process (``tests.cli.inprocess``: the console script's entry
point, its stdout, stderr — warnings and log lines included — and exit code); twenty console
scripts paid ~55 s of interpreter and library imports that none of these checks is about.
``--help`` keeps the console script (its speed is part of what it promises)."""

from __future__ import annotations

import pandas as pd
import pytest

from tests.cli.inprocess import cli
from tests.cli.test_commands import run

pytestmark = pytest.mark.slow  # end to end: `make test-fast` skips it

SCENARIO = """
[scenario]
vehicle = "corolla_sim.toml"
seed = 5
[road]
mu = 0.5
[gnss]
rate_hz = 10
noise = "v100"
[steering]
rate_hz = 20
[[case]]
maneuver = "circle"
speed_kmh = 35
radius_m = 25
laps = 1
"""


def _front(stdout: str) -> str:
    line = next(ln for ln in stdout.splitlines() if ln.startswith("front axle"))
    return line.split(";")[0]


def test_simulate_each_format_and_read_it_back(tmp_path):
    sc = tmp_path / "sc.toml"
    sc.write_text(SCENARIO)
    fronts = {}
    for fmt in ("nmea", "vbo", "ubx", "mf4", "rosbag2"):
        out = tmp_path / fmt
        r = cli("simulate", str(sc), "-o", str(out), "--format", fmt)
        assert r.returncode == 0, r.stderr
        c = pd.read_csv(out / "cases.csv").iloc[0]
        log = out / c["log"]
        assert log.exists() and ("nmea" in c) == (fmt == "nmea")
        cols = c.get("columns")
        columns = ["--columns", cols] if isinstance(cols, str) else []
        # VBOX and MDF4 carry the steering channel inside; NMEA, UBX and ROS bags need the CSV
        steer = ["--steer-csv", str(out / c["steer"])] if fmt in ("nmea", "ubx", "rosbag2") else []
        r = cli("ingest", str(log), *columns)
        assert r.returncode == 0, r.stderr
        assert "balanced: yes" in r.stdout and "channels:" in r.stdout
        vehicle = str(out / "vehicle.toml")
        r = cli("friction", str(log), "--vehicle", vehicle, *columns, *steer, "-o",
                str(tmp_path / f"fr-{fmt}"))  # fmt: skip
        assert r.returncode == 0, r.stderr
        fronts[fmt] = _front(r.stdout)
    assert len(set(fronts.values())) == 1, fronts


def test_bad_format_input_is_one_line(tmp_path):
    (tmp_path / "cut.vbo").write_text("File created on 1/1/2026 @ 10:00\n[header]\ntime\n")
    r = cli("ingest", str(tmp_path / "cut.vbo"))
    assert r.returncode != 0 and "Traceback" not in r.stderr
    assert "no [column names] section" in r.stderr and len(r.stderr.strip().splitlines()) == 1
    r = cli("simulate", "nothing.toml", "--format", "csv", "-o", str(tmp_path / "x"))
    assert r.returncode != 0
    assert "--format 'csv': use one of nmea, vbo, ubx, mf4, rosbag2" in r.stderr
    (tmp_path / "x.mf4").write_bytes(b"MDF     4.10    " + bytes(64))
    r = cli("ingest", str(tmp_path / "x.mf4"), "--columns", "heading=H")
    assert r.returncode != 0 and "Traceback" not in r.stderr and "x.mf4" in r.stderr


def test_help_names_the_formats():
    r = run("ingest", "--help")
    assert "VBOX" in r.stdout and "--dbc" in r.stdout


TORQUE_SCENARIO = """
[scenario]
vehicle = "corolla_sim.toml"
tyre = "MagicFormula61_Paramerters.tir"
seed = 3
[road]
mu = 0.9
[gnss]
rate_hz = 10
noise = "v100"
[steering]
torque = true
[[case]]
maneuver = "constant_radius"
radius_m = 40
speed_start_kmh = 30
speed_end_kmh = 62
accel_mps2 = 0.15
"""


def test_simulate_a_torque_channel_and_estimate_with_it(tmp_path):
    """simulate writes torque_Nm into the steering CSV (its own rows at 100 Hz); friction reads
    it and names it in the front axle's answer; a flipped sign is one line and exit 2."""
    sc = tmp_path / "sc.toml"
    sc.write_text(TORQUE_SCENARIO)
    out = tmp_path / "sim"
    r = cli("simulate", str(sc), "-o", str(out))
    assert r.returncode == 0, r.stderr
    c = pd.read_csv(out / "cases.csv").iloc[0]
    steer = pd.read_csv(out / c["steer"])
    assert {"t_s", "road_wheel_deg", "torque_Nm"} <= set(steer.columns)
    assert steer["torque_Nm"].notna().sum() > steer["road_wheel_deg"].notna().sum()
    vehicle = str(out / c["vehicle_file"])
    args = ("friction", str(out / c["log"]), "--vehicle", vehicle, "--steer-csv",
            str(out / c["steer"]))  # fmt: skip
    r = cli(*args, "-o", str(tmp_path / "fr"))
    assert r.returncode == 0, r.stderr
    assert "steering torque" in r.stdout
    flipped = "t=t_s:s,road_wheel=road_wheel_deg:deg,torque=-torque_Nm:Nm"
    r = cli(*args, "--steer-columns", flipped, "-o", str(tmp_path / "fr2"))
    assert r.returncode == 2
    assert "sign is flipped" in r.stderr and "Traceback" not in r.stderr
    assert len(r.stderr.strip().splitlines()) == 1


def test_the_torque_rides_inside_an_mdf4_log(tmp_path):
    """simulate --format mf4 puts the column torque in the MDF4 file at its own rate
    (SteeringTorque); the case index's --columns read it back and friction uses it."""
    sc = tmp_path / "sc.toml"
    sc.write_text(TORQUE_SCENARIO)
    out = tmp_path / "sim"
    r = cli("simulate", str(sc), "-o", str(out), "--format", "mf4")
    assert r.returncode == 0, r.stderr
    c = pd.read_csv(out / "cases.csv").iloc[0]
    assert "torque=SteeringTorque" in c["columns"]
    r = cli("friction", str(out / c["log"]), "--vehicle", str(out / c["vehicle_file"]),
            "--columns", c["columns"], "-o", str(tmp_path / "fr"))  # fmt: skip
    assert r.returncode == 0, r.stderr
    assert "steering torque" in r.stdout
