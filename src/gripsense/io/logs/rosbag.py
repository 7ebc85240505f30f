"""ROS bags: ROS 1 ``.bag``, ROS 2 ``.db3`` (sqlite3) and ``.mcap``, read with ``rosbags``.

No ROS install is needed: :mod:`rosbags` reads the three containers and decodes their messages
with a type store built from the bag's own message definitions (a ROS 1 bag's connection
headers and a ROS 2 MCAP file carry them; a ``.db3`` bag falls back to the ROS 2 Humble types,
and for the NovAtel types below to the OEM7 driver's definitions, used only where they fit a
message's bytes exactly).

The common message types are understood out of the box (:data:`ROS_TYPES`):

======================================================  ==========================================
message type                                            gives
======================================================  ==========================================
``sensor_msgs/NavSatFix``                               lat, lon, alt (no fix: not used)
``gps_common/GPSFix``                                   lat, lon, alt, course (track), speed
``geometry_msgs/TwistStamped``, ``…WithCovariance…``    course and speed from the ENU velocity
``sensor_msgs/Imu``                                     yaw rate (``angular_velocity.z``, ISO)
``nmea_msgs/Sentence``                                  the sentences, through the NMEA reader
``ublox_msgs/NavRELPOSNED(9)``                          heading (``relPosHeading`` when valid)
``ublox_msgs/NavPVT``                                   lat, lon, alt, course, speed
``novatel_oem7_msgs/HEADING2``                          heading (``SOL_COMPUTED`` only)
``novatel_oem7_msgs/BESTVEL``                           course, speed (``SOL_COMPUTED`` only)
``novatel_oem7_msgs/INSPVA``                            lat, lon, alt, heading, course, speed
                                                        (INS status good, free or aligned)
======================================================  ==========================================

``--columns`` maps a topic the way it maps a channel: ``heading=/gps/heading`` takes the
heading a known type gives; ``heading=/gps/heading.data:deg`` a field (dotted path) of any
type, with its unit; a ``std_msgs`` number (``Float64``…) is its ``data``. What ``--columns``
does not map is taken from the known types (the topic with most messages for each key). Time
is the header stamp (``header.stamp``), else the time the bag recorded the message.

Every message is counted: used, ignored (its topic not mapped, or no valid value: no fix, a
heading flagged invalid) or rejected (it did not decode).
"""

from __future__ import annotations

import contextlib
import logging
import math
import os
import shutil
import tempfile
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from gripsense.errors import InputError
from gripsense.io.logs.channels import CHANNEL_KEYS, Channel, ChannelSpec, parse_channel_spec
from gripsense.io.logs.formats import require
from gripsense.io.logs.measurement import log_from_channels
from gripsense.io.logs.nmea.reader import NmeaLog
from gripsense.io.logs.nmea.schema import MALFORMED, REASONS
from gripsense.io.logs.options import LogInput

if TYPE_CHECKING:
    import pandas as pd

__all__ = [
    "ROSBAG2_COLUMNS",
    "ROS_TYPES",
    "is_rosbag",
    "is_rosbag_dir",
    "read_rosbag",
    "read_rosbag_log",
    "write_rosbag2",
    "write_rosbag2_log",
]

ROS1_MAGIC = b"#ROSBAG V2.0"
MCAP_MAGIC = b"\x89MCAP"
SQLITE_MAGIC = b"SQLite format 3\x00"


def is_rosbag(head: bytes) -> str | None:
    """The ROS bag container of a file from its first bytes.

    Parameters
    ----------
    head : bytes
        The file's first bytes.

    Returns
    -------
    str or None
        ``"bag"`` (ROS 1), ``"mcap"``, ``"db3"`` (ROS 2 sqlite3) or None.
    """
    if head.startswith(ROS1_MAGIC):
        return "bag"
    if head.startswith(MCAP_MAGIC):
        return "mcap"
    if head.startswith(SQLITE_MAGIC):
        return "db3"
    return None


def is_rosbag_dir(path: Path) -> bool:
    """A ROS 2 bag folder: a directory with ``metadata.yaml``.

    Parameters
    ----------
    path : Path
        The path given.

    Returns
    -------
    bool
    """
    return path.is_dir() and (path / "metadata.yaml").is_file()


def _norm(msgtype: str) -> str:
    """``sensor_msgs/msg/NavSatFix`` and ``sensor_msgs/NavSatFix`` -> ``sensor_msgs/NavSatFix``."""
    return msgtype.replace("/msg/", "/")


def _get(msg, path: str):
    for part in path.split("."):
        msg = getattr(msg, part)
    return msg


def _w(ok, v) -> np.ndarray:
    """*v* where *ok*, NaN elsewhere (columns of a topic's messages)."""
    return np.where(ok, np.asarray(v, float), np.nan)


def _int(v) -> np.ndarray:
    return np.asarray(v).astype(np.int64)


# The known types' values, computed on a topic's columns (:class:`_Columns`: each field an
# array over the messages): a message without a valid value gets NaN.


def _navsatfix(m) -> dict[str, np.ndarray]:
    ok = _int(m.status.status) >= 0  # STATUS_NO_FIX is -1
    return {"lat": _w(ok, m.latitude), "lon": _w(ok, m.longitude), "alt": _w(ok, m.altitude)}


def _gpsfix(m) -> dict[str, np.ndarray]:
    """``gps_common/GPSFix``: ``track`` degrees from north, ``speed`` m/s over ground."""
    ok = _int(m.status.status) >= 0  # STATUS_NO_FIX is -1
    return {
        **{k: _w(ok, v) for k, v in (("lat", m.latitude), ("lon", m.longitude))},
        "alt": _w(ok, m.altitude),
        "course": _w(ok, np.mod(np.asarray(m.track, float), 360.0)),
        "speed": _w(ok, m.speed),
    }


def _enu(v) -> dict[str, np.ndarray]:
    """Course (clockwise from north) and speed of an ENU velocity (REP 103/105: x east, y
    north): the convention of ``nmea_navsat_driver``'s and ``gps_common``'s velocity topics.
    """
    e, n = np.asarray(v.x, float), np.asarray(v.y, float)
    return {"course": np.mod(np.degrees(np.arctan2(e, n)), 360.0), "speed": np.hypot(e, n)}


def _field_column(cols, fpath: str, name: str, tp, key: str) -> np.ndarray:
    """A mapped field over a topic's messages; a field that is not a number, or none, is an
    error naming it.
    """
    try:
        v = cols.leaf(fpath)
    except AttributeError:
        fields = ", ".join(f for f in getattr(cols.msg0, "__dataclass_fields__", {}) if f[0] != "_")
        raise InputError(
            f"{name}: topic {tp.name!r} ({tp.msgtype}) has no field {fpath!r} for {key} in "
            f"--columns; its fields: {fields}"
        ) from None
    except _NotNumbers as e:
        v, what = None, str(e)
    else:
        what = "messages"
    if v is not None:
        return v
    raise InputError(
        f"{name}: topic {tp.name!r} field {fpath!r} ({key}) holds {what}, not numbers; map a "
        "field of numbers with --columns (e.g. heading=/TOPIC.FIELD:deg)"
    )


def _relposned(m) -> dict[str, np.ndarray]:
    if not hasattr(m, "relPosHeading"):  # protocol < 27: no heading
        return {}
    ok = (_int(m.flags) & 0x100) != 0  # relPosHeadingValid
    return {"heading": _w(ok, np.asarray(m.relPosHeading, float) * 1e-5)}


def _navpvt(m) -> dict[str, np.ndarray]:
    flags = _int(m.flags)
    ok = (flags & 0x01) != 0  # gnssFixOK
    out = {
        "lat": _w(ok, np.asarray(m.lat, float) * 1e-7),
        "lon": _w(ok, np.asarray(m.lon, float) * 1e-7),
        "alt": _w(ok, np.asarray(m.hMSL, float) * 1e-3),  # above MSL, as the UBX reader
        "course": _w(ok, np.asarray(m.heading, float) * 1e-5),
        "speed": _w(ok, np.asarray(m.gSpeed, float) * 1e-3),
    }
    out["heading"] = _w(ok & ((flags & 0x20) != 0), np.asarray(m.headVeh, float) * 1e-5)
    return out


_INS_GOOD = (3, 6, 7)  # INS_SOLUTION_GOOD, INS_SOLUTION_FREE, INS_ALIGNMENT_COMPLETE


def _solved(m) -> np.ndarray:
    """NovAtel logs whose solution status is SOL_COMPUTED (0)."""
    return _int(m.sol_status.status) == 0


def _heading2(m) -> dict[str, np.ndarray]:
    return {"heading": _w(_solved(m), m.heading)}


def _bestvel(m) -> dict[str, np.ndarray]:
    ok = _solved(m)
    return {"course": _w(ok, m.trk_gnd), "speed": _w(ok, m.hor_speed)}


def _inspva(m) -> dict[str, np.ndarray]:
    ok = np.isin(_int(m.status.status), _INS_GOOD)  # aligning …: azimuth 0, not a heading
    e, n = np.asarray(m.east_velocity, float), np.asarray(m.north_velocity, float)
    return {
        "lat": _w(ok, m.latitude),
        "lon": _w(ok, m.longitude),
        "alt": _w(ok, m.height),
        "heading": _w(ok, m.azimuth),
        "course": _w(ok, np.mod(np.degrees(np.arctan2(e, n)), 360.0)),
        "speed": _w(ok, np.hypot(e, n)),
    }


@dataclass(frozen=True)
class RosType:
    """What a known message type gives.

    Parameters
    ----------
    keys : dict
        ``--columns`` key -> the unit of the value :attr:`values` gives for it.
    values : callable
        Message -> key -> value (an empty dict: the message has no valid value).
    """

    keys: dict[str, str]
    values: object


_POS = {"lat": "deg", "lon": "deg", "alt": "m"}
_VEL = {"course": "deg", "speed": "m/s"}
ROS_TYPES: dict[str, RosType] = {
    "novatel_oem7_msgs/HEADING2": RosType({"heading": "deg"}, _heading2),
    "ublox_msgs/NavRELPOSNED9": RosType({"heading": "deg"}, _relposned),
    "ublox_msgs/NavRELPOSNED": RosType({"heading": "deg"}, _relposned),
    "novatel_oem7_msgs/BESTVEL": RosType(_VEL, _bestvel),
    "geometry_msgs/TwistStamped": RosType(_VEL, lambda m: _enu(m.twist.linear)),
    "geometry_msgs/TwistWithCovarianceStamped": RosType(_VEL, lambda m: _enu(m.twist.twist.linear)),
    "sensor_msgs/NavSatFix": RosType(_POS, _navsatfix),
    "gps_common/GPSFix": RosType({**_POS, **_VEL}, _gpsfix),
    "ublox_msgs/NavPVT": RosType({**_POS, **_VEL, "heading": "deg"}, _navpvt),
    "ublox_msgs/NavPVT7": RosType({**_POS, **_VEL, "heading": "deg"}, _navpvt),
    "novatel_oem7_msgs/INSPVA": RosType({**_POS, **_VEL, "heading": "deg"}, _inspva),
    "sensor_msgs/Imu": RosType({"yaw_rate": "rad/s"}, lambda m: {"yaw_rate": m.angular_velocity.z}),
}
"""Known message type (without ``/msg/``) -> what it gives, in order of preference."""

NMEA_TYPE = "nmea_msgs/Sentence"
_KNOWN_SHORT = (
    "NavSatFix, TwistStamped, Imu, nmea_msgs/Sentence, u-blox NavPVT/NavRELPOSNED, "
    "NovAtel HEADING2/BESTVEL/INSPVA"
)
_NUMBER_TYPES = {f"std_msgs/{t}" for t in ("Float64", "Float32", "Int32", "Int16", "Int64")}

ROSBAG2_COLUMNS = "heading=/gps/heading:deg"
"""The ``--columns`` that read a bag of :func:`write_rosbag2` (its other topics are known
types)."""


@dataclass
class _Topic:
    """What is read from one topic: (key, source) pairs, and the accounting."""

    name: str
    msgtype: str
    count: int
    reads: list[tuple[str, str | None, str | None]] = field(default_factory=list)
    # (key, field path or None for the known type's value, unit or None)
    raws: list[bytes] = field(default_factory=list)
    logtimes: list[int] = field(default_factory=list)
    msgtype_full: str = ""
    used: int = 0
    invalid: int = 0
    bad: int = 0
    first_bad: str = ""


_DTYPES = {
    "bool": "u1", "byte": "u1", "char": "u1", "octet": "u1", "int8": "i1", "uint8": "u1",
    "int16": "<i2", "uint16": "<u2", "int32": "<i4", "uint32": "<u4", "int64": "<i8",
    "uint64": "<u8", "float32": "<f4", "float64": "<f8",
}  # fmt: skip


class _NotNumbers(Exception):
    """A field of a mapped path holds no number (text, an array, a message)."""


class _Columns:
    """A topic's messages as columns: attribute access as on a message, a numeric field an
    array over the messages.

    Messages of one length (a fixed layout: no strings or sequences whose length varies) are
    not decoded one by one: each field's byte offset is found once, by serialising the first
    message with that field changed in its lowest byte, and read with numpy from all of them;
    checked against rosbags' decoding of the first, middle and last message (else, and for
    messages of varying length, every message is decoded by rosbags).
    """

    def __init__(self, reader, tp: _Topic, name: str, strict: bool):
        self.reader, self.tp, self.name = reader, tp, name
        self.cache: dict[str, np.ndarray | None] = {}
        self.keep = np.ones(len(tp.raws), bool)
        self.msgs: list | None = None
        self.block: np.ndarray | None = None
        self.msg0 = None
        raws = tp.raws
        if not raws:
            return
        sizes = {len(r) for r in raws}
        little = reader.is2 is False or raws[0][1:2] == b"\x01"  # CDR: little-endian
        if len(sizes) == 1 and little:
            try:
                self.msg0 = reader.deserialize(raws[0], tp.msgtype_full)
                again = self._serialize(self.msg0)
            except Exception:
                again = None
            if again is not None and bytes(again) == bytes(raws[0]):
                self.block = np.frombuffer(b"".join(raws), np.uint8).reshape(len(raws), -1)
                return
        self._decode_all(strict)

    def _serialize(self, msg):
        ts, t = self.reader.typestore, self.tp.msgtype_full
        return ts.serialize_cdr(msg, t) if self.reader.is2 else ts.serialize_ros1(msg, t)

    def _decode_all(self, strict: bool) -> None:
        msgs, tp = [], self.tp
        # a definition of ours (the bag has none): only where it fits the bytes exactly
        ours = tp.msgtype_full in getattr(self.reader, "fallback_types", ())
        for i, raw in enumerate(tp.raws):
            try:
                msg = self.reader.deserialize(raw, tp.msgtype_full)
                if ours and bytes(self._serialize(msg)) != bytes(raw):
                    raise ValueError("its bytes are not what the definition gives")
                msgs.append(msg)
            except Exception as e:
                why = str(e)
                if ours:
                    why = (
                        f"the bag carries no definition of {tp.msgtype_full} and the NovAtel "
                        f"OEM7 driver's does not fit its bytes (another driver version: {e}); "
                        "map a topic of a standard type with --columns"
                    )
                if (
                    isinstance(e, KeyError)
                    and tp.msgtype_full not in self.reader.typestore.fielddefs
                ):
                    why = (
                        f"its type {tp.msgtype_full} is not defined: the bag carries no message "
                        "definitions (ROS 2 Humble and older record none) and rosbags does not "
                        "know it; map a topic of a standard type with --columns"
                    )
                detail = f"message {i + 1} of {tp.name}: {why}"
                if strict:
                    raise InputError(f"{self.name}: {MALFORMED}: {detail} (strict mode)") from None
                tp.bad += 1
                tp.first_bad = tp.first_bad or detail
                self.keep[i] = False
                msgs.append(None)
        self.msgs = msgs
        self.block = None
        self.msg0 = next((m for m in msgs if m is not None), None)

    def view(self) -> _View:
        return _View(self, "")

    def leaf(self, path: str) -> np.ndarray | None:
        """The field *path* over the messages; None for a nested message; AttributeError for
        no such field, :class:`_NotNumbers` for a field that is not a number.
        """
        if path in self.cache:
            return self.cache[path]
        n = len(self.tp.raws)
        if self.msg0 is None:
            return np.full(n, np.nan)
        v0 = _get(self.msg0, path)
        if hasattr(v0, "__msgtype__"):
            self.cache[path] = None
            return None
        if not isinstance(v0, bool | int | float | np.number):
            raise _NotNumbers("text" if isinstance(v0, str) else f"{type(v0).__name__} values")
        out = self._fast(path, v0) if self.block is not None else None
        if out is None:
            if self.msgs is None:
                self._decode_all(False)
            assert self.msgs is not None
            out = np.array([math.nan if m is None else float(_get(m, path)) for m in self.msgs])
        self.cache[path] = out
        return out

    def _fast(self, path: str, v0) -> np.ndarray | None:
        """The field from the message bytes (see the class documentation), or None."""
        from dataclasses import replace

        base = self._base_type(path)
        if base not in _DTYPES:
            return None
        dt = np.dtype(_DTYPES[base])
        b = bytearray(np.array([v0], dt).tobytes())
        b[0] ^= 1
        v1 = np.frombuffer(bytes(b), dt)[0].item()

        def put(msg, parts):
            if len(parts) == 1:
                return replace(msg, **{parts[0]: v1})
            return replace(msg, **{parts[0]: put(getattr(msg, parts[0]), parts[1:])})

        try:
            changed = np.frombuffer(
                bytes(self._serialize(put(self.msg0, path.split(".")))), np.uint8
            )
        except Exception:
            return None
        assert self.block is not None
        if changed.size != self.block.shape[1]:
            return None
        diff = np.flatnonzero(changed != self.block[0])
        if diff.size != 1:
            return None
        off = int(diff[0])
        out = np.ascontiguousarray(self.block[:, off : off + dt.itemsize]).view(dt).ravel()
        n = len(out)
        for i in {0, n // 2, n - 1}:  # checked against rosbags' decoding
            m = self.reader.deserialize(self.tp.raws[i], self.tp.msgtype_full)
            if float(_get(m, path)) != float(out[i]) and not (
                math.isnan(float(out[i])) and math.isnan(float(_get(m, path)))
            ):
                return None
        return out.astype(float)

    def _base_type(self, path: str) -> str | None:
        """The ROS base type (``float64`` …) of a field path, from the type store."""
        defs = self.reader.typestore.fielddefs
        typ = self.tp.msgtype_full
        for part in path.split("."):
            fields = dict(defs[typ][1])
            if part not in fields:
                return None
            kind, spec = fields[part]
            if int(kind) == 2:  # NAME: a nested message
                typ = spec
            elif int(kind) == 1:  # BASE
                typ = spec[0]
            else:
                return None
        return typ

    def stamps(self) -> np.ndarray:
        """The header stamp [s] of each message, else the time the bag recorded it."""
        logt = np.asarray(self.tp.logtimes, np.int64)
        try:
            sec = self.leaf("header.stamp.sec")
            ns = self.leaf("header.stamp.nanosec")
        except (AttributeError, _NotNumbers):
            return logt * 1e-9
        if sec is None or ns is None:
            return logt * 1e-9
        s_i = np.nan_to_num(sec).astype(np.int64)
        n_i = np.nan_to_num(ns).astype(np.int64)
        stamped = (s_i != 0) | (n_i != 0)
        return np.where(stamped, s_i * 1_000_000_000 + n_i, logt) * 1e-9  # as the record time


class _View:
    """Attribute access on :class:`_Columns` (a nested message, or a field's array)."""

    def __init__(self, cols: _Columns, path: str):
        self._cols, self._path = cols, path

    def __getattr__(self, name: str):
        if name.startswith("_"):
            raise AttributeError(name)
        p = f"{self._path}.{name}" if self._path else name
        v = self._cols.leaf(p)
        return _View(self._cols, p) if v is None else v


@contextlib.contextmanager
def _quiet():
    """Keep rosbags' log lines (warnings on odd definitions) quiet: the notes say more."""
    lg = logging.getLogger("rosbags")
    level = lg.level
    lg.setLevel(logging.CRITICAL)
    try:
        yield
    finally:
        lg.setLevel(level)


# Definitions (fields only) of the known types rosbags does not ship, for ROS 2 bags recorded
# without message definitions (Humble and older record none): novatel_oem7_msgs as NovAtel's
# OEM7 driver defines them (github.com/novatel/novatel_oem7_driver, src/novatel_oem7_msgs/msg,
# branch humble, commit 8903da2901991f99dae68c77842d07ff0ee7830c; © 2020 NovAtel Inc., MIT).
# A bag's own definitions always win; a message whose bytes these do not fit exactly is not
# decoded (counted as malformed), never read with a wrong layout.
_N7 = "novatel_oem7_msgs/msg/"
_FALLBACK_DEFS = {
    _N7 + "Oem7Header": "string message_name\nuint16 message_id\nuint8 message_type\n"
    "uint32 sequence_number\nuint8 time_status\nuint16 gps_week_number\n"
    "uint32 gps_week_milliseconds\nuint32 receiver_status\nfloat32 idle_time",
    _N7 + "SolutionStatus": "uint32 status",
    _N7 + "PositionOrVelocityType": "uint32 type",
    _N7 + "SolutionSource": "uint8 source",
    _N7 + "BestExtendedSolutionStatus": "uint8 status",
    _N7 + "InertialSolutionStatus": "uint32 status",
    _N7 + "HEADING2": "std_msgs/Header header\nOem7Header nov_header\nSolutionStatus sol_status\n"
    "PositionOrVelocityType pos_type\nfloat32 length\nfloat32 heading\nfloat32 pitch\n"
    "float32 reserved\nfloat32 heading_stdev\nfloat32 pitch_stdev\nint8[4] rover_stn_id\n"
    "int8[4] master_stn_id\nuint8 num_sv_tracked\nuint8 num_sv_in_sol\nuint8 num_sv_obs\n"
    "uint8 num_sv_multi\nSolutionSource sol_source\nBestExtendedSolutionStatus ext_sol_status\n"
    "uint8 galileo_beidou_sig_mask\nuint8 gps_glonass_sig_mask",
    _N7 + "BESTVEL": "std_msgs/Header header\nOem7Header nov_header\nSolutionStatus sol_status\n"
    "PositionOrVelocityType vel_type\nfloat32 latency\nfloat32 diff_age\nfloat64 hor_speed\n"
    "float64 trk_gnd\nfloat64 ver_speed\nfloat32 reserved",
    _N7 + "INSPVA": "std_msgs/Header header\nOem7Header nov_header\nfloat64 latitude\n"
    "float64 longitude\nfloat64 height\nfloat64 north_velocity\nfloat64 east_velocity\n"
    "float64 up_velocity\nfloat64 roll\nfloat64 pitch\nfloat64 azimuth\n"
    "InertialSolutionStatus status",
}


def _add_fallback_types(reader) -> list[str]:
    """Register :data:`_FALLBACK_DEFS` for the bag's types its type store lacks (a ROS 2 bag
    without definitions); the types registered.
    """
    if not getattr(reader, "is2", False):
        return []
    from rosbags.typesys import get_types_from_msg

    ts = reader.typestore
    want = {c.msgtype for c in reader.connections} - set(ts.fielddefs)
    if not want & set(_FALLBACK_DEFS):
        return []
    types: dict = {}
    for t, text in _FALLBACK_DEFS.items():
        if t not in ts.fielddefs:
            types.update(get_types_from_msg(text, t))
    ts.register(types)
    return sorted(want & set(_FALLBACK_DEFS))


def _open(path: Path, name: str):
    """An opened ``rosbags`` AnyReader, or one InputError naming the file and the reason."""
    require("rosbags", "reading ROS bags")
    from rosbags.highlevel import AnyReader
    from rosbags.typesys import Stores, get_typestore

    try:
        reader = AnyReader([path], default_typestore=get_typestore(Stores.ROS2_HUMBLE))
        reader.open()
    except Exception as e:
        if "profile is not ros" in str(e).lower():
            raise InputError(
                f"{name}: an MCAP file not recorded by ROS ({e}): its messages are not ROS "
                "messages (JSON, Protobuf …); export the GNSS channels to CSV and read them "
                "with friction --table"
            ) from None
        raise InputError(f"{name}: not a readable ROS bag ({type(e).__name__}: {e})") from None
    reader.fallback_types = _add_fallback_types(reader)  # type: ignore[attr-defined]
    return reader


def read_rosbag(
    path: str | Path,
    data: bytes | None = None,
    *,
    columns: str | dict | None = None,
    time_offset: float | None = None,
    strict: bool = False,
) -> NmeaLog:
    """Read a ROS bag's GNSS topics into the epoch table (see the module documentation).

    Parameters
    ----------
    path : str or Path
        The bag: a ROS 1 ``.bag``, a ROS 2 ``.db3`` or ``.mcap`` file, or a ROS 2 bag folder.
    data : bytes, optional
        Its (decompressed) content, when read from a pipe or a gzip file.
    columns : str or dict, optional
        ``key=TOPIC[.field.path][:unit],…`` (:mod:`gripsense.io.logs.channels`); keys not mapped
        are taken from the known message types.
    time_offset : float, optional
        Seconds since 1970 UTC added to the stamps, for a bag whose stamps are not UTC [s].
    strict : bool
        Raise at the first message that does not decode.

    Returns
    -------
    NmeaLog
        The epoch table; ``report.unit`` is ``messages``.
    """
    name = str(path)
    p = Path(path)
    scratch = None
    if data is not None:  # a pipe or a gzip file: rosbags reads files
        scratch = Path(tempfile.mkdtemp(prefix="gripsense-rosbag-"))
        kind = is_rosbag(data[:16]) or "bag"
        p = scratch / f"bag.{kind}"
        p.write_bytes(data)
    try:
        with _quiet():
            reader = _open(p, name)
            try:
                return _read(reader, name, columns, time_offset, strict)
            finally:
                reader.close()
    finally:
        if scratch is not None:
            shutil.rmtree(scratch, ignore_errors=True)


def _plan(reader, name: str, columns) -> tuple[dict[str, _Topic], dict[str, ChannelSpec], list]:
    """Which topic gives each key: the ``--columns`` ones, then the known types'."""
    counts: dict[str, int] = {}
    types: dict[str, str] = {}
    for c in reader.connections:
        counts[c.topic] = counts.get(c.topic, 0) + int(c.msgcount)
        types[c.topic] = _norm(c.msgtype)
    topics = {t: _Topic(t, types[t], counts[t]) for t in counts}
    mapped = parse_channel_spec(columns)
    notes: list[str] = []
    for key, spec in mapped.items():
        topic, _, fpath = spec.channel.partition(".")
        if topic not in topics:
            import difflib

            close = difflib.get_close_matches(topic, list(topics), n=3, cutoff=0.5)
            hint = f" (did you mean {', '.join(close)}?)" if close else ""
            raise InputError(
                f"{name}: no topic {topic!r} for {key} in --columns{hint}; the bag has "
                f"{len(topics)} topics: "
                + ", ".join(f"{t} ({topics[t].msgtype})" for t in sorted(topics)[:15])
            )
        tp = topics[topic]
        known = ROS_TYPES.get(tp.msgtype)
        if not fpath:
            if tp.msgtype in _NUMBER_TYPES:
                fpath = "data"
            elif known is None or key not in known.keys:
                gives = f"it gives {', '.join(known.keys)}" if known else "not a type known here"
                raise InputError(
                    f"{name}: topic {topic!r} ({tp.msgtype}) for {key}: {gives}; name its field "
                    f"with --columns {key}={topic}.FIELD:UNIT (e.g. {key}={topic}.data:deg)"
                )
        tp.reads.append((key, fpath or None, None if fpath else known.keys[key]))  # type: ignore[union-attr]
    for msgtype, rt in ROS_TYPES.items():
        for key in rt.keys:
            if key in mapped:
                continue
            cands = [t for t in topics.values() if t.msgtype == msgtype and t.count]
            if not cands:
                continue
            best = max(cands, key=lambda t: t.count)
            mapped[key] = ChannelSpec(key, best.name, 1.0, None)
            best.reads.append((key, None, rt.keys[key]))
            others = [t.name for t in cands if t is not best]
            if others:
                notes.append(f"{key} from {best.name}; also in {', '.join(others)} (not read)")
    return topics, mapped, notes


def _read(reader, name: str, columns, time_offset, strict: bool) -> NmeaLog:
    topics, mapped, notes = _plan(reader, name, columns)
    nmea = [t for t in topics.values() if t.msgtype == NMEA_TYPE and t.count]
    if nmea and "heading" not in mapped:  # the sentences carry HDT, RMC, VTG …
        return _read_nmea_topics(reader, name, topics, nmea, strict)
    reading = {t.name: t for t in topics.values() if t.reads}
    if not reading:  # (no connections: rosbags would yield every message)
        raise InputError(
            f"{name}: no topic of a GNSS type known here ({_KNOWN_SHORT}); map a topic with "
            "--columns heading=/TOPIC.FIELD:deg,… "
            "(docs/ingest.md); the bag has "
            + ", ".join(
                f"{t.name} ({t.msgtype})"
                for t in sorted(topics.values(), key=lambda t: t.name)[:15]
            )
        )
    conns = [c for c in reader.connections if c.topic in reading]
    for conn, logtime, raw in reader.messages(connections=conns):
        tp = reading[conn.topic]
        tp.raws.append(bytes(raw))
        tp.logtimes.append(logtime)
        tp.msgtype_full = conn.msgtype
    found = {}
    for tp in reading.values():
        cols = _Columns(reader, tp, name, strict)
        n = len(tp.raws)
        known = ROS_TYPES.get(tp.msgtype)
        # (no message decoded: no values, each message counted as malformed with the reason)
        decoded = cols.msg0 is not None
        given = known.values(cols.view()) if known is not None and n and decoded else {}  # type: ignore[operator]
        vals = {}
        for key, fpath, _ in tp.reads:
            if fpath:
                vals[key] = _field_column(cols, fpath, name, tp, key)
            else:
                vals[key] = np.asarray(given.get(key, np.full(n, np.nan)), float)
        for key, fpath, _ in list(tp.reads):
            if n and fpath is None and not np.isfinite(vals[key]).any() and len(vals) > 1:
                # a key the type gives only when flagged valid, and never is (NavPVT's vehicle
                # heading from a single antenna): not a channel of NaN that would empty the
                # epochs (they are the heading's)
                why = "never flagged valid" if decoded else "no message decoded"
                notes.append(f"{key}: {tp.name} gives none ({why}); not used")
                del vals[key]
                tp.reads.remove((key, fpath, _))
        tt = cols.stamps()
        good = cols.keep & np.any([np.isfinite(v) for v in vals.values()], axis=0)
        tp.used = int(good.sum())
        tp.invalid = int((cols.keep & ~good).sum())
        tp.raws, tp.logtimes = [], []
        for key, _, unit in tp.reads:
            # no unit (a field --columns names): the unit after its colon, or an error asking
            found[key] = Channel(mapped[key].channel, tt[good], vals[key][good], unit or "")
    # the epochs on the heading's (else the speed's, the course's, the position's) time base, a
    # 100 Hz IMU's yaw rate interpolated onto them, not the position onto the IMU's
    order = list(CHANNEL_KEYS)
    found = dict(sorted(found.items(), key=lambda kv: order.index(kv[0])))
    # strict is not passed on: a key a used message lacks (a NavPVT without a valid vehicle
    # heading) is no malformed message; those that did not decode were judged above
    log = log_from_channels(mapped, found, name=name, fmt=_fmt(reader), start_s=0.0,
                            time_offset=time_offset, notes=notes,
                            unit="messages")  # fmt: skip
    _account(log, topics)
    return log


def _fmt(reader) -> str:
    return "ROS 1 bag" if getattr(reader, "is2", False) is False else "ROS 2 bag"


def _account(log: NmeaLog, topics: dict[str, _Topic]) -> None:
    """Every message of the bag in the report: used per topic, ignored, rejected."""
    r = log.report
    parsed, ignored = {}, {}
    rejected = dict.fromkeys(REASONS, 0)
    firsts = []
    for tp in topics.values():
        if not tp.reads:
            if tp.count:
                ignored[f"{tp.name} ({tp.msgtype}, not mapped)"] = tp.count
            continue
        keys = ", ".join(k for k, _, _ in tp.reads)
        parsed[f"{tp.name} ({keys})"] = tp.used
        if tp.invalid:
            ignored[f"{tp.name} (no valid value: no fix or flagged invalid)"] = tp.invalid
        if tp.bad:
            rejected[MALFORMED] += tp.bad
            from gripsense.io.logs.nmea.accounting import RejectedLine

            firsts.append(RejectedLine(0, MALFORMED, tp.first_bad))
    r.parsed = dict(sorted(parsed.items()))
    r.ignored = dict(sorted(ignored.items()))
    r.rejected = rejected
    r.first_rejects = firsts[:20]
    r.total_lines = sum(parsed.values()) + sum(ignored.values()) + sum(rejected.values())


def _read_nmea_topics(reader, name: str, topics, nmea: list[_Topic], strict: bool) -> NmeaLog:
    """The bag's ``nmea_msgs/Sentence`` messages through the NMEA reader, in record order."""
    from gripsense.io.logs.nmea.reader import read_nmea

    keep = {t.name for t in nmea}
    conns = [c for c in reader.connections if c.topic in keep]
    lines = []
    bad = 0
    for conn, _, raw in reader.messages(connections=conns):
        try:
            lines.append(str(reader.deserialize(raw, conn.msgtype).sentence))
        except Exception as e:
            if strict:
                raise InputError(f"{name}: {MALFORMED}: a {NMEA_TYPE} message ({e})") from None
            bad += 1
    log = read_nmea(lines, strict=strict)
    r = log.report
    r.source = name
    r.format = f"{_fmt(reader)} ({NMEA_TYPE})"
    r.unit = "messages"
    for tp in topics.values():
        if tp.name not in keep and tp.count:
            r.ignored[f"{tp.name} ({tp.msgtype}, not mapped)"] = tp.count
            r.total_lines += tp.count
    if bad:
        r.rejected[MALFORMED] = r.rejected.get(MALFORMED, 0) + bad
        r.total_lines += bad
    r.notes.append(f"NMEA sentences of {', '.join(sorted(keep))}")
    return log


def write_rosbag2(epochs, path: str | Path) -> None:
    """Write an epoch table as a ROS 2 bag (MCAP storage) with rosbags' writer.

    Topics: ``/gps/fix`` (``sensor_msgs/NavSatFix``), ``/gps/vel``
    (``geometry_msgs/TwistStamped``, ENU), ``/imu/data`` (``sensor_msgs/Imu``: the yaw rate)
    and ``/gps/heading`` (``std_msgs/Float64``, degrees: :data:`ROSBAG2_COLUMNS`), each message
    recorded at its epoch's time, the stamped ones stamped with it.

    Parameters
    ----------
    epochs : pandas.DataFrame
        ``time_utc``, ``lat_deg``, ``lon_deg``, ``alt_m``, ``speed_mps``, ``course_deg``,
        ``heading_deg``, ``yaw_rate_rps`` (ISO).
    path : str or Path
        The bag folder to create (it must not exist: nothing is replaced).
    """
    require("rosbags", "writing ROS bags")
    import pandas as pd
    from rosbags.rosbag2 import StoragePlugin, Writer
    from rosbags.typesys import Stores, get_typestore

    ts = get_typestore(Stores.ROS2_HUMBLE)
    T = ts.types
    path = Path(path)
    if os.path.lexists(path):  # never replaced: the folder may hold what gripsense did not write
        raise InputError(f"{path}: exists; a ROS 2 bag is written into a new folder")
    ns = pd.DatetimeIndex(epochs["time_utc"]).as_unit("ns").asi8
    names = ("lat_deg", "lon_deg", "alt_m", "speed_mps", "course_deg", "heading_deg")
    col = {c: epochs[c].to_numpy(float) for c in (*names, "yaw_rate_rps")}
    course = np.deg2rad(col["course_deg"])
    ve, vn = col["speed_mps"] * np.sin(course), col["speed_mps"] * np.cos(course)
    Time, Header, Vec = T["builtin_interfaces/msg/Time"], T["std_msgs/msg/Header"], T[
        "geometry_msgs/msg/Vector3"]  # fmt: skip
    Status = T["sensor_msgs/msg/NavSatStatus"]
    Quat = T["geometry_msgs/msg/Quaternion"]
    z9 = np.zeros(9)
    with Writer(path, version=9, storage_plugin=StoragePlugin.MCAP) as w:
        c_fix = w.add_connection("/gps/fix", "sensor_msgs/msg/NavSatFix", typestore=ts)
        c_vel = w.add_connection("/gps/vel", "geometry_msgs/msg/TwistStamped", typestore=ts)
        c_imu = w.add_connection("/imu/data", "sensor_msgs/msg/Imu", typestore=ts)
        c_hdg = w.add_connection("/gps/heading", "std_msgs/msg/Float64", typestore=ts)
        for i, t in enumerate(ns):
            t = int(t)
            h = Header(Time(t // 1_000_000_000, t % 1_000_000_000), "gps")
            fix = T["sensor_msgs/msg/NavSatFix"](
                h, Status(0, 1), col["lat_deg"][i], col["lon_deg"][i], col["alt_m"][i], z9, 0
            )
            vel = T["geometry_msgs/msg/TwistStamped"](
                h, T["geometry_msgs/msg/Twist"](Vec(ve[i], vn[i], 0.0), Vec(0.0, 0.0, 0.0))
            )
            imu = T["sensor_msgs/msg/Imu"](
                h, Quat(0.0, 0.0, 0.0, 1.0), -np.ones(9), Vec(0.0, 0.0, col["yaw_rate_rps"][i]),
                z9, Vec(0.0, 0.0, 0.0), z9,
            )  # fmt: skip
            hdg = T["std_msgs/msg/Float64"](float(np.mod(col["heading_deg"][i], 360.0)))
            w.write(c_fix, t, ts.serialize_cdr(fix, "sensor_msgs/msg/NavSatFix"))
            w.write(c_vel, t, ts.serialize_cdr(vel, "geometry_msgs/msg/TwistStamped"))
            w.write(c_imu, t, ts.serialize_cdr(imu, "sensor_msgs/msg/Imu"))
            w.write(c_hdg, t, ts.serialize_cdr(hdg, "std_msgs/msg/Float64"))


def read_rosbag_log(src: LogInput) -> NmeaLog:
    """Read a ROS bag as :func:`gripsense.io.logs.read_log` hands it over (its registry entry):
    by path when it is a plain file or a bag folder, else from its bytes (:func:`read_rosbag`).

    Parameters
    ----------
    src : gripsense.io.logs.options.LogInput
        The bag and its options (``columns``, ``time_offset``, ``strict``).

    Returns
    -------
    NmeaLog
        Epoch table and message accounting.
    """
    o = src.options
    return read_rosbag(src.path, None if src.read is None else src.data, columns=o.columns,
                       time_offset=o.time_offset, strict=o.strict)  # fmt: skip


def write_rosbag2_log(
    epochs: pd.DataFrame,
    path: Path,
    *,
    nmea_lines: list[str] | None = None,
    steer: pd.DataFrame | None = None,
) -> str | None:
    """Write a drive as a ROS 2 bag folder for :func:`gripsense.io.logs.write_log`
    (:func:`write_rosbag2`).

    Parameters
    ----------
    epochs : pandas.DataFrame
        The drive's epoch table.
    path : Path
        Output folder.
    nmea_lines : list of str, optional
        Unused.
    steer : pandas.DataFrame, optional
        Unused.

    Returns
    -------
    str
        The ``--columns`` that read the bag back (:data:`ROSBAG2_COLUMNS`).
    """
    write_rosbag2(epochs, path)
    return ROSBAG2_COLUMNS
