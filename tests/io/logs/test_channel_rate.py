"""A steering-torque channel read at its own rate (issue "The steering torque that never
misleads", item 2): every sample of a 100 Hz channel is averaged into the 10 Hz epochs."""

from __future__ import annotations

import numpy as np
import pandas as pd

from gripsense.io.sensors.steer import channel_mean_at, with_torque


def _channel(rate_hz=100.0, seconds=20.0, noise=0.5, seed=3):
    rng = np.random.default_rng(seed)
    t = np.arange(0.0, seconds, 1.0 / rate_hz) + 0.003
    x = 2.0 * np.sin(0.3 * t) + rng.normal(0.0, noise, t.size)
    return pd.DataFrame({"t_s": t, "steer_rad": np.nan, "torque_nm": x})


def test_every_sample_in_its_epoch():
    """Each epoch averages the samples within half a step of it, by a loop written here."""
    ch = _channel()
    te = np.arange(1.0, 19.0, 0.1)
    got, n = channel_mean_at(ch, "torque_nm", te)
    tc, x = ch["t_s"].to_numpy(), ch["torque_nm"].to_numpy()
    for k, tk in enumerate(te):
        sel = (tc >= tk - 0.05) & (tc < tk + 0.05)
        assert n[k] == sel.sum() == 10
        assert got[k] == np.float64(x[sel].mean()) or abs(got[k] - x[sel].mean()) < 1e-12
    # all of the channel's samples between the first and the last epoch are used once
    inside = (tc >= te[0] - 0.05) & (tc < te[-1] + 0.05)
    assert n.sum() == inside.sum()


def test_noise_falls_with_the_samples():
    """White noise of the per-epoch values: ~σ/√10 averaged, ~σ interpolated (successive
    differences, the estimator's own measure)."""
    ch = _channel(noise=0.5, seconds=200.0)
    te = np.arange(1.0, 199.0, 0.1)
    got, _ = channel_mean_at(ch, "torque_nm", te)
    interp = np.interp(te, ch["t_s"], ch["torque_nm"])
    sd_mean = np.std(np.diff(got)) / np.sqrt(2)
    sd_interp = np.std(np.diff(interp)) / np.sqrt(2)
    assert 0.5 / np.sqrt(10) * 0.85 < sd_mean < 0.5 / np.sqrt(10) * 1.15
    assert sd_interp > 2.0 * sd_mean


def test_a_slow_channel_is_interpolated():
    """A 5 Hz channel at 10 Hz epochs: epochs between its samples take the interpolation and
    count no sample; outside the channel, NaN."""
    ch = _channel(rate_hz=5.0, noise=0.0)
    te = np.arange(-1.0, 19.0, 0.1)
    got, n = channel_mean_at(ch, "torque_nm", te)
    ref = np.interp(te, ch["t_s"], ch["torque_nm"])
    inside = te >= ch["t_s"].iloc[0]
    none = inside & (n == 0)
    assert none.sum() > 0.4 * inside.sum()
    np.testing.assert_allclose(got[none], ref[none])
    before = te < ch["t_s"].iloc[0] - 0.05  # no sample within half a step
    assert np.isnan(got[before]).all() and (n[before] == 0).all()


def test_with_torque_counts_the_samples():
    ep = pd.DataFrame({"t_s": np.arange(1.0, 10.0, 0.1)})
    out = with_torque(ep, _channel())
    assert (out["torque_samples"] == 10).all()
    assert "torque_samples" not in ep.columns


def test_jittered_epochs_lose_no_sample():
    """Epoch times read from NMEA carry float jitter (0.0999999, 0.20000005 …): every sample
    between the first and the last epoch's interval is still counted once."""
    ch = _channel()
    rng = np.random.default_rng(1)
    te = np.arange(1.0, 19.0, 0.1) + rng.uniform(-2e-7, 2e-7, 180)
    _, n = channel_mean_at(ch, "torque_nm", te)
    tc = ch["t_s"].to_numpy()
    assert (n == 10).all()
    assert n.sum() == ((tc >= 0.5 * (te[0] + te[0] - 0.1)) & (tc < te[-1] + 0.05)).sum()
