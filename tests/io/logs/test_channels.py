"""The channel convention of measurement logs: file units and resampling, worked by hand."""

from __future__ import annotations

import numpy as np
import pytest

from gripsense.errors import InputError
from gripsense.io.logs.channels import (
    file_unit_factor,
    parse_channel_spec,
    recognise_steering,
    resample,
)


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


UNITS = {
    "RoadWheelAngle": "deg",
    "Road_Wheel_Angle": "rad",
    "SteeringWheelAngle": "deg",
    "Steering Wheel Angle": "°",
    "SteeringWhAng": "deg",
    "SteeringWheelSpeed": "deg/s",
    "SteeringWheelTorque": "Nm",
    "SWA": "",
    "RoadWheelAng": "Nm",
    "Steering_Angle": "deg",
    "Speed": "km/h",
}


@pytest.mark.parametrize(
    ("names", "key", "channel", "note"),
    [
        (["Speed", "RoadWheelAngle"], "steer", "RoadWheelAngle", "steer=RoadWheelAngle [deg]"),
        (["Road_Wheel_Angle"], "steer", "Road_Wheel_Angle", "road-wheel angle"),
        (["SteeringWheelAngle"], "steering_wheel", "SteeringWheelAngle", "steering-wheel angle"),
        (["Steering Wheel Angle"], "steering_wheel", "Steering Wheel Angle", "[°]"),
        (["SteeringWhAng"], "steering_wheel", "SteeringWhAng", "steering_wheel=SteeringWhAng"),
        # the road-wheel angle needs no ratio: preferred, the other named
        (["SteeringWheelAngle", "RoadWheelAngle"], "steer", "RoadWheelAngle",
         "'SteeringWheelAngle' not used"),
        # a name that says the hand wheel, a unit that is not an angle: not a steering angle
        (["SteeringWheelSpeed", "SteeringWheelTorque"], None, None, None),
        (["SWA"], None, None, "'SWA' is named like a steering-wheel angle but it has no unit"),
        (["RoadWheelAng"], None, None, "its unit 'Nm' is not an angle"),
        (["Steering_Angle"], None, None, "does not say which: map it with --columns steer="),
    ],
)  # fmt: skip
def test_a_steering_channel_is_found_by_name_and_unit(names, key, channel, note):
    spec, notes = recognise_steering(names, UNITS.get)
    assert (spec.key, spec.channel, spec.factor) == (key, channel, None) if key else spec is None
    if note is None:
        assert notes == []
    else:
        assert any(note in n for n in notes), notes
