"""Live-mode throughput: sustained sentences per second through the whole live loop.

Replays the 24 bundled demo logs back to back (``--repeat`` times) at maximum speed through
``run_live`` (incremental ingest, sliding-window friction updated every 0.25 s, results and raw
bytes recorded with flush + fsync every second), after one warm-up run that compiles the numba
kernels. Prints lines/s and epochs/s, and the ratios to a fast receiver's output (20 Hz × 6
sentences = 120 lines/s) and to a 10 Hz receiver (10 epochs/s, issue 15's target ≥ 1000×).
Friction updates follow the log's own clock (one per second of epoch time, as a receiver in real
time gets them, and the same rows at any replay speed): the loop's cost is ingest plus one
window front end and one online window estimate per axle per log second. (Until 2026-11-26
updates followed the wall clock, so a replay at maximum speed made ~4 updates in the whole run
and the ratio measured ingest alone.)

Usage: python benchmarks/bench_live.py [--repeat 3] [--method brush-2]
"""

from __future__ import annotations

import argparse
import gzip
import tempfile
import time
from pathlib import Path

import gripsense
from gripsense.live import ReplaySource, run_live

DATA = Path(gripsense.__file__).parent / "data"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--method", default="brush-2")
    args = ap.parse_args()
    logs = sorted((DATA / "demo").glob("*.nmea.gz"))
    blob = b"".join(gzip.decompress(p.read_bytes()) for p in logs) * args.repeat
    with tempfile.TemporaryDirectory() as d:
        src_path = Path(d) / "all.nmea"
        src_path.write_bytes(blob)
        warm = Path(d) / "warm.nmea"
        warm.write_bytes(gzip.decompress(logs[0].read_bytes()))
        run_live(
            ReplaySource(warm, speed=0),
            DATA / "corolla_sim.toml",
            method=args.method,
            handle_signals=False,
        )
        t0 = time.perf_counter()
        res = run_live(
            ReplaySource(src_path, speed=0),
            DATA / "corolla_sim.toml",
            method=args.method,
            output=Path(d) / "res.csv",
            handle_signals=False,
        )
        dt = time.perf_counter() - t0
    rep = res["report"]
    print(
        f"{rep.total_lines} lines, {rep.n_epochs} epochs in {dt:.2f} s "
        f"({res['stats'].updates} friction updates, method {args.method})"
    )
    print(f"throughput: {rep.total_lines / dt:,.0f} lines/s, {rep.n_epochs / dt:,.0f} epochs/s")
    print(f"ratio to a 120 lines/s receiver: {rep.total_lines / dt / 120:,.0f}x")
    print(f"ratio to a 10 Hz receiver (10 epochs/s): {rep.n_epochs / dt / 10:,.0f}x")


if __name__ == "__main__":
    main()
