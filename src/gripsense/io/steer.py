"""Steering-angle channel: a CSV with time and road-wheel (or steering-wheel) angle."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from gripsense.errors import InputError
from gripsense.io.table import numeric_column, read_table

__all__ = ["read_steer_csv", "steer_at"]


def read_steer_csv(path: str | Path, *, steering_ratio: float | None = None) -> pd.DataFrame:
    """Read a steering channel.

    The CSV needs a column ``t_s`` (seconds on the same clock as the epoch table's ``t_s``) and
    one of ``road_wheel_deg`` (road-wheel steer angle, ISO: positive to the left) or
    ``steering_wheel_deg`` (divided by the vehicle's ``steering_ratio``).

    Parameters
    ----------
    path : str or Path
        Steering channel CSV.
    steering_ratio : float, optional
        Steering-wheel angle / road-wheel angle [-], needed for ``steering_wheel_deg``.

    Returns
    -------
    pandas.DataFrame
        ``t_s`` [s] and ``steer_rad`` (road-wheel angle) [rad], sorted by time.
    """
    path = Path(path)
    df = read_table(path)
    if "t_s" not in df.columns:
        raise InputError(f"{path}: no column 't_s' (columns: {list(df.columns)})")
    if "road_wheel_deg" in df.columns:
        deg = numeric_column(df, "road_wheel_deg", path)
    elif "steering_wheel_deg" in df.columns:
        if not steering_ratio:
            raise InputError(
                f"{path}: 'steering_wheel_deg' needs [vehicle] steering_ratio in the "
                "vehicle file (or give road_wheel_deg)"
            )
        deg = numeric_column(df, "steering_wheel_deg", path) / steering_ratio
    else:
        raise InputError(f"{path}: needs a column 'road_wheel_deg' or 'steering_wheel_deg'")
    t = numeric_column(df, "t_s", path)
    bad = ~(np.isfinite(t) & np.isfinite(deg))
    if bad.any():
        row = int(np.flatnonzero(bad)[0])
        lines = df.attrs.get("line")
        where = f"line {int(lines[row])}" if lines is not None else f"row {row + 1}"
        raise InputError(f"{path}: {where}: t_s or angle is missing")
    out = pd.DataFrame({"t_s": t, "steer_rad": np.deg2rad(deg)})
    return out.sort_values("t_s", kind="stable").reset_index(drop=True)


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
