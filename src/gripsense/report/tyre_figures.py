"""Figures of a tyre fit, like seed 002's figs 7–13: Fy–α at several loads and at several
cambers (load fixed), measured points against the identified curve, and the residuals.

The measured points of a road test are scattered in (α, γ, Fz): each panel shows the points whose
load (or camber) is near the curve's value, so points and curve are comparable.
"""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np
import pandas as pd
from matplotlib.figure import Figure

__all__ = ["eval_figure", "fit_figure"]


def fit_figure(
    fit, data: pd.DataFrame, *, title: str = "", extra_fits: dict | None = None
) -> Figure:
    """Three panels: Fy–α at 3 loads (at the camber of the points near each load), Fy–α at
    3 cambers (median load), residuals.

    Parameters
    ----------
    fit : gripsense.identify.tyre_fit.TyreFit
        The identified model.
    data : pandas.DataFrame
        ``alpha_rad``, ``gamma_rad``, ``fz_N``, ``fy_N``.
    title : str
        Figure title.
    extra_fits : dict, optional
        ``{label: TyreFit}`` drawn dashed in the first panel (e.g. the unconstrained fit).

    Returns
    -------
    matplotlib.figure.Figure
    """
    a_deg = np.rad2deg(data["alpha_rad"].to_numpy())
    g = data["gamma_rad"].to_numpy()
    fz = data["fz_N"].to_numpy()
    fy = data["fy_N"].to_numpy()
    span = max(np.max(np.abs(a_deg)) * 1.5, 2.0)
    al = np.linspace(-span, span, 301)
    fig, axes = plt.subplots(1, 3, figsize=(15, 4.6), constrained_layout=True)

    ax = axes[0]
    levels = np.quantile(fz, [0.15, 0.5, 0.85])
    width = 0.1 * (np.ptp(fz) + 1.0)
    for lvl, col in zip(levels, ("tab:blue", "tab:green", "tab:red"), strict=True):
        near = np.abs(fz - lvl) < width
        # the curve at the camber those points have, so points and curve are comparable
        g_lvl = float(np.median(g[near])) if near.any() else 0.0
        ax.plot(a_deg[near], fy[near], ".", ms=2, color=col, alpha=0.35)
        ax.plot(
            al,
            fit.predict(lvl, np.deg2rad(al), g_lvl),
            color=col,
            lw=2,
            label=f"Fz = {lvl / 1000:.1f} kN, γ = {np.rad2deg(g_lvl):+.1f}°",
        )
        for i, (lab, other) in enumerate((extra_fits or {}).items()):
            ax.plot(
                al,
                other.predict(lvl, np.deg2rad(al), g_lvl),
                color=col,
                lw=1,
                ls=("--", ":")[i % 2],
                label=f"{lab}" if lvl == levels[0] else None,
            )
    ax.axvspan(a_deg.min(), a_deg.max(), color="0.93", zorder=-1, label="data range")
    ax.set(xlabel="slip angle α [deg]", ylabel="lateral force Fy [N]", title="several loads")
    ax.legend(fontsize=8)
    ax.grid(alpha=0.3)

    ax = axes[1]
    f0 = float(np.median(fz))
    gl = np.quantile(g, [0.1, 0.5, 0.9]) if np.ptp(g) > 0 else np.array([0.0])
    gw = 0.15 * (np.ptp(g) + 1e-9)
    for lvl, col in zip(gl, ("tab:purple", "tab:gray", "tab:orange"), strict=False):
        near = (np.abs(g - lvl) <= gw) & (np.abs(fz - f0) < width)
        ax.plot(a_deg[near], fy[near], ".", ms=2, color=col, alpha=0.35)
        ax.plot(
            al,
            fit.predict(f0, np.deg2rad(al), lvl),
            color=col,
            lw=2,
            label=f"γ = {np.rad2deg(lvl):+.1f}°",
        )
    ax.set(
        xlabel="slip angle α [deg]",
        ylabel="lateral force Fy [N]",
        title=f"Fz = {f0 / 1000:.1f} kN, several cambers",
    )
    ax.legend(fontsize=8)
    ax.grid(alpha=0.3)

    ax = axes[2]
    res = fy - fit.predict(fz, data["alpha_rad"].to_numpy(), g)
    ax.plot(a_deg, res, ".", ms=2, color="0.3", alpha=0.5)
    ax.axhline(0, color="k", lw=0.8)
    ax.set(
        xlabel="slip angle α [deg]",
        ylabel="residual [N]",
        title=f"residuals: rms {fit.residual_rms_N:.0f} N, n = {fit.n}",
    )
    ax.grid(alpha=0.3)
    checks = fit.physical_checks()
    bad = [k for k, v in checks.items() if not v]
    fig.suptitle(
        (title + " — " if title else "")
        + f"{fit.model}, constraints {fit.constraints}; "
        + ("physically plausible" if not bad else "UNPHYSICAL: " + ", ".join(bad))
    )
    return fig


def eval_figure(table: pd.DataFrame, *, title: str = "", max_curves: int = 12) -> Figure:
    """Fy (and Fx where the model gives it) against slip angle, one curve per load, camber and
    slip ratio of a ``gripsense tyre eval`` grid.

    Parameters
    ----------
    table : pandas.DataFrame
        The grid as ``tyre eval -o`` writes it: ``fz_N`` [N], ``kappa`` [-], ``gamma_deg``
        [deg], ``alpha_deg`` [deg], ``fx_N`` [N], ``fy_N`` [N].
    title : str
        Figure title (the model's description).
    max_curves : int
        Curves drawn at most (the first by load, camber, slip ratio); the legend says how many
        were left out.

    Returns
    -------
    matplotlib.figure.Figure
    """
    has_fx = bool(np.isfinite(table["fx_N"]).any())
    fig, axes = plt.subplots(
        1, 2 if has_fx else 1, figsize=(12 if has_fx else 7, 4.6), constrained_layout=True,
        squeeze=False,
    )  # fmt: skip
    groups = list(table.groupby(["fz_N", "gamma_deg", "kappa"], sort=True))
    for i, ((fz, g, k), t) in enumerate(groups[:max_curves]):
        t = t.sort_values("alpha_deg")
        label = f"Fz {fz / 1000:g} kN, γ {g:+g}°" + (f", κ {k:g}" if k else "")
        style = "-" if len(t) > 1 else "o"
        axes[0, 0].plot(t["alpha_deg"], t["fy_N"], style, color=f"C{i % 10}", label=label)
        if has_fx:
            axes[0, 1].plot(t["alpha_deg"], t["fx_N"], style, color=f"C{i % 10}", label=label)
    for ax, what in zip(
        axes[0], ("lateral force Fy [N]", "longitudinal force Fx [N]"), strict=False
    ):
        ax.set(xlabel="slip angle α [deg]", ylabel=what)
        ax.axhline(0, color="k", lw=0.6)
        ax.grid(alpha=0.3)
    more = len(groups) - max_curves
    axes[0, 0].legend(
        fontsize=8, title=f"{more} more curve(s) not drawn" if more > 0 else None, title_fontsize=8
    )
    fig.suptitle(title)
    return fig
