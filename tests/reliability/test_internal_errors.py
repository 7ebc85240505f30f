"""No internal error from inputs a user can give: time stamps that repeat (duplicated rows, a
time column coarser than the sampling), go back or are all one value are one input error naming
the file in every command that divides by a time step (``brake-mu``, ``steering identify``
release and step recordings, ``camera-slip --fps``); a hand-edited ``summary.json`` is one
line naming the key whose value has the wrong kind.

Command-line checks run the command in the test's process (``tests.cli.inprocess``: the
console script's entry point, its stdout, stderr and exit code), without a console
script's 2–4 s of imports per call, which none of these checks is about."""

from __future__ import annotations

import json
import re
import shutil
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import gripsense
from gripsense import InputError
from gripsense._arrays import sample_step
from gripsense.config import SteeringCar
from gripsense.constants import G0
from gripsense.estimate.results import read_result
from gripsense.physics.steering_system import simulate_release, simulate_step
from gripsense.report.html import render_report
from gripsense.report.summary_check import META_KINDS, check_summary_file
from gripsense.vision.slip_camera import slip_from_frames
from tests.cli.inprocess import cli
from tests.estimate.test_braking import trace

DATA = Path(gripsense.__file__).parent / "data"
STEERING = DATA / "of18_steering.toml"

# fault → what it does to a time column (in recorded order)
FAULTS = {
    "every row twice": lambda t: np.repeat(t, 2),
    "coarse stamps": lambda t: np.floor(t / 0.1) * 0.1,
    "one stamp": lambda t: np.zeros_like(t),
    "goes back": lambda t: np.concatenate([t[: t.size // 2], t[t.size // 2 :] - 0.5]),
}


def _faulty(df: pd.DataFrame, fault: str) -> pd.DataFrame:
    t = df["t_s"].to_numpy(float)
    if fault == "every row twice":
        return df.loc[df.index.repeat(2)].reset_index(drop=True)
    return df.assign(t_s=FAULTS[fault](t))


@settings(max_examples=60, deadline=None)
@given(
    st.lists(st.floats(1e-4, 10.0), min_size=2, max_size=50),
    st.integers(0, 49),
    st.sampled_from(["repeat", "back"]),
)
def test_sample_step_is_positive_or_an_input_error(steps, at, how):
    t = np.cumsum(steps)
    assert sample_step(t, source="x") > 0
    i = at % (t.size - 1) + 1
    bad = t.copy()
    bad[i] = bad[i - 1] if how == "repeat" else bad[i - 1] - 1.0
    with pytest.raises(InputError, match=r"x: .*(repeat|goes back)"):
        sample_step(bad, source="x")


def _one_line(r, *words: str) -> None:
    assert r.returncode == 2, (r.returncode, r.stderr)
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: "), r.stderr
    assert "internal error" not in r.stderr and "Traceback" not in r.stderr
    for w in words:
        assert w in r.stderr, r.stderr


@pytest.mark.slow
@pytest.mark.parametrize("fault", [f for f in FAULTS if f != "goes back"])  # the reader sorts
def test_brake_mu_with_bad_time_stamps_is_one_input_error(fault, tmp_path):
    tr = trace(0.7, seed=9)
    f = tmp_path / "acc.csv"
    _faulty(pd.DataFrame({"t_s": tr["t_s"], "ax_g": tr["ax"] / G0}), fault).to_csv(f, index=False)
    _one_line(cli("brake-mu", str(f)), "acc.csv", "repeat")


@pytest.fixture(scope="module")
def recordings(tmp_path_factory) -> dict[str, pd.DataFrame]:
    truth = SteeringCar.from_toml(STEERING).with_cs(70.0).with_ks(3500.0)
    r = simulate_release(truth, alpha0_rad=np.deg2rad(30) / 5, duration_s=4.0)
    t = np.concatenate([np.arange(-0.5, 0, 1e-3), r["t_s"]])
    a = np.rad2deg(np.concatenate([np.full(500, r["alpha_rad"][0]), r["alpha_rad"]])) * 5
    s = simulate_step(
        truth, steer_rate_rad_s=np.deg2rad(70) / 5, stop_rad=np.deg2rad(90) / 5, duration_s=5.0
    )
    return {
        "release": pd.DataFrame({"t_s": t, "steer_deg": a}),
        "step": pd.DataFrame(
            {
                "t_s": s["t_s"],
                "steer_deg": np.rad2deg(s["alpha_rad"]) * 5,
                "yaw_rate_dps": np.rad2deg(s["yaw_rate_rps"]),
            }
        ),
    }


@pytest.mark.slow
@pytest.mark.parametrize("kind", ["release", "step"])
@pytest.mark.parametrize("fault", FAULTS)
def test_steering_identify_with_bad_time_stamps_is_one_input_error(
    kind, fault, recordings, tmp_path
):
    good = tmp_path / "release_ok.csv"
    recordings["release"].to_csv(good, index=False)
    bad = tmp_path / f"{kind}_bad.csv"
    _faulty(recordings[kind], fault).to_csv(bad, index=False)
    extra = ["--release", str(bad)] if kind == "release" else ["--release", str(good),
                                                               "--step", str(bad)]  # fmt: skip
    r = cli("steering", "identify", str(STEERING), *extra)
    _one_line(r, bad.name, "goes back" if fault == "goes back" else "repeat")


@pytest.mark.parametrize("fps", [0.0, -25.0, float("nan"), float("inf")])
def test_camera_slip_needs_a_frame_rate(fps):
    frames = [np.zeros((64, 64), np.uint8)] * 2
    with pytest.raises(InputError, match="fps"):
        slip_from_frames(frames, fps=fps)


# ------------------------------------------------------------------ summary.json
@pytest.fixture(scope="module")
def results(tmp_path_factory) -> dict[str, Path]:
    d = tmp_path_factory.mktemp("summaries")
    out = {}
    for method in ("axle-window", "brush-2"):
        log, veh = DATA / "demo" / "case021.nmea.gz", DATA / "corolla_sim.toml"
        args = ["--vehicle", str(veh), "--method", method, "-o", str(d / method)]
        r = cli("friction", str(log), *args)
        assert r.returncode == 0, r.stderr
        out[method] = d / method
    return out


def _keys(folder: Path) -> list[tuple[str, str]]:
    doc = json.loads((folder / "summary.json").read_text())
    rows = "axles" if "axles" in doc else "wheels"
    return [("meta", k) for k in doc["meta"]] + [(rows, k) for k in doc[rows][0]]


def _edited(src: Path, dst: Path, where: str, key: str, value) -> Path:
    shutil.copytree(src, dst)
    doc = json.loads((dst / "summary.json").read_text())
    if where == "meta":
        doc["meta"][key] = value
    else:
        doc[where][0][key] = value
    (dst / "summary.json").write_text(json.dumps(doc))
    return dst


@pytest.mark.slow
@pytest.mark.parametrize("method", ["axle-window", "brush-2"])
def test_every_key_of_a_hand_edited_summary_is_checked(method, results, tmp_path):
    """A value of the wrong kind under any key the file holds: one InputError naming it."""
    src = results[method]
    for n, (where, key) in enumerate(_keys(src)):
        folder = _edited(src, tmp_path / f"e{n}", where, key, {"edited": 1})
        name = f"meta.{key}" if where == "meta" else f"{where}[0].{key}"
        if where != "meta" or key in META_KINDS:  # a row holds single values only
            with pytest.raises(InputError, match=re.escape(f"summary.json: {name} is")):
                check_summary_file(folder)  # as written on disk (the reader coerces numbers)
        try:  # what the reader makes of it: the report's own check or a page, nothing else
            check_summary_file(folder)
            render_report(read_result(folder))
        except InputError:
            pass


@pytest.mark.slow
@pytest.mark.parametrize(
    ("where", "key", "value"),
    [
        ("meta", "heading_offset_deg", "1.39"),
        ("meta", "method", "axle-widow"),
        ("meta", "epochs_total", 12.5),
        ("axles", "n_windows", "x"),
        ("axles", "observable", "yes"),
        ("axles", "surface", 3),
    ],
)
def test_report_on_a_hand_edited_summary_is_one_line(where, key, value, results, tmp_path):
    folder = _edited(results["axle-window"], tmp_path / "res", where, key, value)
    r = cli("report", str(folder), "-o", str(tmp_path / "r.html"))
    _one_line(r, "summary.json", key)
    assert not (tmp_path / "r.html").exists()
