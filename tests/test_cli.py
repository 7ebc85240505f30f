"""The command line, run as a user runs it (console script in the venv)."""

from __future__ import annotations

import json
import shutil
import subprocess
import sys
from pathlib import Path

import pandas as pd
import pytest

from tests.conftest import GPSD

EXE = shutil.which("gripsense") or str(Path(sys.executable).with_name("gripsense"))


def run(*args: str, cwd: Path | None = None) -> subprocess.CompletedProcess:
    return subprocess.run([EXE, *args], capture_output=True, text=True, cwd=cwd, timeout=120)


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
    r = run("demo", "-o", str(tmp_path / "rep"))
    assert r.returncode == 0, r.stderr
    rep = json.loads((tmp_path / "rep" / "ingest.json").read_text())
    assert rep["total_lines"] == 158 and rep["rejected"]["bad checksum"] == 0
    assert len(pd.read_csv(tmp_path / "rep" / "epochs.csv")) == rep["n_epochs"]


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
    r = run(
        "friction", str(log), "--vehicle", str(sample_path("corolla_thesis.toml")), "-o", str(out)
    )
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
