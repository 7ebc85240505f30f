"""Plausibility at the door (issue 40, item 5): numbers on the command line are finite, sensor
values are finite and plausible for the unit their column declares, and a steering channel
that never overlaps the log is one line, not a front axle dropped without a word."""

from __future__ import annotations

import subprocess
import typing

import pytest
import typer.main
from typer.testing import CliRunner

from gripsense.cli import app
from tests.cli.test_commands import EXE
from tests.io.simulated import simulate

RUNNER = CliRunner()


@pytest.fixture(scope="session")
def simulated(tmp_path_factory):
    """``simulated(fmt)``: real files of ``gripsense simulate`` (tests/io/simulated.py)."""
    base = tmp_path_factory.getbasetemp() / "simulated"
    return lambda fmt="nmea": simulate(base, fmt)


def _float_options() -> list[tuple[tuple[str, ...], str]]:
    """(command path, option) of every option of every command whose value is a number that
    is not an integer (a new option is found without being listed here)."""
    out = []

    def walk(cmd, path):
        for name, sub in getattr(cmd, "commands", {}).items():
            walk(sub, (*path, name))
        for p in getattr(cmd, "params", []):
            ann = getattr(getattr(p, "type_descriptor", None), "annotation", None)
            args = typing.get_args(ann) or (ann,)
            if float in args and p.opts and p.opts[0].startswith("-"):
                out.append((path, max(p.opts, key=len)))

    walk(typer.main.get_command(app), ())
    return out


FLOAT_OPTIONS = _float_options()


def test_the_walk_finds_the_options():
    found = {(" ".join(c), o) for c, o in FLOAT_OPTIONS}
    assert ("camber", "--spacing-m") in found and ("live", "--window-s") in found
    assert ("steering identify", "--yaw-gain") in found
    assert len(found) >= 15


@pytest.mark.parametrize(("command", "option"), FLOAT_OPTIONS, ids=lambda x: str(x))
@pytest.mark.parametrize("value", ["nan", "-inf", "Infinity"])
def test_no_numeric_option_takes_nan_or_inf(command, option, value):
    r = RUNNER.invoke(app, [*command, option, value])
    assert r.exit_code == 2, r.output
    assert option in r.output and "finite" in r.output and "Traceback" not in r.output


@pytest.mark.parametrize(
    ("args", "option"),
    [
        (["tyre", "eval", "{tir}", "--fz", "nan"], "--fz"),
        (["tyre", "eval", "{tir}", "--fz", "4000", "--alpha-deg", "-5:inf:1"], "--alpha-deg"),
        (["tyre", "eval", "{tir}", "--fz", "4000", "--gamma-deg", "0,nan"], "--gamma-deg"),
        (["tyre", "eval", "{tir}", "--fz", "4000", "--kappa", "-inf"], "--kappa"),
    ],
)
def test_numbers_in_a_list_option_are_finite(tmp_path, args, option):
    """``tyre eval --fz nan`` wrote NaN rows with exit 0: the real command, in a process."""
    from importlib.resources import files

    tir = files("gripsense.data") / "tyres" / "PacejkaBook_Defaults.tir"
    out = tmp_path / "eval.csv"
    cmd = [a.replace("{tir}", str(tir)) for a in args] + ["-o", str(out)]
    r = subprocess.run([EXE, *cmd], capture_output=True, text=True, check=False)
    assert r.returncode == 2, r.stdout + r.stderr
    assert option in r.stderr and "finite" in r.stderr and len(r.stderr.splitlines()) == 1
    assert not out.exists()


# ---- sensor values: plausible for their declared unit, finite -------------------------------


def _cli(*args, code: int = 0) -> str:
    r = RUNNER.invoke(app, [str(a) for a in args])
    assert r.exit_code == code, (r.output, r.exception)
    assert "Traceback" not in r.output
    return r.output


def _one_error_line(out: str, *words: str) -> None:
    lines = [ln for ln in out.splitlines() if ln.startswith("error:")]
    assert len(lines) == 1, out
    for w in words:
        assert w in lines[0], (w, lines[0])


def test_degrees_declared_as_radians_in_a_steering_csv(simulated, tmp_path):
    """The issue's example: road-wheel angles up to 10.9 "rad" gave exit 0."""
    sim = simulated("nmea")
    out = _cli("friction", sim.log, "--vehicle", sim.vehicle, "--steer-csv", sim.steer,
               "--steer-columns", "t=t_s,road_wheel=road_wheel_deg:rad", "-o", tmp_path / "r",
               code=2)  # fmt: skip
    _one_error_line(
        out, sim.steer.name, "line ", "'road_wheel_deg'", "road_wheel=road_wheel_deg:deg"
    )
    assert not (tmp_path / "r").exists()


@pytest.mark.parametrize(
    ("header", "values", "columns", "fix"),
    [
        ("road_wheel_deg", [1.0, 5.0, 30.0], "t=t_s,road_wheel=road_wheel_deg:rad", ":deg"),
        ("swa_deg", [10.0, 90.0, 400.0], "t=t_s,steering_wheel=swa_deg:rad", ":deg"),
        ("road_wheel_rad", [0.01, 0.02, 0.03], "t=t_s,road_wheel=road_wheel_rad,torque=trq:Nm",
         "torque"),
        ("road_wheel_rad", [0.01, 0.02, 0.03], "t=t_s,road_wheel=road_wheel_rad,rack=rk:kN",
         "rack=rk:N"),
    ],
)  # fmt: skip
def test_every_steering_channel_is_plausible_for_its_unit(tmp_path, header, values, columns, fix):
    from gripsense.errors import InputError
    from gripsense.io.sensors.steer import read_steer_csv

    p = tmp_path / "steer.csv"
    rows = [
        f"{0.1 * i:.1f},{v},{3000.0 * (i + 1)},{4000.0 * (i + 1)}" for i, v in enumerate(values)
    ]
    p.write_text(f"t_s,{header},trq,rk\n" + "\n".join(rows) + "\n", encoding="utf-8")
    with pytest.raises(InputError, match=r"steer\.csv: line \d") as e:
        read_steer_csv(p, steering_ratio=16.0, columns=columns)
    assert fix in str(e.value) and "\n" not in str(e.value)


def test_a_steering_wheel_angle_over_a_wrong_ratio_is_refused(tmp_path):
    from gripsense.errors import InputError
    from gripsense.io.sensors.steer import read_steer_csv

    p = tmp_path / "steer.csv"
    p.write_text("t_s,steering_wheel_deg\n0,10\n0.1,300\n", encoding="utf-8")
    with pytest.raises(InputError, match="steering_ratio"):
        read_steer_csv(p, steering_ratio=1.6)
    assert len(read_steer_csv(p, steering_ratio=16.0)) == 2


@pytest.mark.parametrize(
    ("text", "columns", "words"),
    [
        ("t_s,ax_g,az_g\n0,0.1,9.81\n0.1,0.2,9.79\n0.2,0.3,9.8\n", None, ("az_g", "mps2")),
        ("t_s,ax_mps2\n0,0.1\n0.1,200\n", None, ("line 3", "ax_mps2")),
    ],
)
def test_accelerations_are_plausible_for_their_unit(tmp_path, text, columns, words):
    """m/s² declared as g (gravity read as 9.81 g); a sample beyond a sensor's ±16 g."""
    p = tmp_path / "acc.csv"
    p.write_text(text, encoding="utf-8")
    out = _cli("brake-mu", p, code=2)
    _one_error_line(out, "acc.csv", *words)


def test_a_motion_table_in_the_wrong_units(tmp_path):
    p = tmp_path / "motion.csv"
    p.write_text(
        "time_s,speed_mps,slip_deg,yaw_rate_rps\n0,20,0.5,20\n0.1,20,0.5,25\n", encoding="utf-8"
    )
    from gripsense.errors import InputError
    from gripsense.io.sensors.motion import read_motion_table

    with pytest.raises(InputError, match=r"yaw_rate_rps.*yaw_rate=yaw_rate_rps:dps"):
        read_motion_table(p)
    p.write_text("time_s,speed_mps,slip_deg,yaw_rate_dps\n0,20,inf,20\n", encoding="utf-8")
    with pytest.raises(InputError, match=r"line 2, column 'slip_deg'.*not a finite number"):
        read_motion_table(p)


def test_a_log_channel_in_degrees_mapped_as_radians(simulated):
    from gripsense.errors import InputError
    from gripsense.io.logs import read_log

    sim = simulated("vbo")
    with pytest.raises(InputError, match=r"RoadWheelAngle.*steer=RoadWheelAngle:deg"):
        read_log(sim.log, columns="steer=RoadWheelAngle:rad")
    read_log(sim.log, columns="steer=RoadWheelAngle:deg")


def test_an_inf_laser_distance_is_rejected_and_counted_not_a_90_degree_camber(tmp_path):
    p = tmp_path / "laser.csv"
    rows = [f"{0.01 * i:.2f},{250 + 0.1 * i:.1f},251" for i in range(100)]
    rows[40] = "0.40,inf,251"
    rows[70] = "0.70,252,-inf"
    p.write_text("t_s,d_outer_mm,d_inner_mm\n" + "\n".join(rows) + "\n", encoding="utf-8")
    out_csv = tmp_path / "camber.csv"
    out = _cli("camber", p, "--spacing-m", "0.3", "-o", out_csv)
    assert "2 of 100 rows" in out and "not a finite number" in out and "line 42" in out, out
    import pandas as pd

    c = pd.read_csv(out_csv, comment="#")
    assert len(c) == 98 and c["camber_deg"].abs().max() < 5


def test_camber_of_non_finite_distances_is_nan():
    import numpy as np

    from gripsense.vision import camber_from_lasers

    g = camber_from_lasers(np.array([0.25, np.inf, 0.25]), np.array([0.25, 0.25, -np.inf]), 0.3)
    assert g[0] == 0 and np.isnan(g[1]) and np.isnan(g[2])


def test_an_inf_in_a_steering_csv_is_counted(simulated, tmp_path):
    sim = simulated("nmea")
    lines = sim.steer.read_text(encoding="utf-8").splitlines()
    head = lines[0].split(",")
    i = next(k for k, ln in enumerate(lines[1:], 1) if ln.split(",")[1])  # a row with an angle
    cells = lines[i].split(",")
    cells[1] = "inf"
    lines[i] = ",".join(cells)
    p = tmp_path / "steer_inf.csv"
    p.write_text("\n".join(lines) + "\n", encoding="utf-8")
    from gripsense.io.sensors.steer import read_steer_csv

    ch = read_steer_csv(p)
    assert ch.attrs["rows"]["rows_not_finite"] == 1 and f"line {i + 1}" in ch.attrs["rows"]["note"]
    assert head[1] in ch.attrs["rows"]["note"] and np_isfinite_all(ch["steer_rad"])


def np_isfinite_all(s) -> bool:
    import numpy as np

    v = s.to_numpy(float)
    return bool(np.isfinite(v[~np.isnan(v)]).all())


# ---- a steering channel that does not cover the log -----------------------------------------


def _shifted_steer(src, dst, shift_s: float, keep: float = 1.0) -> None:
    import pandas as pd

    df = pd.read_csv(src, comment="#")
    df["t_s"] = df["t_s"] + shift_s
    df.iloc[: int(len(df) * keep)].to_csv(dst, index=False)


def test_a_steering_csv_that_never_overlaps_the_log_is_one_line(simulated, tmp_path):
    """It dropped the front axle without a word; now one line naming both time spans and the
    shift that aligns them, exit 2, nothing written — for friction and calibrate alike."""
    sim = simulated("nmea")
    p = tmp_path / "steer_clock.csv"
    _shifted_steer(sim.steer, p, 43_200.0)  # seconds of the day against seconds from the start
    out = _cli("friction", sim.log, "--vehicle", sim.vehicle, "--steer-csv", p, "-o",
               tmp_path / "r", code=2)  # fmt: skip
    _one_error_line(out, "steer_clock.csv", "never overlaps", "43200", "-43200 s")
    assert not (tmp_path / "r").exists()
    out = _cli("calibrate", sim.log, "--vehicle", sim.vehicle, "--steer-csv", p, "-o",
               tmp_path / "c.toml", code=2)  # fmt: skip
    _one_error_line(out, "steer_clock.csv", "never overlaps")


def test_a_steering_csv_that_covers_part_of_the_log_gives_a_note(simulated, tmp_path):
    sim = simulated("nmea")
    p = tmp_path / "steer_part.csv"
    _shifted_steer(sim.steer, p, 0.0, keep=0.5)
    out = _cli("friction", sim.log, "--vehicle", sim.vehicle, "--steer-csv", p, "-o",
               tmp_path / "r")  # fmt: skip
    assert "steer_part.csv covers" in out and "% of the log's epochs" in out, out
    full = _cli("friction", sim.log, "--vehicle", sim.vehicle, "--steer-csv", sim.steer, "-o",
                tmp_path / "r2")  # fmt: skip
    assert "covers" not in full


@pytest.mark.parametrize(
    ("args", "words"),
    [
        (["--spacing-m", "1e-300"], ("spacing", "0.005–5 m")),
        (["--spacing-m", "300"], ("spacing", "metres")),
        (["--spacing-m", "0.3", "--reference-deg", "1e308"], ("reference camber", "±30°")),
    ],
)
def test_camber_arguments_are_plausible(tmp_path, args, words):
    """A spacing of 1e-300 m gave a −90° camber with exit 0."""
    p = tmp_path / "laser.csv"
    p.write_text("t_s,d_outer_mm,d_inner_mm\n0,250,251\n0.01,250,251\n", encoding="utf-8")
    _one_error_line(_cli("camber", p, *args, code=2), *words)


@pytest.mark.parametrize(
    ("args", "words"),
    [(["--time-scale", "0"], ("--time-scale",)), (["--ax-sign", "0"], ("--ax-sign",))],
)
def test_brake_mu_arguments_are_plausible(tmp_path, args, words):
    p = tmp_path / "acc.csv"
    p.write_text("t_ms,ax_g\n0,0\n10,-0.8\n20,-0.8\n", encoding="utf-8")
    out = _cli("brake-mu", p, "--t-col", "t_ms", "--ax-col", "ax_g", "--ay-col", "", "--az-col",
               "", *args, code=2)  # fmt: skip
    _one_error_line(out, *words)


def test_a_log_channel_on_another_clock_is_one_line(tmp_path):
    """An MDF4 whose steering channel's times never meet the heading's: one line naming the
    channel and both spans (it vanished from every epoch without a word)."""
    from gripsense.errors import InputError
    from gripsense.io.logs import read_log
    from gripsense.io.logs.mdf import mdf_columns, write_mdf
    from tests.io.logs.test_measurement_logs import _epochs, _steer

    ep = _epochs()
    st_ = _steer(ep)
    st_["t_s"] += 5000.0
    write_mdf(ep, tmp_path / "m.mf4", steer=st_)
    with pytest.raises(InputError, match=r"'RoadWheelAngle' has values at 5000–5005\.9 s"):
        read_log(tmp_path / "m.mf4", columns=mdf_columns(steering=True))
    st_["t_s"] -= 5000.0
    write_mdf(ep, tmp_path / "ok.mf4", steer=st_)
    ok = read_log(tmp_path / "ok.mf4", columns=mdf_columns(steering=True))
    assert ok.epochs["steer_rad"].notna().sum() >= len(ep) - 1  # the same channel on the clock


def test_an_inf_in_a_tyre_table_is_counted_not_fitted(tmp_path):
    """A tyre table counts the rows it cannot use: an inf force is one of them (it was fitted)."""
    import numpy as np
    import pandas as pd

    from gripsense.physics.magic_formula.pac94 import pac94_lateral
    from gripsense.sim.tyre_data import PAC94_EXAMPLE, cornering_samples

    d = cornering_samples(
        lambda fz, a, g: pac94_lateral(PAC94_EXAMPLE, fz, a, g), 400, rng=np.random.default_rng(2)
    )
    df = pd.DataFrame(
        {"alpha_deg": np.rad2deg(d.alpha_rad), "gamma_deg": np.rad2deg(d.gamma_rad),
         "fz_N": d.fz_N, "fy_N": d.fy_N}
    )  # fmt: skip
    df.loc[7, "fy_N"] = np.inf
    p = tmp_path / "road.csv"
    df.to_csv(p, index=False)
    out = _cli("tyre", "fit", p)
    assert "399 of 400 rows used" in out and "fy_not_a_number 1" in out, out
