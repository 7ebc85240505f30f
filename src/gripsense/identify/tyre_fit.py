"""One-step constrained identification of Magic Formula lateral coefficients (seed 002).

Seed ``002_0ffa298cd6a17b3b.txt`` fits all coefficients at once to scattered on-road points
(α, γ, Fz, Fy) — every point has its own conditions, so the usual staged fit (one load and camber
at a time) is impossible — and adds constraints that keep the curve physical (PHYSICS.md §8.2):

==========  ==========================================================================
set         meaning (PAC94 coefficient names; the MF 6.1 analogue in brackets)
==========  ==========================================================================
shape       eq. 10–11: 1 < C < 2 and −(1 + C²/2) < E < 1 over the data's (Fz, γ) box
            [PCY1; Ey]
symmetric   eq. 12–13: E symmetric and no shifts at γ = 0: a8 = a9 = a11 = a12 = a17 = 0
            [PHY1 = PHY2 = PVY1 = PVY2 = PEY3 = 0]
camber      eq. 14–16: |Sh/γ| < 0.1 deg/deg and |Sv/γ| < 25 N/deg per kN over the data's
            loads, and a15 ≥ 0 (D largest at γ = 0) [PVY3/PVY4, PKY6/PKY7 via Sh; PDY3 ≥ 0]
all         shape + symmetric + camber
none        only the box bounds
==========  ==========================================================================

E is bilinear in (Fz, γ) for a given sign of the shifted slip, so its extremes over the data's
(Fz, γ) box are at the box corners: the shape constraint is enforced there exactly (PAC94);
for MF 6.1 (γ² term) it is enforced on a 5-point camber grid.

The solver is :func:`gripsense.identify.constrained_lsq.solve_constrained_lsq` with the models'
exact Jacobian (PAC94: analytic, sympy-checked; MF 6.1: central differences).
"""

from __future__ import annotations

import json
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pandas as pd

from gripsense._arrays import as_float_array
from gripsense.errors import InputError
from gripsense.identify.constrained_lsq import solve_constrained_lsq
from gripsense.physics.magic_formula.mf6 import MFTyre
from gripsense.physics.magic_formula.pac94 import N_COEF, VARIANTS, pac94_lateral_native

__all__ = [
    "CONSTRAINT_SETS",
    "MF61_LATERAL",
    "TyreFit",
    "fit_from_wheel_table",
    "fit_mf61_lateral",
    "fit_pac94",
]

CONSTRAINT_SETS = ("none", "shape", "symmetric", "camber", "all")
MF61_LATERAL = (
    "PCY1",
    "PDY1",
    "PDY2",
    "PDY3",
    "PEY1",
    "PEY2",
    "PEY3",
    "PEY4",
    "PEY5",
    "PKY1",
    "PKY2",
    "PKY3",
    "PKY4",
    "PKY5",
    "PKY6",
    "PKY7",
    "PHY1",
    "PHY2",
    "PVY1",
    "PVY2",
    "PVY3",
    "PVY4",
)
PAC94_NAMES = tuple(f"a{i}" for i in range(N_COEF))
_DEG = 180.0 / np.pi
_C_MARGIN = 1e-3


def _constraint_flags(constraints: str) -> set[str]:
    if constraints not in CONSTRAINT_SETS:
        raise InputError(f"constraints={constraints!r}; use one of {', '.join(CONSTRAINT_SETS)}")
    return (
        {"shape", "symmetric", "camber"}
        if constraints == "all"
        else (set() if constraints == "none" else {constraints})
    )


@dataclass
class TyreFit:
    """Result of a tyre fit.

    Attributes
    ----------
    model : str
        ``"pac94"`` or ``"mf61"``.
    coefficients : dict
        Name → value (PAC94: native units kN/deg; MF 6.1: SI, as in a ``.tir``).
    stderr : dict
        Name → 1σ standard error from s²(JᵀJ)⁻¹ over the free coefficients (NaN for coefficients
        fixed or held at a bound by a constraint).
    determined : dict
        Name → False where the data cannot determine the coefficient (fixed, at a bound, or
        relative standard error > 1 / rank-deficient direction).
    covariance : ndarray
        Covariance of the free coefficients (order ``free``).
    free : list of str
    constraints : str
    active : dict
        Constraint name → True if active (within 1e-6 of its limit) at the solution.
    residual_rms_N, n, dof, cost : float, int, int, float
    success : bool
    message : str
    nfev : int
    ranges : dict
        Data ranges the fit is valid for: ``fz_N``, ``alpha_rad``, ``gamma_rad`` (min, max).
    variant : str
        PAC94 Sh/Sv form (``published`` or ``seed``).
    extra : dict
        Model constants (MF 6.1: FNOMIN, LFZO; the sign convention).
    """

    model: str
    coefficients: dict[str, float]
    stderr: dict[str, float]
    determined: dict[str, bool]
    covariance: np.ndarray
    free: list[str]
    constraints: str
    active: dict[str, bool]
    residual_rms_N: float
    n: int
    dof: int
    cost: float
    success: bool
    message: str
    nfev: int
    ranges: dict[str, tuple[float, float]]
    variant: str = "published"
    extra: dict = field(default_factory=dict)

    # ------------------------------------------------------------------ use
    def predict(self, fz, alpha, gamma=0.0) -> np.ndarray:
        """Lateral force [N] at loads [N], slip angles [rad] and camber [rad]."""
        fz = as_float_array(fz, "fz")
        alpha = as_float_array(alpha, "alpha")
        gamma = as_float_array(gamma, "gamma")
        if self.model == "pac94":
            x = np.array([self.coefficients[n] for n in PAC94_NAMES])
            return pac94_lateral_native(x, fz / 1000.0, alpha * _DEG, gamma * _DEG, self.variant)
        return (
            _mf61_tyre(self.coefficients, self.extra)
            .forces(fz, 0.0, alpha, gamma, combined=False, limits=False)
            .fy
        )

    def physical_checks(self) -> dict[str, bool]:
        """Seed-002 physical conditions over the fit's data box (independent of the constraint
        set used): C in (1, 2); E in (−(1 + C²/2), 1]; peak largest at γ = 0."""
        fz_lo, fz_hi = self.ranges["fz_N"]
        g_lo, g_hi = self.ranges["gamma_rad"]
        fz = np.array([fz_lo, fz_lo, fz_hi, fz_hi])
        g = np.array([g_lo, g_hi, g_lo, g_hi])
        if self.model == "pac94":
            a = self.coefficients
            c = a["a0"]
            e = []
            for s in (-1.0, 1.0):
                e.append(
                    (a["a6"] * fz / 1000 + a["a7"]) * (1 - (a["a16"] * g * _DEG + a["a17"]) * s)
                )
            e = np.concatenate(e)
            camber_peak = a["a15"] >= 0
        else:
            p = self.coefficients
            c = p["PCY1"]
            dfz = (fz - self.extra["FNOMIN"]) / self.extra["FNOMIN"]
            e = np.concatenate(
                [
                    (p["PEY1"] + p["PEY2"] * dfz)
                    * (1 + p["PEY5"] * g**2 - (p["PEY3"] + p["PEY4"] * g) * s)
                    for s in (-1.0, 1.0)
                ]
            )
            camber_peak = p["PDY3"] >= 0
        return {
            "C_in_(1,2)": bool(1 < c < 2),
            "E_in_range": bool(np.all(e <= 1) and np.all(e > -(1 + c * c / 2))),
            "peak_largest_at_zero_camber": bool(camber_peak),
        }

    # ------------------------------------------------------------------ output
    def to_dict(self) -> dict:
        """JSON-ready dictionary."""
        return {
            "model": self.model,
            "variant": self.variant,
            "constraints": self.constraints,
            "coefficients": self.coefficients,
            "stderr": self.stderr,
            "determined": self.determined,
            "free": self.free,
            "active": self.active,
            "covariance": self.covariance.tolist(),
            "residual_rms_N": self.residual_rms_N,
            "n": self.n,
            "dof": self.dof,
            "cost": self.cost,
            "success": self.success,
            "message": self.message,
            "nfev": self.nfev,
            "ranges": {k: list(v) for k, v in self.ranges.items()},
            "physical_checks": self.physical_checks(),
            "extra": self.extra,
            "units": (
                "PAC94 native: Fz kN, angles deg, Fy N"
                if self.model == "pac94"
                else "MF 6.1: SI, ISO-W"
            ),
        }

    def to_json(self, path: str | Path) -> Path:
        """Write :meth:`to_dict` as JSON (NaN written as null)."""
        path = Path(path)
        d = self.to_dict()
        path.write_text(json.dumps(_nan_to_none(d), indent=2))
        return path

    def to_tir(self, path: str | Path, template: str | Path | None = None) -> Path:
        """Write an MF 6.1 ``.tir`` (MF 6.1 fits only). With ``template`` (an existing ``.tir``),
        its lateral coefficients are replaced and everything else kept; without, a minimal
        file holding the fitted pure-lateral coefficients (others 0, scaling 1) is written."""
        from gripsense.io.tir import TirFile, read_tir, write_tir

        if self.model != "mf61":
            raise InputError(
                "to_tir: only MF 6.1 fits can be written as .tir; write PAC94 "
                "coefficients with to_json"
            )
        if template is not None:
            tir = read_tir(template)
            for k, v in self.coefficients.items():
                tir.set(k, float(v), section="LATERAL_COEFFICIENTS")
            tir.set("FNOMIN", float(self.extra["FNOMIN"]), section="VERTICAL")
        else:
            fz_lo, fz_hi = self.ranges["fz_N"]
            a_lo, a_hi = self.ranges["alpha_rad"]
            g_lo, g_hi = self.ranges["gamma_rad"]
            tir = TirFile.from_sections(
                {
                    "MDI_HEADER": {"FILE_TYPE": "tir", "FILE_VERSION": 3.0, "FILE_FORMAT": "ASCII"},
                    "UNITS": {
                        "LENGTH": "meter",
                        "FORCE": "newton",
                        "ANGLE": "radians",
                        "MASS": "kg",
                        "TIME": "second",
                    },
                    "MODEL": {"FITTYP": 61, "TYRESIDE": "LEFT", "LONGVL": 16.7, "VXLOW": 1.0},
                    "DIMENSION": {"UNLOADED_RADIUS": float(self.extra.get("UNLOADED_RADIUS", 0.3))},
                    "OPERATING_CONDITIONS": {"INFLPRES": 220000.0, "NOMPRES": 220000.0},
                    "VERTICAL": {"FNOMIN": float(self.extra["FNOMIN"])},
                    "VERTICAL_FORCE_RANGE": {"FZMIN": float(fz_lo), "FZMAX": float(fz_hi)},
                    "SLIP_ANGLE_RANGE": {"ALPMIN": float(a_lo), "ALPMAX": float(a_hi)},
                    "INCLINATION_ANGLE_RANGE": {"CAMMIN": float(g_lo), "CAMMAX": float(g_hi)},
                    "SCALING_COEFFICIENTS": {
                        "LFZO": 1.0,
                        "LCY": 1.0,
                        "LMUY": 1.0,
                        "LEY": 1.0,
                        "LKY": 1.0,
                        "LKYC": 1.0,
                        "LHY": 1.0,
                        "LVY": 1.0,
                    },
                    "LONGITUDINAL_COEFFICIENTS": {"PCX1": 1.65, "PDX1": 1.0, "PKX1": 20.0},
                    "LATERAL_COEFFICIENTS": {k: float(v) for k, v in self.coefficients.items()},
                },
                header=[
                    "Magic Formula 6.1 pure lateral coefficients identified by gripsense",
                    f"constraints: {self.constraints}; n = {self.n}; "
                    f"rms residual {self.residual_rms_N:.1f} N",
                    "longitudinal coefficients are placeholders (not identified)",
                ],
            )
        return write_tir(tir, path)


def _nan_to_none(obj):
    if isinstance(obj, dict):
        return {k: _nan_to_none(v) for k, v in obj.items()}
    if isinstance(obj, list | tuple):
        return [_nan_to_none(v) for v in obj]
    if isinstance(obj, float) and not np.isfinite(obj):
        return None
    if isinstance(obj, np.floating | np.integer | np.bool_):
        return _nan_to_none(obj.item())
    return obj


# ---------------------------------------------------------------------- data handling
def _clean(alpha, gamma, fz, fy, weights=None):
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


def _ranges(alpha, gamma, fz):
    return {
        "fz_N": (float(fz.min()), float(fz.max())),
        "alpha_rad": (float(alpha.min()), float(alpha.max())),
        "gamma_rad": (float(gamma.min()), float(gamma.max())),
    }


def _initial_peak_slope(alpha, fz, fy):
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
    force over the data (σᵢ·rms(∂F/∂xᵢ) > 0.05·rms(F))."""
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


# ---------------------------------------------------------------------- PAC94
def _pac94_setup(alpha, gamma, fz, fy, flags, variant, bounds, x0):
    fz_kn, al_deg, g_deg = fz / 1000.0, alpha * _DEG, gamma * _DEG
    lb = np.full(N_COEF, -np.inf)
    ub = np.full(N_COEF, np.inf)
    # a4 = load of the cornering-stiffness maximum: far beyond the data only a3/a4 is seen
    lb[4], ub[4] = 0.05 * fz_kn.max(), 10.0 * fz_kn.max()
    fixed: dict[int, float] = {}
    if "shape" in flags:
        lb[0], ub[0] = 1.0 + _C_MARGIN, 2.0 - _C_MARGIN
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
        fzs, slopes, peaks = _initial_peak_slope(alpha, fz, fy)
        sgn = np.sign(np.median(slopes)) or 1.0
        fzk = fzs / 1000.0
        if fzk.size >= 2 and np.ptp(fzk) > 0:
            a1, a2 = np.linalg.lstsq(np.column_stack([fzk**2, fzk]), sgn * peaks, rcond=None)[0]
        else:
            a1, a2 = 0.0, sgn * peaks[0] / fzk[0]
        a4 = 2.0 * fz_kn.max()
        a3 = float(np.median(slopes / _DEG / np.sin(2 * np.arctan(fzk / a4))))
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
            cs_list += [1.0 - 1e-9 - e, e + 1 + x[0] ** 2 / 2 - _C_MARGIN]
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
        Per-point weights (1/σ² of the force) [1/N²].
    max_iter : int
        Iteration limit of the solver.

    Returns
    -------
    TyreFit
    """
    if variant not in VARIANTS:
        raise InputError(f"variant={variant!r}; use one of {VARIANTS}")
    flags = _constraint_flags(constraints)
    alpha, gamma, fz, fy, w, n_bad = _clean(alpha, gamma, fz, fy, weights)
    if fz.size < N_COEF + 2:
        raise InputError(f"fit_pac94: {fz.size} usable points; need at least {N_COEF + 2}")
    x, lb, ub, fixed, cons, model = _pac94_setup(alpha, gamma, fz, fy, flags, variant, bounds, x0)
    prob = _Problem(
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
        _ranges(alpha, gamma, fz),
        {},
        n_bad,
    )
    nfev0 = 0
    if x0 is None:
        # continuation: the core curve (C, D(Fz), BCD(Fz), E) first, then every coefficient
        core = {i: x[i] for i in range(N_COEF) if i not in (0, 1, 2, 3, 4, 6, 7)}
        stage = _run(prob, x, {**core, **fixed}, 50)
        x = np.array([stage.coefficients[n] for n in PAC94_NAMES])
        nfev0 = stage.nfev
    fit = _run(prob, x, fixed, max_iter)
    fit.nfev += nfev0
    return fit


@dataclass
class _Problem:
    """Everything a fit needs besides the start and the fixed coefficients."""

    model: object  # x -> (prediction, Jacobian)
    cons: object  # x -> (c, A), c >= 0
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


def _run(prob: _Problem, x: np.ndarray, fixed: dict, max_iter: int) -> TyreFit:
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


# ---------------------------------------------------------------------- MF 6.1
def _mf61_tyre(coefs: dict, extra: dict) -> MFTyre:
    params = {
        "FITTYP": 61,
        "FNOMIN": extra["FNOMIN"],
        "UNLOADED_RADIUS": 0.3,
        "LFZO": extra.get("LFZO", 1.0),
        "PCX1": 1.0,
        "PDX1": 1.0,
        "PKX1": 1.0,
    }
    params.update(coefs)
    return MFTyre(params, name="mf61-fit")


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
    flags = _constraint_flags(constraints)
    alpha, gamma, fz, fy, w, n_bad = _clean(alpha, gamma, fz, fy, weights)
    if fz.size < len(MF61_LATERAL) + 2:
        raise InputError(
            f"fit_mf61_lateral: {fz.size} usable points; need at least {len(MF61_LATERAL) + 2}"
        )
    fz0 = float(np.median(fz)) if fnomin is None else float(fnomin)
    extra = {"FNOMIN": fz0, "LFZO": 1.0, "sign_convention": "ISO-W"}
    names = list(MF61_LATERAL)
    p = len(names)
    ix = {n: i for i, n in enumerate(names)}
    lb = np.full(p, -np.inf)
    ub = np.full(p, np.inf)
    fixed: dict[int, float] = {}
    if "shape" in flags:
        lb[ix["PCY1"]], ub[ix["PCY1"]] = 1 + _C_MARGIN, 2 - _C_MARGIN
    if "symmetric" in flags:
        fixed.update({ix[k]: 0.0 for k in ("PHY1", "PHY2", "PVY1", "PVY2", "PEY3")})
    if "camber" in flags:
        lb[ix["PDY3"]] = 0.0
    lb[ix["PKY2"]], ub[ix["PKY2"]] = 0.05 * fz.max() / fz0, 10.0 * fz.max() / fz0
    if x0 is None:
        fzs, slopes, peaks = _initial_peak_slope(alpha, fz, fy)
        mu = float(np.median(peaks / fzs))
        kya = float(np.median(slopes))
        x = np.zeros(p)
        x[ix["PCY1"]] = 1.3
        x[ix["PDY1"]] = mu
        x[ix["PKY4"]] = 2.0
        x[ix["PKY2"]] = 2.0
        x[ix["PKY1"]] = kya / (fz0 * np.sin(2 * np.arctan(np.median(fzs) / (2.0 * fz0))))
    else:
        x = np.array([float(x0.get(n, 0.0)) for n in names])
    for i, v in fixed.items():
        x[i] = v
    x = np.clip(x, lb, ub)
    fz_box = np.array([fz.min(), fz.max()])
    g_grid = np.linspace(gamma.min(), gamma.max(), 5)
    cf, cg, cs = (a.ravel() for a in np.meshgrid(fz_box, g_grid, [-1.0, 1.0], indexing="ij"))
    vmax = 25.0 * _DEG / 1000.0  # |Sv/γ| < 25 N/deg per kN, in N/rad per N

    def con_values(x):
        out = []
        if "shape" in flags:
            dfz = (cf - fz0) / fz0
            e = (x[ix["PEY1"]] + x[ix["PEY2"]] * dfz) * (
                1 + x[ix["PEY5"]] * cg**2 - (x[ix["PEY3"]] + x[ix["PEY4"]] * cg) * cs
            )
            c = x[ix["PCY1"]]
            out += [1.0 - 1e-9 - e, e + 1 + c * c / 2 - _C_MARGIN]
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

    free = [i for i in range(p) if i not in fixed]

    def model(x):
        coefs = dict(zip(names, x, strict=True))
        f0 = _mf61_tyre(coefs, extra).forces(fz, 0.0, alpha, gamma, combined=False, limits=False).fy
        jac = np.zeros((fz.size, p))
        for i in free:
            h = 1e-6 * max(1.0, abs(x[i]))
            cp = dict(coefs)
            cm = dict(coefs)
            cp[names[i]] = x[i] + h
            cm[names[i]] = x[i] - h
            fp = (
                _mf61_tyre(cp, extra).forces(fz, 0.0, alpha, gamma, combined=False, limits=False).fy
            )
            fm = (
                _mf61_tyre(cm, extra).forces(fz, 0.0, alpha, gamma, combined=False, limits=False).fy
            )
            jac[:, i] = (fp - fm) / (2 * h)
        return f0, jac

    prob = _Problem(
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
        _ranges(alpha, gamma, fz),
        extra,
        n_bad,
    )
    return _run(prob, x, fixed, max_iter)


# ---------------------------------------------------------------------- road data
def fit_from_wheel_table(
    wheels: pd.DataFrame,
    *,
    model: str = "pac94",
    constraints: str = "all",
    wheel: str | None = None,
    loss: str = "soft_l1",
    **kwargs,
) -> TyreFit:
    """Fit from the friction pipeline's per-wheel table (seed 002 with a GNSS compass).

    Uses ``slip_angle_rad``, ``load_N`` and ``force_N`` (lateral force estimated from vehicle
    motion, ISO) of the rows with finite values and ``steady`` True; camber is not measured, so
    γ = 0 and the camber coefficients come out flagged undetermined. ``force_sigma_N`` (when
    present) weights the points.

    Parameters
    ----------
    wheels : pandas.DataFrame
        :attr:`gripsense.pipeline.FrictionResult.wheels`.
    model : {"pac94", "mf61"}
    constraints : str
        Constraint set.
    wheel : str, optional
        One wheel (``front_left`` …) or an axle (``front``/``rear``); default all rows.
    loss : str
        Robust loss (default ``soft_l1``: motion-derived forces have outliers).
    **kwargs
        Passed to :func:`fit_pac94` / :func:`fit_mf61_lateral`.

    Returns
    -------
    TyreFit
        ``extra["rows_used"]`` and ``extra["rows_rejected"]`` (reason → count).
    """
    need = ("slip_angle_rad", "load_N", "force_N")
    missing = [c for c in need if c not in wheels.columns]
    if missing:
        raise InputError(
            f"wheel table: missing column {missing[0]!r}; give the wheels table "
            "of `gripsense friction -o DIR` (wheels.parquet)"
        )
    t = wheels
    if wheel is not None:
        sel = t["wheel"].astype(str)
        t = t[(sel == wheel) | sel.str.startswith(wheel + "_")]
        if t.empty:
            raise InputError(f"wheel table: no rows for wheel/axle {wheel!r}")
    rejected: dict[str, int] = {}
    ok = np.ones(len(t), bool)
    if "steady" in t.columns:
        m = ~t["steady"].fillna(False).to_numpy(bool)
        rejected["not_steady"] = int(m.sum())
        ok &= ~m
    vals = t[list(need)].to_numpy(float)
    m = ~np.all(np.isfinite(vals), axis=1) & ok
    rejected["not_finite"] = int(m.sum())
    ok &= ~m
    m = (vals[:, 1] <= 0) & ok
    rejected["no_load"] = int(m.sum())
    ok &= ~m
    weights = None
    if "force_sigma_N" in t.columns:
        s = t["force_sigma_N"].to_numpy(float)[ok]
        if np.all(np.isfinite(s) & (s > 0)):
            weights = 1.0 / s**2
    a, fz, fy = vals[ok, 0], vals[ok, 1], vals[ok, 2]
    fitter = {"pac94": fit_pac94, "mf61": fit_mf61_lateral}.get(model)
    if fitter is None:
        raise InputError(f"model={model!r}; use pac94 or mf61")
    fit = fitter(a, 0.0, fz, fy, constraints=constraints, loss=loss, weights=weights, **kwargs)
    fit.extra.update(
        {"rows_used": int(ok.sum()), "rows_rejected": {k: v for k, v in rejected.items() if v}}
    )
    return fit
