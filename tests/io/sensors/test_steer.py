"""Steering tables with torque channels at their own rates (issue "Friction at half the limit")."""

from __future__ import annotations

import itertools

import numpy as np
import pandas as pd
import pytest

from gripsense.errors import InputError
from gripsense.io.sensors.steer import channel_at, read_steer_csv, with_torque


def _multi_rate(tmp_path):
    """Angle at 50 Hz and torque at 100 Hz in one table, each row carrying what was sampled."""
    t = np.round(np.arange(0, 1.0, 0.01), 6)
    angle = np.where(np.arange(t.size) % 2 == 0, np.sin(t), np.nan)
    torque = 2.0 * np.cos(t)
    p = tmp_path / "steer.csv"
    pd.DataFrame({"time": t, "SWA": np.rad2deg(angle) * 15.0, "TrqCol": torque}).to_csv(
        p, index=False
    )
    return p, t


def test_each_channel_on_its_own_rows(tmp_path):
    p, t = _multi_rate(tmp_path)
    d = read_steer_csv(
        p, steering_ratio=15.0, columns="t=time:s,steering_wheel=SWA:deg,torque=-TrqCol:Nm"
    )
    assert d.attrs["columns"]["torque"] == "-TrqCol:Nm"
    assert len(d) == t.size
    # the angle between its own samples, not NaN on the torque-only rows
    np.testing.assert_allclose(channel_at(d, "steer_rad", [0.01, 0.55]), np.sin([0.01, 0.55]),
                               atol=5e-5)  # fmt: skip
    np.testing.assert_allclose(channel_at(d, "torque_nm", t), -2.0 * np.cos(t), atol=1e-12)
    ep = pd.DataFrame({"t_s": [0.105, 0.205, 0.305, 2.0]})
    out = with_torque(ep, d)
    assert "torque_nm" in out and "torque_nm" not in ep
    # the torque at its own rate: every sample within half an epoch step (0.05 s) averaged
    tq = d.dropna(subset=["torque_nm"])
    near = tq[(tq["t_s"] >= 0.055) & (tq["t_s"] < 0.155)]
    assert out["torque_samples"].iloc[0] == len(near) > 1
    assert out["torque_nm"].iloc[0] == pytest.approx(float(near["torque_nm"].mean()), abs=1e-12)
    assert out["torque_nm"].iloc[0] == pytest.approx(-2.0 * np.cos(0.105), abs=2e-3)
    assert np.isnan(out["torque_nm"].iloc[3])  # after the table: not extrapolated


def test_headers_with_units_map_themselves(tmp_path):
    p = tmp_path / "s.csv"
    p.write_text(
        "t_s,road_wheel_deg,torque_Nm,assist_Nm,rack_kN\n0,1,0.5,2.0,1.2\n0.01,1,0.6,2.1,1.3\n"
    )
    d = read_steer_csv(p)
    assert list(d.columns) == ["t_s", "steer_rad", "torque_nm", "assist_nm", "rack_n"]
    assert d["rack_n"].tolist() == [1200.0, 1300.0]
    plain = tmp_path / "plain.csv"
    plain.write_text("t_s,road_wheel_deg\n0,1\n0.01,1\n")
    ep = pd.DataFrame({"t_s": [0.0]})
    assert with_torque(ep, read_steer_csv(plain)) is ep  # no torque: the table untouched


@pytest.mark.parametrize(
    ("columns", "message"),
    [
        ("t=time:s,road_wheel=SWA:deg,torque=TrqCol:deg", "deg is a unit of angle, but torque"),
        ("t=time:s,road_wheel=SWA:deg,rack=TrqCol:Nm", "Nm is a unit of torque, but rack"),
        ("t=time:s,road_wheel=SWA:deg,torqe=TrqCol:Nm", "torqe"),
    ],
)
def test_wrong_units_and_keys_are_one_clear_error(tmp_path, columns, message):
    p, _ = _multi_rate(tmp_path)
    with pytest.raises(InputError, match=message):
        read_steer_csv(p, columns=columns)


def test_a_row_without_any_channel_is_counted(tmp_path):
    p = tmp_path / "s.csv"
    p.write_text("t_s,road_wheel_deg,torque_Nm\n0,1,0.5\n0.01,,\n0.02,2,\n")
    d = read_steer_csv(p)
    assert d["t_s"].tolist() == [0.0, 0.02]
    rows = d.attrs["rows"]
    assert (rows["rows"], rows["rows_used"], rows["rows_without_channel"]) == (3, 2, 1)
    assert rows["note"] == (
        "s.csv: 1 of 3 rows carry none of the mapped channels (road_wheel_deg, torque_Nm): "
        "not used (the first at line 3)"
    )


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("t_s,road_wheel_deg\n0,1\n,2\n", r"s.csv: line 3, column 't_s' \(t\): no time"),
        ("t_s,road_wheel_deg\n0,1\n0.1,x\n", r"s.csv: line 3, column 'road_wheel_deg': 'x' is"),
        ("t_s,road_wheel_deg,torque_Nm\n0,1,\n0.1,2,\n", r"column 'torque_Nm' \(torque\) has no"),
        ("t_s,road_wheel_deg\n0,\n0.1,\n", r"column 'road_wheel_deg' \(road_wheel\) has no"),
    ],
)
def test_a_malformed_row_is_still_an_error(tmp_path, text, message):
    p = tmp_path / "s.csv"
    p.write_text(text)
    with pytest.raises(InputError, match=message) as e:
        read_steer_csv(p)
    assert "\n" not in str(e.value)


SIM_COLUMNS = {
    "road_wheel": "road_wheel_deg:deg",
    "torque": "torque_Nm:Nm",
    "assist": "assist_Nm:Nm",
}
SUBSETS = [
    tuple(k for k, bit in zip(SIM_COLUMNS, bits, strict=True) if bit)
    for bits in itertools.product((0, 1), repeat=len(SIM_COLUMNS))
]


@pytest.mark.parametrize("keys", SUBSETS, ids=lambda k: "+".join(k) or "time-only")
def test_the_simulated_steering_csv_with_any_subset_mapped(simulated, keys):
    """The steering CSV `gripsense simulate` writes (angle at 20 Hz, torque and assist at
    100 Hz, interleaved): every subset of its channels mapped reads, each channel with exactly
    its own samples; the rows that carry none of them are counted; without an angle the error
    says which column is missing."""
    sim = simulated("nmea")
    raw = pd.read_csv(sim.steer)
    assert {"t_s", "road_wheel_deg", "torque_Nm", "assist_Nm"} <= set(raw.columns)
    spec = ",".join(["t=t_s:s", *(f"{k}={SIM_COLUMNS[k]}" for k in keys)])
    if "road_wheel" not in keys:
        with pytest.raises(InputError, match=r"no column for road_wheel .*add road_wheel="):
            read_steer_csv(sim.steer, columns=spec)
        return
    d = read_steer_csv(sim.steer, columns=spec)
    heads = [SIM_COLUMNS[k].split(":")[0] for k in keys]
    carries = raw[heads].notna().any(axis=1).to_numpy()
    assert len(d) == carries.sum()
    assert d.attrs["rows"]["rows_without_channel"] == (~carries).sum()
    assert d.attrs["rows"]["rows"] == len(raw)
    assert (d.attrs["rows"]["note"] == "") == bool(carries.all())
    np.testing.assert_allclose(
        d["steer_rad"].dropna().to_numpy(), np.deg2rad(raw["road_wheel_deg"].dropna()), atol=1e-12
    )
    for key, col in (("torque", "torque_nm"), ("assist", "assist_nm")):
        assert (col in d) == (key in keys)
        if key in keys:
            assert d[col].notna().sum() == raw[SIM_COLUMNS[key].split(":")[0]].notna().sum()
    # the angle between its own samples on the torque rows, never NaN inside its span
    t = d["t_s"].to_numpy()
    assert np.isfinite(channel_at(d, "steer_rad", t[(t > 1.0) & (t < t[-1] - 1.0)])).all()


def test_the_simulated_steering_csv_as_a_steering_wheel_angle(simulated, tmp_path):
    """The same CSV with a steering-wheel column in place of the road-wheel one (as a CAN
    logger would give it): read with the vehicle's ratio."""
    sim = simulated("nmea")
    raw = pd.read_csv(sim.steer)
    sw = raw.assign(steering_wheel_deg=raw["road_wheel_deg"] * 15.0).drop(columns="road_wheel_deg")
    p = tmp_path / "sw.csv"
    sw.to_csv(p, index=False)
    d = read_steer_csv(
        p, steering_ratio=15.0, columns="t=t_s,steering_wheel=steering_wheel_deg:deg"
    )
    np.testing.assert_allclose(
        d["steer_rad"].to_numpy(), np.deg2rad(raw["road_wheel_deg"].dropna()), atol=1e-12
    )
    with pytest.raises(InputError, match="needs \\[vehicle\\] steering_ratio"):
        read_steer_csv(p)
