"""The files of a live run: created exclusively, locked for the run's life, replaced only by proof,
recovered without losing a byte.

A live run with ``-o OUT`` writes, next to each other:

=====================  ===========================================================================
``OUT``                the results (``.csv``: written as it goes; ``.parquet``: at the end)
``OUT.partial.csv``    the rows while a ``.parquet`` run is running (converted at the end)
``OUT.raw.nmea``       every byte received, in order
``OUT.rejected``       rows :func:`recover` could not read, byte for byte (only when there are)
``OUT.gripsense.json`` the run's *record*: its state and, for every file above, the size and
                       SHA-256 of the bytes gripsense wrote there
=====================  ===========================================================================

Rules (``docs/reliability.md``):

* **Ownership by proof.** An existing file is replaced (``--overwrite``) only when the record
  lists it with the size and SHA-256 it has now: a user's file, or gripsense's file a user
  edited, is never replaced. While a run streams, each flush first records the state the files
  will have after it (the state before it stays valid too), then writes and fsyncs them: a file
  cut by a kill is still one of two recorded states. The record fingerprints itself, so an
  edited record proves nothing.
* **One run per output.** The files are created exclusively (``O_EXCL``) under an advisory lock
  on their folder, and the rows file stays locked (``flock``) for the run's life: a second run
  (or ``--recover``) on the same output is refused with one line naming the running one.
* **Re-checked at install.** A ``.parquet`` result is installed at the end under the folder's
  lock after checking again that what it replaces is still what the record proves (a file that
  appeared meanwhile is never replaced: the rows stay in ``OUT.partial.csv``).
* **Recovery keeps every byte.** :func:`recover` reads the rows file line by line; a row it cannot
  read (a field too many or too few, a number that is not one, NUL bytes after a power loss, a
  last line without its end) goes verbatim to ``OUT.rejected``; numeric columns stay numeric.
  The rows file is deleted only when header + recovered rows + rejected rows are all of it.
"""

from __future__ import annotations

import contextlib
import csv
import hashlib
import io
import json
import math
import os
import socket
import tempfile
import time
from collections.abc import Iterator, Sequence
from pathlib import Path
from typing import Any

import pandas as pd

from gripsense.errors import InputError
from gripsense.estimate.results import UNIT_COLUMNS
from gripsense.io.output_folder import writable_parent

try:  # advisory locks (POSIX); elsewhere exclusive creation alone guards the outputs
    import fcntl
except ImportError:  # pragma: no cover - not on Linux or macOS
    fcntl = None  # type: ignore[assignment]

__all__ = [
    "LIVE_KIND",
    "RECORD_FORMAT",
    "RESULT_COLUMNS",
    "Recorder",
    "check_live_outputs",
    "output_paths",
    "read_record",
    "recover",
    "split_rows",
]

LIVE_KIND = "live"
RECORD_FORMAT = 1
RESULT_COLUMNS = ["wall_time_s", "t_s", "time_utc", *UNIT_COLUMNS, "stale"]
NUMERIC_COLUMNS = (
    "wall_time_s",
    "t_s",
    "mu",
    "mu_low",
    "mu_high",
    "grip_used",
    "grip_used_lower",
    "n_valid",
)
"""Columns that are numbers in every row (empty allowed, except for the two times)."""
REQUIRED_NUMBERS = ("wall_time_s", "t_s")
BOOL_COLUMNS = ("observable", "stale")
BUFFER_LIMIT = 4 << 20
"""Bytes held between two flushes before they are written anyway [bytes]."""

Fingerprint = dict[str, Any]


def output_paths(output: str | Path) -> dict[str, Path]:
    """Files a live run with *output* writes (see the module documentation): ``results``,
    ``rows`` (the output itself for CSV, ``<output>.partial.csv`` for Parquet), ``raw``,
    ``rejected`` and ``record``.

    Parameters
    ----------
    output : str or Path
        ``.csv`` or ``.parquet`` results file [path].

    Returns
    -------
    dict
        Name → path.
    """
    output = Path(output)
    suffix = output.suffix.lower()
    if suffix not in (".csv", ".parquet"):
        raise InputError(f"{output}: use a .csv or .parquet output")
    rows = output if suffix == ".csv" else output.with_name(output.name + ".partial.csv")
    return {
        "results": output,
        "rows": rows,
        "raw": output.with_name(output.name + ".raw.nmea"),
        "rejected": output.with_name(output.name + ".rejected"),
        "record": output.with_name(output.name + ".gripsense.json"),
    }


# ---------------------------------------------------------------------------------------------
# fingerprints and the record


def _fingerprint(path: Path) -> Fingerprint | None:
    """Size and SHA-256 of a file (None when there is none)."""
    h = hashlib.sha256()
    n = 0
    try:
        with open(path, "rb") as fh:
            for block in iter(lambda: fh.read(1 << 20), b""):
                h.update(block)
                n += len(block)
    except FileNotFoundError:
        return None
    except IsADirectoryError:
        raise InputError(f"{path}: is a folder; give -o another name") from None
    return {"bytes": n, "sha256": h.hexdigest()}


def _self_print(body: dict) -> str:
    doc = {k: v for k, v in body.items() if k != "fingerprint"}
    return hashlib.sha256(json.dumps(doc, sort_keys=True).encode()).hexdigest()


def read_record(output: str | Path) -> dict | None:
    """The record of the live run that wrote *output*, or None when there is none.

    Parameters
    ----------
    output : str or Path
        The run's ``-o`` [path].

    Returns
    -------
    dict or None
        The record (state, pid, files → recorded states).

    Raises
    ------
    InputError
        When a file with the record's name exists but is not a record gripsense wrote (or was
        edited since).
    """
    p = output_paths(output)["record"]
    try:
        doc = json.loads(p.read_bytes())
    except FileNotFoundError:
        return None
    except (OSError, ValueError):
        doc = None
    if (
        not isinstance(doc, dict)
        or doc.get("gripsense_live") != RECORD_FORMAT
        or doc.get("fingerprint") != _self_print(doc)
        or not isinstance(doc.get("files"), dict)
    ):
        raise InputError(
            f"{p}: is not a record gripsense wrote (or it was edited), so it proves nothing; "
            "move it away or give -o another name"
        )
    return doc


def _write_record(path: Path, body: dict) -> None:
    """Write the record atomically (temporary sibling, fsync, rename)."""
    body = {"gripsense_live": RECORD_FORMAT, **body}
    body["fingerprint"] = _self_print(body)
    data = (json.dumps(body, indent=1, sort_keys=True) + "\n").encode()
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".gripsense-tmp", dir=path.parent)
    try:
        with os.fdopen(fd, "wb") as fh:
            fh.write(data)
            fh.flush()
            os.fsync(fh.fileno())
        os.chmod(tmp, 0o666 & ~_umask())
        os.replace(tmp, path)
    finally:
        if os.path.exists(tmp):
            os.unlink(tmp)


def _umask() -> int:
    mask = os.umask(0o022)
    os.umask(mask)
    return mask


def _recorded(record: dict | None, path: Path) -> list[Fingerprint]:
    if record is None:
        return []
    states = record["files"].get(path.name, [])
    return [s for s in states if isinstance(s, dict)]


def _owned(record: dict | None, path: Path, fp: Fingerprint | None) -> bool:
    return fp is not None and fp in _recorded(record, path)


# ---------------------------------------------------------------------------------------------
# locks


@contextlib.contextmanager
def _folder_lock(folder: Path) -> Iterator[None]:
    """An exclusive advisory lock on *folder* while outputs are checked, created or installed."""
    if fcntl is None:
        yield
        return
    try:
        fd = os.open(folder, os.O_RDONLY)
    except OSError:
        yield
        return
    try:
        with contextlib.suppress(OSError):  # a file system without locks: O_EXCL still holds
            fcntl.flock(fd, fcntl.LOCK_EX)
        yield
    finally:
        os.close(fd)


def _busy(path: Path) -> bool:
    """Whether another open file (a running live run) holds the run lock of *path*."""
    if fcntl is None:
        return False
    try:
        fd = os.open(path, os.O_RDONLY)
    except OSError:
        return False
    try:
        fcntl.flock(fd, fcntl.LOCK_SH | fcntl.LOCK_NB)
    except BlockingIOError:
        return True
    except OSError:
        return False
    finally:
        os.close(fd)
    return False


def _lock_run(fd: int) -> None:
    if fcntl is not None:
        with contextlib.suppress(OSError):
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)


def _who(output: Path) -> str:
    try:
        rec = read_record(output)
    except InputError:
        rec = None
    if rec and rec.get("pid"):
        return f" (pid {rec['pid']} on {rec.get('host', '?')})"
    return ""


def _refuse_busy(paths: dict[str, Path]) -> None:
    for key in ("rows", "raw"):
        if _busy(paths[key]):
            raise InputError(
                f"{paths['results']}: another gripsense live run is writing it"
                f"{_who(paths['results'])}; wait for it to stop or give -o another name"
            )


# ---------------------------------------------------------------------------------------------
# the check before any work


def _same_file(a: Path, b: Path) -> bool:
    try:
        return a.resolve() == Path(b).resolve()
    except OSError:
        return False


def check_live_outputs(
    output: str | Path, *, overwrite: bool = False, inputs: Sequence[str | Path] = ()
) -> dict | None:
    """Refuse a live output that would destroy something (see the module documentation).

    Parameters
    ----------
    output : str or Path
        ``.csv`` or ``.parquet`` results file [path].
    overwrite : bool
        Replace the outputs of an earlier live run with the same name — only files its record
        proves gripsense wrote, byte for byte.
    inputs : list
        Input files (a replayed log, a steering CSV) [path]: never written.

    Returns
    -------
    dict or None
        The earlier run's record (None when there is nothing to replace).

    Raises
    ------
    InputError
        One line naming the path: an input, a folder, an output another run is writing, an
        unrecovered ``.partial.csv``, an existing output without *overwrite* or one gripsense
        cannot prove it wrote, an unwritable folder.
    """
    paths = output_paths(output)
    for key, p in paths.items():
        for inp in inputs:
            if _same_file(p, Path(inp)):
                raise InputError(f"{p}: is also an input; give -o another name")
        if p.is_dir():
            raise InputError(f"{p}: is a folder; give -o another name")
        if key != "record" and p.exists() and not p.is_file():
            raise InputError(f"{p}: is not a regular file; give -o another name")
    _refuse_busy(paths)
    part = paths["rows"]
    if part != paths["results"] and part.exists():
        raise InputError(
            f"{part}: an earlier run was stopped before it finished; recover it first "
            f"(gripsense live --recover {paths['results']}) or move it away"
        )
    existing = [paths[k] for k in ("results", "raw", "rejected", "record") if paths[k].exists()]
    record = None
    if existing:
        if not overwrite:
            raise InputError(
                f"{existing[0]}: exists; add --overwrite (in Python: overwrite=True) to replace "
                "it, or give -o another name"
            )
        record = read_record(paths["results"])
        for p in existing:
            if p == paths["record"]:
                continue
            if record is None:
                raise InputError(
                    f"{p}: exists and there is no record that gripsense wrote it "
                    f"({paths['record'].name} is missing); gripsense replaces only files it "
                    "can prove it wrote — move it away or give -o another name"
                )
            if not _owned(record, p, _fingerprint(p)):
                raise InputError(
                    f"{p}: exists and is not what gripsense wrote there (changed since, or not "
                    "written by gripsense); gripsense replaces only its own files — move it "
                    "away or give -o another name"
                )
    writable_parent(paths["results"])
    return record


# ---------------------------------------------------------------------------------------------
# the recorder


class _Stream:
    """One append-only output file: buffered between flushes, hashed as written."""

    def __init__(self, path: Path):
        self.path = path
        self.fd = os.open(path, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o666)
        self.hash = hashlib.sha256()
        self.size = 0
        self.buf = bytearray()

    def state(self) -> Fingerprint:
        return {"bytes": self.size, "sha256": self.hash.hexdigest()}

    def pending(self) -> Fingerprint:
        h = self.hash.copy()
        h.update(self.buf)
        return {"bytes": self.size + len(self.buf), "sha256": h.hexdigest()}

    def write_out(self) -> None:
        data, done = bytes(self.buf), 0
        while done < len(data):
            done += os.write(self.fd, data[done:])
        os.fsync(self.fd)
        self.hash.update(self.buf)
        self.size += len(self.buf)
        self.buf.clear()

    def close(self) -> None:
        if self.fd >= 0:
            os.close(self.fd)
            self.fd = -1


class Recorder:
    """The files of one live run: results rows, raw bytes and the record, flushed and fsync'ed
    every ``flush_s``; a ``.parquet`` result is written at :meth:`close`.

    Parameters
    ----------
    output : str or Path or None
        ``.csv`` or ``.parquet`` results file [path] (None: record nothing).
    flush_s : float
        Flush interval [s].
    overwrite : bool
        Replace the outputs of an earlier live run with the same name (only what its record
        proves gripsense wrote).
    inputs : list
        Input files, never written [path] (:func:`check_live_outputs`).
    command : str
        The command line, kept in the record.
    """

    def __init__(
        self,
        output: str | Path | None,
        flush_s: float = 1.0,
        *,
        overwrite: bool = False,
        inputs: Sequence[str | Path] = (),
        command: str = "",
    ):
        self.output = None if output is None else Path(output)
        self.flush_s = flush_s
        self._last_flush = float("-inf")
        self._streams: dict[str, _Stream] = {}
        self._carried: dict[str, list[Fingerprint]] = {}
        self._meta: dict[str, Any] = {}
        if self.output is None:
            return
        paths = self.paths = output_paths(self.output)
        folder = paths["results"].parent
        try:
            folder.mkdir(parents=True, exist_ok=True)
        except OSError as e:
            raise InputError(f"{self.output}: cannot write ({e.strerror or e})") from None
        from gripsense._version import __version__

        self._meta = {
            "output": paths["results"].name,
            "pid": os.getpid(),
            "host": socket.gethostname(),
            "gripsense_version": __version__,
            "command": command,
            "overwrite": bool(overwrite),
        }
        with _folder_lock(folder):  # the check again, now that no other run can slip in
            old = check_live_outputs(self.output, overwrite=overwrite, inputs=inputs)
            parquet = paths["rows"] != paths["results"]
            for key in ("results", "rejected"):
                p = paths[key]
                if parquet and p.exists():  # replaced only when the new result is installed
                    self._carried[p.name] = _recorded(old, p)
                elif p.exists():
                    p.unlink()  # proven gripsense's own by the check
            paths["raw"].unlink(missing_ok=True)
            try:
                for key in ("rows", "raw"):
                    self._streams[key] = _Stream(paths[key])
                    _lock_run(self._streams[key].fd)
            except FileExistsError as e:
                self._abandon()
                raise InputError(
                    f"{e.filename}: appeared while this run started (another run?); give -o "
                    "another name"
                ) from None
            except OSError as e:
                self._abandon()
                raise InputError(f"{self.output}: cannot write ({e.strerror or e})") from None
            self._streams["rows"].buf += (",".join(RESULT_COLUMNS) + "\n").encode()
            self.maybe_flush(force=True)

    def _abandon(self) -> None:
        for s in self._streams.values():
            s.close()
            with contextlib.suppress(OSError):
                s.path.unlink()
        self._streams.clear()

    def _files(self, states: dict[str, list[Fingerprint]]) -> dict[str, list[Fingerprint]]:
        return {**self._carried, **states}

    def raw(self, data: bytes) -> None:
        """Append received bytes to the raw recording.

        Parameters
        ----------
        data : bytes
            The bytes as received.
        """
        if "raw" in self._streams and data:
            self._streams["raw"].buf += data
            if len(self._streams["raw"].buf) > BUFFER_LIMIT:
                self.maybe_flush(force=True)

    def rows(self, df: pd.DataFrame) -> None:
        """Append result rows to the results file.

        Parameters
        ----------
        df : pandas.DataFrame
            Rows with (some of) :data:`RESULT_COLUMNS`.
        """
        if "rows" in self._streams and len(df):
            text = df.reindex(columns=RESULT_COLUMNS).to_csv(header=False, index=False)
            self._streams["rows"].buf += text.encode("utf-8")

    def maybe_flush(self, force: bool = False) -> None:
        """Write, fsync and record the files when ``flush_s`` has passed (or *force*).

        Parameters
        ----------
        force : bool
            Flush now.
        """
        now = time.monotonic()
        if not self._streams or not (force or now - self._last_flush >= self.flush_s):
            return
        self._last_flush = now
        if not any(s.buf for s in self._streams.values()):
            return
        # the record first: after a kill each file is in its state before or after this flush
        states = {s.path.name: [s.state(), s.pending()] for s in self._streams.values()}
        _write_record(self.paths["record"], {**self._meta, "state": "running",
                                             "files": self._files(states)})  # fmt: skip
        for s in self._streams.values():
            if s.buf:
                s.write_out()

    def close(self) -> None:
        """Flush, record, and convert the rows to Parquet for a ``.parquet`` output."""
        if not self._streams:
            return
        try:
            self.maybe_flush(force=True)
            paths = self.paths
            if paths["rows"] == paths["results"]:
                states = {s.path.name: [s.state()] for s in self._streams.values()}
                for key in ("rows", "raw"):
                    os.fsync(self._streams[key].fd)
                _write_record(paths["record"], {**self._meta, "state": "finished",
                                                "files": self._files(states)})  # fmt: skip
            else:
                with _folder_lock(paths["results"].parent):
                    _install(paths, read_record(paths["results"]), self._meta)
        finally:
            for s in self._streams.values():
                s.close()
            self._streams.clear()


# ---------------------------------------------------------------------------------------------
# recovery


def _row_problem(line: bytes, ncols: int, cols: dict[str, int]) -> str:
    """Why a rows-file line cannot be a result row ("" when it can)."""
    if b"\x00" in line:
        return "NUL bytes (a power loss?)"
    if not line.endswith(b"\n"):
        return "no line end (cut off)"
    try:
        text = line.decode("utf-8")
    except UnicodeDecodeError:
        return "not UTF-8 text"
    try:
        fields = next(csv.reader([text.rstrip("\r\n")], strict=True), [])
    except csv.Error as e:
        return f"not a CSV row ({e})"
    if len(fields) != ncols:
        return f"{len(fields)} fields where the header has {ncols}"
    for name, i in cols.items():
        v = fields[i]
        if name in BOOL_COLUMNS:
            if v not in ("True", "False", ""):
                return f"{name} is not True or False: {v[:20]!r}"
            continue
        if v == "" and name not in REQUIRED_NUMBERS:
            continue
        try:
            x = float(v)
        except ValueError:
            return f"{name} is not a number: {v[:20]!r}"
        if name in REQUIRED_NUMBERS and not math.isfinite(x):
            return f"{name} is not a finite number: {v[:20]!r}"
    return ""


def split_rows(data: bytes, source: str = "rows") -> tuple[bytes, list[bytes], list[tuple]]:
    """Cut a live rows file into its header, the rows that can be read back and the rows that
    cannot (with their line number and why); together they are every byte of *data*.

    Parameters
    ----------
    data : bytes
        The rows file's content.
    source : str
        Its name, for the error.

    Returns
    -------
    tuple
        ``(header, good, rejected)``: the header line, the good lines, and
        ``(line_number, line, reason)`` per rejected line.
    """
    # only \n separates lines (splitlines would also cut at \r, \x0b … inside a row)
    lines = [ln + b"\n" for ln in data.split(b"\n")]
    lines[-1] = lines[-1][:-1]
    if not lines[-1]:
        lines.pop()
    if not lines:
        raise InputError(f"{source}: empty (no header): nothing to recover")
    header = lines[0]
    names = header.decode("utf-8", "replace").strip().split(",")
    if not header.endswith(b"\n") or not {"wall_time_s", "t_s", "unit"} <= set(names):
        raise InputError(f"{source}: its first line is not a gripsense live header: not recovered")
    cols = {n: i for i, n in enumerate(names) if n in NUMERIC_COLUMNS or n in BOOL_COLUMNS}
    good: list[bytes] = []
    bad: list[tuple] = []
    for k, ln in enumerate(lines[1:], start=2):
        why = _row_problem(ln, len(names), cols)
        if why:
            bad.append((k, ln, why))
        else:
            good.append(ln)
    return header, good, bad


def _table(header: bytes, good: list[bytes]) -> pd.DataFrame:
    names = header.decode("utf-8").strip().split(",")
    dtype = {c: "float64" for c in NUMERIC_COLUMNS if c in names and c != "n_valid"}
    df = pd.read_csv(io.BytesIO(header + b"".join(good)), dtype=dtype)
    if "n_valid" in df and df["n_valid"].notna().all():
        df["n_valid"] = df["n_valid"].astype("int64")
    if len(df) != len(good):  # pragma: no cover - a row the checks passed but pandas split
        raise InputError("rows read back do not match the lines checked: not recovered")
    return df


def _tmp_write(folder: Path, name: str, write) -> Path:
    fd, tmp = tempfile.mkstemp(prefix=f".{name}.", suffix=".gripsense-tmp", dir=folder)
    os.close(fd)
    try:
        write(Path(tmp))
        with open(tmp, "rb+") as fh:
            os.fsync(fh.fileno())
        os.chmod(tmp, 0o666 & ~_umask())
    except BaseException:
        os.unlink(tmp)
        raise
    return Path(tmp)


def _put(tmp: Path, target: Path, replace: bool) -> None:
    """Move *tmp* to *target*: a rename over a proven file, else a link that fails if the
    target appeared.
    """
    if replace:
        os.replace(tmp, target)
        return
    try:
        os.link(tmp, target)
    except FileExistsError:
        os.unlink(tmp)
        raise InputError(
            f"{target}: appeared while the rows were being converted and gripsense did not "
            "write it; move it away and run gripsense live --recover again"
        ) from None
    os.unlink(tmp)


def _install(paths: dict[str, Path], record: dict | None, meta: dict) -> dict:
    """Convert the rows file to the Parquet result and ``.rejected`` (the caller holds the
    folder's lock and the rows file's run lock); the rows file is deleted last. A ``.csv``
    result is its own rows file: its unreadable rows move to ``.rejected``, the rest stays.
    """
    from gripsense.io.output_folder import write_parquet

    part, out, rej = paths["rows"], paths["results"], paths["rejected"]
    csv_out = part == out
    folder = out.parent
    data = part.read_bytes()
    header, good, bad = split_rows(data, str(part))
    assert len(header) + sum(map(len, good)) + sum(len(b[1]) for b in bad) == len(data)
    df = _table(header, good)
    # re-check what is replaced: still what the record proves (never a file that appeared);
    # a .csv result is rewritten with every byte kept (its rows here, the others in .rejected)
    now = {p: _fingerprint(p) for p in (out, rej)}
    if csv_out and not bad:
        sealed = {
            p.name: [fp]
            for p in (out, rej, paths["raw"])
            if (fp := _fingerprint(p)) is not None and _owned(record, p, fp)
        }
        _write_record(paths["record"], {**meta, "state": "finished", "files": sealed})
        return {"rows": len(good), "rejected": bad, "results": out, "rejected_path": rej}
    for p, fp in now.items():
        if csv_out and p == out:
            continue
        if fp is not None and not _owned(record, p, fp):
            raise InputError(
                f"{p}: exists and is not what gripsense wrote there (it appeared or changed "
                f"during the run); your rows stay in {part.name} — move {p.name} away and run "
                f"gripsense live --recover {out}"
            )
    files: dict[str, list[Fingerprint]] = {}
    raw_fp = _fingerprint(paths["raw"])
    if raw_fp is not None and _owned(record, paths["raw"], raw_fp):
        files[paths["raw"].name] = [raw_fp]
    if csv_out:
        kept = header + b"".join(good)
        new_out = _tmp_write(folder, out.name, lambda t: t.write_bytes(kept))
    else:
        new_out = _tmp_write(folder, out.name, lambda t: write_parquet(df, t, LIVE_KIND))
    new_rej = None
    if bad:
        blob = header + b"".join(b[1] for b in bad)
        new_rej = _tmp_write(folder, rej.name, lambda t: t.write_bytes(blob))
    fp_out = _fingerprint(new_out)
    fp_rej = None if new_rej is None else _fingerprint(new_rej)
    # before the renames: both the old and the new state are gripsense's
    pending = {
        part.name: [s for s in (_fingerprint(part),) if s],
        out.name: [s for s in (now[out], fp_out) if s],
        rej.name: [s for s in (now[rej], fp_rej) if s],
    }
    installing = {**meta, "state": "installing", "files": {**files, **pending}}
    _write_record(paths["record"], installing)
    try:
        _put(new_out, out, now[out] is not None)
        if new_rej is not None:
            _put(new_rej, rej, now[rej] is not None)
        elif now[rej] is not None:
            rej.unlink()  # the earlier result's rejected rows go with it
    finally:
        for t in (new_out, new_rej):
            if t is not None and t.exists():
                t.unlink()
    _fsync_folder(folder)
    files[out.name] = [fp_out] if fp_out else []
    if fp_rej is not None:
        files[rej.name] = [fp_rej]
    # every line is accounted for: the recovered rows are in the result, the rest in .rejected
    n_back = (
        out.read_bytes().count(b"\n") - 1 if csv_out else len(pd.read_parquet(out, columns=["t_s"]))
    )
    if n_back != len(good):  # pragma: no cover - the file just written
        raise InputError(f"{out}: holds {n_back} rows of {len(good)}; {part} kept")
    _write_record(paths["record"], {**meta, "state": "finished", "files": files})
    if not csv_out:
        part.unlink()
        _fsync_folder(folder)
    return {"rows": len(good), "rejected": bad, "results": out, "rejected_path": rej}


def _fsync_folder(folder: Path) -> None:
    with contextlib.suppress(OSError):
        fd = os.open(folder, os.O_RDONLY)
        try:
            os.fsync(fd)
        finally:
            os.close(fd)


def recover(output: str | Path, *, overwrite: bool = False) -> dict:
    """Convert ``<output>.partial.csv`` left by a killed live run to ``output`` (.parquet); rows
    that cannot be read go verbatim to ``<output>.rejected``; the partial file is deleted only
    when every line of it is in one of the two. For a ``.csv`` output (written as it goes) the
    rows that cannot be read (a NUL tail after a power loss, a cut last row) move to
    ``<output>.rejected`` the same way.

    Parameters
    ----------
    output : str or Path
        The ``.parquet`` (or ``.csv``) output of the killed run [path].
    overwrite : bool
        Kept for the command line; an existing result is replaced only when the killed run's
        record proves gripsense wrote it (the run itself was started to replace it).

    Returns
    -------
    dict
        ``results`` (the Parquet file), ``rows`` (rows recovered), ``rejected`` (``(line,
        bytes, reason)`` per row kept in ``rejected_path``).
    """
    del overwrite  # ownership is proven by the record, not asserted by a flag
    paths = output_paths(output)
    part = paths["rows"]
    if not part.exists():
        raise InputError(f"{part}: nothing to recover")
    with _folder_lock(part.parent):
        _refuse_busy(paths)
        try:
            fd = os.open(part, os.O_RDONLY)
        except OSError as e:
            raise InputError(f"{part}: cannot be read ({e.strerror or e})") from None
        try:
            _lock_run(fd)
            record = read_record(paths["results"])
            meta = {k: v for k, v in (record or {}).items() if k not in ("files", "fingerprint")}
            meta.pop("gripsense_live", None)
            meta.update(recovered_by=os.getpid())
            return _install(paths, record, meta)
        finally:
            os.close(fd)
