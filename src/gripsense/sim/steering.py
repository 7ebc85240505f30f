"""Vehicle + steering-system model of seed 003 as a linear descriptor system, and its two tests.

PHYSICS.md §9 (seed ``003_fdc8abf9dc5f3e6a.txt`` eqs. 1–6, errors fixed):

* (1) m V (β̇ + r) = Y_f1 + Y_f2 + Y_r1 + Y_r2
* (2) I ṙ = l_f (Y_f1 + Y_f2) − l_r (Y_r1 + Y_r2)
* (3) I_s (δ̈ + ṙ) + C_s δ̇ − k_s (α − δ) = −ξ (Y_f1 + Y_f2)  (restoring aligning moment of a
  positive trail ξ; the seed's figure with the sign convention is missing — flagged in §9.1)
* (4) (K_i / (k_y V)) Ẏ_i + Y_i = K_i β_i, K_i in N/rad, β_f = δ − β − l_f r/V, β_r = −β + l_r r/V
* (5) I_h α̈ + C_h α̇ + k_s (α − δ) = T_h  (acts on α; the seed prints δ, which makes the
  hands-off system singular)
* (6) k_s = k_s1 k_s2 / (k_s1 + k_s2)

α is the steering angle referred to the kingpin axis (steering-wheel angle / steering ratio N);
steering-wheel inertia and damping are referred to the kingpin with N² (``SteeringCar``
takes them at the steering wheel). r is the yaw rate (the seed's γ). ISO signs: left positive.

Test (i) *step steer*: α ramps at a constant rate to a stopper at constant speed, states
[β, r, δ, δ̇, Y_f1, Y_f2, Y_r1, Y_r2]. Test (ii) *hands-off release* from a steady turn: T_h = 0,
states [β, r, δ, δ̇, α, α̇, Y_f1, Y_f2, Y_r1, Y_r2]. M ẋ = A x + B u is regular
(det M = m I I_s I_h Π K_i / (V³ k_y⁴) ≠ 0, PHYSICS §9.2). Inputs are piecewise linear, so the
response is computed exactly on the sample grid (scipy ``lsim``, first-order hold).
"""

from __future__ import annotations

import math
import tomllib
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np
from scipy.signal import lsim

from gripsense.errors import InputError

__all__ = [
    "RELEASE_STATES",
    "STEP_STATES",
    "SteeringCar",
    "descriptor",
    "settling_time",
    "simulate_release",
    "simulate_step",
    "yaw_gain",
]

STEP_STATES = ("beta", "r", "delta", "delta_dot", "Y_f1", "Y_f2", "Y_r1", "Y_r2")
RELEASE_STATES = (
    "beta",
    "r",
    "delta",
    "delta_dot",
    "alpha",
    "alpha_dot",
    "Y_f1",
    "Y_f2",
    "Y_r1",
    "Y_r2",
)


@dataclass(frozen=True)
class SteeringCar:
    """Parameters of the seed-003 model (SI; kingpin-referred unless said otherwise).

    Attributes
    ----------
    mass_kg, yaw_inertia_kgm2 : float
        m, I.
    lf_m, lr_m : float
        CG to front and rear axle.
    speed_mps : float
        Constant forward speed V.
    kingpin_inertia_kgm2 : float
        I_s: both steered wheels and knuckles about their kingpins.
    kingpin_damping_Nms : float
        C_s: equivalent viscous friction about the kingpins [N·m·s/rad].
    ks1_Nm_per_rad : float
        k_s1: steering stiffness computable from drawings [N·m/rad].
    ks2_Nm_per_rad : float
        k_s2: the part that is not (joints, play); ``inf`` for rigid.
    trail_m : float
        ξ: kingpin-to-force-point distance (mechanical + pneumatic trail) per front wheel [m].
    cornering_stiffness_front_N_per_rad, cornering_stiffness_rear_N_per_rad : float
        K_i per tyre [N/rad] (the seed's "cornering power", per degree in its text).
    tyre_lateral_stiffness_N_per_m : float
        k_y: lateral stiffness of the tyre carcass [N/m]; relaxation length K_i/k_y.
    steering_ratio : float
        N = steering-wheel angle / kingpin angle.
    wheel_inertia_kgm2, wheel_damping_Nms : float
        Steering-wheel side inertia and damping at the steering wheel (the seed's C_h = 0.38).
    """

    mass_kg: float
    yaw_inertia_kgm2: float
    lf_m: float
    lr_m: float
    speed_mps: float
    kingpin_inertia_kgm2: float
    kingpin_damping_Nms: float
    ks1_Nm_per_rad: float
    ks2_Nm_per_rad: float
    trail_m: float
    cornering_stiffness_front_N_per_rad: float
    cornering_stiffness_rear_N_per_rad: float
    tyre_lateral_stiffness_N_per_m: float
    steering_ratio: float
    wheel_inertia_kgm2: float
    wheel_damping_Nms: float

    @property
    def ks(self) -> float:
        """Series stiffness k_s = k_s1 k_s2/(k_s1 + k_s2) (eq. 6) [N·m/rad]."""
        k1, k2 = self.ks1_Nm_per_rad, self.ks2_Nm_per_rad
        return k1 if math.isinf(k2) else k1 * k2 / (k1 + k2)

    @property
    def ih(self) -> float:
        """Steering-wheel inertia referred to the kingpin, I_sw N² [kg·m²]."""
        return self.wheel_inertia_kgm2 * self.steering_ratio**2

    @property
    def ch(self) -> float:
        """Steering-wheel damping referred to the kingpin, C_h N² [N·m·s/rad]."""
        return self.wheel_damping_Nms * self.steering_ratio**2

    def with_ks(self, ks: float) -> SteeringCar:
        """The same car with total stiffness ``ks`` (k_s2 from eq. 6; ``inf`` when ks ≥ k_s1)."""
        k1 = self.ks1_Nm_per_rad
        k2 = math.inf if ks >= k1 else ks * k1 / (k1 - ks)
        return replace(self, ks2_Nm_per_rad=k2)

    def with_cs(self, cs: float) -> SteeringCar:
        """The same car with kingpin damping ``cs``."""
        return replace(self, kingpin_damping_Nms=float(cs))

    @classmethod
    def from_toml(cls, path: str | Path) -> SteeringCar:
        """Read ``[car]``, ``[steering]``, ``[tyre]`` and ``[test]`` tables (see
        ``gripsense/data/of18_steering.toml``); errors name the file, table and key."""
        from gripsense.config import _Reader

        path = Path(path)
        try:
            doc = tomllib.loads(path.read_text(encoding="utf-8"))
        except FileNotFoundError:
            raise InputError(f"{path}: no such file") from None
        except tomllib.TOMLDecodeError as e:
            raise InputError(f"{path}: not valid TOML ({e})") from None
        r = _Reader(doc, str(path))
        car, st, ty, te = (r.table(n, True) for n in ("car", "steering", "tyre", "test"))
        ks2 = r.num(st, "steering", "ks2_Nm_per_rad", unit="N·m/rad", positive=True, required=False)
        return cls(
            mass_kg=r.num(car, "car", "mass_kg", unit="kg", positive=True),
            yaw_inertia_kgm2=r.num(car, "car", "yaw_inertia_kgm2", unit="kg·m²", positive=True),
            lf_m=r.num(car, "car", "lf_m", unit="m", positive=True),
            lr_m=r.num(car, "car", "lr_m", unit="m", positive=True),
            speed_mps=r.num(te, "test", "speed_mps", unit="m/s", positive=True),
            kingpin_inertia_kgm2=r.num(
                st, "steering", "kingpin_inertia_kgm2", unit="kg·m²", positive=True
            ),
            kingpin_damping_Nms=r.num(
                st,
                "steering",
                "kingpin_damping_Nms",
                unit="N·m·s/rad",
                positive=True,
                required=False,
            )
            or 50.0,
            ks1_Nm_per_rad=r.num(st, "steering", "ks1_Nm_per_rad", unit="N·m/rad", positive=True),
            ks2_Nm_per_rad=math.inf if ks2 is None else ks2,
            trail_m=r.num(st, "steering", "trail_m", unit="m", positive=True),
            cornering_stiffness_front_N_per_rad=r.num(
                ty, "tyre", "cornering_stiffness_front_N_per_rad", unit="N/rad", positive=True
            ),
            cornering_stiffness_rear_N_per_rad=r.num(
                ty, "tyre", "cornering_stiffness_rear_N_per_rad", unit="N/rad", positive=True
            ),
            tyre_lateral_stiffness_N_per_m=r.num(
                ty, "tyre", "lateral_stiffness_N_per_m", unit="N/m", positive=True
            ),
            steering_ratio=r.num(st, "steering", "steering_ratio", unit="-", positive=True),
            wheel_inertia_kgm2=r.num(
                st, "steering", "wheel_inertia_kgm2", unit="kg·m²", positive=True
            ),
            wheel_damping_Nms=r.num(
                st, "steering", "wheel_damping_Nms", unit="N·m·s/rad", positive=True
            ),
        )


def descriptor(car: SteeringCar, case: str) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Matrices (M, A, B) of M ẋ = A x + B u (PHYSICS §9.2).

    Parameters
    ----------
    car : SteeringCar
    case : {"step", "release"}
        ``step``: states :data:`STEP_STATES`, input α [rad];
        ``release``: states :data:`RELEASE_STATES`, input T_h [N·m].

    Returns
    -------
    M, A, B : ndarray
    """
    if case not in ("step", "release"):
        raise InputError(f"case={case!r}; use 'step' or 'release'")
    v = car.speed_mps
    lf, lr = car.lf_m, car.lr_m
    kf, kr = car.cornering_stiffness_front_N_per_rad, car.cornering_stiffness_rear_N_per_rad
    ky = car.tyre_lateral_stiffness_N_per_m
    ks, xi = car.ks, car.trail_m
    rel = case == "release"
    names = RELEASE_STATES if rel else STEP_STATES
    ix = {n: i for i, n in enumerate(names)}
    n = len(names)
    m_ = np.zeros((n, n))
    a_ = np.zeros((n, n))
    b_ = np.zeros((n, 1))
    yf, yr = ("Y_f1", "Y_f2"), ("Y_r1", "Y_r2")
    # (1) lateral: m V β̇ = −m V r + ΣY
    m_[0, ix["beta"]] = car.mass_kg * v
    a_[0, ix["r"]] = -car.mass_kg * v
    for y in yf + yr:
        a_[0, ix[y]] = 1.0
    # (2) yaw
    m_[1, ix["r"]] = car.yaw_inertia_kgm2
    for y in yf:
        a_[1, ix[y]] = lf
    for y in yr:
        a_[1, ix[y]] = -lr
    # δ̇ = δ̇
    m_[2, ix["delta"]] = 1.0
    a_[2, ix["delta_dot"]] = 1.0
    # (3) kingpin: I_s δ̈ + I_s ṙ = −C_s δ̇ − k_s δ + k_s α − ξ (Y_f1 + Y_f2)
    m_[3, ix["delta_dot"]] = car.kingpin_inertia_kgm2
    m_[3, ix["r"]] = car.kingpin_inertia_kgm2
    a_[3, ix["delta_dot"]] = -car.kingpin_damping_Nms
    a_[3, ix["delta"]] = -ks
    for y in yf:
        a_[3, ix[y]] = -xi
    row = 4
    if rel:
        a_[3, ix["alpha"]] = ks
        # α̇ = α̇ ; (5) I_h α̈ = −C_h α̇ − k_s (α − δ) + T_h
        m_[4, ix["alpha"]] = 1.0
        a_[4, ix["alpha_dot"]] = 1.0
        m_[5, ix["alpha_dot"]] = car.ih
        a_[5, ix["alpha_dot"]] = -car.ch
        a_[5, ix["alpha"]] = -ks
        a_[5, ix["delta"]] = ks
        b_[5, 0] = 1.0
        row = 6
    else:
        b_[3, 0] = ks
    # (4) tyre lag: (K/(k_y V)) Ẏ = −Y + K β_i
    for y, k, front in (
        (yf[0], kf, True),
        (yf[1], kf, True),
        (yr[0], kr, False),
        (yr[1], kr, False),
    ):
        m_[row, ix[y]] = k / (ky * v)
        a_[row, ix[y]] = -1.0
        a_[row, ix["beta"]] = -k
        if front:
            a_[row, ix["delta"]] = k
            a_[row, ix["r"]] = -k * lf / v
        else:
            a_[row, ix["r"]] = k * lr / v
        row += 1
    return m_, a_, b_


def _state_space(car: SteeringCar, case: str) -> tuple[np.ndarray, np.ndarray]:
    m_, a_, b_ = descriptor(car, case)
    try:
        mi = np.linalg.inv(m_)
    except np.linalg.LinAlgError:
        raise InputError(
            "steering model: singular descriptor matrix; check that every "
            "inertia, stiffness and the speed are > 0"
        ) from None
    return mi @ a_, mi @ b_


def _foh_response(
    a: np.ndarray, b: np.ndarray, x0: np.ndarray, u: np.ndarray, dt: float
) -> np.ndarray:
    """Exact response of ẋ = A x + B u for u linear between samples (scipy's ``lsim`` with
    first-order hold); returns the states per sample."""
    n = a.shape[0]
    t = dt * np.arange(u.size)
    _, _, x = lsim((a, b, np.eye(n), np.zeros((n, 1))), u, t, X0=x0, interp=True)
    return np.asarray(x).reshape(u.size, n)


def simulate_step(
    car: SteeringCar,
    *,
    steer_rate_rad_s: float,
    stop_rad: float,
    duration_s: float = 2.0,
    dt_s: float = 1e-3,
    delay_s: float = 0.1,
) -> dict:
    """Test (i): kingpin angle α ramps from 0 at ``steer_rate`` to ``stop`` (the stopper).

    Parameters
    ----------
    car : SteeringCar
    steer_rate_rad_s : float
        Kingpin-referred steering rate α_v [rad/s] (steering-wheel rate / N).
    stop_rad : float
        Kingpin-referred stopper angle [rad].
    duration_s, dt_s, delay_s : float
        Length, sample interval and the straight-running time before the ramp [s].

    Returns
    -------
    dict
        ``t_s``, ``alpha_rad``, ``yaw_rate_rps``, ``yaw_accel_rps2``, ``delta_rad``, ``beta_rad``,
        ``onset_s`` (ramp start).
    """
    if steer_rate_rad_s <= 0 or stop_rad <= 0:
        raise InputError("simulate_step: steer_rate and stop must be > 0")
    a, b = _state_space(car, "step")
    t = np.arange(0.0, duration_s + dt_s / 2, dt_s)
    alpha = np.clip((t - delay_s) * steer_rate_rad_s, 0.0, stop_rad)
    # the ramp's corners fall between samples: first-order hold of the exact ramp is exact only
    # at the samples, which is fine at dt = 1 ms
    x = _foh_response(a, b, np.zeros(a.shape[0]), alpha, dt_s)
    xd = x @ a.T + np.outer(alpha, b[:, 0])
    return {
        "t_s": t,
        "alpha_rad": alpha,
        "yaw_rate_rps": x[:, 1],
        "yaw_accel_rps2": xd[:, 1],
        "delta_rad": x[:, 2],
        "beta_rad": x[:, 0],
        "onset_s": delay_s,
    }


def steady_turn(car: SteeringCar, alpha_rad: float) -> np.ndarray:
    """Steady state of test (i) held at kingpin angle α: [β, r, δ, δ̇, Y_f1, Y_f2, Y_r1, Y_r2]."""
    a, b = _state_space(car, "step")
    return np.linalg.solve(a, -b[:, 0] * alpha_rad)


def simulate_release(
    car: SteeringCar, *, alpha0_rad: float, duration_s: float = 3.0, dt_s: float = 1e-3
) -> dict:
    """Test (ii): hands off (T_h = 0) at t = 0 from a steady turn held at kingpin angle α0.

    Returns
    -------
    dict
        ``t_s``, ``alpha_rad`` (what a steering-angle sensor sees, kingpin-referred),
        ``delta_rad``, ``yaw_rate_rps``.
    """
    x_step = steady_turn(car, alpha0_rad)
    ix = {n: i for i, n in enumerate(RELEASE_STATES)}
    x0 = np.zeros(len(RELEASE_STATES))
    for i, name in enumerate(STEP_STATES):
        x0[ix[name]] = x_step[i]
    x0[ix["alpha"]] = alpha0_rad
    a, b = _state_space(car, "release")
    t = np.arange(0.0, duration_s + dt_s / 2, dt_s)
    x = _foh_response(a, b, x0, np.zeros(t.size), dt_s)
    return {
        "t_s": t,
        "alpha_rad": x[:, ix["alpha"]],
        "delta_rad": x[:, ix["delta"]],
        "yaw_rate_rps": x[:, ix["r"]],
    }


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
    dt = float(np.median(np.diff(t)))
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
