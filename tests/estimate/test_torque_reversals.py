"""The steering torque never misleads (docs/physics.md §16.6): drives that end each corner as a
driver does — the wheel partly unwound and turned back in, an S-bend into a corner the other
way, the exit to a straight — on a steering system drawn at random (seed 003's balance with
Dahl friction, linear assist, kingpin damping and inertia), declared to within its stated
uncertainty. The truth's aligning moment is the truth tyre's own (an MF 6.1 file's M_z scaled
by similarity, or the brush closed form), never the estimator's trail family."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from hypothesis import HealthCheck, example, given, settings
from hypothesis import strategies as st

from gripsense import FrictionRun
from gripsense.data import sample_path
from gripsense.estimate.noise import NoiseModel
from gripsense.estimate.options import WindowOptions
from gripsense.estimate.torque import (
    FRICTION_STATE_SD,
    SIDE_SLIP_OFFSET_RAD,
    TorqueBins,
    merge_torque_bins,
    past_peak,
    torque_bins,
)
from gripsense.io import read_nmea
from gripsense.io.sensors.steer import steer_at, with_torque
from gripsense.physics.steering_balance import dahl_friction
from gripsense.sim import maneuvers as M
from gripsense.sim.drives import (
    TRUTH_TYRES,
    record_drive,
    truth_tyre,
    truth_vehicle,
    user_vehicle,
)
from gripsense.sim.steering_torque import emulate_torque
from gripsense.sim.vehicle import SimParams

RADIUS = 40.0


def _corner(
    tyre,
    mu,
    u,
    kind,
    friction,
    assist,
    damping,
    unwind,
    rate_dps,
    other_way,
    seed,
    vehicle="sedan",
    steady_s=8.0,
):
    """Simulate and record a corner (a circle held *steady_s*) ending in a reversal, an S-bend
    and the exit: the result, the recording, the epochs with the torque channel, the steer at
    the epochs and the vehicle as declared (its steering system within half the stated 1σ of
    the truth)."""
    tv = truth_vehicle(vehicle)
    truth_st = dataclasses.replace(tv.steering, friction_Nm=friction, assist="linear",
                                   assist_gain=assist, kingpin_damping_Nms=damping)  # fmt: skip
    tv = dataclasses.replace(tv, steering=truth_st)
    t = truth_tyre(tyre)
    p = SimParams.from_vehicle(
        tv, relaxation_length_m=0.5, sim_tyres={} if t is None else {"front": t, "rear": t}
    )
    v_lim = np.sqrt(mu * 9.80665 * RADIUS)
    v = v_lim * np.sqrt(u)
    if kind == "circle":
        m = M.circle(v, RADIUS, laps=steady_s * v / (2 * np.pi * RADIUS), settle_s=4.0, params=p)
    else:
        m = M.constant_radius(RADIUS, 0.5 * v_lim, v, accel_mps2=0.3, params=p)
    res = M.run(p, m, mu=mu)
    m = M.with_corner_exits(m, res, unwind=unwind, rate_rad_s=np.deg2rad(rate_dps),
                            other_way=other_way)  # fmt: skip
    res = M.run(p, m, mu=mu)
    d = record_drive(res, tv, m.settle_s, receiver="v100", seed=seed)
    tq = emulate_torque(res, tv.steering, tv.steering_ratio, scale_error=0.03, offset_Nm=0.2,
                        seed=seed + 1)  # fmt: skip
    uv = user_vehicle(tv, tyre)
    rng = np.random.default_rng(seed)
    s = uv.steering
    declared = dataclasses.replace(  # within half the stated 1σ of the truth
        s,
        friction_Nm=max(friction + float(rng.normal(0, 0.5 * s.friction_uncertainty_Nm)), 0.05),
        assist_gain=max(assist + float(rng.normal(0, 0.5 * s.assist_gain_uncertainty)), 0.0),
    )
    uv = dataclasses.replace(uv, steering=declared)
    ep = read_nmea(d.lines).epochs
    ch = d.steer.assign(steer_rad=np.deg2rad(d.steer["road_wheel_deg"]))
    steer = steer_at(ch, ep["t_s"].to_numpy(float))
    torque = tq.rename(columns={"torque_Nm": "torque_nm"}).assign(steer_rad=np.nan)
    return res, d, ep, with_torque(ep, torque), steer, uv


def _drive(
    tyre, mu, u, kind, friction, assist, damping, unwind, rate_dps, other_way, seed, known=False
):
    """A corner ending in a reversal, an S-bend and the exit; the front axle estimated with
    and without the column torque (and, *known*, with the truth tyre's file in [steering])."""
    _res, d, ep, ep_t, steer, uv = _corner(
        tyre, mu, u, kind, friction, assist, damping, unwind, rate_dps, other_way, seed
    )
    run = FrictionRun(uv, method="axle-window", noise=NoiseModel.for_vehicle(uv, "v100"))
    compass = run.run(ep, steer_rad=steer).summary.set_index("axle").loc["front"]
    with_t = run.run(ep_t, steer_rad=steer).summary.set_index("axle")
    out = [d.axles.set_index("axle").loc["front"], compass, with_t.loc["front"]]
    if known:
        tir = str(sample_path(f"tyres/{TRUTH_TYRES[tyre]}"))
        kv = dataclasses.replace(uv, steering=dataclasses.replace(uv.steering, tyre_file=tir))
        run = FrictionRun(kv, method="axle-window", noise=NoiseModel.for_vehicle(kv, "v100"))
        out.append(run.run(ep_t, steer_rad=steer).summary.set_index("axle"))
        out[-1] = out[-1].loc["front"]
    return tuple(out)


@settings(max_examples=5, deadline=None, derandomize=True,
          suppress_health_check=[HealthCheck.too_slow])  # fmt: skip
@given(
    tyre=st.sampled_from(["mf61", "brush"]),
    mu=st.sampled_from([0.3, 0.5, 0.9]),
    u=st.floats(0.25, 0.85),
    kind=st.sampled_from(["circle", "sweep"]),
    friction=st.floats(0.2, 2.0),
    assist=st.floats(0.0, 4.0),
    damping=st.floats(10.0, 80.0),
    unwind=st.floats(0.2, 0.7),
    rate_dps=st.floats(2.0, 10.0),
    other_way=st.floats(0.3, 1.0),
    seed=st.integers(1, 10_000),
)
# the drive: a μ 0.3 road at 30 % of its grip, a strong friction, a quick exit
@example("mf61", 0.3, 0.3, "circle", 1.6, 3.0, 30.0, 0.5, 8.0, 0.7, 7)
def test_reversals_and_exits_never_mislead(
    tyre, mu, u, kind, friction, assist, damping, unwind, rate_dps, other_way, seed
):
    truth, compass, with_t = _drive(
        tyre, mu, u, kind, friction, assist, damping, unwind, rate_dps, other_way, seed
    )
    mu_true = truth["mu_true"]

    def holds(s):
        return s["mu_low"] <= mu_true <= s["mu_high"]

    # never a range that excludes the truth where compass-only did not
    assert holds(with_t) or not holds(compass), (with_t.to_dict(), compass.to_dict())
    # never wider; the measured grip is the torque's to leave alone
    assert with_t["mu_low"] >= compass["mu_low"] - 1e-9
    assert with_t["mu_high"] <= compass["mu_high"] + 1e-9
    assert with_t["grip_used_lower"] == compass["grip_used_lower"]
    # one statement about the lower end: never below the measured grip, a model's only with
    # a value
    assert with_t["mu_low"] >= with_t["grip_used_lower"]
    if not with_t["observable"]:
        assert with_t["mu_low"] == compass["mu_low"]
    # what was read is said, and limited_by names the torque only when it changed the range
    read = with_t["steering_torque"]
    assert " Hz (" in read and "bins" in read
    changed = read.split(": ")[-1].startswith(("gave", "raised", "lowered"))
    if with_t["limited_by"].startswith("steering torque"):
        assert changed
    if not changed:
        assert with_t["limited_by"] == compass["limited_by"]


@pytest.mark.parametrize(("mu", "u", "kind"), [(0.3, 0.6, "circle"), (0.6, 0.75, "sweep"),
                                                (1.0, 0.7, "circle")])  # fmt: skip
def test_a_known_tyre_on_any_road(mu, u, kind):
    """The front tyre's own file named in [steering], the truth that file carried to the road
    by similarity on a car whose wheels lean: on roads of μ 0.3–1.0, with a corner exit, the
    range never excludes the truth where the family's did not and is never wider than it."""
    truth, _compass, family, known = _drive(
        "mf61", mu, u, kind, 1.0, 2.0, 30.0, 0.4, 5.0, 0.7, 11, known=True
    )
    mu_true = truth["mu_true"]
    assert known["mu_low"] <= mu_true <= known["mu_high"] or not (
        family["mu_low"] <= mu_true <= family["mu_high"]
    )
    assert family["mu_low"] - 1e-9 <= known["mu_low"]
    assert known["mu_high"] <= family["mu_high"] + 1e-9
    assert known["grip_used_lower"] == family["grip_used_lower"]


def test_a_slide_is_not_read_as_the_limit():
    """A μ 0.3 circle at 85 % of its grip whose entry the driver overshoots: the front axle
    slides (its slip several times the peak's, the trail collapsed) before it settles and holds.
    The points the data show past the peak — more slip than another point with as much grip —
    are left out and the read says so; the truth tyre (its own Magic Formula, not the
    estimator's) confirms each is at or past its peak; the range with the tyre's file holds the
    truth."""
    res, d, _ep, ep_t, steer, uv = _corner(
        "mf61", 0.3, 0.85, "circle", 1.2, 2.9, 20.8, 0.4, 4.0, 0.7, 11
    )
    tir = str(sample_path(f"tyres/{TRUTH_TYRES['mf61']}"))
    kv = dataclasses.replace(uv, steering=dataclasses.replace(uv.steering, tyre_file=tir))
    run = FrictionRun(kv, method="axle-window", noise=NoiseModel.for_vehicle(kv, "v100"))
    r = run.run(ep_t, steer_rad=steer)
    front = r.summary.set_index("axle").loc["front"]
    mu_true = d.axles.set_index("axle").loc["front", "mu_true"]
    assert front["mu_low"] <= mu_true <= front["mu_high"], front.to_dict()
    assert "past the force's peak left out" in front["steering_torque"]

    mb = merge_torque_bins(torque_bins(r.wheels, kv), WindowOptions().steady_tolerance)
    beyond = past_peak(mb)
    assert beyond.any()
    tyre = truth_tyre("mf61")
    slip = np.deg2rad(np.linspace(0.05, 20.0, 800))
    wheels = res.wheels
    for i in np.flatnonzero(beyond):
        for name in ("front_left", "front_right"):
            w = wheels[(wheels["wheel"] == name) & wheels["t_s"].between(mb.t0[i], mb.t1[i])]
            peak = slip[np.argmax(tyre.force(slip, w["load_N"].mean(), 0.0, mu_road=0.3))]
            assert np.abs(w["slip_angle_rad"]).mean() >= 0.9 * peak, (name, mb.t0[i])


def _peak_slip(tyre, load, mu):
    """The slip of the truth tyre's largest force at *load* on a road of *mu* (its own Magic
    Formula table, similarity-scaled) [rad]."""
    slip = np.deg2rad(np.linspace(0.05, 30.0, 1200))
    return slip[np.argmax(np.abs(tyre.force(slip, load, 0.0, mu_road=mu)))]


def test_a_spin_is_not_read_as_the_limit():
    """The torque benchmark's last miss, reduced (benchmarks/README.md, ``accuracy.py --torque``):
    the sports car on a μ 0.7 circle at its limit, held 20 s, spins at the corner's exit and
    keeps turning — its front wheels slide at 6–20 times the peak's slip, always on the side of
    the force the turn-in did not use. Read on the rising side those points said "at the
    limit" at μ 0.35–0.62 and, with the tyre's file and the steering's lever, ended the range
    at 0.787 for a true 0.791. The turn-in, at as much grip and far less slip, shows them past
    the peak across the sides: every point the truth tyre (its own Magic Formula, not the
    estimator's) puts beyond four times its peak's slip is left out, each point left out is at
    or past that peak, and the range holds the truth."""
    from tests.estimate.test_calibration import simulated_lever

    res, d, ep, ep_t, steer, uv = _corner(
        "mf-sedan", 0.7, 1.0, "circle", 1.0, 2.0, 30.0, 0.4, 5.0, 0.7, 11, "sports", 20.0
    )
    tir = str(sample_path(f"tyres/{TRUTH_TYRES['mf-sedan']}"))
    st = dataclasses.replace(uv.steering, tyre_file=tir, calibrated_lever_m=simulated_lever(
        "mf-sedan", "sports"), calibrated_lever_uncertainty=0.04)  # fmt: skip
    kv = dataclasses.replace(uv, steering=st)
    run = FrictionRun(kv, method="axle-window", noise=NoiseModel.for_vehicle(kv, "v100"))
    r = run.run(ep_t, steer_rad=steer)
    front = r.summary.set_index("axle").loc["front"]
    compass = run.run(ep, steer_rad=steer).summary.set_index("axle").loc["front"]
    mu_true = d.axles.set_index("axle").loc["front", "mu_true"]
    assert front["mu_low"] <= mu_true <= front["mu_high"], front.to_dict()
    assert compass["mu_low"] - 1e-9 <= front["mu_low"] <= front["mu_high"] <= compass["mu_high"]
    assert "past the force's peak left out" in front["steering_torque"]

    mb = merge_torque_bins(torque_bins(r.wheels, kv), WindowOptions().steady_tolerance)
    beyond = past_peak(mb)
    tyre = truth_tyre("mf-sedan")
    wheels = res.wheels
    times_peak = np.zeros((mb.t0.size, 2))
    for i in range(mb.t0.size):
        for j, name in enumerate(("front_left", "front_right")):
            w = wheels[(wheels["wheel"] == name) & wheels["t_s"].between(mb.t0[i], mb.t1[i])]
            peak = _peak_slip(tyre, w["load_N"].mean(), 0.7)
            times_peak[i, j] = np.abs(w["slip_angle_rad"]).mean() / peak
    spin = times_peak.min(axis=1) >= 4.0
    assert spin.sum() >= 4 and times_peak.max() >= 10.0  # the car spun
    assert beyond[spin].all(), times_peak[spin & ~beyond]
    assert (times_peak[beyond] >= 0.9).all(), times_peak[beyond]


def _mf_points(slip_deg, offset_deg, mu=0.7, load=4000.0):
    """Points of an axle on the truth tyre's own curve (the PAC2002 sedan file, whose two sides
    peak 7 % apart), both wheels at *load*, their slip measured with a common error."""
    tyre = truth_tyre("mf-sedan")
    alpha = np.deg2rad(np.asarray(slip_deg, float))
    force = 2.0 * tyre.force(alpha, load, 0.0, mu_road=mu)
    k = alpha.size
    z, one = np.zeros(k), np.ones(k)
    return TorqueBins(
        t0=np.arange(k, dtype=float), t1=np.arange(k) + 0.9, n=np.full(k, 10), force=force,
        force_sigma=0.005 * 2.0 * load * one, fz_l=load * one, fz_r=load * one, moment=z,
        moment_sigma=one, friction_state=z, friction_sd=one, grip=np.abs(force) / (2.0 * load),
        fz_static=load, source="test", scale_sd=0.03, offset_sd=1.0,
        slip=alpha + np.deg2rad(offset_deg), slip_sigma=np.full(k, np.deg2rad(0.05)),
        force_noise=0.005 * 2.0 * load * one,
    )  # fmt: skip


@pytest.mark.parametrize("offset", [-0.95, 0.95])
def test_past_the_peak_across_the_sides(offset):
    """The rule compares the two sides of the force: with the truth tyre's own curve (not the
    estimator's) and a common slip error just within :data:`SIDE_SLIP_OFFSET_RAD`, no point on
    the rising side of either is taken past the peak, and slides on the side the rising points
    are not on (a spin) all are."""
    assert np.rad2deg(SIDE_SLIP_OFFSET_RAD) >= abs(offset)
    peak = np.rad2deg(_peak_slip(truth_tyre("mf-sedan"), 4000.0, 0.7))
    rising = peak * np.array([0.08, 0.15, 0.3, 0.6, 0.9])
    both = _mf_points(np.concatenate([rising, -rising]), offset)
    assert not past_peak(both).any()
    slides = peak * np.array([2.5, 4.0, 8.0, 14.0])
    spin = _mf_points(np.concatenate([-rising, slides]), offset)
    assert (past_peak(spin) == np.repeat([False, True], [rising.size, slides.size])).all()


@pytest.mark.parametrize(
    "drive",
    [
        ("mf61", 0.3, 0.85, "circle", 1.2, 2.9, 20.8, 0.4, 4.0, 0.7, 11),  # settles, holds
        ("mf61", 0.5, 0.9, "sweep", 1.2, 2.9, 20.8, 0.4, 4.0, 0.7, 5),  # a slow creep
        ("brush", 0.5, 0.6, "sweep", 1.0, 2.0, 30.0, 0.4, 4.0, 0.7, 8),
    ],
)
def test_the_friction_state_is_known_only_where_the_steer_drives_it(drive):
    """Where the estimator takes the friction's state as known (1σ ``FRICTION_STATE_SD``), the
    simulator's own Dahl friction along its noise-free steer, averaged over the bin, agrees
    with it to that 1σ (rms) and never beyond 3σ. A held steer — a controller settled into a
    circle, a sweep's slow creep — is not taken as known: along it the Dahl model of the
    measured steer was off by up to 1.3 (rms 0.7)."""
    res, _d, _ep, ep_t, steer, uv = _corner(*drive)
    run = FrictionRun(uv, method="axle-window", noise=NoiseModel.for_vehicle(uv, "v100"))
    tb = torque_bins(run.run(ep_t, steer_rad=steer).wheels, uv)
    body = res.body
    truth_state = dahl_friction(body["steer_rad"].to_numpy(float), 1.0)
    known = np.flatnonzero(tb.friction_sd <= FRICTION_STATE_SD + 1e-9)
    assert known.size >= 3
    err = np.array(
        [
            truth_state[body["t_s"].between(tb.t0[i], tb.t1[i]).to_numpy()].mean()
            - tb.friction_state[i]
            for i in known
        ]
    )
    assert np.sqrt(np.mean(err**2)) <= 1.5 * FRICTION_STATE_SD, err
    assert np.abs(err).max() <= 3.0 * FRICTION_STATE_SD, err
