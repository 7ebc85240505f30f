"""One self-contained HTML report of a friction run: images embedded, no network needed."""

from __future__ import annotations

import base64
import datetime as dt
import html
import io
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np
import pandas as pd

from gripsense.estimate.estimators import estimator_of
from gripsense.estimate.results import COLUMN_KINDS, FrictionResult
from gripsense.io.output_folder import write_file_atomic
from gripsense.report import figures as F
from gripsense.report.summary_check import check_summary

__all__ = ["fig_to_data_uri", "html_table", "render_report", "write_report"]

CSS = """
body{font-family:system-ui,-apple-system,Segoe UI,Helvetica,Arial,sans-serif;margin:2em auto;
max-width:1100px;color:#222;line-height:1.45;padding:0 1em}
h1{font-size:1.6em;margin-bottom:.2em} h2{border-bottom:1px solid #ccc;padding-bottom:.2em;
margin-top:1.6em} table{border-collapse:collapse;margin:.6em 0;font-size:.92em}
th,td{border:1px solid #ccc;padding:.3em .6em;text-align:right;overflow-wrap:break-word}
th{background:#f3f3f3} table{max-width:100%}
td.l,th.l{text-align:left} .note{background:#fff8e1;border-left:4px solid #f0b400;padding:.6em 1em}
.ok{background:#eaf6ea;border-left:4px solid #3a9a3a;padding:.6em 1em} img{max-width:100%}
.meta{color:#666;font-size:.9em} code{background:#f5f5f5;padding:0 .2em}
"""


def fig_to_data_uri(fig) -> str:
    """A matplotlib figure as a PNG data URI (and close the figure)."""
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=90)
    plt.close(fig)
    return "data:image/png;base64," + base64.b64encode(buf.getvalue()).decode("ascii")


def _img(fig, alt: str) -> str:
    return f'<p><img alt="{html.escape(alt)}" src="{fig_to_data_uri(fig)}"></p>'


def _breakable(text: str) -> str:
    """Text escaped, with a line-break opportunity after each ``_`` and ``.`` of a word
    longer than 14 characters (``grip_used_lower``, ``PacejkaBook_Defaults.tir``): a table
    then fits the page.
    """
    return " ".join(
        html.escape(t).replace("_", "_<wbr>").replace(".", ".<wbr>")
        if len(t) > 14
        else html.escape(t)
        for t in text.split(" ")
    )


def _cell(v, floatfmt: str = "{:.2f}") -> str:
    """One table cell: booleans as yes/no, NaN as —, infinite as ∞, text escaped."""
    if isinstance(v, bool | np.bool_):  # words, not True/False
        return "yes" if v else "no"
    if isinstance(v, float | np.floating):
        if not np.isfinite(v):
            return "—" if np.isnan(v) else "∞"
        return floatfmt.format(v)
    return _breakable(str(v))


def html_table(df: pd.DataFrame, floatfmt: str = "{:.2f}") -> str:
    """An HTML table of *df*, every cell escaped (NaN as —, ∞ for infinite values, booleans as
    yes/no; an ``observable`` column reads "value" / "no value — measured grip only").

    Parameters
    ----------
    df : pandas.DataFrame
        The table.
    floatfmt : str
        Format of float cells.

    Returns
    -------
    str
        ``<table>…</table>``.
    """

    def cell(v):
        return _cell(v, floatfmt)

    if "observable" in df.columns:
        df = df.assign(
            observable=[
                "value" if bool(v) else "no value — measured grip only"
                for v in df["observable"].fillna(False)
            ]
        ).rename(columns={"observable": "estimate"})
    head = "".join(
        f'<th class="{"l" if i == 0 else ""}">{_breakable(str(c))}</th>'
        for i, c in enumerate(df.columns)
    )
    rows = "".join(
        "<tr>"
        + "".join(f'<td class="{"l" if i == 0 else ""}">{cell(v)}</td>' for i, v in enumerate(r))
        + "</tr>"
        for r in df.itertuples(index=False)
    )
    return f"<table><tr>{head}</tr>{rows}</table>"


def _named(columns) -> dict[str, str]:
    """Column → "column (kind)" for a table header."""
    out = {}
    for c in columns:
        kind = COLUMN_KINDS.get(str(c), "count" if str(c).startswith("n") else "")
        out[c] = f"{c} ({kind})" if kind else str(c)
    return out


def _transposed(table: pd.DataFrame, unit: str) -> str:
    """A summary with one row per column ("name (kind)") and one column per axle or wheel:
    as narrow as the page however many columns the method writes.
    """
    named = _named([c for c in table.columns if c != unit])
    rows = {named[c]: [_cell(v) for v in table[c]] for c in table.columns if c != unit}
    body = "".join(
        f'<tr><th class="l">{_breakable(k)}</th>' + "".join(f"<td>{v}</td>" for v in vals) + "</tr>"
        for k, vals in rows.items()
    )
    head = "".join(f"<th>{_breakable(str(u))}</th>" for u in table[unit])
    return f"<table><tr><th class='l'>{html.escape(unit)}</th>{head}</tr>{body}</table>"


def _compact(summary: pd.DataFrame, unit: str) -> str:
    """The summary an engineer reads first: per unit the estimate (or that there is none),
    the measured grip, the surface class and what limits the estimate.
    """
    rows = []
    for r in summary.to_dict("records"):
        mu = r.get("mu", np.nan)
        obs = bool(r.get("observable", False)) and mu is not None and np.isfinite(mu)
        hi = r.get("mu_high", np.nan)
        b = r.get("grip_used_lower", np.nan)
        if obs:
            est = f"μ ≈ {mu:.2f} [{r.get('mu_low', np.nan):.2f}, {hi:.2f}]"
        elif hi is not None and np.isfinite(hi) and np.isfinite(b) and hi > b:
            est = f"no value — μ ≤ {hi:.2f} (upper end only)"
        else:
            est = "no value — measured grip only"
        row = {
            unit: r.get(unit, ""),
            "estimate (model-based, 90 %)": est,
            "measured: the data prove": f"μ ≥ {b:.2f}" if b is not None and np.isfinite(b) else "—",
            "surface": r.get("surface", "") if obs else "undetermined",
            "slippery? (μ < 0.5 at 95 %)": r.get("slippery", "unknown"),
        }
        if "limited_by" in r:
            row["what limits the estimate"] = r.get("limited_by") or ""
        read = r.get("steering_torque")
        if isinstance(read, str) and read:
            row["steering torque read"] = read
        rows.append(row)
    return "<div class='summary'>" + html_table(pd.DataFrame(rows).fillna("")) + "</div>"


def _quality(epochs: pd.DataFrame | None, ingest: dict | None) -> str:
    parts = []
    if ingest:
        rows = [("parsed", k, v) for k, v in ingest.get("parsed", {}).items()]
        rows += [("ignored", k, v) for k, v in ingest.get("ignored", {}).items()]
        rows += [("rejected", k, v) for k, v in ingest.get("rejected", {}).items() if v]
        unit = str(ingest.get("unit", "lines"))
        fmt = html.escape(str(ingest.get("format", "NMEA 0183")))
        parts.append(
            f"<p>{ingest.get('total_lines', 0)} input {html.escape(unit)} ({fmt}) from "
            f"<code>{html.escape(str(ingest.get('source', '')))}</code>; every one is "
            "accounted for below.</p>"
        )
        parts.append(html_table(pd.DataFrame(rows, columns=["bucket", "type / reason", unit])))
    if epochs is not None and len(epochs):
        t = epochs["t_s"].dropna().to_numpy()
        dts = np.diff(np.sort(t))
        dts = dts[dts > 0]
        med = float(np.median(dts)) if dts.size else float("nan")
        gaps = int((dts > 2.5 * med).sum()) if dts.size else 0
        items = [
            f"{len(epochs)} epochs, {t.max() - t.min():.1f} s" if t.size else "no time",
            f"median interval {med:.3f} s ({1 / med:.1f} Hz)" if dts.size else "",
            f"{gaps} gaps longer than 2.5 × the median interval"
            + (f" (longest {dts.max():.2f} s)" if gaps else ""),
        ]
        for col in ("heading_source", "yaw_rate_source"):
            if col in epochs:
                vc = epochs[col].value_counts()
                vc = vc[vc > 0]
                items.append(f"{col}: " + (", ".join(f"{k} {v}" for k, v in vc.items()) or "none"))
        parts.append("<ul>" + "".join(f"<li>{html.escape(i)}</li>" for i in items if i) + "</ul>")
    return "\n".join(parts) or "<p>No ingest information (the run did not start from NMEA).</p>"


def _vehicle(vehicle) -> str:
    if vehicle is None:
        return ""
    rows = [
        ("mass", f"{vehicle.mass_kg:.0f} kg"),
        ("weight on the front axle", f"{vehicle.front_weight_fraction:.0%}"),
        ("CG height", f"{vehicle.cg_height_m:.2f} m"),
        ("track front / rear", f"{vehicle.track_front_m:.2f} / {vehicle.track_rear_m:.2f} m"),
    ]
    if vehicle.wheelbase_m:
        rows.append(("wheelbase", f"{vehicle.wheelbase_m:.2f} m"))
    rows.append(
        (
            "roll model",
            "rigid (roll centres at CG height: the thesis model)"
            if vehicle.roll_centre_heights_m is None
            else f"roll centres {vehicle.roll_centre_heights_m} m, front roll share "
            f"{vehicle.roll_stiffness_front_fraction}",
        )
    )
    for axle, t in vehicle.tyres.items():  # the stiffness: the table below, each kind named
        length = (
            f"l = {t.contact_a}·√m + ({t.contact_b})·m"
            if t.contact_length_m is None
            else f"l = {t.contact_length_m} m"
        )
        rows.append(
            (f"tyre {axle}", f"w = {t.width_m * 1000:.0f} mm, {length}, {t.pressure} pressure")
        )
    for w, (x, y) in vehicle.wheel_offsets.items():
        rows.append((f"{w} from antenna", f"x {x:+.3f} m, y {y:+.3f} m"))
    return html_table(pd.DataFrame(rows, columns=["", "value"]))


def _stiffness_table(record: dict, summary: pd.DataFrame, unit: str) -> str:
    """Per axle the tyre stiffness, every number with its kind: declared (vehicle file),
    learned (calibration file), used (the estimator's prior) and estimated (this drive).
    """
    from gripsense.estimate.results import stiffness_lines

    stiff = record.get("stiffness") or {}
    if not stiff:
        return ""
    cal = record.get("calibration") if isinstance(record.get("calibration"), dict) else {}
    learned = (cal or {}).get("learned") or {}
    est = (
        summary.set_index(unit)["cornering_stiffness_N_per_rad"]
        if unit == "axle" and "cornering_stiffness_N_per_rad" in summary and len(summary)
        else pd.Series(dtype=float)
    )

    def c(x) -> str:
        if not (isinstance(x, list | tuple) and len(x) == 2):
            return "—"
        return f"{x[0]:,.0f} ± {100 * x[1]:.0f} %".replace(",", " ")

    rows = []
    for axle, st in stiff.items():
        st = st if isinstance(st, dict) else {}
        e = est.get(axle, np.nan) if len(est) else np.nan
        rows.append(
            {
                "axle": axle,
                "declared (vehicle file)": c(st.get("declared")),
                "learned (calibration file)": c(learned.get(axle)) if cal else "no calibration",
                "used (the estimator's prior)": c(st.get("used")),
                "estimated from this drive": f"{e:,.0f}".replace(",", " ")
                if e is not None and np.isfinite(e)
                else "—",
            }
        )
    lines = "".join(f"<li>{html.escape(t)}</li>" for t in stiffness_lines(record))
    return (
        "<h3>Tyre cornering stiffness [N/rad per wheel, ± relative 1σ]</h3>"
        + html_table(pd.DataFrame(rows))
        + f"<ul class='meta'>{lines}</ul>"
        + "<p class='meta'>declared, learned and used: at the static load; estimated: the "
        "drive's fit (stiffness scale × the prior) at the loads of the windows analysed.</p>"
    )


def _window_ranges(ct: pd.DataFrame, windows: pd.DataFrame | None) -> tuple[list, list]:
    """Per row of a condition table, the median 90 % range ends of the observable windows of
    the wheel's axle inside the condition (the windows whose values the row's μ is the median
    of; NaN where there are none).
    """
    lo, hi = [], []
    for r in ct.to_dict("records"):
        win = (
            windows[
                (windows["axle"] == str(r["wheel"]).split("_")[0])
                & (windows["t_start"] >= r["t_start"])
                & (windows["t_end"] <= r["t_end"] + 1e-9)
                & windows["observable"].astype(bool)
            ]
            if windows is not None and len(windows)
            else pd.DataFrame()
        )
        lo.append(float(win["mu_low"].median()) if len(win) else np.nan)
        hi.append(float(win["mu_high"].median()) if len(win) else np.nan)
    return lo, hi


class _NotRecorded:
    """A prior the result does not record: formatted as "?" whatever the format."""

    def __format__(self, spec: str) -> str:
        return "?"


def write_report(
    result: FrictionResult,
    path: str | Path,
    **kwargs,
) -> Path:
    """Write :func:`render_report` to *path* atomically.

    Parameters
    ----------
    result : FrictionResult
        The result.
    path : str or Path
        Output ``.html`` (its folder is created).
    **kwargs
        Keyword arguments of :func:`render_report`.

    Returns
    -------
    pathlib.Path
        The file written.
    """
    text = render_report(result, **kwargs)
    return write_file_atomic(path, lambda tmp: tmp.write_text(text, encoding="utf-8"))


def render_report(
    result: FrictionResult,
    *,
    epochs: pd.DataFrame | None = None,
    ingest: dict | None = None,
    vehicle=None,
    title: str | None = None,
    max_conditions: int = 6,
    intro_html: str = "",
    receivers: list[str] | None = None,
) -> str:
    """A self-contained HTML report of a :class:`~gripsense.estimate.results.FrictionResult`.

    Parameters
    ----------
    result : FrictionResult
        The result.
    epochs : pandas.DataFrame, optional
        Epoch table (default the result's): adds the trajectory and data quality.
    ingest : dict, optional
        Ingest accounting (``IngestReport.to_dict()``; default the result's).
    vehicle : Vehicle, optional
        Vehicle (default the result's): adds the vehicle section.
    title : str, optional
        Page title.
    max_conditions : int
        Most steady conditions given their own four-panel figure.
    intro_html : str
        HTML inserted before the result (used by the demo).
    receivers : list of str, optional
        Every receiver of a set the page describes (the demo's): the header names them all,
        and the one of the drive in detail.

    Returns
    -------
    str
        The page.
    """
    # a hand-edited summary.json: one line naming the key, not an error deep in the page
    check_summary(result.meta, result.summary.to_dict("records"), unit=result.unit)
    epochs = epochs if epochs is not None else result.epochs
    ingest = ingest if ingest is not None else result.ingest
    vehicle = vehicle if vehicle is not None else result.vehicle
    conds = result.conditions()
    ct = result.condition_table(conds)
    m = result.meta
    record = result.record()  # what the run used: the same read back from its folder
    method = m.get("method", "")
    s = result.summary
    source = str(record.get("source") or "")
    title = title or (f"Friction — {source}" if source else "Tyre-road friction report")
    out = [_head(title, m, method, record, receivers), intro_html, "<h2>Result</h2>"]
    cal = record.get("calibration") if isinstance(record.get("calibration"), dict) else None
    out += _result_section(result, s, cal)
    out += _figures_section(result, epochs, conds, ct, max_conditions)
    out.append("<h2>Data quality</h2>")
    out.append(_quality(epochs, ingest))
    if "heading_offset_deg" in m:
        out.append(
            f"<p>Heading offset used: {m['heading_offset_deg']:.2f}° "
            f"({html.escape(str(m.get('heading_offset_source', '')))}).</p>"
        )
    out += _method_section(result, vehicle, record, method)
    out.append("</body></html>")
    return "\n".join(out)


def _head(title: str, m: dict, method: str, record: dict, receivers: list[str] | None) -> str:
    """The page's head, title and the line naming vehicle, method, receiver and calibration."""
    rx = html.escape(str(m.get("receiver", "not stated")))
    if receivers and sorted(set(receivers)) != [str(m.get("receiver"))]:
        rx_text = (
            "receivers "
            + ", ".join(f"<code>{html.escape(r)}</code>" for r in sorted(set(receivers)))
            + f" (the drive in detail: <code>{rx}</code>)"
        )
    else:
        rx_text = f"receiver <code>{rx}</code>"
    cal = record.get("calibration") if isinstance(record.get("calibration"), dict) else None
    cal_text = (
        f" · calibration <code>{html.escape(str(cal.get('file', '?')))}</code>" if cal else ""
    )
    return "\n".join(
        [
            f"<!doctype html><html lang='en'><head><meta charset='utf-8'>"
            "<meta name='generator' content='gripsense report'>"
            f"<title>{html.escape(title)}</title><style>{CSS}</style>"
            "</head><body>",
            f"<h1>{html.escape(title)}</h1>",
            f"<p class='meta'>gripsense · {html.escape(str(m.get('vehicle', '')))} · method "
            f"<code>{html.escape(method)}</code> · {rx_text}{cal_text} · written "
            f"{dt.datetime.now(dt.UTC):%Y-%m-%d %H:%M} UTC</p>",
        ]
    )


def _result_section(result: FrictionResult, s: pd.DataFrame, cal: dict | None) -> list[str]:
    """The result: what the run says, its two kinds of statement, the summary and its figure."""
    out: list[str] = []
    observable = result.observable
    box = "ok" if observable else "note"
    text = html.escape(result.explain())
    text += (
        "<br><br>Two kinds of statement: <b>the data prove μ ≥ …</b> is measured — the "
        "friction the axle actually used, from the lateral acceleration and the axle's load, "
        "true for any tyre (on a level road without downforce); <b>μ ≈ …</b> is an estimate "
        "under a tyre model whose curve shape, stiffness and load sensitivity are uncertain, "
        "with a 90 % interval that includes that uncertainty."
    )
    if not observable:
        text += (
            "<br><br>What this means: from how the vehicle moved, the data prove only the "
            "measured grip — the tyres used at least that much of the friction available. "
            "The friction coefficient itself shows in the slip angles only near the "
            "friction limit: at everyday cornering the difference between μ = 0.9 and "
            "μ = ∞ lies in a few hundredths of a degree of slip angle, far below the "
            "heading accuracy of a GNSS compass (tenths of a degree). More lateral "
            "acceleration, a more precise heading or a calibrated tyre stiffness would "
            "change this."
        )
    out.append(f"<p class='{box}'>{text}</p>")
    if len(s):
        out.append(_compact(s, result.unit))
        out.append(_img(F.interval_bars(s, result.unit), "estimates and measured grip"))
        cols = [
            c
            for c in (
                result.unit,
                "mu",
                "mu_low",
                "mu_high",
                "surface",
                "slippery",
                "observable",
                "n_valid",
                "n",
                "n_total",
                "grip_used",
                "grip_used_lower",
                "fit",
                "shape",
                "limited_by",
                "steering_torque",
                "stiffness_scale",
            )
            if c in s.columns
        ]
        out.append(
            "<details><summary>All columns of the summary (each with its kind)</summary>"
            + _transposed(s[cols], result.unit)
            + "</details>"
        )
    if cal:
        out.append(
            f"<p class='meta'>Calibration in use: <code>{html.escape(str(cal.get('file')))}</code>"
            " — it changed the tyre stiffness the estimator starts from; the section <i>Vehicle "
            "and method</i> gives the declared, learned and used values.</p>"
        )
    return out


def _figures_section(
    result: FrictionResult,
    epochs: pd.DataFrame | None,
    conds: list,
    ct: pd.DataFrame,
    max_conditions: int,
) -> list[str]:
    """The figures and the steady conditions (a table and a figure per condition)."""
    w, windows = result.wheels, result.windows
    out: list[str] = []
    # the per-condition μ is another statement than the headline's: it says which
    per_window = result.unit == "axle"
    mu_what = (
        "μ per condition: median of the condition's own window estimates (axle-window, each "
        "3 s window alone: wider and not the headline value, which combines all windows)"
        if per_window
        else "μ per condition: median of the valid samples (per-sample method)"
    )
    mu_col = "μ, window estimates (median)" if per_window else "μ, valid samples (median)"
    n_col = "windows with a value" if per_window else "valid samples"
    has_mu = len(ct) and ct["mu"].notna().any()
    out.append("<h2>Figures</h2>")
    if epochs is not None:
        out.append(_img(F.trajectory(epochs, conds), "trajectory"))
    out.append(_img(F.mu_vs_utilisation(w, windows), "mu vs utilisation"))
    if has_mu:
        out.append(f"<p class='meta'>{html.escape(mu_what)}.</p>")
        out.append(_img(F.mu_vs_radius(ct, what=mu_col), "mu vs radius"))
        out.append(_img(F.mu_vs_yaw_rate(ct, what=mu_col), "mu vs yaw rate"))
    elif len(ct):  # an empty figure beside a headline value would say "nothing" next to it
        out.append(
            "<p class='meta'>μ vs turn radius and vs yaw rate: not drawn — no steady condition "
            + (
                "has a window with a value of its own (a value of the summary above combines "
                "the windows of the whole drive)."
                if per_window
                else "has a valid μ."
            )
            + "</p>"
        )
    if len(ct):
        out.append("<h2>Steady conditions</h2>")
        out.append(f"<details><summary>{len(conds)} steady conditions: table and figures</summary>")
        out.append(f"<p class='meta'>{html.escape(mu_what)}.</p>")
        shown = ct[["condition", "wheel", "speed_kmh", "radius_m", "ay_g", "mu", "n_valid", "n"]]
        names = {
            "speed_kmh": "speed [km/h]",
            "radius_m": "radius [m]",
            "ay_g": "|a_y| [g] (measured)",
            "mu": mu_col,
            "n_valid": n_col,
            "n": "samples",
        }
        if per_window:  # each window's own range beside its value: a reader can compare
            lo, hi = _window_ranges(ct, windows)
            shown = shown.assign(range_lo=lo, range_hi=hi)
            names |= {"range_lo": "their 90 % low (median)", "range_hi": "their 90 % high (median)"}
        out.append(html_table(shown.rename(columns=names)))
        for i, (t0, t1) in enumerate(conds[:max_conditions]):
            sub = ct[ct["condition"] == i + 1]
            ttl = (
                f"condition {i + 1}: {t0:.1f}–{t1:.1f} s, {sub['speed_kmh'].mean():.0f} km/h, "
                f"R {sub['radius_m'].mean():.0f} m, |a_y| {sub['ay_g'].mean():.2f} g"
            )
            fig = F.condition_figure(w, t0, t1, title=ttl, windows=windows if per_window else None)
            out.append(_img(fig, ttl))
        if len(conds) > max_conditions:
            out.append(
                f"<p class='meta'>{len(conds) - max_conditions} more conditions are in "
                "the table above.</p>"
            )
        out.append("</details>")
    else:
        out.append("<p>No steady cornering condition of 3 s or more in this drive.</p>")
    return out


def _method_section(result: FrictionResult, vehicle, record: dict, method: str) -> list[str]:
    """The vehicle, the stiffness used, the estimator and its assumptions."""
    s = result.summary
    out: list[str] = []
    out.append("<h2>Vehicle and method</h2>")
    out.append(_vehicle(vehicle))
    out.append(_stiffness_table(record, s, result.unit))
    nm = result.noise
    est = estimator_of(result)
    text = est.description.format(
        G=nm.tread_stiffness_rel if nm is not None else _NotRecorded(),
        B=nm.heading_bias_deg if nm is not None else _NotRecorded(),
        method=html.escape(method),
    )
    if nm is None:  # never a default stated as if the run had used it
        text += (
            " (?: the priors' widths are not recorded in this result; run gripsense friction "
            "again to have them stated)"
        )
    out.append(f"<p>{text}</p>")
    out.append(
        f"<p class='meta'>Assumptions: {est.assumptions}; level road without downforce for "
        "the measured grip; see the gripsense docs (friction.md, physics.md) for the equations "
        "and their sources.</p>"
    )
    return out
