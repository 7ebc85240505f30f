"""Constrained 18-coefficient tyre fit: gripsense's Gauss–Newton SQP against scipy SLSQP.

Data: ``--n`` (default 10 000) points of road-like cornering (slip angle, camber and load all
driven by the lateral acceleration, seed 002 Figs. 4/16) generated from a PAC94 coefficient set
with 40 N force noise. Both solvers minimise the same cost ½Σ(Fy_model − Fy)² over the same free
coefficients, from the same data-derived start, with the same bounds and the same seed-002
constraints (``--constraints``, default ``all``):

* gripsense: :func:`gripsense.identify.tyre_fit.pac94_fit` (exact Jacobian, Gauss–Newton SQP);
* baseline: ``scipy.optimize.minimize(method="SLSQP")`` with no gradients supplied, so SLSQP uses
  finite differences for the cost and constraint gradients (its default), ``maxiter=2000``,
  ``ftol=1e-12``. To give it a fair chance the variables are scaled to unit curvature
  (1/√diag(JᵀJ) near the start, computed inside the timed section) and the cost is divided by its
  starting value; unscaled, SLSQP stops after one iteration at a cost ~100× higher.

Printed per dataset: wall time, final cost and evaluations of each; the cost ratio (SLSQP /
gripsense, must be ≥ 1); the raw run-time ratio; and the time SLSQP needs to reach gripsense's
final cost (from its per-iteration callback; "never" when it stops above it). ``--repeat`` datasets
with different seeds are run.

Usage: python benchmarks/bench_tyre_fit.py [--n 10000] [--repeat 3] [--constraints all]
"""

from __future__ import annotations

import argparse
import time

import numpy as np
from scipy.optimize import minimize

from gripsense.identify.tyre_fit import fit_pac94
from gripsense.identify.tyre_fit._solve import _constraint_flags
from gripsense.identify.tyre_fit.pac94_fit import _pac94_setup
from gripsense.physics.magic_formula.pac94 import pac94_lateral, pac94_lateral_native
from gripsense.sim.tyre_data import PAC94_EXAMPLE, cornering_samples

TRUTH = PAC94_EXAMPLE


def slsqp_baseline(d, constraints):
    alpha, gamma, fz, fy = (d[c].to_numpy() for c in ("alpha_rad", "gamma_rad", "fz_N", "fy_N"))
    flags = _constraint_flags(constraints)
    x0, lb, ub, fixed, cons, _ = _pac94_setup(alpha, gamma, fz, fy, flags, "published", None, None)
    free = np.array([i for i in range(x0.size) if i not in fixed])
    fz_kn, al, g = fz / 1000.0, np.rad2deg(alpha), np.rad2deg(gamma)

    # give SLSQP a fair, well-scaled problem: unit-scaled variables (1/√diag(JᵀJ) at the start)
    # and the cost divided by its starting value
    t0 = time.perf_counter()
    probe = x0 + 0.01 * (1.0 + np.abs(x0)) * np.where(np.arange(x0.size) % 2, 1.0, -1.0)
    _, j0 = pac94_lateral_native(probe, fz_kn, al, g, jacobian=True)
    scale = 1.0 / np.sqrt(np.maximum(np.einsum("ij,ij->j", j0, j0)[free], 1e-300))
    r0 = pac94_lateral_native(x0, fz_kn, al, g) - fy
    c0 = 0.5 * float(r0 @ r0)

    def full(z):
        x = x0.copy()
        x[free] = x0[free] + z * scale
        return x

    def cost(z):
        r = pac94_lateral_native(full(z), fz_kn, al, g) - fy
        return 0.5 * float(r @ r) / c0

    cl = [{"type": "ineq", "fun": lambda z: cons(full(z))[0]}] if cons(x0)[0].size else []
    bounds = [
        ((lo - x) / s if np.isfinite(lo) else None, (hi - x) / s if np.isfinite(hi) else None)
        for lo, hi, x, s in zip(lb[free], ub[free], x0[free], scale, strict=True)
    ]
    trace: list[tuple[float, float]] = []

    def record(z):
        trace.append((time.perf_counter() - t0, cost(z) * c0))

    res = minimize(
        cost,
        np.zeros(free.size),
        method="SLSQP",
        bounds=bounds,
        constraints=cl,
        options={"maxiter": 2000, "ftol": 1e-12},
        callback=record,
    )
    dt = time.perf_counter() - t0
    # the callback's own cost evaluations are excluded from the trace times only approximately
    return dt, res.fun * c0, res, trace


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, default=10_000)
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--constraints", default="all")
    args = ap.parse_args()
    print(f"constrained PAC94 fit, {args.n} points, constraints={args.constraints}")
    print(
        f"{'seed':>4} {'gripsense s':>11} {'cost':>12} {'nfev':>5} | {'SLSQP s':>8} {'cost':>12} "
        f"{'nfev':>5} {'cost ratio':>10} {'time ratio':>10} {'SLSQP s to reach':>16}"
    )
    ratios, reach_ratios = [], []
    for seed in range(args.repeat):
        rng = np.random.default_rng(seed)
        d = cornering_samples(lambda fz, a, g: pac94_lateral(TRUTH, fz, a, g), args.n, rng=rng)
        t0 = time.perf_counter()
        fit = fit_pac94(d.alpha_rad, d.gamma_rad, d.fz_N, d.fy_N, constraints=args.constraints)
        t_g = time.perf_counter() - t0
        t_s, cost_s, res, trace = slsqp_baseline(d, args.constraints)
        ratios.append(t_s / t_g)
        reach = next((t for t, c in trace if c <= fit.cost * (1 + 1e-6)), None)
        reach_ratios.append(np.inf if reach is None else reach / t_g)
        reach_txt = "never" if reach is None else f"{reach:.3f}"
        print(
            f"{seed:>4} {t_g:>11.3f} {fit.cost:>12.5e} {fit.nfev:>5} | {t_s:>8.3f} "
            f"{cost_s:>12.5e} {res.nfev:>5} {cost_s / fit.cost:>9.2f}x {t_s / t_g:>9.1f}x "
            f"{reach_txt:>16}"
            f"  [{res.message}]"
        )
    print(f"median raw time ratio (SLSQP run time / gripsense): {np.median(ratios):.1f}x")
    print(
        "median time-to-gripsense's-cost ratio (SLSQP / gripsense): "
        f"{np.median(reach_ratios):.1f}x (inf = SLSQP never reached it)"
    )


if __name__ == "__main__":
    main()
