"""CAN logs (Vector BLF and ASC) decoded with a DBC: python-can reads the frames, cantools
decodes the signals.

Only the frames of the DBC messages that carry a mapped signal are decoded; every frame is
accounted for: ``parsed`` per message, ``ignored`` (an identifier the DBC does not know, or a
message without a mapped signal) or rejected as ``malformed field`` (the DBC does not decode
it: a wrong length or a value outside its choices). Signal units come from the DBC
(overridable in ``--columns``). A steering signal whose name and unit say what it is
(``SteeringWheelAngle`` [deg], :func:`gripsense.io.logs.channels.recognise_steering`) is decoded too
when ``--columns`` maps none. Times are the log's: BLF stores absolute times; an ASC file's
``date`` line gives its start; else ``--time-offset`` (seconds since 1970 UTC of the log's
zero) makes them absolute. The signals are put on the heading signal's time base
(:func:`gripsense.io.logs.channels.resample`).
"""

from __future__ import annotations

import io
import logging
import re
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from gripsense.errors import InputError
from gripsense.io.logs.channels import Channel, ChannelSpec, add_steering, parse_channel_spec
from gripsense.io.logs.formats import require
from gripsense.io.logs.measurement import log_from_channels, missing_channel
from gripsense.io.logs.nmea.accounting import RejectedLine
from gripsense.io.logs.nmea.reader import NmeaLog
from gripsense.io.logs.nmea.schema import MALFORMED, TRUNCATED
from gripsense.io.logs.options import LogInput

__all__ = [
    "CAN_SIGNALS",
    "FrameColumns",
    "SignalPlan",
    "can_example_columns",
    "decode_frames",
    "is_asc",
    "is_blf",
    "load_dbc",
    "plan_signals",
    "read_asc_log",
    "read_blf_log",
    "read_can",
    "write_can",
]

_ABSOLUTE_AFTER = 1e8  # timestamps above this are seconds since 1970 (1973 onwards)


def load_dbc(path: str | Path):
    """A DBC database, with one clear error when it cannot be read.

    cantools' log lines while loading (``Overwriting message …`` for a message defined twice)
    are kept off stderr: :func:`read_can` resolves such copies itself and says so.

    Parameters
    ----------
    path : str or Path
        The ``.dbc`` file.

    Returns
    -------
    cantools.database.can.Database
    """
    cantools = require("cantools", "decoding CAN logs")
    logger = logging.getLogger("cantools")
    level = logger.level
    logger.setLevel(logging.CRITICAL)
    try:
        return cantools.database.load_file(str(path), database_format="dbc", strict=False)
    except FileNotFoundError:
        raise InputError(f"{path}: no such DBC file") from None
    except Exception as e:
        raise InputError(f"{path}: not a readable DBC file ({type(e).__name__}: {e})") from None
    finally:
        logger.setLevel(level)


NOT_BLF = "not a BLF object"
"""Reject reason of bytes of a BLF log that are not a log object (the walk resynchronises at
the next ``LOBJ`` signature)."""
NOT_ASC = "not ASC"
"""Reject reason of an ASC line that is neither a frame, an event, a header nor a comment."""


@dataclass
class FrameColumns:
    """A log's CAN frames as arrays, in frame order.

    Parameters
    ----------
    pos : numpy.ndarray
        Each frame's position for messages (line or frame number) [-].
    ids : numpy.ndarray
        Identifiers (11 or 29 bits) [-].
    t : numpy.ndarray
        Times [s].
    data : numpy.ndarray
        Payload bytes, one row per frame, zero-padded to the longest [-].
    lens : numpy.ndarray
        Payload lengths [bytes].
    special : numpy.ndarray
        Error and remote frames (ignored) [-].
    """

    pos: np.ndarray
    ids: np.ndarray
    t: np.ndarray
    data: np.ndarray
    lens: np.ndarray
    special: np.ndarray

    @classmethod
    def of(cls, frames: list) -> FrameColumns:
        """The columns of ``(position, frame)`` pairs (python-can messages)."""
        n = len(frames)
        pay = [bytes(fr.data) for _, fr in frames]
        lens = np.fromiter((len(b) for b in pay), np.int64, n)
        w = int(lens.max()) if n else 0
        data = np.frombuffer(b"".join(b.ljust(w, b"\0") for b in pay), np.uint8)
        special = np.fromiter(
            (bool(getattr(fr, "is_error_frame", False) or getattr(fr, "is_remote_frame", False))
             for _, fr in frames), bool, n,
        )  # fmt: skip
        return cls(
            pos=np.fromiter((k for k, _ in frames), np.int64, n),
            ids=np.fromiter((fr.arbitration_id for _, fr in frames), np.int64, n),
            t=np.fromiter((fr.timestamp for _, fr in frames), float, n),
            data=data.reshape(n, w),
            lens=lens,
            special=special,
        )


@dataclass
class CanFrames:
    """The frames of a CAN log and what else its bytes or lines were."""

    frames: list  # (position, can.Message): line number (ASC) or frame number (BLF)
    ignored: dict[str, int] = field(default_factory=dict)
    rejected: dict[str, int] = field(default_factory=dict)
    firsts: list[RejectedLine] = field(default_factory=list)
    notes: list[str] = field(default_factory=list)
    units: int = 0  # what the report counts beyond the frames (lines, rejected byte ranges)
    unit: str = "frames"
    columns: FrameColumns | None = None  # the frames as arrays (MDF4 bus logs), else *frames*

    def reject(self, where: int, reason: str, detail: str, name: str, strict: bool) -> None:
        if strict:
            raise InputError(f"{name}: {reason}: {detail} (strict mode)")
        self.rejected[reason] = self.rejected.get(reason, 0) + 1
        if len(self.firsts) < 20:
            self.firsts.append(RejectedLine(where, reason, detail))


def _blf_frames(name: str, data: bytes, strict: bool) -> CanFrames:
    """The frames of a BLF log, every byte range accounted for.

    The outer object structure is walked here: the file header (its size must fit the file),
    then ``LOBJ`` objects; bytes that are not an object are rejected (``not a BLF object``,
    with their offset) and the walk resynchronises at the next ``LOBJ``; an object cut off by
    the end of the file is rejected as ``truncated`` and said in the notes (as is a file
    shorter than its header's file size) — the frames it holds up to the cut are read; a
    container whose compressed data are damaged is rejected as ``malformed field``.
    python-can then reads the frames of the good objects.
    """
    import zlib

    can = require("can", "reading CAN logs")
    from can.io import blf

    out = CanFrames([])
    n = len(data)
    fh = blf.FILE_HEADER_STRUCT
    ob = blf.OBJ_HEADER_BASE_STRUCT
    if n < fh.size:
        raise InputError(
            f"{name}: not a readable BLF log: {n} bytes, shorter than a BLF file header "
            f"({fh.size} bytes); the file is cut off"
        )
    header = fh.unpack_from(data)
    hs, file_size = int(header[1]), int(header[10])
    if hs < fh.size or hs > max(n, fh.size) or hs > 1 << 16:
        raise InputError(
            f"{name}: not a readable BLF log: its header says it is {hs} bytes long "
            f"(a BLF header is {fh.size}–65536 bytes, within the file's {n}); the file is "
            "damaged after its 'LOGG' signature"
        )
    if file_size > n:
        out.notes.append(
            f"the BLF log is cut off: its header says {file_size} bytes, the file has {n} "
            "(a recording that stopped?): read up to the cut"
        )
    good = [data[:hs]]
    pos = hs
    while pos < n:
        ok = data[pos : pos + 4] == b"LOBJ" and pos + ob.size <= n
        size = ob.unpack_from(data, pos)[3] if ok else 0
        if ok and size < ob.size:
            ok = False
        if not ok:
            if data[pos:].strip(b"\x00") == b"":
                out.ignored["(padding)"] = out.ignored.get("(padding)", 0) + 1
                out.units += 1
                break
            j = data.find(b"LOBJ", pos + 1)
            end = n if j < 0 else j
            out.units += 1
            out.reject(pos + 1, NOT_BLF, f"bytes {pos}–{end - 1}: not a BLF object "
                       "(no 'LOBJ' signature or an impossible size)", name, strict)  # fmt: skip
            pos = end
            continue
        if pos + size > n:
            out.units += 1
            out.reject(pos + 1, TRUNCATED, f"byte {pos}: a {size}-byte BLF object, the file "
                       f"ends after {n - pos} of them", name, strict)  # fmt: skip
            if not out.notes:
                out.notes.append(
                    f"the BLF log is cut off inside an object at byte {pos} (a recording that "
                    "stopped?): read up to the cut"
                )
            good.append(data[pos:])  # python-can reads the frames it holds up to the cut
            break
        obj = data[pos : pos + size]
        if ob.unpack_from(obj)[4] == blf.LOG_CONTAINER:
            method = blf.LOG_CONTAINER_STRUCT.unpack_from(obj, ob.size)[0]
            if method == blf.ZLIB_DEFLATE:
                try:
                    zlib.decompressobj().decompress(obj[ob.size + blf.LOG_CONTAINER_STRUCT.size :])
                except zlib.error as e:
                    out.units += 1
                    out.reject(pos + 1, MALFORMED, f"byte {pos}: a BLF container whose "
                               f"compressed data are damaged ({e})", name, strict)  # fmt: skip
                    pos += size + size % 4
                    continue
        good.append(obj + data[pos + size : pos + size + size % 4])
        pos += size + size % 4
    try:
        for fr in can.BLFReader(io.BytesIO(b"".join(good))):
            out.frames.append((len(out.frames) + 1, fr))
    except Exception as e:
        out.units += 1
        out.reject(len(out.frames) + 1, MALFORMED, f"the frames after frame {len(out.frames)} "
                   f"cannot be read ({type(e).__name__}: {e})", name, strict)  # fmt: skip
        out.notes.append(
            f"the BLF data are damaged after frame {len(out.frames)}: read up to there"
        )
    return out


_ASC_HEADER = re.compile(
    r"(date\s|base\s+(hex|dec)|(no\s+)?internal\s+events\s+logged|begin\s+triggerblock"
    r"|end\s+triggerblock|//)",
    re.IGNORECASE,
)
_ASC_EVENT = re.compile(r"\d+\.\d+\s+\S")


class _Lines:
    """The lines of an ASC log handed to python-can one at a time, remembering which."""

    def __init__(self, head: list[str], lines: list[str], start: int) -> None:
        self.head, self.lines, self.start = head, lines, start
        self.at = -1

    def close(self) -> None:
        """Nothing to close (python-can calls it when done)."""

    def __iter__(self):
        yield from self.head
        for i in range(self.start, len(self.lines)):
            self.at = i
            yield self.lines[i]


def _asc_frames(name: str, data: bytes, strict: bool) -> CanFrames:
    """The frames of an ASC log, every line accounted for: a frame, an event or header line
    (ignored), or rejected — a line python-can cannot read (``malformed field``), a last line
    without its end (``truncated``: the log was cut off inside it, said in the notes) or a
    line that is none of these (``not ASC``).
    """
    can = require("can", "reading CAN logs")
    text = data.decode("utf-8", errors="replace")
    lines = text.splitlines()
    out = CanFrames([], unit="lines")
    head = [ln for ln in lines[:8] if re.match(r"\s*(date\s|base\s)", ln, re.IGNORECASE)]
    head.append("internal events logged")
    used: set[int] = set()
    bad: set[int] = set()
    n_read = len(lines)
    if lines and lines[-1].strip() and not text.endswith(("\n", "\r")):
        # the last line has no end: the log was cut inside it, and what is left of it (a data
        # byte cut to one digit) would be read as a frame with other values
        n_read -= 1
        bad.add(n_read)
        out.notes.append(f"the ASC log ends inside line {n_read + 1} (cut off?): not read")
        out.reject(n_read + 1, TRUNCATED, f"line {n_read + 1}: the log ends inside it "
                   f"({lines[-1].strip()[:40]!r})", name, strict)  # fmt: skip
    start = 0
    while start < n_read:
        trig = [ln for ln in lines[:start] if re.match(r"\s*begin\s+triggerblock", ln, re.I)]
        src = _Lines(head + trig[-1:], lines[:n_read], start)
        try:
            for fr in can.ASCReader(src, relative_timestamp=False):
                out.frames.append((src.at + 1, fr))
                used.add(src.at)
            break
        except Exception as e:
            i = max(src.at, start)
            bad.add(i)
            out.reject(i + 1, MALFORMED, f"line {i + 1}: not a readable frame "
                       f"({type(e).__name__}: {e})", name, strict)  # fmt: skip
            start = i + 1
    for i, ln in enumerate(lines):
        if i in used or i in bad:
            continue
        s = ln.strip()
        if not s:
            key = "(blank)"
        elif _ASC_HEADER.match(s):
            key = "(ASC header or comment)"
        elif _ASC_EVENT.match(s):
            key = "(ASC event, not a CAN frame)"
        else:
            out.reject(i + 1, NOT_ASC, f"line {i + 1}: neither a frame, an event nor a header "
                       f"({s[:40]!r})", name, strict)  # fmt: skip
            continue
        out.ignored[key] = out.ignored.get(key, 0) + 1
    out.units = len(lines) - len(out.frames)
    out.firsts.sort(key=lambda r: r.line)
    return out


def _frames(path: Path, data: bytes, fmt: str, strict: bool = False) -> CanFrames:
    name = str(path)
    try:
        return (_blf_frames if fmt == "blf" else _asc_frames)(name, data, strict)
    except InputError:
        raise
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
        ``heading=SIGNAL,…`` (:mod:`gripsense.io.logs.channels`); ``heading=MESSAGE.SIGNAL`` or
        ``heading=0x15.SIGNAL`` names one message of a DBC that defines a signal in several.
    time_offset : float, optional
        Seconds since 1970 UTC of the log's time zero [s] (for logs with relative times).
    strict : bool
        Raise at the first frame that does not decode.

    Returns
    -------
    NmeaLog
    """
    name = str(path)
    plan = plan_signals(name, dbc, columns)
    got = _frames(Path(path), data, fmt, strict)
    return decode_frames(name, got, plan, fmt_name=f"CAN {fmt.upper()}", start_s=None,
                         time_offset=time_offset, strict=strict)  # fmt: skip


@dataclass
class SignalPlan:
    """Which DBC messages may carry each mapped signal (:func:`plan_signals`).

    Parameters
    ----------
    dbc : str
        The DBC file, for messages.
    db : cantools.database.can.Database
        The database.
    mapped : dict
        Key -> :class:`~gripsense.io.logs.channels.ChannelSpec`, the channel being the signal name.
    copies : dict
        Key -> the messages (cantools ``Message``) that define the signal: one when the DBC
        defines it once or ``--columns`` named the message; several when the DBC defines the
        same message under several identifiers (the frames the log holds decide).
    steering : dict
        The steering channel read (:func:`gripsense.io.logs.channels.add_steering`).
    notes : list of str
        What the ingest report says about the mapping.
    """

    dbc: str
    db: Any
    mapped: dict[str, ChannelSpec]
    copies: dict[str, list]
    steering: dict[str, str]
    notes: list[str]


def _ident(m) -> str:
    return f"{m.name} (id 0x{m.frame_id:X})"


def plan_signals(name: str, dbc: str | Path, columns: str | dict | None) -> SignalPlan:
    """The DBC messages of the signals ``--columns`` maps, or one error naming what is wrong.

    A signal is named by itself (``heading=Heading``), or with its message's name or identifier
    before a dot (``heading=gnss_attitude.Heading``, ``heading=0x15.Heading``) when the DBC
    defines it in several messages.

    Parameters
    ----------
    name : str
        The log, for messages.
    dbc : str or Path
        The DBC file.
    columns : str or dict
        ``--columns``.

    Returns
    -------
    SignalPlan
    """
    mapped = parse_channel_spec(columns)
    if not mapped:
        raise InputError(f"{name}: give the signals with --columns (heading=…,course=…,speed=…)")
    db = load_dbc(dbc)
    where: dict[str, list] = {}  # signal -> the messages that define it, in the DBC's order
    for m in db.messages:
        for sg in m.signals:
            where.setdefault(sg.name, []).append(m)
    copies: dict[str, list] = {}
    out: dict[str, ChannelSpec] = {}
    for key, spec in mapped.items():
        sig, msgs = spec.channel, where.get(spec.channel)
        if msgs is None and "." in spec.channel:
            head, sig = spec.channel.rsplit(".", 1)
            msgs = [m for m in where.get(sig, []) if _names_message(head, m)]
            if sig in where and not msgs:
                raise InputError(
                    f"{name} (DBC {dbc}): --columns {key}={spec.channel}: no message {head!r} "
                    f"carries signal {sig!r}; it is in "
                    f"{', '.join(_ident(m) for m in where[sig])}"
                )
        if not msgs:
            raise missing_channel(f"{name} (DBC {dbc})", spec, list(where))
        copies[key] = msgs
        out[key] = ChannelSpec(spec.key, sig, spec.sign, spec.factor)

    def unit_of(sig: str) -> str | None:
        return where[sig][0].get_signal_by_name(sig).unit

    steering, notes = add_steering(out, list(where), unit_of)
    for key, spec in out.items():
        copies.setdefault(key, where[spec.channel])
    return SignalPlan(str(dbc), db, out, copies, steering, notes)


def _names_message(head: str, m) -> bool:
    """Whether *head* (of ``MESSAGE.SIGNAL``) is message *m*'s name or identifier."""
    if head == m.name:
        return True
    try:
        return int(head, 0) == m.frame_id
    except ValueError:
        return False


def _pgn(frame_id: int) -> int:
    """The J1939 parameter group number of a 29-bit identifier: priority and source address
    dropped, and the destination address of a PDU1 group (PF < 240) (SAE J1939-21; as
    asammdf's bus-logging decoder matches J1939 messages).
    """
    pgn = (frame_id >> 8) & 0x3FF00
    return pgn + ((frame_id >> 8) & 0xFF) if (frame_id >> 16) & 0xFF >= 240 else pgn


def _key(m) -> tuple[str, int]:
    """What a DBC message matches frames by: its identifier, or its PGN (J1939 DBC)."""
    if getattr(m, "protocol", None) == "j1939" and m.is_extended_frame:
        return ("pgn", _pgn(m.frame_id))
    return ("id", m.frame_id)


def _frame_keys(fid: int, pgns: bool) -> tuple[tuple[str, int], ...]:
    return (("id", fid), ("pgn", _pgn(fid))) if pgns and fid > 0x7FF else (("id", fid),)


def _choose_copies(
    name: str, plan: SignalPlan, counts: dict[tuple[str, int], int]
) -> dict[str, Any]:
    """Key -> the one message whose frames the log holds, for a signal the DBC defines in
    several messages; one error naming the identifiers when the log holds frames of more than
    one.
    """
    chosen = {}
    for key, msgs in plan.copies.items():
        held = [m for m in msgs if counts.get(_key(m), 0)]
        if len(held) > 1:
            spec = plan.mapped[key]
            same = len({m.name for m in held}) < len(held)
            ids = " and ".join(f"{_ident(m)}: {counts[_key(m)]} frames" for m in held)
            pick = (f"0x{held[0].frame_id:X}" if same else held[0].name) + f".{spec.channel}"
            raise InputError(
                f"{name}: signal {spec.channel!r} ({key}) is in {len(held)} messages of the DBC "
                f"{plan.dbc} that the log holds ({ids}); name one with --columns "
                f"{key}={pick}"
            )
        chosen[key] = (held or msgs)[0]
        if not held:
            plan.notes.append(
                f"signal {plan.mapped[key].channel!r} ({key}): the log holds no frame of "
                f"{' or '.join(_ident(m) for m in msgs)}: no values"
            )
        if len(msgs) > 1 and held:
            others = ", ".join(f"0x{m.frame_id:X}" for m in msgs if m is not held[0])
            plan.notes.append(
                f"signal {plan.mapped[key].channel!r} ({key}): the DBC defines it under "
                f"{len(msgs)} identifiers; read from {_ident(held[0])}, the one the log holds "
                f"(not {others})"
            )
    return chosen


def _decode_rows(msg, c: FrameColumns, rows: np.ndarray, sigs: list[str]):
    """The signals *sigs* of message *msg* in the frames at *rows*.

    A frame of the message's length (≤ 8 bytes) of a message without multiplexing is decoded
    in one vectorised pass (:func:`_vector_signal`, the same bits, sign, float and linear
    scaling as cantools); any other frame by cantools frame by frame.

    Returns
    -------
    ok_rows : numpy.ndarray
        The rows that decoded, in frame order.
    values : dict
        Signal -> (its value per ok row, whether the row's frame carries it: a multiplexed
        signal is not in every frame).
    failed : list of (int, str)
        Row and cantools' error of each frame that does not decode.
    """
    size = int(msg.length)
    vector = size <= 8 and not msg.is_multiplexed() and all(
        _vectorisable(msg.get_signal_by_name(s)) for s in sigs
    )  # fmt: skip
    lens = c.lens[rows]
    fast = (lens == size) if vector else np.zeros(rows.size, bool)
    values: dict[str, tuple[np.ndarray, np.ndarray]] = {}
    failed: list[tuple[int, str]] = []
    slow_vals: dict[str, list[float]] = {s: [] for s in sigs}
    slow_has: dict[str, list[bool]] = {s: [] for s in sigs}
    slow_rows: list[int] = []
    for j in np.flatnonzero(~fast).tolist():
        try:
            r = int(rows[j])
            dec = msg.decode(bytes(c.data[r, : c.lens[r]]), decode_choices=False)
        except Exception as e:
            failed.append((int(rows[j]), str(e)))
            continue
        slow_rows.append(j)
        for s in sigs:
            slow_vals[s].append(float(dec[s]) if s in dec else np.nan)
            slow_has[s].append(s in dec)
    fast_idx = np.flatnonzero(fast)
    if fast_idx.size:
        buf = np.zeros((fast_idx.size, 8), np.uint8)
        buf[:, :size] = c.data[rows[fast_idx], :size]
        le = buf.view("<u8").ravel()
        be = buf.view(">u8").ravel().astype(np.uint64)
        fast_vals = {s: _vector_signal(msg.get_signal_by_name(s), le, be) for s in sigs}
    order = np.concatenate([fast_idx, np.asarray(slow_rows, np.int64)])
    srt = np.argsort(order, kind="stable")
    ok_idx = order[srt]
    for s in sigs:
        v = np.concatenate([fast_vals[s] if fast_idx.size else np.zeros(0),
                            np.asarray(slow_vals[s], float)])  # fmt: skip
        has = np.concatenate([np.ones(fast_idx.size, bool), np.asarray(slow_has[s], bool)])
        values[s] = (v[srt], has[srt])
    return rows[ok_idx], values, failed


def _vectorisable(sig) -> bool:
    """Whether a cantools signal is decoded by :func:`_vector_signal` exactly as cantools
    decodes it: a plain integer or IEEE float of at most 64 bits with a linear scaling.
    """
    conv = getattr(sig, "conversion", None)
    linear = conv is None or type(conv).__name__ in ("IdentityConversion", "LinearConversion",
                                                      "LinearIntegerConversion")  # fmt: skip
    if not linear or sig.length < 1 or sig.length > 64 or sig.multiplexer_ids:
        return False
    return not sig.is_float or sig.length in (32, 64)


def _vector_raw(sig, le: np.ndarray, be: np.ndarray) -> np.ndarray:
    """A signal's raw bits (unsigned, ``uint64``) from the frames' 8 data bytes read as one
    little-endian (*le*) and one big-endian (*be*) 64-bit word each: Intel signals from their
    least significant bit (``start``), Motorola signals from their most significant bit (DBC
    sawtooth numbering).
    """
    n = int(sig.length)
    mask = np.uint64((1 << n) - 1) if n < 64 else np.uint64(0xFFFFFFFFFFFFFFFF)
    if sig.byte_order == "little_endian":
        return (le >> np.uint64(sig.start)) & mask
    msb = 8 * (sig.start // 8) + (7 - sig.start % 8)  # bit from byte 0's MSB
    return (be >> np.uint64(64 - msb - n)) & mask


def _vector_signal(sig, le: np.ndarray, be: np.ndarray) -> np.ndarray:
    """A signal's physical values from its raw bits (:func:`_vector_raw`): two's complement
    when signed, IEEE float when float; then ``raw × scale + offset`` (cantools' linear
    conversion).
    """
    n = int(sig.length)
    raw = _vector_raw(sig, le, be)
    x: np.ndarray
    if sig.is_float:
        word = raw.astype(np.uint32).view(np.float32) if n == 32 else raw.view(np.float64)
        with np.errstate(invalid="ignore"):  # a NaN payload stays NaN (counted downstream)
            x = word.astype(float)
    elif sig.is_signed:
        i = raw.astype(np.int64)
        if n < 64:
            i = np.where(i >= (1 << (n - 1)), i - (1 << n), i)
        x = i.astype(float)
    else:
        x = raw.astype(float)
    return x * float(sig.scale) + float(sig.offset)


J1939_NOT_AVAILABLE, J1939_ERROR, J1939_RESERVED = 3, 2, 1
"""Codes of :func:`j1939_range`: the raw value is not a value of the parameter."""


def j1939_range(raw: np.ndarray, length: int) -> np.ndarray:
    """Which raw values of an unsigned J1939 parameter are not values (SAE J1939-71 §5.1.4,
    transmitted signal ranges; ``docs/ingest.md`` "J1939 'not available' values").

    A parameter of whole bytes is judged by its most significant byte: 0x00–0xFA valid,
    0xFB–0xFD parameter-specific indicators and reserved, 0xFE error indicator, 0xFF not
    available (1 byte: 0xFB–0xFD, 0xFE, 0xFF; 2 bytes: 0xFB00–0xFDFF, 0xFE00–0xFEFF,
    0xFF00–0xFFFF; 4 bytes likewise). A discrete parameter of 2–7 bits (J1939-71 discrete
    states: ``10`` error, ``11`` not available for 2 bits) and any other length of ≥ 2
    bits: all ones not available, all ones minus one error. A 1-bit signal has no such
    values.

    Parameters
    ----------
    raw : numpy.ndarray
        Raw (unscaled, unsigned) values [-].
    length : int
        The signal's length [bit].

    Returns
    -------
    numpy.ndarray
        ``int8`` per value: 0 a value, :data:`J1939_RESERVED`, :data:`J1939_ERROR` or
        :data:`J1939_NOT_AVAILABLE`.
    """
    r = np.asarray(raw, np.uint64)
    out = np.zeros(r.shape, np.int8)
    n = int(length)
    if n < 2 or n > 64:
        return out
    if n % 8 == 0:
        top = r >> np.uint64(n - 8)
        out[(top >= 0xFB) & (top <= 0xFD)] = J1939_RESERVED
        out[top == 0xFE] = J1939_ERROR
        out[top == 0xFF] = J1939_NOT_AVAILABLE
    else:
        ones = np.uint64((1 << n) - 1)
        out[r == ones - np.uint64(1)] = J1939_ERROR
        out[r == ones] = J1939_NOT_AVAILABLE
    return out


def _j1939_raw(msg, sig, c: FrameColumns, rows: np.ndarray) -> np.ndarray:
    """The raw bits of an unsigned integer signal in the (decoded) frames at *rows*:
    vectorised (:func:`_vector_raw`) when the signal lies in the first 8 bytes, else by
    cantools (``scaling=False``) frame by frame.
    """
    end = _last_bit(sig)
    if end <= 64 and not sig.multiplexer_ids and c.data.shape[1] > 0:
        buf = np.zeros((rows.size, 8), np.uint8)
        w = min(8, c.data.shape[1])
        buf[:, :w] = c.data[rows, :w]
        return _vector_raw(sig, buf.view("<u8").ravel(), buf.view(">u8").ravel().astype(np.uint64))
    out = np.zeros(rows.size, np.uint64)
    for j, r in enumerate(rows.tolist()):
        dec = msg.decode(bytes(c.data[r, : c.lens[r]]), decode_choices=False, scaling=False)
        out[j] = int(dec.get(sig.name, 0))
    return out


def _last_bit(sig) -> int:
    """One past the last bit (from byte 0's least significant bit, byte-wise) a signal uses."""
    n = int(sig.length)
    if sig.byte_order == "little_endian":
        return int(sig.start) + n
    msb = 8 * (sig.start // 8) + (7 - sig.start % 8)
    return msb + n  # in big-endian numbering: bytes covered up to (msb + n) // 8


def _is_j1939_parameter(msg, sig) -> bool:
    """Whether a signal is judged by :func:`j1939_range`: an unsigned integer signal of a
    J1939 message (``ProtocolType "J1939"``, 29-bit identifier: matched by PGN).
    """
    return _key(msg)[0] == "pgn" and not sig.is_float and not sig.is_signed and sig.length >= 2


def decode_frames(
    name: str,
    got: CanFrames,
    plan: SignalPlan,
    *,
    fmt_name: str,
    start_s: float | None,
    time_offset: float | None = None,
    strict: bool = False,
) -> NmeaLog:
    """The mapped signals of a log's CAN frames decoded with the DBC into the epoch table.

    Parameters
    ----------
    name : str
        The log, for messages.
    got : CanFrames
        Its frames (``(position, frame)``: ``arbitration_id``, ``data``, ``timestamp`` [s])
        and accounting.
    plan : SignalPlan
        Of :func:`plan_signals`.
    fmt_name : str
        Format for the report.
    start_s : float or None
        Seconds since 1970 UTC of the frames' time zero (an MDF4 file's start) [s]; None: the
        frame times are absolute when they are over 1e8 s, else ``time_offset`` is their zero.
    time_offset : float, optional
        ``--time-offset`` [s].
    strict : bool
        Raise at the first frame that does not decode.

    Returns
    -------
    NmeaLog
    """
    mapped = plan.mapped
    pgns = any(_key(m)[0] == "pgn" for m in plan.db.messages)  # a J1939 DBC: match by PGN
    c = got.columns if got.columns is not None else FrameColumns.of(got.frames)
    u, k_ = np.unique(c.ids, return_counts=True)
    ids: dict[int, int] = dict(zip(u.tolist(), k_.tolist(), strict=True))
    counts: dict[tuple[str, int], int] = {}
    for fid, n in ids.items():
        for k in _frame_keys(fid, pgns):
            counts[k] = counts.get(k, 0) + n
    chosen = _choose_copies(name, plan, counts)
    ignored: dict[str, int] = dict(got.ignored)
    if c.special.any():
        ignored["(error/remote frame)"] = ignored.get("(error/remote frame)", 0) + int(
            c.special.sum()
        )
    rows_of, msgs = _rows_of_messages(c, _message_of(ids, plan, chosen, pgns), ignored)
    at = "line" if got.unit == "lines" else "frame"
    d = _decode_series(c, rows_of, msgs, mapped, chosen, at)
    if strict and d.bad:
        raise InputError(f"{name}: {MALFORMED}: {d.bad[0][1]} (strict mode)")
    n_bad = len(d.bad)
    firsts = [RejectedLine(k, MALFORMED, dt) for k, dt in d.bad[:20]]
    found, whole = _found_channels(mapped, chosen, d)
    na_notes = [
        f"{int(k[1:].sum())} frames with 'not available' values of {sig} (SAE J1939-71 raw "
        f"ranges: {int(k[J1939_NOT_AVAILABLE])} not available, {int(k[J1939_ERROR])} error "
        f"indicator, {int(k[J1939_RESERVED])} reserved): no value, not used"
        for sig, k in sorted(d.na.items())
    ]
    if start_s is None:
        t_all = np.concatenate([ch.t for ch in found.values()]) if found else np.zeros(0)
        absolute = bool(t_all.size and np.nanmin(t_all) > _ABSOLUTE_AFTER)
        start = 0.0 if absolute else None
        offset = None if absolute else time_offset
    else:
        absolute, start, offset = False, start_s, time_offset
    log = log_from_channels(
        mapped, found, name=name, fmt=fmt_name, start_s=start, time_offset=offset,
        strict=strict, ignored=ignored, rejected={MALFORMED: n_bad}, first_rejects=firsts,
        unit=got.unit, notes=got.notes + plan.notes + na_notes,
    )  # fmt: skip
    import pandas as pd

    for key, (ts, vs) in whole.items():  # the per-frame rows keep the non-values, as NaN
        log.sentences[key] = pd.DataFrame({"t_s": ts, "value": vs}, copy=False)
    log.report.steering = plan.steering
    # frames, not samples: the parsed count is per message
    rep = log.report
    rep.parsed = dict(sorted(d.parsed.items()))
    for reason, v in got.rejected.items():
        rep.rejected[reason] = rep.rejected.get(reason, 0) + v
    rep.rejected[MALFORMED] = n_bad + got.rejected.get(MALFORMED, 0)
    rep.first_rejects = sorted(got.firsts + firsts, key=lambda r: r.line)[:20]
    rep.total_lines = len(c.ids) + got.units
    if absolute and time_offset is not None:
        rep.notes.append("the log's times are absolute: --time-offset not used")
    return log


def _message_of(ids: dict[int, int], plan: SignalPlan, chosen: dict, pgns: bool) -> dict[int, Any]:
    """Per frame identifier the message it carries: one the mapping chose, None (in the DBC,
    no mapped signal) or False (not in the DBC).
    """
    known = {_key(m) for m in plan.db.messages}
    wanted: dict[tuple[str, int], Any] = {_key(m): m for m in chosen.values()}
    match: dict[int, Any] = {}
    for fid in ids:
        keys = _frame_keys(fid, pgns)
        match[fid] = next((wanted[k] for k in keys if k in wanted), None)
        if match[fid] is None and not any(k in known for k in keys):
            match[fid] = False  # not in the DBC
    return match


def _rows_of_messages(
    c: FrameColumns, match: dict[int, Any], ignored: dict[str, int]
) -> tuple[dict[int, list[int]], dict[int, Any]]:
    """The rows (frame order) each mapped message decodes, and the messages by frame id; the
    frames of no mapped message are counted in *ignored*.
    """
    rows_of: dict[int, list[int]] = {}
    msgs: dict[int, Any] = {}
    keep = np.flatnonzero(~c.special)
    uniq, inverse = np.unique(c.ids[keep], return_inverse=True)
    by = keep[np.argsort(inverse, kind="stable")]  # the rows of each identifier, in order
    cut = np.cumsum(np.bincount(inverse, minlength=uniq.size))[:-1]
    groups = np.split(by, cut) if uniq.size else []
    for f, here in zip(uniq.tolist(), groups, strict=True):
        if not here.size:
            continue
        msg = match[f]
        if not msg:
            key = "(not in the DBC)" if msg is False else "(no mapped signal)"
            ignored[key] = ignored.get(key, 0) + int(here.size)
            continue
        msgs[msg.frame_id] = msg
        rows_of.setdefault(msg.frame_id, []).extend(here.tolist())
    return rows_of, msgs


@dataclass
class _Decoded:
    """The mapped signals decoded: per (message id, signal) times and values, the frames that
    did not decode ((position, detail)), frames per message, J1939 non-values per signal.
    """

    series: dict[tuple[int, str], tuple[np.ndarray, np.ndarray]]
    bad: list[tuple[int, str]]
    parsed: dict[str, int]
    na: dict[str, np.ndarray]


def _decode_series(
    c: FrameColumns,
    rows_of: dict[int, list[int]],
    msgs: dict[int, Any],
    mapped: dict,
    chosen: dict,
    at: str,
) -> _Decoded:
    """Each mapped message's frames decoded (J1939 not-available, error and reserved raw values
    made NaN and counted).
    """
    parsed: dict[str, int] = {}
    bad: list[tuple[int, str]] = []
    series: dict[tuple[int, str], tuple[np.ndarray, np.ndarray]] = {}
    na: dict[str, np.ndarray] = {}  # J1939 signal -> frames per j1939_range code
    for mid, rows_list in rows_of.items():
        msg = msgs[mid]
        rows = np.sort(np.asarray(rows_list, np.int64))
        sigs = [s.channel for k, s in mapped.items() if chosen[k].frame_id == mid]
        ok_rows, values, failed = _decode_rows(msg, c, rows, sigs)
        for i, e in failed:
            at_k = int(c.pos[i])
            bad.append((at_k, f"{at} {at_k} (id 0x{int(c.ids[i]):X}, t = {c.t[i]:.3f} s): "
                              f"{msg.name} does not decode ({e})"))  # fmt: skip
        if ok_rows.size:
            parsed[msg.name] = parsed.get(msg.name, 0) + int(ok_rows.size)
        t = c.t[ok_rows]
        for sig in sigs:
            v, has = values[sig]
            dsig = msg.get_signal_by_name(sig)
            if _is_j1939_parameter(msg, dsig) and has.any():
                code = np.zeros(ok_rows.size, np.int8)
                code[has] = j1939_range(_j1939_raw(msg, dsig, c, ok_rows[has]), dsig.length)
                if code.any():
                    v = np.where(code > 0, np.nan, v)
                    k_na = na.setdefault(sig, np.zeros(4, np.int64))
                    k_na += np.bincount(code, minlength=4)
            series[(mid, sig)] = (t[has], v[has])
    bad.sort(key=lambda b: b[0])
    return _Decoded(series, bad, parsed, na)


def _found_channels(
    mapped: dict, chosen: dict, d: _Decoded
) -> tuple[dict[str, Channel], dict[str, tuple[np.ndarray, np.ndarray]]]:
    """The mapped keys' channels (J1939 non-values left out) and, for the signals that had
    some, the whole series with them as NaN.
    """
    found = {}
    whole: dict[str, tuple[np.ndarray, np.ndarray]] = {}
    for key, spec in mapped.items():
        msg = chosen[key]
        ts, vs = d.series.get((msg.frame_id, spec.channel), (np.zeros(0), np.zeros(0)))
        unit = msg.get_signal_by_name(spec.channel).unit
        ts, vs = np.asarray(ts, float), np.asarray(vs, float)
        if spec.channel in d.na:  # J1939 non-values: not used, not malformed (in the notes)
            whole[key] = (ts, vs)
            keep_v = ~np.isnan(vs)  # an unsigned integer signal is NaN only here
            ts, vs = ts[keep_v], vs[keep_v]
        found[key] = Channel(spec.channel, ts, vs, str(unit or ""))
    return found, whole


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


def is_blf(head: bytes) -> bool:
    """Whether a file is a Vector BLF log from its first bytes (the ``LOGG`` signature).

    Parameters
    ----------
    head : bytes
        The file's first bytes (decompressed).

    Returns
    -------
    bool
    """
    return head.startswith(b"LOGG")


def is_asc(head: bytes) -> bool:
    """Whether a file is a Vector ASC log from its first bytes (its ``date`` or ``base hex``
    header line).

    Parameters
    ----------
    head : bytes
        The file's first bytes (decompressed).

    Returns
    -------
    bool
    """
    start = head[:4096].lstrip().lower()
    return start.startswith(b"date ") or b"\nbase hex" in start[:2048] or start.startswith(b"base ")


def can_example_columns() -> str:
    """The ``--columns`` that read gripsense's own CAN logs, as an example a user can try.

    Returns
    -------
    str
        ``--columns heading=…,course=…,speed=… (…)``.
    """
    cols = ",".join(f"{k}={CAN_SIGNALS[k]}" for k in ("heading", "course", "speed"))
    return f"--columns {cols} (the signals of gripsense's example DBC)"


def _read_can_log(src: LogInput, fmt: str) -> NmeaLog:
    o = src.options
    assert o.dbc is not None  # read_log refuses a CAN log without its DBC
    return read_can(src.path, src.data, fmt, dbc=o.dbc, columns=o.columns,
                    time_offset=o.time_offset, strict=o.strict)  # fmt: skip


def read_blf_log(src: LogInput) -> NmeaLog:
    """Read a BLF log as :func:`gripsense.io.logs.read_log` hands it over (its registry entry;
    :func:`read_can`).

    Parameters
    ----------
    src : gripsense.io.logs.options.LogInput
        The log's bytes, name and options (``dbc``, ``columns``, ``time_offset``, ``strict``).

    Returns
    -------
    NmeaLog
        Epoch table and frame accounting.
    """
    return _read_can_log(src, "blf")


def read_asc_log(src: LogInput) -> NmeaLog:
    """Read an ASC log as :func:`gripsense.io.logs.read_log` hands it over (its registry entry;
    :func:`read_can`).

    Parameters
    ----------
    src : gripsense.io.logs.options.LogInput
        The log's bytes, name and options (``dbc``, ``columns``, ``time_offset``, ``strict``).

    Returns
    -------
    NmeaLog
        Epoch table and frame accounting.
    """
    return _read_can_log(src, "asc")
