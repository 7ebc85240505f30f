"""The channel convention of measurement logs: file units and resampling, worked by hand."""

from __future__ import annotations

import numpy as np
import pytest

from gripsense.errors import InputError
from gripsense.io.channels import file_unit_factor, parse_channel_spec, resample


def test_file_units_by_kind():
    assert file_unit_factor("kN", "force") == 1000.0  # kilonewton, not knots
    assert file_unit_factor("kN", "speed") is None
    assert file_unit_factor("kn", "speed") == pytest.approx(1852 / 3600)
    assert file_unit_factor("°/s", "angular rate") == pytest.approx(np.pi / 180)
    assert file_unit_factor("Degrees", "angle") == pytest.approx(np.pi / 180)
    assert file_unit_factor("N·m", "torque") == 1.0
    assert file_unit_factor("", "angle") is None and file_unit_factor("furlong", "length") is None


def test_resample_by_hand():
    t = np.array([0.0, 1.0, 2.0, 10.0, 11.0])  # intervals 1, 1, 8, 1: the 8 s one is a gap
    v = np.array([0.0, 10.0, 20.0, 100.0, 110.0])
    got = resample(np.array([0.5, 1.5, 5.0, 10.5, 12.0, -1.0]), t, v)
    np.testing.assert_allclose(got, [5.0, 15.0, np.nan, 105.0, np.nan, np.nan])
    # compass angles through north: 350° → 10° passes 0°, not 180°
    got = resample(np.array([0.5, 0.75]), np.array([0.0, 1.0]), np.array([350.0, 10.0]),
                   circular=True)  # fmt: skip
    np.testing.assert_allclose(got, [0.0, 5.0], atol=1e-12)


def test_spec_words():
    m = parse_channel_spec("heading=True_Head,yaw_rate=-YawRate:dps,torque=Trq:Nm")
    assert m["yaw_rate"].sign == -1.0 and m["yaw_rate"].factor == pytest.approx(np.pi / 180)
    assert m["heading"].factor is None and m["torque"].channel == "Trq"
    with pytest.raises(InputError, match="torque needs a unit of torque"):
        parse_channel_spec("torque=Trq:deg")
    with pytest.raises(InputError, match="not key=CHANNEL"):
        parse_channel_spec("heading")
