"""From the GNSS-compass antenna to each wheel: velocity, slip angle, speed and path radius.

Frame: ISO 8855 body axes (x forward, y left, z up); yaw rate r positive counter-clockwise.
Inputs from the receiver stay compass angles (heading ψ_c, course χ_c, clockwise from north).

References: docs/physics.md §3.1 (correct rigid-body transfer), §3.2 (the thesis's eqs. 6.9–6.12 and
their sign traps); seed 000 §6.1.
"""

from __future__ import annotations

import numpy as np

from gripsense._arrays import as_float_array, restore

_ONE_DEG = float(np.deg2rad(1.0))  # [rad]

__all__ = [
    "antenna_sideslip",
    "heading_offset_from_straight",
    "path_radius",
    "point_velocity",
    "slip_angle",
    "wrap_angle",
]


def wrap_angle(angle):
    """Wrap an angle to [−π, π) [rad].

    Parameters
    ----------
    angle : array_like
        Angle [rad].
    """
    a = as_float_array(angle, "angle")
    return restore((a + np.pi) % (2.0 * np.pi) - np.pi, angle)


def antenna_sideslip(heading_rad, course_rad, heading_offset_rad: float = 0.0):
    """Side-slip angle of the antenna point, β_A = wrap(ψ_c − ψ_0 − χ_c) [rad].

    Positive when the velocity points left of the heading (ISO). ψ_0 is the heading mounting
    offset (true heading of the vehicle's x axis = ψ_c − ψ_0).

    Parameters
    ----------
    heading_rad : array_like
        Compass heading ψ_c, clockwise from north [rad].
    course_rad : array_like
        Course over ground χ_c, clockwise from north [rad].
    heading_offset_rad : float
        ψ_0 [rad].

    References
    ----------
    docs/physics.md §3.1 (β_A = wrap(ψ_c − χ_c) = −(θ_t − θ_d) of thesis eq. 6.2).
    """
    h = as_float_array(heading_rad, "heading_rad")
    c = as_float_array(course_rad, "course_rad")
    return restore(wrap_angle(h - heading_offset_rad - c), heading_rad)


def point_velocity(u_a, v_a, yaw_rate, dx, dy):
    """Body-frame velocity of a point at (dx, dy) from the antenna: (U − r dy, V + r dx) [m/s].

    Parameters
    ----------
    u_a, v_a : array_like
        Antenna velocity along body x and y [m/s].
    yaw_rate : array_like
        r, ISO (counter-clockwise positive) [rad/s].
    dx, dy : float or array_like
        Position of the point relative to the antenna, body x forward and y left [m].

    References
    ----------
    docs/physics.md §3.1: v_P = v_A + ω × r_AP with ω = (0, 0, r).
    """
    u, v, r = (
        as_float_array(x, n) for x, n in ((u_a, "u_a"), (v_a, "v_a"), (yaw_rate, "yaw_rate"))
    )
    return restore(u - r * dy, u_a), restore(v + r * dx, u_a)


def slip_angle(u, v, steer_angle=0.0):
    """Wheel slip angle α = atan2(V, U) − δ [rad] (ISO: negative at the rear in a left turn).

    Parameters
    ----------
    u : array_like
        Longitudinal velocity of the wheel centre, body axes [m/s].
    v : array_like
        Lateral velocity, body axes [m/s].
    steer_angle : array_like
        Road-wheel steer angle δ [rad].

    References
    ----------
    docs/physics.md §3.1.
    """
    uu, vv = as_float_array(u, "u"), as_float_array(v, "v")
    d = as_float_array(steer_angle, "steer_angle")
    return restore(np.arctan2(vv, uu) - d, u)


def path_radius(speed, yaw_rate):
    """Path radius of a body point, R = |v_P| / |r| [m] (exact for steady rotation).

    Parameters
    ----------
    speed : array_like
        Speed of the point |v_P| [m/s].
    yaw_rate : array_like
        Yaw rate r [rad/s].

    References
    ----------
    docs/physics.md §3.1.
    """
    s, r = as_float_array(speed, "speed"), as_float_array(yaw_rate, "yaw_rate")
    with np.errstate(divide="ignore", invalid="ignore"):
        return restore(np.abs(s) / np.abs(r), speed)


def heading_offset_from_straight(
    heading_rad,
    course_rad,
    yaw_rate,
    speed,
    *,
    min_speed=5.0,
    max_yaw_rate=_ONE_DEG,
    min_samples: int = 20,
):
    """Heading mounting offset from straight driving: the circular mean of wrap(ψ_c − χ_c).

    On a straight the vehicle's side-slip is ~0, so heading minus course is the offset of the
    compass baseline from the vehicle's x axis (thesis §5.4 found about ±1°).

    Parameters
    ----------
    heading_rad, course_rad : array_like
        Compass heading and course over ground [rad].
    yaw_rate : array_like
        [rad/s]; samples with |r| <= max_yaw_rate count as straight.
    speed : array_like
        [m/s]; samples below min_speed are skipped (course is noisy at low speed).
    min_speed : float
        [m/s].
    max_yaw_rate : float
        [rad/s].
    min_samples : int
        Fewer straight samples than this: the offset is not determined (NaN).

    Returns
    -------
    offset : float
        ψ_0 [rad], NaN when not determined.
    n : int
        Number of straight samples used.
    spread : float
        Standard deviation of the straight samples [rad] (NaN when not determined).
    """
    h, c, r, s = (
        as_float_array(x, n)
        for x, n in (
            (heading_rad, "heading_rad"),
            (course_rad, "course_rad"),
            (yaw_rate, "yaw_rate"),
            (speed, "speed"),
        )
    )
    d = (h - c + np.pi) % (2.0 * np.pi) - np.pi
    ok = np.isfinite(d) & (np.abs(r) <= max_yaw_rate) & (s >= min_speed)
    n = int(ok.sum())
    if n < min_samples:
        return float("nan"), n, float("nan")
    z = np.exp(1j * d[ok])
    mean = float(np.angle(z.mean()))
    spread = float(np.std((d[ok] - mean + np.pi) % (2 * np.pi) - np.pi))
    return mean, n, spread
