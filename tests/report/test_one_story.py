"""One story per result: the report written with the run (``friction --report``) and the one
written later from its folder (``gripsense report DIR``) state the same priors, title,
receiver and calibration; every number of the stiffness carries its kind; the per-condition μ
is labelled; figures are not empty beside a value."""

from __future__ import annotations

import html as H
import json
import os
import re
import subprocess

import matplotlib.colors as mcolors
import numpy as np
import pandas as pd
import pytest

from gripsense.data import path as data_path
from gripsense.errors import InputError
from gripsense.estimate.results import AxleFriction
from gripsense.report import figures as F
from gripsense.report.html import render_report
from gripsense.report.summary_check import check_summary_file
from tests.cli.inprocess import cli
from tests.cli.test_commands import EXE
from tests.report.test_report import _result

pytestmark = pytest.mark.slow  # end to end: `make test-fast` skips it

DEMO = data_path("demo")
VEHICLE = DEMO / "vehicle.toml"
# the demo car's rear wheel at its static load: m = 1200 kg · 0.4 / 2 = 240 kg, contact length
# l = 0.0104 √m − 1.017e-4 m (the vehicle file's l–m model), C = G w l² / 2 (seed 000 eq. 9.1)
_M = 1200.0 * 0.4 / 2
_L = 0.0104 * np.sqrt(_M) - 1.017e-4 * _M
C_REAR_DECLARED = 0.5 * 5e7 * 0.185 * _L**2  # 86 437 N/rad, ± 20 % (the default)
C_REAR_LEARNED, U_REAR_LEARNED = 80000.0, 0.136
CALIBRATION = f"""[calibration]
vehicle = "Corolla-like sedan (simulation)"

[calibration.rear]
cornering_stiffness_N_per_rad = {C_REAR_LEARNED}
stiffness_uncertainty = {U_REAR_LEARNED}
scale = 0.93
bins = 40
"""


def _text(page: str) -> str:
    """The words of a page, without its images and the minute it was written."""
    page = re.sub(r"<img[^>]*>|<wbr>", "", page)
    page = re.sub(r"written \d{4}-\d\d-\d\d \d\d:\d\d UTC", "written …", page)
    return H.unescape(re.sub(r"\s+", " ", re.sub(r"<[^>]+>", " ", page)))


@pytest.fixture(scope="module")
def calibrated_run(tmp_path_factory):
    """``friction --report`` with the RTK receiver and a calibration of the rear axle, and
    ``gripsense report`` of a copy of its folder written later."""
    d = tmp_path_factory.mktemp("story")
    cal = d / "car.calibration.toml"
    cal.write_text(CALIBRATION)
    out = d / "run"
    r = subprocess.run(
        [
            EXE,
            "friction",
            str(DEMO / "case002.nmea.gz"),
            "--vehicle",
            str(VEHICLE),
            "--steer-csv",
            str(DEMO / "case002_steer.csv"),
            "--receiver",
            "rtk",
            "--calibration",
            str(cal),
            "-o",
            str(out),
            "--report",
        ],
        capture_output=True,
        text=True,
        timeout=600,
        env={**os.environ, "COLUMNS": "250"},
    )  # fmt: skip  (a wide console: every table cell on one line)
    assert r.returncode == 0, r.stderr
    again = d / "again.html"
    r2 = cli("report", out, "-o", again)  # in-process: no second interpreter's imports
    assert r2.returncode == 0, r2.stderr
    return out, again, r.stdout


def test_report_later_tells_the_same_story_as_the_run(calibrated_run):
    out, again, _ = calibrated_run
    first = _text((out / "report.html").read_text(encoding="utf-8"))
    later = _text(again.read_text(encoding="utf-8"))
    assert first == later
    # the priors the run used: the RTK compass's residual heading bias √2 × 0.05° (its slow
    # error, docs/physics.md §15) — not the V100 default 0.60°
    assert "heading bias (±0.07°)" in later, later
    assert "±0.60°" not in later
    # the title names the log, not the folder it was later read from
    assert "Friction — case002.nmea.gz" in later


def test_the_calibration_in_use_is_named_with_what_it_changed(calibrated_run):
    _, again, stdout = calibrated_run
    page = again.read_text(encoding="utf-8")
    header = re.search(r"<p class='meta'>gripsense ·(.*?)</p>", page).group(1)
    assert "car.calibration.toml" in header and "rtk" in header
    # per axle: declared, learned and used, each labelled; the used centre is the declared
    # and learned combined in ln C by their inverse variances (docs/calibration.md)
    w_d, w_l = 1 / np.log1p(0.2) ** 2, 1 / np.log1p(U_REAR_LEARNED) ** 2
    used = np.exp((w_d * np.log(C_REAR_DECLARED) + w_l * np.log(C_REAR_LEARNED)) / (w_d + w_l))

    def n(x):
        return f"{x:,.0f}".replace(",", " ")

    text = _text(page)
    for where in (text, stdout):
        line = where[where.index("rear tyre cornering stiffness") :][:300]
        assert f"declared (vehicle file) {n(C_REAR_DECLARED)} N/rad ± 20 %" in line, line
        assert f"learned (calibration) {n(C_REAR_LEARNED)} N/rad ± 14 %" in line, line
        assert f"used (the estimator's prior) {n(used)} N/rad" in line, line
        assert "calibration in use: car.calibration.toml" in where
    # summary.json names each number's kind; its stiffness is the drive's estimate
    kinds = json.loads((again.parent / "run" / "summary.json").read_text())["kinds"]
    assert kinds["grip_used_lower"] == "measured" and kinds["mu"] == "estimated", kinds
    assert kinds["cornering_stiffness_N_per_rad"] == "estimated", kinds
    assert "estimated from this drive" in text
    assert (
        "cornering_stiffness_N_per_rad (estimated)" in text or "stiffness_scale (estimated)" in text
    )


def test_a_hand_edited_record_is_one_line(calibrated_run, tmp_path):
    out, _, _ = calibrated_run
    doc = json.loads((out / "summary.json").read_text())
    doc["record"]["noise"]["heading_bias_deg"] = "small"
    folder = tmp_path / "edited"
    folder.mkdir()
    (folder / "summary.json").write_text(json.dumps(doc))
    with pytest.raises(InputError, match=r"record\.noise\.heading_bias_deg"):
        check_summary_file(folder)


def test_one_line_keeps_the_slippery_word_when_unknown():
    summary = pd.DataFrame(
        [
            {
                "axle": "rear", "n": 40, "observable": False, "mu": np.nan, "mu_low": 0.31,
                "mu_high": np.inf, "grip_used": 0.33, "grip_used_lower": 0.31,
                "surface": "undetermined", "slippery": "unknown", "limited_by": "no upper end",
            }
        ]
    )  # fmt: skip
    line = AxleFriction(wheels=pd.DataFrame(), summary=summary).explain()
    assert "slippery: unknown" in line, line


def test_per_condition_mu_is_labelled_and_no_empty_figure_beside_a_value(tmp_path):
    # the demo's MF-tyre wet circle (RTK): the front axle's value combines all windows of the
    # drive; a condition's own windows have another median — shown only with its own label
    from gripsense import FrictionRun

    run = FrictionRun(DEMO / "vehicle_PacejkaBook_Defaults.toml", receiver="rtk")
    res = run.run_log(DEMO / "case024.nmea.gz", steer_csv=DEMO / "case024_steer.csv")
    assert res.summary.set_index("axle").loc["front", "observable"]
    ct = res.condition_table()
    assert ct["mu"].notna().any()
    page = render_report(res)
    head = re.search(r"Steady conditions</h2>.*?<table><tr>(.*?)</tr>", page, re.S).group(1)
    cols = [H.unescape(c) for c in re.findall(r"<th[^>]*>(.*?)</th>", head)]
    assert "mu" not in cols and "μ, window estimates (median)" in cols, cols
    assert "their 90 % low (median)" in cols and "their 90 % high (median)" in cols, cols
    assert "each 3 s window alone" in H.unescape(page)
    # a condition's panel (d) shows its windows' values, labelled, not "μ not observable"
    row = ct.dropna(subset=["mu"]).iloc[0]
    fig = F.condition_figure(res.wheels, row["t_start"], row["t_end"], windows=res.windows)
    (d,) = [a for a in fig.axes if a.get_title(loc="left") == "(d)"]
    legend = d.get_legend()
    assert legend is not None
    assert any("a window's value" in t.get_text() for t in legend.get_texts())
    assert not any("not observable" in t.get_text() for t in d.texts)
    # far from the limit: no window value in any condition — no empty μ-vs-radius figure
    res, epochs = _result(method="axle-window", mu=0.9, util=0.2)
    assert res.condition_table()["mu"].isna().all()
    page = render_report(res, epochs=epochs)
    assert 'alt="mu vs radius"' not in page and 'alt="mu vs yaw rate"' not in page
    assert "not drawn" in page


def test_trajectory_has_a_legend_and_more_than_one_colour():
    res, epochs = _result(method="brush-2")
    conds = res.conditions()
    assert len(conds) == 1
    fig = F.trajectory(epochs, conds)
    ax = fig.axes[0]
    legend = ax.get_legend()
    assert legend is not None
    labels = [t.get_text() for t in legend.get_texts()]
    assert any(lab.startswith("condition 1") for lab in labels), labels
    drawn = {
        mcolors.to_hex(ln.get_color())
        for ln in ax.get_lines()
        if np.isfinite(np.asarray(ln.get_xdata(), float)).any()
    }
    assert len(drawn) >= 2, drawn


def test_old_folder_without_record_states_no_default_priors(calibrated_run, tmp_path):
    """A folder of an earlier version records no priors: the report says so instead of
    stating defaults the run may not have used."""
    import shutil

    out, _, _ = calibrated_run
    old = tmp_path / "old"
    shutil.copytree(out, old)
    doc = json.loads((old / "summary.json").read_text())
    del doc["record"]
    (old / "summary.json").write_text(json.dumps(doc))
    from gripsense.estimate.results import read_result
    from gripsense.io.output_folder import read_manifest

    man = read_manifest(old)
    man.get("sha256", {}).pop("summary.json", None)
    (old / "manifest.json").write_text(json.dumps(man))
    page = _text(render_report(read_result(old)))
    assert "±0.60°" not in page and "±20%" not in page
    assert "not recorded" in page


def test_trajectory_without_conditions_says_so():
    _, epochs = _result(method="brush-2")
    fig = F.trajectory(epochs, [])
    assert "no steady condition" in fig.axes[0].get_title()


def test_console_report_and_explain_say_an_upper_end_alike(calibrated_run):
    """An axle without a value but with an upper end: the console, the report and explain()
    state the same upper end, and none pairs it with a lower end as if it were a range."""
    out, again, stdout = calibrated_run
    doc = json.loads((out / "summary.json").read_text())
    page = _text(again.read_text(encoding="utf-8"))
    checked = 0
    for r in doc["axles"]:
        hi, lo = r["mu_high"], r["mu_low"]
        if r["observable"] or hi is None or not hi > r["grip_used_lower"]:
            continue
        checked += 1
        assert f"≤ {hi:.2f} (upper end only)" in stdout, stdout
        assert f"no value — μ ≤ {hi:.2f} (upper end only)" in page
        assert f"estimate μ ≤ {hi:.2f} (90 %)" in doc["explain"]
        assert f"{lo:.2f} – {hi:.2f}" not in stdout
    assert checked, doc["axles"]


def test_python_api_names_the_vehicle_files_calibration(tmp_path):
    """FrictionRun applies the calibration a vehicle file names: the result's record names it
    too (and not when another calibration was given instead)."""
    from gripsense import FrictionRun
    from gripsense.estimate.results import stiffness_lines

    (tmp_path / "car.calibration.toml").write_text(CALIBRATION)
    other = tmp_path / "other.calibration.toml"
    other.write_text(CALIBRATION.replace(f"= {C_REAR_LEARNED}", "= 60000.0"))
    veh = tmp_path / "car.toml"
    veh.write_text(
        VEHICLE.read_text(encoding="utf-8") + '\n[calibration]\nfile = "car.calibration.toml"\n'
    )
    log, steer = DEMO / "case002.nmea.gz", DEMO / "case002_steer.csv"
    res = FrictionRun(veh, receiver="rtk").run_log(log, steer_csv=steer)
    rec = res.record()
    assert rec["calibration"]["file"] == "car.calibration.toml"
    assert rec["calibration"]["learned"]["rear"] == [C_REAR_LEARNED, U_REAR_LEARNED]
    assert any("learned (calibration)" in line for line in stiffness_lines(rec))
    res = FrictionRun(veh, receiver="rtk", calibration=other).run_log(log, steer_csv=steer)
    rec = res.record()
    assert "calibration" not in rec
    assert any("did not record" in line for line in stiffness_lines(rec))
