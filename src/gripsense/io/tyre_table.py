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

Other layouts: ``--columns alpha=SA:deg,gamma=IA:deg,fz=-FZ,fy=FY`` (keys ``alpha``, ``gamma``,
``fz``, ``fy``; units ``deg``, ``rad``, ``N``, ``kN``, ``lbf``; a leading ``-`` flips the sign).
Calspan TTC exports use SAE-type axes: FZ is negative under load (hence ``fz=-FZ``) and the
slip-angle and force signs differ from ISO-W between data releases — check the slope sign
gripsense prints (ISO-W expects Fy < 0 for α > 0 with the usual coefficients).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from gripsense.errors import InputError
from gripsense.io.table import parse_columns, read_table

__all__ = ["TYRE_KEYS", "read_tyre_table"]

TYRE_KEYS = ("alpha", "gamma", "fz", "fy")
_UNITS = {"deg": np.pi / 180, "rad": 1.0, "N": 1.0, "kN": 1000.0, "lbf": 4.4482216152605}
_DEFAULTS = {
    "alpha": ("alpha_rad", "alpha_deg"),
    "gamma": ("gamma_rad", "gamma_deg"),
    "fz": ("fz_N", "fz_kN"),
    "fy": ("fy_N", "fy_kN"),
}
_DEFAULT_FACTORS = {
    "alpha_deg": np.pi / 180,
    "gamma_deg": np.pi / 180,
    "fz_kN": 1000.0,
    "fy_kN": 1000.0,
}


def read_tyre_table(
    path: str | Path, columns: str | dict | None = None
) -> tuple[pd.DataFrame, dict]:
    """Read a tyre measurement table.

    Parameters
    ----------
    path : path
        CSV or Parquet file.
    columns : str or dict, optional
        Column mapping (module documentation); default the standard column names.

    Returns
    -------
    table : pandas.DataFrame
        ``alpha_rad``, ``gamma_rad``, ``fz_N``, ``fy_N`` (rows with a value that is not a number
        are dropped and counted).
    info : dict
        ``rows``, ``rows_used``, ``rejected`` (reason -> count), ``source`` (``table`` or
        ``wheels``: the friction pipeline's wheel table).
    """
    path = Path(path)
    df = read_table(path)
    if columns is None and {"slip_angle_rad", "load_N", "force_N"} <= set(df.columns):
        return df, {"rows": len(df), "source": "wheels"}
    if columns is not None:
        m = parse_columns(columns, TYRE_KEYS, _UNITS)
    else:
        m = {}
        for key, names in _DEFAULTS.items():
            for n in names:
                if n in df.columns:
                    m[key] = (n, _DEFAULT_FACTORS.get(n, 1.0))
                    break
    for key in ("alpha", "fz", "fy"):
        if key not in m:
            raise InputError(
                f"{path}: no column for {key} (expected {' or '.join(_DEFAULTS[key])},"
                f" or map one with --columns {key}=NAME[:unit]); columns: "
                f"{list(df.columns)[:20]}"
            )
    out = {}
    rejected: dict[str, int] = {}
    ok = np.ones(len(df), bool)
    for key, (name, factor) in m.items():
        if name not in df.columns:
            raise InputError(
                f"{path}: column {name!r} for {key} not found; columns: {list(df.columns)[:20]}"
            )
        v = pd.to_numeric(df[name], errors="coerce")
        bad = v.isna().to_numpy()
        if bad.any():
            rejected[f"{key}_not_a_number"] = int((bad & ok).sum())
        ok &= ~bad
        out[f"{key}_{'rad' if key in ('alpha', 'gamma') else 'N'}"] = v.to_numpy(float) * factor
    if "gamma" not in m:
        out["gamma_rad"] = np.zeros(len(df))
    t = pd.DataFrame(out)[["alpha_rad", "gamma_rad", "fz_N", "fy_N"]]
    nonpos = ok & ~(t["fz_N"].to_numpy() > 0)
    if nonpos.any():
        rejected["fz_not_positive"] = int(nonpos.sum())
        ok &= ~nonpos
    return t[ok].reset_index(drop=True), {
        "rows": len(df),
        "rows_used": int(ok.sum()),
        "rejected": {k: v for k, v in rejected.items() if v},
        "source": "table",
    }
