"""``gripsense live``: friction from a receiver in real time."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from gripsense.cli._common import (
    LOG_COLUMNS_HELP,
    Dbc,
    Overwrite,
    TimeOffset,
    console,
    fail,
    log_options,
    say,
)
from gripsense.errors import GripsenseError, InputError


def live(
    vehicle: Annotated[Path | None, typer.Option(help="Vehicle TOML")] = None,
    serial: Annotated[str | None, typer.Option(help="Serial device, e.g. /dev/ttyUSB0")] = None,
    baud: Annotated[int, typer.Option(help="Serial baud rate")] = 115200,
    tcp: Annotated[str | None, typer.Option(help="HOST:PORT of a receiver streaming NMEA")] = None,
    replay: Annotated[
        Path | None,
        typer.Option(help="Replay a log file: NMEA, UBX, VBOX, MDF4 or CAN (plain or .gz)"),
    ] = None,
    speed: Annotated[float, typer.Option(help="Replay speed (1 = real time, 0 = max)")] = 1.0,
    method: Annotated[
        str, typer.Option(help="Friction method (as gripsense friction)")
    ] = "axle-window",
    receiver: Annotated[
        str | None,
        typer.Option(
            help="v100 | white-0.3 | rtk | FILE.toml (default: the vehicle file's [receiver], "
            "else v100)"
        ),
    ] = None,
    output: Annotated[
        Path | None, typer.Option("-o", "--output", help="results.csv or results.parquet")
    ] = None,
    calibration: Annotated[
        Path | None,
        typer.Option(help="the vehicle's calibration file (gripsense calibrate)"),
    ] = None,
    window_s: Annotated[float, typer.Option(help="Estimation window [s]")] = 30.0,
    duration_s: Annotated[float | None, typer.Option(help="Stop after this many seconds")] = None,
    quiet: Annotated[bool, typer.Option(help="No live display (headless)")] = False,
    recover: Annotated[
        Path | None,
        typer.Option(help="Convert OUTPUT.parquet.partial.csv left by a killed run, then exit"),
    ] = None,
    columns: Annotated[
        str | None, typer.Option("--columns", help="for --replay: " + LOG_COLUMNS_HELP)
    ] = None,
    steer_csv: Annotated[
        Path | None,
        typer.Option(
            "--steer-csv",
            help="for --replay: a steering CSV replayed beside the log, aligned by time as "
            "gripsense friction --steer-csv (t_s, road_wheel_deg; enables the front axle)",
        ),
    ] = None,
    steer_columns: Annotated[
        str | None,
        typer.Option(
            "--steer-columns",
            help="mapping for --steer-csv: t=...,road_wheel=...|steering_wheel=...,torque=... "
            "(as gripsense friction)",
        ),
    ] = None,
    dbc: Dbc = None,
    time_offset: TimeOffset = None,
    overwrite: Overwrite = False,
) -> None:
    """Read NMEA or UBX as it arrives (serial, TCP or replay), update μ continuously, show and
    record it; Ctrl-C (SIGINT) or SIGTERM stops cleanly.
    """
    from gripsense.live import SerialSource, TcpSource, open_replay, run_live
    from gripsense.live import recover as do_recover
    from gripsense.live.display import LiveDisplay, render
    from gripsense.live.runner import check_live_outputs, output_paths

    try:
        if recover is not None:
            p = do_recover(recover, overwrite=overwrite)
            say(f"recovered {p}")
            return
        if sum(x is not None for x in (serial, tcp, replay)) != 1:
            raise InputError(
                "give exactly one source: --serial DEV, --tcp HOST:PORT or --replay LOG"
            )
        if vehicle is None:
            raise InputError("--vehicle car.toml is required")
        if steer_csv is not None and replay is None:
            raise InputError(
                "--steer-csv is replayed beside --replay LOG on the log's clock; a live "
                "receiver's steering must come in its stream"
            )
        if steer_columns is not None and steer_csv is None:
            raise InputError("--steer-columns maps the columns of --steer-csv FILE: give it too")
        if calibration is not None:
            from gripsense.config.calibration import calibrated_vehicle

            vehicle = calibrated_vehicle(vehicle, calibration)
        if output is not None:  # before the source is opened: nothing is lost to a bad -o
            ins = [p for p in (replay, steer_csv) if p is not None]
            check_live_outputs(output, overwrite=overwrite, inputs=ins)
        if replay is not None:
            src = open_replay(replay, speed, log_options(columns, dbc, time_offset))
        elif tcp is not None:
            host, _, port = tcp.rpartition(":")
            if not host or not port.isdigit():
                raise InputError(f"--tcp {tcp!r}: expected HOST:PORT")
            src = TcpSource(host, int(port))
        else:
            src = SerialSource(serial, baud)
        if quiet:
            res = run_live(
                src,
                vehicle,
                method=method,
                receiver=receiver,
                output=output,
                window_s=window_s,
                duration_s=duration_s,
                overwrite=overwrite,
                steer_csv=steer_csv,
                steer_columns=steer_columns,
            )
        else:
            with LiveDisplay(console) as disp:
                res = run_live(
                    src,
                    vehicle,
                    method=method,
                    receiver=receiver,
                    output=output,
                    window_s=window_s,
                    duration_s=duration_s,
                    display=disp,
                    overwrite=overwrite,
                    steer_csv=steer_csv,
                    steer_columns=steer_columns,
                )
    except GripsenseError as e:
        fail(e)
    rep, st = res["report"], res["stats"]
    if quiet:
        console.print(render(res["summary"], st, _Ing(rep), src))
    console.print(
        f"stopped: {res['stopped_by']}; {rep.total_lines} {rep.unit} "
        f"({sum(rep.parsed.values())} parsed, {sum(rep.ignored.values())} ignored, "
        f"{sum(rep.rejected.values())} rejected), {rep.n_epochs} epochs, "
        f"{getattr(src, 'reconnects', 0)} reconnects"
    )
    for note in [*getattr(src, "notes", []), *res.get("notes", [])]:
        say(f"note: {note}")
    if res.get("steering") and not res.get("front_axle"):  # else the display said why not
        say(f"steering: {res['steering']}")
    for t0, dt in st.gaps:
        console.print(f"gap: {dt:.1f} s of data missing after t = {t0:.1f} s")
    if output is not None:
        say(f"wrote {output} and {output_paths(output)['raw']}")


class _Ing:
    def __init__(self, rep):
        self.report = rep
