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
from gripsense.io.nmea.reader import read_log_bytes

__all__ = ["ReplaySource", "SerialSource", "TcpSource"]

_TIME = re.compile(rb"^\s*\$..(?:GGA|RMC|ZDA),(\d{2})(\d{2})(\d{2}(?:\.\d*)?)")
_BACKOFF = (0.1, 5.0)


class ReplaySource:
    """Replay a log (plain or gzip) at ``speed`` × real time (0 = as fast as possible), paced
    by the time-of-day fields of GGA/RMC/ZDA lines.

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
        self._lines = data.split(b"\n") if speed > 0 else None
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
        out = []
        deadline = now + timeout
        while self._line_i < len(self._lines):
            line = self._lines[self._line_i]
            m = _TIME.match(line)
            if m:
                tod = int(m.group(1)) * 3600 + int(m.group(2)) * 60 + float(m.group(3))
                if self._last_tod is not None and tod < self._last_tod - 43200:
                    self._day += 86400.0
                self._last_tod = tod
                tod += self._day
                if self._t0_log is None:
                    self._t0_log = tod
                if tod - self._t0_log > budget:
                    break
            self._line_i += 1
            piece = line + (b"\n" if self._line_i < len(self._lines) else b"")
            out.append(piece)
            self._pos += len(piece)
        if not out:
            time.sleep(max(0.0, min(timeout, deadline - time.monotonic())))
        return b"".join(out)

    def close(self) -> None:
        """Release the source."""
        pass


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
        self.host, self.port = host, int(port)
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
        except OSError:
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
