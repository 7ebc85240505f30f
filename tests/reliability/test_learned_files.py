"""A learned file is always usable (issue 40, item 6): ``calibrate`` writes only what
``friction --calibration`` and ``calibrate --update`` read back — a value outside the reader's
limits is left out with the reason (the drives' sums are kept) — and every part the writer
learns is checked against every limit of the reader."""

from __future__ import annotations

import gzip
import tomllib

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from typer.testing import CliRunner

from gripsense.cli import app
from gripsense.config.calibration import (
    AXLE_LIMITS,
    STEERING_LIMITS,
    AxleCalibration,
    Calibration,
    DriveSums,
    SteeringCalibration,
    calibration_toml,
    parse_calibration,
    read_calibration,
)
from gripsense.errors import InputError
from gripsense.sim import maneuvers as M
from gripsense.sim.drives import simulate_drive, truth_tyre, truth_vehicle, user_vehicle_toml

RUNNER = CliRunner()


def invoke(*args, code: int = 0) -> str:
    r = RUNNER.invoke(app, [str(a) for a in args])
    assert r.exit_code == code, (r.output, r.exception)
    assert "Traceback" not in r.output
    return r.output


@pytest.fixture(scope="module")
def slalom(tmp_path_factory):
    """A short low-amplitude slalom at 40 km/h with a V100-class compass: the linear-range fit
    of both axles is known to ±1000 % or worse (the issue's 791.1 is this class)."""
    folder = tmp_path_factory.mktemp("slalom")
    drive = simulate_drive(
        "sedan", "mf-sedan", M.slalom(40 / 3.6, amplitude_rad=np.deg2rad(1.0)), 0.9, seed=0
    )
    log = folder / "slalom.nmea.gz"
    with gzip.open(log, "wt", encoding="ascii") as fh:
        fh.write("\n".join(drive.lines) + "\n")
    steer = folder / "slalom_steer.csv"
    drive.steer.to_csv(steer, index=False)
    car = folder / "car.toml"
    car.write_text(
        user_vehicle_toml(truth_vehicle("sedan"), truth_tyre("mf-sedan"), stiffness_error=0.15),
        encoding="utf-8",
    )
    return folder, log, steer, car


def test_calibrate_on_a_slalom_writes_a_file_friction_reads(slalom):
    folder, log, steer, car = slalom
    out = folder / "car.calibration.toml"
    text = invoke("calibrate", log, "--vehicle", car, "--steer-csv", steer, "-o", out)
    assert "not learned" in text and "at most 100 %" in text, text
    cal = read_calibration(out)  # the reader friction and --update use
    for a in cal.axles.values():
        assert a.stiffness_uncertainty <= 1.0
    assert {d.axle for d in cal.drives} >= {"front", "rear"}  # the sums are kept
    assert "not learned" in out.read_text(encoding="utf-8")  # the file says why
    invoke("friction", log, "--vehicle", car, "--steer-csv", steer, "--calibration", out,
           "-o", folder / "res")  # fmt: skip
    # --update onto the same file: still readable, the drive counted once
    again = folder / "again.calibration.toml"
    invoke("calibrate", log, "--vehicle", car, "--steer-csv", steer, "--update", out, "-o", again)
    assert len(read_calibration(again).drives) == len(cal.drives)


def _cal(**axle) -> Calibration:
    a = dict(cornering_stiffness_N_per_rad=50_000.0, stiffness_uncertainty=0.1, scale=1.0, bins=9)
    a.update(axle)
    sums = DriveSums("d.nmea", "ab", "rear", 9, np.arange(7.0))
    return Calibration("car", {"rear": AxleCalibration(**a)}, [sums])


@pytest.mark.parametrize(
    ("key", "value"),
    [
        ("stiffness_uncertainty", 791.1),
        ("stiffness_uncertainty", np.inf),
        ("stiffness_uncertainty", np.nan),
        ("stiffness_uncertainty", 1.00004),  # written as 1.0000: readable, so kept
        ("cornering_stiffness_N_per_rad", 484.0),
        ("cornering_stiffness_N_per_rad", 2e6),
        ("scale", 0.009),
        ("scale", 25.0),
        ("bins", 0),
    ],
)
def test_every_axle_value_outside_the_readers_limits_is_left_out(key, value):
    text = calibration_toml(_cal(**{key: value}))
    back = parse_calibration(text)
    lo, hi, _ = AXLE_LIMITS[key]
    written = float(format(value, ".4f")) if np.isfinite(value) else value
    if np.isfinite(written) and lo <= written <= hi:
        assert "rear" in back.axles
    else:
        assert "rear" not in back.axles and "rear axle not learned" in text
        assert len(back.drives) == 1  # the drive's sums stay for a later --update


@pytest.mark.parametrize(
    ("key", "value"), [("lever_m", 0.9), ("lever_m", 1e-4), ("lever_uncertainty", 3.0)]
)
def test_a_steering_lever_outside_the_readers_limits_is_left_out(key, value):
    st_ = dict(lever_m=0.04, lever_uncertainty=0.05, bins=20)
    st_[key] = value
    cal = Calibration("car", {}, [], steering=SteeringCalibration(**st_))
    text = calibration_toml(cal)
    assert parse_calibration(text).steering is None and "steering lever not learned" in text


def test_drives_with_non_finite_sums_are_not_written():
    d = DriveSums("d.nmea", "ab", "rear", 9, np.array([1, 2, np.nan, 4, 5, 6, 7.0]))
    text = calibration_toml(Calibration("car", {}, [d]))
    assert parse_calibration(text).drives == [] and "not finite" in text


@settings(max_examples=150, deadline=None)
@given(
    name=st.text(min_size=1, max_size=30),
    file=st.text(max_size=30),
    c=st.floats(allow_nan=True, allow_infinity=True),
    u=st.floats(allow_nan=True, allow_infinity=True),
    s=st.floats(allow_nan=True, allow_infinity=True),
    lever=st.floats(allow_nan=True, allow_infinity=True),
    sums=st.lists(st.floats(allow_nan=True, allow_infinity=True), min_size=7, max_size=7),
)
def test_whatever_is_learned_the_file_reads_back(name, file, c, u, s, lever, sums):
    """Any learned numbers, any vehicle or file name (control characters, quotes,
    backslashes, undecodable bytes): the text the writer returns is valid TOML that the
    reader accepts, with the vehicle's name unchanged."""
    cal = Calibration(
        name,
        {"front": AxleCalibration(c, u, s, 12)},
        [DriveSums(file + "\udcff", "00", "front", 12, np.asarray(sums))],
        steering=SteeringCalibration(lever, 0.05, 12),
    )
    text = calibration_toml(cal)
    tomllib.loads(text)
    back = parse_calibration(text)
    assert back.vehicle == name
    for key, (lo, hi, _) in AXLE_LIMITS.items():
        for a in back.axles.values():
            assert lo <= getattr(a, key) <= hi
    for key, (lo, hi, _) in STEERING_LIMITS.items():
        if back.steering is not None:
            assert lo <= getattr(back.steering, key) <= hi


@pytest.mark.parametrize(
    ("body", "word"),
    [
        ('[[calibration.drive]]\naxle = "rear"\nbins = "x"\nsums = [1,2,3,4,5,6,7]\n', "bins"),
        ('[[calibration.drive]]\naxle = "rear"\nsums = [1,2,3,4,5,6,nan]\n', "finite"),
        ('[[calibration.drive]]\naxle = "rear"\nsums = [1,2,3,4,5,6,"a"]\n', "finite"),
        ("[calibration]\nrear = 3\n", "table"),
        ("drive = 3\n", "drive"),
    ],
)
def test_a_hand_edited_calibration_is_one_line(slalom, tmp_path, body, word):
    """Hand-edited values the reader cannot use: one line naming the file and key, exit 2."""
    _, log, _, car = slalom
    from gripsense.config import Vehicle

    name = Vehicle.from_toml(car).name
    bad = tmp_path / "bad.calibration.toml"
    head = f'[calibration]\nvehicle = "{name}"\n'
    bad.write_text(head + "\n" + body if not body.startswith("[calibration]") else
                   body.replace("[calibration]\n", head), encoding="utf-8")  # fmt: skip
    if body.startswith("drive"):
        bad.write_text(head + body, encoding="utf-8")
    out = invoke("friction", log, "--vehicle", car, "--calibration", bad, "-o", tmp_path / "r",
                 code=2)  # fmt: skip
    assert "bad.calibration.toml" in out and word in out, out
    with pytest.raises(InputError):
        read_calibration(bad)


# ---- tyre fit: the file it writes is one tyre eval and a vehicle's tyre_file read ----------


@pytest.fixture(scope="module")
def road_csv(tmp_path_factory):
    """Cornering samples of the PAC94 example tyre (seed 002's coefficients)."""
    import pandas as pd

    from gripsense.physics.magic_formula.pac94 import pac94_lateral
    from gripsense.sim.tyre_data import PAC94_EXAMPLE, cornering_samples

    d = cornering_samples(
        lambda fz, a, g: pac94_lateral(PAC94_EXAMPLE, fz, a, g), 600, rng=np.random.default_rng(1)
    )
    path = tmp_path_factory.mktemp("tyre") / "road.csv"
    pd.DataFrame(
        {
            "alpha_deg": np.rad2deg(d.alpha_rad),
            "gamma_deg": np.rad2deg(d.gamma_rad),
            "fz_N": d.fz_N,
            "fy_N": d.fy_N,
        }
    ).to_csv(path, index=False)
    return path


@pytest.mark.parametrize(
    ("args", "words"),
    [
        (["-o", "{d}/fit.txt"], ("fit.txt", ".json")),  # JSON under a name no reader knows
        (["-o", "{d}/fit.csv"], ("fit.csv", ".json")),
        (["--model", "mf61", "--fnomin", "-4000", "-o", "{d}/fit.tir"], ("--fnomin",)),
        (["--model", "mf61", "--fnomin", "1e-300", "-o", "{d}/fit.tir"], ("--fnomin",)),
    ],
)
def test_tyre_fit_never_writes_a_file_tyre_eval_refuses(road_csv, tmp_path, args, words):
    out = invoke("tyre", "fit", road_csv, *[a.replace("{d}", str(tmp_path)) for a in args],
                 code=2)  # fmt: skip
    lines = [ln for ln in out.splitlines() if ln.startswith("error:")]
    assert len(lines) == 1 and all(w in lines[0] for w in words), out
    assert "internal error" not in out and list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("name", ["fit.json", "fit.tir"])
def test_what_tyre_fit_writes_tyre_eval_reads(road_csv, tmp_path, name):
    out = tmp_path / name
    model = ["--model", "mf61"] if name.endswith(".tir") else []
    invoke("tyre", "fit", road_csv, *model, "-o", out)
    text = invoke("tyre", "eval", out, "--fz", "4000", "--alpha-deg", "-4,4")
    assert "4000" in text
