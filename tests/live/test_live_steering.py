"""`gripsense live` and its front axle (issue 46 item 5c): a steering CSV replayed beside the log,
or the steering channel inside a replayed VBOX; without either, one line says why the front axle
is missing. On the files `gripsense simulate` writes."""

from __future__ import annotations

import pandas as pd
import pytest

from gripsense.live import open_replay, run_live
from gripsense.pipeline import NO_STEERING
from tests.cli.inprocess import cli

ANGLE_ONLY = "t=t_s,road_wheel=road_wheel_deg:deg"


def _live(sim, **kw) -> dict:
    src = open_replay(sim.log, 0.0)
    return run_live(src, sim.vehicle, handle_signals=False, **kw)


def test_a_steering_csv_beside_the_replay_gives_the_front_axle(simulated):
    sim = simulated("nmea")
    res = _live(sim, steer_csv=sim.steer, steer_columns=ANGLE_ONLY)
    assert list(res["summary"]["unit"]) == ["front", "rear"]
    front = res["summary"].set_index("unit").loc["front"]
    assert front["n_valid"] > 0 and front["grip_used_lower"] > 0.2
    assert res["front_axle"] == "" and res["steering"].startswith("--steer-csv")
    assert any("rows carry none of the mapped channels" in n for n in res["notes"])
    # the same drive without it: the rear axle only, and the reason
    bare = _live(sim)
    assert list(bare["summary"]["unit"]) == ["rear"]
    assert bare["front_axle"] == NO_STEERING and bare["stats"].front_axle == NO_STEERING
    # the rear's estimate is the same; its measured grip knows the front's steer (the yaw
    # moment the split leaves out, docs/physics.md §14.1) and never says less with it — nor
    # does a range without a value, which starts at the measured grip (§15.11)
    rear_bare = bare["summary"].set_index("unit").loc["rear"]
    rear = res["summary"].set_index("unit").loc["rear"]
    grip = ["grip_used", "grip_used_lower", "mu_low"]
    pd.testing.assert_series_equal(rear_bare.drop(grip), rear.drop(grip))
    assert rear["grip_used_lower"] >= rear_bare["grip_used_lower"]
    assert rear["mu_low"] >= rear_bare["mu_low"]
    if not rear["observable"]:
        assert rear["mu_low"] == pytest.approx(rear["grip_used_lower"])


def test_the_steering_channel_inside_a_replayed_vbo(simulated):
    sim = simulated("vbo")
    res = _live(sim)
    assert list(res["summary"]["unit"]) == ["front", "rear"]
    assert res["front_axle"] == "" and "RoadWheelAngle" in res["steering"]


def test_the_command_line(simulated, tmp_path):
    """The command in the test's process (``tests.cli.inprocess``: the console script's entry
    point, its stdout, stderr and exit code), without a console script's imports per call."""
    sim = simulated("nmea")
    base = ["live", "--replay", sim.log, "--vehicle", sim.vehicle, "--speed", "0", "--quiet"]
    r = cli(*base, "--steer-csv", sim.steer, "--steer-columns", ANGLE_ONLY,
            "-o", tmp_path / "live.csv")  # fmt: skip
    assert r.returncode == 0, r.stderr
    assert "steering: --steer-csv" in r.stdout and "no steering channel" not in r.stdout
    rows = pd.read_csv(tmp_path / "live.csv")
    assert {"front", "rear"} <= set(rows["unit"])
    r = cli(*base)
    assert r.returncode == 0, r.stderr
    assert " ".join(NO_STEERING.split()) in " ".join(r.stdout.split())  # the display wraps it
    r = cli("live", "--tcp", "localhost:1", "--vehicle", sim.vehicle, "--steer-csv", sim.steer)
    assert r.returncode == 2 and "--steer-csv is replayed beside --replay LOG" in r.stderr
    assert len(r.stderr.strip().splitlines()) == 1
