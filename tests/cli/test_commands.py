"""The command line, run as a user runs it (console script in the venv).

The checks of what a command computes and writes from several runs of it
(``test_friction_axle_window_and_table``, ``test_simulate_command``) run it in the test's process
(``tests.cli.inprocess``: the console script's entry point, its stdout, stderr and exit code),
without a console script's 2–4 s of imports per call; the others keep the console script."""

from __future__ import annotations

import json
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from tests.cli.inprocess import cli
from tests.conftest import GPSD

EXE = shutil.which("gripsense") or str(Path(sys.executable).with_name("gripsense"))


def run(*args: str, cwd: Path | None = None) -> subprocess.CompletedProcess:
    return subprocess.run([EXE, *args], capture_output=True, text=True, cwd=cwd, timeout=600)


def test_ingest_writes_table(tmp_path):
    out = tmp_path / "epochs.parquet"
    r = run("ingest", str(GPSD / "saab-r4.log"), "-o", str(out))
    assert r.returncode == 0, r.stderr
    assert "balanced: yes" in r.stdout
    df = pd.read_parquet(out)
    assert len(df) == 12 and df["heading_deg"].notna().all()
    csv = tmp_path / "epochs.csv"
    assert run("ingest", str(GPSD / "hemi.log"), "-o", str(csv)).returncode == 0
    assert "yaw_rate_rps" in pd.read_csv(csv).columns


def test_ingest_errors_are_clear(tmp_path):
    r = run("ingest", str(tmp_path / "missing.nmea"))
    assert r.returncode == 2 and "no such file" in r.stderr
    bad = tmp_path / "bad.nmea"
    bad.write_text("$GPHDT,1.0,T*00\n")
    r = run("ingest", str(bad), "--strict")
    assert r.returncode == 2 and "bad.nmea:1: bad checksum" in r.stderr
    r = run("ingest", str(GPSD / "hemi.log"), "-o", str(tmp_path / "x.xlsx"))
    assert r.returncode == 2 and "use .parquet or .csv" in r.stderr


def test_demo(tmp_path):
    """The README's main job: runs on the bundled demo set, prints estimate next to truth."""
    r = run("demo", "-o", str(tmp_path / "rep"))
    assert r.returncode == 0, r.stderr
    assert "measured grip and estimated μ" in r.stdout and "verdict:" in r.stdout
    df = pd.read_csv(tmp_path / "rep" / "demo_results.csv")
    assert len(df) == 48 and set(df["receiver"]) == {"v100", "rtk"}
    assert {"brush", "PacejkaBook_Defaults.tir"} == set(df["tyre"])
    assert set(df["axle"]) == {"front", "rear"}  # the steering channel enables the front axle
    # the measured-grip bound never exceeds the truth
    assert df["bound_holds"].all()
    # values are reported only near the limit, and mostly hold the truth
    obs = df[df["observable"]]
    assert len(obs) >= 4 and (obs["utilisation_true"] > 0.6).all()
    assert obs["covered"].mean() >= 0.7
    assert (abs(obs["mu"] - obs["mu_true"]) <= 0.1).all()


def test_simulate_command(tmp_path):
    sc = tmp_path / "sc.toml"
    sc.write_text("""
[scenario]
vehicle = "corolla_sim.toml"
seed = 3
[road]
mu = 0.6
[gnss]
rate_hz = 20
noise = "none"
[accelerometer]
rate_hz = 50
[[case]]
maneuver = "circle"
speed_kmh = 30
radius_m = 20
laps = 1
[[case]]
maneuver = "braking"
speed_kmh = 40
""")
    out = tmp_path / "out"
    r = cli("simulate", str(sc), "-o", str(out))
    assert r.returncode == 0, r.stderr
    cases = pd.read_csv(out / "cases.csv")
    assert list(cases["maneuver"]) == ["circle", "braking"]
    assert (out / "vehicle.toml").exists()
    for c in cases.to_dict("records"):
        assert (out / c["nmea"]).exists() and (out / c["truth"]).exists()
        assert (out / c["accel"]).exists()
    truth = pd.read_parquet(out / cases["truth"][0])
    assert {"t_s", "wheel", "mu_true", "slip_angle_rad", "load_N", "force_N"} <= set(truth)
    assert set(truth["mu_true"].round(6)) == {0.6}
    bad = tmp_path / "bad.toml"
    bad.write_text('[scenario]\nvehicle = "corolla_sim.toml"\n[[case]]\nmaneuver = "drift"\n')
    r = cli("simulate", str(bad), "-o", str(out))
    assert r.returncode == 2 and "maneuver = 'drift'" in r.stderr


def _circle_nmea(path: Path) -> None:
    """Write the synthetic μ = 0.5 circle (tests/estimate/circle.py) as RMC + HDT + ROT."""
    from tests.estimate.circle import circle
    from tests.nmea_helpers import sentence

    epochs, _ = circle(mu=0.5, utilisation=0.92)
    lines = []
    for row in epochs.itertuples(index=False):
        tod = 12 * 3600 + row.t_s
        hh, mm, ss = int(tod // 3600), int(tod % 3600 // 60), tod % 60
        kn = row.speed_mps * 3600 / 1852
        lines.append(
            sentence(
                f"GPRMC,{hh:02d}{mm:02d}{ss:05.2f},A,3336.0000,N,13333.0000,E,"
                f"{kn:.5f},{row.course_deg:.5f},010718,,,A"
            )
        )
        lines.append(sentence(f"GPHDT,{row.heading_deg:.5f},T"))
        rot = -row.yaw_rate_rps * 180 / 3.141592653589793 * 60
        lines.append(sentence(f"GPROT,{rot:.4f},A"))
    path.write_text("\r\n".join(lines) + "\r\n")


def test_friction_command(tmp_path):
    from gripsense.data import sample_path

    log = tmp_path / "circle.nmea"
    _circle_nmea(log)
    out = tmp_path / "res"
    veh = str(sample_path("corolla_thesis.toml"))
    r = run("friction", str(log), "--vehicle", veh, "--method", "brush-2", "-o", str(out))
    assert r.returncode == 0, r.stderr
    assert "rear_left" in r.stdout and "wheels.parquet" in r.stdout
    doc = json.loads((out / "summary.json").read_text())
    rl = next(w for w in doc["wheels"] if w["wheel"] == "rear_left")
    assert rl["mu"] == pytest.approx(0.5, rel=0.02)  # NMEA rounding to 1e-5 degrees
    assert rl["n_valid"] > 100
    assert len(pd.read_parquet(out / "wheels.parquet")) == 400


def test_friction_command_errors(tmp_path):
    log = tmp_path / "circle.nmea"
    _circle_nmea(log)
    r = run("friction", str(log), "--vehicle", str(tmp_path / "none.toml"))
    assert r.returncode == 2 and "no such vehicle file" in r.stderr
    r = run("fit-contact", str(tmp_path / "none.csv"))
    assert r.returncode == 2 and "no such file" in r.stderr


def test_fit_contact_command():
    from gripsense.data import sample_path

    r = run("fit-contact", str(sample_path("thesis_table18.csv")))
    assert r.returncode == 0, r.stderr
    assert "a = 0.0103981" in r.stdout and "b = -0.000101717" in r.stdout
    assert "RMSE = 0.286 cm" in r.stdout


def test_friction_axle_window_and_table(tmp_path):
    """The same drive as NMEA and as a motion table (km/h, deg/s, a clockwise-positive yaw
    column flipped by '-') gives the same per-wheel kinematics; axle-window writes windows."""
    from gripsense.data import sample_path
    from tests.estimate.circle import circle

    veh = str(sample_path("corolla_thesis.toml"))
    log = tmp_path / "circle.nmea"
    _circle_nmea(log)
    out1 = tmp_path / "a"
    r = cli("friction", str(log), "--vehicle", veh, "--method", "axle-window", "-o", str(out1))
    assert r.returncode == 0, r.stderr
    assert "Friction per axle" in r.stdout and (out1 / "windows.parquet").exists()
    doc = json.loads((out1 / "summary.json").read_text())
    assert doc["axles"][0]["axle"] == "rear"
    # the same motion as a table: antenna body velocities
    epochs, _ = circle(mu=0.5, utilisation=0.92)
    beta = np.deg2rad(epochs["heading_deg"] - epochs["course_deg"])
    tab = pd.DataFrame(
        {
            "Time": epochs["t_s"],
            "VelX": epochs["speed_mps"] * np.cos(beta) * 3.6,
            "VelY": epochs["speed_mps"] * np.sin(beta) * 3.6,
            "YawRateCW": -np.rad2deg(epochs["yaw_rate_rps"]),
        }
    )
    csv = tmp_path / "ins.csv"
    tab.to_csv(csv, index=False)
    out2 = tmp_path / "b"
    r = cli(
        "friction",
        "--table",
        str(csv),
        "--columns",
        "t=Time,vx=VelX:kmh,vy=VelY:kmh,yaw_rate=-YawRateCW:dps",
        "--vehicle",
        veh,
        "-o",
        str(out2),
    )
    assert r.returncode == 0, r.stderr
    w = pd.read_parquet(out2 / "wheels.parquet").query("wheel == 'rear_left'")
    _, truth = circle(mu=0.5, utilisation=0.92)
    np.testing.assert_allclose(w["slip_angle_rad"], truth["alpha_rear_left"], rtol=1e-9)
    r = cli(
        "friction",
        "--table",
        str(csv),
        "--columns",
        "t=Time,vx=VelX,vy=Nope,yaw_rate=Time",
        "--vehicle",
        veh,
    )
    assert r.returncode == 2 and "no column 'Nope' for vy" in r.stderr
    r = cli("friction", "--table", str(csv), "--columns", "t=Time,vx=VelX", "--vehicle", veh)
    assert r.returncode == 2 and "no column for yaw_rate" in r.stderr, r.stderr
    # headers that carry a name and a unit need no --columns; the mapping is printed
    sp = np.hypot(tab["VelX"], tab["VelY"])
    auto = pd.DataFrame(
        {
            "time_s": tab["Time"],
            "speed_kmh": sp,
            "slip_deg": np.rad2deg(np.arctan2(tab["VelY"], tab["VelX"])),
            "yaw_rate_dps": -tab["YawRateCW"],
        }
    )
    csv2 = tmp_path / "named.csv"
    auto.to_csv(csv2, index=False)
    out3 = tmp_path / "c"
    r = cli("friction", "--table", str(csv2), "--vehicle", veh, "-o", str(out3))
    assert r.returncode == 0, r.stderr
    assert "t ← time_s [s], speed ← speed_kmh [km/h], slip ← slip_deg [deg]" in r.stdout
    w3 = pd.read_parquet(out3 / "wheels.parquet").query("wheel == 'rear_left'")
    np.testing.assert_allclose(w3["slip_angle_rad"], truth["alpha_rear_left"], rtol=1e-9)
    r = cli("friction", "--table", str(csv), "--vehicle", veh)
    assert r.returncode == 2 and "unit suffix" in r.stderr, r.stderr
