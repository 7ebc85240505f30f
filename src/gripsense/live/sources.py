"""Byte sources for live mode: file replay at real-time pace, TCP client, serial port.

Every source has ``read(timeout) -> bytes`` (possibly empty), ``eof`` (no more data will ever
come), ``status`` (a short text for the display), ``reconnects`` and ``close()``. Network and
serial sources reconnect with exponential backoff (0.1 s doubling to 5 s) when the peer closes
or the device disappears; the time without data is visible to the estimator as a gap in the
epoch times and is reported.
"""

from __future__ import annotations

import re
import socket
import time
from pathlib import Path

from gripsense.errors import InputError
from gripsense.io.logs.nmea.reader import read_log_bytes

__all__ = [
    "EpochReplay",
    "ReplaySource",
    "SerialSource",
    "TcpSource",
    "open_replay",
    "parse_host_port",
]

# the time of day of GGA, RMC, ZDA, GNS (field 1) and GLL (field 5) lines
_TIME = re.compile(
    rb"^\s*\$..(?:(?:GGA|RMC|ZDA|GNS),|GLL(?:,[^,*]*){4},)(\d{2})(\d{2})(\d{2}(?:\.\d*)?)"
)
_BACKOFF = (0.1, 5.0)


class ReplaySource:
    """Replay a log (plain or gzip) at ``speed`` × real time (0 = as fast as possible), paced
    by the time-of-day fields of GGA/RMC/ZDA/GNS/GLL lines.

    Parameters
    ----------
    path : str or Path
        Log file (plain or .gz).
    speed : float
        Replay speed (1 real time, 0 as fast as possible) [-].
    chunk : int
        Bytes per read at maximum speed.
    """

    def __init__(self, path: str | Path, speed: float = 1.0, chunk: int = 65536):
        path = Path(path)
        self.path = path
        data, self.notes = read_log_bytes(path)
        if speed < 0:
            raise InputError("--speed must be >= 0 (0 = as fast as possible)")
        self.name = str(path)
        self._data = data
        self._speed = speed
        self._chunk = chunk
        self._pos = 0
        self._t0_wall: float | None = None
        self._t0_log: float | None = None
        self._lines = _pieces(data) if speed > 0 else None
        self._line_i = 0
        self._last_tod: float | None = None
        self._day = 0.0
        self.reconnects = 0

    @property
    def eof(self) -> bool:
        """Whether the whole file has been replayed."""
        return self._pos >= len(self._data)

    @property
    def status(self) -> str:
        """One word or phrase for the display."""
        return f"replay {100 * self._pos / max(len(self._data), 1):.0f} %"

    def read(self, timeout: float = 0.1) -> bytes:
        """Bytes received within *timeout* seconds (maybe none).

        Parameters
        ----------
        timeout : float
            Longest wait [s].
        """
        if self.eof:
            return b""
        if self._speed == 0:
            out = self._data[self._pos : self._pos + self._chunk]
            self._pos += len(out)
            return out
        now = time.monotonic()
        if self._t0_wall is None:
            self._t0_wall = now
        budget = (now - self._t0_wall) * self._speed
        pieces: list[bytes] = []
        deadline = now + timeout
        lines = self._lines
        assert lines is not None  # a paced replay has its pieces
        while self._line_i < len(lines):
            piece, tod = lines[self._line_i]
            if tod is not None:
                if self._last_tod is not None and tod < self._last_tod - 43200:
                    self._day += 86400.0
                self._last_tod = tod
                tod += self._day
                if self._t0_log is None:
                    self._t0_log = tod
                if tod - self._t0_log > budget:
                    break
            self._line_i += 1
            pieces.append(piece)
            self._pos += len(piece)
        if not pieces:
            time.sleep(max(0.0, min(timeout, deadline - time.monotonic())))
        return b"".join(pieces)

    def close(self) -> None:
        """Release the source."""
        pass


def _pieces(data: bytes) -> list[tuple[bytes, float | None]]:
    """The log cut into the pieces a replay sends, each with its time of day when it has one:
    NMEA lines (GGA/RMC/ZDA/GNS/GLL times) and UBX frames (NAV-PVT's UTC time of day).
    """
    from gripsense.io.logs.ubx import scan_frames

    fr = scan_frames(data) if b"\xb5\x62" in data else None
    if fr is None or not len(fr):
        return [(ln, _tod(ln)) for ln in _split_lines(data)]
    out: list[tuple[bytes, float | None]] = []
    pos = 0
    for start, end in zip(fr["start"], fr["end"], strict=True):
        start, end = int(start), int(end)  # a rejected frame ends where the scan resynchronised
        out += [(ln, _tod(ln)) for ln in _split_lines(data[pos:start])]
        frame = data[start:end]
        tod: float | None = None
        if frame[2:4] == b"\x01\x07" and len(frame) >= 6 + 11:  # NAV-PVT: hour, min, sec
            tod = frame[6 + 8] * 3600 + frame[6 + 9] * 60 + frame[6 + 10]
            tod += int.from_bytes(frame[6 + 16 : 6 + 20], "little", signed=True) * 1e-9
        out.append((frame, tod))
        pos = end
    out += [(ln, _tod(ln)) for ln in _split_lines(data[pos:])]
    return out


def _split_lines(data: bytes) -> list[bytes]:
    parts = data.split(b"\n")
    return [p + b"\n" for p in parts[:-1]] + ([parts[-1]] if parts[-1] else [])


def _tod(line: bytes) -> float | None:
    m = _TIME.match(line)
    if not m:
        return None
    return int(m.group(1)) * 3600 + int(m.group(2)) * 60 + float(m.group(3))


class EpochReplay:
    """Replay a log that is not a byte stream (VBOX, MDF4, CAN) at ``speed`` × real time: the
    file is read once (:func:`gripsense.io.logs.read_log`) and its epochs are handed out as
    their time comes.

    Parameters
    ----------
    path : str or Path
        The log.
    speed : float
        Replay speed (1 real time, 0 as fast as possible) [-].
    log_options : gripsense.io.logs.LogOptions, optional
        Channel mapping, DBC, time offset.
    """

    def __init__(self, path: str | Path, speed: float = 1.0, log_options=None):
        from gripsense.io.logs import read_log

        if speed < 0:
            raise InputError("--speed must be >= 0 (0 = as fast as possible)")
        self.path = Path(path)
        self.name = str(path)
        log = read_log(path, log_options)
        self._epochs = log.epochs
        self._report = log.report
        self._speed = speed
        self._i = 0
        self._t0_wall: float | None = None
        self.reconnects = 0
        self.notes = list(log.report.notes)
        self.ingest = _ReadIngest(log.report)
        #: the log's own steering channel (``IngestReport.steering``; empty when none)
        self.steering = dict(log.report.steering)

    @property
    def eof(self) -> bool:
        """Whether every epoch was handed out."""
        return self._i >= len(self._epochs)

    @property
    def status(self) -> str:
        """One word or phrase for the display."""
        return f"replay {100 * self._i / max(len(self._epochs), 1):.0f} %"

    def read(self, timeout: float = 0.1) -> bytes:
        """No bytes: the epochs come from :meth:`read_epochs`.

        Parameters
        ----------
        timeout : float
            Unused [s].
        """
        return b""

    def read_epochs(self, timeout: float = 0.1):
        """The epochs whose time has come (maybe none).

        Parameters
        ----------
        timeout : float
            Longest wait when none is due [s].
        """
        ep = self._epochs
        if self.eof:
            return ep.iloc[0:0]
        if self._speed == 0:
            out = ep.iloc[self._i : self._i + 1000]
            self._i += len(out)
            return out
        now = time.monotonic()
        if self._t0_wall is None:
            self._t0_wall = now
        t = ep["t_s"].to_numpy(float)
        due = (now - self._t0_wall) * self._speed + float(t[0])
        j = self._i + int((t[self._i :] <= due).sum())
        if j == self._i:
            time.sleep(timeout)
        out = ep.iloc[self._i : j]
        self._i = j
        return out

    def close(self) -> None:
        """Release the source."""


class _ReadIngest:
    """The ingest of an :class:`EpochReplay`: the file was read whole; nothing to feed."""

    def __init__(self, report):
        self.report = report

    def feed(self, data: bytes):
        import pandas as pd

        return pd.DataFrame()

    def finish(self):
        import pandas as pd

        return pd.DataFrame()


def open_replay(path: str | Path, speed: float = 1.0, log_options=None):
    """A replay source for a log of any format: byte streams (NMEA, UBX) through
    :class:`ReplaySource`, the others (VBOX, MDF4, CAN) through :class:`EpochReplay`.

    Parameters
    ----------
    path : str or Path
        The log.
    speed : float
        Replay speed [-].
    log_options : gripsense.io.logs.LogOptions, optional
        Channel mapping, DBC, time offset (VBOX, MDF4, CAN).
    """
    from gripsense.io.logs import LOG_FORMATS, detect_format

    if Path(path).is_dir():  # a ROS 2 bag folder (read_log says if it is not one)
        return EpochReplay(path, speed=speed, log_options=log_options)
    data, _ = read_log_bytes(path)
    if LOG_FORMATS[detect_format(data[:65536])].streams:  # a byte stream paced by its times
        return ReplaySource(path, speed=speed)
    return EpochReplay(path, speed=speed, log_options=log_options)


_HOST_NAME = re.compile(
    r"^(?=.{1,253}$)[A-Za-z0-9_](?:[A-Za-z0-9_-]{0,62})(?:\.[A-Za-z0-9_-]{1,63})*\.?$"
)


def _check_host(host: str, where: str) -> str:
    import ipaddress

    if host.startswith("[") and host.endswith("]"):
        try:
            return str(ipaddress.IPv6Address(host[1:-1]))
        except ValueError:
            raise InputError(f"{where}: {host} is not an IPv6 address") from None
    if ":" in host:
        raise InputError(f"{where}: write an IPv6 address in brackets, e.g. [::1]:10110")
    if not _HOST_NAME.match(host) or host.strip(".").split(".")[-1].startswith("-"):
        raise InputError(f"{where}: {host!r} is not a host name or address")
    return host


def _check_port(port: object, where: str) -> int:
    text = str(port)
    if not (text.isascii() and text.isdigit() and 1 <= int(text) <= 65535):
        raise InputError(f"{where}: the port must be a number from 1 to 65535, not {port!r}")
    return int(text)


def parse_host_port(text: str) -> tuple[str, int]:
    """Host and port of ``HOST:PORT`` (an IPv6 address in brackets: ``[::1]:10110``).

    Parameters
    ----------
    text : str
        The address as given to ``--tcp``.

    Returns
    -------
    tuple
        ``(host, port)``; the port is 1-65535.

    Raises
    ------
    InputError
        One line naming what is wrong (no port, a port out of range, a malformed host).
    """
    where = f"--tcp {text!r}"
    host, sep, port = text.strip().rpartition(":")
    if not sep or not host or not port:
        raise InputError(f"{where}: expected HOST:PORT, e.g. 192.168.1.10:10110")
    return _check_host(host, where), _check_port(port, where)


class TcpSource:
    """TCP client for receivers that stream NMEA over the network (a plain socket: pyserial's
    ``socket://`` drops bytes received while opening).

    Parameters
    ----------
    host : str
        Host name or address.
    port : int
        TCP port.
    connect_timeout : float
        Timeout of one connection attempt [s].
    """

    def __init__(self, host: str, port: int, *, connect_timeout: float = 2.0):
        where = f"tcp {host}:{port}"
        self.host, self.port = _check_host(str(host), where), _check_port(port, where)
        self.name = f"tcp://{host}:{port}"
        self._sock: socket.socket | None = None
        self._next_try = 0.0
        self._backoff = _BACKOFF[0]
        self._timeout = connect_timeout
        self.reconnects = 0
        self._connected_once = False
        self.eof = False
        self.state = "connecting"

    @property
    def status(self) -> str:
        """One word or phrase for the display."""
        return f"{self.name} {self.state}" + (
            f" ({self.reconnects} reconnects)" if self.reconnects else ""
        )

    def _connect(self) -> None:
        now = time.monotonic()
        if now < self._next_try:
            time.sleep(min(0.05, self._next_try - now))
            return
        try:
            s = socket.create_connection((self.host, self.port), timeout=self._timeout)
            s.settimeout(0.1)
            self._sock = s
            if self._connected_once:
                self.reconnects += 1
            self._connected_once = True
            self._backoff = _BACKOFF[0]
            self.state = "connected"
        except (OSError, OverflowError, UnicodeError):
            self.state = f"reconnecting in {self._backoff:.1f} s"
            self._next_try = now + self._backoff
            self._backoff = min(self._backoff * 2, _BACKOFF[1])

    def read(self, timeout: float = 0.1) -> bytes:
        """Bytes received within *timeout* seconds (maybe none).

        Parameters
        ----------
        timeout : float
            Longest wait [s].
        """
        if self._sock is None:
            self._connect()
            if self._sock is None:
                return b""
        self._sock.settimeout(timeout)
        try:
            data = self._sock.recv(65536)
        except TimeoutError:
            return b""
        except OSError:
            data = b""
        if not data:  # peer closed: reconnect with backoff
            self._sock.close()
            self._sock = None
            self.state = "disconnected"
            self._next_try = time.monotonic() + self._backoff
        return data

    def close(self) -> None:
        """Release the source."""
        if self._sock is not None:
            self._sock.close()
            self._sock = None


class SerialSource:
    """Serial port via pyserial (``pip install gripsense[live]``); reopens the device with
    backoff when it disappears (USB receiver unplugged).

    Parameters
    ----------
    port : str
        Device, e.g. /dev/ttyUSB0.
    baud : int
        Baud rate [1/s].
    """

    def __init__(self, port: str, baud: int = 115200):
        try:
            import serial  # noqa: F401
        except ImportError:
            raise InputError("--serial needs pyserial: pip install 'gripsense[live]'") from None
        self.port, self.baud = port, int(baud)
        self.name = f"serial {port} @ {baud}"
        self._ser = None
        self._next_try = 0.0
        self._backoff = _BACKOFF[0]
        self.reconnects = 0
        self._opened_once = False
        self.eof = False
        self.state = "opening"

    @property
    def status(self) -> str:
        """One word or phrase for the display."""
        return f"{self.name} {self.state}" + (
            f" ({self.reconnects} reopens)" if self.reconnects else ""
        )

    def _open(self) -> None:
        import serial

        now = time.monotonic()
        if now < self._next_try:
            time.sleep(min(0.05, self._next_try - now))
            return
        try:
            self._ser = serial.Serial(self.port, self.baud, timeout=0.1)
            if self._opened_once:
                self.reconnects += 1
            self._opened_once = True
            self._backoff = _BACKOFF[0]
            self.state = "open"
        except (OSError, serial.SerialException):
            self.state = f"reopening in {self._backoff:.1f} s"
            self._next_try = now + self._backoff
            self._backoff = min(self._backoff * 2, _BACKOFF[1])

    def read(self, timeout: float = 0.1) -> bytes:
        """Bytes received within *timeout* seconds (maybe none).

        Parameters
        ----------
        timeout : float
            Longest wait [s].
        """
        import serial

        if self._ser is None:
            self._open()
            if self._ser is None:
                return b""
        try:
            self._ser.timeout = timeout
            n = max(1, self._ser.in_waiting)
            return self._ser.read(n)
        except (OSError, serial.SerialException):
            try:
                self._ser.close()
            except (OSError, serial.SerialException):
                pass
            self._ser = None
            self.state = "device lost"
            self._next_try = time.monotonic() + self._backoff
            return b""

    def close(self) -> None:
        """Release the source."""
        if self._ser is not None:
            self._ser.close()
            self._ser = None
