"""The calibrate workflow measured end to end: what a car's own drives teach, and how much more
the ranges say with it, on vehicle models the estimator does not share.

Per car — CommonRoad's single-track drift model and its multi-body model (``vehicle 2``,
Pacejka tyres), and gripsense's simulator with a Magic Formula truth tyre (PAC2002 sedan) — the
user's vehicle file states the stiffness 10 % off, to ±20 %, and the receiver as it is. Then:

- ``declared``: the vehicle file alone (the real-tyre prior family, nothing learned);
- ``calibrated``: the stiffness ``gripsense calibrate`` learns from three everyday drives
  (60 km/h, curves to ~0.35 g, μ 0.9);
- ``learned``: that calibration updated (``calibrate --update``) with one ISO 4138
  constant-radius sweep past the limit on another road (μ 1.0; 0.7 for the multi-body car,
  whose inner wheels lift from ~0.85 g): the curve's shape (a drive near the limit teaches the
  shape, not the stiffness).

Each is applied to steady circles (R 40 m) on μ 0.5 and 0.3 at utilisation 0.7, 0.8, 0.9 and
0.95. Printed per configuration and band of the axle's true utilisation (0.6–0.7: circles aimed at
0.7 that reach a little less): axle-cases, ranges holding the truth (within 0.01, and strictly),
upper ends, median μ_high/μ, values, values within ±0.05 of the truth, and the largest
measured-grip bound above the truth.

``--slippery``: the same configurations on steady circles on μ 0.1, 0.2 and 0.3 (ice, packed snow,
snow) and 0.9 (the dry control) at utilisation 0.8 and 0.9, R ≥ 40 m and 7 m/s: per
configuration and road the share of axle-cases read ``slippery``, analysed (not screened) and
holding the truth (within 0.01, and strictly).

Usage: python benchmarks/learned.py [--workers 2] [--receiver white-0.3] [--cars cr-std,cr-mb,mf]
[--slippery]
"""

from __future__ import annotations

import argparse
import tempfile
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import numpy as np
import pandas as pd

CARS = ("cr-std", "cr-mb", "mf")
US = (0.7, 0.8, 0.9, 0.95)
MUS = (0.5, 0.3)
RADIUS_M = 40.0
SLIPPERY = ((0.1, 0.2, 0.3, 0.9), (0.8, 0.9))
"""--slippery: circles on ice, packed snow and snow at these utilisations, R ≥ 40 m and 7 m/s,
and on a dry road (μ 0.9) as the control that must never read slippery."""


def radius(mu: float, u: float) -> float:
    """The circle's radius [m]: 40 m, or larger so that the speed is at least 7 m/s."""
    return max(RADIUS_M, 7.0**2 / (u * mu * 9.80665))


def _write(d, folder: Path, name: str) -> tuple[Path, Path]:
    log, steer = folder / f"{name}.nmea", folder / f"{name}_steer.csv"
    log.write_text("\n".join(d.lines) + "\n", encoding="ascii")
    d.steer.to_csv(steer, index=False)
    return log, steer


def _drives(car: str, receiver: str):
    """(vehicle file's description, simulate(kind, mu, u, seed) → Drive) of one car."""
    from gripsense.sim import commonroad as CR
    from gripsense.sim import maneuvers as M
    from gripsense.sim.drives import limit_speed, simulate_drive, truth_vehicle, user_vehicle

    if car.startswith("cr-"):
        model = car[3:]
        uv = CR.commonroad_vehicle(stiffness_error=-0.1)

        def sim(kind, mu, u, seed):
            if kind == "everyday":
                plan = CR.cr_everyday(60 / 3.6, seed=seed)
            elif kind == "sweep":
                plan = CR.cr_constant_radius(RADIUS_M, limit_speed(mu, RADIUS_M, 0.5),
                                             limit_speed(mu, RADIUS_M, 1.1))  # fmt: skip
            else:
                plan = CR.cr_circle(limit_speed(mu, radius(mu, u), u), radius(mu, u))
            return CR.commonroad_drive(plan, mu, model=model, receiver=receiver, seed=seed)

        return uv, sim
    uv = user_vehicle(truth_vehicle("sedan"), "mf-sedan", stiffness_error=-0.1,
                      stiffness_uncertainty=0.2)  # fmt: skip

    def sim(kind, mu, u, seed):
        if kind == "everyday":
            return simulate_drive("sedan", "mf-sedan", M.everyday(60 / 3.6, seed=seed), mu,
                                  receiver=receiver, seed=seed)  # fmt: skip
        if kind == "sweep":
            m = M.constant_radius(RADIUS_M, 5.0, limit_speed(1.3 * mu, RADIUS_M, 1.0),
                                  accel_mps2=0.1)  # fmt: skip
            return simulate_drive("sedan", "mf-sedan", m, mu, receiver=receiver, seed=seed)
        r = radius(mu, u)
        return simulate_drive("sedan", "mf-sedan", None, mu, receiver=receiver, seed=seed,
                              circle=(limit_speed(mu, r, u), r))  # fmt: skip

    return uv, sim


def one(job: dict) -> list[dict]:
    from accuracy import declared_band, physical_limit

    from gripsense import FrictionRun
    from gripsense.pipeline import learn_calibration

    car, rec = job["car"], job["receiver"]
    uv, sim = _drives(car, rec)
    band = declared_band(uv)
    rows = []
    with tempfile.TemporaryDirectory(prefix="gripsense-bench-") as tmp:
        folder = Path(tmp)
        every = [_write(sim("everyday", 0.9, None, 10 + i), folder, f"everyday{i}")
                 for i in range(3)]  # fmt: skip
        sweep = _write(sim("sweep", 0.7 if car == "cr-mb" else 1.0, None, 20), folder, "sweep")
        t = time.process_time()
        stiff = learn_calibration([f[0] for f in every], uv, receiver=rec,
                                  steer_csvs=[f[1] for f in every])  # fmt: skip
        full = learn_calibration([sweep[0]], uv, receiver=rec, steer_csvs=[sweep[1]],
                                 previous=stiff)  # fmt: skip
        cpu_learn = time.process_time() - t
        kept = {axle: len(t.shape_members) for axle, t in
                FrictionRun(uv, calibration=full).vehicle.tyres.items()
                if t.shape_members is not None}  # fmt: skip
        learned_axles = sorted({d.axle for d in full.drives if d.shape is not None})
        runs = {
            "declared": FrictionRun(uv, receiver=rec),
            "calibrated": FrictionRun(uv, receiver=rec, calibration=stiff),
            "learned": FrictionRun(uv, receiver=rec, calibration=full),
        }
        seed = 30
        mus, us = SLIPPERY if job.get("slippery") else (MUS, US)
        for mu in mus:
            for u in us:
                seed += 1
                d = sim("circle", mu, u, seed)
                log, steer = _write(d, folder, f"circle{seed}")
                truth = d.axles.set_index("axle")
                limit = {a: physical_limit(d.truth, d.settle_s, uv, a, band)[1]
                         for a in truth.index}  # fmt: skip
                for config, run in runs.items():
                    s = run.run_log(log, steer_csv=steer).summary.set_index("axle")
                    for axle in s.index:
                        r = s.loc[axle]
                        rows.append({
                            "car": car, "receiver": rec, "config": config, "mu_road": mu,
                            "target_u": u, "axle": axle,
                            "mu_true": float(truth.loc[axle, "mu_true"]),
                            "u_true": float(truth.loc[axle, "utilisation"]),
                            "grip_used_lower": float(r["grip_used_lower"]),
                            "mu": float(r["mu"]) if r["observable"] else np.nan,
                            "mu_low": float(r["mu_low"]), "mu_high": float(r["mu_high"]),
                            "limit_high_declared": float(limit.get(axle, np.nan)),
                            "slippery": str(r.get("slippery", "")),
                            "limited_by": str(r.get("limited_by", "")),
                            "shape_learned": axle in learned_axles,
                            "members_kept": kept.get(axle, -1),
                            "cpu_learn_s": cpu_learn,
                        })  # fmt: skip
    return rows


BANDS = [0.6, 0.7, 0.8, 0.9, 1.01]
BAND_NAMES = ["0.6–0.7", "0.7–0.8", "0.8–0.9", "≥ 0.9"]


def scores(df: pd.DataFrame) -> pd.DataFrame:
    """Per configuration and utilisation band: the table the module docstring describes."""
    df = df.assign(
        band=pd.cut(df["u_true"], BANDS, right=False, labels=BAND_NAMES),
        holds=(df["mu_low"] <= df["mu_true"] + 0.01) & (df["mu_true"] - 0.01 <= df["mu_high"]),
        strict=(df["mu_low"] <= df["mu_true"]) & (df["mu_true"] <= df["mu_high"]),
        upper=np.isfinite(df["mu_high"]),
        ratio=df["mu_high"] / df["mu_true"],
        value=np.isfinite(df["mu"]),
        close=(df["mu"] - df["mu_true"]).abs() <= 0.05,
        excess=df["grip_used_lower"] - df["mu_true"],
    )
    g = df.groupby(["config", "band"], observed=True)
    out = pd.DataFrame({
        "cases": g.size(),
        "hold": g["holds"].mean().round(3),
        "hold strictly": g["strict"].mean().round(3),
        "upper": g["upper"].mean().round(3),
        "median μ_high/μ": g["ratio"].median().round(3),
        "value": g["value"].mean().round(3),
        "value ±0.05": g["close"].mean().round(3),
        "bound excess": g["excess"].max().round(3),
    })  # fmt: skip
    return out


def run(cars: str, receiver: str, workers: int, csv: str | None, slippery: bool) -> None:
    """Run the benchmark and print its tables (``accuracy.py --learned`` calls this too)."""
    jobs = [{"car": c, "receiver": receiver, "slippery": slippery} for c in cars.split(",")]
    t = time.time()
    with ProcessPoolExecutor(workers) as ex:
        rows = [r for part in ex.map(one, jobs) for r in part]
    df = pd.DataFrame(rows)
    if csv:
        df.to_csv(csv, index=False)
    pd.set_option("display.width", 160)
    print(f"receiver {receiver}; cars {cars}; {time.time() - t:.0f} s wall")
    if slippery:
        df = df.assign(
            is_slippery=df["slippery"] == "slippery",
            holds=(df["mu_low"] <= df["mu_true"] + 0.01) & (df["mu_true"] - 0.01 <= df["mu_high"]),
            strict=(df["mu_low"] <= df["mu_true"]) & (df["mu_true"] <= df["mu_high"]),
            analysed=~df["limited_by"].eq("no cornering the compass resolves"),
        )
        for name, part in (("u ≥ 0.8", df[df["u_true"] >= 0.8]), ("every circle", df)):
            print(f"slippery, {name} (share of axle-cases; μ 0.9: the dry control):")
            cols = ["is_slippery", "analysed", "holds", "strict"]
            print(part.groupby(["config", "mu_road"])[cols]
                  .agg(["mean"]).droplevel(1, axis=1).assign(cases=part.groupby(
                      ["config", "mu_road"]).size()).round(3).to_string())  # fmt: skip
        cal = df[df["config"] == "calibrated"]
        print("\ncalibrated, per car and road (slippery / axle-cases, every circle):")
        print(cal.groupby(["car", "mu_road"])["is_slippery"].agg(["sum", "size"]).unstack()
              .to_string())  # fmt: skip
        above = int((df["grip_used_lower"] > df["mu_true"] + 0.01).sum())
        print(f"\nmeasured-grip bounds above the truth (+0.01): {above}")
        return
    print(scores(df).to_string())
    print("\nper car, u ≥ 0.8 (upper ends / values ±0.05):")
    hi = df[df["u_true"] >= 0.8]
    hi = hi.assign(upper=np.isfinite(hi["mu_high"]), close=(hi["mu"] - hi["mu_true"]).abs() <= 0.05)
    print(hi.groupby(["car", "config"])[["upper", "close"]].mean().round(2).to_string())
    dec = hi[hi["config"] == "declared"]
    can = np.isfinite(dec["limit_high_declared"])
    print(f"\ndeclared, u ≥ 0.8: upper ends {int(dec['upper'].sum())} of {len(dec)}; the "
          f"physical limit with the declared stiffness's 90 % band (the true operating points, "
          f"no noise) has one on {int(can.sum())}, and the estimate on "
          f"{int(dec['upper'][can].sum())} of those")  # fmt: skip
    members = df[df["config"] == "learned"].groupby(["car", "axle"])["members_kept"].first()
    print("\nprior-family members the sweep left possible (-1: it taught nothing):")
    print(members.to_string())


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--receiver", default="white-0.3")
    ap.add_argument("--cars", default=",".join(CARS))
    ap.add_argument("--csv", default=None)
    ap.add_argument(
        "--slippery", action="store_true",
        help="circles on μ 0.1, 0.2, 0.3 (and 0.9, the control) at u 0.8, 0.9",
    )  # fmt: skip
    args = ap.parse_args()
    run(args.cars, args.receiver, args.workers, args.csv, args.slippery)


if __name__ == "__main__":
    main()
