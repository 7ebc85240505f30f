"""Seed-003 metrics of steering traces — settling time after a release and yaw gain after a
step steer — applied alike to measured recordings and to the model's responses
(``docs/physics.md`` §9.3).
"""

from __future__ import annotations

import numpy as np

from gripsense._arrays import sample_step
from gripsense.errors import InputError

__all__ = ["release_onset", "release_settling_time", "settling_time", "step_metrics", "yaw_gain"]


def settling_time(
    t,
    angle,
    *,
    reference: str = "initial",
    band: float = 0.05,
    release_s: float | None = None,
    final: float | None = None,
) -> float:
    """Seed-003 settling time (整定時間) of a steering-angle trace after release.

    Parameters
    ----------
    t, angle : array_like
        Time [s] and steering angle [any angle unit].
    reference : {"initial", "converged"}
        ``initial`` (seed §4.1, default): from release until the angle stays within
        ``band``·|α0 − α∞| of the converged angle α∞; ``converged`` (seed §1.3): within
        ``band``·|α∞| (needs a trace that settles away from zero).
    band : float
        Relative band (0.05 = 5 %).
    release_s : float, optional
        Release time; default the first sample.
    final : float, optional
        Converged angle α∞; default the mean of the last 10 % of the trace.

    Returns
    -------
    float
        Settling time [s]; NaN when the trace never stays in the band.
    """
    t = np.asarray(t, float)
    y = np.asarray(angle, float)
    t0 = t[0] if release_s is None else release_s
    m = t >= t0
    t, y = t[m], y[m]
    if t.size < 3:
        raise InputError("settling_time: fewer than 3 samples after the release")
    yf = float(np.mean(y[-max(3, y.size // 10) :])) if final is None else float(final)
    if reference == "initial":
        tol = band * abs(y[0] - yf)
    elif reference == "converged":
        if abs(yf) < 1e-9 * (abs(y[0]) + 1e-300):
            raise InputError(
                "settling_time: reference='converged' needs a trace that settles "
                "away from zero; use reference='initial'"
            )
        tol = band * abs(yf)
    else:
        raise InputError(f"reference={reference!r}; use 'initial' or 'converged'")
    outside = np.abs(y - yf) > tol
    if outside[-1]:
        return float("nan")
    if not outside.any():
        return 0.0
    last = np.flatnonzero(outside)[-1]
    # interpolate the crossing between the last sample outside and the next one
    y0, y1 = abs(y[last] - yf), abs(y[last + 1] - yf)
    frac = (y0 - tol) / (y0 - y1) if y0 != y1 else 1.0
    return float(t[last] + frac * (t[last + 1] - t[last]) - t0)


def yaw_gain(
    t,
    yaw_rate,
    *,
    onset_s: float,
    method: str = "rise",
    window_s: float = 0.2,
    smooth_s: float = 0.05,
) -> float:
    """Seed-003 yaw gain (ヨーゲイン): the yaw angular acceleration after the step steer.

    The seed does not define how the number is taken from a trace; its §3 speaks of the *rise*
    of the yaw rate (ヨーレートの立ち上がり). Methods:

    * ``rise`` (default): least-squares slope of the yaw rate while it rises from 10 % to 90 % of
      its final value (the standard rise rate; a linear estimator, so sensor noise does not bias
      it);
    * ``slope``: least-squares slope over ``window_s`` after the onset;
    * ``peak``: the largest yaw acceleration (Savitzky–Golay derivative over ``smooth_s``);
      biased upwards by noise on measured traces.

    In this linear model all three grow in proportion to the steering rate; the seed's measured
    eq. 7 (a ln α_v + b) is concave, which a linear-tyre model cannot reproduce, so gains are
    compared at the reference rate only.

    Parameters
    ----------
    t, yaw_rate : array_like
        Time [s] and yaw rate [any unit/s] (uniformly sampled).
    onset_s : float
        Steering onset [s].
    method : {"rise", "slope", "peak"}
    window_s, smooth_s : float
        Slope window and smoothing window [s].

    Returns
    -------
    float
        Yaw acceleration [yaw-rate unit / s], with the sign of the response.
    """
    from scipy.signal import savgol_filter

    t = np.asarray(t, float)
    r = np.asarray(yaw_rate, float)
    ok = np.isfinite(r) & np.isfinite(t)
    t, r = t[ok], r[ok]
    if method == "slope":
        m = (t >= onset_s) & (t <= onset_s + window_s)
        if m.sum() < 3:
            raise InputError(
                f"yaw_gain: fewer than 3 samples in {window_s} s after onset {onset_s} s"
            )
        return float(np.polyfit(t[m], r[m], 1)[0])
    dt = sample_step(t, source="yaw_gain: step trace")
    n = max(5, round(smooth_s / dt) | 1)
    if r.size < 2 * n + 2:
        raise InputError("yaw_gain: trace shorter than the smoothing window")
    if method == "peak":
        d = savgol_filter(r, n, 2, deriv=1, delta=dt)
        m = t >= onset_s
        return float(d[m][int(np.argmax(np.abs(d[m])))])
    if method != "rise":
        raise InputError(f"yaw_gain: method={method!r}; use 'rise', 'slope' or 'peak'")
    sm = savgol_filter(r, n, 2)
    r0 = float(np.median(r[t < onset_s])) if np.any(t < onset_s) else float(sm[0])
    rf = float(np.mean(sm[-max(3, sm.size // 10) :]))
    span = rf - r0
    if span == 0:
        raise InputError("yaw_gain: the yaw rate does not change after the onset")
    rel = (sm - r0) / span
    after = t >= onset_s
    i10 = int(np.argmax(after & (rel >= 0.1)))
    i90 = int(np.argmax(after & (rel >= 0.9)))
    if not (rel[i90] >= 0.9 and i90 > i10 + 2):
        raise InputError(
            "yaw_gain: the yaw rate does not rise to 90 % of its final value; "
            "record the step until the yaw rate is steady"
        )
    return float(np.polyfit(t[i10 : i90 + 1], r[i10 : i90 + 1], 1)[0])


def release_onset(t, angle, *, run: int = 10) -> float:
    """Time of the release in a measured hands-off trace [s].

    The angle is held before the release; the release is the last sample before the angle
    leaves its held value for good (``run`` samples in a row outside max(2 % of the held value,
    5 × the noise of the hold)), so a noise spike does not count.

    Parameters
    ----------
    t : array_like
        Time [s].
    angle : array_like
        Steering angle [any angle unit].
    run : int
        Samples in a row that must lie outside the hold band.

    Returns
    -------
    float
        Release time [s].
    """
    t = np.asarray(t, float)
    y = np.asarray(angle, float)
    head = y[: max(5, y.size // 20)]
    hold = float(np.median(head))
    noise = 1.4826 * float(np.median(np.abs(np.diff(head) - np.median(np.diff(head))))) / 1.4142
    thr = max(0.02 * abs(hold), 5.0 * noise)
    away = np.abs(y - hold) > thr
    left = np.convolve(away.astype(int), np.ones(run, int), "valid") == run
    if not left.any():
        raise InputError("release trace: the steering angle never leaves its held value")
    return float(t[max(int(np.flatnonzero(left)[0]) - 1, 0)])


def release_settling_time(
    t, angle, *, reference: str = "initial", band: float = 0.05, release_s: float | None = None
) -> float:
    """Settling time of a measured release trace (seed 003 §4.1).

    Parameters
    ----------
    t : array_like
        Time [s].
    angle : array_like
        Steering angle [any angle unit].
    reference : {"initial", "converged"}
        Settling band reference (see :func:`settling_time`).
    band : float
        Relative band [-].
    release_s : float, optional
        Release time [s]; detected with :func:`release_onset` when not given.

    Returns
    -------
    float
        Settling time [s].
    """
    t = np.asarray(t, float)
    y = np.asarray(angle, float)
    dt = sample_step(t, source="release trace")
    if release_s is None:
        release_s = release_onset(t, y)
    # sensor noise near the band edge delays "the last time outside": smooth over ~50 ms first
    n = round(0.05 / dt) | 1
    if n >= 5 and y.size > 2 * n:
        from scipy.signal import savgol_filter

        y = savgol_filter(y, n, 2)
    return settling_time(t, y, reference=reference, band=band, release_s=release_s)


def step_metrics(t, steer_angle, yaw_rate, *, method: str = "rise") -> dict[str, float]:
    """Steering rate (mean over the ramp, 10–90 % of the stopper angle) and yaw gain of a
    measured step-steer trace (any consistent angle units, e.g. deg and deg/s).

    Parameters
    ----------
    t : array_like
        Time [s].
    steer_angle : array_like
        Steering angle [any angle unit].
    yaw_rate : array_like
        Yaw rate [the angle unit per s].
    method : str
        Yaw-gain definition: ``rise``, ``slope`` or ``peak``.
    """
    t = np.asarray(t, float)
    a = np.asarray(steer_angle, float)
    r = np.asarray(yaw_rate, float)
    sample_step(t, source="step trace")  # the ramp's rate divides by a time difference
    a0 = float(np.median(a[: max(3, a.size // 20)]))
    span = float(np.max(np.abs(a - a0)))
    if span <= 0:
        raise InputError("step trace: the steering angle does not move")
    rel = np.abs(a - a0) / span
    i10 = int(np.argmax(rel >= 0.1))
    i90 = int(np.argmax(rel >= 0.9))
    if i90 <= i10:
        raise InputError("step trace: cannot find the steering ramp")
    rate = abs(a[i90] - a[i10]) / (t[i90] - t[i10])
    onset = float(t[i10] - 0.1 * span / rate)
    return {
        "steer_rate": float(rate),
        "onset_s": onset,
        "yaw_gain": abs(yaw_gain(t, r, onset_s=onset, method=method)),
    }
