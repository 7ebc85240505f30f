"""The steering balance (docs/physics.md §16.3; seed 003 eqs. 3, 5) against hand calculations."""

from __future__ import annotations

import numpy as np
import pytest

from gripsense.physics import brush
from gripsense.physics.steering_balance import column_torque, dahl_friction, steering_moment


def test_steady_column_torque_by_hand():
    """Steady left turn, brush front tyres at u = 0.5 each: F = 0.5 μ Fz, t = 0.62 t₀ (§16.1),
    caster trail 20 mm, ratio 15, assist gain 3, no friction. By hand:
    M_s = 2 (0.020 + 0.62 × 0.0233) × 1800 = 124.0 N m; T_col = 124.0/(15 × 4) = 2.07 N m."""
    mu, fz, c, a = 0.9, 4000.0, 60000.0, 0.07
    lam = 1 - 0.5 ** (1 / 3)
    alpha = np.arctan(lam * 3 * mu * fz / c)
    f = brush.lateral_force(mu, alpha, fz, c)
    mz, t = brush.aligning_moment(mu, alpha, fz, c, a)
    assert f == pytest.approx(1800.0, rel=1e-9)
    assert t / (a / 3) == pytest.approx(0.62, abs=0.002)
    m_s = 2 * steering_moment(f, -mz, 0.020)  # ISO: Mz = −t F for F > 0
    assert m_s == pytest.approx(2 * (0.020 + t) * 1800.0, rel=1e-12)
    assert m_s == pytest.approx(124.0, abs=0.3)
    tq = column_torque(m_s, 0.0, 0.0, 0.0, ratio=15.0, assist_gain=3.0)
    assert tq == pytest.approx(2.07, abs=0.01)


def test_dynamic_terms_and_signs():
    """I_s (δ̈ + ṙ) + C_s δ̇ add to the moment; a right turn mirrors everything."""
    tq = column_torque(
        [100.0, -100.0], [0.1, -0.1], [0.5, -0.5], [5.0, -5.0], ratio=16.0, assist_gain=1.0,
        kingpin_inertia_kgm2=2.0, kingpin_damping_Nms=40.0, yaw_accel_rps2=[0.2, -0.2],
    )  # fmt: skip
    by_hand = (100.0 + 2.0 * 0.7 + 40.0 * 0.1 + 5.0) / 32.0
    np.testing.assert_allclose(tq, [by_hand, -by_hand], rtol=1e-12)


def test_dahl_friction_holds_its_last_motion():
    """Steer left and hold: the friction reaches +M_c and stays; steer back: it reverses to −M_c
    within a few travel lengths; never beyond ±M_c."""
    d = np.concatenate([np.linspace(0, 0.05, 200), np.full(100, 0.05), np.linspace(0.05, 0, 200)])
    f = dahl_friction(d, 10.0, travel_rad=0.002)
    assert f[0] == 0.0
    assert f[199] == pytest.approx(10.0, rel=1e-3)
    np.testing.assert_allclose(f[200:300], f[199])
    assert f[-1] == pytest.approx(-10.0, rel=1e-3)
    assert np.all(np.abs(f) <= 10.0)
    assert np.all(dahl_friction(d, 0.0) == 0.0)
