"""The demo job: ingest → friction on the bundled simulated drives, estimate next to truth."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from gripsense.config import Vehicle
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
        res = run.run_log(folder / c["nmea"])
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


def write_demo_report(
    df: pd.DataFrame, folder: Path | None, path: Path, *, case: str = "case022"
) -> Path:
    """The demo's HTML report: estimate vs truth for every case, then the full report of one
    near-limit drive (*case*).
    """
    import html

    import matplotlib.pyplot as plt

    from gripsense.report import write_report
    from gripsense.report.html import fig_to_data_uri, html_table

    folder = Path(folder) if folder is not None else demo_dir()
    fig, ax = plt.subplots(figsize=(7, 4.2))
    obs = df[df["observable"] == True]  # noqa: E712
    nob = df[df["observable"] != True]  # noqa: E712
    ax.errorbar(
        obs["utilisation_true"],
        obs["mu"] - obs["mu_true"],
        yerr=[
            (obs["mu"] - obs["mu_low"]).clip(lower=0),
            (obs["mu_high"] - obs["mu"]).clip(lower=0),
        ],
        fmt="o",
        ms=4,
        label="value ± 90 % interval",
    )
    ax.plot(
        nob["utilisation_true"],
        nob["mu_lower_bound"] - nob["mu_true"],
        "v",
        color="0.5",
        ms=4,
        label="not observable: lower bound",
    )
    ax.axhline(0, color="k", lw=0.8)
    ax.set_xlabel("true utilisation |F|/(μ Fz)")
    ax.set_ylabel("estimate − true μ")
    ax.set_title("Demo set: estimates and bounds against the truth")
    ax.legend(fontsize=8)
    fig.tight_layout()
    show = df[
        [
            "case",
            "name",
            "wheel",
            "mu_true",
            "utilisation_true",
            "mu",
            "mu_low",
            "mu_high",
            "mu_lower_bound",
            "observable",
        ]
    ].copy()
    intro = (
        "<h2>Demo set</h2><p>24 simulated drives (gripsense's vehicle simulator, brush tyres, "
        "known μ): thesis-2018-like circles at 20–50 km/h × radius 20/30/40 m on a dry "
        "(μ 0.9) and a wet (μ 0.5) road, recorded by an emulated V100-like GNSS compass "
        "(heading ≈ 0.5° rms, 0.5° mounting offset) and read back from NMEA. Method: "
        "<code>brush-2</code> per wheel. A value is reported only where the data can carry "
        "it; elsewhere the lower bound the data prove.</p>"
        f'<p><img alt="estimate vs truth" src="{fig_to_data_uri(fig)}"></p>'
        + html_table(show)
        + f"<h2>One drive in detail: {html.escape(case)}</h2>"
    )
    c = pd.read_csv(folder / "cases.csv").set_index("case").loc[case]
    res = FrictionRun(folder / "vehicle.toml").run_log(folder / c["nmea"])
    return write_report(res, path, title="gripsense demo report", intro_html=intro)
