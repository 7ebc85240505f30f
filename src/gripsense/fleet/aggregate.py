"""Aggregation per H3 cell and time bucket: DuckDB over the fleet's partitioned Parquet, and
every pass's statement combined (:mod:`gripsense.estimate.evidence`).
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pandas as pd
from scipy.stats import chi2

from gripsense.constants import CHI2_1_90, Z90
from gripsense.errors import InputError
from gripsense.estimate.evidence import (
    CONTRADICTION_TOL,
    curve_grid,
    curve_range,
    curves_from_bytes,
    gaussian_curves,
    reduce_groups,
)
from gripsense.estimate.options import WindowOptions
from gripsense.estimate.profile import STRAINED_REL
from gripsense.physics.surface import UNDETERMINED, slippery_call, surface_class_interval

__all__ = [
    "CELL_COLUMNS",
    "MAX_LISTED_PASSES",
    "STATUS_CONTRADICTION",
    "STATUS_ESTIMATE",
    "STATUS_INCONSISTENT",
    "STATUS_MEASURED",
    "STATUS_RANGE",
    "aggregate_cells",
    "cells_geojson",
    "check_bucket",
    "write_geojson",
]

STATUS_ESTIMATE = "estimate"
"""A cell with a value: its combined 99 % range is bounded and narrow (the rule of a drive)."""

STATUS_RANGE = "range"
"""A cell with a bounded 90 % range but no value (e.g. one vehicle proves μ ≥ 0.70 and another's
slip bounds it ≤ 0.85: "μ in [0.70, 0.85]")."""

STATUS_MEASURED = "measured grip only"
"""A cell whose statements bound μ from below only (the measured grip)."""

STATUS_INCONSISTENT = "inconsistent: estimate below the measured grip"
"""Status of a cell whose combined model range lies below the grip its data prove (the map, the
surface class and the slippery call use the measured grip only)."""

STATUS_CONTRADICTION = "contradiction: no μ lies in every pass's range"
"""Status of a cell whose statements contradict each other: no μ at or above the measured grip
lies inside every window's (or pass's) own 90 % range. Flagged, never combined into a number
none of them supports; the measured grip stays."""

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
    "n_statements",
    "last_update",
    "passes",
]

MAX_LISTED_PASSES = 12
"""Passes listed per cell in ``passes`` (the map's popup); the rest are counted."""


def check_bucket(bucket: str) -> str:
    """A time bucket as DuckDB reads it, or one line saying how to write one.

    Parameters
    ----------
    bucket : str
        The interval (``"1 hour"``, ``"15 minutes"``, ``"1 day"``) [-].

    Returns
    -------
    str
        *bucket*, checked: a positive interval DuckDB reads.

    Raises
    ------
    InputError
        When DuckDB does not read it as an interval, or it is not positive.
    """
    import duckdb

    fix = "give a positive interval, e.g. '15 minutes', '1 hour', '1 day'"
    try:
        with duckdb.connect() as con:
            row = con.execute("SELECT epoch(CAST(? AS INTERVAL))", [str(bucket)]).fetchone()
        seconds = None if row is None else row[0]
    except duckdb.Error:
        raise InputError(f"--bucket {bucket!r}: not a time interval; {fix}") from None
    if not seconds or seconds <= 0:
        raise InputError(f"--bucket {bucket!r}: not a positive interval; {fix}")
    return str(bucket)


def _read(con, pattern: str, bucket: str) -> None:
    """The rows as view ``r`` with their time bucket, their curve (NULL in files written
    before curves were) and their nuisance group (the tyres their likelihood used).
    """
    src = f"read_parquet('{pattern}', hive_partitioning = true, union_by_name = true)"
    cols = {row[0] for row in con.sql(f"DESCRIBE SELECT * FROM {src}").fetchall()}
    curve = "mu_deviance" if "mu_deviance" in cols else "CAST(NULL AS BLOB)"
    # whose tyre nuisances a statement carries (tasks.tyres_digest; earlier files: its vehicle's)
    own = "'vehicle:' || CAST(vehicle AS VARCHAR)"
    grp = f"COALESCE(tyres, {own})" if "tyres" in cols else own
    literal = bucket.replace("'", "''")  # an SQL string literal (check_bucket read it)
    con.execute(
        f"""CREATE TEMP VIEW r AS
            SELECT *, {curve} AS curve, {grp} AS nuisance_group,
                   time_bucket(INTERVAL '{literal}', CAST(time_utc AS TIMESTAMPTZ)) AS bucket
            FROM {src}"""
    )


def aggregate_cells(
    outdir: str | Path, *, bucket: str = "1 hour", options: WindowOptions | None = None
) -> pd.DataFrame:
    """Combine every pass's statement per cell and time bucket (``docs/fleet.md``,
    :mod:`gripsense.estimate.evidence`).

    Each row carries its statement as a deviance curve on the μ grid (``axle-window``); a
    per-sample method's pass states its inverse-variance mean with the pass's median σ. The
    statements of one vehicle share its tyre and model-form nuisances: its curve is their
    pointwise largest deviance (every statement holds; one long drive says no less than its
    passes) — and so do those of cars described by one declared tyre without a calibration of
    their own (``tyres``, :func:`~gripsense.fleet.tasks.tyres_digest`). Vehicles on tyres of their
    own are independent: their curves add. The cell's range is where the sum is
    within the 90 % level of its minimum, never below the measured grip; a value where the 99 %
    range is bounded, at most ``max_width`` wide and its upper end within 1 / min_utilisation
    of the measured grip (a drive's rule). Statements none of whose ranges all meet are a
    contradiction (flagged, no range); a combined range below the measured grip is inconsistent.

    Two kinds of number (``docs/physics.md`` §14): ``mu``/``mu_sigma``/``mu_low``/``mu_high``
    are the model-based estimate; ``grip_used`` (the largest measured grip) and
    ``grip_used_lower`` (the largest model-free bound: "the data prove μ ≥ …", a bound holds
    whatever the others say) are measured.

    Parameters
    ----------
    outdir : path
        Fleet output folder.
    bucket : str
        DuckDB interval of the time buckets (``"1 hour"``, ``"15 minutes"``, ``"1 day"``); each
        bucket combines its own passes only.
    options : WindowOptions, optional
        The windows' options (μ grid, levels, rules for a value); default as the fleet's runs.

    Returns
    -------
    pandas.DataFrame
        :data:`CELL_COLUMNS`: ``cell, bucket``; ``mu`` (NaN without a value), ``mu_sigma``
        (the range's half-width / 1.645 where there is a value), ``mu_low`` (≥
        ``grip_used_lower``), ``mu_high`` (``inf`` when unbounded; NaN when flagged);
        ``grip_used``, ``grip_used_lower``; ``status`` (:data:`STATUS_ESTIMATE`,
        :data:`STATUS_RANGE`, :data:`STATUS_MEASURED`, :data:`STATUS_INCONSISTENT`,
        :data:`STATUS_CONTRADICTION` or ``no data``); ``surface``; ``slippery``
        (``slippery``/``not slippery``/``unknown``); counts of estimates (rows with a value),
        rows, vehicles, passes and statements (rows and passes with a curve);
        ``last_update``; ``passes`` (JSON: each pass's own statement in the cell — vehicle,
        log, mu_low, mu_high, grip_used_lower — at most :data:`MAX_LISTED_PASSES`, then a
        count).
    """
    check_bucket(bucket)
    import duckdb

    o = options or WindowOptions()
    pattern = str(Path(outdir) / "epochs" / "**" / "*.parquet")
    if not list((Path(outdir) / "epochs").glob("**/*.parquet")):
        return pd.DataFrame(columns=CELL_COLUMNS)
    con = duckdb.connect()
    try:
        con.execute("SET TimeZone = 'UTC'")
        _read(con, pattern, bucket)
        # per pass: its measured grip, counts, and — for a per-sample method (rows without
        # curves) — its statement: the inverse-variance mean with the pass's median σ (its
        # samples share their errors)
        passes = con.sql(
            """
            SELECT cell, bucket, vehicle, log, nuisance_group,
                   SUM(mu / (mu_sigma * mu_sigma))
                       FILTER (WHERE observable AND mu_sigma > 0 AND curve IS NULL)
                     / SUM(1 / (mu_sigma * mu_sigma))
                       FILTER (WHERE observable AND mu_sigma > 0 AND curve IS NULL) AS mu_p,
                   MEDIAN(mu_sigma)
                       FILTER (WHERE observable AND mu_sigma > 0 AND curve IS NULL) AS sigma_p,
                   MAX(grip_used_lower) AS bound_p,
                   MAX(grip_used) AS grip_p,
                   COUNT(*) FILTER (WHERE observable) AS n_est,
                   COUNT(*) AS n_rows,
                   COUNT(curve) AS n_curves,
                   MAX(time_utc) AS last_t
            FROM r WHERE cell IS NOT NULL GROUP BY ALL
            ORDER BY cell, bucket, vehicle, log, nuisance_group
            """
        ).df()
        rows = con.sql(
            "SELECT cell, bucket, vehicle, log, nuisance_group, curve FROM r "
            "WHERE curve IS NOT NULL AND cell IS NOT NULL"
        ).df()
    finally:
        con.close()
    return _cells(passes, rows, o)


def _cells(passes: pd.DataFrame, rows: pd.DataFrame, o: WindowOptions) -> pd.DataFrame:
    """The cell table from the per-pass summary and the rows' curves (:func:`aggregate_cells`)."""
    grid = curve_grid(o)
    keys = ["cell", "bucket", "vehicle", "log", "nuisance_group"]
    for c in ("n_est", "n_rows", "n_curves"):
        passes[c] = passes[c].fillna(0).astype("int64")
    passes["pass_id"] = np.arange(len(passes))
    # every statement: the rows' curves, and the per-sample passes' Gaussian ones
    rid = rows.merge(passes[[*keys, "pass_id"]], on=keys, how="left")["pass_id"].to_numpy()
    gauss = passes[passes["mu_p"].notna() & (passes["sigma_p"] > 0)]
    curves = np.concatenate(
        [
            curves_from_bytes(rows["curve"], grid.size),
            gaussian_curves(gauss["mu_p"].to_numpy(float), gauss["sigma_p"].to_numpy(float), grid),
        ]
    )
    owner = np.concatenate([rid, gauss["pass_id"].to_numpy()]).astype(np.int64)
    n_stat = np.bincount(owner, minlength=len(passes))
    # each statement's own 90 % range: do they all meet?
    s_lo, s_hi, _ = curve_range(curves, grid, CHI2_1_90)
    cell_id = passes.groupby(["cell", "bucket"], sort=True).ngroup().to_numpy()
    veh_id = passes.groupby(["cell", "bucket", "nuisance_group"], sort=True).ngroup().to_numpy()
    n_cells = int(cell_id.max()) + 1 if len(passes) else 0
    st_cell = cell_id[owner]
    max_lo = np.full(n_cells, -np.inf)
    min_hi = np.full(n_cells, np.inf)
    np.maximum.at(max_lo, st_cell, s_lo)
    np.minimum.at(min_hi, st_cell, s_hi)
    # one pass: its statements all hold; statements on the same tyres (one vehicle's, or cars
    # sharing one declared tyre without a calibration of their own): all hold; the rest add
    p_ids, p_curves = reduce_groups(curves, owner, "max")
    v_ids, v_curves = reduce_groups(p_curves, veh_id[p_ids], "max")
    c_ids, c_curves = reduce_groups(v_curves, _first(cell_id, veh_id)[v_ids], "sum")

    g = passes.groupby(cell_id)
    df = pd.DataFrame(
        {
            "cell": g["cell"].first().to_numpy(),
            "bucket": g["bucket"].first().to_numpy(),
            "grip_used": g["grip_p"].max().to_numpy(float),
            "grip_used_lower": g["bound_p"].max().to_numpy(float),
            "n_estimates": g["n_est"].sum().to_numpy(),
            "n_rows": g["n_rows"].sum().to_numpy(),
            "n_vehicles": g["vehicle"].nunique().to_numpy(),
            "n_passes": g["log"].count().to_numpy(),
            "n_statements": np.bincount(cell_id, weights=n_stat, minlength=n_cells).astype("int64"),
            "last_update": g["last_t"].max().to_numpy(),
        }
    )
    has = np.zeros(n_cells, bool)
    has[c_ids] = True
    bound = df["grip_used_lower"].to_numpy(float)
    b0 = np.nan_to_num(bound, nan=0.0)
    mu_low, mu_high, value, hi_raw = _statement(c_curves, c_ids, n_cells, b0, o, grid)
    contra = has & (max_lo > min_hi + CONTRADICTION_TOL)
    below = has & ~contra & (np.minimum(hi_raw, min_hi) < b0 - CONTRADICTION_TOL)
    flagged = contra | below
    value &= ~flagged
    mu_high = np.where(flagged, np.inf, mu_high)
    df["mu_low"] = np.where(flagged, np.nan, mu_low)
    df["mu_high"] = np.where(flagged, np.nan, mu_high)
    with np.errstate(invalid="ignore"):
        df["mu"] = np.where(value, np.sqrt(mu_low * mu_high), np.nan)
        df["mu_sigma"] = np.where(value, (mu_high - mu_low) / (2 * Z90), np.nan)
    bounded = ~flagged & np.isfinite(mu_high)
    n_rows = df["n_rows"].to_numpy()
    df["status"] = np.select(
        [contra, below, value, bounded, np.isfinite(bound), n_rows > 0],
        [STATUS_CONTRADICTION, STATUS_INCONSISTENT, STATUS_ESTIMATE, STATUS_RANGE,
         STATUS_MEASURED, STATUS_MEASURED],
        default="no data",
    )  # fmt: skip
    df["surface"] = np.where(
        bounded, surface_class_interval(mu_low, np.where(bounded, mu_high, np.nan)), UNDETERMINED
    ).astype(str)
    # "is it slippery?" is answered by what stands with any one window left out (one window at a
    # turn-in can state an upper end far below the truth: the call needs a second statement),
    # or by what the data prove where the cell is flagged
    rob = c_curves - _largest_single(curves, veh_id[owner], _first(cell_id, veh_id))
    r_low, r_high, _, _ = _statement(rob, c_ids, n_cells, b0, o, grid)
    df["slippery"] = np.asarray(
        slippery_call(np.where(flagged, b0, r_low), np.where(flagged, np.inf, r_high)), str
    )
    df["passes"] = _pass_lists(passes, p_ids, p_curves, cell_id, grid, n_cells)
    return df[CELL_COLUMNS]


def _statement(curves, c_ids, n_cells, b0, o: WindowOptions, grid):
    """A cell's range from its combined curve (rows *c_ids*; the others have none): its 90 %
    ends, the measured grip *b0* as the lower end unless a value is given (a drive's rule: the
    99 % range bounded by the model on both sides, at most ``max_width`` wide, its upper end
    within 1 / ``min_utilisation`` of the measured grip), an upper end that reaches the
    measured grip dropped (strained). Returns mu_low, mu_high, value and the upper end before
    that drop.
    """
    hi, lo_m, hi_p, lo_p = (np.full(n_cells, np.inf) for _ in range(4))
    lo_m[c_ids], hi[c_ids], _ = curve_range(curves, grid, CHI2_1_90)
    point = float(chi2.ppf(float(o.point_level), 1))
    lo_p[c_ids], hi_p[c_ids], _ = curve_range(curves, grid, point)
    has = np.zeros(n_cells, bool)
    has[c_ids] = True
    hi_raw = hi.copy()
    hi = np.where(hi <= (1.0 + STRAINED_REL) * b0, np.inf, hi)
    with np.errstate(invalid="ignore"):
        value = (
            has & (lo_p > grid[0]) & np.isfinite(hi_p) & np.isfinite(hi)
            & (hi_p - np.fmax(lo_p, b0) <= o.max_width) & (hi * o.min_utilisation <= b0)
        )  # fmt: skip
    mu_low = np.where(value, np.fmax(lo_m, b0), b0)
    return mu_low, np.where(has, hi, np.inf), value, hi_raw


def _largest_single(p_curves, p_group, g_cell) -> np.ndarray:
    """Per cell (rows in the order of the cells that have curves), pointwise, the most any one
    statement adds to the combined curve: in each nuisance group the gap between its largest
    statement curve and its second largest (a group's curve is their maximum), the largest gap
    over the cell's groups. The combined curve minus it is what stands with any one statement
    left out.
    """
    order = np.argsort(p_group, kind="stable")
    pg, pc = p_group[order], p_curves[order]
    groups, start, inverse = np.unique(pg, return_index=True, return_inverse=True)
    d1 = np.maximum.reduceat(pc, start, axis=0)
    top = pc == d1[inverse]
    ties = np.add.reduceat(top.astype(np.int32), start, axis=0)
    d2 = np.maximum.reduceat(np.where(top, 0, pc), start, axis=0)
    gap = d1 - np.where(ties >= 2, d1, d2)
    _, per_cell = reduce_groups(gap, g_cell[groups], "max")
    return per_cell


def _first(cell_id: np.ndarray, veh_id: np.ndarray) -> np.ndarray:
    """The cell of each vehicle group (indexed by the vehicle group's id)."""
    out = np.zeros(int(veh_id.max()) + 1 if veh_id.size else 0, np.int64)
    out[veh_id] = cell_id
    return out


def _pass_lists(passes, p_ids, p_curves, cell_id, grid, n_cells) -> list[str]:
    """Per cell, JSON of its passes' own statements (the popup's list)."""
    lo, hi = np.full(len(passes), np.nan), np.full(len(passes), np.inf)
    p_lo, p_hi, _ = curve_range(p_curves, grid, CHI2_1_90)
    lo[p_ids], hi[p_ids] = p_lo, p_hi
    bound = passes["bound_p"].to_numpy(float)
    lo = np.fmax(lo, bound)
    out: list[list[dict]] = [[] for _ in range(n_cells)]
    count = np.bincount(cell_id, minlength=n_cells)
    for i, (v, lg) in enumerate(zip(passes["vehicle"], passes["log"], strict=True)):
        lst = out[cell_id[i]]
        if len(lst) < MAX_LISTED_PASSES:
            lst.append(
                {
                    "vehicle": str(v),
                    "log": str(lg),
                    "mu_low": _num(lo[i]),
                    "mu_high": _num(hi[i]),
                    "grip_used_lower": _num(bound[i]),
                }
            )
    return [
        json.dumps({"listed": lst, "more": int(count[k] - len(lst))}) for k, lst in enumerate(out)
    ]


def _num(x: float) -> float | None:
    """A JSON number (None for NaN and inf: inf is spelled out by the reader)."""
    return round(float(x), 4) if np.isfinite(x) else None


def cells_geojson(cells: pd.DataFrame) -> dict:
    """GeoJSON FeatureCollection of the latest bucket per cell (hexagon polygons), with
    ``stale`` (the cell's latest bucket is older than the newest bucket of the run) and
    ``newest_bucket``.

    Parameters
    ----------
    cells : pandas.DataFrame
        Cell table of :func:`aggregate_cells`.
    """
    import h3

    latest = cells.sort_values("bucket").groupby("cell", sort=False).tail(1)
    newest = cells["bucket"].max() if len(cells) else None
    feats = []
    for r in latest.to_dict("records"):
        # older evidence is shown as older, never blended with newer (docs/fleet.md, "Time")
        r["stale"] = bool(newest is not None and r["bucket"] < newest)
        r["newest_bucket"] = newest
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
