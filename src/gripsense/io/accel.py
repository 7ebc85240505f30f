"""Accelerometer logs (the thesis's Arduino serial output turned CSV) for ``gripsense brake-mu``."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from gripsense.constants import G0
from gripsense.errors import InputError
from gripsense.io.table import numeric_column, read_table

__all__ = ["read_accel_csv"]


def read_accel_csv(
    path: str | Path,
    *,
    t_col: str = "t_s",
    ax_col: str = "ax_g",
    ay_col: str | None = "ay_g",
    az_col: str | None = "az_g",
    units: str = "g",
    ax_sign: float = 1.0,
    time_scale: float = 1.0,
) -> pd.DataFrame:
    """Read an accelerometer log (the thesis's Arduino serial output turned CSV).

    Parameters
    ----------
    path : path
        CSV; ``#`` lines are comments.
    t_col, ax_col, ay_col, az_col : str
        Column names (``ay``/``az`` optional: without ``az`` no pitch-free form).
    units : {"g", "mps2"}
        Units of the acceleration columns.
    ax_sign : float
        +1 when the x column is positive forward (ISO), −1 when the sensor is mounted backwards.
    time_scale : float
        Seconds per time unit (1e-3 for milliseconds, as Arduino ``millis()``).

    Returns
    -------
    pandas.DataFrame
        ``t_s`` [s], ``ax``, ``ay``, ``az`` [m/s^2] (NaN when a column is not given).
    """
    path = Path(path)
    if units not in ("g", "mps2"):
        raise InputError(f"units={units!r}; use 'g' or 'mps2'")
    df = read_table(path)
    k = G0 if units == "g" else 1.0
    out = {}
    for key, col, scale in (
        ("t_s", t_col, time_scale),
        ("ax", ax_col, k * ax_sign),
        ("ay", ay_col, k),
        ("az", az_col, k),
    ):
        if col is None:
            out[key] = np.full(len(df), np.nan)
            continue
        if col not in df.columns:
            raise InputError(
                f"{path}: no column {col!r} (columns: {list(df.columns)}); set it "
                f"with --{key.rstrip('_s')}-col"
            )
        out[key] = numeric_column(df, col, path) * scale
    res = pd.DataFrame(out).dropna(subset=["t_s", "ax"])
    return res.sort_values("t_s", kind="stable").reset_index(drop=True)
