"""What the tyre fits share: data cleaning, start values, the solver call and the
covariance / "determined" analysis (``docs/physics.md`` §8.2).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from gripsense._arrays import as_float_array
from gripsense.config.tyre_fit import TyreFit
from gripsense.errors import InputError
from gripsense.identify.constrained_lsq import solve_constrained_lsq

CONSTRAINT_SETS = ("none", "shape", "symmetric", "camber", "all")
DEG = 180.0 / np.pi
C_MARGIN = 1e-3


def constraint_flags(constraints: str) -> set[str]:
    if constraints not in CONSTRAINT_SETS:
        raise InputError(f"constraints={constraints!r}; use one of {', '.join(CONSTRAINT_SETS)}")
    return (
        {"shape", "symmetric", "camber"}
        if constraints == "all"
        else (set() if constraints == "none" else {constraints})
    )


# ---------------------------------------------------------------------- data handling
def clean_points(alpha, gamma, fz, fy, weights=None):
    arrs = [
        as_float_array(v, n).ravel()
        for v, n in ((alpha, "alpha"), (gamma, "gamma"), (fz, "fz"), (fy, "fy"))
    ]
    n = max(a.size for a in arrs)
    arrs = [np.broadcast_to(a, (n,)) if a.size == 1 else a for a in arrs]
    if len({a.size for a in arrs}) != 1:
        raise InputError(
            f"tyre fit: alpha, gamma, fz, fy have different lengths {[a.size for a in arrs]}"
        )
    w = np.ones(n) if weights is None else as_float_array(weights, "weights").ravel()
    ok = np.all([np.isfinite(a) for a in arrs], axis=0) & np.isfinite(w) & (w > 0)
    ok &= arrs[2] > 0
    alpha, gamma, fz, fy = (a[ok] for a in arrs)
    return alpha, gamma, fz, fy, w[ok], int((~ok).sum())


def ranges(alpha, gamma, fz):
    return {
        "fz_N": (float(fz.min()), float(fz.max())),
        "alpha_rad": (float(alpha.min()), float(alpha.max())),
        "gamma_rad": (float(gamma.min()), float(gamma.max())),
    }


def initial_peak_slope(alpha, fz, fy):
    """Data-derived start: per load bin, the slope at the origin [N/rad] and the peak |Fy| [N]."""
    nb = int(np.clip(fz.size // 200, 1, 4))
    edges = np.quantile(fz, np.linspace(0, 1, nb + 1))
    fzs, slopes, peaks = [], [], []
    for i in range(nb):
        m = (fz >= edges[i]) & (fz <= edges[i + 1])
        if m.sum() < 10:
            continue
        a, f = alpha[m], fy[m]
        small = np.abs(a) <= np.quantile(np.abs(a), 0.3)
        if small.sum() >= 3 and np.ptp(a[small]) > 0:
            slope = np.polyfit(a[small], f[small], 1)[0]
        else:
            slope = np.polyfit(a, f, 1)[0]
        fzs.append(np.median(fz[m]))
        slopes.append(slope)
        peaks.append(np.quantile(np.abs(f), 0.99))
    if not fzs:
        raise InputError("tyre fit: too few usable points to start from (need ≥ 10)")
    return np.array(fzs), np.array(slopes), np.array(peaks)


def _covariance(res, free_idx, names, lb, ub, x, dof, fy):
    """Covariance s²(JᵀJ)⁻¹ of the free coefficients not held at a bound, and which coefficients
    the data determine: a coefficient is *undetermined* when it lies at a bound, on a null
    direction of JᵀJ, or when its 1σ uncertainty moves the force by more than 5 % of the RMS
    force over the data (σᵢ·rms(∂F/∂xᵢ) > 0.05·rms(F)).
    """
    j = res.jacobian
    xs = x[free_idx]
    tol_b = 1e-9 * (1 + np.abs(xs))
    at_bound = (np.abs(xs - lb[free_idx]) <= tol_b) | (np.abs(xs - ub[free_idx]) <= tol_b)
    s2 = float(res.residuals @ res.residuals) / max(dof, 1)
    jtj = j.T @ j
    m = len(free_idx)
    cov = np.full((m, m), np.nan)
    use = ~at_bound
    det = np.zeros(m, bool)
    if use.any():
        sub = jtj[np.ix_(use, use)]
        u, sv, vt = np.linalg.svd(sub)
        tol = sv.max() * 1e-13 if sv.size else 0
        inv_s = np.where(sv > tol, 1 / np.where(sv > tol, sv, 1), 0)
        cov[np.ix_(use, use)] = (vt.T * inv_s) @ u.T * s2
        weak = np.zeros(use.sum(), bool)
        for k in np.where(sv <= tol)[0]:
            weak |= np.abs(vt[k]) > 0.1
        det[use] = ~weak
    se = np.sqrt(np.clip(np.diag(cov), 0, None))
    effect = se * np.sqrt(np.mean(j**2, axis=0))
    det &= np.isfinite(effect) & (effect <= 0.05 * np.sqrt(np.mean(fy**2)))
    stderr = dict.fromkeys(names, float("nan"))
    determined = dict.fromkeys(names, False)
    for k, i in enumerate(free_idx):
        stderr[names[i]] = float(se[k]) if use[k] else float("nan")
        determined[names[i]] = bool(det[k])
    return cov, stderr, determined


@dataclass
class Problem:
    """Everything a fit needs besides the start and the fixed coefficients."""

    model: Callable[[np.ndarray], tuple[np.ndarray, np.ndarray]]  # x -> (prediction, Jacobian)
    cons: Callable[[np.ndarray], tuple[np.ndarray, np.ndarray]]  # x -> (c, A), c >= 0
    lb: np.ndarray
    ub: np.ndarray
    fy: np.ndarray
    w: np.ndarray
    loss: str
    f_scale: float | None
    names: tuple[str, ...]
    mname: str
    constraints: str
    variant: str
    ranges: dict
    extra: dict
    n_bad: int


def run_problem(prob: Problem, x: np.ndarray, fixed: dict, max_iter: int) -> TyreFit:
    model, cons, lb, ub, fy, w = prob.model, prob.cons, prob.lb, prob.ub, prob.fy, prob.w
    loss, f_scale, names, n_bad = prob.loss, prob.f_scale, prob.names, prob.n_bad
    p = x.size
    # coefficients the data cannot move at all (e.g. camber terms without camber variation)
    probe = x + 0.01 * (1.0 + np.abs(x)) * np.where(np.arange(p) % 2, 1.0, -1.0)
    probe = np.where(np.isfinite(lb) & (probe < lb) | np.isfinite(ub) & (probe > ub), x, probe)
    _, jac0 = model(probe)
    fixed = dict(fixed)
    for i in np.where(~np.any(jac0 != 0, axis=0))[0]:
        fixed.setdefault(int(i), float(x[i]))
    free_idx = np.array([i for i in range(p) if i not in fixed])
    sw = np.sqrt(w / np.mean(w))
    if f_scale is None:
        f_scale = 0.05 * float(np.max(np.abs(fy)))

    def fun(z):
        full = x.copy()
        full[free_idx] = z
        pred, jac = model(full)
        return (pred - fy) * sw, jac[:, free_idx] * sw[:, None]

    def cfun(z):
        full = x.copy()
        full[free_idx] = z
        c, a = cons(full)
        return c, a[:, free_idx]

    res = solve_constrained_lsq(
        fun,
        x[free_idx],
        lb=lb[free_idx],
        ub=ub[free_idx],
        constraints=cfun,
        loss=loss,
        f_scale=f_scale,
        max_iter=max_iter,
    )
    xf = x.copy()
    xf[free_idx] = res.x
    n = fy.size
    dof = n - free_idx.size
    cov, stderr, determined = _covariance(res, free_idx, list(names), lb, ub, xf, dof, fy * sw)
    c_all, _ = cons(xf)
    active = {
        "bounds": bool(np.any(np.isclose(res.x, lb[free_idx]) | np.isclose(res.x, ub[free_idx])))
    }
    if c_all.size:
        active["nonlinear"] = bool(np.any(c_all < 1e-6 * (1 + np.abs(c_all).max())))
    for i in fixed:
        active[f"{names[i]}=fixed"] = True
    r_unw = res.residuals / sw
    msg = res.message + (
        f"; {n_bad} rows without finite values or with Fz <= 0 left out" if n_bad else ""
    )
    return TyreFit(
        model=prob.mname,
        coefficients={names[i]: float(xf[i]) for i in range(p)},
        stderr=stderr,
        determined=determined,
        covariance=cov,
        free=[names[i] for i in free_idx],
        constraints=prob.constraints,
        active=active,
        residual_rms_N=float(np.sqrt(np.mean(r_unw**2))),
        n=n,
        dof=dof,
        cost=res.cost,
        success=res.success,
        message=msg,
        nfev=res.nfev,
        ranges=prob.ranges,
        variant=prob.variant,
        extra=prob.extra,
    )
