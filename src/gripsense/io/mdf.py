"""ASAM MDF4 measurement files (CANape, INCA, IPEmotion, vehicle loggers) via asammdf.

The channels ``--columns`` names are read with :mod:`asammdf` (``MDF.get``) with the unit the
file states for each (overridable after a colon), and a steering channel whose name and unit say
what it is (``RoadWheelAngle`` [deg], :func:`gripsense.io.channels.recognise_steering`) when
``--columns`` maps none; they are put on the heading channel's time
base by linear interpolation (angles unwrapped, nothing across a channel's gaps; see
:func:`gripsense.io.channels.resample`). Times are absolute from the file's start time
(``HD`` block), or from ``--time-offset``. Channels not mapped are not read.
"""

from __future__ import annotations

import datetime as dt
import gc
import io
import logging
import shutil
import sys
import tempfile
from pathlib import Path

import numpy as np
import pandas as pd

from gripsense.errors import InputError
from gripsense.io.channels import Channel, add_steering, parse_channel_spec
from gripsense.io.formats import require
from gripsense.io.measurement import log_from_channels, missing_channel
from gripsense.io.nmea.reader import NmeaLog

__all__ = ["MDF_CHANNELS", "mdf_columns", "read_mdf", "write_mdf"]

MDF_CHANNELS = {
    "heading": ("GNSS_TrueHeading", "deg"),
    "course": ("GNSS_Course", "deg"),
    "speed": ("GNSS_Speed", "km/h"),
    "lat": ("GNSS_Latitude", "deg"),
    "lon": ("GNSS_Longitude", "deg"),
    "alt": ("GNSS_Height", "m"),
    "yaw_rate": ("GNSS_YawRate", "deg/s"),
    "steer": ("RoadWheelAngle", "deg"),
    "torque": ("SteeringTorque", "Nm"),
}
"""Channel names and units :func:`write_mdf` (``gripsense simulate --format mf4``) uses."""


def read_mdf(
    path: str | Path,
    data: bytes | None = None,
    *,
    columns: str | dict | None,
    time_offset: float | None = None,
    strict: bool = False,
) -> NmeaLog:
    """Read the mapped channels of an MDF4 file into the epoch table.

    Parameters
    ----------
    path : str or Path
        The file.
    data : bytes, optional
        Its (decompressed) content, when already read.
    columns : str or dict
        ``heading=…,course=…,speed=…[,steer=…:deg,torque=…:Nm]`` (:mod:`gripsense.io.channels`).
    time_offset : float, optional
        Seconds since 1970 UTC of the file's time zero, replacing its start time [s].
    strict : bool
        Raise at the first sample that is not a number.

    Returns
    -------
    NmeaLog
    """
    asammdf = require("asammdf", "reading MDF4")
    name = str(path)
    mapped = parse_channel_spec(columns)
    if not mapped:
        raise InputError(f"{name}: give the channels with --columns (heading=…,course=…,speed=…)")
    src = io.BytesIO(data) if data is not None else str(path)
    scratch = Path(tempfile.mkdtemp(prefix="gripsense-mdf-"))
    try:
        mdf = _open(asammdf, src, name, scratch)
    except BaseException:
        shutil.rmtree(scratch, ignore_errors=True)
        raise
    try:
        _check_records(mdf, name)
        available = list(mdf.channels_db)
        found = {}
        for spec in mapped.values():
            if spec.channel not in mdf.channels_db:
                raise missing_channel(name, spec, available)
        steering, steer_notes = add_steering(mapped, available, mdf.get_channel_unit)
        try:  # one pass over each channel group's records for all the mapped channels
            sigs = mdf.select([spec.channel for spec in mapped.values()])
        except Exception as e:
            raise InputError(f"{name}: the mapped channels cannot be read ({e})") from None
        for (key, spec), sig in zip(mapped.items(), sigs, strict=True):
            v = np.asarray(sig.samples)
            if v.dtype.kind not in "fiub":
                raise InputError(
                    f"{name}: channel {spec.channel!r} ({key}) holds {v.dtype} values, not numbers"
                )
            found[key] = Channel(spec.channel, np.asarray(sig.timestamps, float), v.astype(float),
                                 str(sig.unit or ""))  # fmt: skip
        start = mdf.header.start_time
    finally:
        mdf.close()
        shutil.rmtree(scratch, ignore_errors=True)
    if start.tzinfo is None:
        start = start.replace(tzinfo=dt.UTC)
    start_s = start.timestamp()
    used = {s.channel for s in mapped.values()}
    n_other = len({c for c in available if c not in used and c.lower() not in ("time", "t")})
    notes = [f"{n_other} channels of the file not mapped (not read)"] if n_other else []
    log = log_from_channels(mapped, found, name=name, fmt="MDF4", start_s=start_s,
                            time_offset=time_offset, strict=strict,
                            notes=steer_notes + notes)  # fmt: skip
    log.report.steering = steering
    return log


def _open(asammdf, src, name: str, scratch: Path):
    """``asammdf.MDF(src)``, or one InputError: a damaged file makes asammdf raise many kinds
    of exception, and its half-built object complains when collected; that is kept quiet.
    asammdf copies an unfinalised file into *scratch* (a private folder the caller removes:
    left in the system's temporary folder, a failed read's copy stayed there).
    """
    err = ""
    hook = sys.unraisablehook
    sys.unraisablehook = lambda _: None
    logger = logging.getLogger("asammdf")  # its log lines on a damaged file: the error says it
    level = logger.level
    logger.setLevel(logging.CRITICAL)
    try:
        try:
            return asammdf.MDF(src, temporary_folder=str(scratch))
        except Exception as e:
            err = f"{type(e).__name__}: {e}"
        gc.collect()  # the half-built object, while its complaint is silenced
    finally:
        sys.unraisablehook = hook
        logger.setLevel(level)
    raise InputError(f"{name}: not a readable MDF file ({err})")


def _check_records(mdf, name: str) -> None:
    """Refuse a file whose channel groups point outside their records or data: asammdf's
    compiled reader would read past its buffers (a crash, not an error) on such a damaged
    file.
    """
    for gi, g in enumerate(mdf.groups):
        cg = g.channel_group
        record = int(cg.samples_byte_nr) + int(getattr(cg, "invalidation_bytes_nr", 0))
        for ch in g.channels:
            if int(getattr(ch, "channel_type", 0)) not in (0, 2, 4):
                continue  # variable-length and virtual channels hold no record bytes
            end = int(ch.byte_offset) + (int(ch.bit_offset) + int(ch.bit_count) + 7) // 8
            if ch.bit_count <= 0 or ch.bit_count > 64 * 8 or end > int(cg.samples_byte_nr):
                raise InputError(
                    f"{name}: damaged MDF file: channel {ch.name!r} of group {gi} lies outside "
                    f"its {cg.samples_byte_nr}-byte record (bytes up to {end})"
                )
        held = sum(int(b.original_size) for b in g.get_data_blocks())
        if record and int(cg.cycles_nr) * record > held:
            raise InputError(
                f"{name}: damaged MDF file: group {gi} declares {cg.cycles_nr} records of "
                f"{record} bytes but its data hold {held} bytes (cut off?)"
            )


def mdf_columns(*, steering: bool = False, torque: bool = False) -> str:
    """The ``--columns`` that read a file of :func:`write_mdf`.

    Parameters
    ----------
    steering : bool
        Include the road-wheel angle channel.
    torque : bool
        Include the steering-torque channel.

    Returns
    -------
    str
        ``key=CHANNEL,…``.
    """
    keys = [
        k for k in MDF_CHANNELS
        if (steering or k != "steer") and (torque or k != "torque")
    ]  # fmt: skip
    return ",".join(f"{k}={MDF_CHANNELS[k][0]}" for k in keys)


def write_mdf(
    epochs: pd.DataFrame,
    path: str | Path,
    *,
    steer: pd.DataFrame | None = None,
) -> None:
    """Write an epoch table as an MDF4 file with asammdf (channels :data:`MDF_CHANNELS`).

    Parameters
    ----------
    epochs : pandas.DataFrame
        ``time_utc``, ``lat_deg``, ``lon_deg``, ``alt_m``, ``speed_mps``, ``course_deg``,
        ``heading_deg``, ``yaw_rate_rps`` (ISO).
    path : str or Path
        Output file.
    steer : pandas.DataFrame, optional
        ``t_s`` (the epochs' clock) and ``road_wheel_deg`` (ISO, left positive): a channel at
        its own rate (``RoadWheelAngle``); with ``torque_Nm``, the column torque as a channel
        of its own rate too (``SteeringTorque``; the rows where each is given).
    """
    asammdf = require("asammdf", "writing MDF4")
    t_utc = pd.DatetimeIndex(epochs["time_utc"])
    start = t_utc[0].to_pydatetime()
    t = (t_utc - t_utc[0]).total_seconds().to_numpy()
    vals = {
        "heading": np.mod(epochs["heading_deg"].to_numpy(float), 360.0),
        "course": epochs["course_deg"].to_numpy(float),
        "speed": epochs["speed_mps"].to_numpy(float) * 3.6,
        "lat": epochs["lat_deg"].to_numpy(float),
        "lon": epochs["lon_deg"].to_numpy(float),
        "alt": epochs["alt_m"].to_numpy(float),
        "yaw_rate": np.rad2deg(epochs["yaw_rate_rps"].to_numpy(float)),
    }
    gnss = [
        asammdf.Signal(vals[k], t, name=MDF_CHANNELS[k][0], unit=MDF_CHANNELS[k][1]) for k in vals
    ]
    mdf = asammdf.MDF(version="4.10")
    mdf.header.start_time = start
    mdf.append(gnss, comment="GNSS compass")
    if steer is not None:
        t0 = float(epochs["t_s"].iloc[0])
        for key, col in (("steer", "road_wheel_deg"), ("torque", "torque_Nm")):
            if col not in steer:
                continue
            x = steer[col].to_numpy(float)
            ok = np.isfinite(x)
            n, u = MDF_CHANNELS[key]
            ts = steer["t_s"].to_numpy(float)[ok] - t0
            mdf.append([asammdf.Signal(x[ok], ts, name=n, unit=u)], comment=key)
    mdf.save(str(path), overwrite=True)
    mdf.close()
