"""Better data never say less, on a car the estimator did not make (docs/physics.md §15.11).

Drives of CommonRoad's multi-body model (vehicle 2: roll, pitch, suspension, lateral load
transfer, camber; its own Pacejka tyres), each recorded by three receivers from the same noise
draws (every receiver's noise scaled from one seed) and estimated with the same vehicle file, as
``benchmarks/accuracy.py --truth commonroad-mb`` pairs them. The references are the other
receivers' answers on the same drive and the multi-body model's own truth.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

pytest.importorskip("vehiclemodels")

from gripsense import FrictionRun
from gripsense.config.receiver import RECEIVERS
from gripsense.estimate.noise import NoiseModel
from gripsense.io import read_nmea
from gripsense.io.sensors.steer import steer_at
from gripsense.sim import commonroad as CR
from gripsense.sim.drives import limit_speed, record_drive

WORSE_TO_BETTER = ("v100", "white-0.3", "rtk")
TOL_ABS, TOL_REL = 0.02, 0.05  # a range end may move this much between two noise draws
# (benchmarks/accuracy.py BETTER_TOL: the median change of an upper end between two draws)


def _estimate(sim, plan, rec, declared, *, stiffness_error: float, seed: int):
    """The per-axle summary of *sim* recorded by receiver *rec* and estimated with the noise
    model of *declared* (the receiver as the user declares it), and the truth's axle table."""
    d = record_drive(sim, CR.commonroad_vehicle(), plan.settle_s, receiver=rec, seed=seed)
    ep = read_nmea(d.lines).epochs
    ch = d.steer.assign(steer_rad=np.deg2rad(d.steer["road_wheel_deg"]))
    steer = steer_at(ch, ep["t_s"].to_numpy(float))
    vehicle = CR.commonroad_vehicle(stiffness_error=stiffness_error)
    run = FrictionRun(vehicle, method="axle-window",
                      noise=NoiseModel.for_vehicle(vehicle, declared))  # fmt: skip
    return run.run(ep, steer_rad=steer).summary.set_index("axle"), d.axles.set_index("axle")


@pytest.fixture(scope="module")
def ramp_steer() -> dict:
    """An ISO 4138 ramp steer at 70 km/h on μ 0.9 (to the inner wheel's lift), recorded by the
    three receivers: per receiver the summary, and the truth."""
    plan = CR.cr_ramp_steer(70 / 3.6, rate_deg_s=0.5, max_steer_deg=8.0)
    sim = CR.commonroad_result(plan, 0.9, model="mb")
    out: dict = {}
    for rec in WORSE_TO_BETTER:
        out[rec], out["truth"] = _estimate(sim, plan, rec, rec, stiffness_error=0.0993, seed=56)
    return out


@pytest.mark.parametrize("axle", ["front", "rear"])
def test_a_better_receiver_never_says_less(ramp_steer, axle):
    """``white-0.3`` and ``rtk`` against ``v100`` (better in every noise component); ``rtk``
    against ``white-0.3`` — not ordered, its slow heading error is larger (§15.11), which counts
    on long steady windows — says no less on this ramp either."""
    r = ramp_steer
    assert RECEIVERS["white-0.3"].at_least_as_good_as(RECEIVERS["v100"])
    assert RECEIVERS["rtk"].at_least_as_good_as(RECEIVERS["v100"])
    for i, worse in enumerate(WORSE_TO_BETTER):
        w = r[worse].loc[axle]
        for better in WORSE_TO_BETTER[i + 1 :]:
            b = r[better].loc[axle]
            what = f"{axle}: {worse} [{w.mu_low:.3f}, {w.mu_high:.3f}] → {better} " \
                   f"[{b.mu_low:.3f}, {b.mu_high:.3f}]"  # fmt: skip
            if np.isfinite(w.mu_high):
                assert np.isfinite(b.mu_high), f"upper end lost: {what}"
                assert b.mu_high <= w.mu_high * (1 + TOL_REL) + TOL_ABS, what
            assert b.mu_low >= w.mu_low * (1 - TOL_REL) - TOL_ABS, what


def test_the_precise_compass_bounds_what_the_others_cannot(ramp_steer):
    """The comparison rests on upper ends: rtk bounds both axles, and a noisier recording never
    bounds more axles (its noise is not read as a bend: docs/physics.md §15.8)."""
    assert np.isfinite(ramp_steer["rtk"].loc[["front", "rear"], "mu_high"]).all()
    bounded = [int(np.isfinite(ramp_steer[rec]["mu_high"]).sum()) for rec in WORSE_TO_BETTER]
    assert bounded == sorted(bounded), dict(zip(WORSE_TO_BETTER, bounded, strict=True))


@pytest.mark.parametrize("rec", WORSE_TO_BETTER)
def test_every_range_holds_the_multibody_truth(ramp_steer, rec):
    s, truth = ramp_steer[rec], ramp_steer["truth"]
    for axle in ("front", "rear"):
        mu = truth.loc[axle, "mu_true"]
        assert s.loc[axle, "grip_used_lower"] <= mu + 0.01
        assert s.loc[axle, "mu_low"] <= mu <= s.loc[axle, "mu_high"]
        # without a value the lower end is the measured grip, for every receiver alike
        if not s.loc[axle, "observable"]:
            assert s.loc[axle, "mu_low"] == pytest.approx(s.loc[axle, "grip_used_lower"])


def test_a_declared_slow_heading_error_is_what_widens_rtk():
    """Where rtk says less than white-0.3 — a steady circle at 90 % of a μ 0.7 road's limit, the
    rear at u ≈ 0.86, its upper end beyond white-0.3's by more than a draw's change — the cause
    is the slow heading error rtk is declared with (0.05°) and white-0.3 without: the same rtk
    recording, declared without it, bounds the rear within white-0.3's range (docs/physics.md
    §15.11: the two receivers are not ordered)."""
    mu, radius = 0.7, 70.0
    plan = CR.cr_circle(limit_speed(mu, radius, 0.90), radius)
    sim = CR.commonroad_result(plan, mu, model="mb")
    kw = {"stiffness_error": 0.0759, "seed": 36}  # benchmarks/accuracy.py's drive
    white, truth = _estimate(sim, plan, "white-0.3", "white-0.3", **kw)
    rtk, _ = _estimate(sim, plan, "rtk", "rtk", **kw)
    no_slow = dataclasses.replace(RECEIVERS["rtk"], heading_slow_deg=0.0)
    rtk0, _ = _estimate(sim, plan, "rtk", no_slow, **kw)
    w, b, b0 = white.loc["rear"], rtk.loc["rear"], rtk0.loc["rear"]
    edge = w.mu_high * (1 + TOL_REL) + TOL_ABS
    assert np.isfinite(w.mu_high) and not b.mu_high <= edge
    assert np.isfinite(b0.mu_high) and b0.mu_high <= edge
    assert b0.mu_low <= truth.loc["rear", "mu_true"] <= b0.mu_high
