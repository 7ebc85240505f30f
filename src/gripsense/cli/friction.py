"""``gripsense friction``, ``report`` and ``stiffness``: friction and tread stiffness of drives."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Annotated

import typer

from gripsense.cli._common import (
    LOG_COLUMNS_HELP,
    Dbc,
    Overwrite,
    TimeOffset,
    command_line,
    console,
    fail,
    log_options,
    say,
)
from gripsense.errors import GripsenseError

if TYPE_CHECKING:
    from gripsense.estimate.results import AxleFriction, FrictionResult, WheelFriction

__all__ = ["RECEIVER_HELP", "friction", "print_friction", "report_cmd", "stiffness"]

RECEIVER_HELP = (
    "receiver: v100 | white-0.3 | rtk | FILE.toml (default: the vehicle file's [receiver], "
    "else v100)"
)


def friction(
    log: Annotated[
        Path | None,
        typer.Argument(
            help="log of the drive: NMEA, VBOX .vbo, UBX, NovAtel ASCII, MDF4, CAN or a ROS bag "
            "(plain or .gz)"
        ),
    ] = None,
    vehicle: Annotated[
        Path | None, typer.Option("--vehicle", help="vehicle description (TOML)")
    ] = None,
    method: Annotated[
        str,
        typer.Option(
            "--method",
            help="axle-window (default: measured grip and μ estimate per axle) | brush-2 | "
            "brush-4 | thesis-2 | thesis-4 (per wheel, to reproduce the 2018 Kochi University of "
            "Technology thesis)",
        ),
    ] = "axle-window",
    receiver: Annotated[str | None, typer.Option("--receiver", help=RECEIVER_HELP)] = None,
    steer_csv: Annotated[
        Path | None,
        typer.Option(
            "--steer-csv",
            help="CSV with t_s and road_wheel_deg (enables front wheels); may also carry the "
            "steering torque: torque_Nm, assist_Nm, rack_N",
        ),
    ] = None,
    steer_columns: Annotated[
        str | None,
        typer.Option(
            "--steer-columns",
            help="mapping for --steer-csv: t=...,road_wheel=...|steering_wheel=...,torque=...,"
            "assist=...,rack=... (units after ':', e.g. torque=TrqCol:Nm; '-' before a header "
            "flips its sign)",
        ),
    ] = None,
    table: Annotated[
        Path | None,
        typer.Option("--table", help="motion table (CSV/Parquet) instead of an NMEA log"),
    ] = None,
    columns: Annotated[
        str | None,
        typer.Option(
            "--columns",
            help="mapping for --table: t=...,vx=...,vy=...,yaw_rate=...,ay=...,steer=... "
            "(units after ':', e.g. yaw_rate=YawRate:dps; default: headers named like "
            "time_s, speed_kmh, slip_deg, yaw_rate_dps); for a log, its " + LOG_COLUMNS_HELP,
        ),
    ] = None,
    dbc: Dbc = None,
    time_offset: TimeOffset = None,
    outdir: Annotated[
        Path | None,
        typer.Option(
            "-o",
            "--outdir",
            help="folder for the result files (default: the log's name with .friction, in the "
            "current folder: drive.nmea.gz -> drive.friction)",
        ),
    ] = None,
    report: Annotated[bool, typer.Option("--report", help="also write OUTDIR/report.html")] = False,
    calibration: Annotated[
        Path | None,
        typer.Option(
            "--calibration",
            help="the vehicle's calibration file (gripsense calibrate): learned tyre stiffness",
        ),
    ] = None,
    overwrite: Overwrite = False,
) -> None:
    """Tyre-road friction per axle (or per wheel with a per-sample --method) during cornering:
    the grip the data prove (model-free) and an estimate of μ with its interval.
    """
    from gripsense.io.output_folder import check_output_folder
    from gripsense.pipeline import FrictionRun

    try:
        vehicle, outdir = _checked_args(vehicle, log, table, outdir)
        check_output_folder(
            outdir, "friction", overwrite=overwrite, files=["report.html"] if report else []
        )
        run = FrictionRun(vehicle, method=method, receiver=receiver, calibration=calibration)
        if table is not None:
            result = _run_table(run, table, columns)
        else:
            opts = log_options(columns, dbc, time_offset)
            assert log is not None  # one of --table and LOG is given (checked above)
            result = _run_log(run, log, steer_csv, steer_columns, opts)
        cal = _calibration_record(run.vehicle, vehicle, calibration, run.calibration_notes)
        if cal is not None:  # the calibration in use, named in every rendering of the result
            result = result.replace(meta={**result.meta, "calibration": cal})
    except GripsenseError as e:
        fail(e)
    _say_run(result, run.calibration_notes, cal)
    inputs = [p for p in (log, table, vehicle, steer_csv, calibration, dbc) if p is not None]
    _write_run(result, outdir, overwrite=overwrite, report=report, inputs=inputs)


def _checked_args(vehicle, log, table, outdir: Path | None) -> tuple[Path, Path]:
    """The vehicle file and the result folder (default: one per log); one source, a vehicle."""
    if vehicle is None:
        raise GripsenseError("--vehicle car.toml is required")
    if (log is None) == (table is None):
        raise GripsenseError("give either an NMEA LOG or --table FILE --columns ...")
    source = log if log is not None else table
    if outdir is None and source is not None:
        outdir = default_outdir(source)
    assert outdir is not None
    return vehicle, outdir


def _run_table(run, table: Path, columns: str | None) -> FrictionResult:
    """``--table``: the motion table read (its column mapping said) and run."""
    from gripsense.io.sensors.motion import read_motion_table
    from gripsense.io.table import describe_columns

    motion = read_motion_table(table, columns or "auto")
    say(f"{table.name}: columns {describe_columns(motion.attrs['columns'])}")
    meta = {"vehicle": run.vehicle.name, "source": str(table)}
    if motion["steer_rad"].isna().all():
        meta["front_axle"] = (
            "front axle: no steering column — add steer=COLUMN:deg (road-wheel angle) to --columns"
        )
    return run.run_motion(motion, meta=meta)


def _run_log(run, log: Path, steer_csv, steer_columns, opts) -> FrictionResult:
    """A log run (its ingest notes said)."""
    result = run.run_log(log, steer_csv=steer_csv, steer_columns=steer_columns, log_options=opts)
    for note in (result.ingest or {}).get("notes", []):
        say(f"note: {note}")
    return result


def _say_run(result: FrictionResult, calibration_notes: list[str], cal: dict | None) -> None:
    """The table; the calibration's conflicts and stiffness; the front axle's absence."""
    print_friction(result)
    for note in calibration_notes:  # a declaration the drives contradict, said out loud
        say(note)
    if cal is not None:
        from gripsense.estimate.results import stiffness_lines

        for line in stiffness_lines(result.record()):
            say(line)
    if result.meta.get("front_axle"):  # the front axle never disappears without a word
        if result.meta["front_axle"] not in result.explain():  # (the axle methods' line says it)
            say(result.meta["front_axle"])
    elif result.meta.get("steering"):
        say(f"steering: {result.meta['steering']}")


def _write_run(result, outdir: Path, *, overwrite: bool, report: bool, inputs: list) -> None:
    """The result folder (and with *report* its report.html), each file said."""
    try:
        paths = result.to_files(outdir, overwrite=overwrite, command=command_line(), inputs=inputs)
        say("wrote " + ", ".join(str(p) for k, p in paths.items() if k != "manifest"))
        if report:  # from the folder as written: the same story as `gripsense report` tells
            say(f"report: {_report_of_folder(outdir, overwrite=False)}")
    except GripsenseError as e:
        fail(e)


def _calibration_record(
    veh, vehicle_file: Path, calibration: Path | None, notes: list[str]
) -> dict | None:
    """The calibration a run used (``--calibration``, else the vehicle file's), for its result
    (``meta["calibration"]``; :func:`gripsense.estimate.results.calibration_record`).
    """
    from gripsense.config import Vehicle
    from gripsense.estimate.results import calibration_record

    path = (
        calibration if calibration is not None else Vehicle.from_toml(vehicle_file).calibration_file
    )
    return None if path is None else calibration_record(path, veh, notes)


def default_outdir(source: Path) -> Path:
    """The result folder of ``friction`` without ``-o``: the log's name without its format
    suffixes, with ``.friction``, in the current folder (``drive.nmea.gz`` → ``drive.friction``).

    Parameters
    ----------
    source : Path
        The log or motion table.

    Returns
    -------
    Path
        The folder.
    """
    name = Path(source).name
    for suffix in (".gz", ".bz2", ".xz"):
        name = name.removesuffix(suffix)
    stem = Path(name).stem or name or "drive"
    return Path(f"{stem}.friction")


def _report_of_folder(folder: Path, output: Path | None = None, *, overwrite: bool) -> Path:
    """Render a friction result folder's report from the folder alone (its recorded run) and
    add it to the folder (or write *output*).
    """
    from gripsense.estimate.results import FrictionResult
    from gripsense.io.output_folder import add_to_folder, write_file_atomic
    from gripsense.report.html import render_report
    from gripsense.report.summary_check import check_summary_file

    check_summary_file(folder)  # a hand-edited value: one line naming its key
    text = render_report(FrictionResult.from_files(folder))
    if output is None:
        return add_to_folder(folder, "report.html", text, overwrite=overwrite)
    return write_file_atomic(output, lambda tmp: tmp.write_text(text, encoding="utf-8"))


def report_cmd(
    result_dir: Annotated[Path, typer.Argument(help="folder written by gripsense friction")],
    output: Annotated[
        Path | None,
        typer.Option("-o", "--output", help="HTML file (default RESULT_DIR/report.html)"),
    ] = None,
    overwrite: Overwrite = False,
) -> None:
    """Write a self-contained HTML report (images embedded) of a friction result folder."""
    from gripsense.io.output_folder import check_output_file

    try:
        if output is not None:
            check_output_file(output, "report", overwrite=overwrite, inputs=[result_dir])
        out = _report_of_folder(result_dir, output, overwrite=overwrite)
    except GripsenseError as e:
        fail(e)
    say(f"report: {out}")


def _print_head(result: FrictionResult) -> None:
    from rich.text import Text

    m = result.meta
    head = Text.assemble((str(m.get("vehicle", "")), "bold"), f" — method {m['method']}")
    if m.get("receiver"):
        head.append(f", receiver {m['receiver']}")
    if "epochs_total" in m:
        head.append(
            f"; {m['epochs_used']} of {m['epochs_total']} epochs usable; heading offset "
            f"{m['heading_offset_deg']:.2f}° ({m['heading_offset_source']})"
        )
    console.print(head)


def print_friction(result: FrictionResult) -> None:
    """Print a friction result's summary table and its one-line explanation.

    Parameters
    ----------
    result : FrictionResult
        The result (one printer per result type: per axle, per wheel, else the head line).
    """
    from gripsense.estimate.results import AxleFriction, WheelFriction

    if isinstance(result, AxleFriction):
        _print_axles(result)
    elif isinstance(result, WheelFriction):
        _print_wheels(result)
    else:
        _print_head(result)
        say(result.explain())


def _num(x, fmt: str = ".2f") -> str:
    import numpy as np

    return "—" if x is None or not np.isfinite(x) else format(x, fmt)


def _print_axles(result: AxleFriction) -> None:
    import numpy as np
    from rich.table import Table

    _print_head(result)
    table = Table(
        title="Friction per axle — measured (model-free) and estimated (axle-window, tyre model)"
    )
    for col in (
        "axle",
        "measured grip",
        "data prove μ ≥",
        "μ estimate",
        "90 % interval",
        "surface",
        "slippery?",
        "limited by",
        "windows with a value",
    ):
        table.add_column(col)
    win = result.windows
    for rec in result.summary.to_dict("records"):
        if not rec.get("n"):
            table.add_row(rec["axle"], "—", "—", "—", "—", "—", "unknown", "no cornering", "—")
            continue
        mu = f"{rec['mu']:.2f}" if rec["observable"] else "no value"
        lo, hi = rec.get("mu_low", np.nan), rec.get("mu_high", np.nan)
        bound = rec.get("grip_used_lower", np.nan)
        if rec["observable"]:
            iv = f"{lo:.2f} – " + (f"{hi:.2f}" if np.isfinite(hi) else "∞")
        elif np.isfinite(hi) and not (np.isfinite(bound) and hi <= bound):
            iv = f"≤ {hi:.2f} (upper end only)"  # as explain() and the report say it
        else:
            iv = "—"
        nw = win[win["axle"] == rec["axle"]] if win is not None and len(win) else None
        obs = f"{int(nw['observable'].sum())} / {len(nw)}" if nw is not None and len(nw) else "—"
        table.add_row(
            rec["axle"],
            _num(rec.get("grip_used")),
            _num(rec.get("grip_used_lower")),
            mu,
            iv,
            rec["surface"],
            str(rec.get("slippery", "unknown")),
            "" if rec["observable"] else str(rec.get("limited_by") or ""),
            obs,
        )
    console.print(table)
    say(result.explain())


def _print_wheels(result: WheelFriction) -> None:
    import numpy as np
    from rich.table import Table

    _print_head(result)
    table = Table(title="Friction per wheel (steady cornering samples)")
    for col in (
        "wheel",
        "μ",
        "90 % interval",
        "surface",
        "valid / total",
        "axle: data prove μ ≥",
        "main flags",
    ):
        table.add_column(col)
    flag_cols = [
        c for c in result.summary.columns if c.startswith("n_") and c not in ("n_valid", "n_total")
    ]
    for rec in result.summary.to_dict("records"):
        mu = "—" if not np.isfinite(rec["mu"]) else f"{rec['mu']:.2f}"
        iv = "—" if not np.isfinite(rec["mu"]) else f"{rec['mu_low']:.2f} – {rec['mu_high']:.2f}"
        lb = _num(rec.get("grip_used_lower"))
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
    say(result.explain())


def stiffness(
    logs: Annotated[list[Path], typer.Argument(help="NMEA log(s) of steady cornering")],
    vehicle: Annotated[Path, typer.Option("--vehicle", help="vehicle description (TOML)")],
    sweep: Annotated[
        bool,
        typer.Option(
            "--sweep",
            help="also the G sweep of the 2018 Kochi University of Technology thesis (ch. 9.2)",
        ),
    ] = False,
    outdir: Annotated[
        Path | None, typer.Option("-o", "--outdir", help="folder for the table (and plots)")
    ] = None,
    overwrite: Overwrite = False,
) -> None:
    """Tread stiffness G per steady condition and wheel (2018 Kochi University of Technology
    thesis, ch. 9, like its Table 23).
    """
    import pandas as pd
    from rich.table import Table
    from rich.text import Text

    from gripsense.estimate.conditions import conditions
    from gripsense.estimate.stiffness import g_sweep, tread_stiffness
    from gripsense.io.output_folder import check_output_folder
    from gripsense.pipeline import FrictionRun
    from gripsense.report.figures import g_sweep_figure

    try:
        if outdir:
            check_output_folder(outdir, "stiffness", overwrite=overwrite)
        run = FrictionRun(vehicle, method="brush-2")
        veh = run.vehicle
        frames, sweeps = [], []
        for log in logs:
            res = run.run_log(log)
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
            Text(r["log"]),
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
        console.print("every condition is near the limit: G is biased low there (physics §6)")
    for name, i, sw in sweeps:
        console.print(f"G sweep {name} condition {i}: chosen {sw.chosen:.3g} N/m³ — {sw.reason}")
    if outdir:
        from gripsense.io.output_folder import ResultWriter

        try:
            with ResultWriter(
                outdir,
                "stiffness",
                overwrite=overwrite,
                command=command_line(),
                inputs=[*logs, vehicle],
            ) as tmp:
                tab.to_csv(tmp / "stiffness.csv", index=False)
                for name, i, sw in sweeps:
                    g_sweep_figure(sw).savefig(tmp / f"gsweep_{Path(name).stem}_{i}.png", dpi=90)
        except GripsenseError as e:
            fail(e)
        say(f"wrote {outdir / 'stiffness.csv'}")
