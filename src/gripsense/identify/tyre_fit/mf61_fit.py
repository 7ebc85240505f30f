"""One-step fit of the MF 6.1 pure-lateral coefficients (``docs/physics.md`` §8, §12)."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from gripsense.config.tyre_fit import MF61_LATERAL, TyreFit, mf61_parameters
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
from gripsense.physics.magic_formula.mf6 import MFTyre

__all__ = ["fit_mf61_lateral"]


def _mf61_fy(coefs: dict, extra: dict, fz, alpha, gamma):
    tyre = MFTyre(mf61_parameters(coefs, extra), name="mf61-fit")
    return tyre.forces(fz, 0.0, alpha, gamma, combined=False, limits=False).fy


def fit_mf61_lateral(
    alpha,
    gamma,
    fz,
    fy,
    *,
    fnomin: float | None = None,
    constraints: str = "all",
    loss: str = "linear",
    f_scale: float | None = None,
    x0: dict | None = None,
    weights=None,
    max_iter: int = 200,
) -> TyreFit:
    """Fit the MF 6.1 pure-lateral coefficients (PCY1, PDY1–3, PEY1–5, PKY1–7, PHY1–2, PVY1–4).

    Parameters
    ----------
    alpha, gamma : array_like
        Slip and camber angle [rad], ISO-W.
    fz : array_like
        Vertical load [N].
    fy : array_like
        Lateral force [N], ISO-W (negative for positive α).
    fnomin : float, optional
        Nominal load FNOMIN [N]; default the median load.
    constraints, loss, f_scale, weights, max_iter
        As :func:`fit_pac94`.
    x0 : dict, optional
        Start values by name (e.g. from an existing ``.tir``); default from the data.

    Returns
    -------
    TyreFit
        ``to_tir`` writes a ``.tir`` gripsense and MFeval can read.
    """
    flags = constraint_flags(constraints)
    alpha, gamma, fz, fy, w, n_bad = clean_points(alpha, gamma, fz, fy, weights)
    if fz.size < len(MF61_LATERAL) + 2:
        raise InputError(
            f"fit_mf61_lateral: {fz.size} usable points; need at least {len(MF61_LATERAL) + 2}"
        )
    fz0 = float(np.median(fz)) if fnomin is None else float(fnomin)
    extra = {"FNOMIN": fz0, "LFZO": 1.0, "sign_convention": "ISO-W"}
    names = list(MF61_LATERAL)
    ix = {n: i for i, n in enumerate(names)}
    lb, ub, fixed = _bounds(flags, ix, fz, fz0)
    x = _start(x0, names, ix, alpha, fz, fy, fz0)
    for i, v in fixed.items():
        x[i] = v
    x = np.clip(x, lb, ub)
    cons = _constraints(flags, ix, fz, gamma, fz0)
    model = _model(names, [i for i in range(len(names)) if i not in fixed], extra, fz, alpha, gamma)
    prob = Problem(
        model,
        cons,
        lb,
        ub,
        fy,
        w,
        loss,
        f_scale,
        tuple(names),
        "mf61",
        constraints,
        "published",
        ranges(alpha, gamma, fz),
        extra,
        n_bad,
    )
    return run_problem(prob, x, fixed, max_iter)


def _bounds(
    flags: set[str], ix: dict[str, int], fz: np.ndarray, fz0: float
) -> tuple[np.ndarray, np.ndarray, dict[int, float]]:
    """Lower and upper bounds of the coefficients and those fixed by the constraints."""
    p = len(ix)
    lb = np.full(p, -np.inf)
    ub = np.full(p, np.inf)
    fixed: dict[int, float] = {}
    if "shape" in flags:
        lb[ix["PCY1"]], ub[ix["PCY1"]] = 1 + C_MARGIN, 2 - C_MARGIN
    if "symmetric" in flags:
        fixed.update({ix[k]: 0.0 for k in ("PHY1", "PHY2", "PVY1", "PVY2", "PEY3")})
    if "camber" in flags:
        lb[ix["PDY3"]] = 0.0
    lb[ix["PKY2"]], ub[ix["PKY2"]] = 0.05 * fz.max() / fz0, 10.0 * fz.max() / fz0
    return lb, ub, fixed


def _start(
    x0: dict | None,
    names: list[str],
    ix: dict[str, int],
    alpha: np.ndarray,
    fz: np.ndarray,
    fy: np.ndarray,
    fz0: float,
) -> np.ndarray:
    """The start: *x0* by name, else peak and slope read from the data."""
    if x0 is not None:
        return np.array([float(x0.get(n, 0.0)) for n in names])
    fzs, slopes, peaks = initial_peak_slope(alpha, fz, fy)
    mu = float(np.median(peaks / fzs))
    kya = float(np.median(slopes))
    x = np.zeros(len(names))
    x[ix["PCY1"]] = 1.3
    x[ix["PDY1"]] = mu
    x[ix["PKY4"]] = 2.0
    x[ix["PKY2"]] = 2.0
    x[ix["PKY1"]] = kya / (fz0 * np.sin(2 * np.arctan(np.median(fzs) / (2.0 * fz0))))
    return x


def _constraints(
    flags: set[str], ix: dict[str, int], fz: np.ndarray, gamma: np.ndarray, fz0: float
) -> Callable[[np.ndarray], tuple[np.ndarray, np.ndarray]]:
    """The constraints x → (c, A), c ≥ 0: the curvature E below 1 and above −(1 + C²/2) (the
    shape) and the camber's vertical shift bounded, on the data's load and camber box; A by
    differences.
    """
    p = len(ix)
    fz_box = np.array([fz.min(), fz.max()])
    g_grid = np.linspace(gamma.min(), gamma.max(), 5)
    cf, cg, cs = (a.ravel() for a in np.meshgrid(fz_box, g_grid, [-1.0, 1.0], indexing="ij"))
    vmax = 25.0 * DEG / 1000.0  # |Sv/γ| < 25 N/deg per kN, in N/rad per N

    def con_values(x):
        out = []
        if "shape" in flags:
            dfz = (cf - fz0) / fz0
            e = (x[ix["PEY1"]] + x[ix["PEY2"]] * dfz) * (
                1 + x[ix["PEY5"]] * cg**2 - (x[ix["PEY3"]] + x[ix["PEY4"]] * cg) * cs
            )
            c = x[ix["PCY1"]]
            out += [1.0 - 1e-9 - e, e + 1 + c * c / 2 - C_MARGIN]
        if "camber" in flags:
            dfz = (fz_box - fz0) / fz0
            v = x[ix["PVY3"]] + x[ix["PVY4"]] * dfz
            out += [vmax - v, vmax + v]
        return np.concatenate(out) if out else np.zeros(0)

    def cons(x):
        c0 = con_values(x)
        a = np.zeros((c0.size, p))
        for i in range(p):
            h = 1e-7 * max(1.0, abs(x[i]))
            xp = x.copy()
            xp[i] += h
            a[:, i] = (con_values(xp) - c0) / h
        return c0, a

    return cons


def _model(
    names: list[str],
    free: list[int],
    extra: dict,
    fz: np.ndarray,
    alpha: np.ndarray,
    gamma: np.ndarray,
) -> Callable[[np.ndarray], tuple[np.ndarray, np.ndarray]]:
    """The model x → (F_y, its Jacobian over the *free* coefficients, central differences)."""
    p = len(names)

    def model(x):
        coefs = dict(zip(names, x, strict=True))
        f0 = _mf61_fy(coefs, extra, fz, alpha, gamma)
        jac = np.zeros((fz.size, p))
        for i in free:
            h = 1e-6 * max(1.0, abs(x[i]))
            cp = dict(coefs)
            cm = dict(coefs)
            cp[names[i]] = x[i] + h
            cm[names[i]] = x[i] - h
            fp = _mf61_fy(cp, extra, fz, alpha, gamma)
            fm = _mf61_fy(cm, extra, fz, alpha, gamma)
            jac[:, i] = (fp - fm) / (2 * h)
        return f0, jac

    return model
