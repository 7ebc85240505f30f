"""Vehicle + steering-system model of seed 003 as a linear descriptor system, and its two tests.

docs/physics.md §9 (seed ``003_fdc8abf9dc5f3e6a.txt`` eqs. 1–6, errors fixed):

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
(det M = m I I_s I_h Π K_i / (V³ k_y⁴) ≠ 0, docs/physics.md §9.2). Inputs are piecewise linear, so
the
response is computed exactly on the sample grid (scipy ``lsim``, first-order hold).
"""

from __future__ import annotations

from typing import Protocol

import numpy as np
from scipy.signal import lsim

from gripsense.errors import InputError

__all__ = [
    "RELEASE_STATES",
    "STEP_STATES",
    "SteeringSystem",
    "descriptor",
    "simulate_release",
    "simulate_step",
]


class SteeringSystem(Protocol):
    """The parameters the model reads (:class:`gripsense.config.SteeringCar` has them): SI
    units, steering-wheel inertia and damping referred to the kingpin (``ih``, ``ch``).
    """

    # read-only (a frozen dataclass satisfies them)
    @property
    def speed_mps(self) -> float: ...  # noqa: D102

    @property
    def lf_m(self) -> float: ...  # noqa: D102

    @property
    def lr_m(self) -> float: ...  # noqa: D102

    @property
    def mass_kg(self) -> float: ...  # noqa: D102

    @property
    def yaw_inertia_kgm2(self) -> float: ...  # noqa: D102

    @property
    def cornering_stiffness_front_N_per_rad(self) -> float: ...  # noqa: D102

    @property
    def cornering_stiffness_rear_N_per_rad(self) -> float: ...  # noqa: D102

    @property
    def tyre_lateral_stiffness_N_per_m(self) -> float: ...  # noqa: D102

    @property
    def trail_m(self) -> float: ...  # noqa: D102

    @property
    def kingpin_inertia_kgm2(self) -> float: ...  # noqa: D102

    @property
    def kingpin_damping_Nms(self) -> float: ...  # noqa: D102

    @property
    def ks(self) -> float: ...  # noqa: D102

    @property
    def ih(self) -> float: ...  # noqa: D102

    @property
    def ch(self) -> float: ...  # noqa: D102


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


def descriptor(car: SteeringSystem, case: str) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Matrices (M, A, B) of M ẋ = A x + B u (docs/physics.md §9.2).

    Parameters
    ----------
    car : SteeringSystem
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


def _state_space(car: SteeringSystem, case: str) -> tuple[np.ndarray, np.ndarray]:
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
    first-order hold); returns the states per sample.
    """
    n = a.shape[0]
    t = dt * np.arange(u.size)
    _, _, x = lsim((a, b, np.eye(n), np.zeros((n, 1))), u, t, X0=x0, interp=True)
    return np.asarray(x).reshape(u.size, n)


def simulate_step(
    car: SteeringSystem,
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
    car : SteeringSystem
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


def steady_turn(car: SteeringSystem, alpha_rad: float) -> np.ndarray:
    """Steady state of test (i) held at kingpin angle α: [β, r, δ, δ̇, Y_f1, Y_f2, Y_r1, Y_r2]."""
    a, b = _state_space(car, "step")
    return np.linalg.solve(a, -b[:, 0] * alpha_rad)


def simulate_release(
    car: SteeringSystem, *, alpha0_rad: float, duration_s: float = 3.0, dt_s: float = 1e-3
) -> dict:
    """Test (ii): hands off (T_h = 0) at t = 0 from a steady turn held at kingpin angle α0.

    Parameters
    ----------
    car : SteeringSystem
        The car.
    alpha0_rad : float
        Kingpin angle held before the release [rad].
    duration_s : float
        Simulated time after the release [s].
    dt_s : float
        Output step [s].

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
