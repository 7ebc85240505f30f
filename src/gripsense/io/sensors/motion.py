"""Motion tables from other sources: GNSS/INS exports (OxTS, VBOX), research datasets.

``read_motion_table(path, columns)`` turns a CSV or Parquet table into the motion table the
friction core uses (:func:`gripsense.estimate.friction.friction_from_motion`): body velocities
of the measurement point (the antenna position of the vehicle file), ISO yaw rate, optional
lateral acceleration and road-wheel steer angle, and time.

Column mapping (the one convention, :mod:`gripsense.io.table`): ``{"t": "Time", "vx":
"VelForward", "vy": "VelLateral:kmh", ...}`` or the command-line form
``t=Time,vx=VelForward,vy=VelLateral:kmh,yaw_rate=AngRateZ:dps``. Keys:

==========  ============================================================  ==============
key         meaning                                                       default unit
==========  ============================================================  ==============
t           time                                                          s
vx, vy      body velocity of the measurement point, x forward, y left     m/s
speed, slip alternative to vx, vy: speed and body slip angle (ISO, left+) m/s, rad
yaw_rate    yaw rate, ISO (counter-clockwise positive)                    rad/s
ay          lateral acceleration of the CG, ISO (left positive)           m/s²
steer       road-wheel steer angle, ISO (left positive)                   rad
==========  ============================================================  ==============
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from gripsense.io.table import (
    ACCEL_LIMIT,
    ACCEL_TYPICAL,
    ROAD_WHEEL_LIMIT,
    SPEED_LIMIT,
    YAW_RATE_LIMIT,
    Quantity,
    map_table,
    read_table,
)

__all__ = ["MOTION_QUANTITIES", "read_motion_table"]

MOTION_QUANTITIES = {
    "t": Quantity("time", ("t", "time")),
    "vx": Quantity("speed", ("vx", "v_x", "vel_x", "velforward"), SPEED_LIMIT,
                   meaning="a vehicle's speed"),
    "vy": Quantity("speed", ("vy", "v_y", "vel_y", "vellateral"), SPEED_LIMIT,
                   meaning="a vehicle's speed"),
    "speed": Quantity("speed", ("speed", "v", "vel"), SPEED_LIMIT, meaning="a vehicle's speed"),
    "slip": Quantity("angle", ("slip", "beta", "sideslip", "slip_angle"), np.pi,
                     meaning="a body slip angle"),
    "yaw_rate": Quantity("angular rate", ("yaw_rate", "yawrate"), YAW_RATE_LIMIT,
                         meaning="a vehicle's yaw rate"),
    "ay": Quantity("acceleration", ("ay", "a_y", "acc_y", "accel_y"), ACCEL_LIMIT,
                   ACCEL_TYPICAL, meaning="a vehicle's acceleration"),
    "steer": Quantity("angle", ("steer", "delta", "steer_angle", "road_wheel"), ROAD_WHEEL_LIMIT,
                      meaning="a road-wheel angle"),
}  # fmt: skip
"""The motion table's keys, and the header names ``read_motion_table`` maps without being told."""


def read_motion_table(path: str | Path, columns: str | dict = "auto") -> pd.DataFrame:
    """Read a CSV/Parquet table into a motion table.

    Parameters
    ----------
    path : path
        ``.csv`` (comment lines ``#``) or ``.parquet``.
    columns : str or dict
        Column mapping (see the module documentation). Needs ``t``, ``yaw_rate`` and either
        ``vx`` + ``vy`` or ``speed`` + ``slip``. ``"auto"`` (default): headers with a known name
        and unit suffix (``time_s``, ``speed_kmh``, ``slip_deg``, ``yaw_rate_dps`` …;
        :data:`MOTION_QUANTITIES`).

    Returns
    -------
    pandas.DataFrame
        ``t_s``, ``epoch`` (row), ``u_mps``, ``v_mps``, ``yaw_rate_rps``, ``ay_mps2``,
        ``steer_rad`` (NaN where not given); ``attrs["columns"]`` holds the mapping used.

    Raises
    ------
    InputError
        Naming the file, key and column when something is missing or not numeric.
    """
    path = Path(path)
    df = read_table(path)
    v, spec = map_table(
        df,
        path,
        MOTION_QUANTITIES,
        columns,
        required=("t", "yaw_rate", (("vx", "vy"), ("speed", "slip"))),
        example="t=Time:s,vx=VelForward:kmh,vy=VelLateral:kmh,yaw_rate=AngRateZ:dps",
    )
    if "vx" in v and "vy" in v:
        u, w = v["vx"], v["vy"]
    else:
        u, w = v["speed"] * np.cos(v["slip"]), v["speed"] * np.sin(v["slip"])
    n = len(df)
    nan = np.full(n, np.nan)
    out = (
        pd.DataFrame(
            {
                "t_s": v["t"],
                "epoch": np.arange(n),
                "u_mps": u,
                "v_mps": w,
                "yaw_rate_rps": v["yaw_rate"],
                "ay_mps2": v.get("ay", nan),
                "steer_rad": v.get("steer", nan),
            }
        )
        .dropna(subset=["t_s", "u_mps", "v_mps", "yaw_rate_rps"])
        .reset_index(drop=True)
    )
    out.attrs["columns"] = spec
    return out
