"""Two-laser camber recordings (seed 002 Fig. 3) for ``gripsense camber``."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from gripsense.errors import InputError
from gripsense.io.table import Quantity, map_table, read_table

__all__ = ["LASER_QUANTITIES", "read_laser_csv"]

LASER_LIMIT = 10.0
"""The largest distance a wheel-carrier laser reads to the road [m]."""

LASER_QUANTITIES = {
    "t": Quantity("time", ("t", "time")),
    "outer": Quantity("length", ("d_outer", "outer", "outer_distance"), LASER_LIMIT,
                      meaning="a laser's distance to the road"),
    "inner": Quantity("length", ("d_inner", "inner", "inner_distance"), LASER_LIMIT,
                      meaning="a laser's distance to the road"),
}  # fmt: skip
"""The keys of a laser recording, the header names mapped without being told and the largest
distance (:class:`gripsense.io.table.Quantity`)."""


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
        ``t_s`` [s], ``d_outer_m``, ``d_inner_m`` [m]; ``attrs["columns"]`` the mapping used;
        ``attrs["rows"]``: ``rows``, ``rows_used``, ``rows_not_finite`` and ``note`` — a row
        with a value that is not a finite number (``inf``) is rejected and counted, never
        turned into a camber; a missing value, or a distance beyond what the declared unit makes
        plausible (:data:`LASER_LIMIT`), is an error naming the file, line and column.
    """
    path = Path(path)
    df = read_table(path)
    legacy = (outer_col, inner_col, scale_m, t_col) != ("d_outer_mm", "d_inner_mm", 1e-3, "t_s")
    if columns is None and legacy:
        columns = {"t": (t_col, 1.0), "outer": (outer_col, scale_m), "inner": (inner_col, scale_m)}
    rejected: dict[str, np.ndarray] = {}
    v, spec = map_table(
        df,
        path,
        LASER_QUANTITIES,
        columns,
        required=("t", "outer", "inner"),
        example="t=t_s:s,outer=d_outer_mm:mm,inner=d_inner_mm:mm",
        rejected=rejected,
    )
    out = pd.DataFrame({"t_s": v["t"], "d_outer_m": v["outer"], "d_inner_m": v["inner"]})
    not_finite = np.zeros(len(out), bool)
    for m in rejected.values():
        not_finite |= m
    lines = df.attrs.get("line")

    def where(row: int) -> str:
        return f"line {int(lines[row])}" if lines is not None else f"row {row + 1}"

    bad = out.isna().any(axis=1).to_numpy() & ~not_finite
    if bad.any():
        row = int(np.flatnonzero(bad)[0])
        raise InputError(f"{path}: {where(row)}: a value is missing")
    n_bad = int(not_finite.sum())
    if n_bad and n_bad == len(out):
        raise InputError(
            f"{path}: no row with finite numbers (the first inf at {where(0)}); correct the values"
        )
    note = ""
    if n_bad:
        cols = ", ".join(_header(spec, k) for k, m in rejected.items() if m.any())
        note = (
            f"{path.name}: {n_bad} of {len(out)} rows with a value that is not a finite number "
            f"(inf) in {cols}: rejected, not used (the first at "
            f"{where(int(np.flatnonzero(not_finite)[0]))})"
        )
    out = out[~not_finite].reset_index(drop=True)
    out.attrs["columns"] = spec
    out.attrs["rows"] = {
        "rows": len(df),
        "rows_used": len(out),
        "rows_not_finite": n_bad,
        "note": note,
    }
    return out


def _header(spec: dict, key: str) -> str:
    v = spec.get(key, key)
    return str(v[0]) if isinstance(v, tuple) else str(v).lstrip("-").rsplit(":", 1)[0]
