"""Sensor commands: ``brake-mu`` (accelerometer), ``camber`` (lasers), ``camera-slip`` (camera)."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from gripsense.cli._common import Columns, Overwrite, console, fail, old_column_flags, say
from gripsense.errors import GripsenseError

__all__ = ["brake_mu", "camber", "camera_slip"]


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
    plot: Annotated[
        Path | None, typer.Option("--plot", help="PNG: the traces with each plateau (Fig. 110)")
    ] = None,
    overwrite: Overwrite = False,
    columns: Columns = None,
) -> None:
    """Friction from locked-wheel braking: μ = a/g per event (2018 Kochi University of Technology
    thesis, ch. 8).
    """
    import numpy as np
    import pandas as pd
    from rich.table import Table
    from rich.text import Text

    from gripsense.estimate.braking import EVENT_COLUMNS, estimate_braking
    from gripsense.io.output_folder import check_output_file, write_file_atomic
    from gripsense.io.sensors.accel import read_accel_csv
    from gripsense.io.table import describe_columns
    from gripsense.report.figures import save_png

    frames = []
    header = [*EVENT_COLUMNS, "file"]
    old = {
        "--t-col": t_col != "t_s",
        "--ax-col": ax_col != "ax_g",
        "--ay-col": ay_col != "ay_g",
        "--az-col": az_col != "az_g",
        "--units": units != "g",
        "--ax-sign": ax_sign != 1.0,
        "--time-scale": time_scale != 1.0,
    }
    used_old = [k for k, v in old.items() if v]
    try:
        old_column_flags(used_old, columns, "t=time:ms,ax=-acc_x:g")
        if output:
            check_output_file(output, "braking", overwrite=overwrite, inputs=accel, header=header)
        if plot:
            check_output_file(plot, "braking", overwrite=overwrite, inputs=accel)
        runs = []
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
                columns=None if used_old else (columns or "auto"),
            )
            say(f"{f.name}: columns {describe_columns(acc.attrs['columns'])}")
            if acc.attrs["rows"]["note"]:  # rows not used (inf, no ax): counted, said
                say(acc.attrs["rows"]["note"])
            res = estimate_braking(acc, source=str(f))
            frames.append(res.events.assign(file=f.name))
            runs.append((acc, res))
        if plot:
            from gripsense.report.sensor_figures import braking_figure

            fig = braking_figure(runs)
            write_file_atomic(plot, lambda tmp: save_png(fig, tmp, "braking", dpi=100))
    except GripsenseError as e:
        fail(e)
    ev = pd.concat(frames, ignore_index=True)
    table = Table(title="Locked-wheel braking events")
    for col in ("file", "onset [s]", "plateau [s]", "μ = a/g", "spread", "μ 3-axis", "slope [1/s]"):
        table.add_column(col)
    for r in ev.to_dict("records"):
        table.add_row(
            Text(r["file"]),
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
        f"μ = {ev['mu'].mean():.3f}{sd} over {len(ev)} event{'' if len(ev) == 1 else 's'} — "
        "sliding friction of "
        "locked wheels (below peak μ; includes ~0.01–0.02 g of drag)"
    )
    if output:
        _write_csv(ev[header], output)
    if plot:
        say(f"wrote {plot}")


def _write_csv(df, output: Path) -> None:
    from gripsense.io.output_folder import write_file_atomic

    try:
        write_file_atomic(output, lambda tmp: df.to_csv(tmp, index=False))
    except GripsenseError as e:
        fail(e)
    say(f"wrote {output}")


def camber(
    laser: Annotated[Path, typer.Argument(help="CSV with t_s and two laser distances")],
    spacing_m: Annotated[float, typer.Option("--spacing-m", help="sensor spacing [m]")],
    outer_col: Annotated[
        str | None, typer.Option("--outer-col", help="deprecated: use --columns outer=…")
    ] = None,
    inner_col: Annotated[
        str | None, typer.Option("--inner-col", help="deprecated: use --columns inner=…")
    ] = None,
    scale_m: Annotated[
        float | None, typer.Option("--scale-m", help="deprecated: use a unit in --columns")
    ] = None,
    columns: Columns = None,
    calibrate_s: Annotated[
        float,
        typer.Option(
            "--calibrate-s",
            help="first seconds on a flat floor at the reference camber (0: no calibration)",
        ),
    ] = 0.0,
    reference_deg: Annotated[float, typer.Option("--reference-deg")] = 0.0,
    output: Annotated[Path | None, typer.Option("-o", "--output", help="CSV")] = None,
    overwrite: Overwrite = False,
) -> None:
    """Camber to the ground from two laser displacement sensors (Toyota CRDL R&D Review
    34(3), 1999, Fig. 3).
    """
    import numpy as np

    from gripsense.io.output_folder import check_output_file
    from gripsense.io.sensors.laser import read_laser_csv
    from gripsense.io.table import describe_columns
    from gripsense.vision.camber_laser import (
        CAMBER_COLUMNS,
        calibration_offsets,
        camber_from_lasers,
    )

    try:
        if output:
            check_output_file(
                output, "camber", overwrite=overwrite, inputs=[laser], header=CAMBER_COLUMNS
            )
        old = {"--outer-col": outer_col, "--inner-col": inner_col, "--scale-m": scale_m}
        used_old = [k for k, v in old.items() if v is not None]
        if old_column_flags(used_old, columns, "t=t_s:s,outer=d_outer_mm:mm,inner=d_inner_mm:mm"):
            d = read_laser_csv(
                laser,
                outer_col=outer_col or "d_outer_mm",
                inner_col=inner_col or "d_inner_mm",
                scale_m=1e-3 if scale_m is None else scale_m,
            )
        else:
            d = read_laser_csv(laser, columns=columns)
        say(f"{laser.name}: columns {describe_columns(d.attrs['columns'])}")
        if d.attrs["rows"]["note"]:  # rows with an inf reading: rejected, counted, said
            say(d.attrs["rows"]["note"])
        off_o, off_i = calibration_offsets(d, calibrate_s) if calibrate_s > 0 else (0.0, 0.0)
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
        _write_csv(d[CAMBER_COLUMNS], output)


def camera_slip(
    source: Annotated[Path, typer.Argument(help="folder of frames or a video file")],
    fps: Annotated[float, typer.Option("--fps", help="frame rate [1/s]")],
    mm_per_px: Annotated[
        float | None, typer.Option("--mm-per-px", help="ground scale (gives the speed)")
    ] = None,
    output: Annotated[
        Path, typer.Option("-o", "--output", help="CSV (a .png plot next to it)")
    ] = Path("camera_slip.csv"),
    overwrite: Overwrite = False,
) -> None:
    """Slip angle from a downward camera on the wheel (Toyota CRDL R&D Review 34(3), 1999,
    §2.1); image top = forward.
    """
    from gripsense.io.output_folder import check_output_file, write_file_atomic
    from gripsense.report.figures import save_png
    from gripsense.report.sensor_figures import camera_slip_figure
    from gripsense.vision.slip_camera import SLIP_COLUMNS, slip_from_frames

    plot = output.with_suffix(".png")
    try:
        check_output_file(
            output, "camera-slip", overwrite=overwrite, inputs=[source], header=SLIP_COLUMNS
        )
        check_output_file(plot, "camera-slip", overwrite=overwrite, inputs=[source])
        res = slip_from_frames(source, fps=fps, mm_per_px=mm_per_px)
        write_file_atomic(output, lambda tmp: res.to_csv(tmp, index=False))
        fig = camera_slip_figure(res)
        write_file_atomic(plot, lambda tmp: save_png(fig, tmp, "camera-slip"))
    except GripsenseError as e:
        fail(e)
    ok = res[res["ok"]]
    if len(ok):
        sp = "" if mm_per_px is None else f", ground speed {ok['speed_mps'].median():.2f} m/s"
        console.print(
            f"{len(ok)} of {len(res)} frame pairs accepted; median slip angle "
            f"{ok['slip_angle_deg'].median():.2f}° (ISO){sp}"
        )
    else:
        console.print(f"no frame pair passed the quality checks ({len(res)} pairs)")
    say(f"wrote {output} and {plot}")
