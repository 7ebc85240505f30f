"""One run of each README command whose output file no other test reads, checked for content
(not just the exit code). In-process (Typer's runner) to keep the suite fast; the subprocess
tests in this folder run the installed console script."""

from __future__ import annotations

import json

import numpy as np
import pandas as pd
import pytest
from typer.testing import CliRunner

from gripsense.cli import app
from gripsense.constants import G0
from gripsense.data import sample_path
from gripsense.demo import demo_dir

RUNNER = CliRunner()


def invoke(*args: str):
    r = RUNNER.invoke(app, [str(a) for a in args])
    assert r.exit_code == 0, (r.output, r.exception)
    return r


@pytest.fixture(scope="module")
def friction_dir(tmp_path_factory):
    """A friction result folder of a near-limit demo drive (brush tyres, RTK-class receiver)."""
    out = tmp_path_factory.mktemp("fr") / "res"
    d = demo_dir()
    invoke(
        "friction", d / "case017.nmea.gz", "--vehicle", d / "vehicle.toml",
        "--receiver", "rtk", "-o", out,
    )  # fmt: skip
    return out


def test_friction_writes_a_complete_result(friction_dir):
    man = json.loads((friction_dir / "manifest.json").read_text())
    assert man["kind"] == "friction" and man["result"] == "axle"  # axle-window by default
    files = {"wheels.parquet", "summary.json", "epochs.parquet", "windows.parquet"}
    assert set(man["files"]) >= files
    summary = json.loads((friction_dir / "summary.json").read_text())
    assert {a["axle"] for a in summary["axles"]} == {"rear"}
    rear = summary["axles"][0]
    # both kinds of statement, under distinct names
    assert 0 < rear["grip_used_lower"] <= rear["grip_used"] and "mu_low" in rear
    assert "the data prove μ ≥" in summary["explain"]
    wheels = pd.read_parquet(friction_dir / "wheels.parquet")
    assert {"grip_used", "grip_sigma", "flag"} <= set(wheels.columns) and len(wheels) > 100
    windows = pd.read_parquet(friction_dir / "windows.parquet")
    assert {"grip_used_lower", "mu", "mu_low", "mu_high"} <= set(windows.columns)
    assert not any("lower_bound" in c for c in windows.columns)


def test_report_command(friction_dir, tmp_path):
    out = tmp_path / "r.html"
    invoke("report", friction_dir, "-o", out)
    text = out.read_text()
    assert text.startswith("<!doctype html>") and "data:image/png;base64," in text


def test_stiffness_command(tmp_path):
    d = demo_dir()
    invoke("stiffness", d / "case001.nmea.gz", "--vehicle", d / "vehicle.toml", "-o", tmp_path)
    tab = pd.read_csv(tmp_path / "stiffness.csv")
    assert len(tab) >= 2 and (tab["G"] > 0).all()


def test_brake_mu_command(tmp_path):
    # a locked-wheel stop at μ = 0.8 after a cruise: plateau −0.8 g, a Fig. 110-like trace
    t = np.arange(0, 6, 0.02)
    noise = 0.03 * np.random.default_rng(1).standard_normal(t.size)
    ax = np.where((t > 2.0) & (t < 4.5), -0.8, 0.0) + noise
    f = tmp_path / "accel.csv"
    pd.DataFrame({"t_s": t, "ax_g": ax, "ay_g": 0.0, "az_g": 1.0}).to_csv(f, index=False)
    out, png = tmp_path / "events.csv", tmp_path / "brake.png"
    r = invoke("brake-mu", f, "-o", out, "--plot", png)
    ev = pd.read_csv(out)
    assert len(ev) == 1 and ev["mu"].iloc[0] == pytest.approx(0.8, abs=0.01)
    assert "columns t ← t_s [s], ax ← ax_g [g]" in r.output and png.stat().st_size > 10_000


def test_camber_command(tmp_path):
    t = np.arange(0, 2, 0.01)
    spacing = 0.2
    outer = 100.0 + np.where(t > 1, spacing * 1000 * np.tan(np.deg2rad(2.0)), 0.0)
    f = tmp_path / "laser.csv"
    pd.DataFrame({"t_s": t, "d_outer_mm": outer, "d_inner_mm": 100.0}).to_csv(f, index=False)
    out = tmp_path / "camber.csv"
    invoke("camber", f, "--spacing-m", spacing, "--calibrate-s", 0.5, "-o", out)
    c = pd.read_csv(out)["camber_deg"].to_numpy()
    assert c[t > 1] == pytest.approx(2.0, abs=1e-9) and c[t < 1] == pytest.approx(0.0, abs=1e-9)


@pytest.mark.parametrize("cmd", [["fit-contact"], ["tyre", "fit-contact"]])
def test_fit_contact_commands(cmd):
    r = invoke(*cmd, sample_path("thesis_table18.csv"))
    # Table 18 fit (docs/physics.md §5): a = 0.010398, b = −1.0172e-4
    assert "a = 0.0103981 " in r.output and "b = -0.000101717 " in r.output


def test_tyre_eval_writes_csv(tmp_path):
    from tests.conftest import DATA

    out = tmp_path / "fy.csv"
    tir = DATA / "tyre" / "tir" / "MagicFormula61_Paramerters.tir"
    invoke("tyre", "eval", tir, "--fz", 4000, "--alpha-deg", "-5:5:1", "-o", out)
    df = pd.read_csv(out, comment="#")
    assert len(df) == 11 and np.all(np.sign(df["fy_N"][df["alpha_deg"] != 0]) != 0)
    assert df["fz_N"].eq(4000).all() and np.isfinite(df["fy_N"]).all()


def test_units_constant_is_standard_gravity():
    assert G0 == 9.80665  # docs/physics.md §0
