"""What survives a kill and a rerun: live and fleet keep the previous outputs intact, a killed
run's partial rows are never truncated by the next run, a fleet run that can use no log leaves
the previous result in place and fails.

The runs to be killed are console scripts (a real process and a real SIGKILL); the runs after
them, whose checks are about the files they leave, run in the test's process
(``tests.cli.inprocess``: the console script's entry point, its stdout, stderr and exit code)
without a console script's 2–4 s of imports each."""

from __future__ import annotations

import hashlib
import signal
import subprocess
import time
from pathlib import Path

import pandas as pd
import pytest

import gripsense
from gripsense.sim.fleet_data import Site, write_fleet
from tests.cli.inprocess import cli
from tests.cli.test_commands import EXE

DATA = Path(gripsense.__file__).parent / "data"
VEHICLE = DATA / "corolla_sim.toml"
DEMO = DATA / "demo" / "case021.nmea.gz"


def _hashes(root: Path) -> dict[str, str]:
    return {
        str(p.relative_to(root)): hashlib.sha256(p.read_bytes()).hexdigest()
        for p in sorted(root.rglob("*"))
        if p.is_file()
    }


def _live(out: Path, *extra: str) -> subprocess.Popen:
    return subprocess.Popen(
        [
            EXE,
            "live",
            "--replay",
            str(DEMO),
            "--speed",
            "3",
            "--vehicle",
            str(VEHICLE),
            "-o",
            str(out),
            "--quiet",
            *extra,
        ],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )


def test_live_rerun_after_sigkill_keeps_the_partial_and_the_raw_recording(tmp_path):
    out = tmp_path / "drive.parquet"
    p = _live(out)
    part = tmp_path / "drive.parquet.partial.csv"
    raw = tmp_path / "drive.parquet.raw.nmea"
    # kill once results were recorded (a header and at least one row flushed)
    deadline = time.monotonic() + 60.0
    while time.monotonic() < deadline and p.poll() is None:
        if part.exists() and part.read_bytes().count(b"\n") >= 2:
            break
        time.sleep(0.2)
    p.send_signal(signal.SIGKILL)
    p.wait(timeout=120)
    assert part.exists() and raw.stat().st_size > 0
    before = _hashes(tmp_path)
    # the natural next step — the same command again — must not truncate anything
    for extra in ((), ("--overwrite",)):
        r = cli(
            "live", "--replay", DEMO, "--speed", "0", "--vehicle", VEHICLE, "-o", out, "--quiet",
            *extra,
        )  # fmt: skip
        assert r.returncode == 2 and "recover it first" in r.stderr, r.stderr
        assert _hashes(tmp_path) == before
    rows = pd.read_csv(part)
    r = cli("live", "--recover", out)
    assert r.returncode == 0, r.stderr
    assert len(pd.read_parquet(out)) == len(rows) > 0
    assert not part.exists() and raw.exists()


def test_live_never_writes_its_input(tmp_path):
    log = tmp_path / "drive.nmea"
    log.write_bytes(DEMO.read_bytes())
    before = _hashes(tmp_path)
    # -o drive.csv used to record the raw bytes into drive.nmea: the replayed log itself
    r = cli(
        "live", "--replay", log, "--speed", "0", "--vehicle", VEHICLE,
        "-o", tmp_path / "drive.csv", "--quiet",
    )  # fmt: skip
    assert r.returncode == 0, r.stderr
    after = _hashes(tmp_path)
    assert after["drive.nmea"] == before["drive.nmea"]
    assert {"drive.csv", "drive.csv.raw.nmea"} <= set(after)
    # output named like the input: refused
    r = cli("live", "--replay", log, "--speed", "0", "--vehicle", VEHICLE, "-o", log, "--quiet")
    assert r.returncode == 2


SITES = [Site("a", 35.0, 139.0, 30.0, 0.9), Site("b", 35.01, 139.0, 30.0, 0.5)]


@pytest.fixture(scope="module")
def fleet_dir(tmp_path_factory):
    d = tmp_path_factory.mktemp("fleet")
    write_fleet(d / "logs", VEHICLE, SITES, n_vehicles=1)
    out = d / "out"
    r = cli(
        "fleet",
        str(d / "logs" / "**" / "*.nmea*"),
        "--vehicle",
        str(VEHICLE),
        "--workers",
        "1",
        "-o",
        str(out),
    )
    assert r.returncode == 0, r.stderr
    return d


def test_fleet_failed_rerun_keeps_the_previous_result(fleet_dir, tmp_path):
    out = fleet_dir / "out"
    before = _hashes(out)
    broken = tmp_path / "broken.toml"
    broken.write_text("[vehicle]\nmass_kg = 1200\n")
    r = cli(
        "fleet",
        str(fleet_dir / "logs" / "**" / "*.nmea*"),
        "--vehicle",
        str(broken),
        "--workers",
        "1",
        "-o",
        str(out),
        "--overwrite",
    )
    assert r.returncode != 0 and "none of the" in r.stderr
    assert _hashes(out) == before


def test_fleet_sigkill_keeps_the_previous_result_and_ids_cannot_escape(fleet_dir, tmp_path):
    out = fleet_dir / "out"
    (out / "epochs" / "2024").mkdir(parents=True, exist_ok=True)
    (out / "epochs" / "2024" / "notes.txt").write_text("my notes\n")
    before = _hashes(out)
    p = subprocess.Popen(
        [
            EXE,
            "fleet",
            str(fleet_dir / "logs" / "**" / "*.nmea*"),
            "--vehicle",
            str(VEHICLE),
            "--workers",
            "1",
            "-o",
            str(out),
            "--overwrite",
        ],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
    )
    # kill while the new result is being built (its temporary sibling exists)
    t_end = time.monotonic() + 60
    while not list(out.parent.glob(".gripsense-out-*")) and time.monotonic() < t_end:
        time.sleep(0.05)
    assert p.poll() is None, "the run finished before it could be killed"
    p.send_signal(signal.SIGKILL)
    p.wait(timeout=120)
    assert _hashes(out) == before
    # the next run replaces the result (one run checks two things): the user's file inside the
    # earlier result survives the overwrite, and a vehicle map whose id tries to leave the
    # output folder writes one folder inside -o (the id's partition) and nothing outside it
    vmap = tmp_path / "map.csv"
    vmap.write_text(f"*,{VEHICLE},../../escaped\n")
    r = cli(
        "fleet",
        str(fleet_dir / "logs" / "**" / "*.nmea*"),
        "--vehicle-map",
        str(vmap),
        "--workers",
        "1",
        "-o",
        str(out),
        "--overwrite",
    )
    assert r.returncode == 0, r.stderr
    assert (out / "epochs" / "2024" / "notes.txt").read_text() == "my notes\n"
    assert not list(tmp_path.parent.rglob("escaped*"))
    assert not list(fleet_dir.parent.rglob("escaped*"))
    parts = {p.parent.name for p in (out / "epochs").rglob("*.parquet")}
    assert parts == {"vehicle=.._.._escaped"}  # one folder inside -o
