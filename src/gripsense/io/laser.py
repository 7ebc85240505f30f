"""Two-laser camber recordings (seed 002 Fig. 3) for ``gripsense camber``."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from gripsense.errors import InputError
from gripsense.io.table import numeric_column, read_table

__all__ = ["read_laser_csv"]


def read_laser_csv(
    path: str | Path,
    *,
    outer_col: str = "d_outer_mm",
    inner_col: str = "d_inner_mm",
    scale_m: float = 1e-3,
    t_col: str = "t_s",
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
    """
    path = Path(path)
    df = read_table(path)
    for c in (t_col, outer_col, inner_col):
        if c not in df.columns:
            raise InputError(f"{path}: no column {c!r} (columns: {list(df.columns)})")
    out = pd.DataFrame(
        {
            "t_s": numeric_column(df, t_col, path),
            "d_outer_m": numeric_column(df, outer_col, path) * scale_m,
            "d_inner_m": numeric_column(df, inner_col, path) * scale_m,
        }
    )
    bad = out.isna().any(axis=1)
    if bad.any():
        row = int(np.flatnonzero(bad.to_numpy())[0])
        raise InputError(f"{path}: line {row + 2}: a value is missing")
    return out
