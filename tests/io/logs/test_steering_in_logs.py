"""A steering channel inside a log is found without --columns where its name and unit say what it
is (issue 46 item 5): the files `gripsense simulate` writes, and a CAN log with the DBC's
SteeringWheelAngle."""

from __future__ import annotations

import numpy as np

from gripsense.io.logs import log_steer, read_log
from gripsense.io.logs.canlog import write_can
from gripsense.io.logs.mdf import mdf_columns
from tests.io.logs.test_measurement_logs import CAN_COLUMNS, DBC, _epochs, _steer


def test_the_simulated_vbo_gives_its_road_wheel_angle_unmapped(simulated):
    sim = simulated("vbo")
    assert sim.columns == "steer=RoadWheelAngle"  # what the case index says it needs
    found = read_log(sim.log)
    mapped = read_log(sim.log, columns=sim.columns)
    np.testing.assert_array_equal(found.epochs["steer_rad"], mapped.epochs["steer_rad"])
    assert found.report.steering == {
        "key": "steer", "channel": "RoadWheelAngle", "unit": "deg", "source": "name and unit"
    }  # fmt: skip
    assert mapped.report.steering["source"] == "--columns"
    assert found.report.notes[0].startswith(
        "steering channel found by its name and unit: steer=RoadWheelAngle [deg]"
    )


def test_the_simulated_mdf4_gives_its_road_wheel_angle_unmapped(simulated):
    sim = simulated("mf4")
    cols = mdf_columns()  # the GNSS channels only
    assert "steer" not in cols and "steer=RoadWheelAngle" in sim.columns
    found = read_log(sim.log, columns=cols)
    mapped = read_log(sim.log, columns=sim.columns)
    np.testing.assert_array_equal(found.epochs["steer_rad"], mapped.epochs["steer_rad"])
    assert found.report.steering["source"] == "name and unit" and found.report.balanced


def test_a_vbo_channel_without_a_unit_is_named_not_used(simulated, tmp_path):
    sim = simulated("vbo")
    text = sim.log.read_bytes().replace(b"[channel units]\r\ndeg\r\n", b"[channel units]\r\n")
    p = tmp_path / "nounit.vbo"
    p.write_bytes(text)
    log = read_log(p)
    assert "steer_rad" not in log.epochs and log.report.steering == {}
    assert any(
        "'RoadWheelAngle' is named like a road-wheel angle but it has no unit" in n
        and "--columns steer=RoadWheelAngle:deg" in n
        for n in log.report.notes
    ), log.report.notes


def test_a_can_steering_wheel_signal_is_decoded_unmapped(tmp_path):
    ep = _epochs()
    sw = _steer(ep, 50.0).rename(columns={"road_wheel_deg": "steering_wheel_deg"})
    write_can(ep, tmp_path / "c.blf", DBC, steering_wheel=sw)
    found = read_log(tmp_path / "c.blf", columns=CAN_COLUMNS, dbc=DBC)
    cols = CAN_COLUMNS + ",steering_wheel=SteeringWheelAngle"
    mapped = read_log(tmp_path / "c.blf", columns=cols, dbc=DBC)
    np.testing.assert_array_equal(
        found.epochs["steering_wheel_rad"], mapped.epochs["steering_wheel_rad"]
    )
    assert found.report.parsed == mapped.report.parsed and found.report.balanced
    assert found.report.steering["key"] == "steering_wheel"
    # the hand-wheel angle divided by the vehicle's ratio
    np.testing.assert_allclose(
        log_steer(found.epochs, 15.0), found.epochs["steering_wheel_rad"] / 15.0
    )
