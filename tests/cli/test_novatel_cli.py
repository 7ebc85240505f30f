"""A NovAtel ASCII log on the command line: ``ingest`` and ``friction`` read it with no
``--columns``, and the drive it holds gives the friction answer of the same drive's NMEA."""

from __future__ import annotations

import gzip
from pathlib import Path

import pandas as pd
import pytest

from gripsense.io import read_nmea
from gripsense.io.logs.novatel import write_novatel
from tests.cli.inprocess import cli
from tests.cli.test_formats_cli import SCENARIO  # the same simulated drive

pytestmark = pytest.mark.slow  # end to end: `make test-fast` skips it

DATA = Path(__file__).resolve().parents[1] / "data" / "formats" / "novatel"


def _axles(stdout: str) -> str:
    """The one-line answer: both axles' values, bounds and intervals."""
    return next(ln for ln in stdout.splitlines() if ln.startswith("front axle"))


def test_ingest_a_real_novatel_log_without_columns():
    r = cli("ingest", DATA / "driver_lines.asc")
    assert r.returncode == 0, r.stderr
    assert "NovAtel ASCII" in r.stdout and "balanced: yes" in r.stdout
    assert r.stderr.strip() == ""


def test_friction_on_a_simulated_drive_logged_as_novatel_ascii(tmp_path):
    sc = tmp_path / "sc.toml"
    sc.write_text(SCENARIO)
    out = tmp_path / "sim"
    r = cli("simulate", sc, "-o", out, "--format", "nmea")
    assert r.returncode == 0, r.stderr
    c = pd.read_csv(out / "cases.csv").iloc[0]
    nmea = out / c["log"]
    # the receiver's NMEA without its rate of turn: NovAtel's logs carry none, so both take
    # the yaw rate from the heading
    lines = gzip.decompress(nmea.read_bytes()).decode().splitlines()
    plain = tmp_path / "norot.nmea"
    plain.write_text("\r\n".join(ln for ln in lines if "ROT," not in ln[:7]) + "\r\n")
    nov = tmp_path / "drive.asc"
    write_novatel(read_nmea(plain).epochs, nov)
    vehicle = out / "vehicle.toml"
    steer = ["--steer-csv", out / c["steer"]]
    r = cli("ingest", nov)
    assert r.returncode == 0, r.stderr
    assert "NovAtel ASCII" in r.stdout and "balanced: yes" in r.stdout
    fronts = {}
    for name, log in (("nmea", plain), ("novatel", nov)):
        r = cli("friction", log, "--vehicle", vehicle, *steer, "-o", tmp_path / f"fr-{name}")
        assert r.returncode == 0, r.stderr
        fronts[name] = _axles(r.stdout)
    assert "μ ≥" in fronts["nmea"] and fronts["novatel"] == fronts["nmea"], fronts
