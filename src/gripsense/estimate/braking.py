"""Friction from straight-line braking with locked wheels: μ = a/g (thesis ch. 8, eq. 1.3).

Estimator (docs/physics.md §7), per braking event in an accelerometer trace:

1. **Bias**: the median of the cruise before the event (the 1.5 s ending 0.5 s before onset,
   or the first second of the trace) is subtracted: mounting tilt and sensor offset.
2. **Detection** (on a 0.2 s running median, used for detection only): threshold
   max(0.05 g, 0.5 × |5th percentile|); onset = first sample below −threshold, end = first
   later sample above it. The stop rebound or pitch-back spike ends the event.
3. **Plateau** [onset + 0.3 s, end − 0.2 s] (no pressure build-up / lock transient, no stop
   jerk): μ = −median/g, spread 1.4826·MAD/g; also the plateau's length and slope (rubber
   friction varies with sliding speed).
4. **Pitch-free form** (3 axes on a level road): μ = √(|f|² − g²)/g with |f| scaled to g at
   rest — a nose-down dive adds −g sin p to the x axis and biases the 1-axis form.

a/g is the sliding friction averaged over the wheels, including ~0.01–0.02 g of drag; it is
lower than peak μ. Road grade: run both directions and average.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pandas as pd

from gripsense._arrays import sample_step
from gripsense.constants import G0
from gripsense.errors import InputError

__all__ = ["EVENT_COLUMNS", "BrakingResult", "estimate_braking"]

EVENT_COLUMNS = [
    "t_onset",
    "t_end",
    "plateau_s",
    "mu",
    "mu_spread",
    "mu_3axis",
    "slope_per_s",
    "bias_mps2",
    "n",
]
"""Columns of :attr:`BrakingResult.events`."""


@dataclass
class BrakingResult:
    """Braking events and their friction.

    Attributes
    ----------
    events : pandas.DataFrame
        Per event: ``t_onset``, ``t_end``, ``plateau_s``, ``mu`` (1-axis), ``mu_spread``
        (1.4826·MAD/g), ``mu_3axis`` (pitch-free, NaN without z), ``slope_per_s`` (dμ/dt on
        the plateau), ``bias_mps2``, ``n``.
    mu : float
        Mean of the events' μ.
    mu_std : float
        Standard deviation between events (NaN for one event).
    """

    events: pd.DataFrame
    mu: float
    mu_std: float

    def explain(self) -> str:
        """One line: μ of the events and their spread."""
        n = len(self.events)
        spread = f" ± {self.mu_std:.3f} (SD of {n} events)" if n > 1 else ""
        return f"locked-wheel braking: μ = {self.mu:.3f}{spread}"


def _running_median(x: np.ndarray, n: int) -> np.ndarray:
    return pd.Series(x).rolling(max(n, 1), center=True, min_periods=1).median().to_numpy()


def estimate_braking(
    acc: pd.DataFrame, *, clip_g: float | None = None, source: str = "trace"
) -> BrakingResult:
    """μ from every locked-wheel braking event of an accelerometer trace (see module docs).

    Parameters
    ----------
    acc : pandas.DataFrame
        ``t_s``, ``ax`` [m/s^2] (``ay``, ``az`` optional), e.g. from
        :func:`gripsense.io.sensors.accel.read_accel_csv`.
    clip_g : float or None
        Sensor full scale [g]: a plateau reaching it is reported as clipped. Default: the
        largest |value| when several samples sit exactly on it.
    source : str
        Name used in error messages.

    Raises
    ------
    InputError
        No braking event; a clipped sensor; values that cannot be a deceleration in m/s²
        (wrong units).
    """
    t = acc["t_s"].to_numpy(float)
    ax = acc["ax"].to_numpy(float)
    if t.size < 20:
        raise InputError(f"{source}: {t.size} samples; a braking test needs a few seconds")
    dt = sample_step(t, source=source)  # a clear error for repeated or backward times
    n02 = max(round(0.2 / dt), 1)
    # wrong units: a braking car does not exceed ~1.5 g; m/s² read as g looks like 9 g
    plausible = 2.0 * G0
    if np.nanpercentile(np.abs(ax - np.nanmedian(ax)), 99) > 3 * plausible:
        raise InputError(
            f"{source}: accelerations of {np.nanmax(np.abs(ax)) / G0:.1f} g — not a "
            "braking car; are the values in m/s² read as g? (--units mps2)"
        )
    sm = _running_median(ax - np.median(ax[: max(int(1.0 / dt), 1)]), n02)
    thr = max(0.05 * G0, 0.5 * abs(np.percentile(sm, 5)))
    below = sm < -thr
    events = []
    k = 0
    while k < t.size:
        if not below[k]:
            k += 1
            continue
        on = k
        while k < t.size and below[k]:
            k += 1
        end = min(k, t.size - 1)
        events.append((on, end))
    rows = []
    full = clip_g * G0 if clip_g else None
    if full is None:
        amax = np.max(np.abs(ax))
        if np.sum(np.abs(ax) == amax) >= 3:
            full = amax
    for on, end in events:
        t_on, t_end = t[on], t[end]
        pre = (t >= t_on - 2.0) & (t < t_on - 0.5)
        bias = (
            float(np.median(ax[pre]))
            if pre.sum() >= 5
            else float(np.median(ax[: max(int(1.0 / dt), 1)]))
        )
        sel = (t >= t_on + 0.3) & (t <= t_end - 0.2)
        if sel.sum() < 5:
            continue  # a spike, not a plateau
        a = ax[sel] - bias
        if full is not None and np.mean(np.abs(ax[sel]) >= full * 0.999) > 0.05:
            raise InputError(
                f"{source}: the sensor is clipped during the braking at "
                f"{t_on:.1f} s (plateau at {full / G0:.2f} g full scale); use a "
                "larger range"
            )
        mu = -float(np.median(a)) / G0
        if mu > 1.6:
            raise InputError(
                f"{source}: a deceleration plateau of {mu:.1f} g at {t_on:.1f} s is "
                "not a car; check --units (m/s² or g) and the column mapping"
            )
        mad = float(np.median(np.abs(a - np.median(a))))
        slope = float(np.polyfit(t[sel], -a / G0, 1)[0]) if sel.sum() > 2 else np.nan
        mu3 = np.nan
        if "az" in acc and np.isfinite(acc["az"]).all() and "ay" in acc:
            f = np.sqrt(acc["ax"] ** 2 + acc["ay"].fillna(0) ** 2 + acc["az"] ** 2).to_numpy()
            rest = f[pre] if pre.sum() >= 5 else f[: max(int(1.0 / dt), 1)]
            scale = G0 / np.median(rest)  # |f| = g at rest
            fs = f[sel] * scale
            mu3 = float(np.median(np.sqrt(np.clip(fs**2 - G0**2, 0, None)))) / G0
        rows.append(
            {
                "t_onset": t_on,
                "t_end": t_end,
                "plateau_s": float(t[sel][-1] - t[sel][0]),
                "mu": mu,
                "mu_spread": 1.4826 * mad / G0,
                "mu_3axis": mu3,
                "slope_per_s": slope,
                "bias_mps2": bias,
                "n": int(sel.sum()),
            }
        )
    if not rows:
        raise InputError(
            f"{source}: no braking event found (no deceleration below −"
            f"{thr / G0:.2f} g lasting > 0.5 s); is the x axis forward "
            "(--ax-sign -1 for a backwards sensor)?"
        )
    ev = pd.DataFrame(rows, columns=EVENT_COLUMNS)
    return BrakingResult(
        events=ev,
        mu=float(ev["mu"].mean()),
        mu_std=float(ev["mu"].std()) if len(ev) > 1 else np.nan,
    )
