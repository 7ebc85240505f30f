"""Incremental ingest of a UBX stream (mixed with NMEA, as a u-blox receiver sends it), and the
choice between it and the NMEA ingest from the first bytes of a live source.

:class:`LiveUbxIngest` has the interface of :class:`gripsense.live.incremental.LiveIngest`:
bytes in as they arrive, final epochs out, equal to the batch reader
(:func:`gripsense.io.logs.ubx.parse_ubx`). The stream is cut into *units*: complete UBX frames, and
the complete lines of the bytes between frames (a line interrupted by a frame continues after
it). A bounded tail of units is re-read at each feed; an epoch (one ``iTOW``, UTC from NAV-PVT)
is final when ``hold`` newer epochs exist.

The accounting is the batch reader's: each frame is counted as the scan decided it (read,
ignored per message, rejected per reason, with its byte offset in the stream), by the batch
reader's own counting (:func:`gripsense.io.logs.ubx.account_frames`), and the bytes between the
frames are counted as one NMEA stream by :class:`~gripsense.live.incremental.LiveIngest`, as
the batch reader reads them with :func:`gripsense.io.read_nmea` (RTCM 3 frames and Ashtech
records among them included).
"""

from __future__ import annotations

from collections import Counter, deque

import numpy as np
import pandas as pd

from gripsense.io.logs.nmea.accounting import IngestReport, RejectedLine
from gripsense.io.logs.nmea.schema import OVER_LIMIT, REASONS
from gripsense.io.logs.ubx import MAX_PAYLOAD, SYNC, account_frames, parse_ubx, scan_frames
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
        self._over_rejects: list[RejectedLine] = []
        self._last: pd.Timestamp | None = None  # newest emitted epoch time
        self._t0: pd.Timestamp | None = None
        self._n_epochs = 0
        self._has_date = False
        self._pending: list[tuple[int, bytes, int, int, int, int]] = []
        # frames not yet counted: stream offset, bytes, length field, status, class, id
        self._offset = 0  # stream offset of the first byte of _buf
        self._n_frames = 0
        self._frame_counts: tuple[Counter, Counter, Counter] = (Counter(), Counter(), Counter())
        self._frame_rejects: list[RejectedLine] = []
        self._over = 0  # pieces dropped over the pending limit
        # the bytes between the frames: one NMEA stream, counted as the batch reader does
        self._nmea = LiveIngest(source=source, epochs=False)
        self._text_nonblank = False  # batch reads the text only when it is not all blank
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
        self._nmea.finish()  # the text's last line, even without its line end
        return self._take(units, final=True)

    @property
    def report(self) -> IngestReport:
        """Accounting so far (equals the batch report once :meth:`finish` was called)."""
        self._account()
        parsed, ignored, rejected = (Counter(c) for c in self._frame_counts)
        rejected.update(dict.fromkeys(REASONS, 0))
        first = list(self._frame_rejects)
        nrep = self._nmea.report if self._text_nonblank else None
        n_lines = 0
        if nrep is not None:
            n_lines = nrep.total_lines
            parsed.update(nrep.parsed)
            ignored.update(nrep.ignored)
            rejected.update(nrep.rejected)
            first += [
                RejectedLine(r.line, r.reason, f"line {r.line} of the NMEA text: {r.detail}")
                for r in nrep.first_rejects
            ]
        if self._over:
            rejected[OVER_LIMIT] += self._over
            first = (first + self._over_rejects)[:20]
        return IngestReport(
            source=self.source,
            total_lines=self._n_frames + n_lines + self._over,
            parsed=dict(sorted(parsed.items())),
            ignored=dict(sorted(ignored.items())),
            rejected={k: int(v) for k, v in rejected.items()},
            first_rejects=first[:20],
            junk_prefix_lines=nrep.junk_prefix_lines if nrep is not None else 0,
            n_epochs=self._n_epochs,
            has_date=self._has_date,
            notes=list(nrep.notes) if nrep is not None else [],
            format="u-blox UBX" + (" + NMEA 0183" if n_lines else ""),
            unit="lines and frames" if n_lines else "frames",
        )

    # ---------------------------------------------------------------- cutting into units
    def _cut(self, buf: bytes, final: bool) -> list[bytes]:
        """Complete frames and complete text lines of *buf*, in stream order; the rest waits.
        The frames are queued for counting, the text goes to the NMEA count.
        """
        fr = scan_frames(buf)
        units: list[bytes] = []
        pos = 0
        rest = b""
        cols = (fr[c].to_numpy() for c in ("start", "end", "length", "status", "cls", "id"))
        for start, end, length, status, c, i in zip(*cols, strict=True):
            start, end = int(start), int(end)
            units += self._text_piece(buf[pos:start])
            if status != 0 and not final and not _decided(start, end, int(length), len(buf)):
                # cut, no resync yet, or the bytes that decide how far it reaches not all here
                rest = buf[start:]
                pos = len(buf)
                break
            unit = buf[start:end]
            units.append(unit)
            self._pending.append(
                (self._offset + start, unit, int(length), int(status), int(c), int(i))
            )
            pos = end
        tail = buf[pos:]
        # a lone sync byte (or the start of a header) at the end may begin a frame
        keep = 0 if final else _frame_start_suffix(tail)
        units += self._text_piece(tail[: len(tail) - keep])
        rest = rest or tail[len(tail) - keep :]
        if final and self._text:
            units.append(self._text)
            self._text = b""
        self._offset += len(buf) - len(rest)
        self._buf = rest
        if len(self._buf) > self.max_pending_bytes:  # a frame that never completes
            self._over_limit("a frame longer than the pending limit; dropped")
            self._offset += len(self._buf)
            self._buf = b""
        return units

    def _text_piece(self, text: bytes) -> list[bytes]:
        """Bytes between frames: counted as NMEA; their complete lines (units for the epochs)."""
        if text:
            self._nmea.feed(text)
            self._text_nonblank = self._text_nonblank or bool(text.strip())
        return self._lines(text)

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
        """A piece that never ended, dropped (memory stays bounded; the batch reader, which
        holds the whole stream, has no such limit).
        """
        self._over += 1
        if len(self._over_rejects) < 20:
            self._over_rejects.append(
                RejectedLine(self._offset + 1, OVER_LIMIT, f"byte {self._offset}: {detail}")
            )

    # ---------------------------------------------------------------- accounting and epochs
    def _take(self, units: list[bytes], final: bool) -> pd.DataFrame:
        new_epoch = False
        if units:
            if len(self._pending) >= ACCOUNT_BATCH:
                self._account()
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
        """Count the pending frames (batched: a count has a fixed cost) with the batch
        reader's counting, on the scan's own decisions and stream offsets.
        """
        if not self._pending:
            return
        frames, self._pending = self._pending, []
        n = len(frames)
        size = np.array([len(f[1]) for f in frames], dtype=np.int64)
        ends = np.cumsum(size)
        d = np.frombuffer(b"".join(f[1] for f in frames), dtype=np.uint8)
        col = np.array([f[2:] for f in frames], dtype=np.int64).reshape(n, 4)
        acc = account_frames(
            d,
            ends - size,
            ends,
            col[:, 0],
            col[:, 1].astype(np.int8),
            col[:, 2],
            col[:, 3],
            at=np.array([f[0] for f in frames], dtype=np.int64),
            name=self.source,
        )
        self._n_frames += n
        for mine, theirs in zip(
            self._frame_counts, (acc.parsed, acc.ignored, acc.rejected), strict=True
        ):
            mine.update(theirs)
        for s, r, det in acc.rejects:
            if len(self._frame_rejects) < 20:
                self._frame_rejects.append(RejectedLine(s + 1, r, f"byte {s}: {det}"))

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


_LOOK = 2 * (MAX_PAYLOAD + 8) + 90
"""Bytes after a damaged frame's claimed end that the scan may look at to decide where it ends
(a good frame or a sentence after it, or inside the reach of a resynchronisation)."""


def _decided(start: int, end: int, length: int, n: int) -> bool:
    """Whether the scan's decision on a damaged frame (bad checksum or length) found in the
    first *n* bytes of a stream is the one it takes on the whole stream: every byte the scan
    may look at is there (a frame or sentence that more bytes would complete could otherwise
    move the point where it resynchronises).
    """
    if end >= n:
        return False
    if length > MAX_PAYLOAD:  # the scan looked for the next frame or sentence as far as needed
        return end + MAX_PAYLOAD + 8 + 90 <= n
    return start + 8 + max(length, 0) + _LOOK <= n


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
