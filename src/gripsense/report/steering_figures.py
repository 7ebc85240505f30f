"""Figures of a steering identification, like seed 003's Figs. 4.1–4.5."""

from __future__ import annotations

from typing import TYPE_CHECKING

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np
from matplotlib.figure import Figure

if TYPE_CHECKING:
    from gripsense.identify.steering import CsResult

__all__ = ["release_figure", "settling_figure", "yaw_gain_figure"]


def release_figure(
    traces: list[tuple[np.ndarray, np.ndarray]], model: dict | None = None
) -> Figure:
    """Fig. 4.1: steering angle after release, normalised to the held angle; the identified
    model dashed. ``traces``: (time since release [s], angle) pairs.

    Parameters
    ----------
    traces : list of (numpy.ndarray, numpy.ndarray)
        Measured time [s] and angle from the release on.
    model : dict, optional
        The identified model's release response
        (:func:`gripsense.physics.steering_system.simulate_release`).
    """
    fig, ax = plt.subplots(figsize=(6.4, 4.0), constrained_layout=True)
    for i, (t, a) in enumerate(traces):
        ax.plot(t, a / a[0], lw=1, label=f"test {i + 1}")
    if model is not None:
        ax.plot(
            model["t_s"],
            model["alpha_rad"] / model["alpha_rad"][0],
            "k--",
            lw=2,
            label="model, identified C_s, k_s",
        )
    ax.axhspan(-0.05, 0.05, color="0.9", label="±5 % band")
    ax.set(
        xlabel="time after release [s]",
        ylabel="steering angle / held angle",
        title="hands-off release",
    )
    ax.legend(fontsize=8)
    ax.grid(alpha=0.3)
    return fig


def settling_figure(results: list[tuple[str, CsResult]], t_mean: float, t_sd: float) -> Figure:
    """Figs. 4.2/4.5: settling time against C_s for each k_s, the measured mean ± SD band and
    the identified C_s. ``results``: (label, CsResult) pairs.

    Parameters
    ----------
    results : list of (str, CsResult)
        Labelled C_s identifications.
    t_mean : float
        Mean measured settling time [s].
    t_sd : float
        Its standard deviation [s].
    """
    fig, ax = plt.subplots(figsize=(6.4, 4.0), constrained_layout=True)
    for label, r in results:
        over = r.overdamped
        ax.plot(r.curve_cs[over], r.curve_t_s[over], "-", lw=2, label=f"{label} (over-damped)")
        if (~over).any():
            ax.plot(
                r.curve_cs[~over], r.curve_t_s[~over], ":", lw=1, label=f"{label} (oscillating)"
            )
        if np.isfinite(r.cs):
            ax.plot([r.cs], [t_mean], "o")
            ax.annotate(
                f"C_s = {r.cs:.0f} [{r.low:.0f}, {r.high:.0f}]",
                (r.cs, t_mean),
                textcoords="offset points",
                xytext=(6, -12),
                fontsize=8,
            )
    ax.axhspan(
        t_mean - t_sd, t_mean + t_sd, color="tab:orange", alpha=0.2, label="measured mean ± SD"
    )
    ax.set(
        xscale="log",
        xlabel="kingpin damping C_s [N·m·s/rad]",
        ylabel="settling time [s]",
        title="settling time vs C_s",
    )
    ax.legend(fontsize=8)
    ax.grid(alpha=0.3, which="both")
    return fig


def yaw_gain_figure(r) -> Figure:
    """Fig. 4.4: model yaw gain against k_s with the measured (normalised) gain.

    Parameters
    ----------
    r : KsResult
        The k_s identification.
    """
    fig, ax = plt.subplots(figsize=(6.4, 4.0), constrained_layout=True)
    ax.plot(r.curve_ks, r.curve_gain_dps2, "-", lw=2, label="model")
    ax.axhline(r.gain_dps2, color="tab:orange", label=f"measured {r.gain_dps2:.1f} deg/s²")
    if np.isfinite(r.ks):
        ax.axvline(r.ks, color="k", ls="--", lw=1, label=f"k_s = {r.ks:.0f} N·m/rad")
    ax.set(
        xlabel="steering stiffness k_s [N·m/rad]",
        ylabel="yaw gain [deg/s²]",
        title="yaw gain vs k_s" + ("" if r.flag == "ok" else " — k_s not determined"),
    )
    ax.legend(fontsize=8)
    ax.grid(alpha=0.3)
    return fig
