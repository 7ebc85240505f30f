"""Tread stiffness G of the brush model from cornering (thesis ch. 9; docs/physics.md §6).

* From the cornering stiffness (thesis §9.3): with K_y = G w l²/2 (eq. 9.1) and F = K_y β
  (9.2), G = 2 m v² cos β /(w l² R β) (second eq. 9.3, the thesis's form, ``G_thesis``). The
  brush model's own linear term gives G = 2 F cos²β /(w l² sin β) (``G``); they differ by ~β²/3.
  Valid in the linear regime only: with partial sliding F/tanβ = C(1 − θ + θ²/3), so G is biased
  **low** near the limit; every row carries its utilisation, and a 0.1° slip error is a
  ~0.1/β relative error in G (``G_rel_sigma``).
* **G sweep** (thesis §9.2): μ per wheel over a log-spaced G grid (1e4–1e8, 1000 points); the
  thesis's criteria — μ within (0, 1.2] on both wheels, and the smallest left/right difference —
  choose G. The result says when they do not pick a unique G.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pandas as pd

from gripsense.config import Vehicle
from gripsense.estimate.conditions import conditions
from gripsense.estimate.per_sample import PRESSURE_MODELS
from gripsense.physics import brush

__all__ = ["GSweep", "g_sweep", "tread_stiffness"]


def tread_stiffness(
    wheels: pd.DataFrame,
    vehicle: Vehicle,
    *,
    slip_sigma_deg: float = 0.1,
    conds: list[tuple[float, float]] | None = None,
) -> pd.DataFrame:
    """G per steady condition and wheel (a table like the thesis's Table 23).

    Parameters
    ----------
    wheels : pandas.DataFrame
        Wheel table of a friction run (any per-sample method).
    vehicle : Vehicle
        For the tyre widths.
    slip_sigma_deg : float
        Slip-angle uncertainty for ``G_rel_sigma`` [deg].
    conds : list of (t0, t1) or None
        Steady conditions (default: :func:`gripsense.report.figures.conditions`).

    Returns
    -------
    pandas.DataFrame
        ``condition``, ``wheel``, ``speed_kmh``, ``radius_m``, ``slip_deg``, ``utilisation``,
        ``G`` and ``G_thesis`` [N/m^3], ``G_rel_sigma`` [-], ``near_limit`` (utilisation > 0.5:
        G biased low).
    """
    conds = conditions(wheels) if conds is None else conds
    rows = []
    for i, (t0, t1) in enumerate(conds):
        seg = wheels[(wheels["t_s"] >= t0) & (wheels["t_s"] <= t1)]
        for w, g in seg.groupby("wheel", observed=True):
            wname = str(w)
            width = vehicle.tyres[wname.split("_")[0]].width_m
            b = np.abs(g["slip_angle_rad"].to_numpy(float))
            f = np.abs(g["force_N"].to_numpy(float))
            length = g["contact_length_m"].to_numpy(float)
            v = g["speed_mps"].to_numpy(float)
            r = g["radius_m"].to_numpy(float)
            m = g["mass_kg"].to_numpy(float)
            with np.errstate(divide="ignore", invalid="ignore"):
                gb = 2 * f * np.cos(b) ** 2 / (width * length**2 * np.sin(b))
                gt = 2 * m * v**2 * np.cos(b) / (width * length**2 * r * b)
            bm = float(np.median(b))
            rows.append(
                {
                    "condition": i + 1,
                    "wheel": wname,
                    "speed_kmh": float(np.mean(v)) * 3.6,
                    "radius_m": float(np.median(r)),
                    "slip_deg": float(np.rad2deg(bm)),
                    "utilisation": float(np.median(g["utilisation"])),
                    "G": float(np.median(gb)),
                    "G_thesis": float(np.median(gt)),
                    "G_rel_sigma": float(np.deg2rad(slip_sigma_deg) / bm) if bm > 0 else np.inf,
                }
            )
    out = pd.DataFrame(rows)
    if len(out):
        out["near_limit"] = out["utilisation"] > 0.5
    return out


@dataclass
class GSweep:
    """Result of a G sweep for one steady condition (the thesis's Fig. 93; plot it with
    :func:`gripsense.report.figures.g_sweep_figure`).

    Attributes
    ----------
    G : numpy.ndarray
        Tread stiffness grid [N/m^3].
    mu : dict
        Wheel → μ(G) [-] (NaN where the inversion has no solution).
    chosen : float
        The G the thesis's criteria pick [N/m^3] (NaN when none).
    unique : bool
        Whether the choice is unique (see :func:`g_sweep`).
    reason : str
        Why the choice is (not) unique.
    """

    G: np.ndarray
    mu: dict  # wheel -> μ(G)
    chosen: float
    unique: bool
    reason: str


def g_sweep(
    wheels: pd.DataFrame,
    vehicle: Vehicle,
    t0: float,
    t1: float,
    *,
    method: str = "thesis-2",
    g_min: float = 1e4,
    g_max: float = 1e8,
    n: int = 1000,
    mu_max: float = 1.2,
    rel_tol: float = 0.01,
) -> GSweep:
    """Sweep G for the steady condition [t0, t1] and pick it by the thesis's criteria.

    Uses the condition's median slip angle, load, force and contact length per wheel; μ(G) from
    the brush inversion of *method* (``thesis-2`` as the thesis, or ``brush-2``, ...). The choice
    is *not unique* when G values with a left/right difference within *rel_tol* of the best
    span more than a factor 1.5, and undefined when no G keeps both μ in (0, mu_max].

    Parameters
    ----------
    wheels : pandas.DataFrame
        Wheel table of a friction run.
    vehicle : Vehicle
        Vehicle description (tyre width).
    t0 : float
        Condition start [s].
    t1 : float
        Condition end [s].
    method : str
        A per-sample method (:data:`gripsense.estimate.per_sample.PRESSURE_MODELS`).
    g_min : float
        Smallest G [N/m^3].
    g_max : float
        Largest G [N/m^3].
    n : int
        Number of log-spaced G values.
    mu_max : float
        Largest admissible μ [-].
    rel_tol : float
        Relative tolerance on the left/right difference that counts as equally good [-].
    """
    pressure, model = PRESSURE_MODELS[method]
    seg = wheels[(wheels["t_s"] >= t0) & (wheels["t_s"] <= t1)]
    G = np.geomspace(g_min, g_max, n)
    mus = {}
    for w, g in seg.groupby("wheel", observed=True):
        wname = str(w)
        tyre = vehicle.tyres[wname.split("_")[0]]
        b = float(np.median(g["slip_angle_rad"]))
        f = float(np.median(g["force_N"]))
        fz = float(np.median(g["load_N"]))
        length = float(np.median(g["contact_length_m"]))
        c = 0.5 * G * tyre.width_m * length**2
        out = brush.invert(
            np.full(n, f),
            np.full(n, b),
            np.full(n, fz),
            c,
            pressure=pressure or tyre.pressure,
            model=model,
        )
        mu = np.where(out["status"] == brush.OK, out["mu"], np.nan)
        mus[wname] = mu
    if len(mus) < 2:
        return GSweep(G, mus, np.nan, False, "the sweep needs both wheels of an axle")
    arr = np.array(list(mus.values()))
    with np.errstate(invalid="ignore"):
        ok = np.all((arr > 0) & (arr <= mu_max), axis=0)
    if not ok.any():
        return GSweep(G, mus, np.nan, False, f"no G keeps μ of both wheels within (0, {mu_max}]")
    filled = np.where(np.isfinite(arr), arr, 0.0)
    diff = np.where(ok, filled.max(axis=0) - filled.min(axis=0), np.inf)
    k = int(np.argmin(diff))
    near = ok & (diff <= diff[k] + rel_tol * max(np.nanmean(arr[:, k]), 1e-9))
    span = G[near].max() / G[near].min()
    unique = bool(span <= 1.5)
    reason = (
        "unique"
        if unique
        else f"not unique: G from {G[near].min():.3g} to {G[near].max():.3g} fit the criteria "
        "equally well"
    )
    return GSweep(G, mus, float(G[k]), unique, reason)
