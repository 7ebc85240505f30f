"""``gripsense fleet``: a friction map from a directory of drives."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

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


def fleet(
    logs: Annotated[
        list[str], typer.Argument(help='Log files or glob patterns ("LOGS/**/*.nmea")')
    ],
    output: Annotated[Path, typer.Option("-o", "--output", help="Output folder")],
    vehicle: Annotated[Path | None, typer.Option(help="Vehicle TOML for every log")] = None,
    vehicle_map: Annotated[
        Path | None, typer.Option(help="CSV pattern,vehicle_toml[,vehicle_id] for mixed fleets")
    ] = None,
    method: Annotated[str, typer.Option(help="Friction method")] = "axle-window",
    receiver: Annotated[
        str | None,
        typer.Option(
            help="v100 | white-0.3 | rtk | FILE.toml (default: each vehicle file's [receiver], "
            "else v100)"
        ),
    ] = None,
    scheduler: Annotated[
        str | None, typer.Option(help="Existing Dask scheduler tcp://HOST:8786")
    ] = None,
    workers: Annotated[int, typer.Option(help="LocalCluster worker processes")] = 2,
    h3_res: Annotated[int, typer.Option("--h3-res", help="H3 resolution (11 ≈ 25 m cells)")] = 11,
    bucket: Annotated[
        str, typer.Option(help="Time bucket, e.g. '1 hour', '15 minutes'")
    ] = "1 hour",
    since: Annotated[
        str | None, typer.Option(help="Ignore data before this ISO time (UTC)")
    ] = None,
    logs_per_task: Annotated[int, typer.Option(help="Logs per Dask task")] = 4,
    calibrate: Annotated[
        bool,
        typer.Option(
            "--calibrate",
            help="Learn each vehicle id's tyre stiffness from its own logs first and use it "
            "(written to OUTPUT/calibration/; starts from the vehicle file's calibration)",
        ),
    ] = False,
    columns: Annotated[str | None, typer.Option("--columns", help=LOG_COLUMNS_HELP)] = None,
    steer_columns: Annotated[
        str | None,
        typer.Option(
            "--steer-columns",
            help="mapping of the logs' steering CSVs (<log stem>_steer.csv beside each log, "
            "e.g. drive1.nmea.gz → drive1_steer.csv): t=...,road_wheel=...|steering_wheel=... "
            "(as gripsense friction --steer-columns; default by header names)",
        ),
    ] = None,
    dbc: Dbc = None,
    time_offset: TimeOffset = None,
    overwrite: Overwrite = False,
) -> None:
    """Turn many drives into a friction map: per-estimate Parquet, cells per H3 cell and time
    bucket (cells.parquet, cells.geojson) and an offline map page (map.html).
    """
    from rich.progress import Progress

    from gripsense.fleet import run_fleet

    try:
        with Progress(console=console, transient=True, disable=not console.is_terminal) as prog:
            res = run_fleet(
                logs,
                output,
                vehicle=vehicle,
                vehicle_map=vehicle_map,
                method=method,
                receiver=receiver,
                h3_res=h3_res,
                bucket=bucket,
                since=since,
                scheduler=scheduler,
                workers=workers,
                logs_per_task=logs_per_task,
                progress=_progress(prog),
                overwrite=overwrite,
                command=command_line(),
                calibrate=calibrate,
                log_options=log_options(columns, dbc, time_offset),
                steer_columns=steer_columns,
            )
    except GripsenseError as e:
        fail(e)
    _say_fleet(res)


def _progress(prog):
    """The tasks' progress: a bar on a terminal; piped, a line per tenth of the tasks."""
    task = prog.add_task("tasks", total=None)
    said = [-1]

    def progress(done, total):
        prog.update(task, completed=done, total=total)
        if not console.is_terminal:  # piped: a line per tenth of the tasks instead
            tenth = 10 * done // max(total, 1)
            if tenth > said[0] or done == total:
                said[0] = tenth
                say(f"tasks: {done} of {total} done")

    return progress


def _say_fleet(res) -> None:
    """What the run made: logs used and with problems, front axles left out for want of a
    steering channel, the cell-buckets by status, the calibrations and the map.
    """
    import pandas as pd

    from gripsense.fleet.aggregate import (
        STATUS_CONTRADICTION,
        STATUS_ESTIMATE,
        STATUS_INCONSISTENT,
        STATUS_MEASURED,
        STATUS_RANGE,
    )

    lg, c = res.logs, res.cells
    bad = int((lg["problem"] != "").sum())
    say(f"{len(lg)} logs: {len(lg) - bad} used, {bad} with problems ({res.paths['problems']})")
    used = lg[lg["problem"] == ""]
    n_front = int((used["front_axle"].fillna("") != "").sum()) if "front_axle" in used else 0
    if n_front:  # the front axles never disappear without a word
        say(
            f"{n_front} log{'s' if n_front != 1 else ''} without a steering channel: front axle "
            f"not estimated (give <log stem>_steer.csv beside each log, or a steering channel in "
            f"the log; {res.paths['logs']} says which; docs/fleet.md)"
        )
    st = c["status"].value_counts() if len(c) else pd.Series(dtype="int64")
    n_slip = int((c["slippery"] == "slippery").sum()) if len(c) else 0
    console.print(
        f"{len(c)} cell-buckets: {st.get(STATUS_ESTIMATE, 0)} with a value, "
        f"{st.get(STATUS_RANGE, 0)} with a bounded range only, "
        f"{st.get(STATUS_MEASURED, 0)} with measured grip only, "
        f"{st.get(STATUS_CONTRADICTION, 0)} contradictions (passes that disagree), "
        f"{st.get(STATUS_INCONSISTENT, 0)} inconsistent (a range below the measured grip: "
        f"check the vehicle file); {n_slip} slippery"
    )
    for note in res.notes:  # a declaration a calibration contradicts, said out loud
        say(note)
    if "calibration" in res.paths:
        say(f"calibrations: {res.paths['calibration']}")
    say(f"map: {res.paths['map']}")
