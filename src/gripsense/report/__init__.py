"""Results people can look at: figures (matplotlib) and a self-contained HTML report. Only
consumes results; computes nothing that an estimator should.
"""

from gripsense.report.figures import (
    condition_figure,
    g_sweep_figure,
    interval_bars,
    mu_vs_radius,
    mu_vs_utilisation,
    mu_vs_yaw_rate,
    trajectory,
)
from gripsense.report.html import write_report
from gripsense.report.sensor_figures import camera_slip_figure
from gripsense.report.steering_figures import release_figure, settling_figure, yaw_gain_figure
from gripsense.report.tyre_figures import fit_figure

__all__ = [
    "camera_slip_figure",
    "condition_figure",
    "fit_figure",
    "g_sweep_figure",
    "interval_bars",
    "mu_vs_radius",
    "mu_vs_utilisation",
    "mu_vs_yaw_rate",
    "release_figure",
    "settling_figure",
    "trajectory",
    "write_report",
    "yaw_gain_figure",
]
