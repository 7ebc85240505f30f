"""`gripsense tyre eval` and `gripsense tyre fit`, run as a user runs them.

The first test runs the console script; the others run the command in the test's process
(``tests.cli.inprocess``: the console script's entry point, its stdout, stderr and exit code),
without a console script's 2–4 s of imports per call, which none of their checks is about."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from gripsense.physics.magic_formula.pac94 import pac94_lateral
from gripsense.sim.tyre_data import PAC94_EXAMPLE, cornering_samples
from tests.cli.inprocess import cli
from tests.cli.test_commands import run

TIR = Path(__file__).parent.parent / "data" / "tyre" / "tir"
TRUTH = PAC94_EXAMPLE


def test_eval_matches_mfeval_reference_rows(tmp_path):
    out = tmp_path / "ev.csv"
    r = run(
        "tyre",
        "eval",
        str(TIR / "PacejkaBook_Defaults.tir"),
        "--fz",
        "4000",
        "--alpha-deg",
        "-12:12:0.5",
        "-o",
        str(out),
    )
    assert r.returncode == 0, r.stderr
    df = pd.read_csv(out, comment="#")
    assert len(df) == 49
    row = df[df.alpha_deg == 4.0].iloc[0]
    assert row.fy_N == pytest.approx(-2709.49, abs=0.01)  # MFeval README hand check


def test_eval_grid_and_errors(tmp_path):
    r = cli(
        "tyre",
        "eval",
        str(TIR / "HMMWV_Pac89Tire.json"),
        "--fz",
        "20000,30000",
        "--alpha-deg",
        "5",
        "--kappa",
        "0,0.05",
    )
    assert r.returncode == 0, r.stderr
    assert "PAC89" in r.stdout
    r = cli("tyre", "eval", str(tmp_path / "missing.tir"), "--fz", "1000")
    assert r.returncode == 2 and "no such file" in r.stderr
    r = cli("tyre", "eval", str(TIR / "FSAE_Defaults.tir"), "--fz", "1000", "--alpha-deg", "1:x")
    assert r.returncode == 2 and "--alpha-deg" in r.stderr
    assert "Traceback" not in r.stderr


@pytest.fixture
def road_csv(tmp_path):
    d = cornering_samples(
        lambda fz, a, g: pac94_lateral(TRUTH, fz, a, g), 1500, rng=np.random.default_rng(0)
    )
    path = tmp_path / "road.csv"
    out = pd.DataFrame(
        {
            "alpha_deg": np.rad2deg(d.alpha_rad),
            "gamma_deg": np.rad2deg(d.gamma_rad),
            "fz_N": d.fz_N,
            "fy_N": d.fy_N,
        }
    )
    out.loc[3, "fy_N"] = np.nan
    out.to_csv(path, index=False)
    return path


def test_fit_pac94_json_and_plot(tmp_path, road_csv):
    out, png = tmp_path / "fit.json", tmp_path / "fit.png"
    r = cli(
        "tyre",
        "fit",
        str(road_csv),
        "--model",
        "pac94",
        "--constraints",
        "all",
        "-o",
        str(out),
        "--plot",
        str(png),
        "--compare",
    )
    assert r.returncode == 0, r.stderr
    assert "1499 of 1500 rows used" in r.stdout and "fy_not_a_number 1" in r.stdout
    doc = json.loads(out.read_text())
    assert doc["physical_checks"] == {
        "C_in_(1,2)": True,
        "E_in_range": True,
        "peak_largest_at_zero_camber": True,
    }
    assert png.stat().st_size > 20_000
    # the fit file evaluates like a tyre model
    r = cli("tyre", "eval", str(out), "--fz", "4000", "--alpha-deg", "3")
    assert r.returncode == 0 and "PAC94" in r.stdout


def test_fit_mf61_tir_with_column_mapping(tmp_path, road_csv):
    df = pd.read_csv(road_csv)
    ttc = pd.DataFrame({"SA": df.alpha_deg, "IA": df.gamma_deg, "FZ": -df.fz_N, "FY": df.fy_N})
    src = tmp_path / "ttc.csv"
    ttc.to_csv(src, index=False)
    out = tmp_path / "fit.tir"
    r = cli(
        "tyre",
        "fit",
        str(src),
        "--model",
        "mf61",
        "--columns",
        "alpha=SA:deg,gamma=IA:deg,fz=-FZ,fy=FY",
        "-o",
        str(out),
    )
    assert r.returncode == 0, r.stderr
    r = cli("tyre", "eval", str(out), "--fz", "4000", "--alpha-deg", "-3,3")
    assert r.returncode == 0, r.stderr
    r = cli("tyre", "fit", str(src), "-o", str(tmp_path / "x.tir"))
    assert r.returncode == 2 and "--model mf61" in r.stderr
    r = cli("tyre", "fit", str(src))
    assert r.returncode == 2 and "--columns" in r.stderr


def test_fit_on_a_friction_runs_wheels_table(tmp_path):
    """`tyre fit` on a friction run's wheels.parquet: both axles without --wheel is refused with
    a line saying what to give; with --wheel the rows add up; a fit that determines nothing is
    refused, never written with exit 0."""
    from gripsense.data import path as data_path

    demo = data_path("demo")
    out = tmp_path / "run"
    r = cli("friction", str(demo / "case002.nmea.gz"), "--vehicle", str(demo / "vehicle.toml"),
            "--steer-csv", str(demo / "case002_steer.csv"), "-o", str(out))  # fmt: skip
    assert r.returncode == 0, r.stderr
    wheels = out / "wheels.parquet"
    r = cli("tyre", "fit", str(wheels), "-o", str(tmp_path / "fit.json"))
    assert r.returncode == 2 and "--wheel front or --wheel rear" in r.stderr, r.stderr
    assert not (tmp_path / "fit.json").exists()
    r = cli("tyre", "fit", str(wheels), "--wheel", "rear", "-o", str(tmp_path / "fit.json"))
    assert r.returncode == 0, r.stderr
    line = next(x for x in r.stdout.splitlines() if "rows used" in x)
    nums = [int(n) for n in __import__("re").findall(r"\b(\d+)\b", line)]
    used, total, rejected = nums[0], nums[1], nums[2:]
    assert used + sum(rejected) == total == len(pd.read_parquet(wheels)), line
    assert "other_wheels" in line
    # points that carry no tyre (force independent of slip): refused, nothing written
    rng = np.random.default_rng(3)
    flat = tmp_path / "flat.csv"
    pd.DataFrame(
        {
            "alpha_deg": rng.uniform(-6, 6, 400),
            "fz_N": rng.uniform(3000, 5000, 400),
            "fy_N": rng.normal(0.0, 30.0, 400),
        }
    ).to_csv(flat, index=False)
    r = cli("tyre", "fit", str(flat), "-o", str(tmp_path / "flat.json"), "--plot",
            str(tmp_path / "flat.png"))  # fmt: skip
    assert r.returncode == 2 and "determines no tyre" in r.stderr, (r.stdout, r.stderr)
    assert not (tmp_path / "flat.json").exists() and not (tmp_path / "flat.png").exists()
