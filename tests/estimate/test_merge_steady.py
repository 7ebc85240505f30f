"""Points of the tyre curve from bins (:func:`gripsense.estimate.bins.merge_steady`): a steady run
is one point, a run whose slip moves while its force stays (a tyre past its peak) is kept as
points, and the points at one level of force share one model error (``docs/physics.md`` §15.9).
Checked on bins built by hand; the ramp steer through the limit that this gives a value on is in
``test_friction_tells.py``."""

from __future__ import annotations

import numpy as np
import pytest

from gripsense.estimate.bins import BIN_COLUMNS, merge_steady

C = {name: i for i, name in enumerate(BIN_COLUMNS)}


def _bins(slip_deg, grip, slip_sigma_deg=0.05):
    """One 1 s bin of 10 samples per slip: both wheels at the slip, force = grip × load."""
    k = len(slip_deg)
    b = np.zeros((k, len(BIN_COLUMNS)))
    a = np.deg2rad(np.asarray(slip_deg, dtype=float))
    b[:, C["alpha_L"]] = b[:, C["alpha_R"]] = a
    b[:, C["fz_L"]] = b[:, C["fz_R"]] = 3000.0
    b[:, C["c_L"]] = b[:, C["c_R"]] = 40000.0
    b[:, C["grip"]] = grip
    b[:, C["force"]] = -grip * 6000.0
    b[:, C["force_sigma"]] = 30.0
    b[:, C["slip_sigma"]] = np.deg2rad(slip_sigma_deg)
    b[:, C["force_model_sd"]] = 0.04 * grip * 6000.0
    t0 = np.arange(k, dtype=float)
    return t0, t0 + 0.9, np.full(k, 10.0), b


def test_steady_run_is_one_point_with_or_without_the_slip_test():
    t0, t1, n, b = _bins([3.0, 3.02, 2.98, 3.01, 3.0], 0.3)
    for z in (np.inf, 4.0):
        mid, m = merge_steady(t0, t1, n, b, 0.03, slip_z=z, drift_sd=np.deg2rad(0.1))
        assert m.shape[0] == 1
        assert mid[0] == pytest.approx(np.mean(0.5 * (t0 + t1)))
        # white noise of a mean of five equal bins: σ/√5; the fidelity stays one bin's
        assert m[0, C["slip_sigma"]] == pytest.approx(np.deg2rad(0.05) / np.sqrt(5))
        assert m[0, C["force_model_sd"]] == pytest.approx(0.04 * 0.3 * 6000.0)


def test_plateau_with_moving_slip_is_kept_as_points():
    """Force steady, slip 3° → 8° at 1°/s: far beyond 4σ of the white noise (0.05°/bin) and of
    the drift's change (0.1° over 20 s, ≤ 0.03° a second) — six points, each carrying √6 of the
    model's fidelity, so the six weigh what the one merged point weighed."""
    slips = [3.0, 4.0, 5.0, 6.0, 7.0, 8.0]
    t0, t1, n, b = _bins(slips, 0.3)
    _, one = merge_steady(t0, t1, n, b, 0.03)
    assert one.shape[0] == 1
    assert np.rad2deg(one[0, C["alpha_L"]]) == pytest.approx(np.mean(slips))
    _, m = merge_steady(t0, t1, n, b, 0.03, slip_z=4.0, drift_sd=np.deg2rad(0.1), tau_s=20.0)
    assert m.shape[0] == 6
    assert np.rad2deg(m[:, C["alpha_L"]]) == pytest.approx(slips)
    assert m[:, C["force_model_sd"]] == pytest.approx(np.full(6, 0.04 * 0.3 * 6000.0 * np.sqrt(6)))
    # weights 1/σ² of the six points add up to the one point's
    assert np.sum(1 / m[:, C["force_model_sd"]] ** 2) == pytest.approx(
        1 / one[0, C["force_model_sd"]] ** 2
    )


def test_slip_within_the_drift_is_steady():
    """A slip change the slow heading error explains (0.5° over 10 s with a 1° drift of 20 s
    correlation: 1σ of the change ≈ 0.89°) is not a moving slip; with a 0.01° drift it is."""
    t0, t1, n, b = _bins(np.linspace(3.0, 3.5, 11), 0.3)
    b[:, C["slip_sigma"]] = 1e-5
    _, m = merge_steady(t0, t1, n, b, 0.03, slip_z=4.0, drift_sd=np.deg2rad(1.0), tau_s=20.0)
    assert m.shape[0] == 1
    _, m = merge_steady(t0, t1, n, b, 0.03, slip_z=4.0, drift_sd=np.deg2rad(0.01), tau_s=20.0)
    assert m.shape[0] > 1


def test_force_change_still_splits_and_starts_a_new_run():
    """A change of force splits as before; the fidelity of each run is its own."""
    t0, t1, n, b = _bins([1.0, 1.0, 3.0, 5.0], 0.3)
    b[:2, C["grip"]] = 0.1
    b[:2, C["force_model_sd"]] = 0.04 * 0.1 * 6000.0
    _, m = merge_steady(t0, t1, n, b, 0.03, slip_z=4.0, drift_sd=np.deg2rad(0.1))
    assert m.shape[0] == 3
    assert m[0, C["force_model_sd"]] == pytest.approx(0.04 * 0.1 * 6000.0)
    assert m[1:, C["force_model_sd"]] == pytest.approx(np.full(2, 0.04 * 0.3 * 6000.0 * np.sqrt(2)))


def test_repeated_visits_of_one_level_share_the_model_error():
    """A slalom passes the same part of the curve again and again (left and right): the points
    at one level of |grip| share one model error, wherever they are in time; other levels keep
    their own."""
    t0, t1, n, b = _bins([1.0, 2.0, -1.0, -2.0, 1.0, -1.0], 0.2)
    b[:, C["grip"]] = [0.10, 0.20, 0.10, 0.20, 0.10, 0.10]
    b[:, C["force_model_sd"]] = 0.04 * b[:, C["grip"]] * 6000.0
    _, m = merge_steady(t0, t1, n, b, 0.03, slip_z=4.0, drift_sd=np.deg2rad(0.1))
    assert m.shape[0] == 6  # the force or the slip changes at every bin
    k = np.where(m[:, C["grip"]] < 0.15, np.sqrt(4), np.sqrt(2))
    assert m[:, C["force_model_sd"]] == pytest.approx(0.04 * m[:, C["grip"]] * 6000.0 * k)
