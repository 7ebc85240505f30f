"""Steady cornering conditions of a drive and their summary table (thesis figs 71–82, Table 25).

A *condition* is a contiguous run of steady, cornering samples of at least ``min_duration_s``;
:func:`condition_table` summarises each per wheel. The report, the stiffness estimate and the
examples share these.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from gripsense.constants import G0
from gripsense.estimate.wheels import NOT_STEADY_CORNERING

__all__ = ["condition_table", "conditions"]


def conditions(wheels: pd.DataFrame, *, min_duration_s: float = 3.0) -> list[tuple[float, float]]:
    """Steady cornering conditions: contiguous runs of steady, cornering samples.

    Parameters
    ----------
    wheels : pandas.DataFrame
        Wheel table of a friction run.
    min_duration_s : float
        Shortest condition [s].

    Returns
    -------
    list of (t_start, t_end) [s]
    """
    if wheels.empty:
        return []
    per_t = wheels.groupby("t_s", sort=True)["flag"].agg(
        lambda f: not f.isin(NOT_STEADY_CORNERING).all()
    )
    t = per_t.index.to_numpy(float)
    ok = per_t.to_numpy(bool)
    if t.size < 2:
        return []
    dt = np.median(np.diff(t))
    out, start = [], None
    for k in range(t.size):
        gap = k > 0 and t[k] - t[k - 1] > 2.5 * dt
        if start is not None and (not ok[k] or gap):
            if t[k - 1] - start >= min_duration_s:
                out.append((start, float(t[k - 1])))
            start = None
        if ok[k] and start is None:
            start = float(t[k])
    if start is not None and t[-1] - start >= min_duration_s:
        out.append((start, float(t[-1])))
    return out


def condition_table(
    wheels: pd.DataFrame, conds: list[tuple[float, float]], windows: pd.DataFrame | None = None
) -> pd.DataFrame:
    """Per condition and wheel: mean speed, radius, yaw rate, a_y; median valid μ; counts.

    With ``axle-window`` windows, μ is the median of the observable windows of the wheel's
    axle inside the condition (NaN when none is observable).

    Parameters
    ----------
    wheels : pandas.DataFrame
        Wheel table of a friction run.
    conds : list of (float, float)
        Conditions from :func:`conditions` [s].
    windows : pandas.DataFrame, optional
        ``axle-window`` windows; μ then comes from their observable windows.
    """
    rows = []
    for i, (t0, t1) in enumerate(conds):
        seg = wheels[(wheels["t_s"] >= t0) & (wheels["t_s"] <= t1)]
        for w, g in seg.groupby("wheel", observed=True):
            ok = g["flag"] == "ok"
            v = g["speed_mps"].mean()
            r = g["radius_m"].median()
            rows.append(
                {
                    "condition": i + 1,
                    "t_start": t0,
                    "t_end": t1,
                    "wheel": str(w),
                    "speed_kmh": v * 3.6,
                    "radius_m": r,
                    "yaw_rate_dps": np.rad2deg(v / r) if r > 0 else np.nan,
                    "ay_g": g["lateral_accel_mps2"].abs().mean() / G0,
                    "mu": g.loc[ok, "mu"].median() if ok.any() else np.nan,
                    "n_valid": int(ok.sum()),
                    "n": len(g),
                    "utilisation": g["utilisation"].median(),
                }
            )
            if windows is not None and len(windows):
                axle = str(w).split("_")[0]
                win = windows[
                    (windows["axle"] == axle)
                    & (windows["t_start"] >= t0)
                    & (windows["t_end"] <= t1 + 1e-9)
                    & windows["observable"]
                ]
                rows[-1]["mu"] = float(win["mu"].median()) if len(win) else np.nan
                rows[-1]["n_valid"] = len(win)
    return pd.DataFrame(rows)
