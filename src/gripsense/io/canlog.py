"""CAN logs (Vector BLF and ASC) decoded with a DBC: python-can reads the frames, cantools
decodes the signals.

Only the frames of the DBC messages that carry a mapped signal are decoded; every frame is
accounted for: ``parsed`` per message, ``ignored`` (an identifier the DBC does not know, or a
message without a mapped signal) or rejected as ``malformed field`` (the DBC does not decode
it: a wrong length or a value outside its choices). Signal units come from the DBC
(overridable in ``--columns``). A steering signal whose name and unit say what it is
(``SteeringWheelAngle`` [deg], :func:`gripsense.io.channels.recognise_steering`) is decoded too
when ``--columns`` maps none. Times are the log's: BLF stores absolute times; an ASC file's
``date`` line gives its start; else ``--time-offset`` (seconds since 1970 UTC of the log's
zero) makes them absolute. The signals are put on the heading signal's time base
(:func:`gripsense.io.channels.resample`).
"""

from __future__ import annotations

import io
from pathlib import Path
from typing import Any

import numpy as np

from gripsense.errors import InputError
from gripsense.io.channels import Channel, add_steering, parse_channel_spec
from gripsense.io.formats import require
from gripsense.io.measurement import log_from_channels, missing_channel
from gripsense.io.nmea.accounting import RejectedLine
from gripsense.io.nmea.reader import NmeaLog
from gripsense.io.nmea.schema import MALFORMED

__all__ = ["CAN_SIGNALS", "load_dbc", "read_can", "write_can"]

_ABSOLUTE_AFTER = 1e8  # timestamps above this are seconds since 1970 (1973 onwards)


def load_dbc(path: str | Path):
    """A DBC database, with one clear error when it cannot be read.

    Parameters
    ----------
    path : str or Path
        The ``.dbc`` file.

    Returns
    -------
    cantools.database.can.Database
    """
    cantools = require("cantools", "decoding CAN logs")
    try:
        return cantools.database.load_file(str(path), database_format="dbc", strict=False)
    except FileNotFoundError:
        raise InputError(f"{path}: no such DBC file") from None
    except Exception as e:
        raise InputError(f"{path}: not a readable DBC file ({type(e).__name__}: {e})") from None


def _frames(path: Path, data: bytes, fmt: str):
    can = require("can", "reading CAN logs")
    try:
        if fmt == "blf":
            return list(can.BLFReader(io.BytesIO(data)))
        text = io.StringIO(data.decode("utf-8", errors="replace"))
        return list(can.ASCReader(text, relative_timestamp=False))
    except Exception as e:
        raise InputError(
            f"{path}: not a readable {fmt.upper()} log ({type(e).__name__}: {e})"
        ) from None


def read_can(
    path: str | Path,
    data: bytes,
    fmt: str,
    *,
    dbc: str | Path,
    columns: str | dict | None,
    time_offset: float | None = None,
    strict: bool = False,
) -> NmeaLog:
    """Read the mapped signals of a CAN log into the epoch table.

    Parameters
    ----------
    path : str or Path
        The log.
    data : bytes
        Its (decompressed) content.
    fmt : {"blf", "asc"}
        Log format.
    dbc : str or Path
        DBC database.
    columns : str or dict
        ``heading=SIGNAL,…`` (:mod:`gripsense.io.channels`).
    time_offset : float, optional
        Seconds since 1970 UTC of the log's time zero [s] (for logs with relative times).
    strict : bool
        Raise at the first frame that does not decode.

    Returns
    -------
    NmeaLog
    """
    name = str(path)
    mapped = parse_channel_spec(columns)
    if not mapped:
        raise InputError(f"{name}: give the signals with --columns (heading=…,course=…,speed=…)")
    db = load_dbc(dbc)
    where: dict[str, Any] = {}  # signal -> its cantools Message
    known = {m.frame_id for m in db.messages}
    for m in db.messages:
        for s in m.signals:
            where.setdefault(s.name, m)
    for spec in mapped.values():
        if spec.channel not in where:
            raise missing_channel(f"{name} (DBC {dbc})", spec, list(where))
    steering, steer_notes = add_steering(
        mapped, list(where), lambda s: where[s].get_signal_by_name(s).unit
    )
    wanted = {where[s.channel].frame_id: where[s.channel] for s in mapped.values()}
    frames = _frames(Path(path), data, fmt)
    series: dict[str, tuple[list, list]] = {s.channel: ([], []) for s in mapped.values()}
    parsed: dict[str, int] = {}
    ignored: dict[str, int] = {}
    n_bad = 0
    firsts: list[RejectedLine] = []
    for k, fr in enumerate(frames):
        if getattr(fr, "is_error_frame", False) or getattr(fr, "is_remote_frame", False):
            ignored["(error/remote frame)"] = ignored.get("(error/remote frame)", 0) + 1
            continue
        msg = wanted.get(fr.arbitration_id)
        if msg is None:
            key = "(not in the DBC)" if fr.arbitration_id not in known else "(no mapped signal)"
            ignored[key] = ignored.get(key, 0) + 1
            continue
        try:
            dec = msg.decode(bytes(fr.data), decode_choices=False)
        except Exception as e:
            detail = (
                f"frame {k + 1} (id 0x{fr.arbitration_id:X}, t = {fr.timestamp:.3f} s): "
                f"{msg.name} does not decode ({e})"
            )
            if strict:
                raise InputError(f"{name}: {MALFORMED}: {detail} (strict mode)") from None
            n_bad += 1
            if len(firsts) < 20:
                firsts.append(RejectedLine(k + 1, MALFORMED, detail))
            continue
        parsed[msg.name] = parsed.get(msg.name, 0) + 1
        for sig, (ts, vs) in series.items():
            if sig in dec:
                ts.append(fr.timestamp)
                vs.append(float(dec[sig]))
    found = {}
    for key, spec in mapped.items():
        ts, vs = series[spec.channel]
        unit = db.get_message_by_name(where[spec.channel].name).get_signal_by_name(
            spec.channel
        ).unit  # fmt: skip
        found[key] = Channel(spec.channel, np.asarray(ts, float), np.asarray(vs, float),
                             str(unit or ""))  # fmt: skip
    t_all = np.concatenate([c.t for c in found.values()]) if found else np.zeros(0)
    absolute = bool(t_all.size and np.nanmin(t_all) > _ABSOLUTE_AFTER)
    start = 0.0 if absolute else None
    fmt_name = f"CAN {fmt.upper()}"
    offset = None if absolute else time_offset
    log = log_from_channels(
        mapped, found, name=name, fmt=fmt_name, start_s=start, time_offset=offset,
        strict=strict, ignored=ignored, rejected={MALFORMED: n_bad}, first_rejects=firsts,
        unit="frames", notes=steer_notes,
    )  # fmt: skip
    log.report.steering = steering
    # frames, not samples: the parsed count is per message
    rep = log.report
    rep.parsed = dict(sorted(parsed.items()))
    rep.rejected[MALFORMED] = n_bad
    rep.total_lines = len(frames)
    if absolute and time_offset is not None:
        rep.notes.append("the log's times are absolute: --time-offset not used")
    return log


CAN_SIGNALS = {
    "heading": "TrueHeading",
    "course": "Course",
    "yaw_rate": "YawRate",
    "speed": "Speed",
    "alt": "Height",
    "lat": "Latitude",
    "lon": "Longitude",
}
"""Signals of the DBC ``tests/data/formats/vehicle.dbc`` that :func:`write_can` fills."""


def write_can(
    epochs,
    path: str | Path,
    dbc: str | Path,
    *,
    steering_wheel=None,
    absolute: bool = True,
) -> None:
    """Write an epoch table as a CAN log (BLF or ASC by the suffix), encoded with cantools
    from a DBC that has the signals of :data:`CAN_SIGNALS` (and ``SteeringWheelAngle``).

    Parameters
    ----------
    epochs : pandas.DataFrame
        ``time_utc``, ``heading_deg``, ``course_deg``, ``yaw_rate_rps`` (ISO, written in deg/s),
        ``speed_mps``, ``alt_m``, ``lat_deg``, ``lon_deg``.
    path : str or Path
        ``.blf`` or ``.asc``.
    dbc : str or Path
        The DBC.
    steering_wheel : pandas.DataFrame, optional
        ``t_s`` (the epochs' clock) and ``steering_wheel_deg``, written as
        ``SteeringWheelAngle`` frames at their own rate.
    absolute : bool
        Frame times in seconds since 1970 (else from the log's start).
    """
    import pandas as pd

    can = require("can", "writing CAN logs")
    db = load_dbc(dbc)
    t_utc = pd.DatetimeIndex(epochs["time_utc"])
    t0 = t_utc[0].timestamp() if absolute else 0.0
    t = t0 + (t_utc - t_utc[0]).total_seconds().to_numpy()
    vals = {
        "TrueHeading": np.mod(epochs["heading_deg"].to_numpy(float), 360.0),
        "Course": np.mod(epochs["course_deg"].to_numpy(float), 360.0),
        "YawRate": np.rad2deg(epochs["yaw_rate_rps"].to_numpy(float)),
        "Speed": epochs["speed_mps"].to_numpy(float) * 3.6,
        "Height": epochs["alt_m"].to_numpy(float),
        "Latitude": epochs["lat_deg"].to_numpy(float),
        "Longitude": epochs["lon_deg"].to_numpy(float),
    }
    frames = []
    for mname in ("GNSS_Heading", "GNSS_Velocity", "GNSS_Position"):
        msg = db.get_message_by_name(mname)
        for k in range(t.size):
            payload = msg.encode({s.name: float(vals[s.name][k]) for s in msg.signals})
            frames.append(can.Message(timestamp=float(t[k]), arbitration_id=msg.frame_id,
                                      data=payload, is_extended_id=False))  # fmt: skip
    if steering_wheel is not None:
        msg = db.get_message_by_name("EPS_Steering")
        ts = steering_wheel["t_s"].to_numpy(float) - float(epochs["t_s"].iloc[0]) + t0
        sw = steering_wheel["steering_wheel_deg"].to_numpy(float)
        for k in range(ts.size):
            payload = msg.encode({"SteeringWheelAngle": float(sw[k]), "ColumnTorque": 0.0,
                                  "Mode": 1})  # fmt: skip
            frames.append(can.Message(timestamp=float(ts[k]), arbitration_id=msg.frame_id,
                                      data=payload, is_extended_id=False))  # fmt: skip
    frames.sort(key=lambda m: m.timestamp)
    writer = can.BLFWriter(str(path)) if str(path).endswith(".blf") else can.ASCWriter(str(path))
    for m in frames:
        writer.on_message_received(m)
    writer.stop()
