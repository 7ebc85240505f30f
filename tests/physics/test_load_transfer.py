"""Load transfer (docs/physics.md §4.2–§4.4; seed 000 eqs. 6.19–6.22)."""

from __future__ import annotations

import numpy as np
import pytest

from gripsense.physics import load_transfer as LT


def test_moment_balance_random():
    rng = np.random.default_rng(11)
    for _ in range(200):
        m = rng.uniform(600, 2500)
        f = rng.uniform(0.4, 0.65)
        masses = (m * f, m * (1 - f))
        h = rng.uniform(0.3, 0.8)
        tracks = tuple(rng.uniform(1.2, 1.7, 2))
        rc = tuple(rng.uniform(0.0, 0.25, 2))
        kf = rng.uniform(0.3, 0.8)
        ay = rng.uniform(-9, 9)
        df, dr = LT.lateral_load_transfer(ay, m, h, masses, tracks, rc, kf)
        assert df * tracks[0] + dr * tracks[1] == pytest.approx(m * ay * h, rel=1e-12)


def test_rigid_and_equal_split_special_cases():
    m, h, tracks, ay = 1200.0, 0.55, (1.5, 1.45), 4.0
    masses = (720.0, 480.0)
    rigid = LT.lateral_load_transfer(ay, m, h, masses, tracks)
    assert rigid[0] == pytest.approx(720 * ay * h / 1.5)
    assert rigid[1] == pytest.approx(480 * ay * h / 1.45)
    same = LT.lateral_load_transfer(ay, m, h, masses, tracks, (0.1, 0.1), 0.6)
    assert same[1] == pytest.approx(480 * ay * h / 1.45)
    # equal splits but different roll-centre heights: an extra term (docs/physics.md §4.2)
    diff = LT.lateral_load_transfer(ay, m, h, masses, tracks, (0.05, 0.15), 0.6)
    assert diff[1] != pytest.approx(480 * ay * h / 1.45)


def test_thesis_readings_physics_4_3():
    """480 kg rear axle, a_y = 1.929 m/s², h = 0.75 m, t = 1.10 m (b = 0.55 m)."""
    ay, h, b = 1.929, 0.75, 0.55
    axle = LT.thesis_load_transfer(480 * ay, h, b)
    assert axle == pytest.approx(631, abs=1)  # axle share: = rigid m_r a_y h / t
    assert axle == pytest.approx(LT.lateral_load_transfer(ay, 1200, h, (720, 480), (1.1, 1.1))[1])
    assert LT.thesis_load_transfer(240 * ay, h, b) == pytest.approx(316, abs=1)
    assert LT.thesis_load_transfer(1200 * ay, h, b) == pytest.approx(1578, abs=1)


def test_wheel_loads_and_axle_force():
    left, right = LT.wheel_loads(480.0, 631.0)
    assert left + right == pytest.approx(480 * 9.80665)
    assert right - left == pytest.approx(2 * 631.0)
    assert LT.axle_lateral_force(480.0, 1.929) == pytest.approx(925.92)
    # steady state: rear-axle force = m a_y l_f / L (docs/physics.md §4.4)
    m, lf, L, ay = 1200.0, 1.04, 2.6, 3.0
    assert LT.axle_lateral_force(m * lf / L, ay) == pytest.approx(m * ay * lf / L)
