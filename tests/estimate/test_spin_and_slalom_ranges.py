"""Slaloms on a slippery road: a spinning axle's bins are not points of the tyre's curve, and a
range is every μ the profile does not exclude (``docs/physics.md`` §15.3, §15.8).

Truth: gripsense's simulator with tyres the estimator does not share (a Magic Formula sports
car, a brush-tyred SUV), driven through a 7° slalom at 60 km/h on μ 0.3 — beyond the limit: the
sports car's rear spins out (slips of 40–100°, its drive torque saturating the rear), the SUV's
front ploughs to 30–37°. Both used to state a value whose lower end lay above the true μ
(0.33–0.39 for 0.30): the spin's bins, a force near zero at 23° of slip, read as the falling
tail of a higher peak, and the profile's range stopped at a bump of its deviance between the
truth and its minimum.
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from gripsense import FrictionRun
from gripsense.constants import CHI2_1_90
from gripsense.estimate.bins import BIN_COLUMNS, SPIN_SLIP_RAD, axle_pairs, on_the_curve
from gripsense.estimate.evidence import curve_range
from gripsense.estimate.noise import NoiseModel
from gripsense.estimate.profile import DEVIANCE_STEP, _crossing, mu_grid
from gripsense.io import read_nmea
from gripsense.io.sensors.steer import steer_at
from gripsense.sim import maneuvers as M
from gripsense.sim.drives import simulate_drive, truth_vehicle, user_vehicle


def _slalom(vehicle: str, tyre: str, receiver: str, seed: int, stiffness_error: float):
    amp = np.deg2rad(7.0)
    t = np.linspace(0.0, 24.0, 1201)
    steer = np.where(t < 6.0, 0.0, amp * np.sin(2 * np.pi * (t - 6.0) / 3.0))
    m = M.slalom(60 / 3.6, amplitude_rad=amp, period_s=3.0, cycles=8)
    m.steer_table, m.duration_s, m.settle_s = (t, steer), 24.0, 6.0
    d = simulate_drive(vehicle, tyre, m, 0.3, receiver=receiver, seed=seed)
    uv = user_vehicle(truth_vehicle(vehicle), tyre, stiffness_error=stiffness_error)
    ep = read_nmea(d.lines).epochs
    ch = d.steer.assign(steer_rad=np.deg2rad(d.steer["road_wheel_deg"]))
    run = FrictionRun(uv, method="axle-window", noise=NoiseModel.for_vehicle(uv, receiver))
    res = run.run(ep, steer_rad=steer_at(ch, ep["t_s"].to_numpy(float)))
    return d, res


@pytest.mark.parametrize(
    ("vehicle", "tyre", "receiver", "seed", "stiffness_error", "axle"),
    [
        ("sports", "mf-book", "white-0.3", 77, 0.0, "rear"),  # spins out
        ("suv", "brush", "white-0.3", 41, -0.062, "front"),  # ploughs
    ],
)
def test_a_slalom_beyond_the_limit_never_overstates_mu(
    vehicle, tyre, receiver, seed, stiffness_error, axle
):
    d, res = _slalom(vehicle, tyre, receiver, seed, stiffness_error)
    truth = d.axles.set_index("axle")
    s = res.summary.set_index("axle")
    for ax, t in truth.iterrows():
        r = s.loc[ax]
        assert r["grip_used_lower"] <= t["mu_true"] + 0.01, ax
        if np.isfinite(r["mu_low"]):
            assert r["mu_low"] <= t["mu_true"] <= r["mu_high"], (ax, r["mu_low"], r["mu_high"])
    # the axle went past the curve's domain: some of its bins are not points of the curve
    assert truth.loc[axle, "utilisation_max"] > 0.95
    pairs = axle_pairs(res.wheels, axle)
    slip = np.maximum(np.abs(pairs["slip_angle_rad_L"]), np.abs(pairs["slip_angle_rad_R"]))
    assert np.max(slip) > SPIN_SLIP_RAD


def test_a_spin_is_not_a_point_of_the_curve():
    """A wheel's mean slip beyond 30° (past the peak of every library tyre, PAC89's at ~28°
    included), or a slip sweeping by more than 5° (1σ) within the bin (a car rotating through
    it), is not a point of the lateral curve; a steady 28° and a turn-in's 4° spread are."""
    slip = np.deg2rad([3.0, 28.0, -29.0, 31.0, -95.0, 2.0, 6.6, 12.0])
    spread = np.deg2rad([0.5, 0.3, 1.0, 0.3, 10.0, 4.0, 5.5, 2.4])
    b = np.zeros((slip.size, len(BIN_COLUMNS)))
    b[:, 0] = b[:, 1] = slip
    b[:, BIN_COLUMNS.index("slip_spread")] = spread
    assert on_the_curve(b).tolist() == [True, True, True, False, False, True, False, True]
    b[0, 1] = np.deg2rad(31.0)  # one wheel beyond is enough
    assert not on_the_curve(b)[0]


def _hull(grid: np.ndarray, dev: np.ndarray, level: float) -> tuple[float, float]:
    """The reference: the smallest and largest grid μ whose deviance is within the level."""
    inside = grid[dev <= level]
    return float(inside.min()), float(inside.max())


@settings(max_examples=200, deadline=None)
@given(
    st.lists(st.integers(0, 255), min_size=8, max_size=40),
    st.floats(0.5, 6.0),
)
def test_a_range_holds_every_mu_its_curve_does_not_exclude(steps, level):
    """Whatever its bumps, the stated range contains every grid μ whose deviance is within the
    level, and no grid μ outside it is within the level — in the profile (``_crossing``) and in
    a stored curve read back (``curve_range``) alike."""
    q = np.array(steps, dtype=float)
    q -= q.min()
    grid = mu_grid(0.05, 3.0, q.size)
    dev = q * DEVIANCE_STEP
    lo_ref, hi_ref = _hull(grid, dev, level)
    lo, hi = _crossing(grid, dev, level, -1), _crossing(grid, dev, level, +1)
    low, high, _ = curve_range(q[None, :], grid, level)
    for a, b in ((lo, hi), (float(low[0]), float(high[0]))):
        assert a <= lo_ref + 1e-12 and b >= hi_ref - 1e-12
        outside = (grid < a - 1e-12) | (grid > b + 1e-12)
        assert np.all(dev[outside] > level)
        # the ends lie between the last grid point inside and the first outside
        below = grid[grid < lo_ref]
        assert a >= (below.max() if below.size else grid[0]) - 1e-12
        above = grid[grid > hi_ref]
        assert b <= (above.min() if above.size else np.inf) + 1e-12
    assert lo == pytest.approx(float(low[0])) and hi == pytest.approx(float(high[0]))


def test_a_bump_between_the_truth_and_the_minimum_does_not_cut_the_range():
    """The SUV's profile on μ 0.3 (deviance at μ 0.29 / 0.31 / 0.34 / 0.41: 3.06 / 1.88 / 2.86
    / 0): the range reaches down past the bump at 0.34 to the truth."""
    grid = np.array([0.24, 0.286, 0.312, 0.34, 0.372, 0.405, 0.44, 0.482])
    dev = np.array([9.79, 3.06, 1.88, 2.86, 1.0, 0.0, 2.0, 8.62])
    lo = _crossing(grid, dev, CHI2_1_90, -1)
    assert 0.286 < lo < 0.312
