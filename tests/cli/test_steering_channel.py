"""The front axle's steering channel, wherever it is (issue 46 items 5 and 6), run as a user runs
`gripsense friction` on the files `gripsense simulate` writes.

Command-line checks run the command in the test's process (``tests.cli.inprocess``: the
console script's entry point, its stdout, stderr and exit code), without a console
script's 2–4 s of imports per call, which none of these checks is about."""

from __future__ import annotations

import json

from gripsense.pipeline import NO_STEERING
from tests.cli.inprocess import cli


def _axle_line(stdout: str, axle: str) -> str:
    """The explanation's part about one axle (the line after the table)."""
    line = next(ln for ln in stdout.splitlines() if ln.startswith(("front axle:", "rear axle:")))
    return next(p for p in line.split("; ") if p.startswith(f"{axle} axle"))


def test_a_vbo_steering_channel_is_used_without_columns(simulated, tmp_path):
    sim = simulated("vbo")
    args = ("friction", str(sim.log), "--vehicle", str(sim.vehicle))
    r = cli(*args, "-o", str(tmp_path / "found"))
    assert r.returncode == 0, r.stderr
    assert "note: steering channel found by its name and unit: steer=RoadWheelAngle [deg]" in (
        r.stdout
    )
    assert "steering: the log's 'RoadWheelAngle' [deg] (found by name and unit)" in r.stdout
    assert "no steering channel" not in r.stdout
    m = cli(*args, "--columns", sim.columns, "-o", str(tmp_path / "mapped"))
    assert m.returncode == 0, m.stderr
    assert _axle_line(r.stdout, "front") == _axle_line(m.stdout, "front")
    summary = json.loads((tmp_path / "found" / "summary.json").read_text())
    assert [a["axle"] for a in summary["axles"]] == ["front", "rear"]


def test_no_steering_channel_is_said_in_one_line(simulated, tmp_path):
    sim = simulated("nmea")
    out = tmp_path / "fr"
    r = cli("friction", str(sim.log), "--vehicle", str(sim.vehicle), "-o", str(out))
    assert r.returncode == 0, r.stderr
    lines = [ln for ln in r.stdout.splitlines() if "steering channel" in ln]
    assert len(lines) == 1 and lines[0].endswith(NO_STEERING)  # the result's one line says it
    assert NO_STEERING.startswith(
        "front axle: no steering channel — give --steer-csv FILE or map one with --columns "
        "steer=CHANNEL"
    )
    summary = json.loads((out / "summary.json").read_text())
    assert summary["meta"]["front_axle"] == NO_STEERING
    assert [a["axle"] for a in summary["axles"]] == ["rear"]


def test_the_simulated_steering_csv_read_angle_only(simulated, tmp_path):
    """The issue's command: the torque rows carry no angle; with the angle only mapped they are
    counted, not refused, and the front axle is estimated as with every column mapped."""
    sim = simulated("nmea")
    base = ("friction", str(sim.log), "--vehicle", str(sim.vehicle), "--steer-csv", str(sim.steer))
    r = cli(*base, "--steer-columns", "t=t_s,road_wheel=road_wheel_deg:deg", "-o",
            str(tmp_path / "a"))  # fmt: skip
    assert r.returncode == 0, r.stderr
    assert "rows carry none of the mapped channels (road_wheel_deg): not used" in r.stdout
    assert "steering: --steer-csv" in r.stdout and "no steering channel" not in r.stdout
    summary = json.loads((tmp_path / "a" / "summary.json").read_text())
    assert [a["axle"] for a in summary["axles"]] == ["front", "rear"]
    ingest = json.loads((tmp_path / "a" / "ingest.json").read_text())
    assert any("rows carry none of the mapped channels" in n for n in ingest["notes"])
