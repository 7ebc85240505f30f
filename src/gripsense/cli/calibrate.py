"""``gripsense calibrate``: a vehicle's tyre stiffness learned from its own everyday driving."""

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
from gripsense.cli.friction import RECEIVER_HELP
from gripsense.errors import GripsenseError

__all__ = ["calibrate"]


def calibrate(
    logs: Annotated[
        list[Path],
        typer.Argument(help="logs of everyday driving (NMEA, VBOX, UBX, MDF4, CAN, ROS bags)"),
    ],
    vehicle: Annotated[Path, typer.Option("--vehicle", help="vehicle description (TOML)")],
    output: Annotated[
        Path, typer.Option("-o", "--output", help="calibration file to write (TOML)")
    ],
    receiver: Annotated[str | None, typer.Option("--receiver", help=RECEIVER_HELP)] = None,
    steer_csv: Annotated[
        list[Path] | None,
        typer.Option(
            "--steer-csv",
            help="steering channel per log, in the logs' order (the front axle needs it)",
        ),
    ] = None,
    update: Annotated[
        Path | None,
        typer.Option(
            "--update",
            help="an earlier calibration of this vehicle: the new drives are added to it",
        ),
    ] = None,
    columns: Annotated[str | None, typer.Option("--columns", help=LOG_COLUMNS_HELP)] = None,
    dbc: Dbc = None,
    time_offset: TimeOffset = None,
    overwrite: Overwrite = False,
) -> None:
    """Learn each axle's cornering stiffness (one wheel, at the static load) and its
    uncertainty from the linear range of everyday driving, the curve's shape from drives that
    took an axle near its limit (a sweep, a track session), and with a steering-torque channel
    the steering's lever at low grip; friction and live take the file with
    --calibration, every command (fleet too) when the vehicle file names it in a calibration
    table (file = "car.calibration.toml").
    """
    from gripsense.config import Vehicle
    from gripsense.config.calibration import calibration_toml, read_calibration, usable_calibration
    from gripsense.io.output_folder import check_output_file, write_file_atomic
    from gripsense.pipeline import learn_calibration

    try:
        inputs = [*logs, vehicle, *(steer_csv or [])]
        check_output_file(output, "calibration", overwrite=overwrite, inputs=inputs)
        veh = Vehicle.from_toml(vehicle)
        previous = read_calibration(update) if update is not None else None
        cal = learn_calibration(  # only what friction and --update can read back
            [str(p) for p in logs],
            veh,
            receiver=receiver,
            steer_csvs=[str(p) for p in steer_csv] if steer_csv else None,
            previous=previous,
            log_options=log_options(columns, dbc, time_offset),
        )
        cal = usable_calibration(cal)
        text = calibration_toml(cal)
    except GripsenseError as e:
        fail(e)
    _print_stiffness(veh, cal, bool(steer_csv))
    _say_findings(veh, cal)
    try:
        out = write_file_atomic(output, lambda tmp: Path(tmp).write_text(text, encoding="utf-8"))
    except GripsenseError as e:
        fail(e)
    say(f"wrote {out}")


def _print_stiffness(veh, cal, steering_channel: bool) -> None:
    """The table of each axle's declared and learned cornering stiffness (why not, where an
    axle was not learned).
    """
    from rich.table import Table

    table = Table(title=f"Cornering stiffness learned for {veh.name}")
    for col in ("axle", "declared [N/rad]", "learned [N/rad]", "1σ", "bins", "drives"):
        table.add_column(col)
    for axle in ("front", "rear"):
        if axle not in veh.tyres:
            continue
        declared = float(veh.cornering_stiffness(axle, veh.static_load(axle)))
        a = cal.axles.get(axle)
        n_drives = sum(d.axle == axle for d in cal.drives)
        if a is None:
            why = (
                "no steering channel"
                if axle == "front" and not steering_channel
                else "too few bins"
            )
            if axle in cal.left_out:
                why = "see below"
            table.add_row(axle, f"{declared:.0f}", f"not learned ({why})", "—", "0", "0")
            continue
        table.add_row(
            axle,
            f"{declared:.0f}",
            f"{a.cornering_stiffness_N_per_rad:.0f}",
            f"{100 * a.stiffness_uncertainty:.1f} %",
            str(a.bins),
            str(n_drives),
        )
    console.print(table)


def _say_findings(veh, cal) -> None:
    """Drives counted once, the curve's shape, conflicts with the declaration (one line each),
    what was left out and why, and the steering lever learned.
    """
    from gripsense.config.calibration import shape_lines, stiffness_conflict

    for name in cal.repeated:
        say(f"{name}: already in the calibration (same content): not counted twice")
    for line in shape_lines(veh, cal):
        say(line)
    for axle, a in sorted(cal.axles.items()):  # conflicts said out loud, one line each
        if a.drives_disagree:
            say(a.drives_disagree)
        if axle in veh.tyres:
            c_d = float(veh.cornering_stiffness(axle, veh.static_load(axle)))
            line = stiffness_conflict(axle, c_d, veh.tyres[axle].stiffness_uncertainty, a)
            if line:
                say(line)
    if cal.steering is not None:
        from gripsense.estimate.calibration import lever_conflict

        line = lever_conflict(veh, cal.steering)
        if line:
            say(line)
    for why in cal.left_out.values():
        say(why)
    if cal.steering is not None:
        st = cal.steering
        n_drives = sum(d.axle == "steering" for d in cal.drives)
        say(
            f"steering lever learned (caster + pneumatic trail × the torque channel's scale): "
            f"{st.lever_m * 1e3:.1f} mm ± {100 * st.lever_uncertainty:.1f} % from {st.bins} "
            f"bins of {n_drives} drive(s)"
        )
