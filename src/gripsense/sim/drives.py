"""Drives for accuracy checks: a truth vehicle with a truth tyre, an emulated receiver, the
vehicle file a user would write, and the true friction per axle.

The estimator never sees the truth tyre: the vehicle file of :func:`user_vehicle` declares, per
axle, the cornering stiffness at the static load as a user would read it from a data sheet or
a ``gripsense stiffness`` run (with a stated error), the default load sensitivity and curve
shape, and the vehicle's geometry (optionally with a wrong CG height).

Truth per axle (``docs/physics.md`` §15.1): at each instant μ_axle = Σ μ_i Fz_i / Σ Fz_i, with
μ_i the wheel's peak friction at its load and inclination in the direction of its force (for a
brush tyre the road μ). |F_axle| ≤ μ_axle Fz_axle always holds, so a measured-grip bound is
sound exactly when it stays below μ_axle.
"""

from __future__ import annotations

import datetime as dt
from dataclasses import dataclass
from functools import cache

import numpy as np
import pandas as pd

from gripsense.config import Vehicle
from gripsense.constants import G0
from gripsense.data import sample_path
from gripsense.errors import InputError
from gripsense.sim import maneuvers as M
from gripsense.sim.gnss import DEFAULT_ORIGIN, DEFAULT_START, CompassNoise, emulate_compass
from gripsense.sim.sensors import emulate_steering
from gripsense.sim.steering_torque import emulate_torque
from gripsense.sim.tyres import SimTyre, load_sim_tyre
from gripsense.sim.vehicle import SimParams, SimResult

__all__ = [
    "TRUTH_TYRES",
    "VEHICLES",
    "Drive",
    "axle_truth",
    "limit_speed",
    "record_drive",
    "simulate_drive",
    "truth_tyre",
    "truth_vehicle",
    "user_vehicle",
    "user_vehicle_toml",
]

VEHICLES = {"sedan": "corolla_sim.toml", "sports": "sports_sim.toml", "suv": "suv_sim.toml"}
"""Bundled truth vehicles: the Corolla-like sedan, a low sports car, a tall SUV (h/t 0.46)."""

TRUTH_TYRES = {
    "brush": None,
    "mf-book": "PacejkaBook_Defaults.tir",
    "mf-sedan": "Sedan_Pac02Tire.tir",
    "mf61": "MagicFormula61_Paramerters.tir",
    "pac89": "HMMWV_Pac89Tire.json",
}
"""Truth tyre families: the simulator's brush tyre, three Magic Formula ``.tir`` files (MF 5.2
book defaults, a PAC2002 sedan tyre, an MF 6.1 tyre) and a PAC89 tyre (``gripsense/data/tyres``,
sources in its README)."""


@cache
def truth_vehicle(name: str) -> Vehicle:
    """A bundled truth vehicle (:data:`VEHICLES`).

    Parameters
    ----------
    name : str
        ``sedan``, ``sports`` or ``suv``.

    Returns
    -------
    Vehicle
        Its description.
    """
    return Vehicle.from_toml(sample_path(VEHICLES[name]))


@cache
def truth_tyre(name: str) -> SimTyre | None:
    """A truth tyre (:data:`TRUTH_TYRES`); None for the brush tyre.

    Parameters
    ----------
    name : str
        Key of :data:`TRUTH_TYRES`.

    Returns
    -------
    SimTyre or None
        The tabulated tyre.
    """
    f = TRUTH_TYRES[name]
    return None if f is None else load_sim_tyre(sample_path(f"tyres/{f}"))


def user_vehicle_toml(
    vehicle: Vehicle,
    tyre: SimTyre | dict | None,
    *,
    stiffness_error: float = 0.0,
    cg_height_factor: float = 1.0,
    stiffness_uncertainty: float = 0.15,
) -> str:
    """The text of the vehicle file a user would write for a truth vehicle on a truth tyre: the
    truth file with its ``cg_height_m`` scaled and its ``[tyre.*]`` tables replaced by the
    declared cornering stiffness at the static load (see :func:`user_vehicle`).

    Parameters
    ----------
    vehicle : Vehicle
        The truth vehicle (read from a file: its text is the template).
    tyre : SimTyre or None or dict
        The truth tyre (None: the vehicle's brush tyres), or axle → tyre.
    stiffness_error : float
        Relative error of the declared cornering stiffness [-].
    cg_height_factor : float
        Declared CG height over the true one [-].
    stiffness_uncertainty : float
        Declared 1σ of the stiffness [-].

    Returns
    -------
    str
        TOML text.
    """
    from pathlib import Path

    out, skip = [], False
    for line in Path(vehicle.source).read_text(encoding="utf-8").splitlines():
        head = line.strip()
        if head.startswith("["):
            skip = head.startswith("[tyre")
        if skip:
            continue
        if head.startswith("cg_height_m") and cg_height_factor != 1.0:
            line = f"cg_height_m = {vehicle.cg_height_m * cg_height_factor:.4g}"
        out.append(line)
    while out and not out[-1].strip():
        out.pop()
    per_axle = tyre if isinstance(tyre, dict) else {"front": tyre, "rear": tyre}
    for axle, ty in vehicle.tyres.items():
        t = per_axle.get(axle)
        name = "brush" if t is None else t.name
        fzs = vehicle.static_load(axle)
        c0 = float(
            vehicle.cornering_stiffness(axle, fzs) if t is None else t.cornering_stiffness(fzs)
        )
        out += [
            "",
            f"[tyre.{axle}]   # {name}: C at the static load {fzs:.0f} N, as measured",
            f"width_m = {ty.width_m}",
            f"cornering_stiffness_N_per_rad = {c0 * (1.0 + stiffness_error):.0f}",
            f"stiffness_uncertainty = {stiffness_uncertainty}",
            "contact_length = { fixed_m = 0.14 }",
        ]
    return "\n".join(out) + "\n"


def user_vehicle(
    vehicle: Vehicle,
    tyre: str,
    *,
    stiffness_error: float = 0.0,
    cg_height_factor: float = 1.0,
    stiffness_uncertainty: float = 0.15,
) -> Vehicle:
    """The vehicle file a user would write for a truth vehicle running on a truth tyre
    (:func:`user_vehicle_toml`, read back).

    Parameters
    ----------
    vehicle : Vehicle
        The truth vehicle.
    tyre : str
        Key of :data:`TRUTH_TYRES`.
    stiffness_error : float
        Relative error of the declared cornering stiffness [-].
    cg_height_factor : float
        Declared CG height over the true one [-] (the declared range is the default ±25 %
        around the declared value).
    stiffness_uncertainty : float
        Declared 1σ of the stiffness [-].

    Returns
    -------
    Vehicle
        Declared C at the static load (the truth tyre's, times 1 + *stiffness_error*), the
        default load sensitivity, shape and camber thrust ratio.
    """
    import tomllib

    text = user_vehicle_toml(
        vehicle,
        truth_tyre(tyre),
        stiffness_error=stiffness_error,
        cg_height_factor=cg_height_factor,
        stiffness_uncertainty=stiffness_uncertainty,
    )
    v = Vehicle.from_dict(
        tomllib.loads(text), source=f"{vehicle.source} (as a user would write it)"
    )
    return v


@dataclass
class Drive:
    """A simulated drive as a user would record it, with the truth.

    Attributes
    ----------
    lines : list of str
        NMEA sentences of the emulated receiver.
    steer : pandas.DataFrame
        Road-wheel steering channel (``t_s``, ``road_wheel_deg``).
    truth : pandas.DataFrame
        Per output time and wheel (see :class:`gripsense.sim.SimResult`).
    axles : pandas.DataFrame
        :func:`axle_truth` after the settling time.
    settle_s : float
        Start of the intended test [s].
    """

    lines: list[str]
    steer: pd.DataFrame
    truth: pd.DataFrame
    axles: pd.DataFrame
    settle_s: float


def axle_truth(truth: pd.DataFrame, settle_s: float = 0.0) -> pd.DataFrame:
    """True friction and utilisation per axle (module documentation).

    Parameters
    ----------
    truth : pandas.DataFrame
        Wheel truth (``t_s``, ``wheel``, ``mu_true``, ``load_N``, ``force_N``).
    settle_s : float
        Samples before this are left out [s].

    Returns
    -------
    pandas.DataFrame
        Per axle: ``mu_true`` (median of μ_axle), ``mu_true_min``, ``mu_true_max``,
        ``utilisation`` (mean |F_axle| / (μ_axle Fz_axle)), ``utilisation_max`` (its 95th
        percentile) and ``grip_max`` (largest |F_axle| / Fz_axle).
    """
    t = truth[truth["t_s"] >= settle_s]
    rows = []
    for axle in ("front", "rear"):
        w = t[t["wheel"].astype(str).str.startswith(axle)]
        if w.empty:
            continue
        g = w.assign(muf=w["mu_true"] * w["load_N"]).groupby("t_s")
        fz = g["load_N"].sum()
        mu_ax = g["muf"].sum() / fz
        grip = g["force_N"].sum().abs() / fz
        util = grip / mu_ax
        rows.append(
            {
                "axle": axle,
                "mu_true": float(mu_ax.median()),
                "mu_true_min": float(mu_ax.min()),
                "mu_true_max": float(mu_ax.max()),
                "utilisation": float(util.mean()),
                "utilisation_max": float(util.quantile(0.95)),
                "grip_max": float(grip.max()),
            }
        )
    return pd.DataFrame(rows)


def simulate_drive(
    vehicle: str | Vehicle,
    tyre: str,
    maneuver: M.Maneuver | None,
    mu: float,
    *,
    receiver: str = "v100",
    seed: int = 0,
    relaxation_length_m: float = 0.5,
    steer_scale_error: float = 0.03,
    circle: tuple[float, float] | None = None,
    torque: bool = False,
    **where,
) -> Drive:
    """Simulate a drive with a truth tyre and emulate the receiver and the steering channel.

    Parameters
    ----------
    vehicle : str or Vehicle
        A key of :data:`VEHICLES` or a description with brush tyres and an antenna.
    tyre : str
        Key of :data:`TRUTH_TYRES` (both axles).
    maneuver : Maneuver or None
        The manoeuvre; None with *circle*.
    mu : float
        Road friction [-].
    receiver : str
        ``v100``, ``white-0.3``, ``rtk`` or ``none``.
    seed : int
        Random seed of the receiver and steering noise.
    relaxation_length_m : float
        Tyre relaxation length of the truth [m].
    steer_scale_error : float
        Scale error of the steering channel [-].
    circle : (speed [m/s], radius [m]), optional
        A 1.5-lap circle after a 6 s lead-in instead of *maneuver*.
    torque : bool
        Add the column-torque channel (``torque_Nm`` at 100 Hz) to the steering table
        (:func:`gripsense.sim.steering_torque.emulate_torque`; the vehicle's ``[steering]``).
    **where
        ``origin`` and ``start`` of :func:`record_drive` (where and when the drive is).

    Returns
    -------
    Drive
        The recording and the truth.
    """
    veh = truth_vehicle(vehicle) if isinstance(vehicle, str) else vehicle
    t = truth_tyre(tyre)
    p = SimParams.from_vehicle(
        veh,
        relaxation_length_m=relaxation_length_m,
        sim_tyres={} if t is None else {"front": t, "rear": t},
    )
    if circle is not None:
        maneuver = M.circle(circle[0], circle[1], laps=1.5, params=p)
    if maneuver is None:
        raise InputError("simulate_drive: give a maneuver or circle=(speed, radius)")
    res = M.run(p, maneuver, mu=mu)
    return record_drive(
        res, veh, maneuver.settle_s, receiver=receiver, seed=seed,
        steer_scale_error=steer_scale_error, torque=torque, **where,
    )  # fmt: skip


def record_drive(
    result: SimResult,
    vehicle: Vehicle,
    settle_s: float,
    *,
    receiver: str = "v100",
    seed: int = 0,
    steer_scale_error: float = 0.03,
    torque: bool = False,
    origin: tuple[float, float, float] = DEFAULT_ORIGIN,
    start: dt.datetime = DEFAULT_START,
) -> Drive:
    """Record a simulated drive (of any vehicle model) as a user would: the emulated compass at
    the vehicle's antenna and a steering channel, with the per-axle truth.

    Parameters
    ----------
    result : SimResult
        The simulated drive.
    vehicle : Vehicle
        The vehicle (its antenna position).
    settle_s : float
        Start of the intended test [s].
    receiver : str
        Receiver preset.
    seed : int
        Random seed of the receiver and steering noise.
    steer_scale_error : float
        Scale error of the steering channel [-].
    torque : bool
        Add the column-torque channel at 100 Hz to the steering table (rows of either rate).
    origin : (lat_deg, lon_deg, alt_m)
        Where the drive is (:func:`~gripsense.sim.gnss.emulate_compass`).
    start : datetime
        UTC time of t = 0.

    Returns
    -------
    Drive
        The recording and the truth.
    """
    if vehicle.cg_offset is None:
        raise InputError(f"{vehicle.name}: the antenna's position ([antenna] x_m, y_m) is needed")
    ant = (-vehicle.cg_offset[0], -vehicle.cg_offset[1])
    log = emulate_compass(
        result, ant, noise=CompassNoise.preset(receiver), seed=seed, origin=origin, start=start
    )
    steer = emulate_steering(result, scale_error=steer_scale_error, seed=seed + 7919)
    if torque:
        if vehicle.steering is None or not vehicle.steering_ratio:
            raise InputError(f"{vehicle.source}: a torque channel needs a [steering] table")
        tq = emulate_torque(result, vehicle.steering, vehicle.steering_ratio, seed=seed + 104729)
        steer = steer.merge(tq, on="t_s", how="outer").sort_values("t_s").reset_index(drop=True)
    return Drive(
        lines=log.lines,
        steer=steer,
        truth=log.truth,
        axles=axle_truth(log.truth, settle_s),
        settle_s=settle_s,
    )


def limit_speed(mu: float, radius_m: float, utilisation: float) -> float:
    """Speed of a circle at a given share of the road's friction [m/s].

    Parameters
    ----------
    mu : float
        Road friction [-].
    radius_m : float
        Radius [m].
    utilisation : float
        a_y / (μ g) [-].

    Returns
    -------
    float
        √(u μ g R) [m/s].
    """
    return float(np.sqrt(utilisation * mu * G0 * radius_m))
