"""Fleet run: many logs → Dask tasks → partitioned Parquet → cells → map page.

Each task processes a batch of logs (small tasks drown in Dask's per-task overhead, so logs are
grouped to about ``batch_s`` seconds of work). The scheduler is a ``LocalCluster`` with
``workers`` processes, or an existing one (``scheduler="tcp://host:8786"``; the workers must
see the same file system, they write ``OUTDIR/epochs/`` themselves). Every log ends up in the
row counts or in ``OUTDIR/problems.csv`` with its reason.

``calibrate=True`` learns each vehicle id's tyre stiffness from its own logs first (a first pass
of tasks, :func:`gripsense.fleet.tasks.calibration_batch`; ``docs/physics.md`` §15.7), starting
from the calibration its vehicle file names, if any; the calibrations are written to
``OUTDIR/calibration/<id>.calibration.toml`` and applied in the second pass.
"""

from __future__ import annotations

import contextlib
import csv
import glob
import logging
import os
import re
import shutil
import sys
import tempfile
import warnings
from dataclasses import dataclass, field
from pathlib import Path

import pandas as pd

from gripsense._signals import signals_deferred
from gripsense.errors import GripsenseError, InputError
from gripsense.fleet.aggregate import aggregate_cells, check_bucket, write_geojson
from gripsense.fleet.mapping import write_map
from gripsense.fleet.tasks import (
    STEER_SUFFIX,
    calibration_batch,
    not_a_log,
    process_batch,
    steer_csv_for,
)
from gripsense.io.output_folder import ResultWriter

__all__ = [
    "STEER_SUFFIX",
    "FleetResult",
    "account_inputs",
    "expand_logs",
    "read_vehicle_map",
    "run_fleet",
    "safe_id",
    "steer_csv_for",
]


@dataclass
class FleetResult:
    """What :func:`run_fleet` produced.

    Attributes
    ----------
    cells : pandas.DataFrame
        μ per cell and time bucket.
    logs : pandas.DataFrame
        One row per log: rows written or the problem.
    paths : dict
        Name → path of each output.
    notes : list of str
        One line per vehicle and axle whose calibration contradicts its vehicle file
        (:func:`~gripsense.config.calibration.stiffness_conflict`), said as ``friction`` says it.
    """

    cells: pd.DataFrame
    logs: pd.DataFrame  # one row per log: rows written or the problem
    paths: dict[str, Path]
    notes: list[str] = field(default_factory=list)


def expand_logs(patterns: list[str]) -> list[str]:
    """Glob patterns (``**`` allowed) → sorted unique file paths; a file that is the steering
    CSV of another matched log (:func:`steer_csv_for`) is not a log.

    Parameters
    ----------
    patterns : list of str
        Log files or glob patterns.

    Returns
    -------
    list of str
        The logs that can be read (:func:`account_inputs` also says why the others cannot).
    """
    return account_inputs(patterns)[0]


def account_inputs(patterns: list[str]) -> tuple[list[str], list[tuple[str, str]]]:
    """Every named or matched input, either a log to read or a problem with its reason.

    A name without wildcards is an input whatever it is: a missing file, a dangling symbolic
    link, a link loop, a named pipe, a device, a socket or a folder is a problem with that
    reason. A wildcard pattern that matches nothing is a problem; what it matches is a log
    when it is a regular file (a folder it matches is not an input: ``**`` reaches inside it),
    a problem otherwise. A second name of the same file (a link to it, another spelling of
    its path) is a problem ("the same file as …"): each file is read once. A file that is the
    steering CSV of a matched log (:func:`steer_csv_for`) is that log's, not a log.

    Parameters
    ----------
    patterns : list of str
        Log files or glob patterns (``**`` allowed).

    Returns
    -------
    logs : list of str
        Regular files to read, sorted.
    problems : list of tuple of str
        ``(input, reason)`` for every input that cannot be read as a log.
    """
    named: dict[str, str | None] = {}  # path → reason it is not a log (None: a regular file)
    problems: list[tuple[str, str]] = []
    for p in patterns:
        if not glob.has_magic(p):
            named.setdefault(p, not_a_log(p, named=True))
            continue
        hits = glob.glob(p, recursive=True)
        if not hits:
            problems.append((p, "no file matches this pattern"))
        for h in hits:
            if h not in named:
                why = not_a_log(h, named=False)
                if why != "":
                    named[h] = why
    steers = {steer_csv_for(h) for h, why in named.items() if why is None}
    logs: list[str] = []
    seen: dict[tuple[int, int], str] = {}
    for h in sorted(named):
        why = named[h]
        if Path(h) in steers:
            continue  # a log's steering CSV (read with it, and its problem if it cannot be)
        if why is not None:
            problems.append((h, why))
            continue
        st = os.stat(h)
        first = seen.setdefault((st.st_dev, st.st_ino), h)
        if first != h:
            problems.append((h, f"the same file as {first} (read once)"))
            continue
        logs.append(h)
    return logs, problems


def read_vehicle_map(path: str | Path) -> list[tuple[str, str, str]]:
    """CSV ``pattern,vehicle_toml[,vehicle_id]``: logs matching a glob pattern (relative to the
    current folder) use that vehicle; the first matching row wins.
    """
    path = Path(path)
    try:
        rows = list(csv.reader(path.read_text(encoding="utf-8").splitlines()))
    except FileNotFoundError:
        raise InputError(f"{path}: no such file") from None
    out = []
    for i, r in enumerate(rows, start=1):
        if not r or r[0].startswith("#") or r[0] == "pattern":
            continue
        if len(r) < 2:
            raise InputError(f"{path} line {i}: expected pattern,vehicle_toml[,vehicle_id]")
        out.append((r[0].strip(), r[1].strip(), (r[2].strip() if len(r) > 2 else "")))
    return out


def _assign(
    logs: list[str], vehicle: str | None, vmap: list[tuple[str, str, str]]
) -> list[tuple[str, str, str]]:
    from fnmatch import fnmatch

    items = []
    for lg in logs:
        vfile, vid = vehicle, ""
        for pat, vf, vi in vmap:
            if fnmatch(lg, pat) or fnmatch(Path(lg).name, pat):
                vfile, vid = vf, vi
                break
        if vfile is None:
            raise InputError(f"{lg}: no vehicle (give --vehicle or a --vehicle-map row)")
        # one log = one pass; the vehicle id defaults to the log's folder (one folder per car)
        items.append((lg, vfile, safe_id(vid or Path(lg).resolve().parent.name)))
    return items


def safe_id(vid: str) -> str:
    """A vehicle id that is safe as one folder name (``vehicle=<id>`` partitions): characters
    other than letters, digits, ``.``, ``_`` and ``-`` become ``_``; ``.``/``..`` are refused.

    Parameters
    ----------
    vid : str
        Id from a vehicle map or a folder name.

    Returns
    -------
    str
        The sanitised id.
    """
    out = re.sub(r"[^A-Za-z0-9._-]", "_", vid.strip())
    if out.strip(".") == "":
        out = out.replace(".", "_") or "_"
    return out


def run_fleet(
    patterns: list[str],
    outdir: str | Path,
    *,
    vehicle: str | Path | None = None,
    vehicle_map: str | Path | None = None,
    method: str = "axle-window",
    receiver: str | None = None,
    h3_res: int = 11,
    bucket: str = "1 hour",
    since: str | None = None,
    scheduler: str | None = None,
    workers: int = 2,
    logs_per_task: int = 4,
    progress=None,
    map_title: str = "gripsense friction map",
    overwrite: bool = False,
    command: str = "",
    calibrate: bool = False,
    log_options=None,
    steer_columns: str | None = None,
) -> FleetResult:
    """Process every log matching *patterns* and build the cell table and the map.

    Parameters
    ----------
    patterns : list of str
        Glob patterns of logs of any supported format (``LOGS/**/*.nmea``, ``*.vbo``, …).
    outdir : path
        Output folder: ``epochs/`` (partitioned Parquet), ``cells.parquet``, ``cells.geojson``,
        ``map.html``, ``logs.csv``, ``problems.csv`` and ``manifest.json``, written atomically
        (:class:`gripsense.io.output_folder.ResultWriter`): a run in which no log can be used raises
        and leaves the previous result as it was.
    vehicle, vehicle_map : path, optional
        One vehicle TOML for all logs, and/or a CSV mapping log patterns to vehicles.
    method : str
        Friction method (default ``axle-window``: calibrated intervals and bounds).
    receiver : str, optional
        The fleet's compasses: ``v100``, ``white-0.3``, ``rtk`` or a TOML file with a
        ``[receiver]`` table (default: each vehicle file's ``[receiver]``, else ``v100``).
    h3_res : int
        H3 resolution (11: ~25 m cells).
    bucket : str
        Time bucket of the aggregation (DuckDB interval).
    since : str, optional
        ISO time; epochs before it are ignored.
    scheduler : str, optional
        Address of an existing Dask scheduler; default a LocalCluster.
    workers : int
        LocalCluster worker processes (1 thread each).
    logs_per_task : int
        Logs per Dask task.
    progress : callable, optional
        ``progress(done, total)`` after each finished task.
    map_title : str
        Title of the map page.
    overwrite : bool
        Replace an earlier fleet result in *outdir* (only the files its manifest lists).
    command : str
        Command line recorded in the manifest.
    calibrate : bool
        Learn each vehicle id's tyre stiffness from its logs and apply it (module docstring).
    log_options : gripsense.io.logs.LogOptions, optional
        Channel mapping and DBC of MDF4 / CAN logs (every format is recognised by content).
    steer_columns : str, optional
        Column mapping of the logs' steering CSVs (``<log stem>_steer.csv`` beside each log,
        :func:`steer_csv_for`; default by header names). A log without one uses its own
        steering channel, if any; ``logs.csv`` says per log which (``steering``) or why its
        front axle was not estimated (``front_axle``).
    """
    if receiver is not None:
        from gripsense.config import receiver_from

        receiver_from(receiver)  # a bad name or file fails here, before any work
    check_bucket(bucket)  # before any work
    outdir = Path(outdir)
    logs, unreadable = account_inputs(list(patterns))
    if not logs:
        if not unreadable:
            raise InputError(f"no log matches {patterns}")
        first = "; ".join(f"{p}: {why}" for p, why in unreadable[:3])
        raise InputError(
            f"none of the {len(unreadable)} logs could be used ({first}); "
            f"the previous result in {outdir} (if any) is unchanged"
        )
    vmap = read_vehicle_map(vehicle_map) if vehicle_map else []
    items = _assign(logs, None if vehicle is None else str(vehicle), vmap)
    batches = [items[i : i + logs_per_task] for i in range(0, len(items), logs_per_task)]
    steers = [str(p) for p in map(steer_csv_for, logs) if not_a_log(str(p), named=True) is None]
    inputs: list[str | Path] = [*logs, *steers, *sorted({it[1] for it in items})]
    inputs += [vehicle_map] if vehicle_map else []
    if calibrate:
        _one_file_per_id(items)
    with (
        ResultWriter(outdir, "fleet", overwrite=overwrite, command=command, inputs=inputs) as tmp,
        _client(scheduler, workers) as client,
    ):
        calibrations = (
            _calibrate(client, batches, tmp, receiver, log_options, steer_columns)
            if calibrate
            else {}
        )
        records = _map(
            client,
            process_batch,
            batches,
            progress,
            outdir=str(Path(tmp).resolve()),
            method=method,
            h3_res=h3_res,
            since=since,
            receiver=receiver,
            calibrations=calibrations,
            log_options=log_options,
            steer_columns=steer_columns,
        )
        records += [
            {"log": p, "vehicle": "", "rows": 0, "problem": why, "steering": "", "front_axle": ""}
            for p, why in unreadable
        ]  # every named or matched input is in logs.csv, these in problems.csv too
        logs_df = pd.DataFrame(records).sort_values("log").reset_index(drop=True)
        problems = logs_df[logs_df["problem"] != ""][["log", "vehicle", "problem"]]
        if len(problems) == len(logs_df):
            first = "; ".join(
                f"{Path(r.log).name}: {r.problem}" for r in problems.head(3).itertuples()
            )
            raise InputError(
                f"none of the {len(logs_df)} logs could be used ({first}); "
                f"the previous result in {outdir} (if any) is unchanged"
            )
        logs_df.to_csv(tmp / "logs.csv", index=False)
        problems.to_csv(tmp / "problems.csv", index=False)
        cells = aggregate_cells(tmp, bucket=bucket)
        cells.to_parquet(tmp / "cells.parquet", index=False)
        write_geojson(cells, tmp / "cells.geojson")
        write_map(cells, tmp / "map.html", title=map_title)
        notes = _calibration_conflicts(items, calibrations)  # its files still in tmp here
    names = ("cells.parquet", "cells.geojson", "map.html", "problems.csv", "logs.csv", "epochs")
    keys = ("cells", "geojson", "map", "problems", "logs", "epochs")
    paths = {k: outdir / v for k, v in zip(keys, names, strict=True)}
    if calibrations:
        paths["calibration"] = outdir / "calibration"
    return FleetResult(cells=cells, logs=logs_df, paths=paths, notes=notes)


def _calibration_conflicts(items: list[tuple[str, str, str]], calibrations: dict) -> list[str]:
    """The conflicts of each vehicle file with its calibration (the run's own per vehicle id,
    else the one the file names), one line each, prefixed by the file (and the run's
    calibration); a pair shared by several vehicle ids is said once. A file that cannot be read
    says nothing here: its logs' problems say it.
    """
    from gripsense.config.calibration import calibrated_vehicle

    out: list[str] = []
    for vfile, cal in sorted({(vf, calibrations.get(vi, "")) for _, vf, vi in items}):
        lines: list[str] = []
        with contextlib.suppress(GripsenseError):
            calibrated_vehicle(vfile, cal or None, lines)
        where = Path(vfile).name + (f" with {Path(cal).name}" if cal else "")
        out += [f"{where}: {line}" for line in lines]
    return out


def _one_file_per_id(items: list[tuple[str, str, str]]) -> None:
    """A vehicle id learns one calibration: it must name one vehicle file."""
    files: dict[str, str] = {}
    for _, vfile, vid in items:
        if files.setdefault(vid, vfile) != vfile:
            raise InputError(
                f"--calibrate: vehicle id {vid!r} has two vehicle files ({files[vid]}, {vfile}); "
                "give each car its own id in the --vehicle-map"
            )


def _calibrate(
    client, batches, outdir: Path, receiver, log_options=None, steer_columns=None
) -> dict[str, str]:
    """First pass: the logs' sums on the workers, one calibration per vehicle id written to
    ``outdir/calibration/`` (id → file).
    """
    import dataclasses

    from gripsense.config import Vehicle
    from gripsense.config.calibration import calibration_toml, read_calibration
    from gripsense.pipeline import solve_calibration

    records = _map(client, calibration_batch, batches, None, receiver=receiver,
                   log_options=log_options, steer_columns=steer_columns)  # fmt: skip
    files = {vid: vfile for b in batches for _, vfile, vid in b}
    out = {}
    folder = Path(outdir) / "calibration"
    for vid, vfile in sorted(files.items()):
        veh = Vehicle.from_toml(vfile)
        previous = read_calibration(veh.calibration_file) if veh.calibration_file else None
        sums = [s for r in records if r["vehicle"] == vid for s in r["sums"]]
        cal = solve_calibration(
            dataclasses.replace(veh, calibration_file=None), sums, previous=previous
        )
        if not cal.axles:
            continue  # nothing learned: the vehicle file as it is
        folder.mkdir(exist_ok=True)
        path = folder / f"{vid}.calibration.toml"
        path.write_text(calibration_toml(cal), encoding="utf-8")
        out[vid] = str(path.resolve())
    return out


class _WorkerDeaths(logging.Handler):
    """One line per worker process that dies during the run (the nanny's own message is at
    INFO, then Dask's warnings and tracebacks, which are silenced).
    """

    def __init__(self, say) -> None:
        super().__init__(logging.INFO)
        self.say = say
        self.active = True

    def emit(self, record: logging.LogRecord) -> None:
        msg = record.getMessage()
        if (
            self.active
            and msg.startswith("Worker process")
            and ("killed by" in msg or "exited with status" in msg)
        ):
            why = msg.split(" ", 3)[-1]
            self.say(
                f"note: a fleet worker process died ({why}); Dask reruns its unfinished tasks "
                "on the other workers"
            )


def _stderr_line(text: str) -> None:
    sys.stderr.write(text + "\n")
    sys.stderr.flush()


@contextlib.contextmanager
def _client(scheduler: str | None, workers: int, say=_stderr_line):
    """A Dask client on a LocalCluster (or an existing scheduler), closed afterwards; started
    and closed whole even when a signal arrives meanwhile; Dask's own log lines silenced, a
    worker that dies told in one line (*say*).
    """
    import dask
    from dask.distributed import Client, LocalCluster

    nanny = logging.getLogger("distributed.nanny")
    deaths = _WorkerDeaths(say)
    level, propagate = nanny.level, nanny.propagate
    nanny.addHandler(deaths)
    nanny.setLevel(logging.INFO)
    # the nanny's lines reach only *deaths*: at INFO they would pass Dask's own handler, whose
    # silence the cluster's close lifts while a slow worker is still being stopped ("Worker
    # process still alive after 4.0 seconds, killing" on a busy machine)
    nanny.propagate = False
    cluster = client = None
    scratch = None
    try:
        with signals_deferred(), warnings.catch_warnings():
            # the scheduler's HTTP server moves off a taken port 8787 (another Dask) by itself
            warnings.filterwarnings("ignore", message="Port .* is already in use")
            if scheduler is None:
                # the workers' spill folder: private, removed with the cluster (Dask's default
                # left a "dask-scratch-space" in the system's temporary folder)
                scratch = tempfile.mkdtemp(prefix="gripsense-dask-")
                with dask.config.set({"temporary-directory": scratch}):  # the scheduler's
                    cluster = LocalCluster(
                        n_workers=workers,
                        threads_per_worker=1,
                        processes=True,
                        dashboard_address=None,
                        host="127.0.0.1",
                        silence_logs=logging.CRITICAL,
                        local_directory=scratch,
                    )
                client = Client(cluster)
            else:
                client = Client(scheduler)
        yield client
    finally:
        deaths.active = False  # workers stopped by the close are not deaths
        with signals_deferred():
            if client is not None:
                client.close()
            if cluster is not None:
                cluster.close()
            if scratch is not None:
                shutil.rmtree(scratch, ignore_errors=True)
        nanny.removeHandler(deaths)
        nanny.setLevel(level)
        nanny.propagate = propagate


def _map(client, fn, batches, progress, **kwargs) -> list[dict]:
    """Run *fn* on every batch; the records of all batches (in completion order)."""
    from dask.distributed import as_completed
    from distributed import KilledWorker

    futs = [client.submit(fn, b, pure=False, **kwargs) for b in batches]
    records: list[dict] = []
    for done, f in enumerate(as_completed(futs), start=1):
        try:
            records.extend(f.result())
        except KilledWorker as e:  # the system's failure, not the input's: exit 1
            raise OSError(
                f"a fleet task was given up after the workers running it died ({e}); the "
                "previous result (if any) is unchanged"
            ) from None
        if progress is not None:
            progress(done, len(futs))
    return records
