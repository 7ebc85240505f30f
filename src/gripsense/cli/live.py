"""``gripsense live``: friction from a receiver in real time."""

from __future__ import annotations

import math
import signal
from pathlib import Path
from typing import Annotated, Any

import typer

from gripsense.cli._common import (
    LOG_COLUMNS_HELP,
    Dbc,
    Overwrite,
    TimeOffset,
    command_line,
    console,
    err_console,
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
        typer.Option(
            help="Replay a log file: NMEA, UBX, VBOX, MDF4, CAN or a ROS bag (plain or .gz)"
        ),
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
        typer.Option(
            help="After a killed run: convert OUTPUT.parquet.partial.csv (or check OUTPUT.csv); "
            "rows that cannot be read are kept in OUTPUT.rejected; then exit"
        ),
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
    # a signal while the run is set up stops it with one line and nothing written; from the
    # moment the output's files exist it stops the loop, which closes them complete (exit 0)
    state: dict = {"phase": "setup", "signal": None}

    def on_signal(signum, _frame):
        if state["phase"] == "setup":
            raise _Interrupted(signum)
        state["signal"] = state["signal"] or signal.Signals(signum).name

    old = {s: signal.signal(s, on_signal) for s in (signal.SIGINT, signal.SIGTERM)}
    try:
        _live(
            vehicle=vehicle, serial=serial, baud=baud, tcp=tcp, replay=replay, speed=speed,
            method=method, receiver=receiver, output=output, calibration=calibration,
            window_s=window_s, duration_s=duration_s, quiet=quiet, recover=recover,
            columns=columns, steer_csv=steer_csv, steer_columns=steer_columns, dbc=dbc,
            time_offset=time_offset, overwrite=overwrite, state=state,
        )  # fmt: skip
    except _Interrupted as e:
        from rich.text import Text

        name = signal.Signals(e.signum).name
        err_console.print(
            Text.assemble(("error: ", "bold red"), f"interrupted ({name}) before the run "
                          "started; nothing was written"),
            highlight=False,
        )  # fmt: skip
        raise typer.Exit(128 + e.signum) from None
    finally:
        for s, h in old.items():
            signal.signal(s, h)


class _Interrupted(BaseException):
    """SIGINT or SIGTERM while a live run is set up (a BaseException: nothing swallows it)."""

    def __init__(self, signum: int):
        super().__init__(signum)
        self.signum = signum


def _check_numbers(speed: float, window_s: float, duration_s: float | None, baud: int) -> None:
    if not (math.isfinite(speed) and speed >= 0):
        raise InputError(f"--speed {speed}: must be a number >= 0 (0 = as fast as possible)")
    if not (math.isfinite(window_s) and window_s > 0):
        raise InputError(f"--window-s {window_s}: must be a number of seconds > 0")
    if duration_s is not None and not (math.isfinite(duration_s) and duration_s > 0):
        raise InputError(f"--duration-s {duration_s}: must be a number of seconds > 0")
    if baud <= 0:
        raise InputError(f"--baud {baud}: must be a positive baud rate, e.g. 115200")


def _live(
    *,
    vehicle,
    serial,
    baud,
    tcp,
    replay,
    speed,
    method,
    receiver,
    output,
    calibration,
    window_s,
    duration_s,
    quiet,
    recover,
    columns,
    steer_csv,
    steer_columns,
    dbc,
    time_offset,
    overwrite,
    state,
) -> None:
    from gripsense.live.recording import check_live_outputs

    try:
        if recover is not None:
            state["phase"] = "recover"  # a signal now waits until the recovery is complete
            _recover(recover, overwrite, state)
            return
        address = _check_args(speed, window_s, duration_s, baud, serial, tcp, replay, vehicle,
                              steer_csv, steer_columns)  # fmt: skip
        if calibration is not None:
            from gripsense.config.calibration import calibrated_vehicle

            conflicts: list[str] = []
            vehicle = calibrated_vehicle(vehicle, calibration, conflicts)
            for line in conflicts:  # a declaration the drives contradict, said out loud
                say(line)
        if output is not None:  # before the source is opened: nothing is lost to a bad -o
            ins = [p for p in (replay, steer_csv) if p is not None]
            check_live_outputs(output, overwrite=overwrite, inputs=ins)
        src = _open_source(serial, baud, address, replay, speed, (columns, dbc, time_offset))
        kw: dict[str, Any] = {
            "method": method, "receiver": receiver, "output": output, "window_s": window_s,
            "duration_s": duration_s, "overwrite": overwrite, "steer_csv": steer_csv,
            "steer_columns": steer_columns, "stop_when": lambda _stats: state["signal"],
            "command": command_line(),
        }  # fmt: skip
        state["phase"] = "run"
        res = _run(src, vehicle, quiet, kw)
    except GripsenseError as e:
        state["phase"] = "done"
        fail(e)
    state["phase"] = "done"
    _say_end(res, src, quiet, output)


def _recover(recover: Path, overwrite: bool, state: dict) -> None:
    """``--recover``: the killed run's output converted (or checked), what was kept said."""
    from gripsense.live import recover as do_recover

    rec = do_recover(recover, overwrite=overwrite)
    say(f"recovered {rec['results']}: {rec['rows']} rows")
    if rec["rejected"]:
        n = len(rec["rejected"])
        line, _, why = rec["rejected"][0]
        say(
            f"note: {n} row{'s' if n > 1 else ''} could not be read (line {line}: {why}"
            f"{' …' if n > 1 else ''}); kept byte for byte in {rec['rejected_path']}"
        )
    if state["signal"]:
        say(f"note: {state['signal']} came during the recovery; it was completed first")


def _check_args(
    speed, window_s, duration_s, baud, serial, tcp, replay, vehicle, steer_csv, steer_columns
) -> tuple[str, int] | None:
    """The options of a run: numbers in range, one source, a vehicle, a steering CSV only
    beside a replay; returns the ``--tcp`` address.
    """
    from gripsense.live.sources import parse_host_port

    _check_numbers(speed, window_s, duration_s, baud)
    if sum(x is not None for x in (serial, tcp, replay)) != 1:
        raise InputError("give exactly one source: --serial DEV, --tcp HOST:PORT or --replay LOG")
    address = parse_host_port(tcp) if tcp is not None else None
    if vehicle is None:
        raise InputError("--vehicle car.toml is required")
    if steer_csv is not None and replay is None:
        raise InputError(
            "--steer-csv is replayed beside --replay LOG on the log's clock; a live "
            "receiver's steering must come in its stream"
        )
    if steer_columns is not None and steer_csv is None:
        raise InputError("--steer-columns maps the columns of --steer-csv FILE: give it too")
    return address


def _open_source(serial, baud, address, replay, speed, log_flags: tuple):
    """The source: a replayed log (read with the log flags ``--columns``, ``--dbc``,
    ``--time-offset``), a TCP stream or a serial port.
    """
    from gripsense.live import SerialSource, TcpSource, open_replay

    if replay is not None:
        return open_replay(replay, speed, log_options(*log_flags))
    if address is not None:
        return TcpSource(*address)
    return SerialSource(serial, baud)


def _run(src, vehicle, quiet: bool, kw: dict[str, Any]) -> dict:
    """:func:`~gripsense.live.run_live`, headless or with the live display."""
    from gripsense.live import run_live
    from gripsense.live.display import LiveDisplay

    if quiet:
        return run_live(src, vehicle, **kw)
    with LiveDisplay(console) as disp:
        return run_live(src, vehicle, display=disp, **kw)


def _say_end(res: dict, src, quiet: bool, output: Path | None) -> None:
    """How the run ended: the last state (headless), the input's accounting, notes, gaps and
    the files written.
    """
    from gripsense.live.display import render
    from gripsense.live.recording import output_paths

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
