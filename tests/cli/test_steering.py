"""`gripsense steering identify`, run as a user runs it, on simulated test recordings.

The commands run in the test's process (``tests.cli.inprocess``: the console script's entry
point, its stdout, stderr and exit code): each console script paid 2–4 s of imports that none of
these checks is about."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pandas as pd

import gripsense
from gripsense.config import SteeringCar
from gripsense.physics.steering_system import simulate_release, simulate_step
from tests.cli.inprocess import cli

TOML = Path(gripsense.__file__).parent / "data" / "of18_steering.toml"


def test_identify_from_recordings(tmp_path):
    car = SteeringCar.from_toml(TOML)
    truth = car.with_cs(70.0).with_ks(3500.0)
    rng = np.random.default_rng(1)
    args = []
    for i in range(4):
        r = simulate_release(truth, alpha0_rad=np.deg2rad(30) / 5, duration_s=4.0)
        t = np.concatenate([np.arange(-0.5, 0, 1e-3), r["t_s"]])
        a = np.rad2deg(np.concatenate([np.full(500, r["alpha_rad"][0]), r["alpha_rad"]])) * 5
        p = tmp_path / f"release{i}.csv"
        pd.DataFrame({"t_s": t, "steer_deg": a + 0.1 * rng.standard_normal(a.size)}).to_csv(
            p, index=False
        )
        args += ["--release", str(p)]
    for rate in (50, 70, 90):
        s = simulate_step(
            truth,
            steer_rate_rad_s=np.deg2rad(rate) / 5,
            stop_rad=np.deg2rad(90) / 5,
            duration_s=5.0,
        )
        p = tmp_path / f"step{rate}.csv"
        pd.DataFrame(
            {
                "t_s": s["t_s"],
                "steer_deg": np.rad2deg(s["alpha_rad"]) * 5,
                "yaw_rate_dps": np.rad2deg(s["yaw_rate_rps"])
                + 0.2 * rng.standard_normal(s["t_s"].size),
            }
        ).to_csv(p, index=False)
        args += ["--step", str(p)]
    out = tmp_path / "out"
    r = cli("steering", "identify", str(TOML), *args, "--gain-law", "linear", "-o", str(out))
    assert r.returncode == 0, r.stderr
    d = json.loads((out / "steering.json").read_text())
    assert d["converged"]
    assert d["cs_low"] <= 70.0 <= d["cs_high"]
    assert d["ks_low"] <= 3500.0 <= d["ks_high"]
    for f in ("release.png", "settling.png", "yaw_gain.png"):
        assert (out / f).stat().st_size > 10_000


def test_seed_summary_numbers_and_errors(tmp_path):
    r = cli(
        "steering",
        "identify",
        str(TOML),
        "--settling",
        "0.80,0.86,0.76,0.84,0.72",
        "--yaw-gain",
        "85.5",
        "--steer-rate",
        "70",
    )
    assert r.returncode == 0, r.stderr
    assert "first pass (seed)" in r.stdout and "converged" in r.stdout
    assert "no interval" in r.stdout
    r = cli("steering", "identify", str(TOML))
    assert r.returncode == 2 and "--settling" in r.stderr
    bad = tmp_path / "bad.csv"
    bad.write_text("t_s,angle\n0,1\n")
    r = cli("steering", "identify", str(TOML), "--release", str(bad))
    assert r.returncode == 2 and "steer_deg" in r.stderr and "Traceback" not in r.stderr
