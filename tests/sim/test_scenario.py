"""Scenario files (``gripsense simulate``) do what docs/simulation.md says (issue 45: a documented
manoeuvre the reader refused, keys documented nowhere, a circle no tyre can drive simulated
without a word, two slaloms under one name)."""

from __future__ import annotations

import re
import shutil
import subprocess
import sys
import warnings
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from gripsense.config import Vehicle
from gripsense.errors import InputError
from gripsense.sim import maneuvers as M
from gripsense.sim.scenario import DEMAND_LIMIT, MANEUVER_KEYS, demand_warning, run_scenario

ROOT = Path(__file__).resolve().parents[2]
DOC = (ROOT / "docs" / "simulation.md").read_text(encoding="utf-8")
EXE = shutil.which("gripsense") or str(Path(sys.executable).with_name("gripsense"))


def _scenario(tmp_path: Path, cases: str, head: str = "") -> Path:
    sc = tmp_path / "sc.toml"
    sc.write_text(
        f'[scenario]\nvehicle = "corolla_sim.toml"\n{head}\n[gnss]\nnoise = "none"\n{cases}',
        encoding="utf-8",
    )
    return sc


def _doc_row(kind: str) -> str:
    rows = [x for x in DOC.splitlines() if re.match(rf"\| `{kind}\(", x)]
    assert len(rows) == 1, f"docs/simulation.md: no (or several) table rows for {kind}"
    return rows[0]


@pytest.mark.parametrize("kind", sorted(MANEUVER_KEYS))
def test_every_manoeuvre_and_its_keys_are_documented(kind):
    row = _doc_row(kind)
    assert f'maneuver = "{kind}"' in row, f"{kind}: the row does not name its scenario value"
    for key in MANEUVER_KEYS[kind]:
        assert f"`{key}`" in row, f"docs/simulation.md: {kind}'s key {key} is documented nowhere"


def test_every_documented_builder_a_scenario_names_is_accepted():
    """The table's builders with a scenario form are exactly the reader's manoeuvres."""
    documented = set(re.findall(r'maneuver = "(\w+)"', DOC))
    assert documented == set(MANEUVER_KEYS)


def test_everyday_and_ramp_steer_keys_simulate(tmp_path):
    sc = _scenario(
        tmp_path,
        """
[[case]]
maneuver = "everyday"
speed_kmh = 40
seed = 3
curves = 2
hold_s = 3
max_steer_deg = 1.5
lead_s = 4
[[case]]
maneuver = "ramp_steer"
speed_kmh = 40
rate_deg_s = 4
max_steer_deg = 6
hold_s = 2
""",
    )
    cases = run_scenario(sc, tmp_path / "out")
    assert list(cases["maneuver"]) == ["everyday", "ramp_steer"]
    # everyday: 4 s straight, then 2 curves of 2 s entry + 3 s hold, then 2 s out
    assert cases["sim_s"].iloc[0] == pytest.approx(4 + 2 * (2 + 3) + 2, abs=0.02)
    # ramp steer: 2 s straight, then 6° at 4°/s
    assert cases["sim_s"].iloc[1] == pytest.approx(2 + 6 / 4, abs=0.02)
    truth = pd.read_parquet(tmp_path / "out" / cases["truth"].iloc[1])
    assert (cases["warning"].fillna("") == "").all()
    assert np.abs(truth["slip_angle_rad"]).max() > 0  # it steered


@pytest.mark.parametrize(
    "case,message",
    [
        ('maneuver = "everyday"\nspeed_kmh = 40\ncurves = 1.5', "curves = 1.5 must be a whole"),
        ('maneuver = "circle"\nspeed_kmh = 0\nradius_m = 20', "speed_kmh = 0 must be > 0"),
        ('maneuver = "ramp_steer"\nspeed_kmh = 40\nwheel = 3', "unknown key 'wheel'"),
    ],
)
def test_bad_keys_are_one_line_naming_the_key(tmp_path, case, message):
    sc = _scenario(tmp_path, f"[[case]]\n{case}\n")
    with pytest.raises(InputError, match=re.escape(message)):
        run_scenario(sc, tmp_path / "out")


def test_names_tell_cases_apart():
    """Two slaloms (or ramp steers) of different amplitude got the same name."""
    a = M.slalom(20.0, amplitude_rad=np.deg2rad(2.0))
    b = M.slalom(20.0, amplitude_rad=np.deg2rad(4.0))
    c = M.slalom(20.0, amplitude_rad=np.deg2rad(4.0), period_s=2.0)
    assert len({a.name, b.name, c.name}) == 3
    r1 = M.ramp_steer(20.0, rate_rad_s=np.deg2rad(1.0))
    r2 = M.ramp_steer(20.0, rate_rad_s=np.deg2rad(2.0))
    assert r1.name != r2.name
    e1, e2 = M.everyday(20.0, seed=1), M.everyday(20.0, seed=2)
    assert e1.name != e2.name
    assert "2.0" in a.name and "4.0" in b.name  # the amplitude in degrees, as given


def test_demand_warning_closed_form():
    """v²/R against μ g: 300 km/h on R 20 m asks for (83.3 m/s)²/20 m = 347 m/s² = 35 g."""
    far = M.circle(300 / 3.6, 20.0, laps=1)
    msg = demand_warning(far, 0.9)
    assert msg is not None and "35 g" in msg
    # the demo's hardest circle, 50 km/h on R 20 m: 0.98 g on μ 0.9 (1.09 μ g) is driven
    assert demand_warning(M.circle(50 / 3.6, 20.0), 0.9) is None
    v = np.sqrt(DEMAND_LIMIT * 0.5 * 9.80665 * 30.0)  # just past the limit on μ 0.5, R 30 m
    assert demand_warning(M.circle(v * 1.01, 30.0), 0.5) is not None
    assert demand_warning(M.circle(v * 0.99, 30.0), 0.5) is None
    sweep = M.constant_radius(30.0, 30 / 3.6, 120 / 3.6)
    assert demand_warning(sweep, 0.9) is not None  # (33.3 m/s)²/30 m = 3.8 g at its end


def test_a_circle_no_tyre_can_drive_warns(tmp_path):
    sc = _scenario(
        tmp_path,
        '[[case]]\nmaneuver = "circle"\nspeed_kmh = 300\nradius_m = 20\nlaps = 0.2\nlead_s = 1\n',
    )
    with warnings.catch_warnings(record=True) as got:
        warnings.simplefilter("always")
        cases = run_scenario(sc, tmp_path / "out")
    assert any("35 g" in str(w.message) for w in got)
    assert "35 g" in cases["warning"].iloc[0]
    # the command line says it in one line and still writes the drive (exit 0)
    r = subprocess.run(
        [EXE, "simulate", str(sc), "-o", str(tmp_path / "cli")],
        capture_output=True,
        text=True,
        timeout=600,
    )
    assert r.returncode == 0, r.stderr
    lines = [x for x in (r.stdout + r.stderr).splitlines() if "35 g" in x]
    assert len(lines) == 1 and lines[0].startswith("warning: "), r.stdout + r.stderr
    assert "Traceback" not in r.stderr


def test_one_receiver_keeps_the_names_and_declares_it(tmp_path):
    sc = _scenario(
        tmp_path,
        '[[case]]\nmaneuver = "braking"\nspeed_kmh = 30\n',
        head="",
    )
    sc.write_text(sc.read_text().replace('noise = "none"', 'noise = "rtk"'))
    cases = run_scenario(sc, tmp_path / "out")
    assert list(cases["vehicle_file"]) == ["vehicle.toml"]
    v = Vehicle.from_toml(tmp_path / "out" / "vehicle.toml")
    assert v.receiver is not None and v.receiver.name == "rtk"
    assert v.receiver.heading_white_deg == 0.05  # RECEIVERS["rtk"] (config/receiver.py)
    # and friction, given only that file, assumes the receiver that recorded the drive
    from gripsense import FrictionRun

    assert FrictionRun(tmp_path / "out" / "vehicle.toml").receiver == "rtk"


def test_python_errors_name_the_python_argument(tmp_path):
    """The Python API's errors talked in command-line flags only (`add --overwrite`)."""
    sc = _scenario(tmp_path, '[[case]]\nmaneuver = "braking"\nspeed_kmh = 20\n')
    run_scenario(sc, tmp_path / "out")
    with pytest.raises(InputError, match=re.escape("overwrite=True")):
        run_scenario(sc, tmp_path / "out")
    assert len(run_scenario(sc, tmp_path / "out", overwrite=True)) == 1
