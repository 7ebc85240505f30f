"""Accuracy of ``axle-window`` on drives whose tyres and vehicles the estimator does not share.

Matrix (issue 14): truth tyre {brush, three Magic Formula .tir files, PAC89}
× vehicle {sedan, low sports car, tall SUV} × receiver {v100: 0.3° white + 0.4° slow heading,
white-0.3: 0.3° white, rtk: 0.05°} × road μ {0.3, 0.5, 0.7, 0.9, 1.1}
× manoeuvre {the thesis's 2018 circles 20–50 km/h × R 20/30/40 m, near-limit circles at 85 and
95 % of the road's friction at R 30 m}. Each drive is simulated with the truth tyre (similarity-
scaled to the road, load dependence and camber thrust of the file, roll-induced camber, 0.5 m
relaxation length), recorded by the emulated receiver (0.5° mounting offset) and a steering
channel with a 3 % scale error, and estimated with the vehicle file a user would write
(:func:`gripsense.sim.drives.user_vehicle`: the truth tyre's C at the static load ± 10 %,
default load sensitivity, shape and camber thrust). A second pass (``--wrong-cg``) declares the
CG height 25 % too high and too low.

Per axle-case: the true μ of the axle (load-weighted peak of its wheels), the true utilisation,
the measured-grip bound, the estimate and its 90 % interval. Per cell and overall: values given
at utilisation ≥ 0.6 and ≥ 0.8, bias, RMSE, 90 % coverage, share of measured-grip bounds above
the truth (+0.01), the largest such excess, abstention.

``--kind transients`` drives slaloms instead (60 km/h, 3 s period, steering amplitude 2–8°:
no steady segment), to show that non-steady windows contribute without bias.

``--kind sweeps`` drives ISO 4138 ramp steers (70 km/h, to 99 % of the front axle's grip and
beyond) with the same truth tyres, ``--kind dwell`` a sine with dwell (80 km/h, 0.7 Hz, 0.5 s
dwell, the road-wheel amplitude 1.3 × the steady steer of the road's limit: FMVSS 126-like).
``--truth commonroad`` uses a vehicle model gripsense did not write as the truth: CommonRoad's
single-track drift model (``gripsense.sim.commonroad``: Pacejka tyres C 1.35, E ≈ 0, no lateral
load transfer, wheel spin), for steady circles at 60–98 % of the limit (R 40 and 70 m, 25 s steady)
and sweeps (ISO 4138 constant radius R 40 m with the speed rising, ramp steer at 70 km/h), μ
0.3–1.0. ``--truth commonroad-mb`` drives the same plans with CommonRoad's multi-body model (29
states: roll, pitch, unsprung masses, suspension, tyre vertical compliance, lateral load transfer,
camber; the truth per wheel as the model computes it), on μ 0.3–0.9: its vehicle 2 lifts an inner
wheel from about 0.85 g, where a drive ends.

Each axle-case also gets the **physical limit** of its range
(:func:`gripsense.physics.friction_limit.mu_range_limit`): the μ that the true operating points
(1 s means of the axle's true slip and force after the settling time, ±0.01 in force per load)
allow for the estimator's shape family and the declared stiffness's 90 % band — no estimator
can be narrower without more information. ``limit_rx`` adds the receiver's share: any common
slip error up to 90 % of the receiver's slow heading error combined with a heading calibration's
residual (0.05°); ``given_u0.95_pinned`` counts values on the axles that reached 0.95 of their
grip and whose limit with the receiver's share is at most 0.1 wide (a value within ±0.05 is
possible at all). Reported per cell: an upper end given (u ≥ 0.8, fit
consistent), the median width of the range over the limit's width, values, coverage, bias, the
"is it slippery?" calls (right on μ ≤ 0.3 at u ≥ 0.85, wrong on μ ≥ 0.8), and per receiver the
median width (a better receiver must not say less). On the CommonRoad drives every receiver
records the same drive (one vehicle file and one noise seed per drive), and the column "better
data never say less" counts the axle-cases where a better receiver (one no noisier in any
component, :meth:`~gripsense.config.receiver.Receiver.at_least_as_good_as`: ``white-0.3`` and
``rtk`` against ``v100``) loses an upper end or states a range not inside the worse one's within
:data:`BETTER_TOL` (:func:`better_says_less`; ``rtk`` against ``white-0.3``, not ordered, is
printed beside it); ``--draws N`` records every drive N times
(each draw's noise shared by the receivers) and also compares each receiver's median range over
the draws (:func:`typical_ranges`): what its data give, not one draw's luck; the other tables
count the first draw. ``--receivers ideal`` adds a receiver
without noise to speak of: the range it leaves is the vehicle file's declared uncertainty alone.

``--torque`` (issue "Friction at half the limit") drives the front axle to utilisation 0.3–1.0 on
Magic Formula truth tyres whose aligning moment the estimator does not share (the files' own
M_z, similarity-scaled; docs/physics.md §16.4): steady circles at R 40 m and slow ISO 4138
constant-radius sweeps (speed rising 0.15 m/s², R 40 m), with a column-torque channel (100 Hz,
0.05 N m noise, 3 % scale error, 0.2 N m offset) from the truth vehicle's ``[steering]``. Each
drive is estimated twice, with and without the torque, and reported per band of the largest
utilisation the front axle reached: upper end given, median width over μ, values, within 0.1,
coverage, bias — against the compass-only estimate of the same drives, and how often the range
with the torque is wider than without.

``--slippery`` drives icy and snowy roads: steady circles on μ 0.1, 0.2 and 0.3 (ice,
packed snow, snow) and, as the control, 0.9, at 70, 80 and 90 % of the road's friction (quick:
80 and 90 %), R 30 m or wider so that the car keeps 7 m/s (a compass's course needs speed);
reported per road and receiver at u ≥ 0.8: analysed, ``slippery``, ranges holding the truth,
measured-grip bounds above the truth.

``--learned`` measures the calibrate workflow (``benchmarks/learned.py``): the vehicle file
alone, the stiffness learned from three everyday drives, and that with the curve's shape learned
from one sweep on another road, on CommonRoad's cars and the Magic Formula truth.

Usage: python benchmarks/accuracy.py [--quick] [--wrong-cg] [--kind circles|transients|sweeps|dwell]
       [--slippery]
       [--truth gripsense|commonroad|commonroad-mb] [--torque] [--workers 2] [--csv out.csv]
       [--plot benchmarks/accuracy.png]
       --torque [--exits] [--shape known] [--calibrated] [--only tyre,vehicle,mu,kind,target_u]
       --learned [--receivers rtk] [--slippery]
"""

from __future__ import annotations

import argparse
import dataclasses
import itertools
import time
from concurrent.futures import ProcessPoolExecutor

import numpy as np
import pandas as pd

TYRES = ("brush", "mf-book", "mf-sedan", "mf61", "pac89")
VEHICLES = ("sedan", "sports", "suv")
RECEIVERS = ("v100", "white-0.3", "rtk")
IDEAL = {"heading_white_deg": 0.01, "heading_slow_deg": 0.0, "velocity_mps": 0.002,
         "yaw_rate_dps": 0.01, "position_slow_m": 0.0, "position_white_m": 0.001}  # fmt: skip
"""``--receivers ideal``: a receiver without noise to speak of (benchmark only). What the
estimator says with it is what the vehicle file's declared uncertainty alone allows: the
model-form floor of the range, against which a real receiver's share is measured."""
MUS = (0.3, 0.5, 0.7, 0.9, 1.1)
SLIPPERY_MUS = (0.1, 0.2, 0.3, 0.9)
"""``--slippery``: ice, packed snow, snow, and a dry road (no drive on it may read slippery)."""


def manoeuvres(mu: float, quick: bool, kind: str = "circles") -> list[tuple[str, float, float]]:
    """(name, speed [m/s], radius [m] or −steer amplitude [deg]) of the drives on a road of
    friction *mu*: circles (the thesis's grid and near-limit circles) or transients (slaloms
    at 60 km/h, 3 s period, from everyday to beyond the limit: no steady segment at all)."""
    from gripsense.sim.drives import limit_speed

    if kind == "sweeps":  # ISO 4138 ramp steer at 70 km/h: 1 °/s at the road wheels
        return [("ramp steer 70 km/h", 70 / 3.6, -100.0)]
    if kind == "dwell":  # sine with dwell at 80 km/h, 1.3 × the steer of the road's limit
        amp = 1.3 * np.rad2deg(2.7 * mu * 9.81 / (80 / 3.6) ** 2)
        return [("sine with dwell 80 km/h", 80 / 3.6, -200.0 - amp)]
    if kind == "slippery":  # steady circles near the limit, at 7 m/s or more (R ≥ 30 m)
        us = (0.8, 0.9) if quick else (0.7, 0.8, 0.9)
        out = []
        for u in us:
            r = max(30.0, 7.0**2 / (u * mu * 9.80665))
            out.append((f"limit {u:.2f} R{r:.0f}", limit_speed(mu, r, u), r))
        return out
    if kind == "transients":
        amps = (3.0, 7.0) if quick else (2.0, 4.0, 6.0, 8.0)
        return [(f"slalom {a:g}° 60 km/h", 60 / 3.6, -a) for a in amps]
    speeds = (30, 50) if quick else (20, 30, 40, 50)
    radii = (20, 40) if quick else (20, 30, 40)
    out = [(f"{v} km/h R{r}", v / 3.6, float(r)) for v in speeds for r in radii]
    for u in (0.85, 0.95):
        out.append((f"limit {u:.2f} R30", limit_speed(mu, 30.0, u), 30.0))
    return out


def jobs(
    quick: bool,
    wrong_cg: bool,
    tyres=TYRES,
    vehicles=VEHICLES,
    receivers=RECEIVERS,
    kind: str = "circles",
) -> list[dict]:
    out = []
    rng = np.random.default_rng(14)
    mus = SLIPPERY_MUS if kind == "slippery" else MUS[::2] if quick else MUS
    receivers = ("white-0.3",) if wrong_cg else receivers
    cg = (1.25, 0.75) if wrong_cg else (1.0,)
    for tyre in tyres:
        for veh in vehicles:
            for mu in mus:
                for name, v, r in manoeuvres(mu, quick, kind):
                    for rec in receivers:
                        for f in cg:
                            out.append(
                                {
                                    "tyre": tyre,
                                    "vehicle": veh,
                                    "mu_road": mu,
                                    "manoeuvre": name,
                                    "speed_mps": v,
                                    "radius_m": r,
                                    "receiver": rec,
                                    "cg_factor": f,
                                    "stiffness_error": float(rng.uniform(-0.1, 0.1)),
                                    "seed": len(out) + 1,
                                }
                            )
    return out


CR_MUS = (0.3, 0.5, 0.7, 0.9, 1.0)


def jobs_commonroad(
    quick: bool, receivers=("white-0.3",), model: str = "std", draws: int = 1
) -> list[dict]:
    """CommonRoad drives (single-track ``std`` or multi-body ``mb``): steady circles at
    utilisation 0.6–0.98 (R 40, 70 m) and the two ISO 4138 sweeps; each recorded *draws*
    times by every receiver (``draw`` 0 with today's seeds, the others with their own)."""
    from gripsense.sim.drives import limit_speed

    out: list[dict] = []
    n_plan = 0
    rng = np.random.default_rng(26)
    if model == "mb":  # vehicle 2's inner wheels lift from ~0.85 g (the drive ends there)
        mus = (0.3, 0.7) if quick else (0.3, 0.5, 0.7, 0.9)
    else:
        mus = (0.3, 0.7, 1.0) if quick else CR_MUS
    us = (0.8, 0.92, 0.98) if quick else (0.6, 0.7, 0.8, 0.9, 0.95, 0.98)
    for mu in mus:
        plans = [
            (f"circle u{u:.2f} R{r}", ("circle", limit_speed(mu, r, u), float(r)))
            for u in us
            for r in ((70,) if quick else (40, 70))
        ]
        plans.append(
            (
                "constant radius R40 rising",
                ("radius", 40.0, limit_speed(mu, 40.0, 0.5), limit_speed(mu, 40.0, 1.1)),
            )
        )
        plans.append(("ramp steer 70 km/h", ("ramp", 70 / 3.6)))
        for name, plan in plans:
            # one drive recorded by every receiver: the same vehicle file (stiffness error) and
            # the same noise seed (common random numbers, each receiver's noise scaled from the
            # same draws), so a comparison between receivers compares their data, not two draws
            n_plan += 1
            serr, seed = float(rng.uniform(-0.1, 0.1)), n_plan
            for draw, rec in itertools.product(range(draws), receivers):
                out.append(
                    {
                        "truth": "commonroad" if model == "std" else "commonroad-mb",
                        "tyre": "cr-pacejka",
                        "vehicle": "cr-vehicle2" if model == "std" else "cr-vehicle2-mb",
                        "mu_road": mu,
                        "manoeuvre": name,
                        "plan": plan,
                        "speed_mps": float(plan[1]) if plan[0] != "radius" else float(plan[2]),
                        "radius_m": float(plan[2]) if plan[0] == "circle" else np.nan,
                        "receiver": rec,
                        "cg_factor": 1.0,
                        "stiffness_error": serr,
                        "seed": seed + DRAW_SEED * draw,
                        "draw": draw,
                    }
                )
    return out


DRAW_SEED = 100_000
"""Seed step between two noise draws of one CommonRoad drive (``--draws``)."""


def receiver_share(receiver: str) -> float:
    """The common slip error a receiver leaves [rad]: 90 % of its slow heading error combined
    with the residual of a heading calibration on straights (0.05°)."""
    from gripsense.config.receiver import RECEIVERS as PRESETS

    return float(np.deg2rad(1.645 * np.hypot(PRESETS[receiver].heading_slow_deg, 0.05)))


def declared_band(vehicle) -> tuple[float, float]:
    """The declared stiffness's 90 % band around the declared value [-]: what the vehicle file
    alone allows (its tyres' largest ``stiffness_uncertainty``, log-normal)."""
    from gripsense.constants import Z90

    sd = np.log1p(max(t.stiffness_uncertainty for t in vehicle.tyres.values()))
    return float(np.exp(-Z90 * sd)), float(np.exp(Z90 * sd))


def physical_limit(
    truth: pd.DataFrame, settle_s: float, vehicle, axle: str, band, slip_offset: float = 0.0
) -> tuple:
    """The range the true operating points of an axle allow (module docstring), with a common
    slip error up to *slip_offset* [rad] (the receiver's share)."""
    from functools import partial

    from gripsense.physics.friction_limit import mu_range_limit as mrl

    mu_range_limit = partial(mrl, slip_offset=slip_offset, n_offset=5)

    t = truth[(truth["t_s"] >= settle_s) & truth["wheel"].astype(str).str.startswith(axle)]
    if t.empty:
        return np.nan, np.nan
    g = t.assign(k=np.floor(t["t_s"])).groupby("k")
    fz = g["load_N"].sum()
    y = (g["force_N"].sum().abs() / fz).to_numpy()
    slip = g["slip_angle_rad"].apply(lambda a: float(np.mean(np.abs(a)))).to_numpy()
    cn = vehicle.cornering_stiffness(axle, vehicle.static_load(axle)) / vehicle.static_load(axle)
    keep = y >= 0.5 * y.max()  # the informative points (near-linear ones add nothing)
    lo, hi = mu_range_limit(y[keep], slip[keep], cn, stiffness_band=band, tolerance=0.01)
    if not np.isfinite(lo):  # not one curve at 0.01 (load transfer): the highest point alone
        i = int(np.argmax(y))
        lo, hi = mu_range_limit(y[i], slip[i], cn, stiffness_band=band, tolerance=0.01)
    return lo, hi


def _cr_drive(job: dict):
    from gripsense.sim import commonroad as CR

    plan = job["plan"]
    if plan[0] == "circle":
        p = CR.cr_circle(plan[1], plan[2])
    elif plan[0] == "radius":
        p = CR.cr_constant_radius(plan[1], plan[2], plan[3])
    else:
        p = CR.cr_ramp_steer(plan[1], rate_deg_s=0.5, max_steer_deg=8.0)
    model = "mb" if job["truth"] == "commonroad-mb" else "std"
    d = CR.commonroad_drive(p, job["mu_road"], model=model, receiver=job["receiver"],
                            seed=job["seed"])  # fmt: skip
    uv = CR.commonroad_vehicle(stiffness_error=job["stiffness_error"])
    return d, uv


def estimate_columns(s) -> dict:
    """What a drive summary's row says of one axle, as the benchmark's columns."""
    return {
        "grip_used_lower": s["grip_used_lower"],
        "observable": bool(s["observable"]),
        "mu": s["mu"],
        "mu_low": s["mu_low"],
        "mu_high": s["mu_high"],
        "fit": s["fit"],
        "limited_by": s.get("limited_by", ""),
        "steering_torque": s.get("steering_torque", ""),
    }


def one(job: dict) -> list[dict]:
    from gripsense import FrictionRun
    from gripsense.estimate.noise import NoiseModel
    from gripsense.io import read_nmea
    from gripsense.io.sensors.steer import steer_at
    from gripsense.sim import maneuvers as M
    from gripsense.sim.drives import simulate_drive, truth_vehicle, user_vehicle

    cr = str(job.get("truth", "")).startswith("commonroad")
    if cr:
        d, uv = _cr_drive(job)
    elif -200 < job["radius_m"] <= -100:  # ISO 4138 ramp steer, 1 °/s, after a 6 s straight
        m = M.ramp_steer(job["speed_mps"], rate_rad_s=np.deg2rad(1.0),
                         max_steer_rad=np.deg2rad(14.0), hold_s=6.0)  # fmt: skip
        circle = None
    elif job["radius_m"] <= -200:  # sine with dwell (0.7 Hz, 0.5 s dwell), after a 6 s straight
        amp = np.deg2rad(-job["radius_m"] - 200.0)
        m, circle = M.sine_with_dwell(job["speed_mps"], amplitude_rad=amp), None
    elif job["radius_m"] > 0:
        m, circle = None, (job["speed_mps"], job["radius_m"])
    else:  # a slalom after a 6 s straight (heading calibration)
        amp = np.deg2rad(-job["radius_m"])
        t = np.linspace(0.0, 24.0, 1201)
        steer = np.where(t < 6.0, 0.0, amp * np.sin(2 * np.pi * (t - 6.0) / 3.0))
        m = M.slalom(job["speed_mps"], amplitude_rad=amp, period_s=3.0, cycles=8)
        m.steer_table, m.duration_s, m.settle_s, circle = (t, steer), 24.0, 6.0, None
    if not cr:
        d = simulate_drive(
            job["vehicle"],
            job["tyre"],
            m,
            job["mu_road"],
            receiver=job["receiver"],
            seed=job["seed"],
            circle=circle,
        )
        uv = user_vehicle(
            truth_vehicle(job["vehicle"]),
            job["tyre"],
            stiffness_error=job["stiffness_error"],
            cg_height_factor=job["cg_factor"],
        )
    ep = read_nmea(d.lines).epochs
    ch = d.steer.assign(steer_rad=np.deg2rad(d.steer["road_wheel_deg"]))
    steer = steer_at(ch, ep["t_s"].to_numpy(float))
    t0 = time.perf_counter()
    run = FrictionRun(uv, method="axle-window", noise=NoiseModel.for_vehicle(uv, job["receiver"]))
    res = run.run(ep, steer_rad=steer)
    wall = time.perf_counter() - t0
    truth = d.axles.set_index("axle")
    band = declared_band(uv)
    rows = []
    for s in res.summary.to_dict("records"):
        ax = s["axle"]
        if ax not in truth.index:
            continue
        t = truth.loc[ax]
        lim_lo, lim_hi = physical_limit(d.truth, d.settle_s, uv, ax, band)
        rx_lo, rx_hi = physical_limit(
            d.truth, d.settle_s, uv, ax, band, receiver_share(job["receiver"])
        )
        rows.append(
            {
                **{k: v for k, v in job.items() if k != "plan"},
                "limit_low": lim_lo,
                "limit_high": lim_hi,
                "limit_rx_low": rx_lo,
                "limit_rx_high": rx_hi,
                "slippery": s.get("slippery", ""),
                "axle": ax,
                "mu_true": t["mu_true"],
                "mu_true_max": t["mu_true_max"],
                "utilisation": t["utilisation"],
                "utilisation_max": t["utilisation_max"],
                **estimate_columns(s),
                "shape": s.get("shape", ""),
                "estimate_s": wall,
            }
        )
    return rows


TORQUE_TYRES = ("mf61", "mf-book", "mf-sedan")
TORQUE_U = (0.3, 0.45, 0.55, 0.65, 0.75, 0.85, 0.95, 1.0)
"""Largest front-axle utilisation the torque drives aim at (the road's μ; the front axle of an
understeering car reaches a little more)."""


def jobs_torque(
    quick: bool, shape: str = "", truth: str = "gripsense", exits: bool = False
) -> list[dict]:
    """Steady circles and constant-radius sweeps to utilisation 0.3–1.0 on MF tyres (or on
    CommonRoad's multi-body car, an MF file's trail added to its forces)."""
    out = []
    if truth == "commonroad-mb":
        rng = np.random.default_rng(271)
        for tyre in ("mf-sedan",) if quick else ("mf-sedan", "mf61"):  # the trail added
            for mu in (0.5, 0.9) if quick else (0.3, 0.5, 0.7, 0.9):
                for kind in ("circle", "sweep"):
                    for u in TORQUE_U[1::2] if quick else TORQUE_U[:-1]:
                        out.append({"truth": truth, "tyre": tyre, "vehicle": "commonroad-2",
                                    "mu_road": mu, "kind": kind, "target_u": u,
                                    "receiver": "white-0.3", "shape": shape,
                                    "stiffness_error": float(rng.uniform(-0.1, 0.1)),
                                    "seed": len(out) + 1, "exits": exits})  # fmt: skip
        return out
    rng = np.random.default_rng(27)
    mus = (0.5, 0.9) if quick else (0.3, 0.5, 0.7, 0.9, 1.1)
    vehicles = ("sedan",) if quick else ("sedan", "sports")
    targets = TORQUE_U[1::2] if quick else TORQUE_U
    for tyre in TORQUE_TYRES:
        for veh in vehicles:
            for mu in mus:
                for kind in ("circle", "sweep"):
                    for u in targets:
                        out.append(
                            {
                                "tyre": tyre,
                                "vehicle": veh,
                                "mu_road": mu,
                                "kind": kind,
                                "target_u": u,
                                "receiver": "v100",
                                "shape": shape,
                                "stiffness_error": float(rng.uniform(-0.1, 0.1)),
                                "seed": len(out) + 1,
                                "exits": exits,
                            }
                        )
    return out


def only_torque(todo: list[dict], spec: str) -> list[dict]:
    """The torque drives whose (tyre, vehicle, μ, kind, target u) match *spec*, comma-separated
    in that order; an empty field matches any (``--only``)."""
    if not spec:
        return todo
    keys = ("tyre", "vehicle", "mu_road", "kind", "target_u")
    want = [(k, v.strip()) for k, v in zip(keys, spec.split(","), strict=False) if v.strip()]

    def match(job: dict, k: str, v: str) -> bool:
        x = job[k]
        return bool(np.isclose(x, float(v))) if isinstance(x, float) else str(x) == v

    return [j for j in todo if all(match(j, k, v) for k, v in want)]


def learned_lever(tv, tyre: str, uv, receiver: str, drives: int = 3) -> tuple[float, float]:
    """The steering lever ``gripsense calibrate`` learns for this car — its truth *tv* on the
    truth tyre *tyre*, its vehicle file *uv*, the drives' torque sensor (scale +3 %, offset
    0.2 N m) — from *drives* everyday drives (60 km/h, curves to ~0.35 g, μ 0.9): (lever [m],
    relative 1σ)."""
    import gzip
    import tempfile
    from pathlib import Path

    from gripsense.pipeline import learn_calibration
    from gripsense.sim import maneuvers as M
    from gripsense.sim.drives import record_drive, truth_tyre
    from gripsense.sim.steering_torque import emulate_torque
    from gripsense.sim.vehicle import SimParams

    t = truth_tyre(tyre)
    p = SimParams.from_vehicle(tv, relaxation_length_m=0.5, sim_tyres={"front": t, "rear": t})
    logs, steers = [], []
    with tempfile.TemporaryDirectory() as tmp:
        for i in range(drives):
            m = M.everyday(60 / 3.6, seed=100 + i)
            res = M.run(p, m, mu=0.9)
            d = record_drive(res, tv, m.settle_s, receiver=receiver, seed=100 + i)
            tq = emulate_torque(res, tv.steering, tv.steering_ratio, scale_error=0.03,
                                offset_Nm=0.2, seed=100 + i + 104729)  # fmt: skip
            steer = d.steer.merge(tq, on="t_s", how="outer").sort_values("t_s")
            log = Path(tmp) / f"drive{i}.nmea.gz"
            with gzip.open(log, "wt", encoding="ascii") as fh:
                fh.write("\n".join(d.lines) + "\n")
            steers.append(Path(tmp) / f"drive{i}_steer.csv")
            steer.to_csv(steers[-1], index=False)
            logs.append(log)
        st = learn_calibration(logs, uv, receiver=receiver, steer_csvs=steers).steering
    return st.lever_m, st.lever_uncertainty


def one_torque(job: dict) -> list[dict]:
    """One drive with a torque channel, estimated with and without it (front axle)."""
    from gripsense import FrictionRun
    from gripsense.data import sample_path
    from gripsense.estimate.noise import NoiseModel
    from gripsense.io import read_nmea
    from gripsense.io.sensors.steer import steer_at, with_torque
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

    radius = 40.0
    v_lim = float(np.sqrt(job["mu_road"] * 9.80665 * radius))
    v = v_lim * np.sqrt(job["target_u"])
    if job.get("truth") == "commonroad-mb":
        from gripsense.sim import commonroad as CR

        tv = CR.commonroad_vehicle()
        plan = (CR.cr_circle(v, radius, steady_s=20.0) if job["kind"] == "circle"
                else CR.cr_constant_radius(radius, 0.45 * v_lim, v, accel_mps2=0.15))  # fmt: skip
        if job.get("exits"):
            plan = CR.with_corner_exits(plan)
        res = CR.commonroad_result(plan, job["mu_road"], model="mb")
        d = record_drive(res, tv, plan.settle_s, receiver=job["receiver"], seed=job["seed"])
        tq = emulate_torque(
            res, tv.steering, tv.steering_ratio, scale_error=0.03, offset_Nm=0.2,
            seed=job["seed"] + 104729, trail_tyre=truth_tyre(job["tyre"]),
        )  # fmt: skip
        uv = CR.commonroad_vehicle(stiffness_error=job["stiffness_error"])
    else:
        tv = truth_vehicle(job["vehicle"])
        if job.get("exits"):  # a steering system of its own: friction, assist and damping
            r2 = np.random.default_rng(job["seed"] + 17)
            tv = dataclasses.replace(tv, steering=dataclasses.replace(
                tv.steering, friction_Nm=float(r2.uniform(0.3, 1.6)),
                assist_gain=float(r2.uniform(1.0, 4.0)),
                kingpin_damping_Nms=float(r2.uniform(15.0, 60.0))))  # fmt: skip
        t = truth_tyre(job["tyre"])
        p = SimParams.from_vehicle(tv, relaxation_length_m=0.5, sim_tyres={"front": t, "rear": t})
        if job["kind"] == "circle":
            m = M.circle(v, radius, laps=20.0 * v / (2 * np.pi * radius), settle_s=5.0, params=p)
        else:
            m = M.constant_radius(radius, 0.45 * v_lim, v, accel_mps2=0.15, params=p)
        res = M.run(p, m, mu=job["mu_road"])
        if job.get("exits"):  # the same corner, then a reversal, an S-bend and the exit
            m = M.with_corner_exits(m, res)
            res = M.run(p, m, mu=job["mu_road"])
        d = record_drive(res, tv, m.settle_s, receiver=job["receiver"], seed=job["seed"])
        tq = emulate_torque(res, tv.steering, tv.steering_ratio, scale_error=0.03,
                            offset_Nm=0.2, seed=job["seed"] + 104729)  # fmt: skip
        uv = user_vehicle(tv, job["tyre"], stiffness_error=job["stiffness_error"])
    s = uv.steering
    if job.get("shape") == "known":  # the front tyre's own .tir named in [steering]
        tir = sample_path(f"tyres/{TRUTH_TYRES[job['tyre']]}")
        s = dataclasses.replace(s, tyre_file=str(tir))
    elif job.get("shape"):
        uv = dataclasses.replace(
            uv, tyres={k: dataclasses.replace(t, shape=job["shape"]) for k, t in uv.tyres.items()}
        )
    # the user declares the steering system to its stated uncertainty, not the truth
    rng = np.random.default_rng(job["seed"])
    s = dataclasses.replace(
        s, mechanical_trail_m=s.mechanical_trail_m
        + float(rng.normal(0, s.mechanical_trail_uncertainty_m)),
    )  # fmt: skip
    if job.get("exits") and tv.steering is not None:  # friction and assist known roughly
        s = dataclasses.replace(
            s, friction_Nm=max(tv.steering.friction_Nm
                               + float(rng.normal(0, 0.5 * s.friction_uncertainty_Nm)), 0.05),
            assist_gain=max(tv.steering.assist_gain
                            + float(rng.normal(0, 0.5 * s.assist_gain_uncertainty)), 0.0),
        )  # fmt: skip
    uv = dataclasses.replace(uv, steering=s)
    lever = (np.nan, np.nan)
    if job.get("calibrated"):  # gripsense calibrate on this car first, with its vehicle file
        lever = learned_lever(tv, job["tyre"], uv, job["receiver"])
        st = dataclasses.replace(
            uv.steering, calibrated_lever_m=lever[0], calibrated_lever_uncertainty=lever[1]
        )
        uv = dataclasses.replace(uv, steering=st)
    ep = read_nmea(d.lines).epochs
    ch = d.steer.assign(steer_rad=np.deg2rad(d.steer["road_wheel_deg"]))
    steer = steer_at(ch, ep["t_s"].to_numpy(float))
    ch_t = tq.rename(columns={"torque_Nm": "torque_nm"}).assign(steer_rad=np.nan)
    ep_t = with_torque(ep, ch_t)
    run = FrictionRun(uv, method="axle-window", noise=NoiseModel.for_vehicle(uv, job["receiver"]))
    truth = d.axles.set_index("axle").loc["front"]
    rows = []
    for with_t, epochs in (("torque", ep_t), ("compass", ep)):
        s = run.run(epochs, steer_rad=steer).summary.set_index("axle").loc["front"]
        rows.append(
            {
                **job,
                "estimate": with_t,
                "lever_m": lever[0],
                "lever_sd": lever[1],
                "mu_true": truth["mu_true"],
                "utilisation": truth["utilisation"],
                "utilisation_max": truth["utilisation_max"],
                **estimate_columns(s),
            }
        )
    return rows


TORQUE_BANDS = ((0.3, 0.5), (0.5, 0.6), (0.6, 0.8), (0.8, 1.01))


def torque_scores(df: pd.DataFrame) -> pd.DataFrame:
    """Per utilisation band (the front axle's largest): compass-only and with the torque."""
    rows = []
    for lo, hi in TORQUE_BANDS:
        band = df[(df["utilisation_max"] >= lo) & (df["utilisation_max"] < hi)]
        for est in ("compass", "torque"):
            d = band[band["estimate"] == est]
            if d.empty:
                continue
            obs = d["observable"].astype(bool)
            width = (d["mu_high"] - d["mu_low"]) / d["mu_true"]
            covered = (d["mu_low"] <= d["mu_true"]) & (d["mu_true"] <= d["mu_high"])
            err = (d["mu"] - d["mu_true"])[obs]
            rows.append(
                {
                    "u_max": f"{lo:.1f}–{min(hi, 1.0):.1f}",
                    "estimate": est,
                    "n": len(d),
                    "upper_end": float(np.isfinite(d["mu_high"]).mean()),
                    "median_width/mu": float(width.replace(np.inf, np.nan).median())
                    if np.isfinite(width).any()
                    else np.inf,
                    "values": float(obs.mean()),
                    "within_0.1": float((np.abs(err) <= 0.1).mean()) if len(err) else np.nan,
                    "coverage_values": float(covered[obs].mean()) if obs.any() else np.nan,
                    "coverage_all": float(covered.mean()),
                    "bias": float(err.mean()) if len(err) else np.nan,
                }
            )
    return pd.DataFrame(rows).set_index(["u_max", "estimate"])


def torque_report(df: pd.DataFrame) -> None:
    """Print the per-band table, the width ratio against the compass-only range and the
    measured-grip bound's excess."""
    fmt = {"float_format": lambda v: f"{v:.3f}"}
    print("\nper band of the front axle's largest utilisation\n"
          + torque_scores(df).to_string(**fmt))  # fmt: skip
    key = ["tyre", "vehicle", "mu_road", "kind", "target_u"]
    both = df.pivot_table(
        index=key,
        columns="estimate",
        values=["mu_low", "mu_high", "mu"],
        aggfunc="first",
        dropna=False,
    )
    mu_true = df[df["estimate"] == "torque"].set_index(key)["mu_true"].reindex(both.index)
    w_t = both[("mu_high", "torque")] - both[("mu_low", "torque")]
    w_c = both[("mu_high", "compass")] - both[("mu_low", "compass")]
    finite = np.isfinite(w_t) & np.isfinite(w_c)
    wider = (w_t > w_c + 1e-9) | (~np.isfinite(w_t) & np.isfinite(w_c))
    ratio = (w_t / w_c)[finite]
    print(f"\nwidth with torque / compass-only (both bounded): median {ratio.median():.3f} "
          f"(n {int(finite.sum())}); ranges wider with the torque: {int(wider.sum())} of "
          f"{len(w_t)}")  # fmt: skip
    cov = {e: (both[("mu_low", e)] <= mu_true) & (mu_true <= both[("mu_high", e)])
           for e in ("torque", "compass")}  # fmt: skip
    bad = ~cov["torque"] & cov["compass"]
    print(f"ranges excluding the truth with the torque where compass-only did not: "
          f"{int(bad.sum())} of {len(bad)}")  # fmt: skip
    for k, r in both[bad].iterrows():
        print(f"    {k}: torque [{r[('mu_low', 'torque')]:.3f}, {r[('mu_high', 'torque')]:.3f}]"
              f", compass [{r[('mu_low', 'compass')]:.3f}, {r[('mu_high', 'compass')]:.3f}], "
              f"true {mu_true[k]:.3f}")  # fmt: skip
    same = (np.isclose(both[("mu_low", "torque")], both[("mu_low", "compass")])
            & (np.isclose(both[("mu_high", "torque")], both[("mu_high", "compass")])
               | (~np.isfinite(w_t) & ~np.isfinite(w_c)))
            & (both[("mu", "torque")].notna() == both[("mu", "compass")].notna()))  # fmt: skip
    tq = df[df["estimate"] == "torque"].set_index(key).reindex(both.index)
    claims = tq["limited_by"].astype(str).str.startswith("steering torque")
    note = tq.get("steering_torque", pd.Series("", index=tq.index)).fillna("").astype(str)
    kept = note.str.contains("did not change|not used") | (note == "")
    print(
        f"limited_by names the torque while the range equals compass-only: "
        f"{int((claims & same).sum())} of {int(same.sum())} identical ranges (and values), "
        f"{int((claims & kept).sum())} of {int(kept.sum())} the torque left unchanged"
    )
    print("what the torque did: " + ", ".join(
        f"{k} {v}" for k, v in note.str.split(": ").str[-1].str.split(" [0-9]").str[0]
        .replace("", "no channel read").value_counts().items()))  # fmt: skip
    excess = (df["grip_used_lower"] - df["mu_true"]).max()
    print(f"largest measured-grip bound over the truth: {excess:+.3f}")
    what = df[df["estimate"] == "torque"].groupby("limited_by").size()
    print("\nwhat limits the torque estimate\n" + what.to_string())


def torque_plot(df: pd.DataFrame, path: str, what: str = "") -> None:
    """The figures of ``docs/friction.md``: per band, how often an upper end is given, and each
    axle-case's range over the true μ, with the torque and without (*what*: the run's options,
    for the title)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (a0, a1) = plt.subplots(1, 2, figsize=(12, 4.5))
    labels = [f"{lo:.1f}–{min(hi, 1.0):.1f}" for lo, hi in TORQUE_BANDS]
    x = np.arange(len(TORQUE_BANDS))
    for j, (est, colour) in enumerate((("compass", "0.6"), ("torque", "C0"))):
        share = []
        for lo, hi in TORQUE_BANDS:
            d = df[(df["estimate"] == est) & (df["utilisation_max"] >= lo)
                   & (df["utilisation_max"] < hi)]  # fmt: skip
            share.append(float(np.isfinite(d["mu_high"]).mean()) if len(d) else np.nan)
        a0.bar(x + (j - 0.5) * 0.38, share, 0.38, color=colour,
               label="compass only" if est == "compass" else "compass + torque")  # fmt: skip
        # the axle-cases the torque bounds: their range with it and without
        key = ["tyre", "vehicle", "mu_road", "kind", "target_u"]
        bounded = df[(df["estimate"] == "torque") & np.isfinite(df["mu_high"])][key]
        d = df[df["estimate"] == est].merge(bounded, on=key)
        hi = np.minimum(d["mu_high"] / d["mu_true"], 3.0)
        lo = d["mu_low"] / d["mu_true"]
        off = (j - 0.5) * 0.003
        a1.vlines(d["utilisation_max"] + off, lo, hi, color=colour, lw=1.0, alpha=0.7)
    a0.set_xticks(x, labels)
    a0.set_xlabel("largest utilisation of the front axle")
    a0.set_ylabel("share of axle-cases with an upper end")
    a0.legend()
    a1.axhline(1.0, color="k", lw=0.8)
    a1.set_ylim(0.3, 3.05)
    a1.set_xlabel("largest utilisation of the front axle")
    a1.set_ylabel("stated range / true μ (upper end cut at 3)")
    a1.set_title("the axle-cases the torque bounds: without it (grey), with it (blue)",
                 fontsize=9)  # fmt: skip
    fig.suptitle(f"MF truth tyres, circles and sweeps (benchmarks/accuracy.py --torque{what})")
    fig.tight_layout()
    fig.savefig(path, dpi=110)


def slippery_report(df: pd.DataFrame) -> pd.DataFrame:
    """``--slippery``: per road μ and receiver, at u ≥ 0.7 and ≥ 0.8, the axle-cases analysed
    (a window passed the screen), called ``slippery``, with an upper end, whose range holds the
    truth, and whose measured-grip bound is above the truth (+0.01)."""
    rows = []
    for (mu, rec), d in df.groupby(["mu_road", "receiver"]):
        row: dict = {"mu_road": mu, "receiver": rec}
        for u in (0.7, 0.8):
            x = d[d["utilisation"] >= u]
            n = len(x)
            row[f"n_u{u}"] = n
            row[f"analysed_u{u}"] = float((~x["fit"].isin(("screened", "no data"))).mean())
            row[f"slippery_u{u}"] = float((x["slippery"] == "slippery").mean())
        x = d[d["utilisation"] >= 0.8]
        held = (x["mu_low"].fillna(-np.inf) <= x["mu_true"]) & (
            x["mu_true"] <= x["mu_high"].fillna(np.inf)
        )
        row["upper_u0.8"] = float(np.isfinite(x["mu_high"]).mean())
        row["range_holds_u0.8"] = float(held.mean())
        row["slippery_any_u"] = int((d["slippery"] == "slippery").sum())
        row["bound_above"] = int((d["grip_used_lower"] - d["mu_true"] > 0.01).sum())
        rows.append(row)
    return pd.DataFrame(rows)


RECEIVER_ORDER = ("v100", "white-0.3", "rtk")
"""The receivers in the order their pairs are listed (worse first where they are ordered):
``white-0.3`` and ``rtk`` are better data than ``v100`` in every component; ``rtk`` and
``white-0.3`` are not ordered — ``rtk``'s white noise is smaller, its 0.05° slow heading error
larger than ``white-0.3``'s none (docs/physics.md §15.11)."""
BETTER_TOL = (0.02, 0.05)
"""How far a better receiver's range end may lie outside the worse one's before it "says less"
(absolute [-], relative to the worse one's end [-]): the typical change of a range's end
between two noise draws of one receiver on the same drive — on the CommonRoad multi-body drives
(white-0.3 and rtk, every seed re-drawn) a finite upper end moved by a median 4.3 % (0.024);
one time in ten by more than 23 %, and 13 of 115 upper ends were stated by one draw only."""


def better_says_less(df: pd.DataFrame, tol: tuple[float, float] = BETTER_TOL) -> pd.DataFrame:
    """Per drive, axle and pair of receivers (``worse`` listed first, ``better`` second, in
    :data:`RECEIVER_ORDER`; for a pair that is not ordered the names are only the listing
    order) recorded on the same drive: whether the pair is ordered (``ordered``: the better one
    no noisier in any component, :meth:`~gripsense.config.receiver.Receiver.
    at_least_as_good_as`) and whether the better receiver says less — an upper end the worse
    one states is lost, or its range is not inside the worse one's within *tol* (an upper end
    above ``hi_w (1 + rel) + abs``, a lower end below ``lo_w (1 − rel) − abs``).

    The rows of one drive are those with the same truth, road, manoeuvre and axle (the
    CommonRoad drives are paired: one vehicle file and one noise seed per drive, every receiver).
    """
    from gripsense.config.receiver import RECEIVERS as PRESETS

    a, r = tol
    key = [k for k in ("truth", "tyre", "vehicle", "mu_road", "manoeuvre", "axle") if k in df]
    rows = []
    for k, g in df.groupby(key, sort=False):
        g = g.drop_duplicates("receiver").set_index("receiver")
        for i, worse in enumerate(RECEIVER_ORDER):
            for better in RECEIVER_ORDER[i + 1 :]:
                if worse not in g.index or better not in g.index:
                    continue
                w, b = g.loc[worse], g.loc[better]
                hi_w, hi_b = float(w["mu_high"]), float(b["mu_high"])
                lost = bool(np.isfinite(hi_w) and not np.isfinite(hi_b))
                higher = bool(np.isfinite(hi_w) and np.isfinite(hi_b) and hi_b > hi_w * (1 + r) + a)
                lower = bool(float(b["mu_low"]) < float(w["mu_low"]) * (1 - r) - a)
                ordered = PRESETS[better].at_least_as_good_as(PRESETS[worse])
                rows.append({**dict(zip(key, k, strict=True)), "worse": worse, "better": better,
                             "ordered": ordered,
                             "utilisation": float(w["utilisation"]), "mu_true": float(w["mu_true"]),
                             "range_worse": f"[{w['mu_low']:.3f}, {hi_w:.3f}]",
                             "range_better": f"[{b['mu_low']:.3f}, {hi_b:.3f}]",
                             "upper_lost": lost, "upper_higher": higher, "lower_lower": lower,
                             "says_less": lost or higher or lower})  # fmt: skip
    return pd.DataFrame(rows)


def typical_ranges(df: pd.DataFrame) -> pd.DataFrame:
    """Per drive, axle and receiver the median over the drive's noise draws (``--draws``) of
    each end of the range (none where at least half the draws state no upper end): the range
    a receiver's data give, not one draw's luck. The rows as they are for one draw."""
    if "draw" not in df or df["draw"].nunique() <= 1:
        return df
    key = [k for k in ("truth", "tyre", "vehicle", "mu_road", "manoeuvre", "axle") if k in df]
    return (
        df.groupby([*key, "receiver"], sort=False)
        .agg(mu_low=("mu_low", "median"), mu_high=("mu_high", "median"),
             utilisation=("utilisation", "first"), mu_true=("mu_true", "first"))
        .reset_index()
    )  # fmt: skip


def better_report(df: pd.DataFrame) -> None:
    """Print the three-receiver column (:func:`better_says_less`): per pair of receivers the
    axle-cases compared and those where the better one says less, the axle-cases where any
    better receiver does, and each of them — for one noise draw per drive, and with
    ``--draws`` for each receiver's typical range (:func:`typical_ranges`)."""
    n_draws = int(df["draw"].nunique()) if "draw" in df else 1
    if n_draws > 1:
        print(f"\n-- one noise draw per drive (draw 0 of {n_draws}):", end="")
        _better_report(df[df["draw"] == 0])
        print(f"\n-- each receiver's median range over {n_draws} noise draws per drive:", end="")
        _better_report(typical_ranges(df))
    else:
        _better_report(df)


def _better_report(df: pd.DataFrame) -> None:
    """:func:`better_report` of one set of rows (one per drive, axle and receiver)."""
    pairs = better_says_less(df)
    if pairs.empty:
        return
    a, r = BETTER_TOL
    per = pairs.groupby(["worse", "better", "ordered"], sort=False)[
        ["upper_lost", "upper_higher", "lower_lower", "says_less"]
    ].sum()
    per.insert(0, "axle-cases", pairs.groupby(["worse", "better", "ordered"], sort=False).size())
    key = [c for c in pairs.columns if c not in ("worse", "better") and c in df.columns]
    key = [c for c in key if c not in ("utilisation", "mu_true")]
    n_cases = pairs.groupby(key).ngroups
    less = pairs[pairs["says_less"] & pairs["ordered"]]
    n_less = less.groupby(key).ngroups if len(less) else 0
    loose = pairs[pairs["says_less"] & ~pairs["ordered"]]
    n_loose = loose.groupby(key).ngroups if len(loose) else 0
    print(f"\nbetter data never say less ({', '.join(RECEIVER_ORDER)}; the same drive; a range "
          f"end outside the worse one's by more than {a:g} + {r:.0%}; ordered: the better one no "
          "noisier in any component):\n" + per.to_string()
          + f"\naxle-cases where a better receiver says less: {n_less} of {n_cases}"
          + f"\n(not ordered, the second listed says less: {n_loose} of {n_cases})")  # fmt: skip
    bad = pairs[pairs["says_less"]]
    if len(bad):
        cols = [c for c in ("mu_road", "manoeuvre", "axle", "worse", "better", "ordered",
                            "utilisation", "mu_true", "range_worse", "range_better")
                if c in bad]  # fmt: skip
        print(bad[cols].to_string(index=False, float_format=lambda v: f"{v:.3f}"))


def scores(df: pd.DataFrame) -> pd.Series:
    """The issue's numbers for a set of axle-cases."""
    obs = df["observable"].astype(bool)
    err = (df["mu"] - df["mu_true"])[obs]
    lo = df["mu_low"].fillna(-np.inf)
    hi = df["mu_high"].fillna(np.inf)
    covered = (lo <= df["mu_true"]) & (df["mu_true"] <= hi)
    excess = (df["grip_used_lower"] - df["mu_true"]).fillna(-1)
    u6, u8 = df["utilisation"] >= 0.6, df["utilisation"] >= 0.8
    near = obs & u8
    u95 = df["utilisation_max"] >= 0.95 if "utilisation_max" in df else df["utilisation"] >= 0.95
    consistent = df["fit"] != "inconsistent"
    near8 = u8 & consistent
    width = df["mu_high"] - df["mu_low"]
    lim_w = df["limit_high"] - df["limit_low"] if "limit_high" in df else width * np.nan
    ratio = (width / lim_w)[near8 & np.isfinite(width) & np.isfinite(lim_w) & (lim_w > 0)]
    rx_w = df["limit_rx_high"] - df["limit_rx_low"] if "limit_rx_high" in df else width * np.nan
    ratio_rx = (width / rx_w)[near8 & np.isfinite(width) & np.isfinite(rx_w) & (rx_w > 0)]
    v95 = obs & u95
    # the axles that reached 0.95 and whose data allow a value within ±0.05 at all (the
    # physical limit with the receiver's share no wider than 0.1)
    pinned = u95 & (rx_w <= 0.1)
    err95 = (df["mu"] - df["mu_true"])[v95]
    call = df["slippery"] if "slippery" in df else pd.Series("", index=df.index)
    low = (df["mu_true"] <= 0.31) & (df["utilisation"] >= 0.85)
    high = df["mu_true"] >= 0.8
    return pd.Series(
        {
            "n": len(df),
            "upper_u0.8": float(np.isfinite(df["mu_high"])[near8].mean())
            if near8.any()
            else np.nan,
            "limit_upper_u0.8": float(np.isfinite(lim_w)[near8].mean()) if near8.any() else np.nan,
            "width_u0.8": float(width[near8 & np.isfinite(width)].median())
            if (near8 & np.isfinite(width)).any()
            else np.nan,
            "width/limit": float(ratio.median()) if len(ratio) else np.nan,
            "width/limit_rx": float(ratio_rx.median()) if len(ratio_rx) else np.nan,
            "given_u0.95": float(obs[u95].mean()) if u95.any() else np.nan,
            "given_u0.95_pinned": float(obs[pinned].mean()) if pinned.any() else np.nan,
            "within_0.05_u0.95": float((np.abs(err95) <= 0.05).mean()) if len(err95) else np.nan,
            "bias_u0.95": float(err95.mean()) if len(err95) else np.nan,
            "coverage90_u0.95": float(covered[v95].mean()) if v95.any() else np.nan,
            "slippery_right": f"{int((call[low] == 'slippery').sum())}/{int(low.sum())}",
            "slippery_wrong": int((call[high] == "slippery").sum()),
            "given_u0.6": float(obs[u6].mean()) if u6.any() else np.nan,
            "given_u0.8": float(obs[u8].mean()) if u8.any() else np.nan,
            "within_0.05_u0.8": float(
                (np.abs(df["mu"] - df["mu_true"])[near] <= 0.05).mean() if near.any() else np.nan
            ),
            "bias": float(err.mean()) if len(err) else np.nan,
            "rmse": float(np.sqrt((err**2).mean())) if len(err) else np.nan,
            "worst_error": float(np.abs(err).max()) if len(err) else np.nan,
            "coverage90": float(covered[obs].mean()) if obs.any() else np.nan,
            "coverage90_all": float(covered.mean()),
            "bound_above": float((excess > 0.01).mean()),
            "bound_excess_max": float(max(excess.max(), 0.0)),
            "abstained": float(1 - obs.mean()),
        }
    )


def run_all(fn, todo: list[dict], workers: int, csv: str | None, chunksize: int) -> pd.DataFrame:
    """Every job on *workers* processes, one table of their rows (written to *csv* if given)."""
    t0 = time.perf_counter()
    with ProcessPoolExecutor(workers) as ex:
        rows = [r for part in ex.map(fn, todo, chunksize=chunksize) for r in part]
    df = pd.DataFrame(rows)
    print(f"{len(todo)} drives, {len(df)} axle-cases in {time.perf_counter() - t0:.0f} s")
    if csv:
        df.to_csv(csv, index=False)
    pd.set_option("display.width", 200)
    return df


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="μ 0.3/0.7/1.1, 4 thesis circles")
    ap.add_argument("--wrong-cg", action="store_true", help="CG height declared ±25 %% off")
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--csv", default=None)
    ap.add_argument("--plot", default=None)
    ap.add_argument("--tyres", default=",".join(TYRES))
    ap.add_argument("--vehicles", default=",".join(VEHICLES))
    ap.add_argument("--receivers", default=",".join(RECEIVERS))
    ap.add_argument(
        "--kind", default="circles", choices=("circles", "transients", "sweeps", "dwell")
    )
    ap.add_argument(
        "--slippery",
        action="store_true",
        help="circles near the limit on μ 0.1/0.2/0.3 (ice, packed snow, snow) and 0.9",
    )
    ap.add_argument(
        "--truth", default="gripsense", choices=("gripsense", "commonroad", "commonroad-mb")
    )
    ap.add_argument(
        "--draws",
        type=int,
        default=1,
        help="--truth commonroad*: record every drive this many times (noise draws) by every "
        "receiver; the tables count the first, the column 'better data never say less' also "
        "compares each receiver's median range over the draws",
    )
    ap.add_argument(
        "--torque",
        action="store_true",
        help="the steering-torque channel against compass-only (MF tyres, u 0.3–1)",
    )
    ap.add_argument(
        "--calibrated",
        action="store_true",
        help="--torque: the steering lever learned first by gripsense calibrate (3 everyday "
        "drives of each drive's car: its steering system, vehicle file and torque sensor)",
    )
    ap.add_argument(
        "--shape",
        default="",
        help="--torque: the tyre shape the user declares (brush, magic-formula), or known (the "
        "front tyre's own .tir in [steering] tyre_file)",
    )
    ap.add_argument(
        "--exits",
        action="store_true",
        help="--torque: every drive ends with a steering reversal, an S-bend and the corner "
        "exit; on gripsense's simulator the truth's steering friction, assist and damping are "
        "drawn at random",
    )
    ap.add_argument(
        "--only",
        default="",
        help="--torque: the drives whose tyre,vehicle,mu,kind,target_u match (a field left "
        "empty matches any), e.g. mf-sedan,sports,0.7,circle,1.0",
    )
    ap.add_argument(
        "--learned",
        action="store_true",
        help="the calibrate workflow: declared, calibrated (stiffness from 3 everyday drives) "
        "and learned (+ the shape from one sweep on another road) on CommonRoad single-track "
        "and multi-body cars and the Magic Formula truth (benchmarks/learned.py; --receivers: "
        "the first; --slippery: circles on μ 0.1–0.3)",
    )
    args = ap.parse_args()
    if args.learned:
        import learned

        rec = args.receivers.split(",")[0] if args.receivers != ",".join(RECEIVERS) else None
        learned.run(",".join(learned.CARS), rec or "white-0.3", args.workers, args.csv,
                    args.slippery)  # fmt: skip
        return
    if args.torque:
        todo = only_torque(jobs_torque(args.quick, args.shape, args.truth, args.exits), args.only)
        if not todo:
            ap.error(f"--only {args.only}: no torque drive matches (tyre,vehicle,mu,kind,target_u)")
        if args.calibrated:
            if args.truth != "gripsense":
                ap.error("--calibrated drives gripsense's simulator (the everyday drives)")
            todo = [{**j, "calibrated": True} for j in todo]
        df = run_all(one_torque, todo, args.workers, args.csv, chunksize=2)
        torque_report(df)
        if args.plot:
            what = (" --calibrated" if args.calibrated else "") + (
                f" --shape {args.shape}" if args.shape else ""
            )
            torque_plot(df, args.plot, what)
        return
    if "ideal" in args.receivers.split(","):
        from gripsense.config.receiver import RECEIVERS as PRESETS
        from gripsense.config.receiver import Receiver

        PRESETS["ideal"] = Receiver("ideal", **IDEAL)  # the workers fork with it
    if args.truth.startswith("commonroad"):
        model = "mb" if args.truth == "commonroad-mb" else "std"
        todo = jobs_commonroad(args.quick, tuple(args.receivers.split(",")), model, args.draws)
    else:
        todo = jobs(
            args.quick,
            args.wrong_cg,
            tuple(args.tyres.split(",")),
            tuple(args.vehicles.split(",")),
            tuple(args.receivers.split(",")),
            "slippery" if args.slippery else args.kind,
        )
    df_all = run_all(one, todo, args.workers, args.csv, chunksize=4)
    df = df_all[df_all["draw"] == 0] if "draw" in df_all else df_all  # the tables: one draw
    if args.slippery:
        fmt = {"float_format": lambda v: f"{v:.3f}"}
        print("\nslippery roads (μ 0.1–0.3) and the control (0.9)\n"
              + slippery_report(df).to_string(index=False, **fmt))  # fmt: skip
        low = df[(df["mu_road"] <= 0.3) & (df["utilisation"] >= 0.8)]
        print(f"\nμ 0.1–0.3, u ≥ 0.8: slippery {int((low['slippery'] == 'slippery').sum())}"
              f"/{len(low)}; μ 0.9 drives slippery: "
              f"{int((df[df['mu_road'] >= 0.8]['slippery'] == 'slippery').sum())}")  # fmt: skip
    fmt = {"float_format": lambda v: f"{v:.3f}"}
    by_rec = df.groupby("receiver").apply(scores, include_groups=False)
    print("\nper receiver\n" + by_rec.to_string(**fmt))
    by_cell = df.groupby(["tyre", "vehicle"]).apply(scores, include_groups=False)
    print("\nper truth tyre and vehicle (all receivers)\n" + by_cell.to_string(**fmt))
    w3 = df[df["receiver"] == "white-0.3"]
    if len(w3):
        by_t = w3.groupby("tyre").apply(scores, include_groups=False)
        print("\nwhite-0.3 receiver, per truth tyre\n" + by_t.to_string(**fmt))
    print("\noverall\n" + scores(df).to_string(**fmt))
    if df["manoeuvre"].nunique() > 1:
        by_m = df.groupby(["manoeuvre"]).apply(scores, include_groups=False)
        print("\nper manoeuvre\n" + by_m.to_string(**fmt))
    # information never falls with better data: the median width per receiver and cell
    u8 = df[(df["utilisation"] >= 0.8) & (df["fit"] != "inconsistent")]
    if u8["receiver"].nunique() > 1:
        w = (u8["mu_high"] - u8["mu_low"]).replace(np.inf, np.nan)
        fin = u8.assign(width=w, upper=np.isfinite(u8["mu_high"]))
        mono = fin.groupby(["tyre", "vehicle", "receiver"]).agg(
            upper=("upper", "mean"), width=("width", "median")
        )
        print("\nper cell and receiver (u ≥ 0.8): upper end given, median width\n"
              + mono.unstack("receiver").to_string(**fmt))  # fmt: skip
    if args.truth.startswith("commonroad"):  # the drives are paired across receivers
        better_report(df_all)
    what = df[df["observable"] | (df["utilisation"] >= 0.8)]
    lim = what.groupby(["receiver", "limited_by"]).size().rename("axle-cases")
    print("\nwhat limits the estimate (utilisation ≥ 0.8 or a value given)\n" + lim.to_string())
    if args.plot:
        plot(df, args.plot)


def plot(df: pd.DataFrame, path: str) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(2, 3, figsize=(14, 8), sharex=True, sharey="row")
    for j, rec in enumerate(RECEIVERS):
        d = df[df["receiver"] == rec]
        ax = axes[0, j]
        gv = d[d["observable"]]
        ax.errorbar(
            gv["utilisation"],
            gv["mu"] - gv["mu_true"],
            yerr=[
                (gv["mu"] - gv["mu_low"]).clip(lower=0),
                (gv["mu_high"] - gv["mu"]).clip(lower=0),
            ],
            fmt="o",
            ms=3,
            alpha=0.5,
            label="estimate ± 90 % interval",
        )
        ax.axhline(0, color="k", lw=0.8)
        ax.set_ylim(-0.4, 0.4)
        ax.set_title(f"estimated μ — {rec}")
        ax = axes[1, j]
        ax.plot(d["utilisation"], d["grip_used_lower"] - d["mu_true"], ".", ms=3, alpha=0.4)
        ax.axhline(0, color="r", lw=0.8)
        ax.set_ylim(-1.0, 0.2)
        ax.set_title(f"measured-grip bound − true μ — {rec}")
        ax.set_xlabel("true utilisation of the axle")
    axes[0, 0].set_ylabel("estimate − true μ")
    axes[1, 0].set_ylabel("bound − true μ (must be ≤ 0)")
    axes[0, 0].legend(loc="lower left", fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    print(f"plot: {path}")


if __name__ == "__main__":
    main()
