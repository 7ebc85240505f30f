"""Channels at different rates onto one time base.

A receiver may send its heading at 25 Hz (``$PASHR``) and its course and speed at 1 Hz
(``$GPRMC``): the two never share an epoch, so no epoch has the side slip β = course − heading
that the friction estimate needs. :func:`align_channels` fills the course and speed of heading
epochs that lie between two course samples:

* the heading is interpolated (circularly) to each course sample's time, which gives the side
  slip there, β_k = course_k − heading(t_k);
* β and the speed are interpolated linearly in time onto the heading epochs between two course
  samples — the side slip varies slowly even in a turn (the heading carries the fast part), so
  this is far more accurate than interpolating the course itself;
* only where the two course samples are at most ``max_gap_s`` apart, the heading brackets each
  course sample within ``max_heading_gap_s``, and the motion is smooth: β changes by at most
  ``max_slip_change_deg`` and the speed by at most ``max_speed_change_mps`` between them, and
  the straight line between the two side slips errs by at most ``max_interp_error_deg``
  (Δt²/8 times β's curvature, from the neighbouring samples).

The time skew between the channels (a receiver that tags its course with the start of the
second, say) is checked and reported, not applied: over each interval between two course
samples the course turns as much as the heading over the same interval shifted by τ, if the side
slip changes slowly; τ is the shift that fits best, given only when the yaw rate varies enough
to tell and the best shift is inside ±0.5 s. In fast transients (a 4 s slalom) the side slip's
own rate biases it by up to ~0.1 s.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pandas as pd

__all__ = ["Alignment", "align_channels"]


@dataclass(frozen=True)
class Alignment:
    """What :func:`align_channels` did.

    Attributes
    ----------
    n_heading : int
        Epochs with a heading.
    n_course : int
        Epochs with course and speed (before alignment).
    n_aligned : int
        Heading epochs that received an interpolated course and speed.
    n_gap : int
        Heading epochs without course left alone: no course sample on one side within
        ``max_gap_s``.
    n_not_smooth : int
        Heading epochs left alone because the side slip or speed changed too much between the
        two course samples.
    heading_rate_hz, course_rate_hz : float
        Median rates of the two channels [Hz] (NaN with fewer than two samples).
    skew_s : float
        Estimated time skew of the course channel against the heading [s] (NaN when the drive
        does not turn enough to tell).
    """

    n_heading: int
    n_course: int
    n_aligned: int
    n_gap: int
    n_not_smooth: int
    heading_rate_hz: float
    course_rate_hz: float
    skew_s: float

    def describe(self) -> str:
        """One line for the ingest summary."""
        if self.n_aligned == 0 and self.n_gap == 0 and self.n_not_smooth == 0:
            return "channels: heading and course/speed share their epochs (nothing to align)"
        if self.n_course == 0:  # no rate to state: nothing was there to align
            return (
                f"channels: no epoch has course and speed: nothing to align onto the "
                f"{self.n_heading} heading epochs"
            )
        skew = (
            ""
            if np.isnan(self.skew_s)
            else f"; course time skew {self.skew_s * 1e3:+.0f} ms (±100 ms in fast transients)"
        )
        return (
            f"aligned: course/speed ({self.course_rate_hz:.3g} Hz) onto the heading epochs "
            f"({self.heading_rate_hz:.3g} Hz) by the side slip — {self.n_aligned} epochs filled, "
            f"{self.n_gap} left (gap), {self.n_not_smooth} left (motion not smooth){skew}"
        )


def _second_derivative(t: np.ndarray, y: np.ndarray) -> np.ndarray:
    """Second divided difference of y(t) at each interior sample (NaN at the ends and across
    NaNs) [unit of y / s²].
    """
    out = np.full(t.size, np.nan)
    if t.size >= 3:
        h1, h2 = np.diff(t)[:-1], np.diff(t)[1:]
        d1 = _wrap180(y[1:-1] - y[:-2]) / np.where(h1 > 0, h1, np.nan)
        d2 = _wrap180(y[2:] - y[1:-1]) / np.where(h2 > 0, h2, np.nan)
        out[1:-1] = 2.0 * (d2 - d1) / (h1 + h2)
    return out


def _rate(t: np.ndarray) -> float:
    dt = np.diff(np.sort(t))
    dt = dt[dt > 0]
    return float(1.0 / np.median(dt)) if dt.size else float("nan")


def _wrap180(x):
    return (np.asarray(x) + 180.0) % 360.0 - 180.0


def _heading_at(t_h, h_unwrapped, t, max_gap_s):
    """Unwrapped heading interpolated at t, NaN where the heading does not bracket t closely."""
    out = np.interp(t, t_h, h_unwrapped, left=np.nan, right=np.nan)
    j = np.searchsorted(t_h, t)
    lo = np.clip(j - 1, 0, t_h.size - 1)
    hi = np.clip(j, 0, t_h.size - 1)
    exact = t_h[hi] == t
    ok = exact | ((t - t_h[lo] <= max_gap_s) & (t_h[hi] - t <= max_gap_s) & (j > 0))
    return np.where(ok, out, np.nan)


def align_channels(
    epochs: pd.DataFrame,
    *,
    max_gap_s: float = 1.5,
    max_heading_gap_s: float = 0.25,
    max_slip_change_deg: float = 2.0,
    max_speed_change_mps: float = 1.5,
    max_interp_error_deg: float = 0.3,
) -> tuple[pd.DataFrame, Alignment]:
    """Course and speed onto the heading epochs where the channels arrive at different rates.

    Parameters
    ----------
    epochs : pandas.DataFrame
        Epoch table of :func:`gripsense.io.read_nmea` (``t_s``, ``heading_deg``,
        ``course_deg``, ``speed_mps``).
    max_gap_s : float
        Longest time between the two course samples that bracket an epoch [s].
    max_heading_gap_s : float
        Longest distance from a course sample to the heading samples that bracket it [s].
    max_slip_change_deg : float
        Largest change of the side slip between the two course samples [deg].
    max_speed_change_mps : float
        Largest change of speed between the two course samples [m/s].
    max_interp_error_deg : float
        Largest error of the straight line between the two side-slip samples, from the side
        slip's curvature at both ends [deg].

    Returns
    -------
    epochs : pandas.DataFrame
        A copy with ``course_deg`` and ``speed_mps`` filled where aligned (the input unchanged
        when nothing is to be aligned).
    Alignment
        What was done.
    """
    t = epochs["t_s"].to_numpy(float)
    h = epochs["heading_deg"].to_numpy(float)
    c = epochs["course_deg"].to_numpy(float)
    v = epochs["speed_mps"].to_numpy(float)
    has_h = np.isfinite(h) & np.isfinite(t)
    has_c = np.isfinite(c) & np.isfinite(v) & np.isfinite(t)
    rates = (_rate(t[has_h]), _rate(t[has_c]))
    need = has_h & ~has_c
    if not need.any() or has_h.sum() < 2 or has_c.sum() < 2:
        return epochs, Alignment(
            int(has_h.sum()), int(has_c.sum()), 0, int(need.sum()), 0, *rates, np.nan
        )
    ih = np.flatnonzero(has_h)
    ih = ih[np.argsort(t[ih], kind="stable")]
    t_h = t[ih]
    h_un = np.rad2deg(np.unwrap(np.deg2rad(h[ih])))
    ic = np.flatnonzero(has_c)
    ic = ic[np.argsort(t[ic], kind="stable")]
    t_c = t[ic]
    h_at_c = _heading_at(t_h, h_un, t_c, max_heading_gap_s)
    beta = _wrap180(c[ic] - h_at_c)
    skew = _skew(t_h, h_un, t_c, c[ic], max_heading_gap_s)
    # each epoch to fill: the course samples before and after it
    jn = np.flatnonzero(need)
    k = np.searchsorted(t_c, t[jn], side="right")
    a, b = k - 1, k
    inside = (a >= 0) & (b < t_c.size)
    a_, b_ = np.clip(a, 0, t_c.size - 1), np.clip(b, 0, t_c.size - 1)
    close = inside & (t_c[b_] - t_c[a_] <= max_gap_s) & (t_c[b_] > t_c[a_])
    ok_beta = np.isfinite(beta[a_]) & np.isfinite(beta[b_])
    d_beta = np.abs(_wrap180(beta[b_] - beta[a_]))
    d_v = np.abs(v[ic][b_] - v[ic][a_])
    # the error of a straight line between the two samples: (Δt²/8)|β''|, β'' from the second
    # divided differences at both ends (a side slip at its peak in a slalom bends the most)
    curv = _second_derivative(t_c, beta)
    bend = np.fmax(np.abs(curv[a_]), np.abs(curv[b_]))
    interp_err = (t_c[b_] - t_c[a_]) ** 2 / 8.0 * np.where(np.isfinite(bend), bend, 0.0)
    smooth = (
        ok_beta
        & (d_beta <= max_slip_change_deg)
        & (d_v <= max_speed_change_mps)
        & (interp_err <= max_interp_error_deg)
    )
    fill = close & smooth
    w = np.where(fill, (t[jn] - t_c[a_]) / np.where(fill, t_c[b_] - t_c[a_], 1.0), 0.0)
    beta_j = beta[a_] + _wrap180(beta[b_] - beta[a_]) * w
    out = epochs.copy()
    cj = out["course_deg"].to_numpy(float).copy()
    vj = out["speed_mps"].to_numpy(float).copy()
    cj[jn[fill]] = ((h[jn] + beta_j) % 360.0)[fill]
    vj[jn[fill]] = (v[ic][a_] + (v[ic][b_] - v[ic][a_]) * w)[fill]
    out["course_deg"] = cj
    out["speed_mps"] = vj
    return out, Alignment(
        int(has_h.sum()),
        int(has_c.sum()),
        int(fill.sum()),
        int((~close).sum()),
        int((close & ~smooth).sum()),
        *rates,
        skew,
    )


def _skew(t_h, h_un, t_c, c, max_heading_gap_s, max_lag_s=0.5) -> float:
    """Lag τ of the course channel: over each interval between two course samples the course
    turns as the heading turns over the same interval shifted by τ (the side slip changes
    slowly). τ minimises the squared difference; NaN when the yaw rate does not vary enough to
    tell (in a steady turn every shift fits equally).
    """
    if t_c.size < 6:
        return float("nan")
    dt = np.diff(t_c)
    dc = _wrap180(np.diff(c))
    lags = np.linspace(-max_lag_s, max_lag_s, 101)
    cost = np.full(lags.size, np.nan)
    for i, lag in enumerate(lags):
        hh = _heading_at(t_h, h_un, t_c + lag, max_heading_gap_s + max_lag_s)
        d = dc - np.diff(hh)
        m = np.isfinite(d) & (dt > 0)
        if m.sum() >= 5:
            cost[i] = float(np.mean((d[m] / dt[m]) ** 2))
    if not np.isfinite(cost).any():
        return float("nan")
    best = int(np.nanargmin(cost))
    # identifiable only if shifting by the whole range costs clearly more than the minimum
    spread = np.nanmax(cost) - cost[best]
    if not spread > 0.25 + 0.5 * cost[best]:  # (deg/s)²: a turn-rate change of ~1 deg/s
        return float("nan")
    if best in (0, lags.size - 1):
        return float("nan")  # at the edge of the search: not a skew this check can name
    return float(lags[best])
