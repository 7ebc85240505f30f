"""Pipelines: a source, a vehicle description and an estimator wired together (like pvlib's
ModelChain). The command line, the demo, live mode and the fleet are thin layers over these.

:meth:`FrictionRun.run_log` is the one way from a log file to a result; :meth:`FrictionRun.run`
takes an epoch table (live mode), :meth:`FrictionRun.run_motion` a motion table from another
source (``gripsense friction --table``). Each estimator of :data:`gripsense.estimate.ESTIMATORS`
returns its own typed result (:class:`~gripsense.estimate.results.WheelFriction` or
:class:`~gripsense.estimate.results.AxleFriction`).
"""

from __future__ import annotations

import dataclasses
import warnings
from dataclasses import fields, replace
from pathlib import Path

import numpy as np
import pandas as pd

from gripsense.config import Receiver, Vehicle, receiver_from
from gripsense.config.calibration import (
    N_SUMS,
    AxleCalibration,
    Calibration,
    DriveSums,
    apply_calibration,
    calibrated_vehicle,
)
from gripsense.errors import InputError
from gripsense.estimate.estimators import Estimator, get_estimator
from gripsense.estimate.friction import friction_from_motion
from gripsense.estimate.noise import NoiseModel
from gripsense.estimate.options import FrictionOptions, WindowOptions
from gripsense.estimate.results import FrictionResult
from gripsense.estimate.wheels import motion_from_epochs
from gripsense.io.logs import LogOptions, log_steer, read_log
from gripsense.io.sensors.steer import read_steer_csv, steer_at, steer_overlap, with_torque
from gripsense.io.table import describe_columns

__all__ = [
    "NO_STEERING",
    "FrictionResult",
    "FrictionRun",
    "Steering",
    "learn_calibration",
    "log_drive_sums",
    "log_steering",
    "log_wheels",
    "solve_calibration",
    "steering_meta",
    "wheel_drive_sums",
]

NO_STEERING = (
    "front axle: no steering channel — give --steer-csv FILE or map one with --columns "
    "steer=CHANNEL (docs/ingest.md)"
)
"""What a result says when the front axle could not be estimated for want of a steering
channel."""


@dataclasses.dataclass(frozen=True)
class Steering:
    """The steering channel of a drive, as found for it (:func:`log_steering`).

    Attributes
    ----------
    steer_rad : numpy.ndarray or None
        Road-wheel angle per epoch [rad]; None without a steering channel.
    epochs : pandas.DataFrame
        The epoch table, with a steering CSV's torque channels joined.
    source : str
        One line: which channel was read, and from where.
    front_axle : str
        Why the front axle cannot be estimated (``""`` when it has a steering channel).
    notes : list of str
        What the ingest report should add (a steering CSV's rows that carry no mapped channel,
        a log's channel not used because a CSV was given).
    """

    steer_rad: np.ndarray | None
    epochs: pd.DataFrame
    source: str
    front_axle: str = ""
    notes: tuple[str, ...] = ()


def log_steering(
    epochs: pd.DataFrame,
    vehicle: Vehicle,
    *,
    log: str | Path = "log",
    steer_csv: str | Path | None = None,
    steer_columns: str | dict | None = None,
    steering: dict | None = None,
) -> Steering:
    """The steering channel of a drive: the steering CSV given for it, else the log's own
    channel (mapped by ``--columns`` or found by its name and unit,
    :func:`gripsense.io.logs.channels.recognise_steering`), else none — and then the one line that
    says why the front axle is not estimated.

    Parameters
    ----------
    epochs : pandas.DataFrame
        Epoch table of the log.
    vehicle : Vehicle
        The vehicle (its ``steering_ratio`` for a steering-wheel angle).
    log : str or Path
        The log, for messages.
    steer_csv : str or Path, optional
        Steering CSV (:func:`gripsense.io.sensors.steer.read_steer_csv`), aligned by ``t_s``.
    steer_columns : str or dict, optional
        Its column mapping.
    steering : dict, optional
        :attr:`gripsense.io.logs.nmea.accounting.IngestReport.steering` of the log.

    Returns
    -------
    Steering
    """
    steering = steering or {}
    if steer_csv is not None:
        ch = read_steer_csv(steer_csv, steering_ratio=vehicle.steering_ratio, columns=steer_columns)
        overlap = steer_overlap(ch, epochs["t_s"].to_numpy(float), steer_csv)  # none: an error
        notes = [n for n in (ch.attrs["rows"]["note"], overlap) if n]
        if steering:
            notes.append(
                f"the log's steering channel {steering['channel']!r} not used: --steer-csv given"
            )
        return Steering(
            steer_at(ch, epochs["t_s"].to_numpy(float)),
            with_torque(epochs, ch),
            f"--steer-csv {Path(steer_csv).name} ({describe_columns(ch.attrs['columns'])})",
            notes=tuple(notes),
        )
    if steering.get("source") == "name and unit" and steering.get("key") == "steering_wheel":
        if not vehicle.steering_ratio:  # found, not asked for: the front axle says why
            return Steering(
                None,
                epochs,
                "",
                f"front axle: the log's steering-wheel angle {steering['channel']!r} needs "
                "[vehicle] steering_ratio in the vehicle file (or give --steer-csv FILE)",
            )
    steer = log_steer(epochs, vehicle.steering_ratio, str(log))
    if steer is None:
        return Steering(None, epochs, "", NO_STEERING)
    how = "by --columns" if steering.get("source") == "--columns" else "found by name and unit"
    what = f"{steering['channel']!r} [{steering.get('unit') or '?'}]" if steering else "channel"
    return Steering(steer, epochs, f"the log's {what} ({how})")


def steering_meta(st: Steering) -> dict[str, str]:
    """The entries a result's ``meta`` gets from its steering channel: ``steering`` (which
    channel was read) or ``front_axle`` (why the front axle is not estimated).

    Parameters
    ----------
    st : Steering
        Of :func:`log_steering`.

    Returns
    -------
    dict
    """
    return {"front_axle": st.front_axle} if st.front_axle else {"steering": st.source}


class FrictionRun:
    """Friction from a drive: vehicle + method + options → a typed result.

    Parameters
    ----------
    vehicle : Vehicle or str or Path
        Vehicle description (or the path of its TOML file).
    method : str
        A key of :data:`gripsense.estimate.ESTIMATORS`: ``axle-window`` (default: measured
        grip and a μ estimate per axle), or a per-sample method of the thesis: ``brush-2``,
        ``brush-4``, ``thesis-2``, ``thesis-4``, ``brush``, ``thesis``.
    noise : NoiseModel, optional
        Uncertainties (a string here is read as *receiver*, deprecated).
    receiver : str or Path or Receiver, optional
        The receiver: ``v100``, ``white-0.3``, ``rtk`` or a TOML file with a ``[receiver]``
        table (default: the vehicle file's ``[receiver]``, else ``v100``). With it (and always
        for ``axle-window``) the noise model combines the receiver with the vehicle file's
        stiffness uncertainty and CG-height range (:meth:`~gripsense.estimate.noise.NoiseModel.
        for_vehicle`); without it the per-sample methods keep the thesis's defaults.
    window : WindowOptions, optional
        Settings of ``axle-window``.
    calibration : Calibration or str or Path, optional
        What the vehicle's own driving taught about its tyres (``gripsense calibrate``): each
        calibrated axle's stiffness and uncertainty replace the vehicle file's (default: the
        vehicle file's ``[calibration] file``, if any). Where the declaration and the learned
        stiffness conflict (or the drives disagreed), ``calibration_notes`` holds one line each.
    **options
        Fields of :class:`~gripsense.estimate.options.FrictionOptions`
        (e.g. ``min_speed_mps=4.0``, ``calibrate_heading=False``).

    Examples
    --------
    >>> run = FrictionRun("car.toml", method="axle-window")    # doctest: +SKIP
    >>> result = run.run_log("drive.nmea")                     # doctest: +SKIP
    >>> result.summary                                         # doctest: +SKIP
    """

    def __init__(
        self,
        vehicle: Vehicle | str | Path,
        method: str = "axle-window",
        *,
        noise: NoiseModel | str | None = None,
        receiver: str | Path | Receiver | None = None,
        window: WindowOptions | None = None,
        calibration: Calibration | str | Path | None = None,
        **options,
    ):
        self.estimator: Estimator = get_estimator(method, "FrictionRun")
        self.calibration_notes: list[str] = []  # conflicts said out loud (docs/physics.md §15.7)
        self.vehicle = calibrated_vehicle(vehicle, calibration, self.calibration_notes)
        if self.vehicle.steering is not None and self.vehicle.steering.calibrated_lever_m:
            from gripsense.estimate.calibration import use_learned_lever

            self.vehicle = use_learned_lever(self.vehicle, self.calibration_notes)
        self.method = method
        known = {f.name for f in fields(FrictionOptions)}
        unknown = set(options) - known
        if unknown:
            raise InputError(
                f"FrictionRun: unknown option(s) {sorted(unknown)}; known: {sorted(known)}"
            )
        opts = replace(FrictionOptions(), **options)
        if isinstance(noise, str | Path):
            warnings.warn(
                f"FrictionRun(noise={str(noise)!r}) names a receiver; write "
                f"receiver={str(noise)!r} (noise= takes a NoiseModel)",
                DeprecationWarning,
                stacklevel=2,
            )
            receiver, noise = noise, None
        if noise is None and (receiver is not None or self.estimator.needs_receiver):
            # the receiver as the user describes it, the vehicle file's tyre and CG ranges
            noise = NoiseModel.for_vehicle(self.vehicle, receiver)
            spec = receiver if receiver is not None else (self.vehicle.receiver or "v100")
            self.receiver = receiver_from(spec).name
        else:
            self.receiver = "noise model given" if noise is not None else "thesis noise model"
        self.options = replace(opts, noise=noise) if noise is not None else opts
        self.window = window or WindowOptions()

    def run_log(
        self,
        log: str | Path,
        *,
        steer_csv: str | Path | None = None,
        steer_columns: str | None = None,
        strict: bool = False,
        since: pd.Timestamp | None = None,
        log_options: LogOptions | None = None,
    ) -> FrictionResult:
        """Estimate μ from a log file of any supported format (NMEA, VBOX, UBX, MDF4, CAN;
        plain or ``.gz``; :func:`gripsense.io.logs.read_log`): ingest, friction, and the
        ingest accounting and epochs kept in the result.

        Parameters
        ----------
        log : str or Path
            Log of the drive.
        steer_csv : str or Path, optional
            Steering channel (:func:`gripsense.io.sensors.steer.read_steer_csv`); enables the front
            wheels. Without it, a steering channel of the log itself is used (a ``steer`` or
            ``steering_wheel`` channel of a VBOX, MDF4 or CAN log, mapped or found by its name
            and unit; :func:`log_steering`). Its torque channels, if any, join the epoch table
            (``torque_nm``, ``assist_nm``, ``rack_n``). The result's ``meta`` says which
            channel was read (``steering``) or why the front axle is not estimated
            (``front_axle``, e.g. :data:`NO_STEERING`).
        steer_columns : str, optional
            Column mapping of *steer_csv* (``t=…,road_wheel=…:deg,torque=…:Nm``); default by
            header names.
        strict : bool
            Stop at the first rejected line.
        since : pandas.Timestamp, optional
            Ignore epochs before this UTC time.
        log_options : LogOptions, optional
            Channel mapping, DBC and time offset of a measurement log.

        Returns
        -------
        FrictionResult
            :class:`~gripsense.estimate.results.WheelFriction` or
            :class:`~gripsense.estimate.results.AxleFriction`.
        """
        opts = log_options or LogOptions()
        if strict:
            opts = replace(opts, strict=True)
        nlog = read_log(log, opts)
        ep, rep = nlog.epochs, nlog.report
        if ep.empty:
            raise InputError(
                f"{log}: no epochs ({rep.total_lines} {rep.unit}, {rep.n_rejected} rejected, "
                f"{rep.n_ignored} ignored); is this a log of a GNSS compass?"
            )
        if since is not None:
            ep = ep[ep["time_utc"] >= since].reset_index(drop=True)
        st = log_steering(ep, self.vehicle, log=log, steer_csv=steer_csv,
                          steer_columns=steer_columns, steering=rep.steering)  # fmt: skip
        rep.notes.extend(st.notes)
        res = self.run(st.epochs, steer_rad=st.steer_rad, ingest=rep.to_dict())
        return res.replace(meta={**res.meta, **steering_meta(st)})

    def run(
        self,
        epochs: pd.DataFrame,
        *,
        steer_rad: np.ndarray | None = None,
        ingest: dict | None = None,
    ) -> FrictionResult:
        """Estimate μ from a GNSS-compass epoch table (:func:`gripsense.io.read_nmea`).

        Parameters
        ----------
        epochs : pandas.DataFrame
            Epoch table.
        steer_rad : numpy.ndarray, optional
            Road-wheel angle per epoch row [rad]; enables the front wheels.
        ingest : dict, optional
            The ingest accounting, kept in the result.

        Returns
        -------
        FrictionResult
            The method's result, with the epochs attached.
        """
        motion, meta = motion_from_epochs(
            epochs, self.vehicle, options=self.options, steer_rad=steer_rad
        )
        return self.run_motion(motion, meta=meta).replace(epochs=epochs, ingest=ingest)

    def wheel_table(
        self, epochs: pd.DataFrame, *, steer_rad: np.ndarray | None = None
    ) -> tuple[pd.DataFrame, dict]:
        """The per-sample wheel table of an epoch table, without the estimator (live mode feeds
        it to the estimator's online form, :meth:`~gripsense.estimate.Estimator.online`).

        Parameters
        ----------
        epochs : pandas.DataFrame
            Epoch table.
        steer_rad : numpy.ndarray, optional
            Road-wheel angle per epoch row [rad].

        Returns
        -------
        wheels : pandas.DataFrame
            :func:`gripsense.estimate.friction.friction_from_motion`'s table.
        meta : dict
            Heading offset and counts.
        """
        motion, meta = motion_from_epochs(
            epochs, self.vehicle, options=self.options, steer_rad=steer_rad
        )
        wheels, meta2 = friction_from_motion(
            motion, self.vehicle, method=self.method, options=self.options
        )
        return wheels, {**meta, **meta2}

    def run_motion(self, motion: pd.DataFrame, *, meta: dict | None = None) -> FrictionResult:
        """Estimate μ from a motion table of the measurement point.

        Parameters
        ----------
        motion : pandas.DataFrame
            Motion table (:func:`gripsense.estimate.friction.friction_from_motion`,
            :func:`gripsense.io.sensors.motion.read_motion_table`).
        meta : dict, optional
            Entries to keep in the result's ``meta`` (source, vehicle …).

        Returns
        -------
        FrictionResult
            The method's result.
        """
        wheels, meta2 = friction_from_motion(
            motion, self.vehicle, method=self.method, options=self.options
        )
        meta2 = {**meta2, "receiver": self.receiver}
        return self.estimator.result(
            wheels,
            self.vehicle,
            options=self.options,
            window=self.window,
            meta={**(meta or {}), **meta2},
        )


def learn_calibration(
    logs: list[str | Path],
    vehicle: Vehicle | str | Path,
    *,
    receiver: str | Path | Receiver | None = None,
    steer_csvs: list[str | Path] | None = None,
    previous: Calibration | None = None,
    log_options: LogOptions | None = None,
) -> Calibration:
    """Learn each axle's cornering stiffness from drives of one vehicle (``docs/physics.md``
    §15.7): the linear-range fit of :mod:`gripsense.estimate.calibration` over every drive,
    added to what *previous* was learned from (a drive already in it is not counted twice);
    and from every drive that took an axle up its curve, what it says of the axle's normalised
    shape (§15.10), with the stiffness just learned.

    Parameters
    ----------
    logs : list of str or Path
        Logs of everyday driving (any format of :func:`gripsense.io.logs.read_log`).
    vehicle : Vehicle or str or Path
        The vehicle file (its declared stiffness is the reference; a calibration it names is
        not applied: learning starts from the declaration). Its tyres' ``tyre_set`` marks the
        drives; drives of *previous* on other tyres are kept but not learned from.
    receiver : str or Path or Receiver, optional
        The receiver (default: the vehicle file's, else ``v100``).
    steer_csvs : list of str or Path, optional
        A steering channel per log, in the same order (the front axle needs it).
    previous : Calibration, optional
        An earlier calibration of this vehicle to update.
    log_options : LogOptions, optional
        Channel mapping, DBC and time offset of measurement logs.

    Returns
    -------
    Calibration
        Per axle the learned stiffness (axles without usable bins are left out) and the drives.
    """
    veh = vehicle if isinstance(vehicle, Vehicle) else Vehicle.from_toml(vehicle)
    veh = dataclasses.replace(veh, calibration_file=None)
    if steer_csvs and len(steer_csvs) != len(logs):
        raise InputError(
            f"--steer-csv: {len(steer_csvs)} channels for {len(logs)} logs; give one per log, "
            "in the same order"
        )
    _same_vehicle(previous, veh)  # before any log is read
    run = FrictionRun(veh, receiver=receiver)
    drives, tables = [], []
    for i, log in enumerate(logs):
        steer = steer_csvs[i] if steer_csvs else None
        wheels, name, digest = log_wheels(log, run, steer_csv=steer, log_options=log_options)
        drives += wheel_drive_sums(wheels, run, name, digest, shape=False)
        tables.append((wheels, name, digest))
    cal = solve_calibration(veh, drives, previous=previous)
    # the shape, with the stiffness just learned (the declaration's ±20 % would blur it); a
    # drive that teaches it took the axle near its limit: it teaches the shape, not the
    # stiffness, which is solved again without it
    learned = apply_calibration(veh, dataclasses.replace(cal, drives=[]))
    shape_run = FrictionRun(learned, receiver=receiver)  # its noise: the learned 1σ too
    held = {(d.sha256, d.axle) for d in previous.drives} if previous is not None else set()
    shapes: dict[tuple[str, str], DriveSums] = {}
    for wheels, name, digest in tables:
        for d in _shape_sums(wheels, shape_run, name, digest):
            if (digest, d.axle) not in held:  # a drive the calibration held: not twice
                shapes[(digest, d.axle)] = d
    if not shapes:
        return cal
    new = [shapes.pop((d.sha256, d.axle), d) for d in drives] + list(shapes.values())
    return solve_calibration(veh, new, previous=previous)


def _same_vehicle(previous: Calibration | None, vehicle: Vehicle) -> None:
    if previous is not None and previous.vehicle != vehicle.name:
        raise InputError(
            f"{previous.source}: a calibration of {previous.vehicle!r}, not of {vehicle.name!r}"
        )


def log_wheels(
    log: str | Path,
    run: FrictionRun,
    *,
    steer_csv: str | Path | None = None,
    steer_columns: str | dict | None = None,
    log_options: LogOptions | None = None,
) -> tuple[pd.DataFrame, str, str]:
    """One log's wheel table with its name and SHA-256 (a pipe or FIFO is read once).

    Parameters
    ----------
    log : str or Path
        Log of any supported format (:func:`gripsense.io.logs.read_log`).
    run : FrictionRun
        The run (vehicle without calibration, receiver).
    steer_csv : str or Path, optional
        The log's steering channel (the front axle needs it; else the log's own, if it has
        one: :func:`log_steering`).
    steer_columns : str or dict, optional
        Column mapping of *steer_csv*.
    log_options : LogOptions, optional
        Channel mapping, DBC and time offset of a measurement log.

    Returns
    -------
    wheels : pandas.DataFrame
        Wheel table (:meth:`FrictionRun.wheel_table`; empty when nothing is usable).
    name : str
        The log's file name.
    sha256 : str
        Its content hash.
    """
    import hashlib
    import tempfile

    from gripsense.io.text import read_bytes

    lo = log_options or LogOptions()
    if Path(log).is_file():
        digest = hashlib.sha256(Path(log).read_bytes()).hexdigest()
        nlog = read_log(log, lo)
    else:  # a pipe or FIFO is read once: hashed, then read from a private copy
        data = read_bytes(log, "log", max_bytes=lo.max_bytes)
        digest = hashlib.sha256(data).hexdigest()
        with tempfile.TemporaryDirectory(prefix="gripsense-") as tmp:
            copy_ = Path(tmp) / (Path(log).name or "log")
            copy_.write_bytes(data)
            nlog = read_log(copy_, lo)
    st = log_steering(nlog.epochs, run.vehicle, log=log, steer_csv=steer_csv,
                      steer_columns=steer_columns, steering=nlog.report.steering)  # fmt: skip
    wheels, _ = run.wheel_table(st.epochs, steer_rad=st.steer_rad)
    return wheels, Path(log).name, digest


def wheel_drive_sums(
    wheels: pd.DataFrame, run: FrictionRun, name: str, sha256: str, *, shape: bool = True
) -> list[DriveSums]:
    """One drive's sums per axle (:func:`gripsense.estimate.calibration.drive_sums`) and, with
    a steering-torque channel, the steering's; with *shape*, what the drive says of each
    axle's curve shape (:func:`gripsense.estimate.shape_learning.shape_evidence`, with the
    run's stiffness); each tagged with the axle's ``tyre_set``.

    Parameters
    ----------
    wheels : pandas.DataFrame
        The drive's wheel table (:func:`log_wheels`).
    run : FrictionRun
        The run (vehicle, receiver).
    name : str
        The drive's file name.
    sha256 : str
        Its content hash.
    shape : bool
        Also learn the curve's shape.

    Returns
    -------
    list of DriveSums
        One per axle with usable bins or shape evidence, and the steering's.
    """
    from gripsense.estimate.calibration import drive_sums, steering_sums

    if wheels.empty:
        return []
    veh = run.vehicle
    out = []
    for axle in ("front", "rear"):
        s = drive_sums(wheels, veh, axle, run.options.noise, file=name, sha256=sha256)
        if s is not None and axle in veh.tyres:
            out.append(dataclasses.replace(s, tyre_set=veh.tyres[axle].tyre_set))
    if shape:
        with_shape = {d.axle: d for d in _shape_sums(wheels, run, name, sha256)}
        out = [with_shape.pop(d.axle, d) for d in out] + list(with_shape.values())
    s = steering_sums(wheels, veh, file=name, sha256=sha256)
    if s is not None:  # a steering-torque channel: the steering's lever (§16.8)
        front = veh.tyres.get("front")
        out.append(dataclasses.replace(s, tyre_set=front.tyre_set if front else ""))
    return out


def _shape_sums(wheels: pd.DataFrame, run: FrictionRun, name: str, sha256: str) -> list[DriveSums]:
    """Per axle whose curve the drive tells apart: the shape evidence of
    :func:`~gripsense.estimate.shape_learning.shape_evidence`, with no linear-range sums — a
    drive that took the axle near its limit teaches the shape, not the stiffness
    (``docs/physics.md`` §15.10).
    """
    from gripsense.estimate.shape_learning import shape_evidence

    out: list[DriveSums] = []
    if wheels.empty:
        return out
    veh = run.vehicle
    for axle in veh.tyres:
        ev = shape_evidence(wheels, veh, axle, noise=run.options.noise, options=run.window)
        if ev is not None:
            out.append(DriveSums(name, sha256, axle, 0, np.zeros(N_SUMS[axle]),
                                 veh.tyres[axle].tyre_set, ev))  # fmt: skip
    return out


def log_drive_sums(
    log: str | Path,
    run: FrictionRun,
    *,
    steer_csv: str | Path | None = None,
    steer_columns: str | dict | None = None,
    log_options: LogOptions | None = None,
) -> list[DriveSums]:
    """The linear-range sums of one log per axle and the shape evidence of the axles it took up
    their curves (:func:`wheel_drive_sums` of :func:`log_wheels`, with the run's stiffness) —
    the part of :func:`learn_calibration` that a fleet runs on its workers.

    Parameters
    ----------
    log : str or Path
        Log of any supported format (:func:`gripsense.io.logs.read_log`).
    run : FrictionRun
        The run (vehicle without calibration, receiver).
    steer_csv : str or Path, optional
        The log's steering channel (the front axle needs it; else the log's own, if it has
        one: :func:`log_steering`).
    steer_columns : str or dict, optional
        Column mapping of *steer_csv*.
    log_options : LogOptions, optional
        Channel mapping, DBC and time offset of a measurement log.

    Returns
    -------
    list of DriveSums
        One per axle with usable bins or shape evidence, and the steering's with a
        steering-torque channel.
    """
    wheels, name, digest = log_wheels(
        log, run, steer_csv=steer_csv, steer_columns=steer_columns, log_options=log_options
    )
    return wheel_drive_sums(wheels, run, name, digest)


def solve_calibration(
    vehicle: Vehicle, drives: list, *, previous: Calibration | None = None
) -> Calibration:
    """Each axle's learned stiffness from the sums of its drives on the tyres fitted, added to
    what *previous* was learned from (a drive already in it is not counted twice; drives on
    another ``tyre_set`` are kept but not learned from).

    Parameters
    ----------
    vehicle : Vehicle
        The vehicle (its declared stiffness is the reference, its tyres' ``tyre_set`` the
        tyres fitted).
    drives : list of DriveSums
        Sums of the new drives (:func:`log_drive_sums`).
    previous : Calibration, optional
        An earlier calibration of this vehicle to update.

    Returns
    -------
    Calibration
        Per axle the learned stiffness (axles without usable bins are left out), the drives,
        in ``left_out`` the axles whose drives on other tyres were not used and in ``repeated``
        the drives given again.
    """
    from gripsense.estimate.calibration import solve_steering_sums, solve_sums

    _same_vehicle(previous, vehicle)
    kept = list(previous.drives) if previous is not None else []
    seen = {(d.sha256, d.axle) for d in kept}
    repeated: list[str] = []
    for d in drives:
        if (d.sha256, d.axle) not in seen:
            kept.append(d)
            seen.add((d.sha256, d.axle))
        elif d.file not in repeated:
            repeated.append(d.file)
    earlier = {d.sha256 for d in previous.drives} if previous is not None else set()
    axles: dict[str, AxleCalibration] = {}
    left: dict[str, str] = {}
    for axle in ("front", "rear"):
        if axle not in vehicle.tyres:
            continue
        fitted = vehicle.tyres[axle].tyre_set
        mine = [d for d in kept if d.axle == axle]
        other = [d for d in mine if d.tyre_set != fitted]
        if other:  # kept in the file, not learned from: the tyres have changed
            sets = ", ".join(sorted({repr(d.tyre_set) if d.tyre_set else "(not named)"
                                     for d in other}))  # fmt: skip
            left[f"tyres {axle}"] = (
                f"{axle} axle: {len(other)} drive(s) on tyre set {sets} kept but not learned "
                f"from (the vehicle file's {axle} tyres are "
                f"{repr(fitted) if fitted else '(not named)'})"
            )
        declared = float(vehicle.cornering_stiffness(axle, vehicle.static_load(axle)))
        use = [d for d in mine if d.tyre_set == fitted and d.bins > 0]
        a = solve_sums(use, declared, earlier=earlier, axle=axle)
        if a is not None:
            axles[axle] = dataclasses.replace(a, tyre_set=fitted)
    front = vehicle.tyres["front"].tyre_set if "front" in vehicle.tyres else ""
    steering = solve_steering_sums(
        [d for d in kept if d.axle == "steering" and d.tyre_set == front]
    )
    return Calibration(vehicle=vehicle.name, axles=axles, drives=kept, steering=steering,
                       left_out=left, repeated=tuple(repeated))  # fmt: skip
