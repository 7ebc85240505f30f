"""The compiled grid score of the resampling search (``estimate/_resample_kernel.py``) against
the numpy fit it replaces in the search (``wheels._fit_score``: bincounts and LAPACK's banded
solve), on random epochs, columns, grids and stamp errors."""

from __future__ import annotations

import numpy as np
import pytest

from gripsense.estimate import wheels as W
from gripsense.estimate._resample_kernel import hat_score


@pytest.mark.parametrize("seed", range(8))
def test_the_compiled_score_is_the_numpy_fit(seed):
    rng = np.random.default_rng(seed)
    for _ in range(40):
        n, m = int(rng.integers(20, 200)), int(rng.integers(1, 5))
        dt = rng.uniform(0.01, 0.2)
        t = np.cumsum(np.full(n, dt) + rng.normal(0, dt * 0.01, n)) + rng.uniform(0, 100)
        y = np.cumsum(rng.normal(0, 3, (n, m)), axis=0) * rng.choice([1e-3, 1.0, 100.0])
        period = dt * rng.uniform(1.05, 12.0)
        phase, e_t = rng.uniform(0, period), float(rng.choice([0.0, 1e-4, 5e-3]))
        want, n_free, _ = W._fit_score(t, y, e_t, period, phase)
        got, n_free_k = hat_score(t, y, period, phase, e_t, W._SMOOTH)
        assert n_free_k == n_free
        if n_free > 0:
            assert got == pytest.approx(want, rel=1e-9, abs=1e-12)


def test_a_resampled_line_scores_zero_on_its_grid_and_not_off_it():
    """Epochs linearly interpolated between a 10 Hz grid's knots fit that grid exactly; the
    same epochs on a grid a third of a period off do not."""
    rng = np.random.default_rng(1)
    knots_t = np.arange(0.0, 10.0, 0.1)
    knots_y = np.cumsum(rng.normal(0, 50, (knots_t.size, 2)), axis=0)
    t = np.arange(0.0, 9.9, 1 / 25)
    y = np.column_stack([np.interp(t, knots_t, c) for c in knots_y.T])
    on, _ = hat_score(t, y, 0.1, 0.0, 0.0, W._SMOOTH)
    off, _ = hat_score(t, y, 0.1, 0.1 / 3, 0.0, W._SMOOTH)
    assert on < 1e-6 and off > 1.0  # (the knots' tiny smoothing weight leaves ~1e-8)
