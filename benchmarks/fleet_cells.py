"""The fleet knows the road (issue 42): what ``gripsense fleet`` says per H3 cell and time bucket
about a road network whose μ is known, from a mixed fleet's everyday driving.

Why: a road operator runs ``gripsense fleet`` to learn where the road is slippery. Everyday
passes rarely reach the grip limit, so a pass rarely gives a value of μ; issue 42 asks that a
cell combine what every pass says (measured grips, upper ends, values) into a range, and sets
targets on a simulated fleet. This is that fleet and its score card.

The network (:func:`gripsense.fleet.network.write_road_network`): five cars — CommonRoad's
single-track and multi-body models (vehicle 2, Pacejka tyres) and gripsense's simulator on three
Magic Formula truth tyres — each with its own vehicle file (stiffness declared 5–10 % off, to
±20 %), receiver (``white-0.3`` or ``rtk``) and calibration learned from three everyday drives of
its own (``[calibration] file``); eight bends (R 35–80 m, 270°) 2 km apart, each with a road μ in
a dry hour (07:00 UTC: 0.9–1.0, two worn roads 0.55) and a wet, cold one (15:00: 0.55–0.65, 0.4,
0.3 and two icy bends, 0.2 and 0.15). Each car passes each bend 2–3 times per hour, as drivers
do: 0.2–0.45 g on a grippy road, 50–90 % of the grip on a slippery one. ``--quick``: two cars
(CommonRoad single-track, the sedan) and three bends.

Then ``run_fleet`` (``--vehicle-map``, ``bucket="1 hour"``, two workers) and per bucket and over
all, on cell-buckets driven by ≥ 3 vehicles and on all: cells; cells with a bounded range
(finite ``mu_low`` and ``mu_high``); ranges holding the bend's road μ (a cell's statement: its
``mu_low`` or else the measured grip ``grip_used_lower`` or else 0, up to its ``mu_high`` or
else ∞; also among the bounded ones, and against the span of the true axle μ of the passes
there — each tyre's own peak at its load, which differs from the road's μ by up to ~15 % for the
PAC2002 sedan tyre); median ``mu_high``/μ of the bounded; values (``mu`` finite) and values
within ±0.05; the slippery calls against the truth (road μ < 0.5): recognised, missed (said
``unknown`` / ``not slippery``), false calls on cells that are not slippery; the largest
``grip_used_lower − μ`` (a measured bound never above the truth) and the ``status`` counts.
Also: per car the stiffness declared, learned and used against the truth; per car the windows
(rows of ``OUT/epochs``) whose own range holds their axle's true μ; per bend and bucket
the cells, bounded ranges and calls; every cell whose range misses the road μ or that is called
slippery when it is not. Finally the same fleet with ``workers=1``: are the cell tables
identical (to 1e-12, NaN = NaN)? The targets of issue 42 are printed beside the figures.

Usage: python benchmarks/fleet_cells.py [--quick] [--keep DIR] [--seed 0] [--csv cells.csv]
(``--keep DIR`` writes the network and the fleet's outputs there and reuses a network already
in it, made with the same options; without it a temporary folder. Full: ~5 min on 2 cores, of
which ~2.5 min make the network; --quick ~40 s, ~1.5 min on a cold numba cache.)
"""

from __future__ import annotations

import argparse
import json
import shutil
import tempfile
import time
from pathlib import Path

import numpy as np
import pandas as pd

QUICK_CARS = ("cr-std", "sedan")
QUICK_BENDS = ("b1", "b4", "b5")
"""--quick: a dry-and-wet bend (0.95 / 0.55), a worn one (0.55 / 0.3), an icy one (0.9 / 0.2)."""
TOLERANCE = 1e-12
"""Two cell tables are identical when every number agrees to this (NaN = NaN) [-]."""
TARGETS = {
    "bounded": "≥ 50 % (≥ 3 vehicles)",
    "holds": "≥ 90 %",
    "recognised": "all slippery",
    "false calls": "0",
    "bound excess": "≤ 0",
    "identical": "yes",
}
"""Issue 42's targets, printed beside the figures."""


def network(outdir: Path, quick: bool, seed: int, workers: int):
    """The simulated fleet in *outdir* (made, or reused when made with the same options)."""
    from gripsense.fleet import network as F

    cars = [c for c in F.NETWORK_CARS if not quick or c.name in QUICK_CARS]
    bends = [b for b in F.network_bends() if not quick or b.name in QUICK_BENDS]
    options = {"quick": quick, "seed": seed}
    stamp = outdir / "options.json"
    if (outdir / "truth.csv").is_file() and stamp.is_file():
        if json.loads(stamp.read_text()) == options:
            logs = pd.read_csv(outdir / "truth.csv", keep_default_na=False,
                               na_values=[""])  # fmt: skip
            print(f"network reused from {outdir} ({len(logs)} passes)")
            return F.FleetNetwork(outdir, cars, bends, list(F.NETWORK_BUCKETS), logs)
        raise SystemExit(f"{outdir}: holds a network made with {stamp.read_text()}; "
                         f"give another --keep folder for {options}")  # fmt: skip
    t = time.time()
    net = F.write_road_network(outdir, cars=cars, bends=bends, seed=seed, workers=workers)
    stamp.write_text(json.dumps(options))
    print(f"network: {len(cars)} cars, {len(bends)} bends, {len(net.logs)} passes, "
          f"simulated and calibrated in {time.time() - t:.0f} s")  # fmt: skip
    return net


def calibrations(net) -> pd.DataFrame:
    """Per car and axle: the stiffness declared, learned from its three everyday drives and
    true (the declaration is the truth times 1 + the car's ``stiffness_error``).
    """
    from gripsense.config import Vehicle
    from gripsense.config.calibration import calibrated_vehicle, read_calibration

    rows = []
    for car in net.cars:
        vfile = net.outdir / "vehicles" / f"{car.name}.toml"
        veh = Vehicle.from_toml(vfile)
        cal = read_calibration(veh.calibration_file)
        used = calibrated_vehicle(veh)
        for axle, t in veh.tyres.items():
            c = t.cornering_stiffness_N_per_rad
            true = c / (1.0 + car.stiffness_error)
            learned = cal.axles[axle] if axle in cal.axles else None
            rows.append({
                "car": car.name, "receiver": car.receiver, "axle": axle,
                "declared/true": round(c / true, 3),
                "learned/true": round(learned.cornering_stiffness_N_per_rad / true, 3)
                if learned else np.nan,
                "learned 1σ": learned.stiffness_uncertainty if learned else np.nan,
                "used/true": round(used.tyres[axle].cornering_stiffness_N_per_rad / true, 3),
                "used 1σ": round(used.tyres[axle].stiffness_uncertainty, 3),
            })  # fmt: skip
    return pd.DataFrame(rows)


def window_scores(outdir: Path, net) -> pd.DataFrame:
    """Per car: the fleet's rows (``OUT/epochs``, one per axle window) and how many of their own
    statements hold their axle's true μ — what every cell's combination starts from.
    """
    rows = pd.read_parquet(outdir / "epochs")
    rows["vehicle"] = rows["vehicle"].astype(str)
    truth = net.logs.assign(name=[Path(x).name for x in net.logs["log"]])
    truth = truth.set_index(["car", "name"])
    key = list(zip(rows["vehicle"], rows["log"], strict=True))
    axle_mu = np.array([truth.loc[k, f"mu_{u}"] for k, u in zip(key, rows["unit"], strict=True)])
    lo = rows["mu_low"].to_numpy(float)
    lo = np.where(np.isfinite(lo), lo, rows["grip_used_lower"].to_numpy(float))
    hi = rows["mu_high"].to_numpy(float)
    hi = np.where(np.isfinite(hi), hi, np.inf)
    rows = rows.assign(
        upper=np.isfinite(hi),
        holds=(lo - 1e-9 <= axle_mu) & (axle_mu <= hi),
        below=hi < axle_mu,
    )
    g = rows.groupby("vehicle")
    out = pd.DataFrame({
        "windows": g.size(),
        "with an upper end": g["upper"].sum(),
        "holding the axle's μ": g["holds"].mean().round(3),
        "upper end below it": g["below"].sum(),
        "values": g["observable"].sum(),
    })  # fmt: skip
    out.loc["all"] = [len(rows), int(rows["upper"].sum()), round(rows["holds"].mean(), 3),
                      int(rows["below"].sum()), int(rows["observable"].sum())]  # fmt: skip
    return out


def statement(cells: pd.DataFrame) -> tuple[np.ndarray, np.ndarray]:
    """Each cell's range as it states it: ``mu_low`` (else the measured grip, else 0) to
    ``mu_high`` (else ∞).
    """
    lo = cells["mu_low"].to_numpy(float)
    lo = np.where(np.isfinite(lo), lo, cells["grip_used_lower"].to_numpy(float))
    lo = np.where(np.isfinite(lo), lo, 0.0)
    hi = cells["mu_high"].to_numpy(float)
    return lo, np.where(np.isfinite(hi), hi, np.inf)


def score(c: pd.DataFrame) -> dict:
    """The figures of the module docstring on the cell-buckets *c* (with the truth)."""
    mu = c["mu_true"].to_numpy(float)
    lo, hi = statement(c)
    bounded = np.isfinite(c["mu_low"].to_numpy(float)) & np.isfinite(c["mu_high"].to_numpy(float))
    holds = (lo - 1e-9 <= mu) & (mu <= hi)
    holds_axle = (lo - 1e-9 <= c["mu_axle_max"].to_numpy(float)) & (
        c["mu_axle_min"].to_numpy(float) <= hi
    )
    value = np.isfinite(c["mu"].to_numpy(float))
    close = value & (np.abs(c["mu"].to_numpy(float) - mu) <= 0.05)
    slip = mu < 0.5
    call = c["slippery"].astype(str).to_numpy()
    bound = c["grip_used_lower"].to_numpy(float)
    n = len(c)

    def share(k: int, of: int) -> str:
        return f"{k}/{of} ({100 * k / of:.0f} %)" if of else "0/0"

    ratio = c["mu_high"].to_numpy(float)[bounded] / mu[bounded]
    return {
        "cells": str(n),
        "bounded": share(int(bounded.sum()), n),
        "holds": share(int(holds.sum()), n),
        "holds (bounded)": share(int((holds & bounded).sum()), int(bounded.sum())),
        "holds an axle's true μ": share(int(holds_axle.sum()), n),
        "median μ_high/μ (bounded)": f"{np.median(ratio):.2f}" if ratio.size else "–",
        "values": share(int(value.sum()), n),
        "values ±0.05": share(int(close.sum()), int(value.sum())),
        "slippery cells": str(int(slip.sum())),
        "recognised": share(int((slip & (call == "slippery")).sum()), int(slip.sum())),
        "missed: unknown": str(int((slip & (call == "unknown")).sum())),
        "missed: not slippery": str(int((slip & (call == "not slippery")).sum())),
        "false calls": share(int((~slip & (call == "slippery")).sum()), int((~slip).sum())),
        "not slippery said (of not slippery)": share(
            int((~slip & (call == "not slippery")).sum()), int((~slip).sum())
        ),
        "bound excess": _signed(np.nanmax(bound - mu) if np.isfinite(bound).any() else np.nan),
        "bound excess over axle μ": _signed(
            np.nanmax(bound - c["mu_axle_max"].to_numpy(float))
            if np.isfinite(bound).any()
            else np.nan
        ),
    }


def _signed(x: float) -> str:
    return "–" if not np.isfinite(x) else f"{x:+.3f}"


def score_table(cells: pd.DataFrame, min_vehicles: int = 3) -> pd.DataFrame:
    """Per bucket and over all, on cells driven by ≥ *min_vehicles* vehicles and on all."""
    cols = {}
    for bucket in [*sorted(cells["bucket_name"].unique()), "all"]:
        b = cells if bucket == "all" else cells[cells["bucket_name"] == bucket]
        cols[f"{bucket} ≥{min_vehicles} veh"] = score(b[b["n_vehicles"] >= min_vehicles])
        cols[f"{bucket} all"] = score(b)
    out = pd.DataFrame(cols)
    out["target"] = [TARGETS.get(k, "") for k in out.index]
    return out


def identical(a: pd.DataFrame, b: pd.DataFrame) -> tuple[bool, str]:
    """Are two cell tables the same (to :data:`TOLERANCE`, NaN = NaN)? And what differs."""
    if list(a.columns) != list(b.columns) or len(a) != len(b):
        return False, f"shapes differ: {a.shape} vs {b.shape}"
    a = a.sort_values(["cell", "bucket"]).reset_index(drop=True)
    b = b.sort_values(["cell", "bucket"]).reset_index(drop=True)
    bad = []
    for col in a.columns:
        x, y = a[col], b[col]
        if pd.api.types.is_numeric_dtype(x) and pd.api.types.is_numeric_dtype(y):
            xa, ya = x.to_numpy(float), y.to_numpy(float)
            same = np.isclose(xa, ya, rtol=0.0, atol=TOLERANCE, equal_nan=True)
            same |= np.isinf(xa) & (xa == ya)
            if not same.all():
                diff = np.nanmax(np.abs(xa - ya)[~same]) if (~same).any() else np.nan
                bad.append(f"{col} ({int((~same).sum())} rows, up to {diff:.3g})")
        elif not (x.isna() == y.isna()).all() or not (x[x.notna()] == y[y.notna()]).all():
            bad.append(f"{col} ({int((x.astype(str) != y.astype(str)).sum())} rows)")
    return not bad, ", ".join(bad)


def run(quick: bool, keep: str | None, seed: int, csv: str | None) -> None:
    """Make (or reuse) the network, run the fleet with 2 and 1 workers, print the score card."""
    from gripsense.fleet import run_fleet
    from gripsense.fleet.network import GRIPPY_MU

    pd.set_option("display.width", 200)
    pd.set_option("display.max_columns", 20)
    folder = Path(keep) if keep else Path(tempfile.mkdtemp(prefix="gripsense-fleet-cells-"))
    try:
        folder.mkdir(parents=True, exist_ok=True)
        net = network(folder / "network", quick, seed, workers=2)
        u = net.logs
        grippy = u[u["mu_road"] >= GRIPPY_MU]
        slippery = u[u["mu_road"] < GRIPPY_MU]
        print(f"passes: a_y {grippy['ay_g'].min():.2f}–{grippy['ay_g'].max():.2f} g on grippy "
              f"roads (μ ≥ {GRIPPY_MU}), utilisation {slippery['utilisation'].min():.2f}–"
              f"{slippery['utilisation'].max():.2f} on slippery ones")  # fmt: skip
        print(calibrations(net).to_string(index=False))
        tables = {}
        for workers in (2, 1):
            out = folder / f"fleet-w{workers}"
            t = time.time()
            res = run_fleet(net.patterns, out, vehicle_map=net.vehicle_map, bucket="1 hour",
                            workers=workers, overwrite=True)  # fmt: skip
            problems = res.logs[res.logs["problem"] != ""]
            print(f"run_fleet, {workers} worker(s): {time.time() - t:.0f} s wall, "
                  f"{len(res.logs)} logs, {len(problems)} problems")  # fmt: skip
            for r in problems.head(5).itertuples():
                print(f"  problem: {Path(r.log).name}: {r.problem}")
            tables[workers] = pd.read_parquet(out / "cells.parquet")
            if workers == 2:
                print("the passes' windows (OUT/epochs), per car:")
                print(window_scores(out, net).to_string())
        cells = net.cell_truth(tables[2])
        names = {pd.Timestamp(b.start): b.name for b in net.buckets}
        cells["bucket_name"] = [
            names.get(pd.Timestamp(t).floor("h"), "?")
            for t in pd.to_datetime(cells["bucket"], utc=True)
        ]
        lost = cells["mu_true"].isna()
        if lost.any():
            print(f"{int(lost.sum())} cell-buckets at no bend or bucket (left out)")
        cells = cells[~lost]
        if csv:
            cells.to_csv(csv, index=False)
        print()
        print(score_table(cells).to_string())
        print("\nstatus (all cell-buckets):")
        print(cells.groupby(["bucket_name", "status"]).size().unstack(fill_value=0).to_string())
        print("\nper bend and bucket (≥ 3 vehicles, else all): cells, bounded, holds, calls")
        per = []
        for (bend, bucket), g in cells.groupby(["bend", "bucket_name"]):
            g3 = g[g["n_vehicles"] >= 3]
            g = g3 if len(g3) else g
            lo, hi = statement(g)
            per.append({
                "bend": bend, "bucket": bucket, "μ road": g["mu_true"].iloc[0],
                "μ axles": f"{g['mu_axle_min'].iloc[0]:.2f}–{g['mu_axle_max'].iloc[0]:.2f}",
                "cells": len(g),
                "bounded": int((np.isfinite(g["mu_low"]) & np.isfinite(g["mu_high"])).sum()),
                "holds": int(((lo - 1e-9 <= g["mu_true"]) & (g["mu_true"] <= hi)).sum()),
                "median low": round(float(np.median(lo)), 2),
                "median high": round(float(np.median(hi)), 2),
                "calls": ", ".join(f"{k} {v}" for k, v in
                                   g["slippery"].value_counts().sort_index().items()),
            })  # fmt: skip
        print(pd.DataFrame(per).to_string(index=False))
        lo, hi = statement(cells)
        wrong = ~((lo - 1e-9 <= cells["mu_true"]) & (cells["mu_true"] <= hi)) | (
            (cells["mu_true"] >= 0.5) & (cells["slippery"] == "slippery")
        )
        if wrong.any():
            print("\ncells whose range misses the road μ, or called slippery when not (all "
                  "columns: --csv):")  # fmt: skip
            cols = ["cell", "bucket_name", "bend", "mu_true", "mu_axle_min", "mu_axle_max",
                    "mu", "mu_low", "mu_high", "grip_used_lower", "status", "slippery",
                    "n_vehicles", "n_passes"]  # fmt: skip
            print(cells.loc[wrong, cols].round(3).to_string(index=False))
        same, why = identical(tables[1], tables[2])
        print(f"\ncells with 1 and 2 workers identical (to {TOLERANCE:g}): "
              f"{'yes' if same else 'NO: ' + why}   [target: {TARGETS['identical']}]")  # fmt: skip
    finally:
        if not keep:
            shutil.rmtree(folder, ignore_errors=True)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="two cars, three bends (< 2 min)")
    ap.add_argument("--keep", default=None, help="folder for the network and the outputs")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--csv", default=None, help="write the scored cell table here")
    args = ap.parse_args()
    run(args.quick, args.keep, args.seed, args.csv)


if __name__ == "__main__":
    main()
