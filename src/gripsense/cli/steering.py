"""``gripsense steering``: identify C_s and k_s of a steering system (Osaka University
steering-stiffness report, 2019).
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Annotated

import typer

from gripsense.cli._common import Columns, Overwrite, command_line, console, fail, say
from gripsense.cli._help import QuickGroup
from gripsense.cli._numbers import finite_numbers
from gripsense.errors import GripsenseError

steering_app = typer.Typer(
    cls=QuickGroup,
    no_args_is_help=True,
    rich_markup_mode=None,
    help="Steering-system identification (Osaka University steering-stiffness report, 2019).",
)


def _floats(text: str, what: str) -> list[float]:
    return finite_numbers(text, f"--{what}")  # each a finite number, else one line naming it


@steering_app.command("identify")
def identify(
    config: Annotated[
        Path, typer.Argument(help="Car TOML (see gripsense/data/of18_steering.toml)")
    ],
    release: Annotated[
        list[Path] | None,
        typer.Option(help="Release test CSV (t_s, steer_deg at the steering wheel); repeat"),
    ] = None,
    step: Annotated[
        list[Path] | None,
        typer.Option(help="Step-steer CSV (t_s, steer_deg, yaw_rate_dps); repeat"),
    ] = None,
    settling: Annotated[
        str | None, typer.Option(help="Measured settling times [s], e.g. 0.80,0.86,0.76,0.84,0.72")
    ] = None,
    yaw_gain: Annotated[
        float | None, typer.Option("--yaw-gain", help="Measured yaw gain [deg/s²] at --steer-rate")
    ] = None,
    steer_rate: Annotated[
        float | None,
        typer.Option(
            "--steer-rate", help="Steering-wheel rate of --yaw-gain / reference rate [deg/s]"
        ),
    ] = None,
    gain_law: Annotated[
        str, typer.Option(help="Yaw gain vs rate: ln (seed eq. 7) or linear")
    ] = "ln",
    reference: Annotated[
        str, typer.Option(help="Settling band: initial (§4.1) or converged")
    ] = "initial",
    method: Annotated[
        str, typer.Option(help="Yaw gain from a trace: rise, slope or peak")
    ] = "rise",
    tyre_deflection: Annotated[
        Path | None, typer.Option(help="CSV force_N, deflection_mm: sets k_y from the slope")
    ] = None,
    output: Annotated[Path | None, typer.Option("-o", "--output", help="Output folder")] = None,
    columns: Columns = None,
    overwrite: Overwrite = False,
) -> None:
    """Identify kingpin damping C_s and steering stiffness k_s (k_s2) by alternating the
    settling-time and yaw-gain inversions to a fixed point.
    """
    from gripsense.config import SteeringCar
    from gripsense.identify.steering_run import identify_from_recordings
    from gripsense.io.output_folder import check_output_folder

    inputs = [config, *(release or []), *(step or [])]
    if tyre_deflection is not None:
        inputs.append(tyre_deflection)
    try:
        if output is not None:
            check_output_folder(output, "steering", overwrite=overwrite)
        run = identify_from_recordings(
            SteeringCar.from_toml(config),
            release=release,
            step=step,
            settling_times=_floats(settling, "settling") if settling else None,
            yaw_gain=yaw_gain,
            steer_rate_dps=steer_rate,
            gain_law=gain_law,
            reference=reference,
            method=method,
            tyre_deflection=tyre_deflection,
            columns=columns,
            log=say,
        )
    except GripsenseError as e:
        fail(e)
    _print_result(run, reference)
    if output is not None:
        _write(output, run, overwrite, inputs)


def _print_result(run, reference: str) -> None:
    """The identification's numbers, one line each."""
    import numpy as np

    res, car, times = run.result, run.car, run.times
    console.print(
        f"settling time {res.cs.t_mean_s:.3f} ± {res.cs.t_sd_s:.3f} s "
        f"({len(times)} tests, band: {reference})"
    )
    fp = res.first_pass
    console.print(
        f"first pass (seed): C_s = {fp.get('cs_rigid', float('nan')):.1f} with "
        f"k_s = k_s1 = {car.ks1_Nm_per_rad:.0f}"
    )
    if res.cs.flag != "ok":
        console.print(f"[yellow]C_s: {res.cs.flag}[/]")
    else:
        console.print(
            f"C_s = {res.cs.cs:.1f} N·m·s/rad  [{res.cs.low:.1f}, {res.cs.high:.1f}] "
            "(mean ± SD of the times)"
        )
    if res.ks is not None:
        if res.ks.flag != "ok":
            console.print(f"[yellow]k_s: {res.ks.flag}[/]")
        else:
            k2 = res.ks.ks2
            if np.isfinite(res.ks.low) and np.isfinite(res.ks.high):
                iv = (
                    f" [{res.ks.low:.0f}, {res.ks.high:.0f}]",
                    f" [{res.ks.ks2_low:.4g}, {res.ks.ks2_high:.4g}] (gain ± 1.96σ)",
                )
            else:
                iv = ("", " (no interval: a single summary yaw gain has no spread)")
            console.print(f"k_s = {res.ks.ks:.0f} N·m/rad{iv[0]}, k_s2 = {k2:.4g} N·m/rad{iv[1]}")
    console.print(
        f"alternation: {len(res.history)} steps, "
        + ("converged" if res.converged else "[yellow]not converged[/]")
    )


def _write(output: Path, run, overwrite: bool, inputs: list[Path]) -> None:
    """steering.json and the figures, atomically."""
    import numpy as np

    from gripsense.io.output_folder import ResultWriter
    from gripsense.physics.steering_system import simulate_release
    from gripsense.report.steering_figures import release_figure, settling_figure, yaw_gain_figure

    res, traces, alpha0 = run.result, run.traces, run.alpha0_rad
    d = res.to_dict()
    model = (
        simulate_release(res.car, alpha0_rad=alpha0, duration_s=3.0)
        if np.isfinite(res.cs.cs)
        else None
    )
    curves = [("k_s = k_s1 (first pass)", res.cs_rigid)]
    if res.ks is not None and np.isfinite(res.ks.ks):
        curves.append((f"k_s = {res.ks.ks:.0f}", res.cs))
    try:
        with ResultWriter(
            output, "steering", overwrite=overwrite, command=command_line(), inputs=inputs
        ) as tmp:
            (tmp / "steering.json").write_text(json.dumps(d, indent=2), encoding="utf-8")
            release_figure(traces, model).savefig(tmp / "release.png", dpi=110)
            settling_figure(curves, res.cs.t_mean_s, res.cs.t_sd_s).savefig(
                tmp / "settling.png", dpi=110
            )
            if res.ks is not None:
                yaw_gain_figure(res.ks).savefig(tmp / "yaw_gain.png", dpi=110)
    except GripsenseError as e:
        fail(e)
    say(f"wrote {output}/steering.json and figures")
