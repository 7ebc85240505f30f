"""Steering-system identification of seed 003: C_s from settling times, k_s from the yaw gain.

docs/physics.md §9.3–9.4. The model is :mod:`gripsense.physics.steering_system`. Procedure:

1. C_s: simulate the hands-off release for a grid of C_s at the current k_s, keep the
   over-damped branch (the measured traces are over-damped), invert the settling-time curve at
   the mean measured time; the interval is the inversion of mean ± 1 sample SD (the seed's "±").
2. k_s: simulate the step steer at the reference steering rate for 0 < k_s ≤ k_s1, invert the
   yaw-gain curve at the measured (rate-normalised) yaw gain; k_s2 = k_s k_s1/(k_s1 − k_s)
   (eq. 6). Interval: inversion of gain ± 1.96σ (σ of the eq.-7 prediction at the reference
   rate; no interval from a single summary number). A gain above the curve's maximum
   (k_s = k_s1) means the data say "stiffer than k_s1": k_s2 is then not determined and
   flagged, never reported as a number.
3. Alternate 1 and 2 to a fixed point (the seed stops after one pass and notes that iterating
   would refine the values); convergence is reported.

Yaw-gain normalisation: measured gains at varying steering rates α_v are fitted with the
corrected eq. 7, dr/dt = a ln(α_v) + b (docs/physics.md §9.3: the printed linear form cannot
reproduce
Table 4.3), and evaluated at the reference rate (70 deg/s).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from gripsense.config import SteeringCar
from gripsense.errors import InputError
from gripsense.identify.steering_metrics import settling_time, yaw_gain
from gripsense.physics.steering_system import simulate_release, simulate_step

__all__ = [
    "CsResult",
    "KsResult",
    "SteeringIdentification",
    "identify_cs",
    "identify_ks",
    "identify_steering",
    "normalise_yaw_gain",
    "settling_curve",
    "tyre_lateral_stiffness",
    "yaw_gain_curve",
]


@dataclass
class CsResult:
    """C_s from settling times (N·m·s/rad); NaN bounds when the band leaves the curve.

    Attributes
    ----------
    cs : float
        C_s [N m s/rad] (NaN when not identified).
    low : float
        Lower end (inversion of mean + SD) [N m s/rad].
    high : float
        Upper end [N m s/rad].
    t_mean_s : float
        Mean measured settling time [s].
    t_sd_s : float
        Its sample standard deviation [s].
    curve_cs : numpy.ndarray
        C_s grid of the simulated curve [N m s/rad].
    curve_t_s : numpy.ndarray
        Simulated settling times [s].
    overdamped : numpy.ndarray
        Whether each grid point's release is over-damped.
    flag : str
        ``ok`` or why C_s is not identified.
    """

    cs: float
    low: float
    high: float
    t_mean_s: float
    t_sd_s: float
    curve_cs: np.ndarray
    curve_t_s: np.ndarray
    overdamped: np.ndarray
    flag: str = "ok"


@dataclass
class KsResult:
    """k_s and k_s2 from the yaw gain (N·m/rad); ``flag`` says when k_s2 is not determined.

    Attributes
    ----------
    ks : float
        k_s [N m/rad].
    ks2 : float
        k_s2 from eq. 6 [N m/rad].
    low : float
        Lower end of k_s (gain − 1.96σ) [N m/rad].
    high : float
        Upper end of k_s [N m/rad].
    ks2_low : float
        Lower end of k_s2 [N m/rad].
    ks2_high : float
        Upper end of k_s2 [N m/rad].
    gain_dps2 : float
        Measured (rate-normalised) yaw gain [deg/s^2].
    curve_ks : numpy.ndarray
        k_s grid of the simulated curve [N m/rad].
    curve_gain_dps2 : numpy.ndarray
        Simulated yaw gains [deg/s^2].
    flag : str
        ``ok`` or why k_s2 is not determined.
    """

    ks: float
    ks2: float
    low: float
    high: float
    ks2_low: float
    ks2_high: float
    gain_dps2: float
    curve_ks: np.ndarray
    curve_gain_dps2: np.ndarray
    flag: str = "ok"


@dataclass
class SteeringIdentification:
    """Result of :func:`identify_steering`.

    Attributes
    ----------
    cs : CsResult
        Final C_s.
    ks : KsResult or None
        Final k_s (None without a yaw gain).
    history : list of dict
        C_s and k_s after each step of the alternation.
    converged : bool
        Whether the alternation reached a fixed point.
    first_pass : dict
        The seed's single pass, for comparison.
    car : SteeringCar or None
        The car with the identified values.
    cs_rigid : CsResult or None
        The first C_s step (k_s = k_s1, seed Fig. 4.2).
    """

    cs: CsResult
    ks: KsResult | None
    history: list[dict] = field(default_factory=list)
    converged: bool = False
    first_pass: dict = field(default_factory=dict)
    car: SteeringCar | None = None
    cs_rigid: CsResult | None = None  #: the first C_s step (k_s = k_s1, seed Fig. 4.2)

    def to_dict(self) -> dict:
        """JSON-ready summary (NaN as None)."""

        def f(x):
            return None if x is None or (isinstance(x, float) and not math.isfinite(x)) else x

        out = {
            "cs_Nms_per_rad": f(self.cs.cs),
            "cs_low": f(self.cs.low),
            "cs_high": f(self.cs.high),
            "cs_flag": self.cs.flag,
            "settling_mean_s": self.cs.t_mean_s,
            "settling_sd_s": self.cs.t_sd_s,
            "converged": self.converged,
            "iterations": len(self.history),
            "history": [{k: f(v) for k, v in h.items()} for h in self.history],
            "first_pass": {k: f(v) for k, v in self.first_pass.items()},
        }
        if self.ks is not None:
            out.update(
                {
                    "ks_Nm_per_rad": f(self.ks.ks),
                    "ks_low": f(self.ks.low),
                    "ks_high": f(self.ks.high),
                    "ks2_Nm_per_rad": f(self.ks.ks2),
                    "ks2_low": f(self.ks.ks2_low),
                    "ks2_high": f(self.ks.ks2_high),
                    "ks_flag": self.ks.flag,
                    "yaw_gain_dps2": self.ks.gain_dps2,
                }
            )
        return out


# ---------------------------------------------------------------------- measurements
def tyre_lateral_stiffness(force_N, deflection_m) -> tuple[float, float]:
    """k_y from measured lateral force and tyre deflection (seed §4.1): slope through the
    origin by least squares, and its 1σ standard error.

    Parameters
    ----------
    force_N : array_like
        Lateral force per tyre [N] (e.g. m·v²/R share on a steady circle).
    deflection_m : array_like
        Measured lateral deflection of the tyre [m].

    Returns
    -------
    k_y, sigma : float
        [N/m].
    """
    f = np.asarray(force_N, float).ravel()
    d = np.asarray(deflection_m, float).ravel()
    ok = np.isfinite(f) & np.isfinite(d)
    f, d = f[ok], d[ok]
    if f.size < 2 or not np.any(d != 0):
        raise InputError(
            "tyre_lateral_stiffness: need at least 2 (force, deflection) pairs with "
            "non-zero deflection"
        )
    k = float(d @ f / (d @ d))
    res = f - k * d
    sig = float(np.sqrt(res @ res / max(f.size - 1, 1) / (d @ d)))
    return k, sig


def normalise_yaw_gain(
    steer_rates_dps, gains_dps2, reference_dps: float = 70.0, law: str = "ln"
) -> dict[str, Any]:
    """Fit the yaw gain against the steering rate and evaluate it at ``reference_dps``.

    ``law="ln"``: the corrected eq. 7, gain = a ln(α_v) + b (docs/physics.md §9.3; fits the seed's
    measurements). ``law="linear"``: gain = a α_v + b (the printed eq. 7; also what a linear
    model produces). With a single measurement the gain is returned as is.

    Parameters
    ----------
    steer_rates_dps : array_like
        Steering-wheel rates of the tests [deg/s].
    gains_dps2 : array_like
        Their yaw gains [deg/s^2].
    reference_dps : float
        Rate to evaluate at [deg/s].
    law : str
        ``ln`` (corrected eq. 7) or ``linear``.

    Returns
    -------
    dict
        ``gain`` [deg/s^2] at the reference rate, ``sigma`` (1σ of that prediction, NaN with < 3
        points), ``a``, ``b``, ``n``, ``law``.
    """
    x = np.asarray(steer_rates_dps, float).ravel()
    y = np.asarray(gains_dps2, float).ravel()
    if x.size != y.size or x.size == 0:
        raise InputError("normalise_yaw_gain: give as many steering rates as yaw gains")
    if np.any(x <= 0):
        raise InputError("normalise_yaw_gain: steering rates must be > 0 deg/s")
    if law not in ("ln", "linear"):
        raise InputError(f"normalise_yaw_gain: law={law!r}; use 'ln' or 'linear'")
    out = {
        "gain": float("nan"),
        "sigma": float("nan"),
        "a": float("nan"),
        "b": float("nan"),
        "n": int(x.size),
        "law": law,
    }
    if x.size == 1:
        out["gain"] = float(y[0])
        return out
    lx = np.log(x) if law == "ln" else x
    x0 = math.log(reference_dps) if law == "ln" else reference_dps
    if np.ptp(lx) == 0:
        out.update(gain=float(y.mean()), sigma=float(y.std(ddof=1) / np.sqrt(y.size)))
        return out
    a, b = np.polyfit(lx, y, 1)
    out.update(gain=float(a * x0 + b), a=float(a), b=float(b))
    if x.size >= 3:
        res = y - (a * lx + b)
        s2 = res @ res / (x.size - 2)
        sxx = ((lx - lx.mean()) ** 2).sum()
        out["sigma"] = float(np.sqrt(s2 * (1 / x.size + (x0 - lx.mean()) ** 2 / sxx)))
    return out


# ---------------------------------------------------------------------- curves
def settling_curve(
    car: SteeringCar,
    cs_grid,
    *,
    alpha0_rad: float,
    reference: str = "initial",
    duration_s: float = 6.0,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Settling time and over-damping per C_s (seed Figs. 4.2/4.5).

    Returns
    -------
    cs, t_settle [s], overdamped (no overshoot through the final angle)
    """
    cs_grid = np.asarray(cs_grid, float)
    ts = np.empty(cs_grid.size)
    over = np.empty(cs_grid.size, bool)
    for i, cs in enumerate(cs_grid):
        r = simulate_release(
            car.with_cs(cs), alpha0_rad=alpha0_rad, duration_s=duration_s, dt_s=2e-3
        )
        a = r["alpha_rad"]
        ts[i] = settling_time(r["t_s"], a, reference=reference, final=0.0)
        over[i] = bool(np.all(a * np.sign(alpha0_rad) >= -1e-3 * abs(alpha0_rad)))
    return cs_grid, ts, over


def yaw_gain_curve(
    car: SteeringCar, ks_grid, *, steer_rate_rad_s: float, stop_rad: float, method: str = "rise"
) -> tuple[np.ndarray, np.ndarray]:
    """Yaw gain [deg/s^2] per total stiffness k_s (seed Fig. 4.4)."""
    ks_grid = np.asarray(ks_grid, float)
    g = np.empty(ks_grid.size)
    dur = 0.1 + stop_rad / steer_rate_rad_s + 2.5  # until the yaw rate is steady
    for i, ks in enumerate(ks_grid):
        s = simulate_step(
            car.with_ks(ks),
            steer_rate_rad_s=steer_rate_rad_s,
            stop_rad=stop_rad,
            duration_s=dur,
            dt_s=1e-3,
        )
        g[i] = np.rad2deg(
            yaw_gain(s["t_s"], s["yaw_rate_rps"], onset_s=s["onset_s"], method=method)
        )
    return ks_grid, g


def _invert(x, y, target, f=None):
    """X where the monotone-increasing y(x) equals target (NaN outside the curve); with the
    model ``f`` the grid bracket is refined by Brent's method (no interpolation bias).
    """
    if not np.isfinite(target) or not (np.nanmin(y) <= target <= np.nanmax(y)):
        return float("nan")
    guess = float(np.interp(target, y, x))
    if f is None:
        return guess
    from scipy.optimize import brentq

    j = int(np.clip(np.searchsorted(y, target), 1, y.size - 1))
    lo, hi = x[j - 1], x[j]
    try:
        return float(brentq(lambda v: f(v) - target, lo, hi, xtol=1e-6 * hi, rtol=1e-8))
    except ValueError:
        return guess


def identify_cs(
    car: SteeringCar,
    settling_times_s,
    *,
    alpha0_rad: float,
    reference: str = "initial",
    cs_grid=None,
) -> CsResult:
    """C_s from measured settling times at the car's current k_s (step 1 above).

    Parameters
    ----------
    car : SteeringCar
        The car (its current k_s is used).
    settling_times_s : array_like
        Measured settling times [s].
    alpha0_rad : float
        Kingpin angle held before the release [rad].
    reference : str
        Settling band reference: ``initial`` or ``converged``.
    cs_grid : array_like, optional
        C_s values to simulate [N m s/rad].
    """
    t = np.asarray(settling_times_s, float)
    t = t[np.isfinite(t)]
    if t.size == 0:
        raise InputError("identify_cs: no finite settling time")
    tm = float(t.mean())
    sd = float(t.std(ddof=1)) if t.size > 1 else 0.0
    grid = np.geomspace(2.0, 800.0, 48) if cs_grid is None else np.asarray(cs_grid, float)
    dur = max(6.0, 4.0 * float(t.max()))
    cs, ts, over = settling_curve(
        car, grid, alpha0_rad=alpha0_rad, reference=reference, duration_s=dur
    )
    ok = over & np.isfinite(ts)
    if ok.sum() < 2:
        return CsResult(
            float("nan"),
            float("nan"),
            float("nan"),
            tm,
            sd,
            cs,
            ts,
            over,
            "no over-damped branch in the C_s grid",
        )
    # the over-damped branch is the upper, contiguous part of the grid; keep where it increases
    first = int(np.flatnonzero(ok)[0])
    br = np.arange(first, cs.size)
    br = br[ok[br]]
    xb, yb = cs[br], ts[br]
    keep = np.concatenate([[True], np.diff(yb) > 0])
    xb, yb = xb[keep], yb[keep]

    def model(c):
        r = simulate_release(car.with_cs(c), alpha0_rad=alpha0_rad, duration_s=dur, dt_s=2e-3)
        return settling_time(r["t_s"], r["alpha_rad"], reference=reference, final=0.0)

    val = _invert(xb, yb, tm, model)
    lo, hi = _invert(xb, yb, tm - sd, model), _invert(xb, yb, tm + sd, model)
    flag = "ok"
    if not np.isfinite(val):
        flag = (
            f"measured settling time {tm:.3f} s outside the over-damped curve "
            f"({yb.min():.3f}–{yb.max():.3f} s)"
        )
    elif not (np.isfinite(lo) and np.isfinite(hi)):
        flag = "interval leaves the curve"
    return CsResult(val, lo, hi, tm, sd, cs, ts, over, flag)


def identify_ks(
    car: SteeringCar,
    gain_dps2: float,
    *,
    steer_rate_rad_s: float,
    stop_rad: float,
    gain_sigma_dps2: float = float("nan"),
    method: str = "rise",
    n_grid: int = 40,
) -> KsResult:
    """k_s (and k_s2) from the rate-normalised yaw gain at the car's current C_s (step 2).

    Parameters
    ----------
    car : SteeringCar
        The car (its current C_s is used).
    gain_dps2 : float
        Measured yaw gain at the reference rate [deg/s^2].
    steer_rate_rad_s : float
        Kingpin steering rate of the reference [rad/s].
    stop_rad : float
        Kingpin angle of the stopper [rad].
    gain_sigma_dps2 : float
        1σ of the gain [deg/s^2] (NaN: no interval).
    method : str
        Yaw-gain definition: ``rise``, ``slope`` or ``peak``.
    n_grid : int
        Number of k_s values simulated.
    """
    k1 = car.ks1_Nm_per_rad
    grid = np.linspace(k1 / n_grid, k1, n_grid)
    ks, g = yaw_gain_curve(
        car, grid, steer_rate_rad_s=steer_rate_rad_s, stop_rad=stop_rad, method=method
    )
    inc = np.concatenate([[True], np.diff(g) > 0])
    ks_m, g_m = ks[inc], g[inc]

    def ks2_of(k):
        if not np.isfinite(k):
            return float("nan")
        return math.inf if k >= k1 * (1 - 1e-9) else k * k1 / (k1 - k)

    def model(k):
        return float(
            yaw_gain_curve(
                car, [k], steer_rate_rad_s=steer_rate_rad_s, stop_rad=stop_rad, method=method
            )[1][0]
        )

    val = _invert(ks_m, g_m, gain_dps2, model)
    s = 1.96 * gain_sigma_dps2 if np.isfinite(gain_sigma_dps2) else 0.0  # 95 % interval
    # a single summary gain has no spread: no interval rather than a zero-width one
    lo = _invert(ks_m, g_m, gain_dps2 - s, model) if s else float("nan")
    hi = _invert(ks_m, g_m, gain_dps2 + s, model) if s else float("nan")
    flag = "ok"
    if not np.isfinite(val):
        if gain_dps2 > g_m.max():
            flag = (
                f"yaw gain {gain_dps2:.1f} deg/s² above the model's {g_m.max():.1f} at "
                f"k_s = k_s1: k_s2 not determined (the model, with these parameters, cannot "
                "be this responsive)"
            )
        else:
            flag = (
                f"yaw gain {gain_dps2:.1f} deg/s² below the curve ({g_m.min():.1f}): "
                "k_s below the grid"
            )
    return KsResult(val, ks2_of(val), lo, hi, ks2_of(lo), ks2_of(hi), gain_dps2, ks, g, flag)


def identify_steering(
    car: SteeringCar,
    settling_times_s,
    *,
    alpha0_rad: float,
    yaw_gain_dps2: float | None = None,
    yaw_gain_sigma_dps2: float = float("nan"),
    steer_rate_rad_s: float | None = None,
    stop_rad: float | None = None,
    reference: str = "initial",
    max_iter: int = 15,
    rtol: float = 1e-3,
    method: str = "rise",
) -> SteeringIdentification:
    """Alternate C_s and k_s identification to a fixed point (seed 003 §4, iterated).

    Parameters
    ----------
    car : SteeringCar
        Known parameters; its k_s2 is the start (``inf``: rigid, as the seed's first pass).
    settling_times_s : array_like
        Measured settling times [s].
    alpha0_rad : float
        Kingpin-referred angle held before the release [rad].
    yaw_gain_dps2, yaw_gain_sigma_dps2 : float, optional
        Rate-normalised yaw gain and its 1σ [deg/s^2]; without it only C_s is identified.
    steer_rate_rad_s, stop_rad : float, optional
        Kingpin-referred reference steering rate and stopper angle of the step test.
    reference : str
        Settling-time definition (:func:`gripsense.physics.steering_system.settling_time`).
    max_iter, rtol : int, float
        Fixed-point iteration limit and relative tolerance on C_s and k_s.
    method : str
        Yaw-gain definition: ``rise``, ``slope`` or ``peak``.

    Returns
    -------
    SteeringIdentification
    """
    history: list[dict] = []
    cur = car
    cs_res = identify_cs(cur, settling_times_s, alpha0_rad=alpha0_rad, reference=reference)
    history.append({"step": "C_s", "cs": cs_res.cs, "ks": cur.ks})
    cs_first = cs_res
    if yaw_gain_dps2 is None:
        return SteeringIdentification(
            cs_res, None, history, True, {"cs_rigid": cs_res.cs}, cur.with_cs(cs_res.cs), cs_first
        )
    if steer_rate_rad_s is None or stop_rad is None:
        raise InputError("identify_steering: the yaw gain needs steer_rate_rad_s and stop_rad")
    first: dict = {"cs_rigid": cs_res.cs}
    ks_res = None
    converged = False
    for it in range(max_iter):
        if not np.isfinite(cs_res.cs):
            break
        cur = cur.with_cs(cs_res.cs)
        ks_res = identify_ks(
            cur,
            yaw_gain_dps2,
            steer_rate_rad_s=steer_rate_rad_s,
            stop_rad=stop_rad,
            gain_sigma_dps2=yaw_gain_sigma_dps2,
            method=method,
        )
        history.append({"step": "k_s", "cs": cs_res.cs, "ks": ks_res.ks, "ks2": ks_res.ks2})
        if it == 0:
            first.update({"ks": ks_res.ks, "ks2": ks_res.ks2})
        if not np.isfinite(ks_res.ks):
            break
        prev_cs = cs_res.cs
        cur = cur.with_ks(ks_res.ks)
        cs_res = identify_cs(cur, settling_times_s, alpha0_rad=alpha0_rad, reference=reference)
        history.append({"step": "C_s", "cs": cs_res.cs, "ks": ks_res.ks, "ks2": ks_res.ks2})
        if it == 0:
            first["cs_corrected"] = cs_res.cs
        if np.isfinite(cs_res.cs) and abs(cs_res.cs - prev_cs) <= rtol * abs(prev_cs):
            converged = True
            break
    final_car = cur.with_cs(cs_res.cs) if np.isfinite(cs_res.cs) else cur
    return SteeringIdentification(cs_res, ks_res, history, converged, first, final_car, cs_first)
