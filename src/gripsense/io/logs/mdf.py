"""ASAM MDF4 measurement files (CANape, INCA, IPEmotion, vehicle loggers) via asammdf.

The channels ``--columns`` names are read with :mod:`asammdf` (``MDF.get``) with the unit the
file states for each (overridable after a colon), and a steering channel whose name and unit say
what it is (``RoadWheelAngle`` [deg], :func:`gripsense.io.logs.channels.recognise_steering`) when
``--columns`` maps none; they are put on the heading channel's time
base by linear interpolation (angles unwrapped, nothing across a channel's gaps; see
:func:`gripsense.io.logs.channels.resample`). Times are absolute from the file's start time
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
from gripsense.io.logs.channels import Channel, add_steering, parse_channel_spec
from gripsense.io.logs.formats import require
from gripsense.io.logs.measurement import log_from_channels, missing_channel
from gripsense.io.logs.nmea.reader import NmeaLog
from gripsense.io.logs.options import LogInput

__all__ = [
    "MDF_CHANNELS",
    "is_mdf",
    "mdf_columns",
    "mdf_example_columns",
    "read_mdf",
    "read_mdf_log",
    "write_mdf",
    "write_mdf_log",
]

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
    dbc: str | Path | None = None,
) -> NmeaLog:
    """Read the mapped channels of an MDF4 file into the epoch table.

    A file of raw CAN frames (ASAM bus logging: ``CAN_DataFrame`` groups of CANedge, Vector
    and other loggers) is decoded with *dbc*, the way a BLF or ASC log is
    (:func:`gripsense.io.logs.canlog.decode_frames`).

    Parameters
    ----------
    path : str or Path
        The file.
    data : bytes, optional
        Its (decompressed) content, when already read.
    columns : str or dict
        ``heading=…,course=…,speed=…[,steer=…:deg,torque=…:Nm]`` (:mod:`.channels`).
    time_offset : float, optional
        Seconds since 1970 UTC of the file's time zero, replacing its start time [s].
    strict : bool
        Raise at the first sample that is not a number.
    dbc : str or Path, optional
        DBC database decoding the file's raw CAN frames (``--dbc``).

    Returns
    -------
    NmeaLog
    """
    asammdf = require("asammdf", "reading MDF4")
    name = str(path)
    mapped = parse_channel_spec(columns)
    if not mapped:
        raise InputError(f"{name}: give the channels with --columns (heading=…,course=…,speed=…)")
    plan = None
    if dbc is not None:
        from gripsense.io.logs.canlog import plan_signals

        plan = plan_signals(name, dbc, columns)
    src = io.BytesIO(data) if data is not None else str(path)
    scratch = Path(tempfile.mkdtemp(prefix="gripsense-mdf-"))
    try:
        mdf = _open(asammdf, src, name, scratch)
    except BaseException:
        shutil.rmtree(scratch, ignore_errors=True)
        raise
    logger = logging.getLogger("asammdf")  # its lines say nothing the errors here do not
    level = logger.level
    logger.setLevel(logging.CRITICAL)
    try:
        start = mdf.header.start_time
        if start.tzinfo is None:
            start = start.replace(tzinfo=dt.UTC)
        bus = _bus_groups(mdf)
        if plan is not None and bus:
            got = _bus_frames(mdf, name, bus, strict)
        else:
            found, steer_notes, steering, available = _read_channels(mdf, name, mapped, bus)
    finally:
        logger.setLevel(level)
        mdf.close()
        shutil.rmtree(scratch, ignore_errors=True)
    start_s = start.timestamp()
    if plan is not None and bus:
        from gripsense.io.logs.canlog import decode_frames

        return decode_frames(name, got, plan, fmt_name="MDF4 (CAN frames)", start_s=start_s,
                             time_offset=time_offset, strict=strict)  # fmt: skip
    used = {s.channel for s in mapped.values()}
    n_other = len({c for c in available if c not in used and c.lower() not in ("time", "t")})
    notes = [f"{n_other} channels of the file not mapped (not read)"] if n_other else []
    if dbc is not None:
        notes.append("--dbc not used: the MDF4 file holds no raw CAN frames (CAN_DataFrame)")
    log = log_from_channels(mapped, found, name=name, fmt="MDF4", start_s=start_s,
                            time_offset=time_offset, strict=strict,
                            notes=steer_notes + notes)  # fmt: skip
    log.report.steering = steering
    return log


_BUS = "CAN_DataFrame"
_BUS_OTHER = ("CAN_RemoteFrame", "CAN_ErrorFrame")


def _bus_groups(mdf) -> dict[int, tuple[str, int]]:
    """The channel groups of raw CAN frames (ASAM MDF4 bus logging): group -> (the frame
    structure channel's name, its index), for groups with records.
    """
    out = {}
    for gi, g in enumerate(mdf.groups):
        if not int(g.channel_group.cycles_nr):
            continue
        for ci, ch in enumerate(g.channels):
            if ch.name in (_BUS, *_BUS_OTHER):
                out[gi] = (ch.name, ci)
                break
    return out


def _pick(mdf, channel: str) -> tuple[int, int, str]:
    """The (group, index) of a channel name, and a note when it occurs in several groups:
    the group with the most records is read (asammdf would refuse or take the first).
    """
    entries = list(mdf.channels_db[channel])
    if len(entries) == 1:
        return entries[0][0], entries[0][1], ""
    n = [int(mdf.groups[g].channel_group.cycles_nr) for g, _ in entries]
    best = int(np.argmax(n))
    held = sum(1 for k in n if k)
    note = (
        f"channel {channel!r} occurs in {len(entries)} channel groups ({held} with records): "
        f"read from group {entries[best][0]} ({n[best]} records)"
    )
    return entries[best][0], entries[best][1], note


def _read_channels(mdf, name: str, mapped: dict, bus: dict):
    """The mapped channels of a file of named channels: (found, notes, steering, available)."""
    available = list(mdf.channels_db)
    for spec in mapped.values():
        if spec.channel not in mdf.channels_db:
            if any(n == _BUS for n, _ in bus.values()):
                k = sum(int(mdf.groups[g].channel_group.cycles_nr) for g in bus)
                raise InputError(
                    f"{name}: no channel {spec.channel!r} for {spec.key} in --columns; the file "
                    f"holds raw CAN frames ({k} frames in CAN_DataFrame groups): give the DBC "
                    "that decodes them with --dbc, and map its signals (docs/ingest.md)"
                )
            raise missing_channel(name, spec, available)

    def unit_of(channel: str) -> str:
        g, i, _ = _pick(mdf, channel)
        return mdf.get_channel_unit(channel, g, i)

    steering, notes = add_steering(mapped, available, unit_of)
    where = {key: _pick(mdf, spec.channel) for key, spec in mapped.items()}
    notes += [w[2] for w in where.values() if w[2]]
    _check_records(mdf, name, {g: [i] for g, i, _ in where.values()})
    try:  # one pass over each channel group's records for all the mapped channels
        sigs = mdf.select([(spec.channel, *where[key][:2]) for key, spec in mapped.items()])
    except Exception as e:
        raise InputError(f"{name}: the mapped channels cannot be read ({e})") from None
    found = {}
    for (key, spec), sig in zip(mapped.items(), sigs, strict=True):
        v = np.asarray(sig.samples)
        what = _not_numbers(v)
        if what:
            bus_hint = ""
            if spec.channel.startswith(("CAN_", "LIN_", "FLX_")):
                bus_hint = " (raw CAN frames: decode them with --dbc)"
            raise InputError(
                f"{name}: channel {spec.channel!r} ({key}) holds {what}, not numbers; map a "
                f"channel of numbers with --columns{bus_hint}"
            )
        found[key] = Channel(spec.channel, np.asarray(sig.timestamps, float), v.astype(float),
                             str(sig.unit or ""))  # fmt: skip
    return found, notes, steering, available


def _not_numbers(v: np.ndarray) -> str:
    """What a channel's samples are when they are not one number each ("" when they are)."""
    if v.dtype.names is not None:
        return "structures (records of several fields)"
    if v.ndim != 1 or v.dtype.kind == "V":
        return "byte arrays" if v.dtype.kind in "uiV" else f"arrays of {v.dtype} values"
    if v.dtype.kind in "SUO":
        return "text"
    if v.dtype.kind not in "fiub":
        return f"{v.dtype} values"
    return ""


def _bus_frames(mdf, name: str, bus: dict, strict: bool):
    """The CAN frames of an MDF4 bus log's ``CAN_DataFrame`` groups as arrays, in time order
    (:class:`gripsense.io.logs.canlog.FrameColumns`); remote and error frames counted as ignored.
    """
    from gripsense.io.logs.canlog import CanFrames, FrameColumns

    _check_records(mdf, name, {g: None for g in bus})
    out = CanFrames([])
    ts, ids, datas, lens = [], [], [], []
    for gi, (kind, ci) in bus.items():
        n = int(mdf.groups[gi].channel_group.cycles_nr)
        if kind != _BUS:
            out.ignored["(error/remote frame)"] = out.ignored.get("(error/remote frame)", 0) + n
            out.units += n
            continue
        try:
            sig = mdf.get(kind, gi, ci)
        except Exception as e:
            raise InputError(
                f"{name}: the CAN frames of channel group {gi} cannot be read ({e})"
            ) from None
        rec = sig.samples
        fields = rec.dtype.names or ()

        def col(f: str, rec=rec, fields=fields):
            key = f"{_BUS}.{f}"
            return np.asarray(rec[key]) if key in fields else None

        raw = col("ID")
        data = col("DataBytes")
        if raw is None or data is None:
            raise InputError(
                f"{name}: channel group {gi} ({kind}) has no ID or DataBytes field: not an "
                "ASAM bus-logging group"
            )
        m = len(raw)
        if data.dtype.kind == "V":
            data = np.frombuffer(data.tobytes(), np.uint8).reshape(m, -1)
        elif data.dtype.kind == "O" or data.ndim != 2:  # variable-length (CAN FD) payloads
            rows = [bytes(x) for x in data]
            w = max((len(x) for x in rows), default=0)
            data = np.frombuffer(b"".join(x.ljust(w, b"\0") for x in rows), np.uint8)
            data = data.reshape(m, w)
        length = col("DataLength")
        if length is None:
            length = col("DLC")
        n_bytes = np.full(m, data.shape[1], np.int64)
        if length is not None:
            n_bytes = np.minimum(np.asarray(length).astype(np.int64), data.shape[1])
        ids.append(raw.astype(np.int64) & 0x1FFFFFFF)
        ts.append(np.asarray(sig.timestamps, float))
        datas.append(data.astype(np.uint8, copy=False))
        lens.append(n_bytes)
    w = max((d.shape[1] for d in datas), default=0)
    data = np.zeros((sum(len(t) for t in ts), w), np.uint8)
    at = 0
    for d in datas:
        data[at : at + len(d), : d.shape[1]] = d
        at += len(d)
    t = np.concatenate(ts) if ts else np.zeros(0)
    order = np.argsort(t, kind="stable")
    out.columns = FrameColumns(
        pos=np.arange(1, t.size + 1),
        ids=(np.concatenate(ids) if ids else np.zeros(0, np.int64))[order],
        t=t[order],
        data=data[order],
        lens=(np.concatenate(lens) if lens else np.zeros(0, np.int64))[order],
        special=np.zeros(t.size, bool),
    )
    return out


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


_NUMERIC = (0, 1, 2, 3, 4, 5, 15, 16)  # MDF4 integer, float and complex data types
_MAX_BITS = 64 * 8


def _check_records(mdf, name: str, read: dict[int, list[int] | None]) -> None:
    """Refuse a file whose channels to be read point outside their records, or whose groups to
    be read hold fewer data than their records declare: asammdf's compiled reader would read
    past its buffers (a crash, not an error) on such a damaged file.

    Only what will be read is judged (*read*: group -> the indices of its channels read, None
    for all of them; its master channels always), and as asammdf reads it: a fixed-length
    channel's bytes (``byte_offset`` + the bits) must lie in the record; a number holds at
    most 512 bits, a string or byte array (a CANape ``$CalibrationLog``, 256 bytes) any number
    that fits; variable-length and virtual channels hold no record bytes.
    """
    for gi, which in read.items():
        g = mdf.groups[gi]
        cg = g.channel_group
        record = int(cg.samples_byte_nr) + int(getattr(cg, "invalidation_bytes_nr", 0))
        for ci, ch in enumerate(g.channels):
            kind = int(getattr(ch, "channel_type", 0))
            if which is not None and ci not in which and kind not in (2, 3):
                continue
            if kind not in (0, 2, 4):
                continue  # variable-length and virtual channels hold no record bytes
            end = int(ch.byte_offset) + (int(ch.bit_offset) + int(ch.bit_count) + 7) // 8
            numeric = int(getattr(ch, "data_type", 0)) in _NUMERIC
            if ch.bit_count <= 0 or (numeric and ch.bit_count > _MAX_BITS) or (
                end > int(cg.samples_byte_nr)
            ):  # fmt: skip
                raise InputError(
                    f"{name}: damaged MDF file: channel {ch.name!r} of group {gi} lies outside "
                    f"its {cg.samples_byte_nr}-byte record (bytes up to {end}, "
                    f"{ch.bit_count} bits)"
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


def is_mdf(head: bytes) -> bool:
    """Whether a file is MDF4 from its first bytes: the ``MDF     `` identification block (or
    ``UnFinMF `` of a file its logger did not finalise).

    Parameters
    ----------
    head : bytes
        The file's first bytes (decompressed).

    Returns
    -------
    bool
    """
    return head.startswith(b"MDF     ") or head.startswith(b"UnFinMF ")


def mdf_example_columns() -> str:
    """The ``--columns`` that read gripsense's own MDF4 files, as an example a user can try.

    Returns
    -------
    str
        ``--columns heading=…,course=…,speed=… (…)``.
    """
    cols = ",".join(f"{k}={MDF_CHANNELS[k][0]}" for k in ("heading", "course", "speed"))
    return f"--columns {cols} (the channels of gripsense simulate --format mf4)"


def read_mdf_log(src: LogInput) -> NmeaLog:
    """Read an MDF4 file as :func:`gripsense.io.logs.read_log` hands it over (its registry
    entry): by path when it is a plain file, else from its bytes (:func:`read_mdf`).

    Parameters
    ----------
    src : gripsense.io.logs.options.LogInput
        The log and its options (``columns``, ``time_offset``, ``strict``, ``dbc``).

    Returns
    -------
    NmeaLog
        Epoch table and channel accounting.
    """
    o = src.options
    return read_mdf(src.path, None if src.read is None else src.data, columns=o.columns,
                    time_offset=o.time_offset, strict=o.strict, dbc=o.dbc)  # fmt: skip


def write_mdf_log(
    epochs: pd.DataFrame,
    path: Path,
    *,
    nmea_lines: list[str] | None = None,
    steer: pd.DataFrame | None = None,
) -> str | None:
    """Write a drive as MDF4 for :func:`gripsense.io.logs.write_log` (:func:`write_mdf`).

    Parameters
    ----------
    epochs : pandas.DataFrame
        The drive's epoch table.
    path : Path
        Output file.
    nmea_lines : list of str, optional
        Unused.
    steer : pandas.DataFrame, optional
        ``t_s``, ``road_wheel_deg`` (and ``torque_Nm``): channels written inside.

    Returns
    -------
    str
        The ``--columns`` that read the file back (:func:`mdf_columns`).
    """
    write_mdf(epochs, path, steer=steer)
    return mdf_columns(
        steering=steer is not None, torque=steer is not None and "torque_Nm" in steer
    )
