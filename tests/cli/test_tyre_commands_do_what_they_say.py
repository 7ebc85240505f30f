"""`gripsense tyre eval` and `tyre fit` do what they say (issue 45): bundled names as
`simulate` takes them, the file's version as its FITTYP says, no silent clipping, a plot,
no unconverged fit written with exit 0, no curve drawn at a load the fit is not valid for.

Command-line checks run the command in the test's process (``tests.cli.inprocess``: the
console script's entry point, its stdout, stderr and exit code), without a console
script's 2–4 s of imports per call, which none of these checks is about."""

from __future__ import annotations

import re
from pathlib import Path

import matplotlib.image as mpimg
import numpy as np
import pandas as pd
import pytest
from typer.testing import CliRunner

from gripsense.data import path as data_path
from gripsense.io.tyres.tir import read_tir
from gripsense.physics.magic_formula.pac94 import pac94_lateral
from gripsense.sim.tyre_data import PAC94_EXAMPLE, cornering_samples
from tests.cli.inprocess import cli

ROOT = Path(__file__).resolve().parents[2]
BUNDLED = data_path("tyres")
VERSIONS = {5: "5.2", 6: "5.2", 21: "5.2", 61: "6.1", 62: "6.2"}  # FITTYP → MF version


def _eval_csv(tmp_path: Path, *args: str, name: str = "ev.csv"):
    out = tmp_path / name
    r = cli("tyre", "eval", *args, "-o", str(out), cwd=tmp_path)
    return r, (pd.read_csv(out, comment="#") if out.exists() else None)


def test_eval_takes_the_bundled_names_simulate_takes(tmp_path):
    r, df = _eval_csv(tmp_path, "PacejkaBook_Defaults.tir", "--fz", "4000", "--alpha-deg", "4")
    assert r.returncode == 0, r.stderr
    # MFeval's README hand check of this file (tests/data/tyre/mfeval_ref/README.md)
    assert df["fy_N"].iloc[0] == pytest.approx(-2709.49, abs=0.01)
    r = cli("tyre", "eval", "NoSuchTyre.tir", "--fz", "4000", cwd=tmp_path)
    assert r.returncode == 2 and "PacejkaBook_Defaults.tir" in r.stderr  # names the bundled ones
    assert len(r.stderr.strip().splitlines()) == 1


@pytest.mark.parametrize("tir", sorted(p.name for p in BUNDLED.glob("*.tir")))
def test_the_version_eval_prints_is_the_files_fittyp_and_the_docs_say_so(tir, tmp_path):
    fittyp = read_tir(BUNDLED / tir).parameters().get("FITTYP")
    r = cli("tyre", "eval", tir, "--fz", "4000", cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    if fittyp is None:  # PAC2002 files without FITTYP are read as MF 5.2 (docs/tyre.md)
        assert "MF 5.2" in r.stdout
        return
    version = VERSIONS[int(fittyp)]
    assert f"MF {version}" in r.stdout
    for doc in sorted((ROOT / "docs").glob("*.md")):
        for said in re.findall(rf"`{re.escape(tir)}` \(MF (\d\.\d)", doc.read_text("utf-8")):
            assert said == version, f"{doc.name} calls {tir} MF {said}; its FITTYP {fittyp}"


def test_eval_says_when_it_clips_to_the_files_limits(tmp_path):
    tir = BUNDLED / "PacejkaBook_Defaults.tir"
    p = read_tir(tir).parameters()
    fzmax = p["FZMAX"]  # 10 000 N in the file
    args = (str(tir), "--fz", f"{fzmax:g},{fzmax * 1.2:g}", "--alpha-deg", "3")
    r, df = _eval_csv(tmp_path, *args)
    assert r.returncode == 0, r.stderr
    notes = [x for x in r.stdout.splitlines() if "limits" in x]
    assert len(notes) == 1 and "1 of 2 points" in notes[0] and f"{fzmax:.0f}" in notes[0]
    assert df["fy_N"].iloc[1] == df["fy_N"].iloc[0]  # evaluated at FZMAX, as MFeval does
    r, df2 = _eval_csv(tmp_path, *args, "--no-limits", name="free.csv")
    assert r.returncode == 0 and "limits" not in r.stdout
    assert abs(df2["fy_N"].iloc[1] / df2["fy_N"].iloc[0] - 1) > 0.01  # the formula at 12 kN
    # within the limits: no note
    r, _ = _eval_csv(tmp_path, str(tir), "--fz", "4000", "--alpha-deg", "3", name="in.csv")
    assert r.returncode == 0 and "limits" not in r.stdout


def test_eval_plot(tmp_path):
    png = tmp_path / "curves.png"
    r = cli("tyre", "eval", "MagicFormula61_Paramerters.tir", "--fz", "2000,4000",
            "--alpha-deg", "-12:12:0.5", "--kappa", "0,0.05", "--plot", str(png),
            cwd=tmp_path)  # fmt: skip
    assert r.returncode == 0, r.stderr
    img = mpimg.imread(png)
    assert img.shape[0] > 300 and float(np.std(img[..., :3])) > 0.02
    r = cli("tyre", "eval", "PacejkaBook_Defaults.tir", "--fz", "4000", "--plot",
            str(tmp_path / "x.jpg"), cwd=tmp_path)  # fmt: skip
    assert r.returncode == 2 and "--plot" in r.stderr


@pytest.fixture
def road_csv(tmp_path):
    d = cornering_samples(
        lambda fz, a, g: pac94_lateral(PAC94_EXAMPLE, fz, a, g), 800, rng=np.random.default_rng(1)
    )
    path = tmp_path / "road.csv"
    pd.DataFrame(
        {
            "alpha_deg": np.rad2deg(d.alpha_rad),
            "gamma_deg": np.rad2deg(d.gamma_rad),
            "fz_N": d.fz_N,
            "fy_N": d.fy_N,
        }
    ).to_csv(path, index=False)
    return path


def test_fit_that_hit_the_iteration_limit_is_refused_unless_forced(tmp_path, road_csv):
    out, png = tmp_path / "fit.json", tmp_path / "fit.png"
    r = cli("tyre", "fit", str(road_csv), "--max-iter", "4", "-o", str(out), "--plot", str(png))
    assert r.returncode == 2, (r.stdout, r.stderr)
    assert "did not converge" in r.stderr and "--force" in r.stderr
    assert len(r.stderr.strip().splitlines()) == 1
    assert not out.exists() and not png.exists()
    r = cli("tyre", "fit", str(road_csv), "--max-iter", "4", "-o", str(out), "--force")
    assert r.returncode == 0, r.stderr
    assert any(x.startswith("warning:") and "did not converge" in x for x in r.stdout.splitlines())
    assert '"success": false' in out.read_text()
    # the same data with the default iterations converge and are written without a word
    r = cli("tyre", "fit", str(road_csv), "-o", str(tmp_path / "ok.json"))
    assert r.returncode == 0 and "did not converge" not in r.stdout + r.stderr


def test_fit_plot_uses_the_points_of_the_fit_only(tmp_path, monkeypatch):
    """A wheels table's other wheels and unsteady rows are not the fit's data: the figure got
    them and drew a curve at a load outside the fit's valid range (1.7 kN vs 2.1–4.8 kN)."""
    import gripsense.report.tyre_figures as tf
    from gripsense.cli._app import app

    rng = np.random.default_rng(5)
    n = 600
    a = rng.uniform(-0.08, 0.08, n)
    fz = rng.uniform(3500, 4500, n)
    rear = pd.DataFrame(
        {
            "wheel": np.where(np.arange(n) % 2, "rear_left", "rear_right"),
            "slip_angle_rad": a,
            "load_N": fz,
            "force_N": pac94_lateral(PAC94_EXAMPLE, fz, a, 0.0) + rng.normal(0, 30, n),
            "steady": True,
        }
    )
    other = rear.assign(wheel="front_left", load_N=rear["load_N"] * 0.4)  # 1.4–1.8 kN
    unsteady = rear.iloc[:50].assign(load_N=1000.0, steady=False)
    table = pd.concat([rear, other, unsteady], ignore_index=True)
    wheels = tmp_path / "wheels.parquet"
    table.to_parquet(wheels)
    seen = {}

    def spy(fit, data, **kw):
        seen["fz"] = np.asarray(data["fz_N"], float)
        seen["range"] = fit.ranges["fz_N"]
        return real(fit, data, **kw)

    real = tf.fit_figure
    monkeypatch.setattr(tf, "fit_figure", spy)
    res = CliRunner().invoke(
        app, ["tyre", "fit", str(wheels), "--wheel", "rear", "--plot", str(tmp_path / "f.png")]
    )
    assert res.exit_code == 0, res.output
    lo, hi = seen["range"]
    assert len(seen["fz"]) == n  # the rear wheels' steady rows: what the fit used
    assert seen["fz"].min() >= lo and seen["fz"].max() <= hi


def test_python_errors_name_the_python_argument():
    """In Python the fit's refusal names ``wheel=``, not only the command's ``--wheel``."""
    from gripsense.errors import InputError
    from gripsense.identify.tyre_fit import fit_from_wheel_table

    both = pd.DataFrame(
        {
            "wheel": ["front_left", "rear_left"],
            "slip_angle_rad": [0.01, 0.02],
            "load_N": [4000.0, 4000.0],
            "force_N": [-500.0, -900.0],
        }
    )
    with pytest.raises(InputError, match=re.escape('wheel="front"')):
        fit_from_wheel_table(both)
