"""One fleet task: a batch of logs → per-estimate rows with position and H3 cell, as Parquet.

Rows (one per estimate; schema :data:`ROW_COLUMNS`):

* ``axle-window`` (default): one row per axle window — the estimate μ, its 1σ and 90 %
  interval when observable (model-based), the window's statement as a deviance curve on the μ
  grid (``mu_deviance``, one byte per grid point: :func:`~gripsense.estimate.profile.
  deviance_curve`; what a cell combines, :mod:`gripsense.fleet.aggregate`), and always the
  measured grip and its model-free lower bound ``grip_used_lower`` (one-sided 99 % per window,
  level road assumed; the window's numbers of ``friction``, the measured grip the drive's bound
  takes: ``docs/physics.md`` §14.1); placed at the epoch nearest the window's middle;
* per-sample methods (``brush-2`` …): one row per valid wheel sample (μ, σ_μ), plus per log and
  cell one measured-grip row: ``grip_used`` the 95th percentile of the axle's measured grip (the
  bound's, ``grip_proven``) over the cell's cornering samples, ``grip_used_lower`` that minus
  3 × the samples' median 1σ.

Every row also names what its likelihood depends on besides the vehicle: the ``receiver`` (its
noise model's name), the tyre ``calibration`` in use (its file; empty: the vehicle file's
declared tyres) and ``tyres``, a digest of the tyre description the likelihood used (the vehicle
file's and the calibration's bytes): statements with the same ``tyres`` share their tyre
nuisances, whichever vehicle made them (:mod:`gripsense.fleet.aggregate`).

A log that cannot be read or analysed never fails the batch: it is returned as a problem with
its reason.

With ``calibrate``, a first pass (:func:`calibration_batch`) returns each log's linear-range sums
per axle (``docs/physics.md`` §15.7); the run learns one calibration per vehicle id from them
and the second pass (:func:`process_batch` with ``calibrations``) applies it.
"""

from __future__ import annotations

import errno
import hashlib
import os
import stat
import traceback
from pathlib import Path
from typing import Any

import numba
import numpy as np
import pandas as pd

from gripsense.errors import GripsenseError
from gripsense.io.output_folder import write_parquet

__all__ = [
    "ROW_COLUMNS",
    "STEER_SUFFIX",
    "calibration_batch",
    "not_a_log",
    "process_batch",
    "process_log",
    "steer_csv_for",
    "tyres_digest",
]

ROW_COLUMNS = [
    "vehicle",
    "log",
    "time_utc",
    "t_s",
    "lat_deg",
    "lon_deg",
    "cell",
    "unit",
    "observable",
    "mu",
    "mu_sigma",
    "mu_low",
    "mu_high",
    "grip_used",
    "grip_used_lower",
    "mu_deviance",
    "receiver",
    "calibration",
    "tyres",
]


STEER_SUFFIX = "_steer.csv"
"""A log's steering CSV is ``<log stem>_steer.csv`` beside it (:func:`steer_csv_for`)."""


def steer_csv_for(log: str | Path) -> Path:
    """Where a log's steering CSV is by the fleet's naming rule: ``<stem>_steer.csv`` in the
    log's folder, the stem being the log's file name without a trailing ``.gz`` and then
    without its last suffix (``drive1.nmea.gz``, ``drive1.nmea``, ``drive1.vbo`` →
    ``drive1_steer.csv``; ``a.b.ubx`` → ``a.b_steer.csv``; ``drive1`` → ``drive1_steer.csv``) —
    the name ``gripsense simulate`` gives it.

    Parameters
    ----------
    log : str or Path
        The log.

    Returns
    -------
    Path
        The steering CSV's path (which may not exist).
    """
    p = Path(log)
    name = p.name[:-3] if p.name.lower().endswith(".gz") else p.name
    stem = Path(name).stem if Path(name).suffix else name
    return p.with_name(stem + STEER_SUFFIX)


_KINDS = {
    stat.S_IFIFO: "a named pipe (FIFO), not a regular file: fleet workers read each file by "
    "name (twice with --calibrate); copy it to a file",
    stat.S_IFSOCK: "a socket, not a regular file",
    stat.S_IFCHR: "a character device, not a regular file",
    stat.S_IFBLK: "a block device, not a regular file",
}


def not_a_log(path: str, *, named: bool = True) -> str | None:
    """Why *path* cannot be read as a fleet input.

    Parameters
    ----------
    path : str
        A log (or steering CSV) as named or matched.
    named : bool
        Named by the user (a folder is then a problem); else matched by a wildcard pattern (a
        folder is then no input at all: ``**`` reaches inside it).

    Returns
    -------
    str or None
        ``None`` for a regular file; ``""`` for a folder a pattern matched; else the reason
        (no such file, a dangling link, a link loop, a named pipe, a device …).
    """
    try:
        st = os.stat(path)
    except FileNotFoundError:
        if os.path.islink(path):
            return f"a dangling symbolic link (to {os.readlink(path)}, which does not exist)"
        return "no such file"
    except OSError as e:
        if e.errno == errno.ELOOP:
            return "a symbolic link loop (the link never reaches a file)"
        return (e.strerror or str(e)).lower()
    if stat.S_ISREG(st.st_mode):
        return None
    if stat.S_ISDIR(st.st_mode):
        return "a folder, not a log (give a pattern such as DIR/**/*.nmea*)" if named else ""
    return _KINDS.get(stat.S_IFMT(st.st_mode), "not a regular file")


def _steer_csv(log: str | Path) -> Path | None:
    """The log's steering CSV when there is one; one that is there but cannot be read (a
    dangling link, a pipe …) makes the log a problem, with the reason.
    """
    steer = steer_csv_for(log)
    if not os.path.lexists(steer):
        return None
    why = not_a_log(str(steer))
    if why is not None:
        raise GripsenseError(f"its steering CSV {steer}: {why}")
    return steer


def _cells(lat: np.ndarray, lon: np.ndarray, res: int) -> list[str | None]:
    import h3

    return [
        h3.latlng_to_cell(float(a), float(b), res) if np.isfinite(a) and np.isfinite(b) else None
        for a, b in zip(lat, lon, strict=True)
    ]


def process_log(
    path: str | Path,
    vehicle,
    *,
    vehicle_id: str,
    method: str = "axle-window",
    h3_res: int = 11,
    since: pd.Timestamp | None = None,
    receiver: str | None = None,
    log_options=None,
    steer_columns: str | None = None,
    calibration: str = "",
    tyres: str = "",
) -> pd.DataFrame:
    """Rows of one log (schema :data:`ROW_COLUMNS`).

    Parameters
    ----------
    path : str or Path
        NMEA log.
    vehicle : Vehicle
        Vehicle description.
    vehicle_id : str
        Vehicle id written into the rows.
    method : str
        Friction method.
    h3_res : int
        H3 resolution of the cells.
    since : pandas.Timestamp, optional
        Epochs before it are ignored.
    receiver : str, optional
        Receiver class or file (:func:`gripsense.config.receiver_from`); default the vehicle
        file's ``[receiver]``, else ``v100``.
    log_options : gripsense.io.logs.LogOptions, optional
        Channel mapping and DBC of MDF4 / CAN logs (:func:`gripsense.io.logs.read_log`).
    steer_columns : str, optional
        Column mapping of the log's steering CSV, ``<log stem>_steer.csv`` beside it
        (:func:`gripsense.fleet.run.steer_csv_for`), used when it exists; else the log's own
        steering channel, if any.
    calibration : str
        The tyre calibration *vehicle* carries (its file), written into the rows (empty: the
        declared tyres).
    tyres : str
        Digest of the tyre description (:func:`tyres_digest`), written into the rows (empty:
        the vehicle id stands for it).

    Returns
    -------
    pandas.DataFrame
        One row per estimate placed at the epoch nearest its middle, plus, for estimates that
        carry no bound of their own (per-sample methods), one bound row per cell: the 95th
        percentile of the friction used there. ``attrs["steering"]``: the steering channel
        read, ``attrs["front_axle"]``: why the front axle was not estimated (``""`` when it
        was).

    Raises
    ------
    GripsenseError
        With the reason when the log cannot be used.
    """
    from gripsense.estimate.options import WindowOptions
    from gripsense.pipeline import FrictionRun

    # a cell combines the windows' statements: the drive's own profile is not needed
    run = FrictionRun(
        vehicle,
        method=method,
        receiver=receiver,
        window=WindowOptions(drive=False, nuisances=False),
    )
    res = run.run_log(path, since=since, log_options=log_options,
                      steer_csv=_steer_csv(path),
                      steer_columns=steer_columns)  # fmt: skip
    steering = {
        "steering": str(res.meta.get("steering", "")),
        "front_axle": str(res.meta.get("front_axle", "")),
    }
    ep = res.epochs
    if ep is None or ep.empty:
        out = pd.DataFrame(columns=ROW_COLUMNS)
        out.attrs.update(steering)
        return out
    if not np.isfinite(ep["lat_deg"].to_numpy(float)).any():
        raise GripsenseError("no position fix in the log (NMEA GGA/RMC/GNS/GLL)")
    est = res.estimates()
    e = est["epoch"].to_numpy(int)
    rows = est.drop(columns=["epoch", "t_start", "t_end"]).assign(
        time_utc=ep["time_utc"].array.take(e),  # tz-aware: no object array of the whole log
        t_s=ep["t_s"].to_numpy(float)[e],
        lat_deg=ep["lat_deg"].to_numpy(float)[e],
        lon_deg=ep["lon_deg"].to_numpy(float)[e],
    )
    rows["cell"] = _cells(rows["lat_deg"].to_numpy(), rows["lon_deg"].to_numpy(), h3_res)
    per_window = run.estimator.per_window
    own = rows["observable"].to_numpy(bool) | per_window
    parts = [rows[own]]
    samples = rows[~rows["observable"].to_numpy(bool)] if not per_window else rows.iloc[:0]
    if len(samples) and samples["cell"].notna().any():
        sig = res.wheels.groupby("epoch")["grip_sigma"].median()
        samples = samples.assign(grip_sigma=sig.reindex(est["epoch"]).to_numpy()[~own])
        b = (
            samples.groupby("cell")
            .agg(
                time_utc=("time_utc", "max"),
                t_s=("t_s", "max"),
                lat_deg=("lat_deg", "mean"),
                lon_deg=("lon_deg", "mean"),
                grip_used=("grip_used", lambda u: float(np.quantile(u, 0.95))),
                grip_sigma=("grip_sigma", "median"),
            )
            .reset_index()
        )
        b["grip_used_lower"] = np.maximum(b["grip_used"] - 3.0 * b["grip_sigma"], 0.0)
        parts.append(
            b.drop(columns="grip_sigma").assign(
                unit="all",
                observable=False,
                mu=np.nan,
                mu_sigma=np.nan,
                mu_low=np.nan,
                mu_high=np.nan,
                mu_deviance=None,
            )
        )
    rows = pd.concat(parts, ignore_index=True) if len(parts) > 1 else parts[0]
    rows = rows.assign(
        vehicle=vehicle_id,
        log=Path(path).name,
        receiver=run.receiver,
        calibration=calibration,
        tyres=tyres or f"vehicle:{vehicle_id}",
    )
    rows = rows[rows["cell"].notna()]
    out = rows[ROW_COLUMNS].reset_index(drop=True)
    out.attrs.update(steering)
    return out


def calibration_batch(
    items: list[tuple[str, str, str]],
    *,
    receiver: str | None = None,
    log_options=None,
    steer_columns: str | None = None,
) -> list[dict]:
    """The first pass of a calibrating fleet run: each log's linear-range sums per axle.

    Parameters
    ----------
    items : list of tuple
        ``(log path, vehicle toml, vehicle id)``.
    receiver : str, optional
        Receiver class or file (default: the vehicle file's, else ``v100``).
    log_options : gripsense.io.logs.LogOptions, optional
        Channel mapping and DBC of MDF4 / CAN logs.
    steer_columns : str, optional
        Column mapping of the logs' steering CSVs (``<log stem>_steer.csv``, as
        :func:`process_log`).

    Returns
    -------
    list of dict
        Per log: ``log``, ``vehicle`` (id), ``sums`` (list of DriveSums) and ``problem`` (empty
        when the log could be read; a log that cannot be used is skipped here and reported by
        the second pass).
    """
    import dataclasses

    from gripsense.config import Vehicle
    from gripsense.pipeline import FrictionRun, log_drive_sums

    threads = numba.get_num_threads()
    numba.set_num_threads(1)  # as in process_batch
    runs: dict[str, FrictionRun] = {}
    out = []
    try:
        for path, vfile, vid in items:
            rec: dict[str, Any] = {"log": path, "vehicle": vid, "sums": [], "problem": ""}
            try:
                if vfile not in runs:
                    veh = dataclasses.replace(Vehicle.from_toml(vfile), calibration_file=None)
                    runs[vfile] = FrictionRun(veh, receiver=receiver)
                rec["sums"] = log_drive_sums(path, runs[vfile], log_options=log_options,
                                             steer_csv=_steer_csv(path),
                                             steer_columns=steer_columns)  # fmt: skip
            except Exception as e:  # the second pass reports it with its reason
                rec["problem"] = f"{type(e).__name__}: {e}"
            out.append(rec)
    finally:
        numba.set_num_threads(threads)
    return out


def process_batch(
    items: list[tuple[str, str, str]],
    outdir: str,
    *,
    method: str,
    h3_res: int,
    since: str | None,
    receiver: str | None = None,
    calibrations: dict[str, str] | None = None,
    log_options=None,
    steer_columns: str | None = None,
) -> list[dict]:
    """Process ``(log path, vehicle toml, vehicle id)`` items; write
    ``outdir/epochs/vehicle=<id>/<log>.parquet``; return one status dict per log (``rows``,
    ``problem``, ``steering``: the steering channel read, ``front_axle``: why the front axle
    was not estimated). A vehicle id in *calibrations* (id → calibration TOML) uses that
    calibration instead of the one its vehicle file names; *steer_columns* maps the logs'
    steering CSVs (:func:`process_log`).
    """
    # a fleet worker has one thread per core: numba's parallel loops stay on this thread
    # (numba's thread count is per thread), so two workers on two cores do not each wake a
    # second, spinning OpenMP thread on the other's core (1 → 2 workers 1.55× → 1.92×)
    threads = numba.get_num_threads()
    numba.set_num_threads(1)
    try:
        return _process_items(items, outdir, method, h3_res, since, receiver,
                              calibrations or {}, log_options, steer_columns)  # fmt: skip
    finally:
        numba.set_num_threads(threads)


def _calibration_name(vfile: str, given: str | None) -> str:
    """The calibration a vehicle of the run uses: the run's own (``--calibrate``), else the one
    its vehicle file names, else ``""`` (the declared tyres).
    """
    if given:
        return str(given)
    from gripsense.config import Vehicle

    return str(Vehicle.from_toml(vfile).calibration_file or "")


def tyres_digest(vehicle_file: str | Path, calibration: str | Path = "") -> str:
    """What a statement's tyre nuisances are: a digest of the vehicle file's bytes and its
    calibration's. Two cars described by the same declared file without a calibration of their
    own share its declared tyre (its stiffness and shape priors): their statements are not
    independent; a calibration learned per car (``--calibrate``) makes them so.

    Parameters
    ----------
    vehicle_file : str or Path
        The vehicle TOML.
    calibration : str or Path
        The calibration TOML in use (empty: none).

    Returns
    -------
    str
        12 hexadecimal digits.
    """
    h = hashlib.sha1(Path(vehicle_file).read_bytes())
    if calibration and Path(calibration).is_file():
        h.update(b"\0" + Path(calibration).read_bytes())
    return h.hexdigest()[:12]


def _process_items(
    items, outdir, method, h3_res, since, receiver, calibrations, log_options=None,
    steer_columns=None,
) -> list[dict]:  # fmt: skip
    """The loop of :func:`process_batch`."""
    from gripsense.config.calibration import calibrated_vehicle

    out = []
    vehicles: dict[str, object] = {}
    cal_names: dict[str, str] = {}
    digests: dict[str, str] = {}
    since_ts = None if since is None else pd.Timestamp(since)
    if since_ts is not None and since_ts.tzinfo is None:
        since_ts = since_ts.tz_localize("UTC")
    for path, vfile, vid in items:
        rec = {"log": path, "vehicle": vid, "rows": 0, "problem": "", "steering": "",
               "front_axle": ""}  # fmt: skip
        try:
            key = f"{vfile}\0{vid}"
            if key not in vehicles:
                vehicles[key] = calibrated_vehicle(vfile, calibrations.get(vid))
                cal_names[key] = _calibration_name(vfile, calibrations.get(vid))
                digests[key] = tyres_digest(vfile, cal_names[key])
            rows = process_log(
                path,
                vehicles[key],
                calibration=cal_names[key],
                tyres=digests[key],
                vehicle_id=vid,
                method=method,
                h3_res=h3_res,
                since=since_ts,
                receiver=receiver,
                log_options=log_options,
                steer_columns=steer_columns,
            )
            rec["steering"] = rows.attrs.get("steering", "")
            rec["front_axle"] = rows.attrs.get("front_axle", "")
            if len(rows):
                d = Path(outdir) / "epochs" / f"vehicle={vid}"
                d.mkdir(parents=True, exist_ok=True)
                tag = hashlib.sha1(str(Path(path).resolve()).encode()).hexdigest()[:8]
                write_parquet(rows.drop(columns="vehicle"), d / f"{Path(path).name}-{tag}.parquet")
            rec["rows"] = len(rows)
            rec["observable"] = int(rows["observable"].sum()) if len(rows) else 0
        except GripsenseError as e:
            rec["problem"] = str(e)
        except Exception as e:
            tb = traceback.extract_tb(e.__traceback__)[-1]
            rec["problem"] = f"{type(e).__name__}: {e} (at {Path(tb.filename).name}:{tb.lineno})"
        out.append(rec)
    return out
