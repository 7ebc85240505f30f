"""Figures of the auxiliary sensors: camera slip angle over time."""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import pandas as pd
from matplotlib.figure import Figure

__all__ = ["camera_slip_figure"]


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
