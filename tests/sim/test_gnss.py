"""Emulators read back: NMEA through read_nmea, slip angles through the friction core."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from gripsense import FrictionRun
from gripsense.config import Vehicle
from gripsense.data import sample_path
from gripsense.io import read_nmea
from gripsense.sim import SimParams
from gripsense.sim import maneuvers as M
from gripsense.sim.gnss import CompassNoise, emulate_compass
from gripsense.sim.sensors import emulate_accelerometer

VEH = Vehicle.from_toml(sample_path("corolla_sim.toml"))
P = SimParams.from_vehicle(VEH)
ANT = (-VEH.cg_offset[0], -VEH.cg_offset[1])


@pytest.fixture(scope="module")
def drive():
    m = M.circle(40 / 3.6, 30.0, laps=1.0, params=P)
    return M.run(P, m, mu=0.5), m


def test_noise_free_round_trip(drive):
    res, _ = drive
    log = emulate_compass(res, ANT, noise=CompassNoise.none(), rate_hz=10)
    nl = read_nmea(log.lines)
    assert nl.report.balanced and nl.report.n_rejected == 0
    assert nl.report.parsed == {
        k: len(log.antenna) for k in ("GGA", "HDT", "PSAT,HPR", "RMC", "ROT", "VTG")
    }
    ep = nl.epochs
    a = log.antenna
    assert len(ep) == len(a)
    np.testing.assert_allclose(ep["t_s"], a["t_s"] - a["t_s"].iloc[0], atol=1e-6)
    dh = (ep["heading_deg"] - a["heading_deg"] + 180) % 360 - 180
    assert np.abs(dh).max() < 6e-4  # printed to 1e-3 deg
    dc = (ep["course_deg"] - a["course_deg"] + 180) % 360 - 180
    assert np.abs(dc).max() < 6e-4
    np.testing.assert_allclose(ep["speed_mps"], a["speed_mps"], atol=5e-5)
    np.testing.assert_allclose(ep["yaw_rate_rps"], a["yaw_rate_rps"], atol=3e-6)  # 0.01°/min
    np.testing.assert_allclose(ep["lat_deg"], a["lat_deg"], atol=2e-9)
    np.testing.assert_allclose(ep["lon_deg"], a["lon_deg"], atol=2e-9)
    assert (ep["heading_source"] == "HPR").all() and (ep["yaw_rate_source"] == "ROT").all()


def test_slip_angles_recovered_through_the_friction_core(drive):
    """The core's antenna-to-wheel kinematics, fed the emulated log, give the simulator's own
    per-wheel slip angles (two independent implementations of the rigid-body transfer)."""
    res, m = drive
    log = emulate_compass(res, ANT, noise=CompassNoise.none(mounting_offset_deg=0.5))
    nl = read_nmea(log.lines)
    out = FrictionRun(VEH).run(nl.epochs)
    assert out.meta["heading_offset_deg"] == pytest.approx(0.5, abs=2e-3)  # from the lead-in
    w = out.wheels
    t0 = w["t_s"].min()
    truth = log.truth.assign(t_s=lambda d: d["t_s"] - d["t_s"].min())
    for wheel in ("rear_left", "rear_right"):
        est = w[w["wheel"] == wheel].set_index("t_s")["slip_angle_rad"]
        tru = truth[truth["wheel"] == wheel].set_index("t_s")["slip_angle_rad"]
        est.index = np.round(est.index - t0, 3)
        tru.index = np.round(tru.index, 3)
        both = pd.concat([est, tru], axis=1, join="inner").dropna()
        both = both[both.index > m.settle_s]
        assert len(both) > 100
        err = both.iloc[:, 0] - both.iloc[:, 1]
        assert np.abs(err).max() < np.deg2rad(0.01), wheel


def test_noise_model_statistics(drive):
    res, _ = drive
    noise = CompassNoise()
    log = emulate_compass(res, ANT, noise=noise, seed=3, rate_hz=20)
    nl = read_nmea(log.lines)
    dh = ((nl.epochs["heading_deg"] - log.antenna["heading_deg"] + 180) % 360 - 180).to_numpy()
    dh = dh - noise.mounting_offset_deg
    white = np.diff(dh) / np.sqrt(2)  # the slow part cancels in differences
    assert np.std(white) == pytest.approx(noise.heading_white_deg, rel=0.15)
    assert np.sqrt(np.mean(dh**2)) < 0.75  # thesis Table 13: < 0.75° rms
    assert emulate_compass(res, ANT, seed=3).lines == emulate_compass(res, ANT, seed=3).lines


def test_accelerometer_braking_plateau():
    res = M.run(P, M.braking(50 / 3.6), mu=0.7)
    acc = emulate_accelerometer(res, noise_g=0.0, pitch_deg=0.0)
    braking = acc[(acc["t_s"] > 3.5) & (acc["t_s"] < 4.5)]
    assert braking["ax_g"].mean() == pytest.approx(-0.7, abs=5e-3)
    assert acc["az_g"].iloc[0] == pytest.approx(1.0)
    tilted = emulate_accelerometer(res, noise_g=0.0, pitch_deg=2.0)
    # a sensor tilted nose-up by θ reads a_x cosθ − g sinθ (in g)
    rest = tilted.iloc[:10]["ax_g"].mean()
    assert rest == pytest.approx(-np.sin(np.deg2rad(2.0)), abs=1e-6)
    assert set(acc.columns) == {"t_s", "ax_g", "ay_g", "az_g"}
    assert np.diff(acc["t_s"]).mean() == pytest.approx(0.02)


def test_friction_patch_changes_the_truth():
    m = M.braking(40 / 3.6, cruise_s=1.0)  # brakes from x ≈ 11 m
    patches = np.array([[14.0, 1e3, -50.0, 50.0, 0.2]])  # ice beyond x = 14 m
    res = M.run(P, m, mu=0.9, patches=patches)
    dry = M.run(P, m, mu=0.9)
    w = res.wheels.merge(res.body[["t_s", "x_m"]], on="t_s")
    assert set(np.round(w.loc[w["x_m"] < 10, "mu_true"], 3)) == {0.9}
    # CG beyond 16 m: the rear axle (1.04 m behind) is on the ice too
    assert set(np.round(w.loc[w["x_m"] > 16, "mu_true"], 3)) == {0.2}
    assert res.body["x_m"].max() > dry.body["x_m"].max() + 5.0  # stops much later on ice
