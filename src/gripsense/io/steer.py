"""Steering-angle channel: a CSV with time and road-wheel (or steering-wheel) angle."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from gripsense.errors import InputError

__all__ = ["read_steer_csv", "steer_at"]


def read_steer_csv(path: str | Path, *, steering_ratio: float | None = None) -> pd.DataFrame:
    """Read a steering channel.

    The CSV needs a column ``t_s`` (seconds on the same clock as the epoch table's ``t_s``) and
    one of ``road_wheel_deg`` (road-wheel steer angle, ISO: positive to the left) or
    ``steering_wheel_deg`` (divided by the vehicle's ``steering_ratio``).

    Returns
    -------
    pandas.DataFrame
        ``t_s`` [s] and ``steer_rad`` (road-wheel angle) [rad], sorted by time.
    """
    path = Path(path)
    try:
        df = pd.read_csv(path, comment="#")
    except FileNotFoundError:
        raise InputError(f"{path}: no such steering file") from None
    except (pd.errors.ParserError, UnicodeDecodeError) as e:
        raise InputError(f"{path}: not a readable CSV ({e})") from None
    if "t_s" not in df.columns:
        raise InputError(f"{path}: no column 't_s' (columns: {list(df.columns)})")
    if "road_wheel_deg" in df.columns:
        deg = df["road_wheel_deg"]
    elif "steering_wheel_deg" in df.columns:
        if not steering_ratio:
            raise InputError(
                f"{path}: 'steering_wheel_deg' needs [vehicle] steering_ratio in the "
                "vehicle file (or give road_wheel_deg)"
            )
        deg = df["steering_wheel_deg"] / steering_ratio
    else:
        raise InputError(f"{path}: needs a column 'road_wheel_deg' or 'steering_wheel_deg'")
    t = pd.to_numeric(df["t_s"], errors="coerce")
    a = pd.to_numeric(deg, errors="coerce")
    bad = t.isna() | a.isna()
    if bad.any():
        first = int(np.flatnonzero(bad.to_numpy())[0]) + 2  # header is line 1
        raise InputError(f"{path}: line {first}: t_s or angle is not a number")
    out = pd.DataFrame({"t_s": t.to_numpy(float), "steer_rad": np.deg2rad(a.to_numpy(float))})
    return out.sort_values("t_s", kind="stable").reset_index(drop=True)


def steer_at(steer: pd.DataFrame, t_s: np.ndarray) -> np.ndarray:
    """Road-wheel angle [rad] at times t_s by linear interpolation (NaN outside the channel)."""
    t = np.asarray(t_s, dtype=float)
    out = np.interp(t, steer["t_s"].to_numpy(), steer["steer_rad"].to_numpy())
    out[(t < steer["t_s"].iloc[0]) | (t > steer["t_s"].iloc[-1]) | np.isnan(t)] = np.nan
    return out
