"""``axle-window``: friction per axle over windows, with calibrated intervals and abstention.

Why: at everyday lateral acceleration the whole difference between μ = 0.9 and μ = ∞ lies in a
few hundredths of a degree of slip angle (docs/physics.md §1.4), and the compass heading carries
errors of tenths of a degree that do not average out (mounting offset, multipath). A per-sample
formula cannot know that; this estimator does.

Model, for one axle and one steady window (docs/physics.md §4.4, §1.2, §2.3):

    F̄ = m_axle · ā_y = Σ_{L,R} −sign(ᾱ'_i) F_brush(μ, |ᾱ'_i|, F̄z_i, s_C · C̄_i) + e
    ᾱ'_i = ᾱ_i − δψ

where bars are means over the window. In steady cornering the true slip angle is one value per
wheel, so the window mean is its sufficient estimate: the white noise averages down (variance
/n) identically for every hypothesis. Treating samples as independent instead lets a fully
sliding tyre, whose force does not depend on the slip angle, "explain" the white slip noise for
free and win every comparison — a degeneracy this formulation avoids.

* one μ per axle; the left/right split of the force follows from the brush model with each
  wheel's own slip angle and load (not assumed equal);
* nuisance parameters: the stiffness scale s_C ~ N(1, σ_G) (prior from the tread-stiffness
  uncertainty) and a heading bias δψ ~ N(0, σ_bias) common to the samples of a window
  (residual mounting offset + slowly varying heading error);
* window variance (errors in variables, linearised): σ_F² (speed and yaw-rate noise in
  a_y, and a systematic axle-force model error) + (∂F/∂α)² σ_α² (white heading, course and
  yaw-rate noise in the slip angles) +
  (∂F/∂ΔFz · ρ ΔFz)² (load-transfer parameter uncertainty ρ), evaluated at the candidate
  parameters — the effective-variance method of errors-in-variables least squares (Orear,
  Am. J. Phys. 50 (1982) 912; York et al., Am. J. Phys. 72 (2004) 367). A ½ log σ² term (full
  Gaussian likelihood) is deliberately left out: it rewards the degenerate fully-sliding fit,
  whose slope ∂F/∂α vanishes.

Interval: **profile likelihood**. For each μ on a log grid the negative log-likelihood is
minimised over (s_C, δψ) on a grid; {μ : 2(ℓ(μ) − ℓ_min) ≤ 2.706} is the 90 % interval
(Wilks). It handles what the data cannot say: when the likelihood stays flat towards large μ
(low utilisation), the interval is unbounded above, the window is reported **not observable**
and only the interval's lower end — a one-sided 95 % lower bound — is given. No prior on μ is
needed, and the interval's coverage is checked on simulated drives (``benchmarks/accuracy.py``).
A point value is reported only when the interval at ``point_level`` (99 %) is bounded and
narrower than ``max_width``; the interval reported is the 90 % one.

The window means are running sums, so an online estimator keeps them incrementally
(:class:`OnlineAxleWindow`) and gives the batch answers. The per-axle summary combines disjoint
segments (``segment_s``), each with its own heading bias.
"""

from __future__ import annotations

from collections import deque
from dataclasses import dataclass

import numpy as np
import pandas as pd
from numba import njit, prange

from gripsense.config import Vehicle
from gripsense.constants import CHI2_1_90
from gripsense.estimate.friction import NOT_STEADY_CORNERING
from gripsense.estimate.noise import NoiseModel
from gripsense.physics.brush import force_slope_scalar

__all__ = ["OnlineAxleWindow", "WindowOptions", "axle_samples", "estimate_windows", "profile"]


@dataclass(frozen=True)
class WindowOptions:
    """Settings of the ``axle-window`` estimator.

    Attributes
    ----------
    window_s, step_s : float
        Sliding-window length and step [s].
    segment_s : float
        Length of the disjoint segments whose likelihoods are combined for the per-axle
        summary, each with its own heading bias [s] (about the correlation time of slowly
        varying heading errors).
    max_width : float
        Largest width of the ``point_level`` interval for which a point value is reported [-].
    point_level : float
        Confidence level of the interval that decides abstention (0.99): a point value needs
        strong evidence, while the reported interval is the 90 % one.
    min_samples : int
        Fewest usable samples in a window.
    mu_min, mu_max : float
        μ grid range [-]; an interval reaching mu_max is unbounded.
    n_mu, n_stiffness, n_bias : int
        Grid sizes (μ log-spaced; s_C over ±2.5 σ; δψ over ±3 σ). Dense, because a window
        is one super-sample (cheap) and a coarse δψ grid biases the profile.
    """

    window_s: float = 3.0
    step_s: float = 1.0
    segment_s: float = 20.0
    max_width: float = 0.3
    point_level: float = 0.99
    min_samples: int = 10
    mu_min: float = 0.05
    mu_max: float = 3.0
    n_mu: int = 80
    n_stiffness: int = 41
    n_bias: int = 201


@njit(cache=True, nogil=True, parallel=True)
def _nll_grid(aL, aR, fzL, fzR, cL, cR, F, sF, sa, dfz, lt_rel, mu_g, s_g, d_g, quartic, out):
    """out[im, js, kd] = Σ_k NLL_k(μ_im, s_js, δψ_kd) (without the priors)."""
    n = F.size
    for im in prange(mu_g.size):
        mu = mu_g[im]
        for js in range(s_g.size):
            sc = s_g[js]
            for kd in range(d_g.size):
                d = d_g[kd]
                acc = 0.0
                for k in range(n):
                    a1 = aL[k] - d
                    a2 = aR[k] - d
                    t1 = abs(np.tan(a1))
                    t2 = abs(np.tan(a2))
                    f1, g1 = force_slope_scalar(mu, t1, fzL[k], sc * cL[k], quartic)
                    f2, g2 = force_slope_scalar(mu, t2, fzR[k], sc * cR[k], quartic)
                    p1 = -f1 if a1 > 0 else f1
                    p2 = -f2 if a2 > 0 else f2
                    # ∂F/∂Fz at fixed α and C: (F − slope · t/(1 + t²)) / Fz
                    dz1 = (f1 - g1 * t1 / (1.0 + t1 * t1)) / fzL[k] if fzL[k] > 0 else 0.0
                    dz2 = (f2 - g2 * t2 / (1.0 + t2 * t2)) / fzR[k] if fzR[k] > 0 else 0.0
                    if a1 > 0:
                        dz1 = -dz1
                    if a2 > 0:
                        dz2 = -dz2
                    lt = lt_rel * dfz[k] * (dz2 - dz1)
                    var = sF[k] * sF[k] + (g1 + g2) ** 2 * sa[k] * sa[k] + lt * lt + 1e-6
                    r = F[k] - p1 - p2
                    # effective-variance least squares (Orear 1982; York 2004): no log-variance
                    # term, which would reward the degenerate fully-sliding fit (zero slope)
                    acc += 0.5 * r * r / var
                out[im, js, kd] = acc


def _grids(o: WindowOptions, noise: NoiseModel):
    mu_g = np.geomspace(o.mu_min, o.mu_max, o.n_mu)
    sig_s = max(noise.tread_stiffness_rel, 1e-6)
    s_g = np.clip(1.0 + sig_s * np.linspace(-2.5, 2.5, o.n_stiffness), 0.2, None)
    sig_d = max(np.deg2rad(noise.heading_bias_deg), 1e-9)
    d_g = sig_d * np.linspace(-3.0, 3.0, o.n_bias)
    prior = (s_g[:, None] - 1.0) ** 2 / (2 * sig_s**2) + d_g[None, :] ** 2 / (2 * sig_d**2)
    return mu_g, s_g, d_g, prior


def grid_nll(x: dict, o: WindowOptions, noise: NoiseModel, quartic: bool) -> np.ndarray:
    """NLL grid (μ, s_C, δψ) of a set of axle samples (without priors)."""
    mu_g, s_g, d_g, _ = _grids(o, noise)
    out = np.zeros((mu_g.size, s_g.size, d_g.size))
    if x["F"].size:
        _nll_grid(
            x["aL"],
            x["aR"],
            x["fzL"],
            x["fzR"],
            x["cL"],
            x["cR"],
            x["F"],
            x["sF"],
            x["sa"],
            x["dfz"],
            noise.load_transfer_rel,
            mu_g,
            s_g,
            d_g,
            quartic,
            out,
        )
    return out


def _crossing(x: np.ndarray, y: np.ndarray, level: float, i_from: int, step: int) -> float:
    """First x (log-interpolated) from index i_from moving by step where y rises above level."""
    i = i_from
    while 0 <= i + step < x.size:
        j = i + step
        if y[j] > level:
            f = (level - y[i]) / (y[j] - y[i])
            return float(np.exp(np.log(x[i]) + f * (np.log(x[j]) - np.log(x[i]))))
        i = j
    return float("inf") if step > 0 else float(x[0])


def profile(
    nll: np.ndarray,
    o: WindowOptions,
    noise: NoiseModel,
    *,
    dof: int = 1,
    utilisation: float = np.nan,
) -> dict:
    """Profile-likelihood estimate from an NLL grid (μ, s_C, δψ) or (μ, s_C).

    Returns ``mu``, ``mu_low``, ``mu_high`` (inf when unbounded), ``observable``,
    ``mu_lower_bound``, ``stiffness_scale`` and its 90 % interval, ``heading_bias_deg``,
    ``fit`` (``ok``, or ``inconsistent`` when the best fit fails a χ² test with *dof* degrees
    of freedom at 0.1 %, or lies on the lowest μ of the grid: the data contradict the model —
    e.g. an uncorrected heading offset — and no value is given; the lower bound then falls
    back to the *utilisation*, which every tyre model respects).
    """
    mu_g, s_g, d_g, prior = _grids(o, noise)
    sig_s = max(noise.tread_stiffness_rel, 1e-6)
    kd_best = None
    if nll.ndim == 3:
        tot = nll + prior[None, :, :]
        kd_best = np.argmin(tot, axis=2)
        p_ms = np.take_along_axis(tot, kd_best[..., None], 2)[..., 0]
    else:
        p_ms = nll + ((s_g - 1.0) ** 2 / (2 * sig_s**2))[None, :]
    p_mu = p_ms.min(axis=1)
    dev = 2.0 * (p_mu - p_mu.min())
    im = int(np.argmin(p_mu))
    # refine the minimum with a parabola in log μ
    mu_hat = mu_g[im]
    if 0 < im < mu_g.size - 1:
        x0, x1, x2 = np.log(mu_g[im - 1 : im + 2])
        y0, y1, y2 = p_mu[im - 1 : im + 2]
        den = (x0 - x1) * (x0 - x2) * (x1 - x2)
        a = (x2 * (y1 - y0) + x1 * (y0 - y2) + x0 * (y2 - y1)) / den
        b = (x2**2 * (y0 - y1) + x1**2 * (y2 - y0) + x0**2 * (y1 - y2)) / den
        if a > 0:
            mu_hat = float(np.exp(np.clip(-b / (2 * a), x0, x2)))
    lo = _crossing(mu_g, dev, CHI2_1_90, im, -1)
    hi = _crossing(mu_g, dev, CHI2_1_90, im, +1)
    from scipy.stats import chi2

    level = float(chi2.ppf(o.point_level, 1))
    lo_p = _crossing(mu_g, dev, level, im, -1)
    hi_p = _crossing(mu_g, dev, level, im, +1)
    observable = bool(np.isfinite(hi_p) and hi_p - lo_p <= o.max_width)
    fit_ok = bool(2.0 * p_mu.min() <= chi2.ppf(0.999, dof) and im > 0)
    if not fit_ok:
        observable = False
    p_s = p_ms.min(axis=0)
    dev_s = 2.0 * (p_s - p_s.min())
    js = int(np.argmin(p_s))
    inside = s_g[dev_s <= CHI2_1_90]
    out = {
        "mu": float(mu_hat) if observable else np.nan,
        "mu_low": float(lo),
        "mu_high": float(hi),
        "observable": observable,
        "mu_lower_bound": float(lo) if fit_ok else float(utilisation),
        "fit": "ok" if fit_ok else "inconsistent",
        "mu_best": float(mu_hat),
        "stiffness_scale": float(s_g[js]),
        "stiffness_scale_low": float(inside.min()) if inside.size else np.nan,
        "stiffness_scale_high": float(inside.max()) if inside.size else np.nan,
    }
    if kd_best is not None:
        im_s = int(np.argmin(p_ms[im]))
        out["heading_bias_deg"] = float(np.rad2deg(d_g[kd_best[im, im_s]]))
    return out


def axle_samples(wheels: pd.DataFrame, axle: str) -> dict:
    """Per-sample inputs of one axle from a wheel table
    (:func:`gripsense.estimate.friction.friction_from_motion`).

    Samples with both wheels present, steady cornering above the speed gate and finite inputs.

    Parameters
    ----------
    wheels : pandas.DataFrame
        Wheel table.
    axle : str
        ``front`` or ``rear``.
    """
    lname, rname = f"{axle}_left", f"{axle}_right"
    cols = [
        "epoch",
        "t_s",
        "slip_angle_rad",
        "load_N",
        "cornering_stiffness_N_per_rad",
        "force_N",
        "force_sigma_N",
        "slip_sigma_rad",
        "flag",
    ]
    L = wheels.loc[wheels["wheel"] == lname, cols].set_index("epoch")
    R = wheels.loc[wheels["wheel"] == rname, cols].set_index("epoch")
    both = L.add_suffix("_L").join(R.add_suffix("_R"), how="inner")
    usable = ~both["flag_L"].isin(NOT_STEADY_CORNERING) & ~both["flag_R"].isin(NOT_STEADY_CORNERING)
    num = both[[c for c in both.columns if not c.startswith("flag")]]
    usable &= np.isfinite(num.to_numpy(dtype=float)).all(axis=1)
    b = both[usable]
    fzl, fzr = b["load_N_L"].to_numpy(float), b["load_N_R"].to_numpy(float)
    F = (b["force_N_L"] + b["force_N_R"]).to_numpy(float)
    return {
        "epoch": b.index.to_numpy(),
        "t": b["t_s_L"].to_numpy(float),
        "aL": b["slip_angle_rad_L"].to_numpy(float),
        "aR": b["slip_angle_rad_R"].to_numpy(float),
        "fzL": fzl,
        "fzR": fzr,
        "cL": b["cornering_stiffness_N_per_rad_L"].to_numpy(float),
        "cR": b["cornering_stiffness_N_per_rad_R"].to_numpy(float),
        "F": F,
        "sF": (b["force_sigma_N_L"] + b["force_sigma_N_R"]).to_numpy(float),
        "sa": 0.5 * (b["slip_sigma_rad_L"] + b["slip_sigma_rad_R"]).to_numpy(float),
        "dfz": 0.5 * (fzr - fzl),
        "util": np.abs(F) / (fzl + fzr),
    }


def _take(x: dict, sel) -> dict:
    return {k: v[sel] for k, v in x.items()}


_MEAN_KEYS = ("aL", "aR", "fzL", "fzR", "cL", "cR", "F", "dfz")


def window_mean(x: dict, axle_force_rel: float = 0.0) -> dict:
    """One super-sample from a window's samples: means, white variances divided by n, plus
    the systematic axle-force model error (not divided).
    """
    n = x["F"].size
    out = {k: np.array([x[k].mean()]) for k in _MEAN_KEYS}
    out["sa"] = np.array([np.sqrt(np.mean(x["sa"] ** 2) / n)])
    f = out["F"][0]
    out["sF"] = np.array([np.sqrt(np.mean(x["sF"] ** 2) / n + (axle_force_rel * f) ** 2)])
    return out


def estimate_windows(
    wheels: pd.DataFrame,
    vehicle: Vehicle,
    *,
    noise: NoiseModel | None = None,
    options: WindowOptions | None = None,
) -> tuple[pd.DataFrame, pd.DataFrame]:
    """Windowed per-axle estimates and a per-axle summary.

    Parameters
    ----------
    wheels : pandas.DataFrame
        Wheel table of :func:`gripsense.estimate.friction.friction_from_motion`.
    vehicle : Vehicle
    noise : NoiseModel
    options : WindowOptions

    Returns
    -------
    windows : pandas.DataFrame
        One row per axle and window: ``axle``, ``t_start``, ``t_end``, ``n``, ``utilisation``
        (95th percentile of |F_axle|/Fz_axle), ``mu`` (NaN unless ``observable``), ``mu_low``,
        ``mu_high`` (inf when unbounded), ``mu_lower_bound``, ``observable``,
        ``stiffness_scale`` with ``_low``/``_high`` (× the nominal C), ``heading_bias_deg``,
        ``cornering_stiffness_N_per_rad`` (estimated, mean over the window's wheels).
    summary : pandas.DataFrame
        One row per axle: the same quantities from all usable samples, combined over disjoint
        segments of ``segment_s`` each with its own heading bias.
    """
    noise = noise or NoiseModel()
    o = options or WindowOptions()
    rows, summ = [], []
    axles = sorted({w.split("_")[0] for w in wheels["wheel"].astype(str).unique()})
    for axle in axles:
        x = axle_samples(wheels, axle)
        quartic = vehicle.tyres[axle].pressure == "quartic"
        t = x["t"]
        if t.size:
            starts = np.arange(t.min(), t.max() - o.window_s + o.step_s + 1e-9, o.step_s)
            for t0 in starts:
                sel = (t >= t0) & (t < t0 + o.window_s)
                if sel.sum() < o.min_samples:
                    continue
                w = _take(x, sel)
                mean = window_mean(w, noise.axle_force_rel)
                est = profile(
                    grid_nll(mean, o, noise, quartic),
                    o,
                    noise,
                    utilisation=float(np.quantile(w["util"], 0.95)),
                )
                rows.append(_row(axle, w, est, t0, t0 + o.window_s))
        # summary: disjoint segments, each with its own heading bias, combined
        total = None
        n_used = 0
        n_seg = 0
        if t.size:
            _, _, d_g, _ = _grids(o, noise)
            sig_d = max(np.deg2rad(noise.heading_bias_deg), 1e-9)
            d_prior = d_g**2 / (2 * sig_d**2)
            seg = np.floor((t - t.min()) / o.segment_s).astype(int)
            for s_id in np.unique(seg):
                sel = seg == s_id
                if sel.sum() < o.min_samples:
                    continue
                g = grid_nll(window_mean(_take(x, sel), noise.axle_force_rel), o, noise, quartic)
                g = (g + d_prior[None, None, :]).min(axis=2)  # this segment's own bias
                total = g if total is None else total + g
                n_used += int(sel.sum())
                n_seg += 1
        if total is not None:
            # adds the stiffness prior once; dof = number of segments
            est = profile(
                total, o, noise, dof=n_seg, utilisation=float(np.quantile(x["util"], 0.95))
            )
            summ.append(_row(axle, x, est, float(t.min()), float(t.max())) | {"n": n_used})
        else:
            summ.append(
                {
                    "axle": axle,
                    "n": 0,
                    "observable": False,
                    "mu": np.nan,
                    "mu_low": np.nan,
                    "mu_high": np.nan,
                    "mu_lower_bound": np.nan,
                    "utilisation": np.nan,
                }
            )
    return pd.DataFrame(rows), pd.DataFrame(summ)


def _row(axle: str, w: dict, est: dict, t0: float, t1: float) -> dict:
    c = 0.5 * (w["cL"] + w["cR"]).mean() if w["F"].size else np.nan
    return {
        "axle": axle,
        "t_start": t0,
        "t_end": t1,
        "n": int(w["F"].size),
        "utilisation": float(np.quantile(w["util"], 0.95)) if w["F"].size else np.nan,
        **est,
        "cornering_stiffness_N_per_rad": est["stiffness_scale"] * c,
    }


class OnlineAxleWindow:
    """Sliding-window ``axle-window`` estimator for live use, updated sample by sample.

    Keeps running sums of the window's samples (added on arrival, subtracted on expiry), so
    an update costs O(1) and an estimate one super-sample grid. The estimates equal the batch
    :func:`estimate_windows` windows on the same data (up to floating-point summation order).

    Parameters
    ----------
    quartic : bool
        Pressure shape of the axle's tyres.
    noise, options
        As for :func:`estimate_windows`.
    """

    _SUMS = (*_MEAN_KEYS, "sa2", "sF2")

    def __init__(
        self,
        *,
        quartic: bool = False,
        noise: NoiseModel | None = None,
        options: WindowOptions | None = None,
    ):
        self.noise = noise or NoiseModel()
        self.o = options or WindowOptions()
        self.quartic = quartic
        self._sum = dict.fromkeys(self._SUMS, 0.0)
        self._items: deque = deque()  # (t, {key: value})
        self._util: deque = deque()

    def _add(self, v: dict, sign: float) -> None:
        for k in self._SUMS:
            self._sum[k] += sign * v[k]

    def push(self, sample: dict) -> None:
        """Add one axle sample (keys of :func:`axle_samples`, scalars; ``t`` [s]).

        Parameters
        ----------
        sample : dict
            One axle sample: the keys of :func:`axle_samples` as scalars, ``t`` [s].
        """
        v = {k: float(sample[k]) for k in (*_MEAN_KEYS, "t", "util")}
        v["sa2"] = float(sample["sa"]) ** 2
        v["sF2"] = float(sample["sF"]) ** 2
        self._items.append((v["t"], v))
        self._add(v, +1.0)

    def expire(self, t_start: float) -> None:
        """Drop samples older than *t_start*.

        Parameters
        ----------
        t_start : float
            Samples before this time are dropped [s].
        """
        while self._items and self._items[0][0] < t_start:
            _, v = self._items.popleft()
            self._add(v, -1.0)

    def estimate(self, t_start: float, t_end: float) -> dict | None:
        """Estimate over the samples in [t_start, t_end) (None with too few samples).

        Parameters
        ----------
        t_start : float
            Window start [s].
        t_end : float
            Window end (exclusive) [s].
        """
        self.expire(t_start)
        late = [v for t, v in self._items if t >= t_end]
        n = len(self._items) - len(late)
        if n < self.o.min_samples:
            return None
        tot = dict(self._sum)
        for v in late:
            for k in self._SUMS:
                tot[k] -= v[k]
        w = {k: np.array([tot[k] / n]) for k in _MEAN_KEYS}
        w["sa"] = np.array([np.sqrt(tot["sa2"] / n / n)])
        f = w["F"][0]
        w["sF"] = np.array([np.sqrt(tot["sF2"] / n / n + (self.noise.axle_force_rel * f) ** 2)])
        util = np.array([v["util"] for t, v in self._items if t < t_end])
        est = profile(
            grid_nll(w, self.o, self.noise, self.quartic),
            self.o,
            self.noise,
            utilisation=float(np.quantile(util, 0.95)),
        )
        c = 0.5 * (w["cL"][0] + w["cR"][0])
        return {
            "t_start": t_start,
            "t_end": t_end,
            "n": n,
            "utilisation": float(np.quantile(util, 0.95)),
            **est,
            "cornering_stiffness_N_per_rad": est["stiffness_scale"] * c,
        }
