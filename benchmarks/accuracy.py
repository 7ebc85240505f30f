"""Accuracy of the friction methods on simulated drives with known μ.

Drives: gripsense's simulator (brush tyres, the demo's Corolla-like car), circles from the
thesis's grids (20–50 km/h × R 20/30/40 m) plus near-limit circles (utilisation 0.85, 0.95 at
R 30 m) on roads with μ ∈ {0.2, 0.3, …, 1.1}; 1.5 laps after a 6 s straight lead-in, receiver
emulated at 10 Hz with a 0.5° mounting offset. Two receivers:

* ``v100``: Hemisphere V100-like defaults (heading 0.3° white + 0.4° slow, ≈ 0.5° rms), and the
  estimator's default noise model (G known to 20 %);
* ``rtk``: an RTK-class dual-antenna receiver (0.05° + 0.05°) and a calibrated tyre (G to 5 %).

Methods: ``thesis-2`` and ``brush-2`` (per-wheel summaries of the rear wheels: the median of
valid samples, reported only when most steady samples are valid) and ``axle-window`` (rear-axle
summary, profile-likelihood interval). For each, binned by the true rear-axle utilisation
a_y/(μ g): how often a value is given, its bias and RMSE, how often the reported interval
covers the truth, and the worst miss of an interval. Prints a table and saves a plot.

Usage: python benchmarks/accuracy.py [--quick] [--workers 2] [--plot benchmarks/accuracy.png]
"""

from __future__ import annotations

import argparse
import time
from concurrent.futures import ProcessPoolExecutor

import numpy as np
import pandas as pd

MUS = [0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 0.9, 1.0, 1.1]
BINS = [0.0, 0.4, 0.6, 0.8, 0.9, 1.01]


def cases(quick: bool) -> list[dict]:
    g = 9.80665
    out = []
    mus = MUS[::3] if quick else MUS
    speeds = (30, 50) if quick else (20, 30, 40, 50)
    radii = (20, 40) if quick else (20, 30, 40)
    for mu in mus:
        for v in speeds:
            for r in radii:
                out.append({"mu": mu, "speed_kmh": v, "radius_m": r})
        for u in (0.85, 0.95):
            out.append(
                {"mu": mu, "speed_kmh": float(np.sqrt(u * mu * g * 30.0) * 3.6), "radius_m": 30.0}
            )
    return out


def one(args) -> list[dict]:
    case, receiver, seed = args
    from gripsense import FrictionRun
    from gripsense.config import Vehicle
    from gripsense.data import sample_path
    from gripsense.estimate.noise import NoiseModel
    from gripsense.io import read_nmea
    from gripsense.sim import SimParams
    from gripsense.sim import maneuvers as M
    from gripsense.sim.gnss import CompassNoise, emulate_compass

    veh = Vehicle.from_toml(sample_path("corolla_sim.toml"))
    p = SimParams.from_vehicle(veh)
    ant = (-veh.cg_offset[0], -veh.cg_offset[1])
    if receiver == "rtk":
        noise, nm = CompassNoise.rtk(), NoiseModel.rtk()
    else:
        noise, nm = CompassNoise(), NoiseModel()
    m = M.circle(case["speed_kmh"] / 3.6, case["radius_m"], laps=1.5, params=p)
    res = M.run(p, m, mu=case["mu"])
    log = emulate_compass(res, ant, noise=noise, seed=seed)
    tr = log.truth[
        (log.truth["t_s"] > m.settle_s) & log.truth["wheel"].astype(str).str.startswith("rear")
    ]
    util = (
        float((tr.groupby("t_s")["force_N"].sum().abs() / tr.groupby("t_s")["load_N"].sum()).mean())
        / case["mu"]
    )
    ep = read_nmea(log.lines).epochs
    rows = []
    for method in ("thesis-2", "brush-2", "axle-window"):
        r = FrictionRun(veh, method=method, noise=nm).run(ep)
        s = r.summary
        recs = (
            s.to_dict("records")
            if method == "axle-window"
            else [x for x in s.to_dict("records") if x["wheel"].startswith("rear")]
        )
        for x in recs:
            rows.append(
                {
                    **case,
                    "receiver": receiver,
                    "method": method,
                    "utilisation": util,
                    "given": bool(x["observable"]),
                    "mu_hat": x["mu"],
                    "lo": x["mu_low"],
                    "hi": x["mu_high"],
                    "bound": x["mu_lower_bound"],
                }
            )
    return rows


def table(df: pd.DataFrame) -> pd.DataFrame:
    df = df.copy()
    df["bin"] = pd.cut(
        df["utilisation"],
        BINS,
        right=False,
        labels=["<0.4", "0.4-0.6", "0.6-0.8", "0.8-0.9", ">=0.9"],
    )
    err = df["mu_hat"] - df["mu"]
    df["err"] = np.where(df["given"], err, np.nan)
    lo = df["lo"].fillna(-np.inf)
    hi = df["hi"].fillna(np.inf)
    df["covered"] = (lo <= df["mu"]) & (df["mu"] <= hi)
    df["miss"] = np.where(df["given"], np.maximum(lo - df["mu"], df["mu"] - hi).clip(0), np.nan)
    df["bound_ok"] = df["bound"].fillna(0) <= df["mu"] + 0.02
    g = df.groupby(["receiver", "method", "bin"], observed=True)
    out = g.agg(
        n=("mu", "size"),
        given=("given", "mean"),
        bias=("err", "mean"),
        rmse=("err", lambda e: float(np.sqrt(np.nanmean(e**2))) if e.notna().any() else np.nan),
        coverage=("covered", "mean"),
        worst_miss=("miss", "max"),
        bound_ok=("bound_ok", "mean"),
    )
    return out.reset_index()


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--plot", default="benchmarks/accuracy.png")
    ap.add_argument("--csv", default=None)
    args = ap.parse_args()
    jobs = [(c, rec, 100 + i) for rec in ("v100", "rtk") for i, c in enumerate(cases(args.quick))]
    t0 = time.perf_counter()
    with ProcessPoolExecutor(args.workers) as ex:
        rows = [r for part in ex.map(one, jobs, chunksize=4) for r in part]
    df = pd.DataFrame(rows)
    print(f"{len(jobs)} drives in {time.perf_counter() - t0:.0f} s")
    if args.csv:
        df.to_csv(args.csv, index=False)
    t = table(df)
    pd.set_option("display.width", 160)
    print(t.to_string(index=False, float_format=lambda v: f"{v:.3f}"))
    for rec in ("v100", "rtk"):
        aw = df[(df["method"] == "axle-window") & (df["receiver"] == rec)]
        lo = aw["lo"].fillna(-np.inf)
        hi = aw["hi"].fillna(np.inf)
        cov = float(((lo <= aw["mu"]) & (aw["mu"] <= hi)).mean())
        hi_u = aw[aw["utilisation"] >= 0.6]
        e = (hi_u["mu_hat"] - hi_u["mu"])[hi_u["given"]]
        miss = np.maximum(lo - aw["mu"], aw["mu"] - hi)[aw["given"]].clip(lower=0)
        print(
            f"\naxle-window, {rec}: coverage {cov:.1%} (target 85–95 %); where utilisation ≥ 0.6: "
            f"{len(e)} values, bias {e.mean() if len(e) else float('nan'):+.3f} (≤ 0.05), "
            f"RMSE {np.sqrt((e**2).mean()) if len(e) else float('nan'):.3f} (≤ 0.08); worst miss "
            f"of a value's interval {miss.max() if len(miss) else 0:.3f} (≤ 0.2); "
            f"abstained {1 - aw['given'].mean():.0%}"
        )
    if args.plot:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        fig, axes = plt.subplots(2, 3, figsize=(14, 8), sharex=True, sharey=True)
        for i, rec in enumerate(("v100", "rtk")):
            for j, method in enumerate(("thesis-2", "brush-2", "axle-window")):
                ax = axes[i, j]
                d = df[(df["receiver"] == rec) & (df["method"] == method)]
                gv = d[d["given"]]
                ax.errorbar(
                    gv["utilisation"],
                    gv["mu_hat"] - gv["mu"],
                    yerr=[
                        (gv["mu_hat"] - gv["lo"]).clip(lower=0),
                        (gv["hi"] - gv["mu_hat"]).clip(lower=0),
                    ],
                    fmt="o",
                    ms=3,
                    alpha=0.6,
                    label="value ± 90 % interval",
                )
                nb = d[~d["given"]]
                ax.plot(
                    nb["utilisation"],
                    nb["bound"] - nb["mu"],
                    "v",
                    ms=3,
                    alpha=0.5,
                    color="grey",
                    label="abstained: lower bound",
                )
                ax.axhline(0, color="k", lw=0.8)
                ax.set_ylim(-1.0, 1.0)
                ax.set_title(f"{method} — {rec}")
                if i == 1:
                    ax.set_xlabel("true utilisation a_y / (μ g)")
                if j == 0:
                    ax.set_ylabel("estimate − true μ")
        axes[0, 0].legend(loc="lower left", fontsize=8)
        fig.tight_layout()
        fig.savefig(args.plot, dpi=110)
        print(f"plot: {args.plot}")


if __name__ == "__main__":
    main()
