"""Vehicle descriptions: the bundled thesis vehicle and clear errors naming the key."""

from __future__ import annotations

import math

import pytest

from gripsense import InputError, Vehicle
from gripsense.data import sample_path

BASE = """
[vehicle]
mass_kg = 1500.0
front_weight_fraction = 0.58
wheelbase_m = 2.70
cg_height_m = 0.55
track_front_m = 1.55
track_rear_m = 1.53
[antenna]
x_m = 0.30
y_m = 0.10
heading_offset_deg = 0.5
[tyre.front]
width_m = 0.205
cornering_stiffness_N_per_rad = 80000.0
contact_length = { fixed_m = 0.15 }
[tyre.rear]
width_m = 0.205
tread_stiffness_N_per_m3 = 3e7
contact_length = { a = 0.0104, b = -1.017e-4 }
pressure = "quartic"
"""


def test_thesis_vehicle():
    v = Vehicle.from_toml(sample_path("corolla_thesis.toml"))
    assert v.mass_kg == 1200 and v.axle_masses_kg == pytest.approx((720, 480))
    assert v.cg_height_m == 0.75 and v.track_rear_m == pytest.approx(2 * 0.55)
    assert v.wheel_offsets == {"rear_right": (-0.76, -0.205), "rear_left": (-0.76, 1.0)}
    t = v.tyres["rear"]
    assert (t.width_m, t.tread_stiffness_N_per_m3, t.contact_a, t.contact_b) == (
        0.185,
        5e7,
        0.0104,
        -1.017e-4,
    )


def test_wheels_from_antenna_and_cg(tmp_path):
    p = tmp_path / "car.toml"
    p.write_text(BASE)
    v = Vehicle.from_toml(p)
    l_f, l_r = 2.70 * 0.42, 2.70 * 0.58
    assert v.wheel_offsets["front_left"] == pytest.approx((l_f - 0.30, 1.55 / 2 - 0.10))
    assert v.wheel_offsets["rear_right"] == pytest.approx((-l_r - 0.30, -1.53 / 2 - 0.10))
    assert v.cg_offset == (-0.30, -0.10)
    assert v.heading_offset_rad == pytest.approx(math.radians(0.5))
    assert v.tyres["front"].cornering_stiffness(0.15) == 80000.0
    assert v.tyres["rear"].pressure == "quartic"
    assert v.tyres["rear"].cornering_stiffness(0.14) == pytest.approx(0.5 * 3e7 * 0.205 * 0.14**2)


@pytest.mark.parametrize(
    ("edit", "match"),
    [
        (("mass_kg = 1500.0", ""), r"\[vehicle\] mass_kg: missing \[kg\]"),
        (("mass_kg = 1500.0", "mass_kg = -3"), r"mass_kg: = -3: must be > 0 \[kg\]"),
        (("mass_kg = 1500.0", 'mass_kg = "heavy"'), r"mass_kg: = 'heavy': must be a number"),
        (("front_weight_fraction = 0.58", "front_weight_fraction = 1.4"), "between 0 and 1"),
        (
            (
                "width_m = 0.205\ncornering_stiffness_N_per_rad = 80000.0",
                "width_m = 0.205\ncornering_stiffness_N_per_rad = 80000.0\n"
                "tread_stiffness_N_per_m3 = 3e7",
            ),
            r"\[tyre.front\] tread_stiffness_N_per_m3: give exactly one",
        ),
        (('pressure = "quartic"', 'pressure = "cubic"'), r"\[tyre.rear\] pressure"),
        (
            ("contact_length = { fixed_m = 0.15 }", "contact_length = { a = 0.01 }"),
            r"contact_length\] a: give both a and b",
        ),
        (("x_m = 0.30\n", ""), "give both x_m and y_m"),
    ],
)
def test_errors_name_the_key(tmp_path, edit, match):
    p = tmp_path / "car.toml"
    p.write_text(BASE.replace(*edit, 1))
    with pytest.raises(InputError, match=match) as exc:
        Vehicle.from_toml(p)
    assert "car.toml" in str(exc.value)


def test_missing_file_and_bad_toml(tmp_path):
    with pytest.raises(InputError, match="no such vehicle file"):
        Vehicle.from_toml(tmp_path / "none.toml")
    p = tmp_path / "bad.toml"
    p.write_text("[vehicle\nmass_kg = 1")
    with pytest.raises(InputError, match="not valid TOML"):
        Vehicle.from_toml(p)


STEERING = """
[steering]
ratio = 15.5
mechanical_trail_m = 0.025
assist = "linear"
assist_gain = 4.0
friction_Nm = 0.8
"""


def test_steering_table(tmp_path):
    p = tmp_path / "car.toml"
    p.write_text(BASE + STEERING)
    v = Vehicle.from_toml(p)
    s = v.steering
    assert v.steering_ratio == 15.5
    assert (s.mechanical_trail_m, s.assist, s.assist_gain, s.friction_Nm) == (
        0.025,
        "linear",
        4.0,
        0.8,
    )
    assert s.pneumatic_trail_m is None and s.torque_scale_uncertainty == 0.03
    p.write_text(BASE)
    assert Vehicle.from_toml(p).steering is None


@pytest.mark.parametrize(
    ("edit", "match"),
    [
        (("ratio = 15.5", "ratio = 155"), r"\[steering\] ratio: .*outside"),
        (('assist = "linear"', 'assist = "hydraulic"'), r"\[steering\] assist: .*none, linear"),
        (('assist = "linear"', 'assist = "none"'), r"\[steering\] assist_gain: .*\"linear\""),
        (("friction_Nm = 0.8", "friction_nm = 0.8"), r"\[steering\].*friction_nm"),
    ],
)
def test_steering_errors_name_the_key(tmp_path, edit, match):
    p = tmp_path / "car.toml"
    p.write_text(BASE + STEERING.replace(*edit, 1))
    with pytest.raises(InputError, match=match) as exc:
        Vehicle.from_toml(p)
    assert "car.toml" in str(exc.value)


def test_steering_ratio_given_twice_must_agree(tmp_path):
    p = tmp_path / "car.toml"
    p.write_text(BASE.replace("cg_height_m", "steering_ratio = 16.0\ncg_height_m", 1) + STEERING)
    with pytest.raises(InputError, match=r"\[steering\] ratio: = 15.5 but \[vehicle\]"):
        Vehicle.from_toml(p)


def test_steering_tyre_file(tmp_path):
    """[steering] tyre_file: a path relative to the vehicle file; a missing or unreadable file is
    refused with the key."""
    import shutil

    from gripsense.data import sample_path

    shutil.copy(sample_path("tyres/PacejkaBook_Defaults.tir"), tmp_path / "front.tir")
    p = tmp_path / "car.toml"
    p.write_text(BASE + STEERING + 'tyre_file = "front.tir"\n')
    s = Vehicle.from_toml(p).steering
    assert s.tyre_file == str(tmp_path / "front.tir")
    p.write_text(BASE + STEERING + 'tyre_file = "rear.tir"\n')
    with pytest.raises(InputError, match=r"car.toml: \[steering\] tyre_file: = 'rear.tir': no"):
        Vehicle.from_toml(p)
    (tmp_path / "bad.tir").write_text("[MODEL]\nFITTYP = 61\nLONGVL = fast\n")
    p.write_text(BASE + STEERING + 'tyre_file = "bad.tir"\n')
    with pytest.raises(InputError, match=r"bad\.tir"):
        Vehicle.from_toml(p)
