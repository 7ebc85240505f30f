"""One fleet task: a batch of logs → per-estimate rows with position and H3 cell, as Parquet.

Rows (one per estimate; schema :data:`ROW_COLUMNS`):

* ``axle-window`` (default, the calibrated estimator): one row per axle window — μ and its
  1σ from the 90 % interval when observable, the window's lower bound (calibrated: "bound ok"
  ≥ 99 % in the accuracy benchmark) always; placed at the epoch nearest the window's middle;
* per-sample methods (``brush-2`` …): one row per valid wheel sample (μ, σ_μ), plus per log and
  cell one bound row = the 95th percentile of the steady cornering utilisation (noisier than a
  window bound).

A log that cannot be read or analysed never fails the batch: it is returned as a problem with
its reason.
"""

from __future__ import annotations

import hashlib
import traceback
from pathlib import Path

import numpy as np
import pandas as pd

from gripsense.errors import GripsenseError
from gripsense.pipeline import Z90

__all__ = ["ROW_COLUMNS", "process_batch", "process_log"]

ROW_COLUMNS = [
    "vehicle",
    "log",
    "time_utc",
    "t_s",
    "lat_deg",
    "lon_deg",
    "cell",
    "unit",
    "observable",
    "mu",
    "mu_sigma",
    "mu_lower_bound",
    "utilisation",
]


def _cells(lat: np.ndarray, lon: np.ndarray, res: int) -> list[str]:
    import h3

    return [
        h3.latlng_to_cell(float(a), float(b), res) if np.isfinite(a) and np.isfinite(b) else None
        for a, b in zip(lat, lon, strict=True)
    ]


def process_log(
    path: str | Path,
    vehicle,
    *,
    vehicle_id: str,
    method: str = "axle-window",
    h3_res: int = 11,
    since: pd.Timestamp | None = None,
    receiver: str = "v100",
) -> pd.DataFrame:
    """Rows of one log (raises GripsenseError with the reason when it cannot be used)."""
    from gripsense.io import read_nmea
    from gripsense.pipeline import FrictionRun

    log = read_nmea(path)
    ep = log.epochs
    if ep.empty:
        raise GripsenseError(
            f"no epochs ({log.report.total_lines} lines, "
            f"{sum(log.report.rejected.values())} rejected)"
        )
    if since is not None:
        ep = ep[ep["time_utc"] >= since].reset_index(drop=True)
        if ep.empty:
            return pd.DataFrame(columns=ROW_COLUMNS)
    if not np.isfinite(ep["lat_deg"].to_numpy(float)).any():
        raise GripsenseError("no position fix in the log (GGA/RMC)")
    from gripsense.estimate.friction import NoiseModel

    noise = NoiseModel.rtk() if receiver == "rtk" else NoiseModel()
    res = FrictionRun(vehicle, method=method, noise=noise).run(ep)
    t = ep["t_s"].to_numpy(float)
    name = Path(path).name
    if method == "axle-window":
        w = res.windows
        if w is None or w.empty:
            return pd.DataFrame(columns=ROW_COLUMNS)
        mid = 0.5 * (w["t_start"].to_numpy(float) + w["t_end"].to_numpy(float))
        idx = np.clip(np.searchsorted(t, mid), 0, len(t) - 1)
        obs = w["observable"].to_numpy(bool)
        sig = (w["mu_high"].to_numpy(float) - w["mu_low"].to_numpy(float)) / (2 * Z90)
        rows = pd.DataFrame(
            {
                "time_utc": ep["time_utc"].to_numpy()[idx],
                "t_s": t[idx],
                "lat_deg": ep["lat_deg"].to_numpy(float)[idx],
                "lon_deg": ep["lon_deg"].to_numpy(float)[idx],
                "unit": w["axle"].astype(str),
                "observable": obs,
                "mu": np.where(obs, w["mu"].to_numpy(float), np.nan),
                "mu_sigma": np.where(obs, sig, np.nan),
                "mu_lower_bound": w["mu_lower_bound"].to_numpy(float),
                "utilisation": w["utilisation"].to_numpy(float),
            }
        )
    else:
        wh = res.wheels
        e = wh["epoch"].to_numpy(int)
        ok = (wh["flag"] == "ok").to_numpy()
        steady_corner = ~wh["flag"].isin(["low_speed", "not_cornering", "not_steady"]).to_numpy()
        base = pd.DataFrame(
            {
                "time_utc": ep["time_utc"].to_numpy()[e],
                "t_s": t[e],
                "lat_deg": ep["lat_deg"].to_numpy(float)[e],
                "lon_deg": ep["lon_deg"].to_numpy(float)[e],
                "unit": wh["wheel"].astype(str).to_numpy(),
                "observable": ok,
                "mu": np.where(ok, wh["mu"].to_numpy(float), np.nan),
                "mu_sigma": np.where(ok, wh["mu_sigma"].to_numpy(float), np.nan),
                "mu_lower_bound": np.nan,
                "utilisation": wh["utilisation"].to_numpy(float),
            }
        )
        rows = base[ok]
        corner = base[steady_corner].copy()
        if len(corner):
            corner["cell"] = _cells(
                corner["lat_deg"].to_numpy(), corner["lon_deg"].to_numpy(), h3_res
            )
            b = (
                corner.groupby("cell")
                .agg(
                    time_utc=("time_utc", "max"),
                    t_s=("t_s", "max"),
                    lat_deg=("lat_deg", "mean"),
                    lon_deg=("lon_deg", "mean"),
                    utilisation=("utilisation", "median"),
                    mu_lower_bound=("utilisation", lambda u: float(np.quantile(u, 0.95))),
                )
                .reset_index(drop=True)
            )
            b = b.assign(unit="all", observable=False, mu=np.nan, mu_sigma=np.nan)
            rows = pd.concat([rows, b], ignore_index=True)
    rows = rows.assign(
        vehicle=vehicle_id,
        log=name,
        cell=_cells(rows["lat_deg"].to_numpy(), rows["lon_deg"].to_numpy(), h3_res),
    )
    rows = rows[rows["cell"].notna()]
    return rows[ROW_COLUMNS].reset_index(drop=True)


def process_batch(
    items: list[tuple[str, str, str]],
    outdir: str,
    *,
    method: str,
    h3_res: int,
    since: str | None,
    receiver: str = "v100",
) -> list[dict]:
    """Process ``(log path, vehicle toml, vehicle id)`` items; write
    ``outdir/epochs/vehicle=<id>/<log>.parquet``; return one status dict per log."""
    from gripsense.config import Vehicle

    out = []
    vehicles: dict[str, object] = {}
    since_ts = None if since is None else pd.Timestamp(since)
    if since_ts is not None and since_ts.tzinfo is None:
        since_ts = since_ts.tz_localize("UTC")
    for path, vfile, vid in items:
        rec = {"log": path, "vehicle": vid, "rows": 0, "problem": ""}
        try:
            if vfile not in vehicles:
                vehicles[vfile] = Vehicle.from_toml(vfile)
            rows = process_log(
                path,
                vehicles[vfile],
                vehicle_id=vid,
                method=method,
                h3_res=h3_res,
                since=since_ts,
                receiver=receiver,
            )
            if len(rows):
                d = Path(outdir) / "epochs" / f"vehicle={vid}"
                d.mkdir(parents=True, exist_ok=True)
                tag = hashlib.sha1(str(Path(path).resolve()).encode()).hexdigest()[:8]
                rows.drop(columns="vehicle").to_parquet(
                    d / f"{Path(path).name}-{tag}.parquet", index=False
                )
            rec["rows"] = len(rows)
            rec["observable"] = int(rows["observable"].sum()) if len(rows) else 0
        except GripsenseError as e:
            rec["problem"] = str(e)
        except Exception as e:
            tb = traceback.extract_tb(e.__traceback__)[-1]
            rec["problem"] = f"{type(e).__name__}: {e} (at {Path(tb.filename).name}:{tb.lineno})"
        out.append(rec)
    return out
