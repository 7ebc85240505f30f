"""Every command's ``--help`` as a newcomer reads it (issue "What a newcomer trips on"): every
bracketed unit and default in a help string survives (no markup eats ``[deg]``), the sources are
named, and a usage error is one line with a hint — through the console script, as a user runs
it."""

from __future__ import annotations

import re
import subprocess
import sys

import pytest
import typer
from typer.testing import CliRunner

from gripsense.cli import app

RUNNER = CliRunner()


def _commands(cmd, path=()):
    yield path, cmd
    for name, sub in getattr(cmd, "commands", {}).items():
        yield from _commands(sub, (*path, name))


COMMANDS = list(_commands(typer.main.get_command(app)))


@pytest.mark.parametrize("path", [p for p, _ in COMMANDS], ids=lambda p: " ".join(p) or "root")
def test_help_keeps_every_bracket_and_names_its_sources(path):
    cmd = dict(COMMANDS)[path]
    r = RUNNER.invoke(app, [*path, "--help"])
    assert r.exit_code == 0, r.output
    flat = " ".join(r.output.split())
    texts = [getattr(p, "help", None) or "" for p in cmd.params] + [cmd.help or ""]
    brackets = {b for t in texts for b in re.findall(r"\[[^\]\s][^\]]*\]", t)}
    for b in brackets:
        assert " ".join(b.split()) in flat, (path, b)
    # the source documents by name, not by the project's internal numbering
    assert not re.search(r"seed 00\d", flat), path
    assert not re.search(r"(?<!University of Technology )thesis ch\.", flat), path


def test_a_unit_in_a_help_string_is_printed():
    """The issue's examples: units that markup used to delete."""
    out = " ".join(RUNNER.invoke(app, ["tyre", "eval", "--help"]).output.split())
    assert "Slip angle(s) [deg], e.g. -12:12:0.5" in out
    assert "Camber angle(s) [deg]" in out


@pytest.mark.parametrize(
    ("args", "want"),
    [
        (["ingest", "LOG", "--strict", "true"], "switches take no value"),
        (["frction"], "Did you mean 'friction'?"),
        (["ingest", "LOG", "--max-lines", "many"], "--max-lines"),
    ],
)
def test_a_usage_error_is_one_line(args, want, tmp_path):
    log = tmp_path / "drive.nmea"
    log.write_text("", encoding="ascii")
    args = [str(log) if a == "LOG" else a for a in args]
    r = subprocess.run(
        [sys.executable, "-c", "from gripsense.cli import main; main()", *args],
        capture_output=True,
        text=True,
        timeout=600,
    )
    assert r.returncode == 2, r
    lines = [x for x in (r.stdout + r.stderr).splitlines() if x.strip()]
    assert len(lines) == 1, lines
    assert lines[0].startswith("error: gripsense") and want in lines[0], lines
    assert "Traceback" not in r.stderr


def test_tables_are_whole_in_a_log_file(tmp_path):
    """Output piped to a file (a log, a CI job): no column cut to "measur…"/"undete…"."""
    from gripsense.data import path as data_path

    demo = data_path("demo")
    env = {k: v for k, v in __import__("os").environ.items() if k != "COLUMNS"}
    r = subprocess.run(
        [sys.executable, "-c", "from gripsense.cli import main; main()", "friction",
         str(demo / "case002.nmea.gz"), "--vehicle", str(demo / "vehicle.toml"),
         "--steer-csv", str(demo / "case002_steer.csv"), "-o", str(tmp_path / "run")],
        capture_output=True, text=True, timeout=300, env=env,
    )  # fmt: skip
    assert r.returncode == 0, r.stderr
    assert "…" not in r.stdout, r.stdout
    for header in ("measured grip", "data prove μ ≥", "90 % interval", "slippery?"):
        assert header in r.stdout
