"""The ``gripsense`` command line: a thin layer over the library."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import numpy as np
import typer
from rich.table import Table

from gripsense.cli_common import console, fail
from gripsense.cli_fleet import fleet as fleet_cmd
from gripsense.cli_live import live as live_cmd
from gripsense.cli_steering import steering_app
from gripsense.cli_tyre import tyre_app
from gripsense.errors import GripsenseError
from gripsense.io import NmeaLog, read_nmea

app = typer.Typer(
    add_completion=False,
    no_args_is_help=True,
    help="gripsense: tyre-road friction, tyre and steering parameters from how a vehicle moves.",
)




def print_ingest(log: NmeaLog) -> None:
    """Print the line accounting and a summary of an ingested log."""
    rep = log.report
    table = Table(title=f"Line accounting — {Path(rep.source).name}")
    table.add_column("bucket")
    table.add_column("type / reason")
    table.add_column("lines", justify="right")
    for row in rep.to_frame().itertuples(index=False):
        if row.bucket == "rejected" and row.lines == 0:
            continue
        table.add_row(row.bucket, row.kind, str(row.lines))
    table.add_row("[bold]total[/]", "", f"[bold]{rep.total_lines}[/]")
    console.print(table)
    ok = "[green]yes[/]" if rep.balanced else "[red]NO[/]"
    console.print(
        f"parsed {rep.n_parsed} + ignored {rep.n_ignored} + rejected {rep.n_rejected} "
        f"= {rep.total_lines} lines; balanced: {ok}"
    )
    if rep.junk_prefix_lines:
        console.print(
            f"{rep.junk_prefix_lines} sentences recovered after non-NMEA bytes on their line"
        )
    for r in rep.first_rejects[:5]:
        console.print(f"  line {r.line}: {r.reason} — {r.detail}")
    ep = log.epochs
    t = ep["t_s"].to_numpy()
    timed = t[~np.isnan(t)]
    console.print(f"\n[bold]{len(ep)} epochs[/] ({rep.epochs_without_time} without time)")
    if timed.size >= 2:
        dur = float(timed.max() - timed.min())
        dt = np.diff(np.sort(timed))
        dt = dt[dt > 0]
        rate = 1.0 / float(np.median(dt)) if dt.size else float("nan")
        first = ep["time_utc"].dropna()
        start = f", from {first.iloc[0]}" if len(first) else " (no date in log)"
        console.print(f"duration {dur:.2f} s{start}, median rate {rate:.1f} Hz")
    present = []
    for col in (
        "lat_deg",
        "speed_mps",
        "course_deg",
        "heading_deg",
        "pitch_deg",
        "rot_deg_per_min",
        "yaw_rate_rps",
    ):
        n = int(ep[col].notna().sum())
        if n:
            present.append(f"{col} {n}")
    console.print("present: " + (", ".join(present) if present else "nothing usable"))
    for col in ("heading_source", "yaw_rate_source"):
        vc = ep[col].value_counts()
        vc = vc[vc > 0]
        if len(vc):
            console.print(f"{col}: " + ", ".join(f"{k} {v}" for k, v in vc.items()))


def write_table(df, out: Path) -> None:
    """Write an epoch table to Parquet or CSV (chosen by the file suffix)."""
    suffix = out.suffix.lower()
    if suffix == ".parquet":
        df.to_parquet(out, index=False)
    elif suffix == ".csv":
        df.to_csv(out, index=False)
    else:
        raise GripsenseError(f"{out}: unknown output format {suffix!r}; use .parquet or .csv")


@app.command()
def ingest(
    log: Annotated[Path, typer.Argument(help="NMEA log (plain or .gz)")],
    output: Annotated[
        Path | None, typer.Option("-o", "--output", help="write epochs to .parquet or .csv")
    ] = None,
    strict: Annotated[
        bool, typer.Option("--strict", help="stop at the first rejected line")
    ] = False,
) -> None:
    """Read an NMEA log into the epoch table and print its line accounting."""
    try:
        nlog = read_nmea(log, strict=strict)
        print_ingest(nlog)
        if output is not None:
            write_table(nlog.epochs, output)
            console.print(f"wrote {len(nlog.epochs)} epochs to {output}")
    except GripsenseError as e:
        fail(e)


@app.command()
def friction(
    log: Annotated[Path | None, typer.Argument(help="NMEA log of the drive (plain or .gz)")] = None,
    vehicle: Annotated[
        Path | None, typer.Option("--vehicle", help="vehicle description (TOML)")
    ] = None,
    method: Annotated[
        str,
        typer.Option("--method", help="brush-2 | brush-4 | thesis-2 | thesis-4 | axle-window"),
    ] = "brush-2",
    steer_csv: Annotated[
        Path | None,
        typer.Option("--steer-csv", help="CSV with t_s and road_wheel_deg (enables front wheels)"),
    ] = None,
    table: Annotated[
        Path | None,
        typer.Option("--table", help="motion table (CSV/Parquet) instead of an NMEA log"),
    ] = None,
    columns: Annotated[
        str | None,
        typer.Option(
            "--columns",
            help="mapping for --table: t=...,vx=...,vy=...,yaw_rate=..."
            ",ay=...,steer=... (units after ':', e.g. yaw_rate=YawRate:dps)",
        ),
    ] = None,
    outdir: Annotated[
        Path, typer.Option("-o", "--outdir", help="folder for the result files")
    ] = Path("friction-results"),
    report: Annotated[bool, typer.Option("--report", help="also write OUTDIR/report.html")] = False,
) -> None:
    """Tyre-road friction per wheel (or per axle with --method axle-window) during cornering."""
    from gripsense.config import Vehicle
    from gripsense.io.steer import read_steer_csv, steer_at
    from gripsense.io.table import read_motion_table
    from gripsense.pipeline import FrictionRun

    try:
        if vehicle is None:
            raise GripsenseError("--vehicle car.toml is required")
        if (log is None) == (table is None):
            raise GripsenseError("give either an NMEA LOG or --table FILE --columns ...")
        veh = Vehicle.from_toml(vehicle)
        run = FrictionRun(veh, method=method)
        if table is not None:
            if not columns:
                raise GripsenseError(
                    "--table needs --columns (e.g. t=Time,vx=Vx,vy=Vy,yaw_rate=YawRate:dps)"
                )
            result = run.run_motion(
                read_motion_table(table, columns), meta={"vehicle": veh.name, "source": str(table)}
            )
        else:
            nlog = read_nmea(log)
            steer = None
            if steer_csv is not None:
                ch = read_steer_csv(steer_csv, steering_ratio=veh.steering_ratio)
                steer = steer_at(ch, nlog.epochs["t_s"].to_numpy())
            result = run.run(nlog.epochs, steer_rad=steer)
            result.ingest = nlog.report.to_dict()
    except GripsenseError as e:
        fail(e)
    print_friction(result)
    paths = result.to_files(outdir)
    console.print("wrote " + ", ".join(str(p) for p in paths.values()))
    if report:
        from gripsense.report import write_report

        rp = write_report(result, outdir / "report.html", title=f"Friction — {(log or table).name}")
        console.print(f"report: {rp}")


@app.command("report")
def report_cmd(
    result_dir: Annotated[Path, typer.Argument(help="folder written by gripsense friction")],
    output: Annotated[
        Path | None,
        typer.Option("-o", "--output", help="HTML file (default RESULT_DIR/report.html)"),
    ] = None,
) -> None:
    """Write a self-contained HTML report (images embedded) of a friction result folder."""
    from gripsense.report import write_report
    from gripsense.report.html import read_result

    try:
        res = read_result(result_dir)
    except GripsenseError as e:
        fail(e)
    out = write_report(
        res, output or result_dir / "report.html", title=f"Friction — {result_dir.name}"
    )
    console.print(f"report: {out}")


def print_friction(result) -> None:
    """Print the per-wheel summary table and the one-line explanation."""
    m = result.meta
    head = f"[bold]{m.get('vehicle', '')}[/] — method {m['method']}"
    if "epochs_total" in m:
        head += (
            f"; {m['epochs_used']} of {m['epochs_total']} epochs usable; heading offset "
            f"{m['heading_offset_deg']:.2f}° ({m['heading_offset_source']})"
        )
    console.print(head)
    if "axle" in result.summary.columns:
        table = Table(title="Friction per axle (axle-window: 90 % profile-likelihood interval)")
        for col in (
            "axle",
            "μ",
            "90 % interval",
            "surface",
            "utilisation",
            "samples",
            "windows observable",
        ):
            table.add_column(col)
        win = result.windows
        for rec in result.summary.to_dict("records"):
            if not rec.get("n"):
                table.add_row(rec["axle"], "—", "—", "—", "—", "0", "—")
                continue
            mu = f"{rec['mu']:.2f}" if rec["observable"] else "n/o"
            hi = f"{rec['mu_high']:.2f}" if np.isfinite(rec["mu_high"]) else "∞"
            nw = win[win["axle"] == rec["axle"]] if win is not None and len(win) else []
            obs = f"{int(nw['observable'].sum())} / {len(nw)}" if len(nw) else "—"
            table.add_row(
                rec["axle"],
                mu,
                f"{rec['mu_low']:.2f} – {hi}",
                rec["surface"],
                f"{rec['utilisation']:.2f}",
                str(rec["n"]),
                obs,
            )
        console.print(table)
        console.print(result.explain(), soft_wrap=True)
        return
    table = Table(title="Friction per wheel (steady cornering samples)")
    for col in (
        "wheel",
        "μ",
        "90 % interval",
        "surface",
        "valid / total",
        "μ ≥ (proven)",
        "main flags",
    ):
        table.add_column(col)
    flag_cols = [
        c for c in result.summary.columns if c.startswith("n_") and c not in ("n_valid", "n_total")
    ]
    for rec in result.summary.to_dict("records"):
        mu = "—" if not np.isfinite(rec["mu"]) else f"{rec['mu']:.2f}"
        iv = "—" if not np.isfinite(rec["mu"]) else f"{rec['mu_low']:.2f} – {rec['mu_high']:.2f}"
        lb = "—" if not np.isfinite(rec["mu_lower_bound"]) else f"{rec['mu_lower_bound']:.2f}"
        flags = sorted(((rec[c], c[2:]) for c in flag_cols if rec[c]), reverse=True)[:3]
        table.add_row(
            rec["wheel"],
            mu,
            iv,
            rec["surface"],
            f"{rec['n_valid']} / {rec['n_total']}",
            lb,
            ", ".join(f"{f} {n}" for n, f in flags),
        )
    console.print(table)
    console.print(result.explain(), soft_wrap=True)


@app.command("fit-contact")
def fit_contact(
    table: Annotated[Path, typer.Argument(help="CSV with mass_kg and length_m (or length_cm)")],
) -> None:
    """Fit the contact-length model l = a·√m + b·m (thesis eq. 6.23) to measurements."""
    import pandas as pd

    from gripsense.identify import fit_contact_length

    try:
        try:
            df = pd.read_csv(table, comment="#")
        except FileNotFoundError:
            raise GripsenseError(f"{table}: no such file") from None
        if "mass_kg" not in df.columns:
            raise GripsenseError(f"{table}: no column 'mass_kg' (columns: {list(df.columns)})")
        if "length_m" in df.columns:
            length = df["length_m"]
        elif "length_cm" in df.columns:
            length = df["length_cm"] / 100.0
        else:
            raise GripsenseError(f"{table}: needs a column 'length_m' or 'length_cm'")
        params, stats = fit_contact_length(df["mass_kg"], length)
    except GripsenseError as e:
        fail(e)
    console.print(f"l = a·√m + b·m fitted to {stats['n']} rows of {table.name}:")
    console.print(f"  a = {params['a']:.6g} m/kg^0.5")
    console.print(f"  b = {params['b']:.6g} m/kg")
    console.print(
        f"  R² = {stats['r2']:.4f}, RMSE = {stats['rmse_m'] * 100:.3f} cm "
        f"(√(SSE/(n−2)) = {stats['rmse_dof_m'] * 100:.3f} cm)"
    )
    if np.isfinite(stats["m_peak_kg"]):
        console.print(f"  the model stops growing at m = {stats['m_peak_kg']:.0f} kg")
    console.print(
        f"  vehicle file: contact_length = {{ a = {params['a']:.6g}, b = {params['b']:.6g} }}"
    )


@app.command()
def simulate(
    scenario: Annotated[Path, typer.Argument(help="scenario TOML (see gripsense.sim.scenario)")],
    outdir: Annotated[Path, typer.Option("-o", "--outdir", help="output folder")] = Path("sim-out"),
) -> None:
    """Simulate drives with known friction and emulate the receiver (logs, truth, vehicle)."""
    from rich.progress import Progress

    from gripsense.sim.scenario import run_scenario

    try:
        with Progress(console=console, transient=True) as prog:
            task = prog.add_task("simulating", total=None)

            def tick(i, n, cid):
                prog.update(task, total=n, completed=i, description=f"simulating {cid}")

            cases = run_scenario(scenario, outdir, progress=tick)
    except GripsenseError as e:
        fail(e)
    console.print(
        f"simulated {len(cases)} cases into {outdir}/ "
        f"(median {cases['realtime_factor'].median():.0f}× real time); index: "
        f"{outdir / 'cases.csv'}"
    )


@app.command()
def stiffness(
    logs: Annotated[list[Path], typer.Argument(help="NMEA log(s) of steady cornering")],
    vehicle: Annotated[Path, typer.Option("--vehicle", help="vehicle description (TOML)")],
    sweep: Annotated[bool, typer.Option("--sweep", help="also the thesis's G sweep")] = False,
    outdir: Annotated[
        Path | None, typer.Option("-o", "--outdir", help="folder for the table (and plots)")
    ] = None,
) -> None:
    """Tread stiffness G per steady condition and wheel (thesis ch. 9, like Table 23)."""
    import pandas as pd

    from gripsense.config import Vehicle
    from gripsense.estimate.stiffness import g_sweep, tread_stiffness
    from gripsense.pipeline import FrictionRun
    from gripsense.report.figures import conditions

    try:
        veh = Vehicle.from_toml(vehicle)
        frames, sweeps = [], []
        for log in logs:
            res = FrictionRun(veh).run(read_nmea(log).epochs)
            conds = conditions(res.wheels)
            t = tread_stiffness(res.wheels, veh, conds=conds)
            frames.append(t.assign(log=log.name))
            if sweep:
                for i, c in enumerate(conds):
                    sweeps.append((log.name, i + 1, g_sweep(res.wheels, veh, *c)))
    except GripsenseError as e:
        fail(e)
    tab = pd.concat(frames, ignore_index=True) if frames else pd.DataFrame()
    if tab.empty:
        console.print("no steady cornering condition of 3 s or more: G cannot be estimated")
        raise typer.Exit(1)
    table = Table(title="Tread stiffness G per steady condition (brush linear term)")
    for col in (
        "log",
        "cond.",
        "wheel",
        "km/h",
        "R [m]",
        "slip [°]",
        "utilisation",
        "G [N/m³]",
        "± (0.1° slip)",
        "note",
    ):
        table.add_column(col)
    for r in tab.to_dict("records"):
        table.add_row(
            r["log"],
            str(r["condition"]),
            r["wheel"],
            f"{r['speed_kmh']:.0f}",
            f"{r['radius_m']:.1f}",
            f"{r['slip_deg']:.2f}",
            f"{r['utilisation']:.2f}",
            f"{r['G']:.3g}",
            f"{100 * r['G_rel_sigma']:.0f} %",
            "near limit: biased low" if r["near_limit"] else "",
        )
    console.print(table)
    lin = tab[~tab["near_limit"]]
    if len(lin):
        console.print(
            f"mean G over the {len(lin)} linear-range rows: {lin['G'].mean():.3g} N/m³ "
            f"(all rows: {tab['G'].mean():.3g})"
        )
    else:
        console.print("every condition is near the limit: G is biased low there (PHYSICS §6)")
    for name, i, sw in sweeps:
        console.print(f"G sweep {name} condition {i}: chosen {sw.chosen:.3g} N/m³ — {sw.reason}")
    if outdir:
        outdir.mkdir(parents=True, exist_ok=True)
        tab.to_csv(outdir / "stiffness.csv", index=False)
        for name, i, sw in sweeps:
            sw.plot().savefig(outdir / f"gsweep_{Path(name).stem}_{i}.png", dpi=90)
        console.print(f"wrote {outdir / 'stiffness.csv'}")


@app.command("camera-slip")
def camera_slip(
    source: Annotated[Path, typer.Argument(help="folder of frames or a video file")],
    fps: Annotated[float, typer.Option("--fps", help="frame rate [1/s]")],
    mm_per_px: Annotated[
        float | None, typer.Option("--mm-per-px", help="ground scale (gives the speed)")
    ] = None,
    output: Annotated[
        Path, typer.Option("-o", "--output", help="CSV (a .png plot next to it)")
    ] = Path("camera_slip.csv"),
) -> None:
    """Slip angle from a downward camera on the wheel (seed 002 §2.1); image top = forward."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from gripsense.vision.slip_camera import slip_from_frames

    try:
        res = slip_from_frames(source, fps=fps, mm_per_px=mm_per_px)
    except GripsenseError as e:
        fail(e)
    output.parent.mkdir(parents=True, exist_ok=True)
    res.to_csv(output, index=False)
    ok = res[res["ok"]]
    fig, ax = plt.subplots(figsize=(7, 3.5))
    ax.plot(res["t_s"], res["slip_angle_deg"], ".", color="0.6", label="all pairs")
    ax.plot(ok["t_s"], ok["slip_angle_deg"], "o", ms=3, label="accepted")
    ax.set_xlabel("time [s]")
    ax.set_ylabel("slip angle [deg] (ISO)")
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(output.with_suffix(".png"), dpi=90)
    if len(ok):
        sp = "" if mm_per_px is None else f", ground speed {ok['speed_mps'].median():.2f} m/s"
        console.print(
            f"{len(ok)} of {len(res)} frame pairs accepted; median slip angle "
            f"{ok['slip_angle_deg'].median():.2f}° (ISO){sp}"
        )
    else:
        console.print(f"no frame pair passed the quality checks ({len(res)} pairs)")
    console.print(f"wrote {output} and {output.with_suffix('.png')}")


@app.command()
def camber(
    laser: Annotated[Path, typer.Argument(help="CSV with t_s and two laser distances")],
    spacing_m: Annotated[float, typer.Option("--spacing-m", help="sensor spacing [m]")],
    outer_col: Annotated[str, typer.Option("--outer-col")] = "d_outer_mm",
    inner_col: Annotated[str, typer.Option("--inner-col")] = "d_inner_mm",
    scale_m: Annotated[float, typer.Option("--scale-m", help="metres per unit (1e-3: mm)")] = 1e-3,
    calibrate_s: Annotated[
        float,
        typer.Option(
            "--calibrate-s",
            help="first seconds on a flat floor at the reference camber (0: no calibration)",
        ),
    ] = 0.0,
    reference_deg: Annotated[float, typer.Option("--reference-deg")] = 0.0,
    output: Annotated[Path | None, typer.Option("-o", "--output", help="CSV")] = None,
) -> None:
    """Camber to the ground from two laser displacement sensors (seed 002 Fig. 3)."""
    from gripsense.vision.camber_laser import camber_from_lasers, read_laser_csv

    try:
        d = read_laser_csv(laser, outer_col=outer_col, inner_col=inner_col, scale_m=scale_m)
        off_o = off_i = 0.0
        if calibrate_s > 0:
            cal = d[d["t_s"] < d["t_s"].iloc[0] + calibrate_s]
            off_o, off_i = float(cal["d_outer_m"].median()), float(cal["d_inner_m"].median())
        d["camber_deg"] = np.rad2deg(
            camber_from_lasers(
                d["d_outer_m"],
                d["d_inner_m"],
                spacing_m,
                offset_outer=off_o,
                offset_inner=off_i,
                reference_camber_rad=np.deg2rad(reference_deg),
            )
        )
    except GripsenseError as e:
        fail(e)
    c = d["camber_deg"]
    console.print(
        f"camber (top outward positive): median {c.median():.2f}°, "
        f"range {c.min():.2f}° … {c.max():.2f}° over {len(d)} samples"
    )
    if output:
        d.to_csv(output, index=False)
        console.print(f"wrote {output}")


@app.command("brake-mu")
def brake_mu(
    accel: Annotated[list[Path], typer.Argument(help="accelerometer CSV file(s)")],
    t_col: Annotated[str, typer.Option("--t-col", help="time column")] = "t_s",
    ax_col: Annotated[str, typer.Option("--ax-col", help="forward acceleration column")] = "ax_g",
    ay_col: Annotated[str, typer.Option("--ay-col")] = "ay_g",
    az_col: Annotated[str, typer.Option("--az-col", help="'' for none")] = "az_g",
    units: Annotated[str, typer.Option("--units", help="g | mps2")] = "g",
    ax_sign: Annotated[float, typer.Option("--ax-sign", help="-1 if x points backwards")] = 1.0,
    time_scale: Annotated[
        float, typer.Option("--time-scale", help="seconds per time unit (0.001 for ms)")
    ] = 1.0,
    output: Annotated[Path | None, typer.Option("-o", "--output", help="events CSV")] = None,
) -> None:
    """Friction from locked-wheel braking: μ = a/g per event (thesis ch. 8)."""
    import pandas as pd

    from gripsense.estimate.braking import estimate_braking, read_accel_csv

    frames = []
    try:
        for f in accel:
            acc = read_accel_csv(
                f,
                t_col=t_col,
                ax_col=ax_col,
                ay_col=ay_col or None,
                az_col=az_col or None,
                units=units,
                ax_sign=ax_sign,
                time_scale=time_scale,
            )
            res = estimate_braking(acc, source=str(f))
            frames.append(res.events.assign(file=f.name))
    except GripsenseError as e:
        fail(e)
    ev = pd.concat(frames, ignore_index=True)
    table = Table(title="Locked-wheel braking events")
    for col in ("file", "onset [s]", "plateau [s]", "μ = a/g", "spread", "μ 3-axis", "slope [1/s]"):
        table.add_column(col)
    for r in ev.to_dict("records"):
        table.add_row(
            r["file"],
            f"{r['t_onset']:.2f}",
            f"{r['plateau_s']:.2f}",
            f"{r['mu']:.3f}",
            f"{r['mu_spread']:.3f}",
            "—" if np.isnan(r["mu_3axis"]) else f"{r['mu_3axis']:.3f}",
            f"{r['slope_per_s']:+.3f}",
        )
    console.print(table)
    sd = f" ± {ev['mu'].std():.3f} (SD)" if len(ev) > 1 else ""
    console.print(
        f"μ = {ev['mu'].mean():.3f}{sd} over {len(ev)} events — sliding friction of "
        "locked wheels (below peak μ; includes ~0.01–0.02 g of drag)"
    )
    if output:
        ev.to_csv(output, index=False)
        console.print(f"wrote {output}")


@app.command()
def demo(
    outdir: Annotated[
        Path, typer.Option("-o", "--outdir", help="folder for the demo's output")
    ] = Path("demo-report"),
) -> None:
    """Friction on the bundled simulated drives (dry μ 0.9, wet μ 0.5), estimate next to truth."""
    from rich.progress import Progress

    from gripsense.demo import demo_dir, run_demo

    folder = demo_dir()
    console.print(
        f"[bold]gripsense demo[/] — {folder.name}: thesis-2018-like circles "
        "(20–50 km/h × R 20–40 m) on a dry and a wet road, emulated V100-like compass"
    )
    with Progress(console=console, transient=True) as prog:
        task = prog.add_task("ingest → friction", total=None)

        def tick(i, n, cid):
            prog.update(task, total=n, completed=i, description=f"ingest → friction {cid}")

        df = run_demo(folder, progress=tick)
    from rich import box

    table = Table(
        title="Estimated vs true μ (rear wheels; n/o = not observable)",
        box=box.SIMPLE_HEAD,
        pad_edge=False,
    )
    for col in ("case", "v", "R", "true μ", "a_y/μg", "rear left", "rear right", "in"):
        table.add_column(col, no_wrap=True)
    for case, g in df.groupby("case", sort=False):
        cells = []
        marks = []
        for rec in g.to_dict("records"):
            if rec.get("observable"):
                cells.append(f"{rec['mu']:.2f} [{rec['mu_low']:.2f}–{rec['mu_high']:.2f}]")
                marks.append("✓" if rec["covered"] else "✗")
            else:
                cells.append(f"n/o  ≥ {rec['mu_lower_bound']:.2f}")
        first = g.iloc[0]
        v, r = first["name"].split()[1:3]
        table.add_row(
            case,
            v[2:-4],
            r[2:-1],
            f"{first['mu_true']:.1f}",
            f"{g['utilisation_true'].mean():.2f}",
            *cells,
            "".join(marks),
        )
    console.print(table)
    obs = df[df["observable"] == True]  # noqa: E712 - pandas element-wise
    n_cov = int(obs["covered"].sum())
    console.print(
        f"{len(obs)} of {len(df)} wheel-cases observable (n/o = not observable: only the "
        f"lower bound is reported); truth inside the 90 % interval in {n_cov} of {len(obs)}; "
        f"lower bound ≤ truth (+0.05) in {int(df['bound_holds'].sum())} of {len(df)}."
    )
    outdir.mkdir(parents=True, exist_ok=True)
    df.to_csv(outdir / "demo_results.csv", index=False)
    from gripsense.demo import write_demo_report

    rp = write_demo_report(df, folder, outdir / "report.html")
    console.print(f"wrote {outdir / 'demo_results.csv'}")
    console.print(f"report: {rp}")


# commands that live in their own modules, listed after the ones above
app.command("live")(live_cmd)
app.command("fleet")(fleet_cmd)
app.add_typer(tyre_app, name="tyre")
app.add_typer(steering_app, name="steering")


def main() -> None:
    """Console-script entry point."""
    app()


if __name__ == "__main__":
    main()
