"""The guard that refuses an upper end a linear tyre explains (docs/physics.md §15.8) tests all
of an axle's bins at once: a tyre that *is* linear passes it nine times in ten, with one bin or
with forty, and a noisier recording of it is not more often read as bent. Where a bin's force
and slip errors are independent (its slip did not move beyond its noise) the guard is at its 90 %
and no wider: adding the two parts' 90 % edges passed a linear tyre 95–99.9 % of the time, and
so refused upper ends the data allow."""

from __future__ import annotations

import numpy as np
import pytest

from gripsense.estimate.bins import BIN_COLUMNS
from gripsense.estimate.profile import Priors, _linear_explains

COL = {name: i for i, name in enumerate(BIN_COLUMNS)}
FZ, C = 4000.0, 60_000.0  # each wheel's load [N] and stiffness [N/rad]: C/Fz = 15 /rad


def _priors(stiffness_sd: float = 0.05, offset_deg: float = 1e-4) -> Priors:
    sd = np.full(9, 1e-3)
    sd[0], sd[5] = np.log1p(stiffness_sd), np.deg2rad(offset_deg)
    return Priors(np.zeros(9), sd, np.deg2rad(offset_deg), 20.0)


def _linear_bins(rng, n: int, slip_sd_deg: float, force_sd: float) -> np.ndarray:
    """*n* bins of an axle whose tyres are linear at the declared stiffness, each bin's slip and
    force drawn with the white noise the bin states (slip [deg], force per load [-])."""
    alpha = -np.deg2rad(rng.uniform(0.5, 3.0, n))  # ISO: a left turn's slips are negative
    force = -2 * C * np.tan(alpha)
    b = np.zeros((n, len(BIN_COLUMNS)))
    seen = alpha + np.deg2rad(slip_sd_deg) * rng.standard_normal(n)
    b[:, COL["alpha_L"]] = b[:, COL["alpha_R"]] = seen
    b[:, COL["fz_L"]] = b[:, COL["fz_R"]] = FZ
    b[:, COL["c_L"]] = b[:, COL["c_R"]] = C
    b[:, COL["force"]] = force + force_sd * 2 * FZ * rng.standard_normal(n)
    b[:, COL["force_sigma"]] = force_sd * 2 * FZ
    b[:, COL["slip_sigma"]] = np.deg2rad(slip_sd_deg)
    b[:, COL["force_model_sd"]] = 1e-4 * np.abs(force)
    return b


@pytest.mark.parametrize("n", [1, 4, 40])
def test_a_linear_tyre_is_explained_nine_times_in_ten_however_many_bins(n):
    rng = np.random.default_rng(n)
    pri = _priors()
    said = [_linear_explains(_linear_bins(rng, n, 0.1, 0.005), pri) for _ in range(400)]
    # at least 90 % (the stiffness's freedom inside its band only adds to it); 400 draws: the
    # binomial's 1σ at 0.9 is 0.015
    assert np.mean(said) >= 0.86


def test_more_noise_is_not_read_as_a_bend():
    rng = np.random.default_rng(7)
    pri = _priors()
    for slip_sd in (0.05, 0.2):
        said = [_linear_explains(_linear_bins(rng, 20, slip_sd, 0.002), pri) for _ in range(300)]
        assert np.mean(said) >= 0.86, slip_sd


@pytest.mark.parametrize("n", [1, 4, 20])
def test_a_steady_bin_is_tested_at_its_ninety_percent_not_wider(n):
    """Force and slip noise of comparable size (0.026 of the load each), the stiffness known: a
    linear tyre passes about nine times in ten (the old sum of the two edges: 0.985–0.999)."""
    rng = np.random.default_rng(10 + n)
    pri = _priors(stiffness_sd=1e-4)
    said = [_linear_explains(_linear_bins(rng, n, 0.1, 0.026), pri) for _ in range(1000)]
    # 1000 draws: the binomial's 1σ at 0.9 is 0.0095
    assert 0.86 <= np.mean(said) <= 0.94


def test_a_transient_bin_keeps_the_sum_of_its_edges():
    """A bin whose slip moved within it beyond its noise: its force and slip are not
    simultaneous, and their errors are not independent; the two 90 % edges add."""
    rng = np.random.default_rng(3)
    pri = _priors(stiffness_sd=1e-4)
    said = []
    for _ in range(1000):
        b = _linear_bins(rng, 1, 0.1, 0.026)
        b[:, COL["slip_spread"]] = 2.0 * b[:, COL["slip_sigma"]]
        said.append(_linear_explains(b, pri))
    assert np.mean(said) >= 0.95
