"""The command line, run as a user runs it (console script in the venv)."""

from __future__ import annotations

import json
import shutil
import subprocess
import sys
from pathlib import Path

import pandas as pd

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
