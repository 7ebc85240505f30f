"""``friction`` without ``-o`` writes one folder per log, named after it, in the current folder:
two logs never share a result, and a second run on the same log refuses to replace it."""

from __future__ import annotations

import shutil

from typer.testing import CliRunner

from gripsense.cli import app
from gripsense.cli.friction import default_outdir
from gripsense.data import path as data_path

RUNNER = CliRunner()


def test_default_folder_names():
    assert str(default_outdir(data_path("demo") / "case002.nmea.gz")) == "case002.friction"
    for name, want in (("drive.nmea.gz", "drive"), ("a.b.vbo", "a.b"), ("run.mf4", "run")):
        assert str(default_outdir(name)) == f"{want}.friction"


def test_friction_without_o_writes_beside_in_the_current_folder(tmp_path, monkeypatch):
    demo = data_path("demo")
    for case in ("case002", "case003"):
        shutil.copy(demo / f"{case}.nmea.gz", tmp_path / f"{case}.nmea.gz")
    vehicle = next(demo.glob("vehicle*.toml"))
    monkeypatch.chdir(tmp_path)
    for case in ("case002", "case003"):
        r = RUNNER.invoke(app, ["friction", f"{case}.nmea.gz", "--vehicle", str(vehicle)])
        assert r.exit_code == 0, r.output
        assert (tmp_path / f"{case}.friction" / "summary.json").is_file()
    again = RUNNER.invoke(app, ["friction", "case002.nmea.gz", "--vehicle", str(vehicle)])
    assert again.exit_code != 0 and "case002.friction" in again.output
    assert "Traceback" not in again.output
