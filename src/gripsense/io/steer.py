"""Steering-angle channel: a CSV with time and road-wheel (or steering-wheel) angle."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from gripsense.errors import InputError
from gripsense.io.table import Quantity, map_table, read_table

__all__ = ["STEER_QUANTITIES", "read_steer_csv", "steer_at"]


STEER_QUANTITIES = {
    "t": Quantity("time", ("t", "time")),
    "road_wheel": Quantity("angle", ("road_wheel", "steer", "delta")),
    "steering_wheel": Quantity("angle", ("steering_wheel", "handwheel", "swa")),
}
"""The keys of a steering channel and the header names mapped without being told."""


def read_steer_csv(
    path: str | Path, *, steering_ratio: float | None = None, columns: str | dict | None = None
) -> pd.DataFrame:
    """Read a steering channel.

    The table needs a time column (seconds on the same clock as the epoch table's ``t_s``)
    and either the road-wheel steer angle (ISO: positive to the left) or the steering-wheel
    angle (divided by the vehicle's ``steering_ratio``). Headers with a unit suffix are mapped
    by themselves (``t_s``, ``road_wheel_deg``, ``steering_wheel_deg``; the one column
    convention, :func:`gripsense.io.table.map_table`).

    Parameters
    ----------
    path : str or Path
        Steering channel CSV.
    steering_ratio : float, optional
        Steering-wheel angle / road-wheel angle [-], needed for a steering-wheel angle.
    columns : str or dict, optional
        ``t=HEADER[:unit],road_wheel=…`` or ``steering_wheel=…``; default by header names.

    Returns
    -------
    pandas.DataFrame
        ``t_s`` [s] and ``steer_rad`` (road-wheel angle) [rad], sorted by time;
        ``attrs["columns"]`` the mapping used.
    """
    path = Path(path)
    df = read_table(path)
    v, spec = map_table(
        df,
        path,
        STEER_QUANTITIES,
        columns,
        required=("t", (("road_wheel",), ("steering_wheel",))),
        example="t=time:s,road_wheel=delta:deg",
    )
    if "road_wheel" in v:
        angle = v["road_wheel"]
    else:
        if not steering_ratio:
            raise InputError(
                f"{path}: a steering-wheel angle needs [vehicle] steering_ratio in the "
                "vehicle file (or give the road-wheel angle, e.g. road_wheel_deg)"
            )
        angle = v["steering_wheel"] / steering_ratio
    t = v["t"]
    bad = ~(np.isfinite(t) & np.isfinite(angle))
    if bad.any():
        row = int(np.flatnonzero(bad)[0])
        lines = df.attrs.get("line")
        where = f"line {int(lines[row])}" if lines is not None else f"row {row + 1}"
        raise InputError(f"{path}: {where}: time or angle is missing")
    out = pd.DataFrame({"t_s": t, "steer_rad": angle})
    out = out.sort_values("t_s", kind="stable").reset_index(drop=True)
    out.attrs["columns"] = spec
    return out


def steer_at(steer: pd.DataFrame, t_s: np.ndarray) -> np.ndarray:
    """Road-wheel angle [rad] at times t_s by linear interpolation (NaN outside the channel).

    Parameters
    ----------
    steer : pandas.DataFrame
        Channel of :func:`read_steer_csv`.
    t_s : array_like
        Times [s] on the channel's clock.
    """
    t = np.asarray(t_s, dtype=float)
    out = np.interp(t, steer["t_s"].to_numpy(), steer["steer_rad"].to_numpy())
    out[(t < steer["t_s"].iloc[0]) | (t > steer["t_s"].iloc[-1]) | np.isnan(t)] = np.nan
    return out
