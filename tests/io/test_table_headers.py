"""GNSS/INS tables as they come (issue 43): a header that repeats names (``x,y,z`` after each
vector of a rosbag-to-CSV, ADMA, OxTS or VBOX export) is read by position, by occurrence or by
the vector's name, and the command says which column it took; a repeated name that could mean
two different columns is one line naming them and how to choose."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from gripsense.errors import InputError
from gripsense.io.sensors.motion import read_motion_table
from gripsense.io.table import describe_columns

rng = np.random.default_rng(43)
N = 40
T = np.arange(N) * 0.1
VX = rng.uniform(5, 25, N)  # twist.linear.x [m/s]
VY = rng.normal(0, 0.5, N)  # twist.linear.y
VZ = rng.normal(0, 0.05, N)
WX = rng.normal(0, 0.02, N)  # twist.angular.x [rad/s]
WY = rng.normal(0, 0.02, N)
WZ = rng.normal(0, 0.3, N)  # twist.angular.z: ISO yaw rate


def _write(path, header: list[str], columns: list[np.ndarray]) -> None:
    """A CSV with exactly this header line (pandas would rename repeated names)."""
    rows = [",".join(header)]
    rows += [",".join(repr(float(c[i])) for c in columns) for i in range(N)]
    path.write_text("\n".join(rows) + "\n")


def _leaf_table(tmp_path):
    """A rosbag-to-CSV export of geometry_msgs/TwistStamped with the leaf names only."""
    p = tmp_path / "twist.csv"
    _write(p, ["stamp", "x", "y", "z", "x", "y", "z"], [T, VX, VY, VZ, WX, WY, WZ])
    return p


def test_repeated_names_by_occurrence_and_by_position(tmp_path):
    p = _leaf_table(tmp_path)
    m = read_motion_table(p, "t=stamp,vx=x[1],vy=y[1],yaw_rate=z[2]")
    np.testing.assert_array_equal(m["u_mps"], VX)
    np.testing.assert_array_equal(m["v_mps"], VY)
    np.testing.assert_array_equal(m["yaw_rate_rps"], WZ)
    said = describe_columns(m.attrs["columns"])
    assert "vx ← x (column 2)" in said and "yaw_rate ← z (column 7)" in said
    # the same columns by their position in the file (counted from 1), with units and a sign
    m2 = read_motion_table(p, "t=stamp,vx=#2:kmh,vy=-#3,yaw_rate=#7:dps")
    np.testing.assert_allclose(m2["u_mps"], VX / 3.6, rtol=1e-15)
    np.testing.assert_array_equal(m2["v_mps"], -VY)
    np.testing.assert_allclose(m2["yaw_rate_rps"], np.deg2rad(WZ), rtol=1e-15)
    assert "vy ← −y (column 3)" in describe_columns(m2.attrs["columns"])


def test_repeated_names_by_the_vector_they_follow(tmp_path):
    """A header that names each vector before its components (``vel,x,y,z,rate,x,y,z``)."""
    p = tmp_path / "ins.csv"
    speed = np.hypot(VX, VY)
    norm = np.sqrt(WX**2 + WY**2 + WZ**2)
    _write(
        p,
        ["time", "vel", "x", "y", "z", "rate", "x", "y", "z"],
        [T, speed, VX, VY, VZ, norm, np.rad2deg(WX), np.rad2deg(WY), np.rad2deg(WZ)],
    )
    m = read_motion_table(p, "t=time,vx=vel.x,vy=vel/y,yaw_rate=rate.z:dps")
    np.testing.assert_array_equal(m["u_mps"], VX)
    np.testing.assert_array_equal(m["v_mps"], VY)
    np.testing.assert_allclose(m["yaw_rate_rps"], WZ, rtol=1e-12)
    said = describe_columns(m.attrs["columns"])
    assert "yaw_rate ← z (column 9, after 'rate') [deg/s]" in said
    # the name alone is ambiguous: one line naming both columns and the ways to choose
    with pytest.raises(InputError) as e:
        read_motion_table(p, "t=time,vx=x,vy=vel.y,yaw_rate=rate.z:dps")
    msg = str(e.value)
    assert "\n" not in msg and "ins.csv" in msg
    assert "'x' (x (column 3, after 'vel'), x (column 7, after 'rate'))" in msg
    assert "vx=vel.x or vx=rate.x" in msg and "vx=#3" in msg


def test_a_repeated_name_mapped_alone_is_refused_when_the_columns_differ(tmp_path):
    p = _leaf_table(tmp_path)
    with pytest.raises(InputError, match=r"twist.csv: the header names 2 columns 'x'.*vx=x\[1\]"):
        read_motion_table(p, "t=stamp,vx=x,vy=y[1],yaw_rate=z[2]")
    with pytest.raises(InputError, match=r"the table has 7 columns \(#1 to #7\)"):
        read_motion_table(p, "t=stamp,vx=#8,vy=y[1],yaw_rate=z[2]")
    with pytest.raises(InputError, match=r"names 2 columns 'z'; use \[1\] to \[2\]"):
        read_motion_table(p, "t=stamp,vx=x[1],vy=y[1],yaw_rate=z[3]")


def test_a_repeated_name_with_equal_columns_is_read_and_said(tmp_path):
    """A channel exported twice (VBOX CSV exports repeat a CAN channel logged twice)."""
    p = tmp_path / "twice.csv"
    _write(
        p,
        ["time_s", "vx_mps", "vy_mps", "yaw_rate_rps", "yaw_rate_rps"],
        [T, VX, VY, WZ, WZ],
    )
    m = read_motion_table(p)  # headers with a unit suffix: mapped without --columns
    np.testing.assert_array_equal(m["yaw_rate_rps"], WZ)
    said = describe_columns(m.attrs["columns"])
    assert "yaw_rate ← yaw_rate_rps (column 4; the first of 2 equal columns) [rad/s]" in said
    _write(p, ["time_s", "vx_mps", "vy_mps", "yaw_rate_rps", "yaw_rate_rps"], [T, VX, VY, WZ, -WZ])
    with pytest.raises(InputError, match=r"2 columns 'yaw_rate_rps'.*yaw_rate=yaw_rate_rps\[2\]"):
        read_motion_table(p)


def test_unique_headers_read_as_before(tmp_path):
    """A name the header holds once is mapped and said as before (no column number)."""
    p = tmp_path / "plain.csv"
    pd.DataFrame({"Time": T, "VelX": VX, "VelY": VY, "Yaw": WZ}).to_csv(p, index=False)
    m = read_motion_table(p, "t=Time,vx=VelX,vy=VelY,yaw_rate=Yaw")
    np.testing.assert_array_equal(m["u_mps"], VX)
    assert describe_columns(m.attrs["columns"]) == "t ← Time, vx ← VelX, vy ← VelY, yaw_rate ← Yaw"


def test_friction_table_with_repeated_names_on_the_command_line(tmp_path):
    """`friction --table` on a rosbag-style export of the circle drive: the slip angles are the
    circle's truth, and the output says which column each key took."""
    from gripsense.data import sample_path
    from tests.cli.inprocess import cli
    from tests.estimate.circle import circle

    epochs, truth = circle(mu=0.5, utilisation=0.92)
    beta = np.deg2rad(epochs["heading_deg"] - epochs["course_deg"])
    u = (epochs["speed_mps"] * np.cos(beta)).to_numpy()
    v = (epochs["speed_mps"] * np.sin(beta)).to_numpy()
    r = epochs["yaw_rate_rps"].to_numpy()
    zero = np.zeros(len(u))
    p = tmp_path / "twist.csv"
    lines = ["stamp,x,y,z,x,y,z"] + [
        ",".join(repr(float(c)) for c in row)
        for row in zip(epochs["t_s"], u, v, zero, zero, zero, r, strict=True)
    ]
    p.write_text("\n".join(lines) + "\n")
    veh = str(sample_path("corolla_thesis.toml"))
    out = tmp_path / "o"
    cols = "t=stamp,vx=x[1],vy=y[1],yaw_rate=z[2]"
    res = cli("friction", "--table", p, "--columns", cols, "--vehicle", veh, "-o", out)
    assert res.returncode == 0, res.stderr
    assert "yaw_rate ← z (column 7)" in res.stdout
    w = pd.read_parquet(out / "wheels.parquet").query("wheel == 'rear_left'")
    np.testing.assert_allclose(w["slip_angle_rad"], truth["alpha_rear_left"], rtol=1e-9)
    res = cli("friction", "--table", p, "--columns", "t=stamp,vx=x,vy=y[1],yaw_rate=z[2]",
              "--vehicle", veh)  # fmt: skip
    assert res.returncode == 2 and "Traceback" not in res.stderr
    assert "the header names 2 columns 'x'" in res.stderr


def test_a_two_row_header_names_each_vector_over_its_components(tmp_path):
    """The layout of motion-capture and INS exports: the vector's name over its first column,
    ``x,y,z`` under it (``,VelocityBody,,,AngularRate,,`` / ``Time,x,y,z,x,y,z``)."""
    p = tmp_path / "ins2.csv"
    lines = [",VelocityBody,,,AngularRate,,", "Time,x,y,z,x,y,z"] + [
        ",".join(repr(float(c)) for c in row)
        for row in zip(T, VX, VY, VZ, np.rad2deg(WX), np.rad2deg(WY), np.rad2deg(WZ), strict=True)
    ]
    p.write_text("\n".join(lines) + "\n")
    m = read_motion_table(
        p, "t=Time,vx=VelocityBody.x,vy=VelocityBody.y,yaw_rate=AngularRate.z:dps"
    )
    np.testing.assert_array_equal(m["t_s"], T)
    np.testing.assert_array_equal(m["u_mps"], VX)
    np.testing.assert_array_equal(m["v_mps"], VY)
    np.testing.assert_allclose(m["yaw_rate_rps"], WZ, rtol=1e-12)
    said = describe_columns(m.attrs["columns"])
    assert "yaw_rate ← z (column 7, after 'AngularRate') [deg/s]" in said
    with pytest.raises(InputError, match=r"vx=VelocityBody.x or vx=AngularRate.x"):
        read_motion_table(p, "t=Time,vx=x,vy=VelocityBody.y,yaw_rate=AngularRate.z:dps")
    # a non-number in the data is named by its line in the file (the header has two lines)
    lines[5] = lines[5].replace(repr(float(VX[3])), "bad", 1)
    p.write_text("\n".join(lines) + "\n")
    with pytest.raises(InputError, match=r"ins2.csv: line 6, column 'x': 'bad' is not a number"):
        read_motion_table(
            p, "t=Time,vx=VelocityBody.x,vy=VelocityBody.y,yaw_rate=AngularRate.z:dps"
        )


def test_a_units_row_under_unique_names_is_not_a_header_of_vectors(tmp_path):
    """``Time,Vx,Vy`` over ``s,m/s,m/s``: still one header line (the units row is a row that
    is not a number, named as before)."""
    p = tmp_path / "units.csv"
    p.write_text("Time,Vx,Vy,Yaw\ns,m/s,m/s,rad/s\n0.0,1.0,0.1,0.01\n0.1,1.0,0.1,0.01\n")
    with pytest.raises(InputError, match=r"line 2, column 'Time': 's' is not a number"):
        read_motion_table(p, "t=Time,vx=Vx,vy=Vy,yaw_rate=Yaw")
