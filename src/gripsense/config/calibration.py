"""What a vehicle's own driving taught about its tyres: the calibration file.

``gripsense calibrate DRIVES… --vehicle car.toml -o car.calibration.toml`` learns, per axle, the
cornering stiffness at the static load from the linear range of everyday driving (the thesis's
linear-range fit, ``docs/physics.md`` §15.7) with its uncertainty and the drives it came from;
``friction``, ``live`` and ``fleet`` take it (``--calibration FILE``) as the prior of the stiffness
instead of the vehicle file's declaration. The file keeps each drive's least-squares sums, so
adding a drive (``--update``) combines them exactly::

    # gripsense calibration — written by gripsense; learned from the drives listed below
    [calibration]
    vehicle = "Corolla-like sedan (simulation)"

    [calibration.rear]
    cornering_stiffness_N_per_rad = 41250.0   # one wheel at the static load
    stiffness_uncertainty = 0.032             # relative, 1σ
    scale = 1.031                             # over the vehicle file's declaration
    bins = 412

    [[calibration.drive]]
    file = "monday.nmea.gz"
    sha256 = "…"
    axle = "rear"
    bins = 201
    sums = [ … ]                              # XᵀWX (2 × 2), XᵀWk (2), kᵀWk, centred

With a steering-torque channel the file also keeps the steering's lever at low grip (the caster
plus zero-slip pneumatic trail times the channel's scale, ``docs/physics.md`` §16.8), which the
torque estimator then takes as a constraint of its trail nuisances::

    [calibration.steering]
    lever_m = 0.0391                          # k (t_c + t₀), moment at the axes per axle force
    lever_uncertainty = 0.031                 # relative, 1σ
    bins = 388

(its drives have ``axle = "steering"``, their sums those of the lever and the friction).

Unknown keys are errors, like everywhere else.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from gripsense.config.toml_reader import TomlReader
from gripsense.config.vehicle import Vehicle
from gripsense.errors import InputError
from gripsense.io.text import read_toml

__all__ = [
    "AXLE_KEYS",
    "AxleCalibration",
    "Calibration",
    "DriveSums",
    "SteeringCalibration",
    "apply_calibration",
    "calibrated_vehicle",
    "calibration_toml",
    "read_calibration",
]

AXLE_KEYS = ("cornering_stiffness_N_per_rad", "stiffness_uncertainty", "scale", "bins")
DRIVE_KEYS = ("file", "sha256", "axle", "bins", "sums")
STEERING_KEYS = ("lever_m", "lever_uncertainty", "bins")
N_SUMS = {"front": 7, "rear": 7, "steering": 7}  # 2 × 2 + 2 + 1


@dataclass(frozen=True)
class DriveSums:
    """One drive's weighted least-squares sums of one axle's linear-range fit.

    Attributes
    ----------
    file : str
        The drive's file name.
    sha256 : str
        Its content hash (the same drive is not counted twice).
    axle : str
        ``front`` or ``rear`` (the stiffness), or ``steering`` (the steering's lever).
    bins : int
        Bins used.
    sums : numpy.ndarray
        XᵀWX (2 × 2, row-major), XᵀWk (2) and kᵀWk of the drive's bins centred on their
        weighted means: 7 numbers.
    """

    file: str
    sha256: str
    axle: str
    bins: int
    sums: np.ndarray


@dataclass(frozen=True)
class AxleCalibration:
    """The learned stiffness of one axle.

    Attributes
    ----------
    cornering_stiffness_N_per_rad : float
        One wheel's cornering stiffness at the static load [N/rad].
    stiffness_uncertainty : float
        Its relative 1σ [-].
    scale : float
        Learned over declared stiffness [-].
    bins : int
        Bins of all drives used.
    """

    cornering_stiffness_N_per_rad: float
    stiffness_uncertainty: float
    scale: float
    bins: int


@dataclass(frozen=True)
class SteeringCalibration:
    """The learned lever of the steering at low grip.

    Attributes
    ----------
    lever_m : float
        k (t_c + t₀): the moment at the steering axes per front axle force at low grip, the
        caster plus zero-slip pneumatic trail times the torque channel's scale [m].
    lever_uncertainty : float
        Its relative 1σ [-].
    bins : int
        Bins of all drives used.
    """

    lever_m: float
    lever_uncertainty: float
    bins: int


@dataclass(frozen=True)
class Calibration:
    """A calibration file's content.

    Attributes
    ----------
    vehicle : str
        The vehicle's name (a calibration of another vehicle is refused).
    axles : dict
        ``front`` / ``rear`` → :class:`AxleCalibration`.
    drives : list of DriveSums
        What it was learned from.
    source : str
        The file, for messages.
    steering : SteeringCalibration or None
        The steering's lever, when the drives had a torque channel.
    """

    vehicle: str
    axles: dict[str, AxleCalibration]
    drives: list[DriveSums] = field(default_factory=list)
    source: str = "<calibration>"
    steering: SteeringCalibration | None = None


def read_calibration(path: str | Path) -> Calibration:
    """Read a calibration file (strict keys).

    Parameters
    ----------
    path : str or Path
        The ``.calibration.toml`` file.

    Returns
    -------
    Calibration
        Its content.
    """
    src = str(path)
    doc = read_toml(path)
    r = TomlReader(doc, src)
    r.known(doc, "", ("calibration",))
    t = doc.get("calibration")
    if not isinstance(t, dict):
        raise InputError(f"{src}: no [calibration] table; write one with gripsense calibrate")
    r.known(t, "calibration", ("vehicle", "front", "rear", "steering", "drive"))
    vehicle = t.get("vehicle")
    if not isinstance(vehicle, str):
        raise InputError(f"{src}: [calibration] vehicle: a string (the vehicle's name) is needed")
    axles = {}
    for axle in ("front", "rear"):
        a = t.get(axle)
        if a is None:
            continue
        where = f"calibration.{axle}"
        r.known(a, where, AXLE_KEYS)
        c = r.num(a, where, "cornering_stiffness_N_per_rad", unit="N/rad", plausible=(1e3, 1e6))
        u = r.num(a, where, "stiffness_uncertainty", unit="-", plausible=(0.001, 1.0))
        s = r.num(a, where, "scale", unit="-", plausible=(0.05, 20.0))
        n = r.num(a, where, "bins", unit="-", plausible=(1, 1e9))
        axles[axle] = AxleCalibration(float(c), float(u), float(s), int(n))
    steering = None
    st = t.get("steering")
    if st is not None:
        r.known(st, "calibration.steering", STEERING_KEYS)
        lever = r.num(st, "calibration.steering", "lever_m", unit="m", plausible=(0.002, 0.5))
        u = r.num(st, "calibration.steering", "lever_uncertainty", unit="-", plausible=(0.001, 1))
        n = r.num(st, "calibration.steering", "bins", unit="-", plausible=(1, 1e9))
        steering = SteeringCalibration(float(lever), float(u), int(n))
    drives = []
    for i, d in enumerate(t.get("drive", []) or []):
        where = f"calibration.drive[{i}]"
        if not isinstance(d, dict):
            raise InputError(f"{src}: {where}: a table is needed")
        r.known(d, where, DRIVE_KEYS)
        sums = d.get("sums")
        if d.get("axle") not in N_SUMS:
            raise InputError(
                f"{src}: {where}: axle = {d.get('axle')!r}; use front, rear or steering"
            )
        need = N_SUMS[d["axle"]]
        if not (isinstance(sums, list) and len(sums) == need):
            raise InputError(f"{src}: {where}: sums: {need} numbers are needed")
        drives.append(
            DriveSums(
                str(d.get("file", "")),
                str(d.get("sha256", "")),
                str(d["axle"]),
                int(d.get("bins", 0)),
                np.asarray(sums, dtype=float),
            )
        )
    return Calibration(vehicle, axles, drives, src, steering)


def calibration_toml(cal: Calibration) -> str:
    """The text of a calibration file (the header marks it as gripsense's own output).

    Parameters
    ----------
    cal : Calibration
        The content.

    Returns
    -------
    str
        TOML text.
    """
    out = [
        "# gripsense calibration — written by gripsense; learned from the drives listed below",
        "# (per axle: one wheel's cornering stiffness at the static load, docs/physics.md §15.7)",
        "[calibration]",
        f"vehicle = {_q(cal.vehicle)}",
    ]
    for axle, a in sorted(cal.axles.items()):
        out += [
            "",
            f"[calibration.{axle}]",
            f"cornering_stiffness_N_per_rad = {a.cornering_stiffness_N_per_rad:.1f}",
            f"stiffness_uncertainty = {a.stiffness_uncertainty:.4f}",
            f"scale = {a.scale:.4f}",
            f"bins = {a.bins}",
        ]
    if cal.steering is not None:
        out += [
            "",
            "[calibration.steering]",
            f"lever_m = {cal.steering.lever_m:.6f}",
            f"lever_uncertainty = {cal.steering.lever_uncertainty:.4f}",
            f"bins = {cal.steering.bins}",
        ]
    for d in cal.drives:
        sums = ", ".join(f"{v:.10g}" for v in d.sums)
        out += [
            "",
            "[[calibration.drive]]",
            f"file = {_q(d.file)}",
            f"sha256 = {_q(d.sha256)}",
            f"axle = {_q(d.axle)}",
            f"bins = {d.bins}",
            f"sums = [{sums}]",
        ]
    return "\n".join(out) + "\n"


def _q(s: str) -> str:
    return '"' + s.replace("\\", "\\\\").replace('"', '\\"') + '"'


def apply_calibration(vehicle: Vehicle, cal: Calibration) -> Vehicle:
    """The vehicle with each calibrated axle's stiffness and its uncertainty taken from *cal*.

    Parameters
    ----------
    vehicle : Vehicle
        The vehicle file's description.
    cal : Calibration
        A calibration of this vehicle.

    Returns
    -------
    Vehicle
        The description the estimators use: per axle the declaration and the learned stiffness
        combined by their uncertainties (in ln C: the vehicle file's value is the prior, the
        drives the data) — a calibration that knows less than the vehicle file (a receiver too
        noisy for the slips of everyday driving) leaves the declaration nearly as it is, never
        widens it; the steering's learned lever, a constraint the torque estimator adds to its
        trail priors (docs/physics.md §16.8).
    """
    if cal.vehicle != vehicle.name:
        raise InputError(
            f"{cal.source}: a calibration of {cal.vehicle!r}, not of {vehicle.name!r}; "
            "use the vehicle's own calibration file"
        )
    tyres = dict(vehicle.tyres)
    for axle, a in cal.axles.items():
        if axle not in tyres:
            continue
        c_d = float(vehicle.cornering_stiffness(axle, vehicle.static_load(axle)))
        w_d = 1.0 / np.log1p(tyres[axle].stiffness_uncertainty) ** 2
        w_l = 1.0 / np.log1p(a.stiffness_uncertainty) ** 2
        ln_c = (w_d * np.log(c_d) + w_l * np.log(a.cornering_stiffness_N_per_rad)) / (w_d + w_l)
        tyres[axle] = dataclasses.replace(
            tyres[axle],
            cornering_stiffness_N_per_rad=float(np.exp(ln_c)),
            stiffness_uncertainty=float(np.expm1(1.0 / np.sqrt(w_d + w_l))),
        )
    steering = vehicle.steering
    if cal.steering is not None and steering is not None:
        steering = dataclasses.replace(
            steering,
            calibrated_lever_m=cal.steering.lever_m,
            calibrated_lever_uncertainty=cal.steering.lever_uncertainty,
        )
    return dataclasses.replace(vehicle, tyres=tyres, steering=steering)


def calibrated_vehicle(
    vehicle: Vehicle | str | Path, calibration: Calibration | str | Path | None = None
) -> Vehicle:
    """A vehicle description with its calibration applied: *calibration* when given, else the
    file the vehicle file names (``[calibration] file``), else the declaration as it is.

    Parameters
    ----------
    vehicle : Vehicle or str or Path
        The vehicle or its file.
    calibration : Calibration or str or Path, optional
        A calibration of this vehicle or its file.

    Returns
    -------
    Vehicle
        The description the estimators use (its ``calibration_file`` cleared once applied).
    """
    veh = vehicle if isinstance(vehicle, Vehicle) else Vehicle.from_toml(vehicle)
    if calibration is None:
        calibration = veh.calibration_file
    if calibration is None:
        return veh
    cal = calibration if isinstance(calibration, Calibration) else read_calibration(calibration)
    return dataclasses.replace(apply_calibration(veh, cal), calibration_file=None)
