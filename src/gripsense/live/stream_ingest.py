"""Incremental ingest of a UBX stream (mixed with NMEA, as a u-blox receiver sends it), and the
choice between it and the NMEA ingest from the first bytes of a live source.

:class:`LiveUbxIngest` has the interface of :class:`gripsense.live.incremental.LiveIngest`:
bytes in as they arrive, final epochs out, equal to the batch reader
(:func:`gripsense.io.ubx.parse_ubx`). The stream is cut into *units* exactly as the batch
reader counts them: complete UBX frames, and the complete lines of the bytes between frames
(a line interrupted by a frame continues after it). A bounded tail of units is re-read at each
feed; an epoch (one ``iTOW``, UTC from NAV-PVT) is final when ``hold`` newer epochs exist.
"""

from __future__ import annotations

from collections import Counter, deque

import numpy as np
import pandas as pd

from gripsense.io.nmea.accounting import IngestReport, RejectedLine
from gripsense.io.nmea.schema import OVER_LIMIT
from gripsense.io.ubx import SYNC, parse_ubx, scan_frames
from gripsense.live.incremental import LiveIngest

__all__ = ["AutoIngest", "LiveUbxIngest"]

ACCOUNT_BATCH = 5000
"""Received units are counted in batches of at most this many (or when the report is read)."""


class LiveUbxIngest:
    """Feed bytes of a UBX (+ NMEA) stream, get final epochs (see the module documentation).

    Parameters
    ----------
    max_units : int
        Frames and lines kept for re-reading (bounds memory and per-update cost).
    hold : int
        Newest epochs held back (a later frame can still join them, and the yaw rate's
        central difference needs the next epoch).
    source : str
        Name used in the report.
    max_pending_bytes : int
        Longest piece kept while waiting for its end (a frame or a line); a longer one is
        counted as rejected and dropped [bytes].
    """

    def __init__(
        self,
        *,
        max_units: int = 300,
        hold: int = 3,
        source: str = "<live>",
        max_pending_bytes: int = 1 << 16,
    ):
        self.max_units = int(max_units)
        self.hold = int(hold)
        self.source = source
        self.max_pending_bytes = int(max_pending_bytes)
        self._buf = b""  # bytes not yet cut into units (a partial frame at the end)
        self._text = b""  # the partial line of the text between frames
        self._tail: deque[bytes] = deque()
        self._n_units = 0
        self._parsed: Counter = Counter()
        self._ignored: Counter = Counter()
        self._rejected: Counter = Counter()
        self._first_rejects: list[RejectedLine] = []
        self._last: pd.Timestamp | None = None  # newest emitted epoch time
        self._t0: pd.Timestamp | None = None
        self._n_epochs = 0
        self._has_date = False
        self._nmea_lines = 0
        self._pending: list[bytes] = []  # units not yet counted
        self._last_itow = -1

    def feed(self, data: bytes) -> pd.DataFrame:
        """Add received bytes; return the epochs that became final (maybe none).

        Parameters
        ----------
        data : bytes
            Bytes as they arrived (any piece of the stream).
        """
        if not data:
            return pd.DataFrame()
        units = self._cut(self._buf + data, final=False)
        return self._take(units, final=False)

    def finish(self) -> pd.DataFrame:
        """End of stream: pending bytes count as they are; emit every remaining epoch."""
        units = self._cut(self._buf, final=True)
        return self._take(units, final=True)

    @property
    def report(self) -> IngestReport:
        """Accounting so far (equals the batch report once :meth:`finish` was called)."""
        self._account()
        fmt = "u-blox UBX" + (" + NMEA 0183" if self._nmea_lines else "")
        return IngestReport(
            source=self.source,
            total_lines=self._n_units,
            parsed=dict(sorted(self._parsed.items())),
            ignored=dict(sorted(self._ignored.items())),
            rejected={k: int(v) for k, v in self._rejected.items()},
            first_rejects=list(self._first_rejects),
            n_epochs=self._n_epochs,
            has_date=self._has_date,
            format=fmt,
            unit="lines and frames" if self._nmea_lines else "frames",
        )

    # ---------------------------------------------------------------- cutting into units
    def _cut(self, buf: bytes, final: bool) -> list[bytes]:
        """Complete frames and complete text lines of *buf*, in stream order; the rest waits."""
        fr = scan_frames(buf)
        units: list[bytes] = []
        pos = 0
        rest = b""
        for start, status, end in zip(fr["start"], fr["status"], fr["end"], strict=True):
            start, end = int(start), int(end)
            units += self._lines(buf[pos:start])
            if end >= len(buf) and status != 0 and not final:  # cut, or no resync yet: wait
                rest = buf[start:]
                pos = len(buf)
                break
            units.append(buf[start:end])
            pos = end
        tail = buf[pos:]
        # a lone sync byte (or the start of a header) at the end may begin a frame
        keep = 0 if final else _frame_start_suffix(tail)
        units += self._lines(tail[: len(tail) - keep])
        rest = rest or tail[len(tail) - keep :]
        if final and self._text:
            units.append(self._text)
            self._text = b""
        self._buf = rest
        if len(self._buf) > self.max_pending_bytes:  # a frame that never completes
            self._over_limit("a frame longer than the pending limit; dropped")
            self._buf = b""
        return units

    def _lines(self, text: bytes) -> list[bytes]:
        if not text:
            return []
        parts = (self._text + text).split(b"\n")
        self._text = parts.pop()
        if len(self._text) > self.max_pending_bytes:
            self._over_limit("a line longer than the pending limit; dropped")
            self._text = b""
        return [p + b"\n" for p in parts]

    def _over_limit(self, detail: str) -> None:
        self._n_units += 1
        self._rejected[OVER_LIMIT] += 1
        if len(self._first_rejects) < 20:
            self._first_rejects.append(RejectedLine(self._n_units, OVER_LIMIT, detail))

    # ---------------------------------------------------------------- accounting and epochs
    def _take(self, units: list[bytes], final: bool) -> pd.DataFrame:
        new_epoch = False
        if units:
            self._pending.extend(units)
            if len(self._pending) >= ACCOUNT_BATCH:
                self._account()
            self._nmea_lines += sum(1 for u in units if not u.startswith(SYNC))
            self._n_units += len(units)
            self._tail.extend(units)
            itow = max((_itow(u) for u in units), default=-1)
            new_epoch = itow > self._last_itow
            self._last_itow = max(itow, self._last_itow)
        if final:
            self._account()
        elif not new_epoch:  # nothing can have become final: no re-read
            return pd.DataFrame()
        out = self._emit(final)
        if len(self._tail) > 2 * self.max_units:
            for _ in range(len(self._tail) - self.max_units):
                self._tail.popleft()
        return out

    def _account(self) -> None:
        """Count the pending units (batched: a read has a fixed cost)."""
        if not self._pending:
            return
        units, self._pending = self._pending, []
        start = self._n_units - len(units)
        if units:
            rep = parse_ubx(b"".join(units), self.source).report
            self._parsed.update(rep.parsed)
            self._ignored.update(rep.ignored)
            self._rejected.update(rep.rejected)
            for r in rep.first_rejects:
                if len(self._first_rejects) < 20:
                    self._first_rejects.append(
                        RejectedLine(start + 1, r.reason, f"from unit {start + 1}: {r.detail}")
                    )

    def _emit(self, final: bool) -> pd.DataFrame:
        if not self._tail:
            return pd.DataFrame()
        ep = parse_ubx(b"".join(self._tail), self.source).epochs
        t = ep["time_utc"]
        if not len(ep) or not t.notna().any():
            return pd.DataFrame()
        n = len(ep)
        hi = n if final else max(n - self.hold, 0)
        ok = np.zeros(n, dtype=bool)
        ok[:hi] = True
        ok &= t.notna().to_numpy()
        if self._last is not None:
            ok &= (t > self._last).to_numpy()
        out = ep[ok]
        if not len(out):
            return pd.DataFrame()
        if self._t0 is None:
            self._t0 = out["time_utc"].iloc[0]
        out = out.assign(t_s=(out["time_utc"] - self._t0).dt.total_seconds())
        self._last = out["time_utc"].iloc[-1]
        self._n_epochs += len(out)
        self._has_date = True
        return out.reset_index(drop=True)


def _itow(unit: bytes) -> int:
    """The GPS time of week [ms] of a NAV-PVT, NAV-ATT or NAV-RELPOSNED frame, else −1."""
    if len(unit) < 16 or not unit.startswith(SYNC) or unit[2] != 0x01:
        return -1
    off = {0x07: 6, 0x05: 6, 0x3C: 10}.get(unit[3])
    return int.from_bytes(unit[off : off + 4], "little") if off else -1


def _frame_start_suffix(tail: bytes) -> int:
    """How many bytes at the end of *tail* could be the start of a UBX frame header."""
    if tail.endswith(SYNC[:1]):
        return 1
    k = tail.rfind(SYNC, max(0, len(tail) - 6))
    return len(tail) - k if k >= 0 else 0


class AutoIngest:
    """The live ingest chosen from the stream's first bytes: :class:`LiveUbxIngest` when a UBX
    frame with a good checksum arrives, :class:`LiveIngest` (NMEA) when NMEA lines come first.

    Parameters
    ----------
    source : str
        Name used in the report.
    decide_bytes : int
        Bytes after which the stream is taken as NMEA if no UBX frame was seen [bytes].
    """

    def __init__(self, *, source: str = "<live>", decide_bytes: int = 4096):
        self.source = source
        self.decide_bytes = int(decide_bytes)
        self._seen = b""
        self._inner: LiveIngest | LiveUbxIngest | None = None

    @property
    def kind(self) -> str:
        """``"ubx"``, ``"nmea"`` or ``"undecided"``."""
        if self._inner is None:
            return "undecided"
        return "ubx" if isinstance(self._inner, LiveUbxIngest) else "nmea"

    def _has_ubx(self) -> bool:
        fr = scan_frames(self._seen)
        return bool(len(fr) and (fr["status"] == 0).any())

    def _decide(self) -> None:
        if self._has_ubx():
            self._inner = LiveUbxIngest(source=self.source)
        elif len(self._seen) >= self.decide_bytes or self._seen.count(b"\n$") >= 3:
            self._inner = LiveIngest(source=self.source)

    def feed(self, data: bytes) -> pd.DataFrame:
        """Add received bytes; return the epochs that became final.

        Parameters
        ----------
        data : bytes
            Bytes as they arrived.
        """
        if self._inner is not None:
            return self._inner.feed(data)
        self._seen += data
        self._decide()
        if self._inner is None:
            return pd.DataFrame()
        seen, self._seen = self._seen, b""
        return self._inner.feed(seen)

    def finish(self) -> pd.DataFrame:
        """End of stream: emit every remaining epoch."""
        first = pd.DataFrame()
        if self._inner is None:
            self._inner = (
                LiveUbxIngest(source=self.source)
                if self._has_ubx()
                else LiveIngest(source=self.source)
            )
            seen, self._seen = self._seen, b""
            first = self._inner.feed(seen)
        last = self._inner.finish()
        parts = [x for x in (first, last) if len(x)]
        return pd.concat(parts, ignore_index=True) if parts else pd.DataFrame()

    @property
    def report(self) -> IngestReport:
        """Accounting so far."""
        if self._inner is None:
            return IngestReport(self.source, 0, {}, {}, {})
        return self._inner.report
