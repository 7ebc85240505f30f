"""``gripsense steering``: identify C_s and k_s of a steering system (Osaka University
steering-stiffness report, 2019).
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Annotated

import numpy as np
import typer

from gripsense.cli._common import Columns, Overwrite, command_line, console, fail, say
from gripsense.errors import GripsenseError, InputError
from gripsense.io.output_folder import ResultWriter, check_output_folder
from gripsense.io.table import Quantity

steering_app = typer.Typer(
    no_args_is_help=True,
    rich_markup_mode=None,
    help="Steering-system identification (Osaka University steering-stiffness report, 2019).",
)


STEERING_QUANTITIES = {
    "t": Quantity("time", ("t", "time")),
    "steer": Quantity("angle", ("steer", "steering_wheel", "handwheel", "swa")),
    "yaw_rate": Quantity("angular rate", ("yaw_rate", "yawrate")),
    "force": Quantity("force", ("force", "fy")),
    "deflection": Quantity("length", ("deflection", "y")),
}
"""Keys of the steering recordings (release, step-steer, tyre deflection) and the header names
mapped without being told; one ``--columns`` serves all of them."""


def _read_csv(path: Path, need: tuple[str, ...], columns: str | None) -> dict[str, np.ndarray]:
    """Values in SI of the keys *need* (rows with a missing value dropped)."""
    from gripsense.io.table import describe_columns, map_table, parse_columns, read_table

    spec = None
    if columns:
        parse_columns(columns, STEERING_QUANTITIES)  # every key and unit checked, for any file
        spec = ",".join(p for p in columns.split(",") if p.split("=", 1)[0].strip() in need)
    df = read_table(path)
    v, used = map_table(
        df,
        path,
        {k: STEERING_QUANTITIES[k] for k in need},
        spec if spec else None,
        required=need,
        example=",".join(f"{k}=HEADER:unit" for k in need),
    )
    say(f"{path.name}: columns {describe_columns(used)}")
    ok = np.all([np.isfinite(v[k]) for k in need], axis=0)
    return {k: v[k][ok] for k in need}


def _floats(text: str, what: str) -> list[float]:
    try:
        return [float(x) for x in text.split(",") if x.strip()]
    except ValueError:
        raise InputError(f"--{what}: {text!r} is not a comma-separated list of numbers") from None


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
    from dataclasses import replace

    from gripsense.config import SteeringCar
    from gripsense.identify.steering import (
        identify_steering,
        normalise_yaw_gain,
        tyre_lateral_stiffness,
    )
    from gripsense.identify.steering_metrics import (
        release_onset,
        release_settling_time,
        step_metrics,
    )
    from gripsense.physics.steering_system import simulate_release

    inputs = [config, *(release or []), *(step or [])]
    if tyre_deflection is not None:
        inputs.append(tyre_deflection)
    try:
        if output is not None:
            check_output_folder(output, "steering", overwrite=overwrite)
        car = SteeringCar.from_toml(config)
        n = car.steering_ratio
        ref_rate = float(steer_rate or car.reference_steer_rate_dps)
        stop = np.deg2rad(car.step_stop_deg) / n
        alpha0 = np.deg2rad(car.release_angle_deg) / n
        if tyre_deflection is not None:
            td = _read_csv(tyre_deflection, ("force", "deflection"), columns)
            ky, ky_sig = tyre_lateral_stiffness(td["force"], td["deflection"])
            car = replace(car, tyre_lateral_stiffness_N_per_m=ky)
            console.print(
                f"k_y = {ky / 1000:.1f} ± {ky_sig / 1000:.1f} N/mm from "
                f"{tyre_deflection.name} ({len(td['force'])} points)"
            )
        times = _floats(settling, "settling") if settling else []
        traces = []
        for p in release or []:
            df = _read_csv(p, ("t", "steer"), columns)
            t, a = df["t"], np.rad2deg(df["steer"])
            ts = release_settling_time(t, a, reference=reference)
            times.append(ts)
            say(f"{p.name}: settling time {ts:.3f} s")
            on = t >= release_onset(t, a)
            traces.append((t[on] - t[on][0], a[on]))
        if not times:
            raise InputError("give settling times: --settling t1,t2,... or --release FILE.csv")
        gain, gain_sig = yaw_gain, float("nan")
        if step:
            rates, gains = [], []
            for p in step:
                df = _read_csv(p, ("t", "steer", "yaw_rate"), columns)
                m = step_metrics(
                    df["t"], np.rad2deg(df["steer"]), np.rad2deg(df["yaw_rate"]), method=method
                )
                rates.append(m["steer_rate"])
                gains.append(m["yaw_gain"])
                console.print(
                    f"{p.name}: steering rate {m['steer_rate']:.1f} deg/s, "
                    f"yaw gain {m['yaw_gain']:.1f} deg/s²"
                )
            g = normalise_yaw_gain(rates, gains, ref_rate, law=gain_law)
            gain, gain_sig = g["gain"], g["sigma"]
            console.print(
                f"yaw gain at {ref_rate:.0f} deg/s ({gain_law} law, {g['n']} tests): "
                f"{gain:.1f} deg/s²" + (f" ± {gain_sig:.1f}" if np.isfinite(gain_sig) else "")
            )
        res = identify_steering(
            car,
            times,
            alpha0_rad=alpha0,
            yaw_gain_dps2=gain,
            yaw_gain_sigma_dps2=gain_sig,
            steer_rate_rad_s=np.deg2rad(ref_rate) / n,
            stop_rad=stop,
            reference=reference,
            method=method,
        )
    except GripsenseError as e:
        fail(e)
    d = res.to_dict()
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
    if output is not None:
        from gripsense.report.steering_figures import (
            release_figure,
            settling_figure,
            yaw_gain_figure,
        )

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
