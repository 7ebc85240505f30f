"""Incremental NMEA ingest: bytes in as they arrive, final epochs out, the batch reader's answer.

:class:`LiveIngest` keeps the partial last line and a bounded tail of recent complete lines.
Each :meth:`LiveIngest.feed`:

* classifies only the *new* complete lines (the accounting of
  :func:`gripsense.io.read_nmea` is per line, so the running totals equal the batch report);
* re-reads the tail with the batch reader and emits the epochs that are *final*: not among the
  last ``hold`` epochs (a later sentence can still join the newest epoch, and the yaw rate's
  central difference needs the next one) and not among the first ``hold`` of a trimmed tail
  (their earlier lines may be gone).

RTCM 3 frames and Ashtech binary records (``$PASHR,MCA,`` …) between the sentences are cut
out of the bytes before the lines are split, with the batch reader's scanner
(:class:`gripsense.io.logs.nmea.rtcm.RtcmStream`; a frame cut across two reads is completed by the
next), and counted as the batch reader counts them; reported line numbers are the stream's (a
frame's bytes hold line ends).

``t_s`` is kept on the batch scale (seconds from the stream's first epoch) through an anchor
epoch seen in two consecutive reads. :meth:`finish` emits the rest at the end of the stream.
Memory is bounded by ``max_lines`` whatever the duration.

Known difference to the batch reader: an epoch without a date takes the date of the nearest
dated epoch *within the tail* (batch: within the whole log); receivers that send RMC or ZDA
every burst are not affected.
"""

from __future__ import annotations

from bisect import bisect_right
from collections import Counter, deque

import numpy as np
import pandas as pd

from gripsense.io import read_nmea
from gripsense.io.logs.nmea import schema as S
from gripsense.io.logs.nmea.accounting import IngestReport, RejectedLine
from gripsense.io.logs.nmea.reader import N_FIRST_REJECTS
from gripsense.io.logs.nmea.rtcm import RtcmFrames, RtcmStream, binary_notes, frame_detail

ACCOUNT_BATCH = 20_000
"""Received lines are counted in batches of at most this many (or when the report is read)."""

__all__ = ["LiveIngest"]


class LiveIngest:
    """Feed bytes, get final epochs (see the module documentation).

    Parameters
    ----------
    max_lines : int
        Lines kept for re-reading (bounds memory and per-update cost).
    hold : int
        Epochs held back at each end of the tail.
    source : str
        Name used in the report.
    max_line_bytes : int
        Longest line kept while its end has not arrived; a longer one is counted as rejected and
        dropped (bounded memory against binary junk) [bytes].
    epochs : bool
        Build epochs; False: only count (the live UBX reader counts the NMEA text between its
        frames with this, and builds the epochs itself).
    """

    def __init__(
        self,
        *,
        max_lines: int = 3000,
        hold: int = 3,
        source: str = "<live>",
        max_line_bytes: int = 4096,
        epochs: bool = True,
    ):
        self._epochs = bool(epochs)
        self.max_lines = int(max_lines)
        self.max_line_bytes = int(max_line_bytes)
        self._dropping = False  # inside an over-long line: its bytes are discarded
        self.hold = int(hold)
        self.source = source
        self._partial = b""
        self._tail: deque[bytes] = deque()
        self._tail_start = 0  # global index of the tail's first line
        self._n_lines = 0
        self._parsed: Counter = Counter()
        self._ignored: Counter = Counter()
        self._rejected: Counter = Counter()
        self._junk = 0
        self._first_rejects: list = []
        self._pending: list[bytes] = []  # received lines not yet counted (see _account)
        self._pending_start = 0  # global index of the first pending line
        self._n_epochs = 0
        self._no_time = 0
        self._has_date = False
        self._emitted_last_line = -1  # global first line of the newest emitted epoch
        self._anchor: tuple[int, float] | None = None  # (first line, global t_s)
        self._starts: deque[int] = deque(maxlen=64)  # first lines of recently emitted epochs
        self._aligned = True  # the tail starts where an epoch starts in the batch reading
        self.last_data_monotonic: float | None = None
        # RTCM 3 frames between the sentences: cut out of the bytes before the lines are split,
        # as the batch reader does (a frame's bytes hold line ends by chance)
        self._rtcm = RtcmStream()
        self._n_frames = 0
        self._n_ashtech = 0  # of which Ashtech binary records
        self._frame_rejects: list[RejectedLine] = []
        self._text_bytes = 0  # bytes of text (the stream without its frames) so far
        self._text_lines = 0  # line ends in that text
        self._text_at_line_start = True  # the text so far ends with a line end (or is empty)
        self._removed = 0  # frame bytes cut out so far
        # text line -> stream line: from text line _shift_from[j] on, _shift[j] more line ends
        # (those inside the frames before it); entries before the pending lines are merged
        self._shift_from: list[int] = []
        self._shift: list[int] = []
        self._shift_base = 0

    # ------------------------------------------------------------------ input
    def feed(self, data: bytes) -> pd.DataFrame:
        """Add received bytes; return the epochs that became final (maybe none).

        Parameters
        ----------
        data : bytes
            Bytes as they arrived (any piece of the stream).
        """
        if not data:
            return self._empty()
        text, frames = self._rtcm.feed(data)
        if frames is not None:
            self._count_frames(frames, text)
        self._advance_text(text)
        return self._emit(final=False) if self._lines_of(text) and self._epochs else self._empty()

    def _lines_of(self, text: bytes) -> bool:
        """Split the text (the stream without its frames) into lines; whether any completed."""
        if not text:
            return False
        buf = self._partial + text
        parts = buf.split(b"\n")
        self._partial = parts.pop()
        if self._dropping and parts:
            parts.pop(0)  # the end of an over-long line, counted when it was dropped
            self._dropping = False
        if parts:
            lines = [p + b"\n" for p in parts]
            self._queue(lines)
            if self._epochs:
                self._tail.extend(lines)
            self._n_lines += len(lines)
        if len(self._partial) > self.max_line_bytes and not self._dropping:
            self._account()
            # a line that never ends (binary data, a stuck device) must not grow without bound:
            # it is counted once as rejected and its bytes are dropped up to its line end
            self._n_lines += 1
            self._rejected[S.OVER_LIMIT] += 1
            if len(self._first_rejects) < 20:
                self._first_rejects.append(
                    RejectedLine(
                        self._stream_line(self._n_lines - 1) + 1,
                        S.OVER_LIMIT,
                        f"longer than {self.max_line_bytes} bytes without a line end; dropped",
                    )
                )
            self._dropping = True
        if self._dropping:
            self._partial = b""
        return bool(parts)

    def finish(self) -> pd.DataFrame:
        """End of stream: the partial last line counts as a line; emit every remaining epoch."""
        text, frames = self._rtcm.feed(b"", final=True)
        if frames is not None:
            self._count_frames(frames, text)
        self._advance_text(text)
        self._lines_of(text)
        if self._partial:
            line = [self._partial]
            self._partial = b""
            self._queue(line)
            if self._epochs:
                self._tail.extend(line)
            self._n_lines += 1
        self._account()
        return self._emit(final=True) if self._epochs else self._empty()

    # ------------------------------------------------------------------ RTCM 3 frames
    def _count_frames(self, frames: RtcmFrames, text: bytes) -> None:
        """Count the frames as the batch reader does (good: ignored per message number; CRC
        not matching: rejected, *bad checksum*) and note where each was cut out of the text.
        """
        self._n_frames += frames.size
        self._n_ashtech += frames.n_ashtech
        self._ignored.update(frames.ignored_counts())
        lines, inner = self._rtcm.line, self._rtcm.inner_newlines
        lengths = frames.end - frames.start
        removed = self._removed + np.concatenate([[0], np.cumsum(lengths)[:-1]])
        tb = np.frombuffer(text, dtype=np.uint8)
        nl = np.flatnonzero(tb == 10)
        for k in range(frames.size):
            if not frames.good[k]:
                self._rejected[S.BAD_CHECKSUM] += 1
                if len(self._frame_rejects) < N_FIRST_REJECTS:
                    self._frame_rejects.append(
                        RejectedLine(
                            int(lines[k]) + 1,
                            S.BAD_CHECKSUM,
                            f"byte {frames.start[k]}: {frame_detail(frames, k)}",
                        )
                    )
            if inner[k] == 0:
                continue
            # the text line the frame was cut in; the lines starting at or after the cut are
            # that many line ends further on in the stream
            at = int(frames.start[k] - removed[k]) - self._text_bytes  # offset in *text*
            ends_before = self._text_lines + int(np.searchsorted(nl, at, side="left"))
            line_start = tb[at - 1] == 10 if at > 0 else self._text_at_line_start
            first = ends_before if line_start else ends_before + 1
            self._shift_from.append(first)
            prev = self._shift[-1] if self._shift else self._shift_base
            self._shift.append(prev + int(inner[k]))
        self._removed += int(lengths.sum())

    def _advance_text(self, text: bytes) -> None:
        self._text_bytes += len(text)
        self._text_lines += text.count(b"\n")
        if text:
            self._text_at_line_start = text.endswith(b"\n")

    def _stream_line(self, line: int) -> int:
        """0-based line of the stream of 0-based text line *line* (frames hold line ends)."""
        j = bisect_right(self._shift_from, line)
        return line + (self._shift[j - 1] if j else self._shift_base)

    # ------------------------------------------------------------------ accounting
    def _queue(self, lines: list[bytes]) -> None:
        """Lines to count: counted in batches (one read per ``ACCOUNT_BATCH`` lines or when
        the report is asked for), as a read has a fixed cost that small pieces would repeat.
        """
        if not self._pending:
            self._pending_start = self._n_lines
        self._pending.extend(lines)
        if len(self._pending) >= ACCOUNT_BATCH:
            self._account()

    def _account(self) -> None:
        """Count the pending lines (parsed, ignored, rejected with a reason)."""
        if not self._pending:
            return
        lines, start = self._pending, self._pending_start
        self._pending = []
        rep = read_nmea(b"".join(lines), decompress=False).report
        self._parsed.update(rep.parsed)
        self._ignored.update(rep.ignored)
        self._rejected.update(rep.rejected)
        self._junk += rep.junk_prefix_lines
        for r in rep.first_rejects:
            if len(self._first_rejects) < 20:
                line = self._stream_line(r.line - 1 + start) + 1
                self._first_rejects.append(type(r)(line, r.reason, r.detail))
        # later lookups are of later lines: merge the shifts before them (bounded memory)
        j = bisect_right(self._shift_from, self._n_lines)
        if j:
            self._shift_base = self._shift[j - 1]
            del self._shift_from[:j], self._shift[:j]

    @property
    def report(self) -> IngestReport:
        """Line accounting so far (equals the batch report once :meth:`finish` was called)."""
        self._account()
        first = self._first_rejects
        if self._frame_rejects:
            first = sorted(first + self._frame_rejects, key=lambda r: r.line)
        nf = self._n_frames
        return IngestReport(
            source=self.source,
            total_lines=self._n_lines + nf,
            parsed=dict(sorted(self._parsed.items())),
            ignored=dict(sorted(self._ignored.items())),
            rejected={k: int(v) for k, v in self._rejected.items()},
            first_rejects=first[:N_FIRST_REJECTS],
            junk_prefix_lines=self._junk,
            n_epochs=self._n_epochs,
            epochs_without_time=self._no_time,
            has_date=self._has_date,
            notes=binary_notes(nf, self._n_ashtech),
            unit="lines and frames" if nf else "lines",
        )

    # ------------------------------------------------------------------ epochs
    def _empty(self) -> pd.DataFrame:
        return pd.DataFrame()

    def _emit(self, final: bool) -> pd.DataFrame:
        if not self._tail:
            return self._empty()
        log = read_nmea(b"".join(self._tail), decompress=False)
        ep = log.epochs
        if ep.empty:
            self._trim()
            return self._empty()
        first_line = np.full(len(ep), np.iinfo(np.int64).max, dtype=np.int64)
        for f in log.sentences.values():
            if len(f):
                e = f["epoch"].to_numpy()
                ln = f["line"].to_numpy() - 1 + self._tail_start
                np.minimum.at(first_line, e, ln)
        n = len(ep)
        lo = 0 if self._aligned else self.hold
        hi = n if final else max(n - self.hold, 0)
        idx = np.arange(n)
        ok = (idx >= lo) & (idx < hi) & (first_line > self._emitted_last_line)
        # t_s on the stream's scale through an anchor epoch seen before
        offset = 0.0
        if self._anchor is not None:
            a_line, a_t = self._anchor
            hit = np.flatnonzero(first_line == a_line)
            if hit.size and np.isfinite(ep["t_s"].iloc[hit[0]]):
                offset = a_t - float(ep["t_s"].iloc[hit[0]])
            elif self._tail_start > 0:
                ok &= False  # no anchor in the tail: wait (cannot happen with a sane max_lines)
        ep = ep.assign(t_s=ep["t_s"] + offset)
        out = ep[ok]
        if len(out):
            self._emitted_last_line = int(first_line[ok].max())
            self._starts.extend(int(x) for x in np.sort(first_line[ok]))
            # newest emitted epoch with a time becomes the anchor for the next read
            timed = np.flatnonzero(ok & np.isfinite(ep["t_s"].to_numpy()))
            if timed.size:
                j = int(timed[-1])
                self._anchor = (int(first_line[j]), float(ep["t_s"].iloc[j]))
            self._n_epochs += len(out)
            self._no_time += int(out["time_utc"].isna().sum() if "time_utc" in out else 0)
            self._has_date = self._has_date or bool(log.report.has_date)
        self._trim()
        return out.reset_index(drop=True)

    def _trim(self) -> None:
        """Drop old lines, cutting only where an emitted epoch starts: the epoch grouping is a
        state machine over the whole stream, and a re-read must start in the state the batch
        reader is in there (at an epoch start the state is just that epoch).
        """
        end = self._tail_start + len(self._tail)
        target = end - self.max_lines
        if target <= self._tail_start:
            return
        keep_from = self._starts[-(self.hold + 1)] if len(self._starts) > self.hold else None
        cut = None
        if keep_from is not None:
            limit = min(target, keep_from)
            cands = [x for x in self._starts if self._tail_start < x <= limit]
            cut = max(cands) if cands else None
        if cut is None:
            if len(self._tail) <= 4 * self.max_lines:
                return  # wait for an epoch boundary
            cut, self._aligned = target, False  # no epochs for a long time: bound memory anyway
        else:
            self._aligned = True
        for _ in range(cut - self._tail_start):
            self._tail.popleft()
        self._tail_start = cut
