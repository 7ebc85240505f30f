"""Fleet throughput: vehicle-hours of 10 Hz logs processed per minute, 1 and 2 workers.

Logs: road-like drives from the simulator — 50 s of straight driving, then one lap of a curve
(R 30–60 m, near the grip limit on dry, wet or snowy road) — so curves are ~15 % of the time, as
on real roads; 8 distinct drives, copied ``--copies`` times into per-vehicle folders (the work per
log is the same, copies only make the batch long enough to measure). Each run is a full
``run_fleet`` (a new LocalCluster — about 3 s of start-up included —, tasks of
``--logs-per-task`` logs, per-estimate Parquet, DuckDB aggregation, map page).

With ``--segments S`` each log is S such drives one after the other (S = 12: ~15-minute logs).

Usage: python benchmarks/bench_fleet.py [--copies 40] [--segments 1] [--method ...]
(issue 15's shape, ≥ 200 logs and ≥ 50 vehicle-hours: --copies 25 --segments 12, 200 logs of
~15 min; the short-log case: --copies 300, 2400 logs of ~75 s)
"""

from __future__ import annotations

import argparse
import datetime
import gzip
import shutil
import tempfile
import time
from pathlib import Path

import gripsense
from gripsense.config import Vehicle
from gripsense.fleet import run_fleet
from gripsense.io import read_nmea
from gripsense.sim import maneuvers as M
from gripsense.sim.gnss import DEFAULT_START, CompassNoise, emulate_compass
from gripsense.sim.vehicle import SimParams

VEHICLE = Path(gripsense.__file__).parent / "data" / "corolla_sim.toml"


def make_drives(d: Path, segments: int = 1) -> list[Path]:
    """The 8 distinct logs. With ``segments`` > 1 each log is that many drives one after the
    other on one clock (its own drive first, then the others in turn; a fresh noise seed for
    each) — logs of ``segments`` × ~75 s with the same mix of straight driving and curves."""
    veh = Vehicle.from_toml(VEHICLE)
    params = SimParams.from_vehicle(veh, drive="front")
    ant = (-veh.cg_offset[0], -veh.cg_offset[1])
    sims = []
    for k, (mu, radius) in enumerate(
        [(0.9, 40), (0.5, 30), (0.25, 30), (0.9, 60), (0.5, 60), (0.9, 30), (0.25, 50), (0.5, 40)]
    ):
        speed = (0.93 * mu * 9.81 * radius) ** 0.5
        m = M.circle(speed, radius, laps=1.0, lead_s=50.0, left=bool(k % 2), params=params)
        sims.append(M.run(params, m, mu=mu))
    out = []
    for k in range(len(sims)):
        start = DEFAULT_START
        lines: list[str] = []
        for j in range(segments):
            res = sims[(k + j) % len(sims)]
            log = emulate_compass(
                res,
                ant,
                noise=CompassNoise.rtk(),
                seed=k + 8 * j,
                origin=(33.62 + 0.002 * k, 133.72, 10.0),
                start=start,
            )
            lines += log.lines
            start += datetime.timedelta(seconds=float(res.body["t_s"].iloc[-1]) + 0.1)
        p = d / f"drive{k}.nmea.gz"
        with gzip.open(p, "wt", newline="") as f:
            f.write("\r\n".join(lines) + "\r\n")
        out.append(p)
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--copies", type=int, default=40)
    ap.add_argument("--method", default="axle-window")
    ap.add_argument("--logs-per-task", type=int, default=8)
    ap.add_argument("--segments", type=int, default=1, help="drives per log (12: ~15-minute logs)")
    args = ap.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        drives = make_drives(tmp, args.segments)
        hours = sum(read_nmea(p).epochs["t_s"].max() for p in drives) / 3600
        logs = tmp / "logs"
        for c in range(args.copies):
            vd = logs / f"car{c:03d}"
            vd.mkdir(parents=True)
            for p in drives:
                shutil.copy(p, vd / p.name)
        total_h = hours * args.copies
        print(
            f"{len(drives) * args.copies} logs, {total_h:.2f} vehicle-hours at 10 Hz, "
            f"method {args.method}"
        )
        rates = {}
        for w in (1, 2):
            t0 = time.perf_counter()
            res = run_fleet(
                [str(logs / "**" / "*.nmea.gz")],
                tmp / f"out{w}",
                vehicle=VEHICLE,
                method=args.method,
                receiver="rtk",
                workers=w,
                logs_per_task=args.logs_per_task,
            )
            dt = time.perf_counter() - t0
            rates[w] = total_h / (dt / 60)
            print(
                f"{w} worker(s): {dt:.1f} s total ({total_h / (dt / 60):,.1f} vehicle-hours/min); "
                f"{len(res.cells)} cell-buckets, {int((res.logs['problem'] != '').sum())} problems"
            )
        print(f"speed-up 1 → 2 workers: {rates[2] / rates[1]:.2f}x")
        breakdown(drives, tmp, args.method, len(drives) * args.copies, dt_total=dt)


def breakdown(drives: list[Path], tmp: Path, method: str, n_logs: int, dt_total: float) -> None:
    """Where the time goes: the steps of one task timed in this process on the distinct drives
    (scaled to the run's number of logs), DuckDB aggregation on the 2-worker result, and the
    rest of the 2-worker run (cluster start, scheduling, map page) as the remainder."""
    from gripsense.config import Vehicle
    from gripsense.estimate.options import WindowOptions
    from gripsense.fleet.aggregate import aggregate_cells
    from gripsense.fleet.tasks import _cells
    from gripsense.io.output_folder import write_parquet
    from gripsense.pipeline import FrictionRun

    veh = Vehicle.from_toml(VEHICLE)
    # as a fleet task runs it: the windows' statements, no drive profile
    run = FrictionRun(veh, method=method, receiver="rtk", window=WindowOptions(drive=False))
    t = dict.fromkeys(("ingest", "estimation", "rows + H3", "Parquet"), 0.0)
    for p in drives:
        t0 = time.perf_counter()
        ep = read_nmea(p).epochs
        t1 = time.perf_counter()
        res = run.run(ep)
        t2 = time.perf_counter()
        est = res.estimates()
        e = est["epoch"].to_numpy(int)
        rows = est.assign(
            lat_deg=ep["lat_deg"].to_numpy(float)[e], lon_deg=ep["lon_deg"].to_numpy(float)[e]
        )
        rows["cell"] = _cells(rows["lat_deg"].to_numpy(), rows["lon_deg"].to_numpy(), 11)
        t3 = time.perf_counter()
        write_parquet(rows.drop(columns="vehicle", errors="ignore"), tmp / f"{p.stem}.parquet")
        t4 = time.perf_counter()
        for k, dt in zip(t, (t1 - t0, t2 - t1, t3 - t2, t4 - t3), strict=True):
            t[k] += dt * n_logs / len(drives)
    t0 = time.perf_counter()
    aggregate_cells(tmp / "out2")
    t["DuckDB aggregation"] = time.perf_counter() - t0
    work = sum(t.values())
    print("where the time goes (CPU seconds for the run's logs, one core):")
    for k, v in t.items():
        print(f"  {k:<20} {v:6.2f} s")
    print(
        f"  2-worker run {dt_total:.2f} s wall for {work:.2f} s of work: the rest (cluster "
        f"start, scheduling, serialisation, map page, two workers sharing 2 cores with the "
        f"client) {max(dt_total - work / 2, 0):.2f} s"
    )


if __name__ == "__main__":
    main()
