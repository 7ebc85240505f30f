"""Every reader, fed damaged versions of real files: a clear InputError or a correct result —
never another exception (hypothesis)."""

from __future__ import annotations

import gzip
import math
import re

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from gripsense.config import PLAUSIBLE, SteeringCar, Vehicle
from gripsense.config.tyre_files import load_mf_tyre
from gripsense.data import sample_path
from gripsense.errors import InputError
from gripsense.io import (
    read_accel_csv,
    read_laser_csv,
    read_motion_table,
    read_nmea,
    read_steer_csv,
    read_tir,
    read_tyre_table,
)
from tests.conftest import DATA

SETTINGS = settings(
    max_examples=60, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture]
)
VEHICLE_TEXT = sample_path("corolla_sim.toml").read_text()
STEERING_TEXT = sample_path("of18_steering.toml").read_text()
TIR_TEXT = (DATA / "tyre" / "tir" / "MagicFormula61_Paramerters.tir").read_text()
RST39 = sample_path("rst39.log").read_bytes()


@st.composite
def damaged_lines(draw, text: str) -> str:
    """*text* with a few lines deleted, duplicated, truncated, garbled or with a value replaced."""
    lines = text.splitlines()
    for _ in range(draw(st.integers(1, 4))):
        i = draw(st.integers(0, len(lines) - 1))
        op = draw(
            st.sampled_from(["delete", "duplicate", "truncate", "garble", "value", "typo", "bytes"])
        )
        line = lines[i]
        if op == "delete":
            del lines[i]
        elif op == "duplicate":
            lines.insert(i, line)
        elif op == "truncate":
            lines[i] = line[: draw(st.integers(0, max(len(line) - 1, 0)))]
        elif op == "garble":
            lines[i] = draw(st.text(max_size=30))
        elif op == "value" and "=" in line:
            value = draw(
                st.sampled_from(
                    ["nan", "inf", "0", "-1", "1e30", "55", "0.001", "'x'", "", "[1, 2]", "true"]
                )
            )
            lines[i] = line.split("=", 1)[0] + "= " + value
        elif op == "typo" and "=" in line:
            key = line.split("=", 1)[0]
            pos = draw(st.integers(0, max(len(key.strip()) - 1, 0)))
            k = key.strip()
            lines[i] = k[:pos] + "X" + k[pos:] + " =" + line.split("=", 1)[1]
        elif op == "bytes":
            lines[i] = line + "\udcff"
        if not lines:
            break
    return "\n".join(lines) + "\n"


def _write(tmp_path, name: str, text: str):
    p = tmp_path / name
    p.write_bytes(text.encode("utf-8", "surrogateescape"))
    return p


@SETTINGS
@given(text=damaged_lines(VEHICLE_TEXT))
def test_vehicle_file(tmp_path, text):
    try:
        v = Vehicle.from_toml(_write(tmp_path, "car.toml", text))
    except InputError as e:
        assert str(e) and "\n" not in str(e)
        return
    # accepted: every number is in its plausible range and the loads stay positive at 0.5 g
    lo, hi = PLAUSIBLE["mass_kg"]
    assert lo <= v.mass_kg <= hi
    assert 0 < v.front_weight_fraction < 1
    assert min(v.track_front_m, v.track_rear_m) / (2 * v.cg_height_m) >= 0.5
    for t in v.tyres.values():
        length = t.contact_length(v.mass_kg / 4)
        assert np.all(np.isfinite(length)) and np.all(length > 0)


@SETTINGS
@given(text=damaged_lines(STEERING_TEXT))
def test_steering_car_file(tmp_path, text):
    try:
        car = SteeringCar.from_toml(_write(tmp_path, "car.toml", text))
    except InputError as e:
        assert str(e)
        return
    assert car.mass_kg > 0 and math.isfinite(car.ks)


@SETTINGS
@given(text=damaged_lines(TIR_TEXT))
def test_tir_file(tmp_path, text):
    path = _write(tmp_path, "t.tir", text)
    try:
        tyre = load_mf_tyre(read_tir(path))
        f = tyre.forces(4000.0, 0.0, np.deg2rad(np.array([-4.0, 4.0])), 0.0)
    except InputError as e:
        assert re.search(r"t\.tir", str(e)) or "mandatory" in str(e), str(e)
        return
    # accepted: every coefficient read is finite and the forces are numbers
    assert all(math.isfinite(v) for v in tyre.params.values())
    assert np.isfinite(f.fy).all() or np.isnan(f.fy).all()


@settings(max_examples=80, deadline=None)
@given(
    data=st.one_of(
        st.binary(max_size=400),
        st.binary(max_size=200).map(lambda b: b"\x1f\x8b" + b),
        st.integers(10, 4000).map(lambda n: gzip.compress(RST39)[:n]),
        st.integers(0, 3000).map(lambda n: RST39[:n] + b"\x00\xff" * 10 + RST39[n:]),
    )
)
def test_nmea_bytes(data):
    try:
        log = read_nmea(data)
    except InputError as e:
        assert "gzip" in str(e)
        return
    assert log.report.balanced


TABLE_READERS = {
    "accel": lambda p: read_accel_csv(p),
    "laser": lambda p: read_laser_csv(p),
    "steer": lambda p: read_steer_csv(p),
    "tyre": lambda p: read_tyre_table(p),
    "motion": lambda p: read_motion_table(p, "t=t_s,vx=vx,vy=vy,yaw_rate=r"),
}
GOOD = {
    "accel": "t_s,ax_g,ay_g,az_g\n0,0.0,0.0,1.0\n0.02,-0.5,0.0,1.0\n",
    "laser": "t_s,d_outer_mm,d_inner_mm\n0,100,100\n0.01,101,100\n",
    "steer": "t_s,road_wheel_deg\n0,1.0\n0.1,1.5\n",
    "tyre": "alpha_deg,fz_N,fy_N\n1,4000,-1000\n2,4000,-1900\n",
    "motion": "t_s,vx,vy,r\n0,10,0.1,0.2\n0.1,10,0.1,0.2\n",
}


@pytest.mark.parametrize("kind", sorted(TABLE_READERS))
@settings(
    max_examples=40, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture]
)
@given(
    text=st.one_of(
        st.just(""),
        st.text(max_size=120),
        st.sampled_from(sorted(GOOD.values())).flatmap(lambda t: damaged_lines(t)),
    )
)
def test_tables(tmp_path, kind, text):
    path = _write(tmp_path, f"{kind}.csv", text)
    try:
        out = TABLE_READERS[kind](path)
    except InputError as e:
        assert str(path) in str(e)
        return
    assert out is not None
