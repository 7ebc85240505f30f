"""Accelerometer logs (the thesis's Arduino serial output turned CSV) for ``gripsense brake-mu``."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from gripsense.constants import G0
from gripsense.errors import InputError
from gripsense.io.table import (
    ACCEL_LIMIT,
    ACCEL_TYPICAL,
    Quantity,
    channel_rows,
    map_table,
    read_table,
)

__all__ = ["ACCEL_QUANTITIES", "read_accel_csv"]

ACCEL_QUANTITIES = {
    "t": Quantity("time", ("t", "time", "timestamp")),
    **{
        k: Quantity("acceleration", names, ACCEL_LIMIT, ACCEL_TYPICAL,
                    meaning="a vehicle's accelerometer")
        for k, names in (
            ("ax", ("ax", "a_x", "acc_x", "accel_x")),
            ("ay", ("ay", "a_y", "acc_y", "accel_y")),
            ("az", ("az", "a_z", "acc_z", "accel_z")),
        )
    },
}  # fmt: skip
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
        ``ax_sign`` and ``time_scale`` arguments (which are used when it is None).

    Returns
    -------
    pandas.DataFrame
        ``t_s`` [s], ``ax``, ``ay``, ``az`` [m/s^2] (NaN when a column is not given or a row
        leaves it empty): the rows that carry ``ax`` (any subset of the columns may be mapped;
        a row without ``ax`` is counted in ``attrs["rows"]``, not used; a row whose values have
        no time, or a mapped column without any value, is an error naming the file, line and
        column — :func:`gripsense.io.table.channel_rows`); ``attrs["columns"]`` holds the
        mapping used.
    """
    path = Path(path)
    if columns is None:  # the old per-column arguments, as a mapping with factors to SI
        if units not in ("g", "mps2"):
            raise InputError(f"units={units!r}; use 'g' or 'mps2'")
        if ax_sign not in (1.0, -1.0):
            raise InputError(f"--ax-sign {ax_sign:g}: use 1 (x forward) or -1 (x backwards)")
        if not 1e-9 <= time_scale <= 1e3:
            raise InputError(
                f"--time-scale {time_scale:g}: seconds per time unit, e.g. 1 (s) or 0.001 (ms)"
            )
        k = G0 if units == "g" else 1.0
        old = {"t": (t_col, time_scale), "ax": (ax_col, k * ax_sign), "ay": (ay_col, k)}
        columns = {key: cf for key, cf in {**old, "az": (az_col, k)}.items() if cf[0] is not None}
    df = read_table(path)
    rejected: dict[str, np.ndarray] = {}
    v, spec = map_table(
        df, path, ACCEL_QUANTITIES, columns, required=("t", "ax"), example="t=HEADER:s,ax=HEADER:g",
        rejected=rejected,
    )  # fmt: skip
    keep, acc = channel_rows(df, path, v, spec, needed=("ax",), rejected=rejected)
    nan = np.full(len(df), np.nan)
    res = pd.DataFrame(
        {"t_s": v["t"], "ax": v["ax"], "ay": v.get("ay", nan), "az": v.get("az", nan)}
    )[keep]
    res = res.sort_values("t_s", kind="stable").reset_index(drop=True)
    res.attrs["columns"] = spec
    res.attrs["rows"] = acc
    return res
