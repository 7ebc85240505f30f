"""Outputs get the user's umask like any other tool's (issue "What a newcomer trips on": files
installed by rename kept ``mkstemp``'s 0600 and result folders ``mkdtemp``'s 0700): every file and
folder each command writes, under umask 027.

The commands run in the test's process (``tests.cli.inprocess``: the console script's entry
point, the umask set for the call) — a mode comes from the umask and the calls that create the
file (``mkstemp``/``mkdtemp``/``open``), the same in a fresh process; six subprocesses paid
~15 s of imports for nothing the check needs."""

from __future__ import annotations

import os
import stat

import numpy as np
import pandas as pd
import pytest

from gripsense.data import path as data_path
from tests.cli.inprocess import cli
from tests.conftest import GPSD

pytestmark = pytest.mark.slow  # end to end: `make test-fast` skips it


def _run(args, mask, cwd):
    r = cli(*args, cwd=cwd, umask=mask)
    assert r.returncode == 0, (args, r.stderr)


@pytest.mark.parametrize("mask", [0o027])
def test_every_output_has_the_umask_mode(tmp_path, mask):
    demo = data_path("demo")
    log, veh = demo / "case001.nmea.gz", demo / "vehicle.toml"
    t = np.arange(0, 6, 0.02)
    accel = tmp_path / "accel.csv"
    ax = np.where((t > 2) & (t < 4.5), -0.8, 0.0)
    ax = ax + 0.03 * np.random.default_rng(1).standard_normal(t.size)
    pd.DataFrame({"t_s": t, "ax_g": ax, "ay_g": 0.0, "az_g": 1.0}).to_csv(accel, index=False)
    os.chmod(accel, 0o644)
    out = tmp_path / "out"
    out.mkdir()
    os.chmod(out, 0o755)
    commands = [
        ["ingest", GPSD / "hemi.log", "-o", out / "epochs.csv"],
        ["friction", log, "--vehicle", veh, "--steer-csv", demo / "case001_steer.csv",
         "-o", out / "run", "--report"],
        ["report", out / "run", "-o", out / "report.html"],
        ["brake-mu", accel, "-o", out / "events.csv", "--plot", out / "brake.png"],
        ["tyre", "eval", data_path("tyres/PacejkaBook_Defaults.tir"), "--fz", "4000",
         "-o", out / "tyre.csv"],
        ["calibrate", log, "--vehicle", veh, "-o", out / "car.calibration.toml"],
    ]  # fmt: skip
    for args in commands:
        _run(args, mask, tmp_path)
    want_file, want_dir = 0o666 & ~mask, 0o777 & ~mask
    seen = 0
    for root, dirs, files in os.walk(out):
        for d in dirs:
            assert stat.S_IMODE(os.stat(os.path.join(root, d)).st_mode) == want_dir, d
        for f in files:
            mode = stat.S_IMODE(os.stat(os.path.join(root, f)).st_mode)
            assert mode == want_file, (f, oct(mode))
            seen += 1
    assert seen >= 8
