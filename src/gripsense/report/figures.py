"""Figures of a friction run, like the thesis's figs 71–82 and 112–139.

Computation (:func:`conditions`, :func:`condition_table`) is kept apart from plotting; every
plot function takes tables and returns a matplotlib Figure. Left wheels are red and right
wheels blue, as in the thesis. All figures accept missing channels (no yaw rate from ROT, no
steering angle) and runs without a single valid μ.
"""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np
import pandas as pd
from matplotlib.axes import Axes
from matplotlib.figure import Figure

from gripsense.constants import Z90
from gripsense.estimate.wheels import NOT_STEADY_CORNERING
from gripsense.physics.surface import SURFACE_BANDS

__all__ = [
    "condition_figure",
    "g_sweep_figure",
    "interval_bars",
    "mu_vs_radius",
    "mu_vs_utilisation",
    "mu_vs_yaw_rate",
    "save_png",
    "trajectory",
]

WHEEL_COLOURS = {
    "rear_left": "tab:red",
    "front_left": "lightcoral",
    "rear_right": "tab:blue",
    "front_right": "lightskyblue",
}
BAND_COLOURS = {"ICE": "#dbe9f6", "SNOW": "#eef3f8", "WET": "#fff4d6", "DRY": "#e8f5e0"}


def _bands(ax, ymax: float) -> None:
    for name, lo, hi in SURFACE_BANDS:
        ax.axhspan(lo, min(hi, ymax), color=BAND_COLOURS[name], zorder=0)
        if lo < ymax:
            ax.text(
                0.995,
                min((lo + min(hi, ymax)) / 2, ymax),
                name,
                transform=ax.get_yaxis_transform(),
                ha="right",
                va="center",
                fontsize=7,
                color="0.45",
            )


def _legend_outside(ax) -> None:
    """The legend right of the axes: inside it covered the surface-band labels."""
    ax.legend(fontsize=8, loc="upper left", bbox_to_anchor=(1.01, 1.0), borderaxespad=0.0)


def interval_bars(summary: pd.DataFrame, unit: str, *, mu_max: float = 1.4) -> Figure:
    """Per unit (axle or wheel), the two statements against the surface bands (Table 4): the
    estimate's 90 % interval as a bar with its value, or — without a value — the measured-grip
    bound as an arrow pointing right (the data prove μ ≥ it).

    Parameters
    ----------
    summary : pandas.DataFrame
        A result's summary: *unit*, ``mu``, ``mu_low``, ``mu_high``, ``observable``, and
        ``grip_used_lower`` where the method has it.
    unit : str
        Name of the unit column (``axle`` or ``wheel``).
    mu_max : float
        Right end of the axis [-].

    Returns
    -------
    matplotlib.figure.Figure
        The figure.
    """
    n = len(summary)
    fig, ax = plt.subplots(figsize=(9.0, 1.2 + 0.45 * max(n, 1)))
    for name, lo, hi in SURFACE_BANDS:
        ax.axvspan(lo, min(hi, mu_max), color=BAND_COLOURS[name], zorder=0)
        ax.text((lo + min(hi, mu_max)) / 2, 1.0, name, transform=ax.get_xaxis_transform(),
                ha="center", va="bottom", fontsize=8, color="0.4")  # fmt: skip
    labels = []
    for i, r in enumerate(summary.to_dict("records")):
        y = n - 1 - i
        labels.append(str(r.get(unit, i)))
        bound = r.get("grip_used_lower", np.nan)
        if bool(r.get("observable", False)) and np.isfinite(r.get("mu", np.nan)):
            lo, hi = r.get("mu_low", np.nan), r.get("mu_high", np.nan)
            lab = "estimate: 90 % interval" if i == 0 else None
            ax.plot([lo, min(hi, mu_max)], [y, y], color="tab:blue", lw=6, alpha=0.6,
                    solid_capstyle="butt", label=lab)  # fmt: skip
            ax.plot(r["mu"], y, "o", color="navy", ms=6)
        if bound is not None and np.isfinite(bound):
            ax.annotate("", xy=(min(bound + 0.12, mu_max), y - 0.18), xytext=(bound, y - 0.18),
                        arrowprops={"arrowstyle": "->", "color": "tab:red", "lw": 1.5})  # fmt: skip
            ax.plot(bound, y - 0.18, "|", color="tab:red", ms=12, mew=2)
    ax.plot([], [], "|", color="tab:red", ms=10, mew=2, label="measured: the data prove μ ≥")
    ax.set_yticks(range(n))
    ax.set_yticklabels(labels[::-1])
    ax.set_ylim(-0.7, n - 0.3)
    ax.set_xlim(0, mu_max)
    ax.set_xlabel("μ")
    ax.legend(loc="center left", bbox_to_anchor=(1.01, 0.5), fontsize=7, frameon=False)
    fig.tight_layout()
    return fig


def condition_figure(
    wheels: pd.DataFrame,
    t0: float,
    t1: float,
    *,
    title: str = "",
    windows: pd.DataFrame | None = None,
) -> Figure:
    """Four panels for one steady condition (thesis figs 72–81 / 113–137).

    (a) slip angle and turn radius, (b) load and contact length, (c) lateral force and slide
    point, (d) μ with its 90 % interval, invalid samples shaded, Table-4 surface bands behind.

    Parameters
    ----------
    wheels : pandas.DataFrame
        Wheel table of a friction run.
    t0 : float
        Condition start [s].
    t1 : float
        Condition end [s].
    title : str
        Figure title.
    windows : pandas.DataFrame, optional
        ``axle-window`` windows: panel (d) shows the values of this condition's windows per
        axle (each window alone) instead of per-sample values, which that method has none of.
    """
    seg = wheels[(wheels["t_s"] >= t0) & (wheels["t_s"] <= t1)]
    fig, axs = plt.subplots(2, 2, figsize=(11, 7), sharex=True)
    _condition_panels(axs, seg)
    _mu_panel(axs[1, 1], seg, t0, t1, windows)
    for a in axs[1]:
        a.set_xlabel("time [s]")
    fig.suptitle(title, fontsize=11)
    fig.tight_layout()
    return fig


def _condition_panels(axs: np.ndarray, seg: pd.DataFrame) -> None:
    """Panels (a)–(c) of :func:`condition_figure`: each wheel's quantity (solid) and its
    companion (dashed, right axis).
    """
    specs = [
        (
            axs[0, 0],
            "slip_angle_rad",
            np.rad2deg,
            "slip angle [deg]",
            "radius_m",
            1.0,
            "radius [m]",
            "(a)",
        ),
        (
            axs[0, 1],
            "load_N",
            None,
            "load [N]",
            "contact_length_m",
            1000.0,
            "contact length [mm]",
            "(b)",
        ),
        (
            axs[1, 0],
            "force_N",
            None,
            "lateral force [N]",
            "slide_point_m",
            1000.0,
            "slide point [mm]",
            "(c)",
        ),
    ]
    for ax, col, fn, label, col2, k2, label2, tag in specs:
        ax2 = ax.twinx()
        for w, g in seg.groupby("wheel", observed=True):
            c = WHEEL_COLOURS.get(str(w), "k")
            y = g[col].to_numpy(float)
            ax.plot(g["t_s"], fn(y) if fn else y, color=c, lw=1.2, label=str(w))
            ax2.plot(g["t_s"], g[col2].to_numpy(float) * k2, color=c, lw=0.8, ls="--")
        ax.set_ylabel(label)
        ax2.set_ylabel(label2 + " (dashed)", color="0.4")
        ax.set_title(tag, loc="left", fontsize=10)
    axs[0, 0].legend(fontsize=8, loc="best")


def _mu_panel(
    ax: Axes, seg: pd.DataFrame, t0: float, t1: float, windows: pd.DataFrame | None
) -> None:
    """Panel (d) of :func:`condition_figure`: μ per valid sample or per window, |F|/Fz dotted."""
    ymax = 1.3
    _bands(ax, ymax)
    any_valid = False
    for w, g in seg.groupby("wheel", observed=True):
        c = WHEEL_COLOURS.get(str(w), "k")
        ok = g["flag"] == "ok"
        if ok.any():
            any_valid = True
            ax.errorbar(
                g.loc[ok, "t_s"],
                g.loc[ok, "mu"],
                yerr=Z90 * g.loc[ok, "mu_sigma"],
                fmt="o",
                ms=2.5,
                color=c,
                elinewidth=0.6,
                alpha=0.8,
                label=str(w),
            )
        ax.plot(g["t_s"], g["utilisation"], color=c, lw=0.8, ls=":", alpha=0.8)
    per_window = windows is not None
    if windows is not None:
        win = windows[(windows["t_start"] >= t0) & (windows["t_end"] <= t1 + 1e-9)]
        win = win[win["observable"].astype(bool)]
        for axle, g in win.groupby("axle"):
            c = WHEEL_COLOURS.get(f"{axle}_left", "k")
            for k, r in enumerate(g.to_dict("records")):
                lab = f"{axle} axle: a window's value, 90 %" if k == 0 else None
                ax.plot([r["t_start"], r["t_end"]], [r["mu"], r["mu"]], color=c, lw=2, label=lab)
                tm = 0.5 * (r["t_start"] + r["t_end"])
                ax.plot([tm, tm], [r["mu_low"], min(r["mu_high"], ymax)], color=c, lw=0.8)
        any_valid = len(win) > 0
    else:
        bad = seg.groupby("t_s")["flag"].agg(lambda f: not (f == "ok").any())
        tt = bad.index.to_numpy(float)
        if tt.size > 1:
            dt = np.median(np.diff(tt))
            for t, b in zip(tt, bad.to_numpy(bool), strict=True):
                if b:
                    ax.axvspan(t - dt / 2, t + dt / 2, color="0.85", alpha=0.6, lw=0, zorder=1)
    if per_window:
        if any_valid:
            ax.legend(fontsize=7, loc="lower right")
        else:
            ax.text(
                0.5,
                0.55,
                "no window of this condition has a value of its own\n(the summary's value, if "
                "any, combines the whole drive;\ndotted: |F|/Fz, what the data prove: μ ≥ it)",
                transform=ax.transAxes,
                ha="center",
                fontsize=8,
            )
    elif not any_valid:
        ax.text(
            0.5,
            0.55,
            "μ not observable in this condition\n(dotted: |F|/Fz, what the data prove: μ ≥ it)",
            transform=ax.transAxes,
            ha="center",
            fontsize=9,
        )
    ax.set_ylim(0, ymax)
    ax.set_ylabel(
        "μ (bars: windows, axle-window; dotted: |F|/Fz)"
        if per_window
        else "μ (points: valid; dotted: |F|/Fz)"
    )
    ax.set_title("(d)", loc="left", fontsize=10)


def _speed_groups(ct: pd.DataFrame) -> pd.Series:
    return (ct["speed_kmh"] / 5).round() * 5


def mu_vs_radius(ct: pd.DataFrame, *, what: str = "μ (median of valid samples)") -> Figure:
    """μ per condition vs turn radius, per speed group, with least-squares lines (figs 82, 138).

    Parameters
    ----------
    ct : pandas.DataFrame
        Condition table (:func:`gripsense.estimate.conditions.condition_table`).
    what : str
        What the condition's μ is (the y label): the median of the valid samples of a
        per-sample method, or of the condition's own windows (``axle-window``).
    """
    fig, ax = plt.subplots(figsize=(7, 4.5))
    _bands(ax, 1.5)
    d = ct.dropna(subset=["mu"])
    if d.empty:
        ax.text(0.5, 0.5, "no condition with a valid μ", transform=ax.transAxes, ha="center")
    else:
        for (spd, g), mk in zip(d.groupby(_speed_groups(d)), "osD^v<>", strict=False):
            ax.plot(g["radius_m"], g["mu"], mk, label=f"{spd:.0f} km/h")
            if g["radius_m"].nunique() >= 2:
                a, b = np.polyfit(g["radius_m"], g["mu"], 1)
                x = np.linspace(g["radius_m"].min(), g["radius_m"].max(), 10)
                ax.plot(x, a * x + b, "-", lw=1, color=ax.lines[-1].get_color())
        _legend_outside(ax)
    ax.set_xlabel("turn radius [m]")
    ax.set_ylabel(what)
    ax.set_ylim(0, 1.5)
    ax.set_title("μ vs turn radius, per speed (least-squares lines)")
    fig.tight_layout()
    return fig


def mu_vs_yaw_rate(ct: pd.DataFrame, *, what: str = "μ") -> Figure:
    """μ per condition vs yaw rate (fig 139).

    Parameters
    ----------
    ct : pandas.DataFrame
        Condition table.
    what : str
        What the condition's μ is (the y label; :func:`mu_vs_radius`).
    """
    fig, ax = plt.subplots(figsize=(7, 4.5))
    _bands(ax, 1.5)
    d = ct.dropna(subset=["mu"])
    for w, g in d.groupby("wheel"):
        ax.plot(g["yaw_rate_dps"], g["mu"], "o", color=WHEEL_COLOURS.get(w, "k"), label=w)
    if d.empty:
        ax.text(0.5, 0.5, "no condition with a valid μ", transform=ax.transAxes, ha="center")
    else:
        _legend_outside(ax)
    ax.set_xlabel("yaw rate [deg/s]")
    ax.set_ylabel(what)
    ax.set_ylim(0, 1.5)
    ax.set_title("μ vs yaw rate")
    fig.tight_layout()
    return fig


def mu_vs_utilisation(wheels: pd.DataFrame, windows: pd.DataFrame | None = None) -> Figure:
    """Estimated μ with its 90 % interval vs the measured grip — where μ is observable.

    Estimates (model-based) where the method gives one; everywhere the measured grip's
    model-free lower bound (grey triangles: what the data prove without a tyre model). With
    ``axle-window`` windows, one point per window.

    Parameters
    ----------
    wheels : pandas.DataFrame
        Wheel table.
    windows : pandas.DataFrame, optional
        ``axle-window`` windows: one point per window.
    """
    fig, ax = plt.subplots(figsize=(7, 4.5))
    _bands(ax, 1.5)
    ax.plot([0, 1.5], [0, 1.5], color="0.5", lw=0.8, ls="--", label="μ = measured grip")
    if windows is not None and len(windows):
        ay = windows["grip_used"]
        ok = windows["observable"].astype(bool)
        ax.errorbar(
            ay[ok],
            windows.loc[ok, "mu"],
            yerr=[
                windows.loc[ok, "mu"] - windows.loc[ok, "mu_low"],
                windows.loc[ok, "mu_high"] - windows.loc[ok, "mu"],
            ],
            fmt="o",
            ms=3,
            label="estimate μ (tyre model), 90 % interval",
        )
        ax.plot(
            ay,
            windows["grip_used_lower"],
            "v",
            color="0.5",
            ms=3,
            label="measured: the data prove μ ≥ (model-free)",
        )
    else:
        c = wheels[~wheels["flag"].isin(NOT_STEADY_CORNERING)]
        ok = c["flag"] == "ok"
        ay = c["grip_proven" if "grip_proven" in c else "grip_used"]  # the bound's (§14.1)
        ax.errorbar(
            ay[ok],
            c.loc[ok, "mu"],
            yerr=Z90 * c.loc[ok, "mu_sigma"],
            fmt="o",
            ms=2,
            alpha=0.5,
            elinewidth=0.5,
            label="valid μ ± 90 %",
        )
        ax.plot(
            ay,
            (ay - Z90 * c["grip_sigma"]).clip(lower=0),
            "v",
            color="0.5",
            ms=2,
            alpha=0.5,
            label="measured: the data prove μ ≥ (model-free)",
        )
    ax.set_xlim(0, max(1.0, ax.get_xlim()[1]))
    ax.set_ylim(0, 1.5)
    ax.set_xlabel("measured grip of the axle |F_axle| / Fz_axle")
    ax.set_ylabel("μ")
    ax.set_title("estimated μ vs measured grip: μ is observable only near the limit")
    ax.legend(fontsize=7, loc="upper left")
    fig.tight_layout()
    return fig


def trajectory(epochs: pd.DataFrame, conds: list[tuple[float, float]] | None = None) -> Figure:
    """Driven path from lat/lon (fig 71/112), steady conditions highlighted.

    Parameters
    ----------
    epochs : pandas.DataFrame
        Epoch table with ``lat_deg``/``lon_deg``.
    conds : list of (float, float), optional
        Steady conditions to highlight [s].
    """
    fig, ax = plt.subplots(figsize=(6, 6))
    e = epochs.dropna(subset=["lat_deg", "lon_deg"]) if "lat_deg" in epochs else epochs.iloc[:0]
    conds = list(conds or [])
    if e.empty:
        ax.text(0.5, 0.5, "no position in the log", transform=ax.transAxes, ha="center")
    else:
        lat0 = np.deg2rad(e["lat_deg"].mean())
        x = (np.deg2rad(e["lon_deg"] - e["lon_deg"].iloc[0]) * 6371000.0 * np.cos(lat0)).to_numpy()
        y = (np.deg2rad(e["lat_deg"] - e["lat_deg"].iloc[0]) * 6371000.0).to_numpy()
        t = e["t_s"].to_numpy(float)
        steady = np.zeros(len(e), bool)
        for t0, t1 in conds:
            steady |= (t >= t0) & (t <= t1)
        # the path outside the conditions in grey (dashed under them): never one colour alone
        ax.plot(x, y, color="0.55", lw=1, ls=":", zorder=1)
        ax.plot(np.where(steady, np.nan, x), np.where(steady, np.nan, y), color="0.35", lw=1.2,
                label="not a steady condition", zorder=2)  # fmt: skip
        colours = [plt.get_cmap("tab10")(k) for k in range(10)]
        for i, (t0, t1) in enumerate(conds):
            sel = (t >= t0) & (t <= t1)
            lab = (
                f"condition {i + 1}: {t0:.0f}–{t1:.0f} s"
                if i < 9 or len(conds) == 10
                else (f"conditions 10–{len(conds)} (colours repeat)" if i == 9 else None)
            )
            ax.plot(x[sel], y[sel], lw=2.8, color=colours[i % len(colours)], zorder=3, label=lab)
        ax.plot(x[:1], y[:1], "o", color="k", ms=5, label="start", zorder=4)
        ax.set_aspect("equal", adjustable="datalim")
        ax.legend(fontsize=7, loc="best")
    ax.set_xlabel("east [m]")
    ax.set_ylabel("north [m]")
    ax.set_title(
        "trajectory: steady conditions in colour (see legend)"
        if conds
        else "trajectory (no steady condition of 3 s or more)"
    )
    fig.tight_layout()
    return fig


def g_sweep_figure(sweep) -> Figure:
    """μ per wheel against the tread stiffness G of a G sweep (thesis Fig. 93).

    Parameters
    ----------
    sweep : gripsense.estimate.stiffness.GSweep
        Result of :func:`gripsense.estimate.stiffness.g_sweep`.

    Returns
    -------
    matplotlib.figure.Figure
        Log G axis, the admissible band 0 < μ ≤ 1.2 and the chosen G.
    """
    fig, ax = plt.subplots(figsize=(7, 4.5))
    for w, mu in sweep.mu.items():
        ax.semilogx(sweep.G, mu, color=WHEEL_COLOURS.get(w, "k"), label=w)
    ax.axhspan(0, 1.2, color="0.93", zorder=0, label="0 < μ ≤ 1.2")
    if np.isfinite(sweep.chosen):
        ax.axvline(
            sweep.chosen,
            color="k",
            ls="--",
            lw=1,
            label=f"chosen G = {sweep.chosen:.3g}" + ("" if sweep.unique else " (not unique)"),
        )
    ax.set_ylim(0, 3)
    ax.set_xlabel("G [N/m³]")
    ax.set_ylabel("μ")
    ax.set_title("G sweep (thesis §9.2)")
    ax.legend(fontsize=8)
    fig.tight_layout()
    return fig


def save_png(fig: Figure, path, kind: str, dpi: int = 90) -> None:
    """Save *fig* as PNG with ``Software: gripsense <kind>`` in its metadata, so a later run
    recognises the file as its own (:func:`gripsense.io.output_folder.is_own_file`), and close it.

    Parameters
    ----------
    fig : matplotlib.figure.Figure
        The figure.
    path : str or Path
        Output file.
    kind : str
        Output kind.
    dpi : int
        Resolution [1/inch].
    """
    fig.savefig(path, dpi=dpi, format="png", metadata={"Software": f"gripsense {kind}"})
    plt.close(fig)
