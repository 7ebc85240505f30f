"""The demo job: ingest → friction on the bundled simulated drives, estimate next to truth."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from gripsense.config import Vehicle
from gripsense.io import read_nmea
from gripsense.pipeline import FrictionRun

__all__ = ["DEMO_WHEELS", "run_demo"]

DEMO_WHEELS = ("rear_left", "rear_right")


def demo_dir() -> Path:
    """Folder of the bundled demo set."""
    from gripsense.data import sample_path

    return sample_path("demo_scenario.toml").parent / "demo"


def run_demo(folder: Path | None = None, *, method: str = "brush-2", progress=None) -> pd.DataFrame:
    """Estimate μ for every case of a simulated set and put it next to the truth.

    Parameters
    ----------
    folder : path
        A folder written by ``gripsense simulate`` (default: the bundled demo set).
    method : str
        Friction method.
    progress : callable or None
        ``progress(i, n, case)`` before each case.

    Returns
    -------
    pandas.DataFrame
        One row per case and wheel: case parameters, ``mu_true``, ``utilisation_true`` (mean
        |F|/(μ Fz) of the wheel after settling), the summary (``mu``, ``mu_low``, ``mu_high``,
        ``observable``, ``mu_lower_bound``, ``surface``) and ``covered`` (truth inside the
        interval, for observable wheels).
    """
    folder = Path(folder) if folder is not None else demo_dir()
    cases = pd.read_csv(folder / "cases.csv")
    vehicle = Vehicle.from_toml(folder / "vehicle.toml")
    run = FrictionRun(vehicle, method=method)
    rows = []
    for i, c in enumerate(cases.to_dict("records")):
        if progress:
            progress(i, len(cases), c["case"])
        log = read_nmea(folder / c["nmea"])
        res = run.run(log.epochs)
        truth = pd.read_parquet(folder / c["truth"])
        after = truth[truth["t_s"] >= c["settle_s"]]
        summ = res.summary.set_index("wheel")
        for w in DEMO_WHEELS:
            tw = after[after["wheel"] == w]
            util = float(np.mean(np.abs(tw["force_N"]) / (tw["mu_true"] * tw["load_N"])))
            rec = {
                "case": c["case"],
                "name": c["name"],
                "wheel": w,
                "mu_true": c["mu_road"],
                "utilisation_true": util,
            }
            if w in summ.index:
                s = summ.loc[w]
                rec.update(
                    mu=s["mu"],
                    mu_low=s["mu_low"],
                    mu_high=s["mu_high"],
                    observable=bool(s["observable"]),
                    mu_lower_bound=s["mu_lower_bound"],
                    surface=s["surface"],
                )
                rec["covered"] = (
                    bool(s["mu_low"] <= c["mu_road"] <= s["mu_high"]) if rec["observable"] else None
                )
                rec["bound_holds"] = bool(s["mu_lower_bound"] <= c["mu_road"] + 0.05)
            rows.append(rec)
    return pd.DataFrame(rows)
