"""A window's stored curve says what the window says (``docs/physics.md`` §15.12).

Windows of a drive recorded from a Magic Formula truth tyre (not the estimator's own curves):
each window's curve, read back with the combination's range reader, holds the window's stated
range and is within a few per cent of it — rounding down only widens a range."""

from __future__ import annotations

import numpy as np
import pytest

from gripsense.estimate.evidence import (
    curve_grid,
    curve_range,
    curves_from_bytes,
    gaussian_curves,
    reduce_groups,
)
from gripsense.estimate.profile import DEVIANCE_CAP, DEVIANCE_STEP, _crossing, deviance_curve
from gripsense.pipeline import FrictionRun
from gripsense.sim.drives import limit_speed, simulate_drive, truth_vehicle, user_vehicle


@pytest.fixture(scope="module")
def windows(tmp_path_factory):
    """Windows of a steady circle at 0.95 of a μ 0.9 road and one at 0.95 of μ 0.5."""
    tv = truth_vehicle("sedan")
    uv = user_vehicle(tv, "mf-sedan", stiffness_error=-0.1, stiffness_uncertainty=0.2)
    d = tmp_path_factory.mktemp("evidence")
    out = []
    for k, (mu, u) in enumerate([(0.9, 0.95), (0.5, 0.95)]):
        drive = simulate_drive(tv, "mf-sedan", None, mu, receiver="white-0.3", seed=3,
                               circle=(limit_speed(mu, 40.0, u), 40.0))  # fmt: skip
        log, steer = d / f"d{k}.nmea", d / f"d{k}_steer.csv"
        log.write_text("\n".join(drive.lines) + "\n", encoding="ascii")
        drive.steer.to_csv(steer, index=False)
        out.append(FrictionRun(uv, receiver="white-0.3").run_log(log, steer_csv=steer).windows)
    return out


def test_a_windows_curve_holds_its_range_within_two_percent(windows):
    grid = curve_grid()
    n_bounded = n_value = 0
    for w in windows:
        has = w["mu_deviance"].notna().to_numpy()
        assert has[w["analysed"].to_numpy(bool) & (w["fit"] != "inconsistent").to_numpy()].all()
        lo, hi, mn = curve_range(curves_from_bytes(w.loc[has, "mu_deviance"], grid.size), grid)
        bound = w.loc[has, "grip_used_lower"].to_numpy(float)
        lo = np.fmax(lo, bound)
        s_lo, s_hi = w.loc[has, "mu_low"].to_numpy(float), w.loc[has, "mu_high"].to_numpy(float)
        assert np.all(mn == 0)  # one window's curve: its minimum is its own
        assert np.all(lo <= s_lo + 1e-12) and np.all(hi >= s_hi - 1e-12)  # never narrower
        assert np.all(lo >= 0.98 * s_lo)
        fin = np.isfinite(s_hi)
        assert not np.any(np.isfinite(hi) & ~fin)  # no upper end the window does not state
        # rounding down can lose an upper end only in the grid's last step (above 2.75)
        lost = fin & ~np.isfinite(hi)
        assert np.all(s_hi[lost] > grid[-2])
        # within 2 % up to μ 1.5; above, where the deviance rises slowly, within a grid step
        near, far = fin & ~lost & (s_hi <= 1.5), fin & ~lost & (s_hi > 1.5)
        assert np.all(hi[near] <= 1.02 * s_hi[near])
        assert np.all(hi[far] <= grid[1] / grid[0] * s_hi[far])
        n_bounded += int(fin.sum())
        n_value += int(w.loc[has, "observable"].sum())
    assert n_bounded >= 10 and n_value >= 3  # the check saw bounded ranges and values


def test_a_side_the_window_does_not_state_is_flat():
    """The encoder flattens an untrusted side: no lower end without a value, no upper end
    where a linear tyre explains the data; everything else rounded down and capped."""
    grid = curve_grid()
    dev = (np.log(grid / 0.6) / 0.05) ** 2
    i = int(np.argmin(dev))
    dev -= dev[i]
    both = np.frombuffer(deviance_curve(dev, i, lower_trusted=True, upper_trusted=True), np.uint8)
    assert np.all(both * DEVIANCE_STEP <= dev + 1e-12)
    assert np.all((both == DEVIANCE_CAP) | (both * DEVIANCE_STEP > dev - DEVIANCE_STEP))
    up = np.frombuffer(deviance_curve(dev, i, lower_trusted=False, upper_trusted=True), np.uint8)
    assert np.all(up[:i] == 0) and np.array_equal(up[i:], both[i:])
    lo, hi, _ = curve_range(up[None].astype(np.int32), grid)
    assert lo[0] == grid[0] and hi[0] == pytest.approx(
        _crossing(grid, both * DEVIANCE_STEP, 2.705543454095404, +1)
    )


def test_gaussian_curves_and_group_reductions_against_closed_forms():
    grid = curve_grid()
    g = gaussian_curves(np.array([0.5]), np.array([0.05]), grid)
    lo, hi, _ = curve_range(g, grid)
    half = 0.05 * np.sqrt(2.705543454095404)
    assert lo[0] == pytest.approx(0.5 - half, rel=0.02) and hi[0] == pytest.approx(
        0.5 + half, rel=0.02
    )
    c = np.array([[1, 5, 2], [3, 1, 0], [7, 7, 7]], np.int32)
    ids, mx = reduce_groups(c, np.array([4, 2, 4]), "max")
    assert ids.tolist() == [2, 4] and mx.tolist() == [[3, 1, 0], [7, 7, 7]]
    ids, sm = reduce_groups(c, np.array([1, 1, 0]), "sum")
    assert sm.tolist() == [[7, 7, 7], [4, 6, 2]]
