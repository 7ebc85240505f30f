"""Figures of the auxiliary sensors: braking deceleration (with the plateaus read), camera slip
angle over time.
"""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np
import pandas as pd
from matplotlib.figure import Figure

__all__ = ["braking_figure", "camera_slip_figure"]


def camera_slip_figure(res: pd.DataFrame) -> Figure:
    """Slip angle per frame pair, all and accepted (``gripsense camera-slip``).

    Parameters
    ----------
    res : pandas.DataFrame
        :func:`gripsense.vision.slip_camera.slip_from_frames` output (``t_s``,
        ``slip_angle_deg``, ``ok``).

    Returns
    -------
    matplotlib.figure.Figure
        Slip angle [deg] (ISO) against time [s].
    """
    ok = res[res["ok"]]
    fig, ax = plt.subplots(figsize=(7, 3.5))
    ax.plot(res["t_s"], res["slip_angle_deg"], ".", color="0.6", label="all pairs")
    ax.plot(ok["t_s"], ok["slip_angle_deg"], "o", ms=3, label="accepted")
    ax.set_xlabel("time [s]")
    ax.set_ylabel("slip angle [deg] (ISO)")
    ax.legend(fontsize=8)
    fig.tight_layout()
    return fig


def braking_figure(runs: list) -> Figure:
    """Forward acceleration of braking stops with the plateau each μ was read from (a figure
    like the thesis's Fig. 110; ``gripsense brake-mu``).

    Parameters
    ----------
    runs : list of (pandas.DataFrame, BrakingResult)
        Accelerometer table (``t_s`` [s], ``ax`` [m/s^2]) and its
        :func:`gripsense.estimate.braking.estimate_braking` result, one pair per recording.

    Returns
    -------
    matplotlib.figure.Figure
        a_x / g against time from each event's onset − 1 s; the plateau shaded and its μ
        written at its end.
    """
    from gripsense.constants import G0

    fig, ax = plt.subplots(figsize=(7.5, 4), layout="constrained")
    for i, (acc, res) in enumerate(runs):
        color = f"C{i % 10}"
        for ev in res.events.itertuples():
            t0 = ev.t_onset - 1.0
            sel = (acc["t_s"] >= t0) & (acc["t_s"] <= ev.t_end + 1.0)
            t = acc["t_s"][sel] - t0
            ax.plot(t, acc["ax"][sel] / G0, color=color, lw=0.8, label=f"{ev.mu:.3f}")
            p0 = ev.t_onset + 0.3 - t0
            ax.plot([p0, p0 + ev.plateau_s], [-ev.mu, -ev.mu], color=color, lw=3, alpha=0.6)
    ax.axhline(0, color="0.5", lw=0.5)
    mus = np.concatenate([r.events["mu"].to_numpy() for _, r in runs]) if runs else np.array([])
    ax.set(
        xlabel="time from onset − 1 s [s]",
        ylabel="forward acceleration a_x / g [-]",
        title=f"Locked-wheel braking: μ = a/g on each plateau (mean {np.mean(mus):.3f})",
    )
    ax.legend(title="μ per stop (bar: plateau)", fontsize=8, ncols=2, loc="lower right")
    return fig
