"""Antenna-to-wheel kinematics against hand-computed rigid-body cases (docs/physics.md §3)."""

from __future__ import annotations

import numpy as np
import pytest

from gripsense.physics import kinematics as K


def test_point_velocity_hand_computed():
    # U_A = 10 m/s, V_A = 0, left turn r = 0.5 rad/s; wheel 1 m behind, 0.5 m left of antenna:
    # v_P = v_A + ω × r_AP = (10, 0) + (−r·dy, r·dx) = (10 − 0.25, −0.5)
    u, v = K.point_velocity(10.0, 0.0, 0.5, -1.0, 0.5)
    assert (u, v) == (pytest.approx(9.75), pytest.approx(-0.5))
    # rear wheel slips to the outside: α < 0 in a left turn even with zero antenna side-slip
    a = K.slip_angle(u, v)
    assert a == pytest.approx(np.arctan2(-0.5, 9.75))
    assert a < 0


def test_left_turn_antenna_ahead_of_rear_axle():
    """Rigid body turning about a centre: every point's velocity is ⟂ to its radius vector."""
    r = 0.3  # rad/s, left
    centre = np.array([-1.2, 20.0])  # instantaneous centre in body axes relative to the antenna
    # antenna velocity = ω × (antenna − centre)
    rel = -centre
    u_a, v_a = -r * rel[1], r * rel[0]
    for dx, dy in [(-0.76, -0.205), (-0.76, 1.0), (1.8, 0.7), (0.0, 0.0)]:
        u, v = K.point_velocity(u_a, v_a, r, dx, dy)
        p = np.array([dx, dy]) - centre
        assert u == pytest.approx(-r * p[1], abs=1e-12)
        assert v == pytest.approx(r * p[0], abs=1e-12)
        assert K.path_radius(np.hypot(u, v), r) == pytest.approx(np.hypot(*p), rel=1e-12)


def test_thesis_sign_trap_size():
    """A wrong l_x sign shifts the rear slip by 2 l_x / R: 3.48° at R = 25 m (physics §3.2)."""
    R, l_x, v = 25.0, 0.76, 10.0
    r = v / R
    right = K.slip_angle(*K.point_velocity(v, 0.0, r, -l_x, 0.0))
    wrong = K.slip_angle(*K.point_velocity(v, 0.0, r, +l_x, 0.0))
    assert np.rad2deg(wrong - right) == pytest.approx(np.rad2deg(2 * l_x / R), rel=1e-3)
    assert np.rad2deg(2 * l_x / R) == pytest.approx(3.48, abs=0.01)


def test_antenna_sideslip_sign_and_wrap():
    # heading 10°, course 8°: the velocity points left of the heading -> β_A > 0 (ISO)
    assert K.antenna_sideslip(np.deg2rad(10), np.deg2rad(8)) == pytest.approx(np.deg2rad(2))
    # across north
    assert K.antenna_sideslip(np.deg2rad(1), np.deg2rad(359)) == pytest.approx(np.deg2rad(2))
    assert K.antenna_sideslip(np.deg2rad(359), np.deg2rad(1)) == pytest.approx(np.deg2rad(-2))
    # the mounting offset is removed from the heading
    assert K.antenna_sideslip(np.deg2rad(10), np.deg2rad(8), np.deg2rad(1.5)) == pytest.approx(
        np.deg2rad(0.5)
    )


def test_heading_offset_calibration():
    rng = np.random.default_rng(3)
    n = 400
    course = rng.uniform(0, 2 * np.pi, n)
    offset = np.deg2rad(1.2)
    heading = course + offset + rng.normal(0, np.deg2rad(0.3), n)
    yaw = np.where(np.arange(n) < 300, rng.normal(0, 0.005, n), 0.3)  # last 100 samples turning
    speed = np.full(n, 12.0)
    est, m, spread = K.heading_offset_from_straight(heading, course, yaw, speed)
    assert m == 300
    assert np.rad2deg(est) == pytest.approx(1.2, abs=0.1)
    assert np.rad2deg(spread) == pytest.approx(0.3, abs=0.05)
    # too little straight driving: not determined
    est, m, _ = K.heading_offset_from_straight(heading[:10], course[:10], yaw[:10], speed[:10])
    assert np.isnan(est) and m == 10
