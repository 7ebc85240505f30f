"""Steering tables with torque channels at their own rates (issue "Friction at half the limit")."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from gripsense.errors import InputError
from gripsense.io.steer import channel_at, read_steer_csv, with_torque


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
    ep = pd.DataFrame({"t_s": [0.105, 0.5, 2.0]})
    out = with_torque(ep, d)
    assert "torque_nm" in out and "torque_nm" not in ep
    assert out["torque_nm"].iloc[0] == pytest.approx(-2.0 * np.cos(0.105), abs=1e-4)
    assert np.isnan(out["torque_nm"].iloc[2])  # after the table: not extrapolated


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


def test_a_row_without_any_channel_is_named(tmp_path):
    p = tmp_path / "s.csv"
    p.write_text("t_s,road_wheel_deg,torque_Nm\n0,1,0.5\n0.01,,\n")
    with pytest.raises(InputError, match=r"s.csv: line 3: time, or every channel"):
        read_steer_csv(p)
