"""Aggregation per H3 cell and time bucket with DuckDB over the fleet's partitioned Parquet."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pandas as pd

from gripsense.constants import Z90
from gripsense.physics.surface import slippery_call, surface_class_interval

__all__ = [
    "CELL_COLUMNS",
    "STATUS_INCONSISTENT",
    "aggregate_cells",
    "cells_geojson",
    "write_geojson",
]

STATUS_INCONSISTENT = "inconsistent: estimate below the measured grip"
"""Status of a cell whose estimate lies below the grip its data prove (``mu`` is kept for
diagnosis, but the map, the surface class and the slippery call use the measured grip only)."""

CELL_COLUMNS = [
    "cell",
    "bucket",
    "mu",
    "mu_sigma",
    "mu_low",
    "mu_high",
    "grip_used",
    "grip_used_lower",
    "status",
    "surface",
    "slippery",
    "n_estimates",
    "n_rows",
    "n_vehicles",
    "n_passes",
    "last_update",
]


def aggregate_cells(outdir: str | Path, *, bucket: str = "1 hour") -> pd.DataFrame:
    """Combine the estimates in ``outdir/epochs/`` per cell and time bucket.

    Within one pass (log) the overlapping windows share their errors, so they are averaged by
    inverse variance but keep the pass's median σ; passes are independent and are combined by
    inverse variance (σ = (Σ 1/σ_p²)^(−½)). Also counts of estimates, vehicles and
    passes (logs), and the last update.

    Two kinds of number (``docs/physics.md`` §14): ``mu``/``mu_sigma``/``mu_low``/``mu_high``
    are the model-based estimate; ``grip_used`` (the largest measured grip) and
    ``grip_used_lower`` (the largest model-free bound: "the data prove μ ≥ …", a bound holds
    whatever the others say) are measured.

    Parameters
    ----------
    outdir : path
        Fleet output folder.
    bucket : str
        DuckDB interval of the time buckets (``"1 hour"``, ``"15 minutes"``, ``"1 day"``).

    Returns
    -------
    pandas.DataFrame
        ``cell, bucket, mu, mu_sigma, mu_low, mu_high, grip_used, grip_used_lower, status
        (``estimate``, ``measured grip only``, :data:`STATUS_INCONSISTENT` or ``no data``;
        ``mu_low`` is at least ``grip_used_lower``, as in a drive), surface, slippery
        (``slippery``/``not slippery``/``unknown``), n_estimates, n_rows, n_vehicles,
        n_passes, last_update``.
    """
    import duckdb

    pattern = str(Path(outdir) / "epochs" / "**" / "*.parquet")
    if not list((Path(outdir) / "epochs").glob("**/*.parquet")):
        return pd.DataFrame(columns=CELL_COLUMNS)
    con = duckdb.connect()
    con.execute("SET TimeZone = 'UTC'")
    # windows of one pass overlap and share their errors (heading bias, tyre stiffness): they are
    # combined within the pass without shrinking the uncertainty (σ = median σ of the pass);
    # passes are independent and combined by inverse variance
    q = f"""
        WITH r AS (
            SELECT *, time_bucket(INTERVAL '{bucket}', CAST(time_utc AS TIMESTAMPTZ)) AS bucket
            FROM read_parquet('{pattern}', hive_partitioning = true, union_by_name = true)
        ), passes AS (
            SELECT cell, bucket, vehicle, log,
                   SUM(mu / (mu_sigma * mu_sigma)) FILTER (WHERE observable AND mu_sigma > 0)
                     / SUM(1 / (mu_sigma * mu_sigma)) FILTER (WHERE observable AND mu_sigma > 0)
                     AS mu_p,
                   MEDIAN(mu_sigma) FILTER (WHERE observable AND mu_sigma > 0) AS sigma_p,
                   MAX(grip_used_lower) AS bound_p,
                   MAX(grip_used) AS grip_p,
                   COUNT(*) FILTER (WHERE observable) AS n_est,
                   COUNT(*) AS n_rows,
                   MAX(time_utc) AS last_t
            FROM r GROUP BY ALL
        )
        SELECT cell, bucket,
               SUM(mu_p / (sigma_p * sigma_p)) / SUM(1 / (sigma_p * sigma_p)) AS mu,
               1 / sqrt(SUM(1 / (sigma_p * sigma_p))) AS mu_sigma,
               MAX(grip_p) AS grip_used,
               MAX(bound_p) AS grip_used_lower,
               SUM(n_est) AS n_estimates,
               SUM(n_rows) AS n_rows,
               COUNT(DISTINCT vehicle) AS n_vehicles,
               COUNT(DISTINCT log) AS n_passes,
               MAX(last_t) AS last_update
        FROM passes GROUP BY ALL
        ORDER BY cell, bucket
    """
    df = con.sql(q).to_arrow_table().to_pandas()
    con.close()
    for c in ("n_estimates", "n_rows", "n_vehicles", "n_passes"):
        df[c] = df[c].fillna(0).astype("int64")
    bound = df["grip_used_lower"].to_numpy(float)
    # a drive's rule: an estimate's lower end is at least what the data prove (no estimate: NaN)
    df["mu_low"] = np.fmax(np.maximum(df["mu"] - Z90 * df["mu_sigma"], 0.0), bound)
    df.loc[df["mu"].isna(), "mu_low"] = np.nan
    df["mu_high"] = df["mu"] + Z90 * df["mu_sigma"]
    has = df["mu"].notna().to_numpy()
    # an estimate below the grip the data prove contradicts them: flagged, never a plain value
    bad = has & (df["mu"].to_numpy(float) < np.nan_to_num(bound, nan=-np.inf))
    df["status"] = np.where(
        bad,
        STATUS_INCONSISTENT,
        np.where(
            has,
            "estimate",
            np.where(df["grip_used_lower"].notna(), "measured grip only", "no data"),
        ),
    )
    ok = has & ~bad
    df["surface"] = [
        surface_class_interval(lo, hi) if h else "undetermined"
        for lo, hi, h in zip(df["mu_low"], df["mu_high"], ok, strict=True)
    ]
    df["surface"] = df["surface"].astype(str)
    # "is it slippery?": the cell's range (only the measured grip where it is inconsistent)
    hi = np.where(bad, np.inf, df["mu_high"].to_numpy(float))
    lo = np.where(bad, bound, np.fmax(df["mu_low"].to_numpy(float), bound))
    df["slippery"] = np.asarray(slippery_call(lo, hi), dtype=str)
    return df[CELL_COLUMNS]


def cells_geojson(cells: pd.DataFrame) -> dict:
    """GeoJSON FeatureCollection of the latest bucket per cell (hexagon polygons).

    Parameters
    ----------
    cells : pandas.DataFrame
        Cell table of :func:`aggregate_cells`.
    """
    import h3

    latest = cells.sort_values("bucket").groupby("cell", sort=False).tail(1)
    feats = []
    for r in latest.to_dict("records"):
        ring = [[lon, lat] for lat, lon in h3.cell_to_boundary(r["cell"])]
        ring.append(ring[0])
        props = {}
        for k, v in r.items():
            if isinstance(v, float) and not np.isfinite(v):
                v = None
            elif isinstance(v, pd.Timestamp):
                v = None if pd.isna(v) else v.isoformat()
            elif isinstance(v, np.integer):
                v = int(v)
            elif isinstance(v, np.floating):
                v = float(v)
            props[k] = v
        feats.append(
            {
                "type": "Feature",
                "geometry": {"type": "Polygon", "coordinates": [ring]},
                "properties": props,
            }
        )
    return {"type": "FeatureCollection", "features": feats}


def write_geojson(cells: pd.DataFrame, path: str | Path) -> Path:
    """Write :func:`cells_geojson` to *path*."""
    path = Path(path)
    path.write_text(json.dumps(cells_geojson(cells)))
    return path
