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

__all__ = ["column_torque", "dahl_friction", "steering_moment"]


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
