"""Friction inversion speed: vectorised closed forms against a per-sample root finder.

For each method, μ is computed for ``--n`` wheel-epochs (default 10 M) in one call of
``gripsense.physics.brush.invert``. The baseline is what one would write without the closed
forms: for each sample, scipy's ``brentq`` on the method's force equation F(μ) = F_measured
(bracketed on the model's monotone branch; the force is a plain-Python ``math`` function), in a
Python loop. The baseline is timed on
``--n-baseline`` samples and its per-sample time is extrapolated to ``--n``; both rates and the
ratio are printed. Inputs are realistic wheel-epochs (loads 1.5–6 kN, C 2e4–2e5 N/rad,
slip 0.05–6°, μ 0.1–1.3) generated once, so both sides get the same samples.

Usage: python benchmarks/bench_friction.py [--n 10000000] [--n-baseline 20000]
"""

from __future__ import annotations

import argparse
import math
import time

import numpy as np
from scipy.optimize import brentq

from gripsense.physics import brush

METHODS = {
    "brush-2": ("parabolic", "exact"),
    "brush-4": ("quartic", "exact"),
    "thesis-2": ("parabolic", "thesis"),
    "thesis-4": ("quartic", "thesis"),
}


def samples(n: int, rng: np.random.Generator, pressure: str, model: str):
    mu = rng.uniform(0.1, 1.3, n)
    fz = rng.uniform(1500.0, 6000.0, n)
    c = rng.uniform(2e4, 2e5, n)
    b = np.deg2rad(rng.uniform(0.05, 6.0, n))
    f = brush.lateral_force(mu, b, fz, c, pressure=pressure, model=model)
    return f, b, fz, c


def _force(mu: float, t: float, fz: float, pressure: str, model: str) -> float:
    """Scalar brush force in plain Python (math module): what a per-sample solver would call."""
    th = t / (3.0 * mu * fz)
    if pressure == "parabolic":
        if model == "exact":
            return mu * fz * (1.0 - (1.0 - th) ** 3) if th < 1.0 else mu * fz
        return mu * fz * (3.0 * th - 3.0 * th * th) if th <= 1.0 else 0.0
    if th >= 5.0 / 3.0:
        xi = 0.0
    else:
        p, q = 1.0 / 6.0, 0.3 * th - 5.0 / 54.0
        xi = 2.0 / 3.0 - 2.0 * math.sqrt(p / 3.0) * math.sinh(
            math.asinh((3.0 * q / (2.0 * p)) * math.sqrt(3.0 / p)) / 3.0
        )
    if model == "exact":
        if th >= 5.0 / 3.0:
            return mu * fz
        phi = 5 * xi**2 - 10 * xi**3 + 10 * xi**4 - 4 * xi**5
        return mu * fz * (3.0 * th * xi * xi + 1.0 - phi)
    return 3.0 * mu * fz * th * xi


def baseline(f, b, fz, c, pressure, model) -> np.ndarray:
    """Per-sample brentq on F(μ) − F = 0 (plain-Python scalar force, rising branch)."""
    out = np.full(f.size, np.nan)
    t = (c * np.abs(np.tan(b))).tolist()
    f, fz = f.tolist(), fz.tolist()
    # on the rising branch θ = T/(3μFz) lies below the peak: μ > T/(3 Fz θ_peak)
    th_peak = {
        ("parabolic", "exact"): 1.0,
        ("quartic", "exact"): 5 / 3,
        ("parabolic", "thesis"): 0.5,
        ("quartic", "thesis"): 5 / 12,
    }[(pressure, model)]
    for i in range(len(f)):
        lo = t[i] / (3 * fz[i] * th_peak) * (1 + 1e-12)

        def g(mu, i=i):
            return _force(mu, t[i], fz[i], pressure, model) - f[i]

        hi = lo * 2
        try:
            while g(hi) > 0 and hi < 1e6:  # force falls as μ grows on the physical branch
                hi *= 2
            if g(lo) * g(hi) < 0:
                out[i] = brentq(g, lo, hi, xtol=1e-14, rtol=1e-12)
        except ValueError:
            pass
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, default=10_000_000)
    ap.add_argument("--n-baseline", type=int, default=20_000)
    args = ap.parse_args()
    rng = np.random.default_rng(2018)
    brush.invert(1.0, 0.01, 1000.0, 1e4, pressure="quartic")  # load the compiled root finder
    print(
        f"{'method':10s} {'gripsense s':>12s} {'samples/s':>13s} {'brentq µs/sample':>17s} "
        f"{'ratio':>9s} {'agree':>7s}"
    )
    for name, (pressure, model) in METHODS.items():
        f, b, fz, c = samples(args.n, rng, pressure, model)
        t0 = time.perf_counter()
        out = brush.invert(f, b, fz, c, pressure=pressure, model=model)
        dt = time.perf_counter() - t0
        k = args.n_baseline
        t0 = time.perf_counter()
        ref = baseline(f[:k], b[:k], fz[:k], c[:k], pressure, model)
        dtb = time.perf_counter() - t0
        per = dtb / k
        ok = (out["status"][:k] == brush.OK) & np.isfinite(ref)
        agree = np.allclose(out["mu"][:k][ok], ref[ok], rtol=1e-8)
        ratio = per * args.n / dt
        print(
            f"{name:10s} {dt:12.3f} {args.n / dt:13,.0f} {per * 1e6:17.1f} {ratio:8.0f}x "
            f"{'yes' if agree else 'NO':>7s}"
        )
    print(
        f"\n{args.n:,} wheel-epochs per method; baseline timed on {args.n_baseline:,} samples "
        "and extrapolated. Target: ratio >= 100x."
    )


if __name__ == "__main__":
    main()
