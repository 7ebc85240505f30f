"""Accelerometer logs (the thesis's Arduino serial output turned CSV) for ``gripsense brake-mu``."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from gripsense.constants import G0
from gripsense.errors import InputError
from gripsense.io.table import Quantity, map_table, numeric_column, read_table

__all__ = ["ACCEL_QUANTITIES", "read_accel_csv"]

ACCEL_QUANTITIES = {
    "t": Quantity("time", ("t", "time", "timestamp")),
    "ax": Quantity("acceleration", ("ax", "a_x", "acc_x", "accel_x")),
    "ay": Quantity("acceleration", ("ay", "a_y", "acc_y", "accel_y")),
    "az": Quantity("acceleration", ("az", "a_z", "acc_z", "accel_z")),
}
"""Header names (before the unit suffix) that ``read_accel_csv`` maps without being told."""


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
    columns: str | dict | None = None,
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
    columns : str or dict, optional
        ``t=HEADER[:unit],ax=…,ay=…,az=…`` (:func:`gripsense.io.table.map_table`; ``-``
        flips a sign), or ``"auto"``: headers with a known name and unit suffix (``time_s``,
        ``ax_mps2``, ``ay_g`` …; :data:`ACCEL_QUANTITIES`). Replaces the ``*_col``, ``units``,
        ``ax_sign`` and ``time_scale`` arguments.

    Returns
    -------
    pandas.DataFrame
        ``t_s`` [s], ``ax``, ``ay``, ``az`` [m/s^2] (NaN when a column is not given);
        ``attrs["columns"]`` holds the mapping used.
    """
    path = Path(path)
    if columns is not None:
        df = read_table(path)
        v, spec = map_table(
            df,
            path,
            ACCEL_QUANTITIES,
            columns,
            required=("t", "ax"),
            example="t=HEADER:s,ax=HEADER:g",
        )
        nan = np.full(len(df), np.nan)
        res = pd.DataFrame(
            {"t_s": v["t"], "ax": v["ax"], "ay": v.get("ay", nan), "az": v.get("az", nan)}
        ).dropna(subset=["t_s", "ax"])
        res = res.sort_values("t_s", kind="stable").reset_index(drop=True)
        res.attrs["columns"] = spec
        return res
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
    res = res.sort_values("t_s", kind="stable").reset_index(drop=True)
    legacy = (
        ("t", t_col, time_scale),
        ("ax", ax_col, k * ax_sign),
        ("ay", ay_col, k),
        ("az", az_col, k),
    )
    res.attrs["columns"] = {key: (c, f) for key, c, f in legacy if c is not None}
    return res
