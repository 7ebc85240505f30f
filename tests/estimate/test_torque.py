"""Friction from the steering torque (issue "Friction at half the limit"; docs/physics.md §16.6):
on drives of gripsense's simulator whose aligning moment is the truth tyre's own (the brush
closed form, an MF 6.1 file's M_z), never the estimator's trail family."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from gripsense import FrictionRun
from gripsense.errors import InputError
from gripsense.estimate.noise import NoiseModel
from gripsense.io import read_nmea
from gripsense.io.sensors.steer import steer_at, with_torque
from gripsense.sim import maneuvers as M
from gripsense.sim.drives import record_drive, truth_tyre, truth_vehicle, user_vehicle
from gripsense.sim.steering_torque import emulate_torque
from gripsense.sim.vehicle import SimParams

RADIUS = 40.0


def _sweep(tyre: str, mu: float, u_max: float, seed: int = 3):
    """ISO 4138 constant radius, speed rising from 45 % of the limit to *u_max* of it."""
    tv = truth_vehicle("sedan")
    t = truth_tyre(tyre)
    p = SimParams.from_vehicle(
        tv, relaxation_length_m=0.5, sim_tyres={} if t is None else {"front": t, "rear": t}
    )
    v_lim = np.sqrt(mu * 9.80665 * RADIUS)
    m = M.constant_radius(RADIUS, 0.45 * v_lim, v_lim * np.sqrt(u_max), accel_mps2=0.15, params=p)
    res = M.run(p, m, mu=mu)
    d = record_drive(res, tv, m.settle_s, receiver="v100", seed=seed)
    tq = emulate_torque(res, tv.steering, tv.steering_ratio, scale_error=0.03, offset_Nm=0.2,
                        seed=seed)  # fmt: skip
    uv = user_vehicle(tv, tyre)
    ep = read_nmea(d.lines).epochs
    ch = d.steer.assign(steer_rad=np.deg2rad(d.steer["road_wheel_deg"]))
    steer = steer_at(ch, ep["t_s"].to_numpy(float))
    torque = tq.rename(columns={"torque_Nm": "torque_nm"}).assign(steer_rad=np.nan)
    return d, uv, ep, steer, torque


def _front(uv, ep, steer):
    run = FrictionRun(uv, method="axle-window", noise=NoiseModel.for_vehicle(uv, "v100"))
    res = run.run(ep, steer_rad=steer)
    return res.summary.set_index("axle").loc["front"], res


@pytest.fixture(scope="module")
def mf_drive():
    return _sweep("mf61", 0.9, 0.85)


@pytest.mark.parametrize("tyre", ["brush", "mf61"])
def test_the_climb_bounds_mu(tyre, mf_drive):
    """A sweep to ~0.8 of the front axle's grip: the compass alone gives no upper end; with
    the torque the range is bounded and holds the true μ. Real (MF) trails fall late, so the
    range is wide (docs/physics.md §16.5); the measured grip stays model-free."""
    d, uv, ep, steer, torque = mf_drive if tyre == "mf61" else _sweep("brush", 0.9, 0.85)
    truth = d.axles.set_index("axle").loc["front"]
    assert 0.65 < truth["utilisation_max"] < 0.85
    compass, _ = _front(uv, ep, steer)
    with_t, res = _front(uv, with_torque(ep, torque), steer)
    assert not np.isfinite(compass["mu_high"])
    assert np.isfinite(with_t["mu_high"]) and with_t["mu_low"] < with_t["mu_high"]
    assert with_t["mu_low"] <= truth["mu_true"] <= with_t["mu_high"]
    # below what one operating point allows the compass (2.4 × at u 0.6, docs/physics.md §15)
    assert with_t["mu_high"] <= 2.4 * truth["mu_true"]
    assert with_t["limited_by"].startswith("steering torque")
    assert with_t["grip_used_lower"] == compass["grip_used_lower"]
    assert "torque_nm" in res.wheels.columns


def test_never_wider_than_without():
    """Near the limit, where the compass bounds μ itself, the torque never widens the range."""
    _d, uv, ep, steer, torque = _sweep("mf61", 0.9, 1.0)
    compass, _ = _front(uv, ep, steer)
    with_t, _ = _front(uv, with_torque(ep, torque), steer)
    assert np.isfinite(with_t["mu_high"]) and with_t["mu_low"] < with_t["mu_high"]
    assert with_t["mu_low"] >= compass["mu_low"] and with_t["mu_high"] <= compass["mu_high"]


def test_no_torque_channel_changes_nothing(mf_drive):
    """A torque column without a sample, or none at all: the same answer, rear axle always."""
    _, uv, ep, steer, torque = mf_drive
    plain, res_p = _front(uv, ep, steer)
    empty, _ = _front(uv, ep.assign(torque_nm=np.nan), steer)
    pd.testing.assert_series_equal(plain, empty)
    _, res_t = _front(uv, with_torque(ep, torque), steer)
    rear_p = res_p.summary.set_index("axle").loc["rear"]
    rear_t = res_t.summary.set_index("axle").loc["rear"]
    pd.testing.assert_series_equal(rear_p, rear_t)
    assert "torque_nm" not in res_p.wheels.columns


@pytest.mark.parametrize(
    ("edit", "message"),
    [
        (lambda x: -x, "sign is flipped"),
        (lambda x: 100.0 * x, "unit"),  # N cm read as N m
    ],
)
def test_a_wrong_channel_is_one_clear_error(mf_drive, edit, message):
    _, uv, ep, steer, torque = mf_drive
    bad = torque.assign(torque_nm=edit(torque["torque_nm"]))
    with pytest.raises(InputError, match=message):
        _front(uv, with_torque(ep, bad), steer)


def test_a_known_tyre_says_more(mf_drive):
    """The front tyre's own .tir named in [steering] (docs/physics.md §16.7): the trail's shape
    and its zero-slip value come from the file, not the family — on the same sweep the range
    holds the truth and is narrower than with the family."""
    import dataclasses

    from gripsense.data import sample_path

    d, uv, ep, steer, torque = mf_drive
    truth = d.axles.set_index("axle").loc["front"]
    family, _ = _front(uv, with_torque(ep, torque), steer)
    tir = sample_path("tyres/MagicFormula61_Paramerters.tir")
    known_v = dataclasses.replace(
        uv,
        steering=dataclasses.replace(uv.steering, tyre_file=str(tir)),
    )
    known, _ = _front(known_v, with_torque(ep, torque), steer)
    assert known["mu_low"] <= truth["mu_true"] <= known["mu_high"]
    assert known["mu_high"] - known["mu_low"] < family["mu_high"] - family["mu_low"]
    assert family["mu_low"] <= known["mu_low"] and known["mu_high"] <= family["mu_high"]
    assert known["grip_used_lower"] == family["grip_used_lower"]


def test_a_learned_lever(mf_drive):
    """The steering's lever learned by gripsense calibrate (docs/physics.md §16.8; here the
    simulator's own lever at low grip, 4 % 1σ): the range holds the truth and stays within the
    family's without it — also for a lever learned 10 % off."""
    import dataclasses

    from gripsense.data import sample_path
    from gripsense.estimate.torque import trail_family
    from tests.estimate.test_calibration import simulated_lever

    d, uv, ep, steer, torque = mf_drive
    truth = d.axles.set_index("axle").loc["front"]
    plain, _ = _front(uv, with_torque(ep, torque), steer)
    lever = simulated_lever("mf61")
    # docs/physics.md §16.8: on the road (the sedan's wheels lean with the body) the MF 6.1
    # file's pneumatic part is ~0.026 m, its zero-camber zero-slip lever ~0.017 m
    tir = dataclasses.replace(uv.steering, tyre_file=str(sample_path(
        "tyres/MagicFormula61_Paramerters.tir")))  # fmt: skip
    file_t0 = trail_family(dataclasses.replace(uv, steering=tir)).t0_m
    road = lever - uv.steering.mechanical_trail_m
    assert road == pytest.approx(0.026, abs=0.002) and file_t0 == pytest.approx(0.017, abs=0.001)
    for factor in (1.0, 0.9, 1.1):
        st = dataclasses.replace(uv.steering, calibrated_lever_m=lever * factor,
                                 calibrated_lever_uncertainty=0.04)  # fmt: skip
        cal, _ = _front(dataclasses.replace(uv, steering=st), with_torque(ep, torque), steer)
        assert plain["mu_low"] <= cal["mu_low"] and cal["mu_high"] <= plain["mu_high"]
        if factor == 1.0:
            assert cal["mu_low"] <= truth["mu_true"] <= cal["mu_high"]
