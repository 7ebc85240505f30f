"""Tyres learned per vehicle (issue 26, part 4): ranges at utilisation ≥ 0.8 with the stiffness
``gripsense calibrate`` learned from ten minutes of everyday driving of the same car, against the
vehicle file's declaration (the truth tyre's stiffness ±10 %, stated to ±20 %).

Per truth tyre × vehicle × receiver: five everyday drives of 128 s (``sim.maneuvers.everyday``,
60 km/h, curves to ~0.35 g both ways, μ 0.9) teach the stiffness; then near-limit circles
(u 0.85, 0.92, 0.97 on R 30 m, μ 0.4 and 0.8) are estimated twice — with the declaration and
with the calibration. Reported: the learned stiffness's error and stated 1σ, and per setting
the share of axle-cases with an upper end, the median width, values, coverage of the stated
ranges and of the values.

Usage: python benchmarks/calibration.py [--workers 2] [--receivers rtk,white-0.3,v100]
"""

from __future__ import annotations

import argparse
import time
from concurrent.futures import ProcessPoolExecutor

import numpy as np
import pandas as pd

TYRES = ("mf-book", "mf-sedan", "mf61")
VEHICLES = ("sedan", "sports", "suv")


def one(job: dict) -> list[dict]:
    from gripsense import FrictionRun
    from gripsense.config.calibration import Calibration, apply_calibration
    from gripsense.estimate.calibration import drive_sums, solve_sums
    from gripsense.io import read_nmea
    from gripsense.io.sensors.steer import steer_at
    from gripsense.sim import maneuvers as M
    from gripsense.sim.drives import (
        limit_speed,
        simulate_drive,
        truth_tyre,
        truth_vehicle,
        user_vehicle,
    )

    veh, tyre, rec = job["vehicle"], job["tyre"], job["receiver"]
    declared = user_vehicle(
        truth_vehicle(veh), tyre, stiffness_error=job["stiffness_error"], stiffness_uncertainty=0.2
    )

    def epochs_and_steer(d):
        ep = read_nmea(d.lines).epochs
        ch = d.steer.assign(steer_rad=np.deg2rad(d.steer["road_wheel_deg"]))
        return ep, steer_at(ch, ep["t_s"].to_numpy(float))

    run = FrictionRun(declared, receiver=rec)
    sums = []
    for i in range(5):  # ten minutes of everyday driving
        d = simulate_drive(
            veh, tyre, M.everyday(60 / 3.6, seed=job["seed"] + i), 0.9, receiver=rec,
            seed=job["seed"] + i,
        )  # fmt: skip
        ep, steer = epochs_and_steer(d)
        wheels, _ = run.wheel_table(ep, steer_rad=steer)
        for axle in ("front", "rear"):
            s = drive_sums(wheels, declared, axle, run.options.noise, file=f"d{i}")
            if s is not None:
                sums.append(s)
    axles = {}
    learned_err = {}
    tt = truth_tyre(tyre)
    for axle in ("front", "rear"):
        c0 = float(declared.cornering_stiffness(axle, declared.static_load(axle)))
        a = solve_sums([s for s in sums if s.axle == axle], c0)
        if a is not None:
            axles[axle] = a
            true_c = float(tt.cornering_stiffness(truth_vehicle(veh).static_load(axle)))
            learned_err[axle] = (
                a.cornering_stiffness_N_per_rad / true_c - 1,
                a.stiffness_uncertainty,
            )
    calibrated = apply_calibration(declared, Calibration(declared.name, axles))
    rows = []
    for mu in (0.4, 0.8):
        for u in (0.85, 0.92, 0.97):
            d = simulate_drive(
                veh, tyre, None, mu, receiver=rec, seed=job["seed"] + 100,
                circle=(limit_speed(mu, 30.0, u), 30.0),
            )  # fmt: skip
            ep, steer = epochs_and_steer(d)
            truth = d.axles.set_index("axle")
            for setting, v in (("declared ±20 %", declared), ("learned", calibrated)):
                s = FrictionRun(v, receiver=rec).run(ep, steer_rad=steer).summary
                for r in s.to_dict("records"):
                    t = truth.loc[r["axle"]]
                    err, sd = learned_err.get(r["axle"], (np.nan, np.nan))
                    rows.append(
                        {
                            **job,
                            "setting": setting,
                            "mu_road": mu,
                            "axle": r["axle"],
                            "mu_true": t["mu_true"],
                            "utilisation": t["utilisation"],
                            "mu": r["mu"],
                            "mu_low": r["mu_low"],
                            "mu_high": r["mu_high"],
                            "observable": bool(r["observable"]),
                            "learned_error": err,
                            "learned_sd": sd,
                        }
                    )
    return rows


def summarise(df: pd.DataFrame) -> pd.Series:
    near = df[df["utilisation"] >= 0.8]
    fin = np.isfinite(near["mu_high"])
    cov = (near["mu_low"] <= near["mu_true"]) & (near["mu_true"] <= near["mu_high"].fillna(np.inf))
    val = near["observable"].astype(bool)
    vcov = cov[val].mean() if val.any() else np.nan
    return pd.Series(
        {
            "n": len(near),
            "upper end": fin.mean(),
            "median width": (near["mu_high"] - near["mu_low"])[fin].median(),
            "values": val.mean(),
            "coverage (ranges)": cov.mean(),
            "coverage (values)": vcov,
        }
    )


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--receivers", default="rtk,white-0.3,v100")
    ap.add_argument("--csv", default=None)
    args = ap.parse_args()
    rng = np.random.default_rng(26)
    jobs = [
        {
            "tyre": t,
            "vehicle": v,
            "receiver": r,
            "stiffness_error": float(rng.uniform(-0.1, 0.1)),
            "seed": 1000 * k,
        }
        for k, (t, v, r) in enumerate(
            (t, v, r) for t in TYRES for v in VEHICLES for r in args.receivers.split(",")
        )
    ]
    t0 = time.perf_counter()
    with ProcessPoolExecutor(args.workers) as ex:
        df = pd.DataFrame([row for part in ex.map(one, jobs) for row in part])
    print(f"{len(jobs)} cars, {len(df)} estimates in {time.perf_counter() - t0:.0f} s")
    if args.csv:
        df.to_csv(args.csv, index=False)
    fmt = {"float_format": lambda x: f"{x:.3f}"}
    learned = df.drop_duplicates(["tyre", "vehicle", "receiver", "axle"])
    err = learned.groupby("receiver").agg(
        median_abs_error=("learned_error", lambda e: float(np.nanmedian(np.abs(e)))),
        worst_abs_error=("learned_error", lambda e: float(np.nanmax(np.abs(e)))),
        median_stated_sd=("learned_sd", "median"),
    )
    print("\nlearned stiffness against the truth tyre's (per axle)\n" + err.to_string(**fmt))
    tab = df.groupby(["receiver", "setting"]).apply(summarise, include_groups=False)
    print("\nnear-limit circles (u ≥ 0.8)\n" + tab.to_string(**fmt))


if __name__ == "__main__":
    main()
