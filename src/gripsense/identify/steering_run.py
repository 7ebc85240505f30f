"""The steering identification from recordings (``gripsense steering identify``): read the
release, step-steer and tyre-deflection tables, measure settling times and yaw gains, and
alternate the two inversions of :func:`gripsense.identify.steering.identify_steering` — the
workflow, so that the command line only parses options and prints.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np

from gripsense._arrays import sample_step
from gripsense.config import SteeringCar
from gripsense.errors import InputError
from gripsense.identify.steering import (
    SteeringIdentification,
    identify_steering,
    normalise_yaw_gain,
    tyre_lateral_stiffness,
)
from gripsense.identify.steering_metrics import release_onset, release_settling_time, step_metrics
from gripsense.io.table import Quantity, describe_columns, map_table, parse_columns, read_table

__all__ = ["STEERING_QUANTITIES", "SteeringRun", "identify_from_recordings", "read_recording"]

STEERING_QUANTITIES = {
    "t": Quantity("time", ("t", "time")),
    "steer": Quantity("angle", ("steer", "steering_wheel", "handwheel", "swa")),
    "yaw_rate": Quantity("angular rate", ("yaw_rate", "yawrate")),
    "force": Quantity("force", ("force", "fy")),
    "deflection": Quantity("length", ("deflection", "y")),
}
"""Keys of the steering recordings (release, step-steer, tyre deflection) and the header names
mapped without being told; one ``--columns`` serves all of them."""


def read_recording(
    path: Path,
    need: tuple[str, ...],
    columns: str | None,
    log: Callable[[str], None] = lambda _: None,
) -> dict[str, np.ndarray]:
    """Values in SI of the keys *need* of a recording (rows with a missing value dropped).

    Parameters
    ----------
    path : Path
        The table (CSV, Parquet …).
    need : tuple of str
        Keys of :data:`STEERING_QUANTITIES`.
    columns : str or None
        The ``--columns`` mapping (every key and unit checked, for any file).
    log : callable
        Told which columns were used.

    Returns
    -------
    dict of numpy.ndarray
        Key → values [SI].
    """
    spec = None
    if columns:
        parse_columns(columns, STEERING_QUANTITIES)
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
    log(f"{path.name}: columns {describe_columns(used)}")
    ok = np.all([np.isfinite(v[k]) for k in need], axis=0)
    return {k: v[k][ok] for k in need}


@dataclass
class SteeringRun:
    """What :func:`identify_from_recordings` found.

    Attributes
    ----------
    result : SteeringIdentification
        C_s, k_s and the alternation.
    car : SteeringCar
        The car (with k_y from the deflection test, when given).
    times : list of float
        Settling times used [s].
    traces : list of tuple
        Release traces from their onset: (t [s], steering-wheel angle [deg]).
    alpha0_rad : float
        Release angle at the kingpin [rad].
    ref_rate_dps : float
        Steering-wheel rate the yaw gain refers to [deg/s].
    gain_sigma : float
        1σ of the normalised yaw gain [deg/s²] (NaN: one summary gain).
    """

    result: SteeringIdentification
    car: SteeringCar
    times: list[float]
    traces: list[tuple[np.ndarray, np.ndarray]] = field(default_factory=list)
    alpha0_rad: float = 0.0
    ref_rate_dps: float = float("nan")
    gain_sigma: float = float("nan")


def identify_from_recordings(
    car: SteeringCar,
    *,
    release: list[Path] | None = None,
    step: list[Path] | None = None,
    settling_times: list[float] | None = None,
    yaw_gain: float | None = None,
    steer_rate_dps: float | None = None,
    gain_law: str = "ln",
    reference: str = "initial",
    method: str = "rise",
    tyre_deflection: Path | None = None,
    columns: str | None = None,
    log: Callable[[str], None] = lambda _: None,
) -> SteeringRun:
    """Identify C_s and k_s (k_s2) from recordings and measured values (docs/physics.md §9.3).

    Parameters
    ----------
    car : SteeringCar
        The car.
    release : list of Path, optional
        Release-test tables (t, steering-wheel angle).
    step : list of Path, optional
        Step-steer tables (t, steering-wheel angle, yaw rate).
    settling_times : list of float, optional
        Measured settling times [s] (added to the release tests').
    yaw_gain : float, optional
        Measured yaw gain at *steer_rate_dps* [deg/s²] (instead of step tests).
    steer_rate_dps : float, optional
        Steering-wheel rate of the yaw gain [deg/s] (default: the car's reference rate).
    gain_law : str
        Yaw gain vs rate: ``ln`` (seed eq. 7) or ``linear``.
    reference : str
        Settling band: ``initial`` (§4.1) or ``converged``.
    method : str
        Yaw gain from a trace: ``rise``, ``slope`` or ``peak``.
    tyre_deflection : Path, optional
        Table of force and deflection: k_y from its slope.
    columns : str, optional
        The ``--columns`` mapping of the tables.
    log : callable
        Told what each recording gave (one line each).

    Returns
    -------
    SteeringRun
        The identification and what it was made from.
    """
    n = car.steering_ratio
    ref_rate = float(steer_rate_dps or car.reference_steer_rate_dps)
    stop = np.deg2rad(car.step_stop_deg) / n
    alpha0 = np.deg2rad(car.release_angle_deg) / n
    if tyre_deflection is not None:
        td = read_recording(tyre_deflection, ("force", "deflection"), columns, log)
        ky, ky_sig = tyre_lateral_stiffness(td["force"], td["deflection"])
        car = replace(car, tyre_lateral_stiffness_N_per_m=ky)
        log(
            f"k_y = {ky / 1000:.1f} ± {ky_sig / 1000:.1f} N/mm from "
            f"{tyre_deflection.name} ({len(td['force'])} points)"
        )
    times = list(settling_times or [])
    traces = []
    for p in release or []:
        df = read_recording(p, ("t", "steer"), columns, log)
        sample_step(df["t"], source=str(p))  # the file named when its times cannot be used
        t, a = df["t"], np.rad2deg(df["steer"])
        ts = release_settling_time(t, a, reference=reference)
        times.append(ts)
        log(f"{p.name}: settling time {ts:.3f} s")
        on = t >= release_onset(t, a)
        traces.append((t[on] - t[on][0], a[on]))
    if not times:
        raise InputError("give settling times: --settling t1,t2,... or --release FILE.csv")
    gain, gain_sig = yaw_gain, float("nan")
    if step:
        rates, gains = [], []
        for p in step:
            df = read_recording(p, ("t", "steer", "yaw_rate"), columns, log)
            sample_step(df["t"], source=str(p))
            m = step_metrics(
                df["t"], np.rad2deg(df["steer"]), np.rad2deg(df["yaw_rate"]), method=method
            )
            rates.append(m["steer_rate"])
            gains.append(m["yaw_gain"])
            log(
                f"{p.name}: steering rate {m['steer_rate']:.1f} deg/s, "
                f"yaw gain {m['yaw_gain']:.1f} deg/s²"
            )
        g = normalise_yaw_gain(rates, gains, ref_rate, law=gain_law)
        gain, gain_sig = g["gain"], g["sigma"]
        log(
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
    return SteeringRun(res, car, times, traces, float(alpha0), ref_rate, gain_sig)
