"""Every input ``gripsense fleet`` is given is accounted for: each named or matched path is in
``logs.csv`` (used) or ``problems.csv`` (with its reason), and the summary counts them all —
a typo, a dangling link, a link loop, a named pipe, a device, a folder, a pattern that matches
nothing, a second name of the same file, a log whose steering CSV cannot be read."""

from __future__ import annotations

import os
from pathlib import Path

import pandas as pd
import pytest

import gripsense
from gripsense.fleet.run import account_inputs
from gripsense.sim.fleet_data import Site, write_fleet
from tests.cli.test_commands import run

VEHICLE = Path(gripsense.__file__).parent / "data" / "corolla_sim.toml"


@pytest.fixture(scope="module")
def logs(tmp_path_factory) -> Path:
    d = tmp_path_factory.mktemp("fleet_inputs")
    write_fleet(d / "logs", VEHICLE, [Site("a", 35.0, 139.0, 30.0, 0.9)], n_vehicles=1)
    return d / "logs"


def _good(logs: Path) -> Path:
    (log,) = sorted(logs.rglob("*.nmea*"))
    return log


# kind → (make it in folder d, returning the name to give; a word its reason must hold)
KINDS = {
    "typo": (lambda d: d / "drvie1.nmea.gz", "no such file"),
    "dangling": (lambda d: _link(d / "dangling.nmea", "nowhere.nmea"), "dangling"),
    "loop": (lambda d: _link(d / "loop.nmea", "loop.nmea"), "loop"),
    "loop2": (lambda d: _link(d / "b.nmea", _link(d / "c.nmea", "b.nmea").name), "loop"),
    "fifo": (lambda d: _fifo(d / "pipe.nmea"), "named pipe"),
    "device": (lambda d: Path("/dev/null"), "device"),
    "folder": (lambda d: _folder(d / "sub"), "folder"),
    "through a file": (lambda d: d / "x.nmea" / "y.nmea", "not a directory"),
}


def _link(p: Path, target: str) -> Path:
    p.symlink_to(target)
    return p


def _fifo(p: Path) -> Path:
    os.mkfifo(p)
    return p


def _folder(p: Path) -> Path:
    p.mkdir()
    (p / "notes.txt").write_text("not a log\n")
    return p


@pytest.mark.parametrize("kind", KINDS)
def test_every_named_input_is_a_log_or_a_problem_with_its_reason(kind, logs, tmp_path):
    make, word = KINDS[kind]
    (tmp_path / "x.nmea").write_text("$GPGGA\n")
    bad = str(make(tmp_path))
    good = str(_good(logs))
    used, problems = account_inputs([good, bad])
    assert used == [good]
    assert [p for p, _ in problems] == [bad]
    assert word in problems[0][1], problems


def test_patterns_account_for_what_they_match_and_for_matching_nothing(logs, tmp_path):
    d = tmp_path / "car02"
    d.mkdir()
    good = _good(logs)
    (d / "drive.nmea.gz").symlink_to(good)  # a second name of the same file
    (d / "dangling.nmea").symlink_to("gone.nmea")
    os.mkfifo(d / "pipe.nmea")
    (d / "deeper").mkdir()  # a folder a pattern matches is no input
    (d / "drive_steer.csv").write_text("t_s,steer_deg\n")  # the log's, not a log
    used, problems = account_inputs([str(good), str(d / "*"), str(tmp_path / "*.vbo")])
    assert used == [str(good)]
    why = dict(problems)
    assert set(why) == {
        str(d / "drive.nmea.gz"),
        str(d / "dangling.nmea"),
        str(d / "pipe.nmea"),
        str(tmp_path / "*.vbo"),
    }, why
    assert "the same file as" in why[str(d / "drive.nmea.gz")]
    assert "no file matches" in why[str(tmp_path / "*.vbo")]


@pytest.mark.slow
def test_fleet_counts_every_input_in_its_csvs_and_summary(logs, tmp_path):
    """The issue's case: a log and four named inputs it cannot read, plus a log whose steering
    CSV is a dangling link; a real run (LocalCluster, 1 worker)."""
    good = _good(logs)
    d = tmp_path / "car03"
    d.mkdir()
    second = d / "second.nmea.gz"
    second.write_bytes(good.read_bytes())
    (d / "second_steer.csv").symlink_to("missing_steer.csv")
    bad = [
        str(d / "drvie1.nmea.gz"),
        str(_link(d / "dangling.nmea", "nowhere.nmea")),
        str(_link(d / "loop.nmea", "loop.nmea")),
        str(_fifo(d / "pipe.nmea")),
    ]
    out = tmp_path / "out"
    r = run("fleet", str(good), str(second), *bad, "--vehicle", str(VEHICLE),
            "--workers", "1", "-o", str(out))  # fmt: skip
    assert r.returncode == 0, r.stderr
    assert "6 logs: 1 used, 5 with problems" in r.stdout, r.stdout
    lg = pd.read_csv(out / "logs.csv", keep_default_na=False)
    pr = pd.read_csv(out / "problems.csv", keep_default_na=False)
    assert sorted(lg["log"]) == sorted([str(good), str(second), *bad])
    assert sorted(pr["log"]) == sorted([str(second), *bad])
    why = dict(zip(pr["log"], pr["problem"], strict=True))
    assert "steering CSV" in why[str(second)] and "dangling" in why[str(second)]
    assert "no such file" in why[bad[0]] and "loop" in why[bad[2]]
    assert "named pipe" in why[bad[3]]
    assert r.stderr.strip() == "", r.stderr


@pytest.mark.slow
def test_fleet_with_no_readable_input_fails_naming_them(tmp_path):
    out = tmp_path / "out"
    r = run("fleet", str(tmp_path / "typo.nmea"), str(_link(tmp_path / "l.nmea", "l.nmea")),
            "--vehicle", str(VEHICLE), "--workers", "1", "-o", str(out))  # fmt: skip
    assert r.returncode == 2, r.stderr
    assert "none of the 2 logs" in r.stderr and "no such file" in r.stderr
    assert len(r.stderr.strip().splitlines()) == 1 and "Traceback" not in r.stderr
    assert not out.exists()
