"""The live loop: source → incremental ingest → sliding-window friction → display and recording.

Recording: every update appends one row per wheel (or axle) to a CSV and every received byte to
``<output>.raw.nmea`` (next to the output, named after it in full so it can never be an input's
name); both are flushed (and fsync'ed) every ``flush_s``. CSV rows are whole lines, so after a
SIGKILL the file is readable up to the last flush. With a ``.parquet`` output the rows go to
``<output>.partial.csv`` while running and are converted at a clean stop; :func:`recover`
converts what a killed run left. SIGINT/SIGTERM stop the loop cleanly (exit 0).

Nothing is overwritten by accident, and one output has one run at a time: the files, their
record (``<output>.gripsense.json``, the fingerprint of every byte written), the locks and
:func:`recover` are :mod:`gripsense.live.recording`'s. SIGINT/SIGTERM are taken over before
anything is created, so a signal at any moment of the run gives complete, recorded files.
"""

from __future__ import annotations

import itertools
import signal
import time
from collections import deque
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from gripsense.errors import GripsenseError
from gripsense.estimate.results import UNIT_COLUMNS
from gripsense.live.recording import (
    LIVE_KIND,
    RESULT_COLUMNS,
    Recorder,
    check_live_outputs,
    output_paths,
    recover,
)
from gripsense.live.stream_ingest import AutoIngest

__all__ = [
    "LIVE_KIND",
    "RESULT_COLUMNS",
    "LiveFriction",
    "LiveStats",
    "Recorder",
    "check_live_outputs",
    "output_paths",
    "recover",
    "run_live",
]

DISPLAY_S = 0.25
"""Refresh interval of the display, on the wall clock [s] (the rows follow the log's clock)."""


class LiveFriction:
    """Friction over the last ``window_s`` seconds of epochs, recomputed on demand.

    Per-sample methods: :class:`gripsense.pipeline.FrictionRun` on the window, so live results
    are the batch method's results on the same recent data. Per-window methods (``axle-window``):
    the wheel table of the window feeds, sample by sample, the estimator's online form
    (:meth:`~gripsense.estimate.Estimator.online`, an :class:`~gripsense.estimate.
    OnlineAxleWindow`) per axle (bins kept as running means), so an update costs the newest
    window's profile whatever the window length; the row per axle is the newest window's
    measured grip and estimate (the batch ``windows.parquet`` row of the same samples).

    The front axle needs a steering channel: a steering CSV replayed beside the log
    (*steer_csv*, aligned by ``t_s`` as ``gripsense friction --steer-csv``), else the log's own
    (*steering*: a VBOX, MDF4 or CAN replay's channel, mapped or found by its name and unit);
    without one :attr:`front_axle` says so in one line.

    Parameters
    ----------
    vehicle : Vehicle or str or Path
        Vehicle description.
    method : str
        Friction method (``gripsense friction --method``).
    window_s : float
        Estimation window [s].
    receiver : str or Path or Receiver, optional
        The receiver.
    steer_csv : str or Path, optional
        Steering CSV (:func:`gripsense.io.sensors.steer.read_steer_csv`).
    steer_columns : str, optional
        Its column mapping.
    steering : dict, optional
        The log's own steering channel (:attr:`gripsense.io.logs.nmea.accounting.IngestReport.
        steering`).
    """

    def __init__(
        self,
        vehicle,
        method: str = "axle-window",
        window_s: float = 30.0,
        receiver=None,
        *,
        steer_csv: str | Path | None = None,
        steer_columns: str | None = None,
        steering: dict | None = None,
    ):
        from gripsense.io.sensors.steer import read_steer_csv
        from gripsense.pipeline import NO_STEERING, FrictionRun

        self.run = FrictionRun(vehicle, method=method, receiver=receiver)
        self.window_s = float(window_s)
        #: the steering CSV replayed beside the log
        #: (:func:`gripsense.io.sensors.steer.read_steer_csv`)
        self.steer = None
        #: the log's own steering channel (``IngestReport.steering``), when it has one
        self.steering = dict(steering or {})
        #: what the steering CSV's reading noted (rows without a mapped channel)
        self.notes: list[str] = []
        #: why the front axle is not estimated ("" when it has a steering channel)
        self.front_axle = "" if self.steering else NO_STEERING
        self.steering_source = ""
        if steer_csv is not None:
            self.steer = read_steer_csv(
                steer_csv, steering_ratio=self.run.vehicle.steering_ratio, columns=steer_columns
            )
            note = self.steer.attrs["rows"]["note"]
            self.notes = [note] if note else []
            self.front_axle = ""
            self.steering_source = f"--steer-csv {Path(steer_csv).name}"
        self._online: dict = {}
        self._pushed_t = -np.inf
        self._last_rows: dict = {}
        self._epochs: deque[pd.DataFrame] = deque()
        self.last_t: float = float("nan")
        self.resets = 0  #: times the data's clock went backwards (window restarted)
        #: the newest window's logger copies (duplicated, held or interpolated epochs,
        #: collapsed: each measurement counts once), "" when it had none
        self.collapsed = ""
        self.last_time_utc = pd.NaT

    def add(self, epochs: pd.DataFrame) -> None:
        """Add final epochs; the window restarts when the data clock goes backwards."""
        if epochs is None or epochs.empty:
            return
        t = epochs["t_s"].to_numpy(float)
        # time going backwards (receiver reset, concatenated replays): a new session starts;
        # the window restarts there instead of mixing the two
        prev = np.concatenate([[self.last_t], t[:-1]])
        back = np.flatnonzero(np.isfinite(t) & np.isfinite(prev) & (t < prev - 1e-6))
        if back.size:
            self.resets += 1
            self._epochs.clear()
            self._online.clear()
            self._last_rows.clear()
            self._pushed_t = -np.inf
            epochs = epochs.iloc[back[-1] :]
            t = t[back[-1] :]
            self.last_t = float("nan")
        self._epochs.append(epochs)
        if np.isfinite(t).any():
            self.last_t = float(np.nanmax(t))
            if "time_utc" in epochs:
                tu = epochs["time_utc"].dropna()
                if len(tu):
                    self.last_time_utc = tu.iloc[-1]
        # keep only the window
        while self._epochs and len(self._epochs) > 1:
            first_t = self._epochs[0]["t_s"].to_numpy(float)
            if np.isfinite(first_t).any() and np.nanmax(first_t) < self.last_t - self.window_s:
                self._epochs.popleft()
            else:
                break

    def _steering(self, ep: pd.DataFrame) -> tuple[pd.DataFrame, np.ndarray | None]:
        """The window's epochs (with the CSV's torque channels) and its road-wheel angle."""
        from gripsense.io.sensors.steer import steer_at, with_torque
        from gripsense.pipeline import log_steering

        if self.steer is not None:
            return with_torque(ep, self.steer), steer_at(self.steer, ep["t_s"].to_numpy(float))
        st = log_steering(ep, self.run.vehicle, steering=self.steering)
        self.front_axle = st.front_axle
        self.steering_source = st.source
        return st.epochs, st.steer_rad

    def estimate(self) -> pd.DataFrame:
        """Summary over the window (one row per wheel/axle; empty when there is no data)."""
        if not self._epochs:
            return pd.DataFrame()
        ep = (
            pd.concat(list(self._epochs), ignore_index=True)
            if len(self._epochs) > 1
            else (self._epochs[0])
        )
        ep = ep[ep["t_s"] >= self.last_t - self.window_s].reset_index(drop=True)
        self._epochs = deque([ep])  # one frame: the next update joins two, not hundreds
        if len(ep) < 5:
            return pd.DataFrame()
        ep, steer = self._steering(ep)
        if self.run.estimator.per_window:
            return self._online_estimate(ep, steer)
        try:
            res = self.run.run(ep, steer_rad=steer)
        except GripsenseError:
            return pd.DataFrame()  # e.g. too little data in the window yet
        if res.meta.get("epochs_collapsed"):
            self.collapsed = f"in the last {self.window_s:g} s: {res.meta['epochs_collapsed']}"
        return res.unit_table()

    def _online_estimate(self, ep: pd.DataFrame, steer: np.ndarray | None) -> pd.DataFrame:
        """Feed the samples that became final to the online estimators; the newest windows."""
        from gripsense.physics.surface import slippery_call, surface_class_interval

        try:
            wheels, meta = self.run.wheel_table(ep, steer_rad=steer)
        except GripsenseError:
            return pd.DataFrame()
        if meta.get("epochs_collapsed"):
            self.collapsed = f"in the last {self.window_s:g} s: {meta['epochs_collapsed']}"
        if wheels.empty:
            return pd.DataFrame()
        # a sample is final once the ±0.5 s slopes around it are complete
        t = wheels["t_s"].to_numpy(float)
        final = (t > self._pushed_t) & (t <= self.last_t - 1.0)
        new = wheels[final]
        if len(new):
            self._pushed_t = float(new["t_s"].max())
            for axle in sorted({w.split("_")[0] for w in new["wheel"].astype(str)}):
                est = self._online.get(axle)
                if est is None:
                    est = self._online[axle] = self.run.estimator.online(
                        self.run.vehicle, axle, noise=self.run.options.noise,
                        window=self.run.window,
                    )  # fmt: skip
                assert est is not None  # a per-window estimator has an online form
                est.push(new)
                row = est.estimate()
                if row is not None:
                    self._last_rows[axle] = row
        rows = []
        for axle, r in sorted(self._last_rows.items()):
            obs = bool(r.get("observable", False))
            lo, hi = r.get("mu_low", np.nan), r.get("mu_high", np.nan)
            rows.append(
                {
                    "unit": axle,
                    "mu": r.get("mu", np.nan) if obs else np.nan,
                    "mu_low": lo,
                    "mu_high": hi,
                    "surface": str(surface_class_interval(lo, hi)) if obs else "undetermined",
                    "slippery": slippery_call(np.fmax(lo, r.get("grip_used_lower", np.nan)), hi),
                    "observable": obs,
                    "grip_used": r.get("grip_used", np.nan),
                    "grip_used_lower": r.get("grip_used_lower", np.nan),
                    "n_valid": int(r.get("n", 0)),
                }
            )
        return pd.DataFrame(rows, columns=UNIT_COLUMNS)


@dataclass
class LiveStats:
    """Counters shown in the display and returned at the end."""

    bytes: int = 0
    epochs: int = 0
    updates: int = 0
    started: float = field(default_factory=time.monotonic)
    last_data: float | None = None
    gaps: list = field(default_factory=list)  # (t_s before, seconds missing)
    last_epoch_t: float | None = None
    median_dt: float | None = None
    front_axle: str = ""  # why the front axle is not estimated ("" when it has steering)


def _note_epochs(stats: LiveStats, ep: pd.DataFrame) -> None:
    t = ep["t_s"].to_numpy(float)
    t = t[np.isfinite(t)]
    if not t.size:
        return
    if stats.last_epoch_t is not None:
        t = np.concatenate([[stats.last_epoch_t], t])
    d = np.diff(t)
    if d.size:
        med = float(np.median(d)) if stats.median_dt is None else stats.median_dt
        stats.median_dt = med if med > 0 else stats.median_dt
        if stats.median_dt:
            for i in np.flatnonzero(d > 3 * stats.median_dt):
                stats.gaps.append((float(t[i]), float(d[i])))
    stats.last_epoch_t = float(t[-1])


def run_live(
    source,
    vehicle,
    *,
    method: str = "axle-window",
    receiver=None,
    output: str | Path | None = None,
    window_s: float = 30.0,
    update_s: float = 1.0,
    flush_s: float = 1.0,
    stale_s: float = 2.0,
    duration_s: float | None = None,
    display=None,
    on_epochs=None,
    handle_signals: bool = True,
    overwrite: bool = False,
    steer_csv: str | Path | None = None,
    steer_columns: str | None = None,
    stop_when=None,
    command: str = "",
) -> dict:
    """Run until the source ends, ``duration_s`` passes, *stop_when* says so, or SIGINT/SIGTERM.

    Parameters
    ----------
    source : ReplaySource | EpochReplay | TcpSource | SerialSource
        A byte stream (NMEA or UBX, recognised from its first bytes) or an epoch replay of a
        VBOX, MDF4 or CAN log.
    vehicle : Vehicle or path
    method : str
        Friction method (``gripsense friction --method``).
    receiver : str or Path or Receiver, optional
        The receiver (``gripsense friction --receiver``).
    output : path, optional
        Results file (.csv or .parquet); raw bytes go to ``<output>.raw.nmea`` next to it.
    window_s, update_s, flush_s, stale_s : float
        Estimation window, update interval **on the log's clock** (a row per unit every
        ``update_s`` of epoch time — the windows' step — so a replay gives the same rows at any
        speed), flush interval, silence after which the source is shown stale [s].
    duration_s : float, optional
        Stop after this wall time.
    display : callable, optional
        ``display(summary, stats, ingest, source)`` called every update.
    on_epochs : callable, optional
        Receives each batch of final epochs (tests, custom sinks).
    handle_signals : bool
        Install SIGINT/SIGTERM handlers that stop the loop cleanly.
    overwrite : bool
        Replace the outputs of an earlier live run with the same name (gripsense's own only).
    steer_csv : str or Path, optional
        A steering CSV replayed beside the log (:func:`gripsense.io.sensors.steer.read_steer_csv`),
        aligned by ``t_s`` as ``gripsense friction --steer-csv`` does: enables the front axle.
        Without it the front axle uses the log's own steering channel (a VBOX, MDF4 or CAN
        replay's, ``source.steering``), if any.
    steer_columns : str, optional
        Column mapping of *steer_csv*.
    stop_when : callable, optional
        ``stop_when(stats)`` is asked after every read; a true value stops the run (a string
        is the reason reported as ``stopped_by``; tests, embedding).
    command : str
        The command line, kept in the output's record.

    Returns
    -------
    dict
        ``report`` (line accounting), ``stats``, ``summary`` (last), ``stopped_by``, ``notes``
        (what reading the steering CSV noted; the last window's logger copies, collapsed),
        ``front_axle`` (why the front axle was not estimated, ``""`` when it had a steering
        channel) and ``steering`` (the channel read).
    """
    stop: dict = {"why": None}

    def _stop(signum, _frame):
        stop["why"] = signal.Signals(signum).name

    old = {}
    if handle_signals:  # first: a signal from here on stops the loop, never the setup midway
        for s in (signal.SIGINT, signal.SIGTERM):
            old[s] = signal.signal(s, _stop)
    rec = None
    try:
        reads_epochs = hasattr(source, "read_epochs")  # a VBOX, MDF4 or CAN replay
        ingest = (
            source.ingest if reads_epochs else AutoIngest(source=getattr(source, "name", "<live>"))
        )
        est = LiveFriction(vehicle, method, window_s, receiver=receiver, steer_csv=steer_csv,
                           steer_columns=steer_columns,
                           steering=getattr(source, "steering", None))  # fmt: skip
        rec = Recorder(
            output,
            flush_s,
            overwrite=overwrite,
            inputs=[p for p in [getattr(source, "path", None), steer_csv] if p],
            command=command,
        )
        return _loop(source, ingest, est, rec, stop, update_s=update_s, stale_s=stale_s,
                     duration_s=duration_s, display=display, on_epochs=on_epochs,
                     stop_when=stop_when)  # fmt: skip
    finally:
        try:
            if rec is not None:
                rec.close()
        finally:
            source.close()
            for s, h in old.items():
                signal.signal(s, h)


def _loop(source, ingest, est, rec, stop, *, update_s, stale_s, duration_s, display, on_epochs,
          stop_when) -> dict:  # fmt: skip
    """The loop of :func:`run_live` (its files and signals are set up and closed there)."""
    reads_epochs = hasattr(source, "read_epochs")
    stats = LiveStats(front_axle=est.front_axle)

    summary = pd.DataFrame()
    # updates follow the log's own clock (every update_s of epoch time), so a replay gives the
    # same rows at any speed; the display follows the wall clock
    clock: dict[str, Any] = {
        "next": None,
        "shown": time.monotonic(),
        "pending": False,
        "last": np.nan,
    }

    def update(now: float) -> None:
        nonlocal summary
        summary = _update(est, rec, stats, now, stale_s)

    def show(now: float, force: bool = False) -> None:
        if display is not None and (force or now - clock["shown"] >= DISPLAY_S):
            clock["shown"] = now
            display(summary, stats, ingest, source)

    def flush_pending() -> None:
        if clock["pending"]:  # a boundary is crossed: an update on what came before it
            update(time.monotonic())
            clock["pending"] = False

    def take_session(ep: pd.DataFrame, t: np.ndarray) -> None:
        """Epochs of one session (clock not going backwards): add them up to each boundary of
        the log's clock, updating at each.
        """
        t = np.fmax.accumulate(np.where(np.isfinite(t), t, -np.inf))  # NaN: the time before
        if clock["next"] is None and np.isfinite(t[-1]):
            clock["next"] = t[np.isfinite(t)][0] + update_s
        i = 0
        while i < len(ep):
            nxt = np.inf if clock["next"] is None else clock["next"]
            k = i + int(np.searchsorted(t[i:], nxt, side="left"))
            if k > i:
                est.add(ep.iloc[i:k])
                clock["pending"] = True
            if k >= len(ep):
                return
            flush_pending()
            # the next boundary after this epoch (one update across a gap, not one per step)
            steps = np.floor((t[k] - clock["next"]) / update_s) + 1.0
            clock["next"] += max(float(steps), 1.0) * update_s
            i = k

    def take(ep: pd.DataFrame) -> None:
        if not len(ep):
            return
        stats.epochs += len(ep)
        _note_epochs(stats, ep)
        if on_epochs is not None:
            on_epochs(ep)
        t = ep["t_s"].to_numpy(float)
        prev = np.concatenate([[clock["last"]], t[:-1]])
        back = np.flatnonzero(np.isfinite(t) & np.isfinite(prev) & (t < prev - 1e-6))
        cuts = [0, *back.tolist(), len(ep)]
        for a, b in itertools.pairwise(cuts):
            if a in back:  # the clock went backwards: a new session, on its own clock
                flush_pending()
                clock["next"] = None
            if b > a:
                take_session(ep.iloc[a:b], t[a:b])
        if np.isfinite(t).any():
            clock["last"] = float(t[np.isfinite(t)][-1])

    t_end = None if duration_s is None else time.monotonic() + duration_s
    while stop["why"] is None:
        if reads_epochs:
            ep = source.read_epochs(0.05)
            if len(ep):
                stats.last_data = time.monotonic()
                take(ep)
        data = source.read(0.05) if not reads_epochs else b""
        now = time.monotonic()
        if data:
            stats.bytes += len(data)
            stats.last_data = now
            rec.raw(data)
            take(ingest.feed(data))
        show(now)
        rec.maybe_flush()
        if source.eof and not data:
            stop["why"] = "end of input"
        if t_end is not None and now >= t_end:
            stop["why"] = "duration"
        why = stop_when(stats) if stop_when is not None and stop["why"] is None else None
        if why:
            stop["why"] = why if isinstance(why, str) else "stop_when"
    take(ingest.finish())
    clock["pending"] = True  # the end: one last update on everything
    flush_pending()
    show(time.monotonic(), force=True)
    return {
        "report": ingest.report,
        "stats": stats,
        "summary": summary,
        "stopped_by": stop["why"],
        # first the conflicts of the vehicle file's calibration (none if the caller applied it)
        "notes": [
            *est.run.calibration_notes,
            *est.notes,
            *([est.collapsed] if est.collapsed else []),
        ],
        "front_axle": est.front_axle,
        "steering": est.steering_source,
    }


def _update(
    est: LiveFriction, rec: Recorder, stats: LiveStats, now: float, stale_s: float
) -> pd.DataFrame:
    s = est.estimate()
    stats.front_axle = est.front_axle
    stats.updates += 1
    if len(s):
        stale = stats.last_data is None or now - stats.last_data > stale_s
        s = s.assign(
            wall_time_s=time.time(), t_s=est.last_t, time_utc=est.last_time_utc, stale=stale
        )
        rec.rows(s)
    return s
