"""One-step PAC94 fit of seed 002's a0..a17 lateral formula (``docs/physics.md`` §8)."""

from __future__ import annotations

import numpy as np

from gripsense.config.tyre_fit import PAC94_NAMES, TyreFit
from gripsense.errors import InputError
from gripsense.identify.tyre_fit._solve import (
    C_MARGIN,
    DEG,
    Problem,
    clean_points,
    constraint_flags,
    initial_peak_slope,
    ranges,
    run_problem,
)
from gripsense.physics.magic_formula.pac94 import N_COEF, VARIANTS, pac94_lateral_native

__all__ = ["fit_pac94"]


def _pac94_setup(alpha, gamma, fz, fy, flags, variant, bounds, x0):
    fz_kn, al_deg, g_deg = fz / 1000.0, alpha * DEG, gamma * DEG
    lb = np.full(N_COEF, -np.inf)
    ub = np.full(N_COEF, np.inf)
    # a4 = load of the cornering-stiffness maximum: far beyond the data only a3/a4 is seen
    lb[4], ub[4] = 0.05 * fz_kn.max(), 10.0 * fz_kn.max()
    fixed: dict[int, float] = {}
    if "shape" in flags:
        lb[0], ub[0] = 1.0 + C_MARGIN, 2.0 - C_MARGIN
    if "symmetric" in flags:
        fixed.update({8: 0.0, 9: 0.0, 11: 0.0, 12: 0.0, 17: 0.0})
    g_box = np.array([g_deg.min(), g_deg.max()])
    fz_box = np.array([fz_kn.min(), fz_kn.max()])
    g_abs = max(float(np.max(np.abs(g_box))), 1e-9)
    if "shape" in flags:
        # D and BCD keep their sign over the data's camber range (gripsense addition, §8.2 note)
        ub[15] = min(ub[15], 0.9 / g_abs**2)
        ub[5] = min(ub[5], 0.9 / g_abs)
    if "camber" in flags:
        lb[15] = 0.0
        lim = 0.1 if variant == "published" else 0.1 / fz_box.max()
        lb[10], ub[10] = -lim, lim
    for name, (lo, hi) in (bounds or {}).items():
        i = PAC94_NAMES.index(name)
        lb[i], ub[i] = max(lb[i], lo), min(ub[i], hi)
    # start from the data
    if x0 is None:
        fzs, slopes, peaks = initial_peak_slope(alpha, fz, fy)
        sgn = np.sign(np.median(slopes)) or 1.0
        fzk = fzs / 1000.0
        if fzk.size >= 2 and np.ptp(fzk) > 0:
            a1, a2 = np.linalg.lstsq(np.column_stack([fzk**2, fzk]), sgn * peaks, rcond=None)[0]
        else:
            a1, a2 = 0.0, sgn * peaks[0] / fzk[0]
        a4 = 2.0 * fz_kn.max()
        a3 = float(np.median(slopes / DEG / np.sin(2 * np.arctan(fzk / a4))))
        x = np.zeros(N_COEF)
        x[[0, 1, 2, 3, 4]] = [1.3, a1, a2, a3, a4]
        if sgn * (a1 * fz_box + a2).min() <= 0:  # keep the start inside the sign constraint
            x[[1, 2]] = [0.0, sgn * float(np.median(peaks / fzk))]
    else:
        x = np.asarray(x0, float).copy()
    sgn_d = 1.0 if x[2] + x[1] * fz_box.mean() >= 0 else -1.0
    if "shape" in flags:
        if sgn_d > 0:
            lb[3] = max(lb[3], 0.0)
        else:
            ub[3] = min(ub[3], 0.0)
    for i, v in fixed.items():
        x[i] = v
    x = np.clip(x, lb, ub)

    corners = [(f, g, s) for f in fz_box for g in g_box for s in (-1.0, 1.0)]
    cf = np.array([c[0] for c in corners])
    cg = np.array([c[1] for c in corners])
    cs = np.array([c[2] for c in corners])

    def e_at(x):
        return (x[6] * cf + x[7]) * (1 - (x[16] * cg + x[17]) * cs)

    def constraints(x):
        cs_list, a_list = [], []
        if "shape" in flags:
            e = e_at(x)
            de = np.zeros((cf.size, N_COEF))
            h = 1 - (x[16] * cg + x[17]) * cs
            de[:, 6] = cf * h
            de[:, 7] = h
            de[:, 16] = -(x[6] * cf + x[7]) * cg * cs
            de[:, 17] = -(x[6] * cf + x[7]) * cs
            cs_list += [1.0 - 1e-9 - e, e + 1 + x[0] ** 2 / 2 - C_MARGIN]
            lo = de.copy()
            lo[:, 0] += x[0]
            a_list += [-de, lo]
            # D(Fz) = (a1 Fz + a2) Fz keeps the sign of the data's peak over the load range
            dd = np.zeros((2, N_COEF))
            dd[:, 1] = sgn_d * fz_box
            dd[:, 2] = sgn_d
            cs_list.append(sgn_d * (x[1] * fz_box + x[2]) - 1e-6 * abs(x[2]))
            a_list.append(dd)
        if "camber" in flags:
            # |a13 Fz + a14| <= 25 N/deg per kN at both ends of the load range (linear)
            v = x[13] * fz_box + x[14]
            dv = np.zeros((2, N_COEF))
            dv[:, 13] = fz_box
            dv[:, 14] = 1.0
            cs_list += [25.0 - v, 25.0 + v]
            a_list += [-dv, dv]
        if not cs_list:
            return np.zeros(0), np.zeros((0, N_COEF))
        return np.concatenate(cs_list), np.vstack(a_list)

    def model(x):
        return pac94_lateral_native(x, fz_kn, al_deg, g_deg, variant, jacobian=True)

    return x, lb, ub, fixed, constraints, model


def fit_pac94(
    alpha,
    gamma,
    fz,
    fy,
    *,
    constraints: str = "all",
    variant: str = "published",
    bounds: dict[str, tuple[float, float]] | None = None,
    loss: str = "linear",
    f_scale: float | None = None,
    x0=None,
    weights=None,
    max_iter: int = 200,
) -> TyreFit:
    """Fit the seed-002 a0..a17 lateral formula to scattered (α, γ, Fz, Fy) points in one step.

    Parameters
    ----------
    alpha : array_like
        Slip angle [rad].
    gamma : array_like
        Camber angle [rad] (scalar 0 when not measured: camber coefficients are then flagged
        undetermined).
    fz : array_like
        Vertical load [N] (> 0).
    fy : array_like
        Lateral force [N], in the convention wanted for the coefficients (ISO: D, BCD < 0).
    constraints : {"none", "shape", "symmetric", "camber", "all"}
        Seed-002 constraint set (module documentation).
    variant : {"published", "seed"}
        Form of Sh and Sv (:mod:`gripsense.physics.magic_formula.pac94`).
    bounds : dict, optional
        Extra box bounds ``{"a5": (0, 0.05)}`` in native units.
    loss : {"linear", "soft_l1", "huber", "cauchy"}
        Robust loss against outliers.
    f_scale : float, optional
        Residual scale of the robust loss [N]; default 5 % of the largest |Fy|.
    x0 : array_like, optional
        Start; default derived from the data (peak |Fy| and slope at the origin per load bin).
    weights : array_like, optional
        Per-point weights (1/σ² of the force) [1/N^2].
    max_iter : int
        Iteration limit of the solver.

    Returns
    -------
    TyreFit
    """
    if variant not in VARIANTS:
        raise InputError(f"variant={variant!r}; use one of {VARIANTS}")
    flags = constraint_flags(constraints)
    alpha, gamma, fz, fy, w, n_bad = clean_points(alpha, gamma, fz, fy, weights)
    if fz.size < N_COEF + 2:
        raise InputError(f"fit_pac94: {fz.size} usable points; need at least {N_COEF + 2}")
    x, lb, ub, fixed, cons, model = _pac94_setup(alpha, gamma, fz, fy, flags, variant, bounds, x0)
    prob = Problem(
        model,
        cons,
        lb,
        ub,
        fy,
        w,
        loss,
        f_scale,
        PAC94_NAMES,
        "pac94",
        constraints,
        variant,
        ranges(alpha, gamma, fz),
        {},
        n_bad,
    )
    nfev0 = 0
    if x0 is None:
        # continuation: the core curve (C, D(Fz), BCD(Fz), E) first, then every coefficient
        core = {i: x[i] for i in range(N_COEF) if i not in (0, 1, 2, 3, 4, 6, 7)}
        stage = run_problem(prob, x, {**core, **fixed}, 50)
        x = np.array([stage.coefficients[n] for n in PAC94_NAMES])
        nfev0 = stage.nfev
    fit = run_problem(prob, x, fixed, max_iter)
    fit.nfev += nfev0
    return fit
