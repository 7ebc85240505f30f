"""Two-laser camber recordings (seed 002 Fig. 3) for ``gripsense camber``."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from gripsense.errors import InputError
from gripsense.io.table import Quantity, map_table, read_table

__all__ = ["LASER_QUANTITIES", "read_laser_csv"]

LASER_QUANTITIES = {
    "t": Quantity("time", ("t", "time")),
    "outer": Quantity("length", ("d_outer", "outer", "outer_distance")),
    "inner": Quantity("length", ("d_inner", "inner", "inner_distance")),
}
"""The keys of a laser recording and the header names mapped without being told."""


def read_laser_csv(
    path: str | Path,
    *,
    outer_col: str = "d_outer_mm",
    inner_col: str = "d_inner_mm",
    scale_m: float = 1e-3,
    t_col: str = "t_s",
    columns: str | dict | None = None,
) -> pd.DataFrame:
    """Read two laser channels (default in mm) into ``t_s``, ``d_outer_m``, ``d_inner_m``.

    Parameters
    ----------
    path : str or Path
        CSV (or Parquet) with time and two distance columns.
    outer_col : str
        Column of the outer sensor.
    inner_col : str
        Column of the inner sensor.
    scale_m : float
        Metres per unit of the distance columns (1e-3: mm) [m].
    t_col : str
        Time column [s].
    columns : str or dict, optional
        ``t=HEADER[:unit],outer=…,inner=…`` or ``"auto"``
        (:func:`gripsense.io.table.map_table`): replaces the ``*_col`` and ``scale_m``
        arguments. ``None`` with the default arguments is the same as ``"auto"``.

    Returns
    -------
    pandas.DataFrame
        ``t_s`` [s], ``d_outer_m``, ``d_inner_m`` [m]; ``attrs["columns"]`` the mapping used.
    """
    path = Path(path)
    df = read_table(path)
    legacy = (outer_col, inner_col, scale_m, t_col) != ("d_outer_mm", "d_inner_mm", 1e-3, "t_s")
    if columns is None and legacy:
        columns = {"t": (t_col, 1.0), "outer": (outer_col, scale_m), "inner": (inner_col, scale_m)}
    v, spec = map_table(
        df,
        path,
        LASER_QUANTITIES,
        columns,
        required=("t", "outer", "inner"),
        example="t=t_s:s,outer=d_outer_mm:mm,inner=d_inner_mm:mm",
    )
    out = pd.DataFrame({"t_s": v["t"], "d_outer_m": v["outer"], "d_inner_m": v["inner"]})
    bad = out.isna().any(axis=1)
    if bad.any():
        row = int(np.flatnonzero(bad.to_numpy())[0])
        lines = df.attrs.get("line")
        where = f"line {int(lines[row])}" if lines is not None else f"row {row + 1}"
        raise InputError(f"{path}: {where}: a value is missing")
    out.attrs["columns"] = spec
    return out
