"""The demo job: ingest → friction on the bundled simulated drives, estimate next to truth."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from gripsense.config import Vehicle
from gripsense.pipeline import FrictionRun

__all__ = [
    "DEMO_COLUMNS",
    "DEMO_METHOD",
    "demo_description",
    "demo_estimate_text",
    "demo_verdict",
    "run_demo",
]

DEMO_METHOD = "axle-window"

DEMO_COLUMNS = {
    "kmh": "km/h",
    "mu_true": "μ true (simulator)",
    "grip_used_lower": "measured: data prove μ ≥",
    "share_proven": "share of μ true proven (μ ≥ ÷ μ true)",
    "estimate": "estimate μ [90 %] (tyre model)",
    "limited_by": "what limits the estimate",
}
"""The demo report's table headers: each number's name and kind."""


def demo_dir() -> Path:
    """Folder of the bundled demo set."""
    from gripsense.data import sample_path

    return sample_path("demo_scenario.toml").parent / "demo"


def run_demo(
    folder: Path | None = None, *, method: str = DEMO_METHOD, progress=None
) -> pd.DataFrame:
    """Estimate μ for every case of a simulated set and put it next to the truth.

    Each case is estimated with the vehicle file a user would write for it (``vehicle_file``
    of ``cases.csv``) and the receiver it was recorded with (``receiver``), as a user would
    run ``gripsense friction --receiver``.

    Parameters
    ----------
    folder : path
        A folder written by ``gripsense simulate`` (default: the bundled demo set).
    method : str
        Friction method (default ``axle-window``).
    progress : callable or None
        ``progress(i, n, case)`` before each case.

    Returns
    -------
    pandas.DataFrame
        One row per case and axle: case parameters (``tyre``, ``receiver`` …), ``mu_true`` (the
        axle's load-weighted peak friction), ``utilisation_true`` (mean over the drive), the
        measured grip
        ``grip_used_lower`` (model-free), the estimate ``mu``, ``mu_low``, ``mu_high``,
        ``observable``, ``surface``, ``limited_by``, ``covered`` (truth inside the interval,
        for values) and ``bound_holds`` (measured-grip bound ≤ truth + 0.01).
    """
    from gripsense.sim.drives import axle_truth

    folder = Path(folder) if folder is not None else demo_dir()
    cases = pd.read_csv(folder / "cases.csv")
    runs: dict = {}
    rows = []
    for i, c in enumerate(cases.to_dict("records")):
        if progress:
            progress(i, len(cases), c["case"])
        vfile = c.get("vehicle_file", "vehicle.toml")
        rec = c.get("receiver", "v100")
        key = (vfile, rec)
        if key not in runs:
            veh = Vehicle.from_toml(folder / vfile)
            runs[key] = FrictionRun(veh, method=method, receiver=rec)
        steer = c.get("steer")
        steer_csv = folder / steer if isinstance(steer, str) and steer else None
        res = runs[key].run_log(folder / c["nmea"], steer_csv=steer_csv)
        truth = axle_truth(pd.read_parquet(folder / c["truth"]), c["settle_s"]).set_index("axle")
        summ = res.unit_table().set_index("unit")
        for axle in truth.index:
            if axle not in summ.index:
                continue  # front wheels need a steering channel
            s, t = summ.loc[axle], truth.loc[axle]
            obs = bool(s["observable"])
            rows.append(
                {
                    "case": c["case"],
                    "name": c["name"],
                    "tyre": str(c.get("tyre", "brush")),
                    "receiver": rec,
                    "axle": axle,
                    "mu_true": float(t["mu_true"]),
                    "utilisation_true": float(t["utilisation"]),
                    "grip_used_lower": float(s["grip_used_lower"]),
                    "mu": float(s["mu"]) if obs else np.nan,
                    "mu_low": float(s["mu_low"]),
                    "mu_high": float(s["mu_high"]),
                    "observable": obs,
                    "surface": s["surface"],
                    "limited_by": str(
                        res.summary.set_index("axle").loc[axle].get("limited_by", "")
                    ),
                    "covered": bool(s["mu_low"] <= t["mu_true"] <= s["mu_high"]) if obs else None,
                    "bound_holds": bool(s["grip_used_lower"] <= t["mu_true"] + 0.01),
                }
            )
    return pd.DataFrame(rows)


def demo_estimate_text(rec: dict) -> str:
    """A demo row's estimate as the console prints it: "0.52 [0.47, 0.57]" for a value,
    "— (≤ 0.67)" for only an upper end, "—" for none.

    Parameters
    ----------
    rec : dict
        A row of :func:`run_demo`'s table.

    Returns
    -------
    str
        The text.
    """
    if rec["observable"]:
        return f"{rec['mu']:.2f} [{rec['mu_low']:.2f}, {rec['mu_high']:.2f}]"
    hi = rec["mu_high"]
    return "—" + (f" (≤ {hi:.2f})" if np.isfinite(hi) else "")


def demo_description(folder: str | Path | None = None) -> str:
    """What the demo drives are, from their own cases table (so the text cannot drift from the
    data): speeds, radii, roads, tyres and receivers.

    Parameters
    ----------
    folder : str or Path, optional
        Demo folder (default the bundled one).

    Returns
    -------
    str
        One sentence, plain text.
    """
    folder = Path(folder) if folder is not None else demo_dir()
    c = pd.read_csv(folder / "cases.csv")
    speeds = sorted(c["speed_kmh"].unique())
    radii = sorted(c["radius_m"].unique())
    mus = sorted(c["mu_road"].unique(), reverse=True)
    tyres = "brush tyres" + (" and a Magic Formula tyre" if (c["tyre"] != "brush").any() else "")
    rx = " and ".join(sorted(c["receiver"].unique()))
    return (
        f"{len(c)} steady circles like the 2018 thesis's: {speeds[0]:g}–{speeds[-1]:g} km/h "
        f"({', '.join(f'{v:g}' for v in speeds)}) on radius "
        f"{' and '.join(f'{r:g}' for r in radii)} m, road μ {' and '.join(f'{m:g}' for m in mus)}, "
        f"{tyres} (the estimator is not told which), receivers {rx}"
    )


def demo_verdict(df: pd.DataFrame) -> str:
    """The demo's one-line verdict.

    Parameters
    ----------
    df : pandas.DataFrame
        :func:`run_demo`'s table.

    Returns
    -------
    str
        "truth inside the interval in N of M values; truth below the upper end in J of L
        axle-cases with an upper end and no value; measured-grip bound ≤ truth in K of K".
    """
    obs = df[df["observable"].astype(bool)]
    n_cov = int(obs["covered"].astype(bool).sum())
    n_b = int(df["bound_holds"].astype(bool).sum())
    upper = df[~df["observable"].astype(bool) & np.isfinite(df["mu_high"].astype(float))]
    n_up = int((upper["mu_true"] <= upper["mu_high"]).sum())
    return (
        f"truth inside the 90 % interval in {n_cov} of {len(obs)} values; truth below the upper "
        f"end in {n_up} of {len(upper)} axle-cases with only an upper end; measured-grip bound "
        f"≤ truth in {n_b} of {len(df)} axle-cases"
    )


def write_demo_report(
    df: pd.DataFrame, folder: Path | None, path: Path, *, case: str | None = None
) -> Path:
    """The demo's HTML report: estimate vs truth for every case, then the full report of one
    near-limit drive (*case*).
    """
    import html

    import matplotlib.pyplot as plt

    from gripsense.report import write_report
    from gripsense.report.html import fig_to_data_uri, html_table

    folder = Path(folder) if folder is not None else demo_dir()
    cases = pd.read_csv(folder / "cases.csv").set_index("case")
    if case is None:  # the nearest-the-limit case with a value, else the nearest the limit
        pick = df.sort_values(["observable", "utilisation_true"], ascending=False)
        case = str(pick.iloc[0]["case"]) if len(pick) else str(cases.index[0])
    fig, ax = plt.subplots(figsize=(7, 4.2))
    obs = df[df["observable"] == True]  # noqa: E712
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
        df["utilisation_true"],
        df["grip_used_lower"] - df["mu_true"],
        "v",
        color="0.5",
        ms=4,
        label="measured: data prove μ ≥ (model-free)",
    )
    ax.axhline(0, color="k", lw=0.8)
    ax.set_xlabel("true utilisation of the axle |F|/(μ Fz), mean over the drive")
    ax.set_ylabel("statement − true μ")
    ax.set_title("Demo set: estimates and measured bounds against the truth")
    ax.legend(fontsize=8)
    fig.tight_layout()
    show = df.assign(
        kmh=df["name"].str.extract(r"v=([\d.]+)\s*km/h", expand=False).fillna(""),
        share_proven=df["grip_used_lower"] / df["mu_true"],
        estimate=[demo_estimate_text(r) for r in df.to_dict("records")],
    )[
        [
            "case",
            "tyre",
            "receiver",
            "kmh",
            "axle",
            "mu_true",
            "grip_used_lower",
            "share_proven",
            "estimate",
            "limited_by",
        ]
    ].rename(columns=DEMO_COLUMNS)
    intro = (
        f"<h2>Demo set</h2><p>Simulated drives (gripsense's vehicle simulator, known μ): "
        f"{html.escape(demo_description(folder))}; recorded by an emulated V100-like compass "
        "(heading ≈ 0.5° rms) or an RTK-class compass (0.05°), 0.5° mounting offset, read back "
        "from NMEA with the steering channel. <i>measured: data prove μ ≥</i> is the friction "
        "the axle used in its best 1 s, measured from the log less its uncertainty: at most "
        "μ true on every row, and its share of μ true is a lower bound of how near the limit "
        "the drive went (the figure's axis: the true utilisation |F|/(μ F<sub>z</sub>), a mean "
        "over the drive, is lower than its peak). "
        "Method: <code>axle-window</code> per axle. Two kinds of statement: the measured grip "
        "(model-free: <i>the data prove μ ≥ …</i>) for every axle, and an estimate of μ with "
        "its 90 % interval (tyre model, shape uncertainty included) only where the data can "
        f"carry it. Verdict: {html.escape(demo_verdict(df))}.</p>"
        f'<p><img alt="estimate vs truth" src="{fig_to_data_uri(fig)}"></p>'
        + html_table(show)
        + f"<h2>One drive in detail: {html.escape(case)}</h2>"
    )
    c = cases.loc[case]
    run = FrictionRun(
        folder / c.get("vehicle_file", "vehicle.toml"),
        method=DEMO_METHOD,
        receiver=c.get("receiver", "v100"),
    )
    steer = c.get("steer")
    steer_csv = folder / steer if isinstance(steer, str) and steer else None
    res = run.run_log(folder / c["nmea"], steer_csv=steer_csv)  # as in the table above
    return write_report(
        res,
        path,
        title="gripsense demo report",
        intro_html=intro,
        receivers=sorted({str(r) for r in df["receiver"]}),
    )
