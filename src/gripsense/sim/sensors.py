"""Sensor emulators besides the compass: the accelerometer of the braking test and a steering
channel.

Accelerometer (thesis ch. 8: KX022 at 50 Hz on the dashboard).

Output layout (what ``gripsense brake-mu`` reads): CSV with ``t_s, ax_g, ay_g, az_g`` — specific
force along the sensor axes (x forward, y left, z up) in units of g, so a level sensor at rest
reads (0, 0, 1). Mounting tilt (pitch nose-up, roll right-side-down positive), bias and white
noise are configurable; the planar simulator has no pitch or roll motion of the body.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from gripsense.constants import G0
from gripsense.sim.vehicle import SimResult

__all__ = ["emulate_accelerometer", "emulate_steering"]


def emulate_accelerometer(
    result: SimResult,
    *,
    rate_hz: float = 50.0,
    pitch_deg: float = 0.0,
    roll_deg: float = 0.0,
    noise_g: float = 0.01,
    bias_g: tuple[float, float, float] = (0.0, 0.0, 0.0),
    seed: int = 0,
) -> pd.DataFrame:
    """Accelerometer readings of a simulated drive.

    Parameters
    ----------
    result : SimResult
    rate_hz : float
        Sample rate [Hz] (the simulator output rate must be a multiple).
    pitch_deg, roll_deg : float
        Mounting tilt of the sensor relative to the body [deg].
    noise_g : float
        White noise per axis [g].
    bias_g : (float, float, float)
        Constant bias per axis [g].
    seed : int

    Returns
    -------
    pandas.DataFrame
        ``t_s``, ``ax_g``, ``ay_g``, ``az_g``.
    """
    b = result.body
    step = round(result.meta.get("output_hz", 100.0) / rate_hz)
    sub = b.iloc[::step]
    n = len(sub)
    f = (
        np.column_stack([sub["ax_mps2"].to_numpy(), sub["ay_mps2"].to_numpy(), np.full(n, G0)]) / G0
    )  # specific force, body axes [g]
    th, ph = np.deg2rad(pitch_deg), np.deg2rad(roll_deg)
    ry = np.array([[np.cos(th), 0, -np.sin(th)], [0, 1, 0], [np.sin(th), 0, np.cos(th)]])
    rx = np.array([[1, 0, 0], [0, np.cos(ph), np.sin(ph)], [0, -np.sin(ph), np.cos(ph)]])
    s = f @ (rx @ ry).T
    rng = np.random.default_rng(seed)
    s = s + np.asarray(bias_g) + rng.normal(0.0, noise_g, s.shape)
    return pd.DataFrame(
        {"t_s": sub["t_s"].to_numpy(), "ax_g": s[:, 0], "ay_g": s[:, 1], "az_g": s[:, 2]}
    )


def emulate_steering(
    result: SimResult,
    *,
    rate_hz: float = 50.0,
    noise_deg: float = 0.05,
    scale_error: float = 0.03,
    offset_deg: float = 0.0,
    seed: int = 0,
) -> pd.DataFrame:
    """A road-wheel steering-angle channel of a simulated drive, as a steering-angle sensor
    behind the steering ratio gives it: a scale error (the ratio is never known exactly and
    varies with the angle), a zero offset and white noise.

    Parameters
    ----------
    result : SimResult
        The drive.
    rate_hz : float
        Sample rate [Hz] (the simulator output rate must be a multiple).
    noise_deg : float
        White noise of the road-wheel angle [deg], 1 σ.
    scale_error : float
        Relative scale error: the channel reads (1 + scale_error) × the true angle [-].
    offset_deg : float
        Zero offset of the road-wheel angle [deg].
    seed : int
        Random seed.

    Returns
    -------
    pandas.DataFrame
        ``t_s`` and ``road_wheel_deg`` (ISO: positive to the left), the layout of
        :func:`gripsense.io.sensors.steer.read_steer_csv`.
    """
    b = result.body
    step = max(round(result.meta.get("output_hz", 100.0) / rate_hz), 1)
    sub = b.iloc[::step]
    rng = np.random.default_rng(seed)
    deg = np.rad2deg(sub["steer_rad"].to_numpy(float)) * (1.0 + scale_error) + offset_deg
    deg = deg + rng.normal(0.0, noise_deg, deg.size)
    return pd.DataFrame({"t_s": sub["t_s"].to_numpy(float), "road_wheel_deg": deg})
