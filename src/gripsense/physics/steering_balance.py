"""The steering balance: what the steering system must supply to hold the front wheels.

About their steering (kingpin) axes the front tyres return the moment of their lateral forces
about the ground point of the axis plus their own aligning moments (seed 003 eq. 3, ξ = t_c + t;
``docs/physics.md`` §16.3). With the road-wheel angle δ(t) of a drive given, seed 003's eq. (3)
solved for the torque through the column (its k_s (α − δ) term) is

    T_col · i_s (1 + g) = M_s + I_s (δ̈ + ṙ) + C_s δ̇ + M_f,      M_s = Σ (t_c F_y,i − M_z,i)

with i_s the steering ratio, g the power steering's assist gain (assist torque over the
column torque it answers), I_s and C_s the inertia and viscous damping about the kingpins and M_f
the system's Coulomb friction (a Dahl model: it builds up with steer travel and saturates at
±M_c, so a held steer keeps the friction of its last motion). ISO axes: a positive moment
turns the wheels to the left; in a steady left turn F_y > 0, M_z < 0 and M_s > 0.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from gripsense._arrays import as_float_array

__all__ = ["backlash", "column_torque", "dahl_friction", "friction_state", "steering_moment"]


def steering_moment(fy_N, mz_Nm, mechanical_trail_m):
    """The moment the steering must supply to hold a front wheel, t_c F_y − M_z [N m].

    Parameters
    ----------
    fy_N : array_like
        Lateral force of the wheel, wheel axes, ISO [N].
    mz_Nm : array_like
        Its aligning moment, ISO (negative for a positive force below the peak) [N m].
    mechanical_trail_m : array_like
        Caster trail: how far the steering axis meets the ground ahead of the contact centre [m].

    Returns
    -------
    numpy.ndarray
        M [N m], ISO: positive towards the left. Sum it over the steered wheels.

    References
    ----------
    Seed 003 eq. (3) (ξ Y with ξ = t_c + t); docs/physics.md §16.3.
    """
    fy = as_float_array(fy_N, "fy_N")
    mz = as_float_array(mz_Nm, "mz_Nm")
    tc = as_float_array(mechanical_trail_m, "mechanical_trail_m")
    return tc * fy - mz


@njit(cache=True)
def _dahl(delta: np.ndarray, limit: float, stiffness: float) -> np.ndarray:  # pragma: no cover
    out = np.empty(delta.size)
    f = 0.0
    out[0] = 0.0
    for k in range(1, delta.size):
        d = delta[k] - delta[k - 1]
        s = 1.0 if d > 0 else -1.0
        f = f + stiffness * d * (1.0 - f / limit * s) if d != 0 else f
        f = min(max(f, -limit), limit)
        out[k] = f
    return out


def dahl_friction(steer_rad, limit_Nm: float, travel_rad: float = 0.002):
    """Coulomb friction of the steering with memory (Dahl model), along a steer history.

    dM_f/dδ = σ (1 − M_f/M_c sgn δ̇), σ = M_c/travel: the friction opposes the motion, reaches
    ±M_c within a few *travel* of steer, and a held steer keeps the friction of its last motion.

    Parameters
    ----------
    steer_rad : array_like
        Road-wheel angle δ along the drive, in time order [rad].
    limit_Nm : float
        Coulomb friction M_c, referred to the kingpins [N m].
    travel_rad : float
        Steer travel over which the friction builds up (σ = M_c/travel) [rad].

    Returns
    -------
    numpy.ndarray
        M_f [N m], ISO sign of the moment it asks of the steering (positive while steering left).

    References
    ----------
    P. Dahl, "A solid friction model", Aerospace Corp. TOR-0158 (1968); docs/physics.md §16.3.
    """
    d = np.ascontiguousarray(as_float_array(steer_rad, "steer_rad"), dtype=float).ravel()
    if d.size == 0 or limit_Nm <= 0:
        return np.zeros(d.size)
    return _dahl(d, float(limit_Nm), float(limit_Nm) / float(travel_rad))


@njit(cache=True)
def _backlash(x: np.ndarray, half: float) -> np.ndarray:  # pragma: no cover
    out = np.empty(x.size)
    y = np.nan
    for k in range(x.size):
        v = x[k]
        if np.isnan(v):
            out[k] = y
            continue
        if np.isnan(y):
            y = v
        y = min(max(y, v - half), v + half)
        out[k] = y
    return out


def backlash(x, half_width: float):
    """The play (backlash) operator: the output stays until the input has moved more than
    *half_width* from it, then follows at that distance — a deadband that a signal's noise
    inside it does not cross, while any motion beyond it passes (delayed by the half-width).

    Parameters
    ----------
    x : array_like
        The input in time order [its unit] (NaN: the output held).
    half_width : float
        Half the deadband [x's unit].

    Returns
    -------
    numpy.ndarray
        The output [x's unit].

    References
    ----------
    M. A. Krasnosel'skii, A. V. Pokrovskii, *Systems with Hysteresis* (1989), the play
    operator; docs/physics.md §16.6.
    """
    d = np.ascontiguousarray(as_float_array(x, "x"), dtype=float).ravel()
    if d.size == 0:
        return np.zeros(0)
    return _backlash(d, float(max(half_width, 0.0)))


@njit(cache=True)
def _relay(d: np.ndarray, band: float, margin: float, travel: float):  # pragma: no cover
    n = d.size
    state = np.zeros(n)
    known = np.zeros(n)
    s = 0.0  # the direction of the last confirmed motion (0: none yet)
    hi = np.nan  # the running extremes since the last reversal, and where they were
    lo = np.nan
    hi_i = 0
    lo_i = 0
    ext = np.nan  # the steer where the last reversal began
    for k in range(n):
        x = d[k]
        if np.isnan(x):
            continue
        if np.isnan(hi):
            hi, lo, hi_i, lo_i = x, x, k, k
        if x >= hi:  # the last sample at the extreme: a reversal begins after it
            hi, hi_i = x, k
        if x <= lo:
            lo, lo_i = x, k
        if s >= 0.0 and x < hi - band:  # unwinding, confirmed: it began where the steer
            s, ext = -1.0, hi  # last was within the noise of its maximum
            j = k - 1
            while j > hi_i and not d[j] >= hi - margin:
                state[j], known[j] = 0.0, 0.0
                j -= 1
            lo, lo_i = x, k
        elif s <= 0.0 and x > lo + band:
            s, ext = 1.0, lo
            j = k - 1
            while j > lo_i and not d[j] <= lo + margin:
                state[j], known[j] = 0.0, 0.0
                j -= 1
            hi, hi_i = x, k
        if s == 0.0 or (not np.isnan(ext) and abs(x - ext) < travel):
            continue  # no direction yet, or the friction still building up
        state[k], known[k] = s, 1.0
    return state, known


def friction_state(steer_rad, noise_rad: float = 0.0, travel_rad: float = 0.002):
    """The steering friction's state along a measured steer history, and where it is known.

    The friction opposes the steering's last motion (the Dahl model's memory, §16.3). From a
    measured steer it is known only where that motion is certain: a reversal counts once the
    steer has moved back from its extreme by the band b = max(2 *travel_rad*, 6 *noise_rad*)
    (the sensor's noise does not cross it), and it began after the last sample within
    max(*travel_rad*, 3 *noise_rad*) of the extreme (a held steer's noise makes no motion);
    the samples from there until the friction has built up again (a *travel_rad* from the
    extreme) are not known.
    A correction smaller than the band is not seen: its share of the friction is the
    estimator's to carry (``FRICTION_STATE_SD``).

    Parameters
    ----------
    steer_rad : array_like
        Road-wheel angle in time order [rad] (NaN: no sample).
    noise_rad : float
        1σ white noise of the steer samples [rad].
    travel_rad : float
        Steer travel over which the friction builds up (the Dahl model's) [rad].

    Returns
    -------
    state : numpy.ndarray
        +1 after steering left, −1 after steering right, 0 where not known [-].
    known : numpy.ndarray of bool
        Where the state is known.

    References
    ----------
    P. Dahl (1968); docs/physics.md §16.3, §16.6.
    """
    d = np.ascontiguousarray(as_float_array(steer_rad, "steer_rad"), dtype=float).ravel()
    if d.size == 0:
        return np.zeros(0), np.zeros(0, dtype=bool)
    band = max(2.0 * travel_rad, 6.0 * noise_rad)
    margin = max(travel_rad, 3.0 * noise_rad)
    state, known = _relay(d, float(band), float(margin), float(travel_rad))
    return state, known.astype(bool)


def column_torque(
    moment_Nm,
    steer_rate_rps,
    steer_accel_rps2,
    friction_Nm,
    *,
    ratio: float,
    assist_gain: float = 0.0,
    kingpin_inertia_kgm2: float = 0.0,
    kingpin_damping_Nms: float = 0.0,
    yaw_accel_rps2=0.0,
):
    """Torque through the steering column (what its torque sensor reads) [N m].

    Parameters
    ----------
    moment_Nm : array_like
        Steering moment M_s of the front wheels, summed (:func:`steering_moment`) [N m].
    steer_rate_rps : array_like
        δ̇ [rad/s].
    steer_accel_rps2 : array_like
        δ̈ [rad/s²].
    friction_Nm : array_like
        Friction moment at the kingpins (:func:`dahl_friction`) [N m].
    ratio : float
        Steering ratio i_s, steering-wheel angle over road-wheel angle [-].
    assist_gain : float
        Power-steering assist torque over the column torque [-] (0: manual steering).
    kingpin_inertia_kgm2 : float
        I_s of both steered wheels about their axes [kg m²].
    kingpin_damping_Nms : float
        C_s, viscous damping about the axes [N m s/rad].
    yaw_accel_rps2 : array_like
        ṙ [rad/s²] (the wheels' inertia turns with the body, seed 003 eq. 3).

    Returns
    -------
    numpy.ndarray
        T_col = (M_s + I_s (δ̈ + ṙ) + C_s δ̇ + M_f) / (i_s (1 + g)) [N m], ISO sign.

    References
    ----------
    Seed 003 eqs. (3), (5); docs/physics.md §16.3.
    """
    m = as_float_array(moment_Nm, "moment_Nm")
    rate = as_float_array(steer_rate_rps, "steer_rate_rps")
    acc = as_float_array(steer_accel_rps2, "steer_accel_rps2")
    fric = as_float_array(friction_Nm, "friction_Nm")
    yaw_acc = as_float_array(yaw_accel_rps2, "yaw_accel_rps2")
    total = m + kingpin_inertia_kgm2 * (acc + yaw_acc) + kingpin_damping_Nms * rate + fric
    return total / (ratio * (1.0 + assist_gain))
