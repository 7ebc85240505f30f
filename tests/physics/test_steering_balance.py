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


def test_friction_state_by_hand():
    """Travel 1 mrad, no noise (band 2 mrad), worked by hand: the direction is unknown until
    the steer has moved by the band; steering left is +1 once built up (1 mrad from where it
    began); unwinding is confirmed 2 mrad below the maximum and began after its last sample
    within the margin (1 mrad) of it (the samples between are not known); a hold keeps the
    state; a correction smaller than the band is not seen; NaN: not known."""
    from gripsense.physics.steering_balance import friction_state

    d = np.array([0.0, 1.0, 2.5, 4.0, 4.0, 3.5, 2.0, 1.0, 1.0, np.nan, 1.0, 2.5, 0.0]) * 1e-3
    state, known = friction_state(d, 0.0, 1e-3)
    #            0    1    2    3    4    5    6     7     8     9   10    11    12
    want = [0.0, 0.0, 1.0, 1.0, 1.0, 1.0, 0.0, -1.0, -1.0, 0.0, -1.0, -1.0, -1.0]
    np.testing.assert_array_equal(state, want)
    np.testing.assert_array_equal(known, np.abs(want) > 0)
    # unwinding confirmed at 1 (3 below the first sample), then a reversal confirmed at 3.5:
    # the sample after the minimum is not known once it is more than the margin above it
    state, known = friction_state(np.array([4.0, 2.0, 1.0, 2.1, 3.5, 5.0]) * 1e-3, 0.0, 1e-3)
    np.testing.assert_array_equal(state, [0.0, 0.0, -1.0, 0.0, 1.0, 1.0])


def test_friction_state_holds_through_noise():
    """A turn-in, then a hold read with white noise: the state stays +1 (the Dahl model's
    memory) on almost every sample; the Dahl model run on the same noisy samples wanders —
    the physical law is no estimator of its own state."""
    from gripsense.physics.steering_balance import friction_state

    rng = np.random.default_rng(5)
    sd = 2e-4
    d = np.concatenate([np.linspace(0.0, 0.05, 100), np.full(900, 0.05)])
    d = d + rng.normal(0.0, sd, d.size)
    state, known = friction_state(d, sd, 0.002)
    assert np.all(state[known] == 1.0)
    assert known[100:].mean() > 0.9
    dahl = dahl_friction(d, 1.0, 0.002)
    assert np.min(dahl[100:]) < 0.0


def test_backlash_by_hand():
    """The play operator, half-width 1, worked by hand: the output holds until the input is
    more than 1 away, then follows at that distance; NaN holds it."""
    from gripsense.physics.steering_balance import backlash

    x = np.array([0.0, 0.5, 1.5, 3.0, 2.5, 1.0, 0.5, np.nan, 0.6, -1.0])
    want = [0.0, 0.0, 0.5, 2.0, 2.0, 2.0, 1.5, 1.5, 1.5, 0.0]
    np.testing.assert_allclose(backlash(x, 1.0), want)


def test_a_held_steer_keeps_its_friction_behind_the_deadband():
    """The Dahl model along a held, noisy steer drifts towards zero (a step back reverses the
    friction, a step on builds nothing); behind a deadband of 4σ the hold keeps +1 — what
    learned the steering's lever 4–7 % high when it drifted (docs/physics.md §16.6)."""
    from gripsense.physics.steering_balance import backlash

    rng = np.random.default_rng(2)
    sd = 3e-4
    d = np.concatenate([np.linspace(0.0, 0.03, 30), np.full(300, 0.03)])
    noisy = d + rng.normal(0.0, sd, d.size)
    drifted = dahl_friction(noisy, 1.0, 0.002)
    held = dahl_friction(backlash(noisy, 4 * sd), 1.0, 0.002)
    assert np.mean(drifted[100:]) < 0.7
    assert np.min(held[100:]) > 0.95
