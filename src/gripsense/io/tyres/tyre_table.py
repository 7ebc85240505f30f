"""Tyre measurement tables (slip angle, camber, load, lateral force) for ``gripsense tyre fit``.

Default columns (CSV with ``#`` comments, or Parquet):

===========  =========================================================  ==============
column       meaning                                                    unit
===========  =========================================================  ==============
alpha_rad    slip angle, ISO-W (or ``alpha_deg``)                       rad (deg)
gamma_rad    camber (inclination) angle, ISO-W (or ``gamma_deg``);      rad (deg)
             optional, 0 when absent
fz_N         vertical load, positive                                    N
fy_N         lateral force, ISO-W (negative for positive α)             N
===========  =========================================================  ==============

The friction pipeline's ``wheels.parquet`` (``slip_angle_rad``, ``load_N``, ``force_N``) is
recognised and read as road data (camber 0).

Other layouts: the one column convention of every command (:func:`gripsense.io.table.map_table`):
headers with a known name and unit suffix are mapped by themselves (``alpha_deg``, ``sa_deg``,
``ia_deg``, ``fz_kN``, ``fy_N`` …), or ``--columns alpha=SA:deg,gamma=IA:deg,fz=-FZ:N,fy=FY:N``
(keys ``alpha``, ``gamma``, ``fz``, ``fy``; units ``deg``, ``rad``, ``N``, ``kN``, ``lbf``; a
leading ``-`` flips the sign). Calspan TTC exports use SAE-type axes: FZ is negative under load
(hence ``fz=-FZ``) and the slip-angle and force signs differ from ISO-W between data releases —
check the slope sign gripsense prints (ISO-W expects Fy < 0 for α > 0 with the usual
coefficients).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from gripsense.io.table import Quantity, map_table, read_table

__all__ = ["TYRE_KEYS", "TYRE_QUANTITIES", "read_tyre_table"]

TYRE_QUANTITIES = {
    "alpha": Quantity("angle", ("alpha", "sa", "slip_angle")),
    "gamma": Quantity("angle", ("gamma", "ia", "camber", "inclination")),
    "fz": Quantity("force", ("fz", "load")),
    "fy": Quantity("force", ("fy",)),
}
"""The keys of a tyre table and the header names mapped without being told."""
TYRE_KEYS = tuple(TYRE_QUANTITIES)


def read_tyre_table(
    path: str | Path, columns: str | dict | None = None
) -> tuple[pd.DataFrame, dict]:
    """Read a tyre measurement table.

    Parameters
    ----------
    path : path
        CSV or Parquet file.
    columns : str or dict, optional
        Column mapping (module documentation); default: headers with a known name and unit
        suffix (``alpha_deg``, ``fz_N`` …).

    Returns
    -------
    table : pandas.DataFrame
        ``alpha_rad``, ``gamma_rad``, ``fz_N``, ``fy_N`` (rows with a value that is not a number
        are dropped and counted).
    info : dict
        ``rows``, ``rows_used``, ``rejected`` (reason -> count), ``source`` (``table`` or
        ``wheels``: the friction pipeline's wheel table), ``columns`` (the mapping used).
    """
    path = Path(path)
    df = read_table(path)
    if columns is None and {"slip_angle_rad", "load_N", "force_N"} <= set(df.columns):
        return df, {"rows": len(df), "source": "wheels"}
    v, spec = map_table(
        df,
        path,
        TYRE_QUANTITIES,
        columns,
        required=("alpha", "fz", "fy"),
        example="alpha=SA:deg,gamma=IA:deg,fz=-FZ:N,fy=FY:N",
        non_numeric="nan",
    )
    out = {}
    rejected: dict[str, int] = {}
    ok = np.ones(len(df), bool)
    for key, values in v.items():
        bad = np.isnan(values)
        if bad.any():
            rejected[f"{key}_not_a_number"] = int((bad & ok).sum())
        ok &= ~bad
        out[f"{key}_{'rad' if key in ('alpha', 'gamma') else 'N'}"] = values
    if "gamma" not in v:
        out["gamma_rad"] = np.zeros(len(df))
    t = pd.DataFrame(out)[["alpha_rad", "gamma_rad", "fz_N", "fy_N"]]
    nonpos = ok & ~(t["fz_N"].to_numpy() > 0)
    if nonpos.any():
        rejected["fz_not_positive"] = int(nonpos.sum())
        ok &= ~nonpos
    return t[ok].reset_index(drop=True), {
        "rows": len(df),
        "rows_used": int(ok.sum()),
        "rejected": {k: n for k, n in rejected.items() if n},
        "source": "table",
        "columns": spec,
    }
