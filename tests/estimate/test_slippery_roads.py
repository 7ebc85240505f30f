"""Cornering on slippery roads (issue 41, item 4): the screen asks what the compass resolves, not
how much grip was used.

Truth: gripsense's simulator with a Magic Formula tyre (``PacejkaBook_Defaults.tir``) that the
estimator does not share (it sees the NMEA text, a steering channel and the vehicle file a user
would write). On ice and packed snow a car at its limit corners at 0.1–0.2 g — below the old
screen's absolute 0.15 g — with slip angles a compass resolves over a 3 s window. The screen
itself is checked against its own noise definition (``docs/physics.md`` §15.2): noise alone
never passes it.
"""

from __future__ import annotations

import numpy as np
import pytest

from gripsense import FrictionRun
from gripsense.estimate import WindowOptions
from gripsense.estimate.bins import BIN_COLUMNS
from gripsense.estimate.noise import NoiseModel, receiver_noise
from gripsense.estimate.screen import offset_residual_rad, resolvable
from gripsense.io import read_nmea
from gripsense.io.sensors.steer import steer_at
from gripsense.physics.surface import SLIPPERY_MU
from gripsense.sim import maneuvers as M
from gripsense.sim.drives import limit_speed, simulate_drive, truth_vehicle, user_vehicle

R = 30.0  # [m]


def estimate(drive, vehicle, receiver, **options):
    ep = read_nmea(drive.lines).epochs
    ch = drive.steer.assign(steer_rad=np.deg2rad(drive.steer["road_wheel_deg"]))
    steer = steer_at(ch, ep["t_s"].to_numpy(float))
    run = FrictionRun(vehicle, method="axle-window", receiver=receiver, **options)
    return run.run(ep, steer_rad=steer)


@pytest.mark.parametrize("receiver", ["rtk", "white-0.3"])
def test_packed_snow_at_its_limit_is_analysed_and_slippery(receiver):
    """μ 0.15 at 85 % of the grip (0.13 g, 6.1 m/s on R 30 m): both axles are analysed and read
    slippery (their upper end below 0.5), the ranges hold the truth and the model-free bound
    stays below it. The old screen (0.15 g) analysed nothing here: 'unknown'."""
    mu, u = 0.15, 0.85
    d = simulate_drive(
        "sedan", "mf-book", None, mu, receiver=receiver, seed=41,
        circle=(limit_speed(mu, R, u), R),
    )  # fmt: skip
    truth = d.axles.set_index("axle")
    assert (truth["utilisation"] >= 0.8).all() and (truth["grip_max"] < 0.15).all()
    res = estimate(d, user_vehicle(truth_vehicle("sedan"), "mf-book"), receiver)
    s = res.summary.set_index("axle")
    for axle, t in truth.iterrows():
        r = s.loc[axle]
        assert r["n_screened"] < r["n_windows"], axle  # analysed
        assert r["fit"] not in ("screened", "no data"), axle
        assert r["mu_high"] < SLIPPERY_MU and r["slippery"] == "slippery", (axle, r["mu_high"])
        assert r["mu_low"] <= t["mu_true"] <= r["mu_high"], (axle, r["mu_low"], r["mu_high"])
        assert r["grip_used_lower"] <= t["mu_true"] + 0.01, axle


@pytest.mark.parametrize("u", [0.15, 0.85])
def test_a_dry_road_is_never_slippery(u):
    """μ 0.9, at everyday grip (0.14 g: now analysed, the slip resolved) and near the limit:
    no axle reads slippery, and near the limit both read 'not slippery'."""
    mu = 0.9
    d = simulate_drive(
        "sedan", "mf-book", None, mu, receiver="v100", seed=43,
        circle=(limit_speed(mu, 40.0, u), 40.0),
    )  # fmt: skip
    res = estimate(d, user_vehicle(truth_vehicle("sedan"), "mf-book"), "v100")
    s = res.summary.set_index("axle")
    assert (s["slippery"] != "slippery").all(), s[["mu_low", "mu_high"]]
    assert (s["n_screened"] < s["n_windows"]).all()  # analysed at 0.14 g too
    if u > 0.8:
        assert (s["slippery"] == "not slippery").all(), s[["mu_low", "mu_high"]]


def _bins(m, slip, ay_g, noise, n=10, c=60_000.0, fz=4_000.0):
    """(k, m) windows of bins with a given axle slip [rad] and lateral acceleration [g]: the
    axle force the declared stiffness C per wheel needs for that slip, and the white noise of
    a bin of n samples at 10 m/s."""
    k = np.broadcast(slip, ay_g).shape[0]
    d = np.zeros((k, m, len(BIN_COLUMNS)))
    d[..., 0] = d[..., 1] = np.asarray(slip)[:, None]
    d[..., 2] = d[..., 3] = fz
    d[..., 4] = d[..., 5] = c
    d[..., 6] = -2.0 * c * np.asarray(slip)[:, None]
    sig_slip = np.hypot(np.deg2rad(noise.heading_white_deg), noise.velocity_mps / 10.0)
    d[..., 8] = sig_slip / np.sqrt(n)
    d[..., 10] = np.asarray(ay_g)[:, None]
    gsig = np.full((k, m), 0.002)
    return d, gsig


@pytest.mark.parametrize("receiver", ["v100", "white-0.3", "rtk"])
def test_screen_threshold_is_its_noise_definition(receiver):
    """A window passes exactly when the slip its force needs is ≥ z √(Σσ²/m² + σ_cal²) and its
    mean lateral acceleration ≥ z √(Σσ_grip²)/m (closed form from the noise model)."""
    noise = receiver_noise(receiver)
    z, m = WindowOptions().screen_z, 3
    d0, _ = _bins(1, np.array([0.0]), np.array([0.0]), noise)
    sig_w = np.hypot(d0[0, 0, 8] / np.sqrt(m), offset_residual_rad(noise))
    sig_ay = np.sqrt(m * 0.002**2) / m
    slip = np.array([0.9, 1.1, 1.1, 1.1]) * z * sig_w
    ay = np.array([0.1, 0.1, 0.9 * z * sig_ay, 1.1 * z * sig_ay])  # 0.1 g: plenty
    d, g = _bins(m, slip, ay, noise)
    assert resolvable(d, g, noise, z).tolist() == [False, True, False, True]


@pytest.mark.parametrize("receiver", ["v100", "white-0.3", "rtk"])
def test_noise_alone_never_passes_the_screen(receiver):
    """Bins of a straight (zero slip and force, zero lateral acceleration) with the receiver's
    white noise and a calibration residual drawn from its stated σ: none of 20 000 windows
    passes."""
    rng = np.random.default_rng(7)
    noise = NoiseModel(**{**receiver_noise(receiver).__dict__, "heading_calibration_deg": 0.05})
    k, m = 20_000, 3
    d, g = _bins(m, np.zeros(k), np.zeros(k), noise)
    offset = rng.normal(0.0, offset_residual_rad(noise), (k, 1))
    slip = offset + rng.normal(0.0, 1.0, (k, m)) * d[..., 8]
    d[..., 0] = d[..., 1] = slip  # what the compass reads; the force reads none
    force_sd = 2.0 * 4_000.0 * 0.002
    d[..., 6] = rng.normal(0.0, force_sd, (k, m))
    d[..., 10] = rng.normal(0.0, 1.0, (k, m)) * g
    assert not resolvable(d, g, noise, WindowOptions().screen_z).any()


def test_straight_drive_with_noise_only_is_never_analysed():
    """A 60 s straight at 15 m/s recorded by a V100-class receiver, the per-sample cornering
    gates switched off so that every noisy sample is binned: no window is analysed and no axle
    says anything but the measured-grip bound ('no cornering the compass resolves')."""
    d = simulate_drive(
        "sedan", "mf-book", M.fixed_steer(15.0, 0.0, duration_s=60.0), 0.9, receiver="v100",
        seed=44,
    )  # fmt: skip
    res = estimate(
        d, user_vehicle(truth_vehicle("sedan"), "mf-book"), "v100",
        min_lateral_accel_mps2=0.0, min_yaw_rate_dps=0.0,
    )  # fmt: skip
    w = res.windows
    assert len(w) > 40  # the noise was binned
    assert not w["analysed"].any()
    s = res.summary
    assert (s["fit"] == "screened").all() and np.isinf(s["mu_high"]).all()
    assert (s["slippery"] == "unknown").all()
