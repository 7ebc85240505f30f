"""Result folders and output files: written atomically, owned by proof, never mixed with other
files.

A result folder holds tables (Parquet), JSON documents and copies of small inputs, plus
``manifest.json``: the kind of result, the command, gripsense's version, the inputs with their
SHA-256, every file the folder's writer created and the SHA-256 of each (``sha256``). The
manifest is written last, so a folder without one is incomplete (a killed run) and is never
taken for a result. A single output file (a CSV, a report, a calibration) is recorded in
``.gripsense-outputs.json`` in its folder: name, kind, size and SHA-256.

Rules (``docs/reliability.md``):

* gripsense owns a file only while its bytes match the SHA-256 it recorded when it wrote it
  (a manifest's ``sha256`` or the folder's ``.gripsense-outputs.json``); what a file says
  about itself (a header, a "gripsense report" tag) proves nothing;
* a new folder is written as a temporary sibling and renamed into place (atomic); a new file
  is linked into place (which fails if the name appeared meanwhile);
* an existing folder is written into only if its manifest says it is gripsense's result of the
  same kind, every file it lists still has its recorded bytes, no file the new result writes is
  one the manifest does not list, **and** ``overwrite`` is set; then each file is replaced
  atomically, the files the old manifest listed and the new one does not are deleted (nothing
  else), the manifest last;
* the check before the work remembers what it found; the install re-checks under an advisory
  lock (``flock``) on the output's folder and goes ahead only if the output is still as it
  was then: of two runs racing for one output, the second is refused and nothing is lost;
* a folder that exists and is not empty and is not a gripsense result is refused; so is an
  output that is not a regular file (a device such as ``/dev/stdout``, a FIFO, a socket, a
  symbolic link).
"""

from __future__ import annotations

import contextlib
import errno
import hashlib
import json
import os
import shutil
import stat
import tempfile
from collections.abc import Callable, Iterator, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import pandas as pd

from gripsense._signals import signals_deferred
from gripsense.errors import InputError

__all__ = [
    "MANIFEST",
    "ResultFolder",
    "ResultWriter",
    "add_to_folder",
    "check_output_file",
    "check_output_folder",
    "file_sha256",
    "is_own_file",
    "read_manifest",
    "read_result_folder",
    "record_output",
    "user_mode",
    "write_file_atomic",
    "write_parquet",
    "write_result_folder",
]

MANIFEST = "manifest.json"
FORMAT = 1


def file_sha256(path: str | Path) -> str:
    """SHA-256 of a file, hex.

    Parameters
    ----------
    path : str or Path
        File to hash.

    Returns
    -------
    str
        64 hex digits.
    """
    h = hashlib.sha256()
    with open(path, "rb") as fh:
        for block in iter(lambda: fh.read(1 << 20), b""):
            h.update(block)
    return h.hexdigest()


def read_manifest(folder: str | Path) -> dict | None:
    """The manifest of a gripsense result folder, or None when *folder* has none (or it is not
    readable JSON).

    Parameters
    ----------
    folder : str or Path
        Folder to look into.

    Returns
    -------
    dict or None
        The manifest.
    """
    p = Path(folder) / MANIFEST
    try:
        doc = json.loads(p.read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return None
    return doc if isinstance(doc, dict) and doc.get("gripsense_result") == FORMAT else None


REGISTRY = ".gripsense-outputs.json"
"""gripsense's record of the single output files it wrote in a folder (name → kind, size,
SHA-256): the proof that a file is gripsense's own."""
REGISTRY_FORMAT = 1


@dataclass(frozen=True)
class _Claim:
    """What a run found at its output when it checked it, before its work.

    ``state`` is None for a new output (absent, or an empty folder), else the SHA-256 of the
    file (or of the result folder's manifest). The output is installed only if it is still in
    this state then, so a run never replaces what another run wrote meanwhile.
    """

    kind: str
    overwrite: bool
    state: str | None


_CLAIMS: dict[str, _Claim] = {}
"""Output path → what this process's check found there (consumed when the output is
installed)."""


def _key(path: str | Path) -> str:
    return os.path.abspath(path)


@contextlib.contextmanager
def _locked(folder: Path) -> Iterator[None]:
    """Hold an exclusive advisory lock (``flock``) on *folder* itself — no lock file is left
    behind — while an output in it is re-checked and installed. A killed holder releases it.
    """
    try:
        import fcntl
    except ImportError:  # no advisory locks (Windows): the no-clobber link/rename still refuse
        yield
        return
    try:
        fd = os.open(folder, os.O_RDONLY | getattr(os, "O_DIRECTORY", 0))
    except OSError as e:
        raise InputError(f"{folder}: cannot be opened to lock it ({e.strerror or e})") from None
    try:
        try:
            fcntl.flock(fd, fcntl.LOCK_EX)
        except OSError:  # a file system without flock: the no-clobber link/rename still refuse
            pass
        yield
    finally:
        os.close(fd)


def _changed_meanwhile(path: Path) -> InputError:
    return InputError(
        f"{path}: changed while this run worked (another run wrote it); this run's output was "
        "not installed — check that output, then run again (with --overwrite, in Python "
        "overwrite=True, to replace it)"
    )


def _not_regular(path: Path) -> InputError:
    return InputError(
        f"{path}: is not a regular file (a device, pipe, socket or symbolic link); gripsense "
        "writes a file through a temporary sibling renamed into place — give a file path"
    )


def _folder_state(folder: Path) -> str | None:
    """None for a missing or empty folder, the manifest's SHA-256 for a result folder, ``""``
    for anything else.
    """
    if not folder.is_dir():
        return "" if os.path.lexists(folder) else None
    try:
        entries = [p for p in folder.iterdir() if not p.name.startswith(".gripsense-")]
    except OSError:
        return ""
    if not entries:
        return None
    try:
        return file_sha256(folder / MANIFEST)
    except OSError:
        return ""


def _inside(folder: Path, name: str) -> bool:
    try:
        return folder.resolve() in (folder / name).resolve().parents
    except (OSError, RuntimeError):
        return False


def _verify_result_folder(
    folder: Path, kind: str, *, overwrite: bool, files: Sequence[str] = ()
) -> None:
    """Refuse unless *folder* may receive a result of *kind* (see :func:`check_output_folder`)."""
    if os.path.lexists(folder) and not folder.is_dir():
        raise InputError(f"{folder}: exists and is not a folder; give -o a folder path")
    if not folder.is_dir():
        return
    try:
        entries = [p for p in folder.iterdir() if not p.name.startswith(".gripsense-")]
    except PermissionError:
        raise InputError(f"{folder}: permission denied (cannot list the folder)") from None
    if not entries:
        return
    man = read_manifest(folder)
    if man is None:
        raise InputError(
            f"{folder}: not empty and not a gripsense result folder; give -o a new or "
            "empty folder (gripsense never writes among files it did not create)"
        )
    if man.get("kind") != kind:
        raise InputError(
            f"{folder}: holds a gripsense {man.get('kind')!r} result, not {kind!r}; "
            "give -o another folder"
        )
    if not overwrite:
        raise InputError(
            f"{folder}: holds an earlier {kind} result; add --overwrite (in Python: "
            "overwrite=True) to replace it, or give -o another folder"
        )
    listed = [str(n) for n in man.get("files", [])]
    hashes = man.get("sha256")
    if not isinstance(hashes, dict) or any(not isinstance(hashes.get(n), str) for n in listed):
        raise InputError(
            f"{folder}: its {MANIFEST} records no fingerprint of the files (an older gripsense "
            "wrote it), so gripsense cannot prove they are its own — delete the folder "
            "yourself or give -o another folder"
        )
    for name in listed:
        p = folder / name
        if not _inside(folder, name):
            raise InputError(
                f"{folder / MANIFEST}: lists {name!r}, outside the folder; give -o another folder"
            )
        if not os.path.lexists(p):
            continue  # the user removed it: nothing to protect
        if p.is_symlink() or not p.is_file() or file_sha256(p) != hashes[name]:
            raise InputError(
                f"{p}: changed since gripsense wrote it; --overwrite replaces only files whose "
                f"bytes still match what gripsense recorded — move it out of {folder} or give "
                "-o another folder"
            )
    for name in files:
        p = folder / name
        if name not in listed and os.path.lexists(p):
            raise InputError(
                f"{p}: not written by gripsense (its {MANIFEST} does not list it); move it out "
                f"of {folder} or give -o another folder"
            )


def check_output_folder(
    folder: str | Path, kind: str, *, overwrite: bool, files: Sequence[str] = ()
) -> None:
    """Check before any work that *folder* may receive a result of *kind*, and remember what is
    there: the result is installed only if the folder is still in that state then.

    Parameters
    ----------
    folder : str or Path
        Output folder.
    kind : str
        Result kind (``"friction"``, ``"fleet"`` …).
    overwrite : bool
        Whether the user asked to replace an earlier result of the same kind.
    files : list of str
        Names (relative to *folder*) the result will hold, when known before the work (e.g.
        ``report.html``): a file of that name that gripsense did not write is refused now.

    Raises
    ------
    InputError
        When the path is not a folder; the folder holds something that is not a gripsense
        result of this kind, or holds one and *overwrite* is not set; a file the manifest lists
        changed since gripsense wrote it (its SHA-256 differs) or the manifest records no
        fingerprints; a file of *files* is there and not the result's; or the parent cannot be
        written.
    """
    _check_folder(Path(folder), kind, overwrite=overwrite, files=files, keep_claim=False)


def _check_folder(
    folder: Path, kind: str, *, overwrite: bool, files: Sequence[str], keep_claim: bool
) -> None:
    _verify_result_folder(folder, kind, overwrite=overwrite, files=files)
    writable_parent(folder, folder if folder.is_dir() else None)
    claim = _Claim(kind, overwrite, _folder_state(folder))
    old = _CLAIMS.get(_key(folder))
    if not (keep_claim and old is not None and old.kind == kind):
        _CLAIMS[_key(folder)] = claim


def writable_parent(path: Path, parent: Path | None = None) -> Path:
    """The nearest existing folder above *path* (or *parent*), checked to be a folder gripsense
    can write in; an :class:`InputError` naming *path* otherwise.

    Parameters
    ----------
    path : Path
        The output to be created.
    parent : Path, optional
        The folder to check instead of searching upwards from *path*.

    Returns
    -------
    Path
        That folder.
    """
    if parent is None:
        parent = path.parent
        while not parent.exists() and parent != parent.parent:
            parent = parent.parent
        if not parent.is_dir():
            raise InputError(f"{path}: {parent} is not a folder")
    if not os.access(parent, os.W_OK | os.X_OK):
        raise InputError(f"{path}: permission denied ({parent} is not writable)")
    return parent


def _same_file(a: Path, b: Path) -> bool:
    try:
        return a.resolve() == Path(b).resolve()
    except OSError:
        return False


def _read_registry(folder: Path) -> dict[str, dict]:
    """The records of *folder*'s registry (name → record); ``{}`` when there is none.

    Raises
    ------
    InputError
        When a file of the registry's name is there and is not one.
    """
    p = folder / REGISTRY
    if not os.path.lexists(p):
        return {}
    try:
        doc = json.loads(p.read_text(encoding="utf-8"))
    except (OSError, ValueError):
        doc = None
    if (
        p.is_symlink()
        or not isinstance(doc, dict)
        or doc.get("gripsense_outputs") != REGISTRY_FORMAT
        or not isinstance(doc.get("files"), dict)
    ):
        raise InputError(
            f"{p}: not gripsense's record of its outputs (damaged, or not gripsense's); move "
            "it away — gripsense will then refuse to replace the files it recorded"
        )
    return {str(k): v for k, v in doc["files"].items() if isinstance(v, dict)}


def _replace_json(path: Path, doc: dict, indent: int) -> None:
    """Write *doc* as JSON to *path* through a temporary sibling renamed over it (the user's
    umask).
    """
    fd, tmp = tempfile.mkstemp(prefix=f".{path.stem}.", suffix=".gripsense-tmp", dir=path.parent)
    try:
        with os.fdopen(fd, "w", encoding="utf-8") as fh:
            fh.write(json.dumps(doc, indent=indent) + "\n")
        user_mode(tmp)
        os.replace(tmp, path)
    finally:
        if os.path.exists(tmp):
            os.unlink(tmp)


def _write_registry(folder: Path, files: dict[str, dict]) -> None:
    doc = {"gripsense_outputs": REGISTRY_FORMAT, "files": dict(sorted(files.items()))}
    _replace_json(folder / REGISTRY, doc, 1)


def _record_file(path: Path, kind: str, sha: str, size: int) -> None:
    """Add *path* to its folder's registry (call under :func:`_locked`); records of files
    that are gone are dropped.
    """
    files = _read_registry(path.parent)
    files = {n: r for n, r in files.items() if os.path.lexists(path.parent / n)}
    files[path.name] = {"kind": kind, "bytes": size, "sha256": sha}
    _write_registry(path.parent, files)


def _file_owner(path: Path) -> str | None:
    """The kind gripsense recorded for *path* when the file's bytes still match the record;
    None otherwise (no record, a changed file, not a regular file).
    """
    try:
        st = os.lstat(path)
        rec = _read_registry(path.parent).get(path.name)
    except (OSError, InputError):
        return None
    if rec is None or not stat.S_ISREG(st.st_mode) or rec.get("bytes") != st.st_size:
        return None
    try:
        if file_sha256(path) != rec.get("sha256"):
            return None
    except OSError:
        return None
    return str(rec.get("kind"))


def record_output(path: str | Path, kind: str) -> None:
    """Record a file gripsense wrote in place (not through :func:`write_file_atomic`, e.g. a
    recording appended as it goes) as its own output of *kind*, with its SHA-256 as it is now,
    so a later ``--overwrite`` may replace it while its bytes still match.

    Parameters
    ----------
    path : str or Path
        The file, complete.
    kind : str
        Output kind.
    """
    path = Path(path)
    try:
        st = os.lstat(path)
        if not stat.S_ISREG(st.st_mode):
            raise _not_regular(path)
        sha = file_sha256(path)
        with _locked(path.parent):
            _record_file(path, kind, sha, st.st_size)
    except OSError as e:
        raise InputError(f"{path}: cannot record it ({e.strerror or e})") from None


def is_own_file(path: str | Path, kind: str, *, header: list[str] | None = None) -> bool:
    """Whether *path* is a file gripsense wrote as output of *kind* and nobody changed since.

    The proof is gripsense's record in the file's folder (``.gripsense-outputs.json``: name,
    kind, size and SHA-256 of every single output file it wrote there); what a file says about
    itself (a header, a "gripsense report" tag) proves nothing.

    Parameters
    ----------
    path : str or Path
        The existing file.
    kind : str
        Output kind (``"epochs"``, ``"report"`` …).
    header : list of str, optional
        Ignored (a CSV header is no proof); kept for existing callers.

    Returns
    -------
    bool
        True only when the record names *kind* and the file's bytes match it.
    """
    del header
    return _file_owner(Path(path)) == kind


def check_output_file(
    path: str | Path,
    kind: str,
    *,
    overwrite: bool,
    inputs: Sequence[str | Path] = (),
    header: list[str] | None = None,
) -> None:
    """Check before any work that *path* may receive an output file of *kind*, and remember
    what is there: the file is installed only if the path is still in that state then.

    Parameters
    ----------
    path : str or Path
        Output file.
    kind : str
        Output kind.
    overwrite : bool
        Whether the user asked to replace an earlier output of the same kind.
    inputs : list
        The command's input files: an output may never be one of them.
    header : list of str, optional
        Ignored (a CSV header is no proof of ownership; :func:`is_own_file`).

    Raises
    ------
    InputError
        When the path is a folder, an input, or not a regular file (device, FIFO, socket,
        symbolic link); exists without *overwrite*; exists and gripsense has no record of
        writing it as *kind* with these bytes; or its folder cannot be created or written.
    """
    del header
    path = Path(path)
    for inp in inputs:
        if _same_file(path, Path(inp)):
            raise InputError(f"{path}: is also an input; give the output another name")
    if path.is_dir():
        raise InputError(f"{path}: is a folder; give a file name")
    if path.name.startswith(".gripsense-"):
        raise InputError(f"{path}: names starting with .gripsense- are gripsense's own records")
    state = None
    if os.path.lexists(path):
        if not stat.S_ISREG(os.lstat(path).st_mode):
            raise _not_regular(path)
        if not overwrite:
            raise InputError(
                f"{path}: exists; add --overwrite (in Python: overwrite=True) to replace it, or "
                "give another name"
            )
        owner = _file_owner(path)
        if owner is None:
            raise InputError(
                f"{path}: exists and gripsense has no record of writing it (or it changed "
                "since); gripsense replaces only its own unchanged files — move it away or "
                "give another name"
            )
        if owner != kind:
            raise InputError(
                f"{path}: holds a gripsense {owner} output, not {kind}; give another name"
            )
        state = file_sha256(path)
    writable_parent(path)
    _CLAIMS[_key(path)] = _Claim(kind, overwrite, state)


def _umask() -> int:
    """The process's umask (read without changing it where the system says it)."""
    try:
        with open("/proc/self/status", encoding="ascii") as fh:
            for line in fh:
                if line.startswith("Umask:"):
                    return int(line.split()[1], 8)
    except (OSError, ValueError):
        pass
    mask = os.umask(0o022)  # elsewhere: set and restore (the only portable way)
    os.umask(mask)
    return mask


def user_mode(path: str | Path, *, folder: bool = False) -> None:
    """Give a file (or folder) that gripsense created through a private temporary name the mode
    any other tool's output gets: 0666 (0777 for a folder) less the user's umask — ``mkstemp``
    and ``mkdtemp`` create 0600 / 0700.

    Parameters
    ----------
    path : str or Path
        The file or folder.
    folder : bool
        *path* is a folder.
    """
    os.chmod(path, (0o777 if folder else 0o666) & ~_umask())


def write_file_atomic(
    path: str | Path, write: Callable[[Path], object], *, kind: str | None = None
) -> Path:
    """Write a file through a temporary sibling installed when complete, so a reader (or a
    crash) never sees half a file; missing parent folders are created.

    The install re-checks the path under a lock on its folder: it must be as the command's
    :func:`check_output_file` found it (a new file still absent — it is linked in, which fails
    if anything appeared meanwhile; an earlier output still with the bytes gripsense recorded).
    Without a check, only a new file or gripsense's own unchanged output is replaced. The file
    is then recorded as gripsense's (:func:`is_own_file`).

    Parameters
    ----------
    path : str or Path
        The file.
    write : callable
        ``write(tmp_path)`` writes the content to the temporary path.
    kind : str, optional
        Output kind recorded for the file when no :func:`check_output_file` named it.

    Returns
    -------
    Path
        The file written.
    """
    path = Path(path)
    claim = _CLAIMS.pop(_key(path), None)  # what this run's check found (used once)
    if os.path.lexists(path) and not stat.S_ISREG(os.lstat(path).st_mode):
        if path.is_dir():
            raise InputError(f"{path}: is a folder; give a file name")
        raise _not_regular(path)
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        fd, tmp = tempfile.mkstemp(
            prefix=f".{path.name}.", suffix=".gripsense-tmp", dir=path.parent
        )
        os.close(fd)
    except OSError as e:
        raise InputError(f"{path}: cannot write ({e.strerror or e})") from None
    try:
        write(Path(tmp))
        user_mode(tmp)
        sha, size = file_sha256(tmp), os.path.getsize(tmp)
        with _locked(path.parent):
            current = _file_state(path)
            if claim is not None and current != claim.state:
                raise _changed_meanwhile(path)
            rec_kind = claim.kind if claim is not None else (kind or "file")
            _read_registry(path.parent)  # a damaged record is refused before anything changes
            if current is None:
                _link_new(Path(tmp), path)
            else:
                owner = _file_owner(path)
                if owner is None or (claim is None and kind is not None and owner != kind):
                    raise InputError(
                        f"{path}: exists and gripsense has no record of writing it (or it "
                        "changed since); gripsense replaces only its own unchanged files — "
                        "move it away or give another name"
                    )
                os.replace(tmp, path)
            _record_file(path, rec_kind, sha, size)
    except OSError as e:
        raise InputError(f"{path}: cannot write ({e.strerror or e})") from None
    finally:
        if os.path.exists(tmp):
            os.unlink(tmp)
    return path


def _file_state(path: Path) -> str | None:
    """None for a missing file, its SHA-256 for a regular file; refuses anything else."""
    if not os.path.lexists(path):
        return None
    if not stat.S_ISREG(os.lstat(path).st_mode):
        raise _not_regular(path)
    return file_sha256(path)


def _link_new(tmp: Path, path: Path) -> None:
    """Install *tmp* as the new file *path*; refuse if *path* appeared (even from a process
    that takes no lock): a hard link never replaces an existing name.
    """
    try:
        os.link(tmp, path)
    except FileExistsError:
        raise _changed_meanwhile(path) from None
    except OSError as e:
        if e.errno not in (errno.EPERM, errno.EOPNOTSUPP, errno.ENOTSUP, errno.EXDEV, errno.EMLINK):
            raise
        if os.path.lexists(path):  # no hard links here: the lock alone orders gripsense runs
            raise _changed_meanwhile(path) from None
        os.replace(tmp, path)
        return
    os.unlink(tmp)


def write_parquet(df: pd.DataFrame, path: str | Path, kind: str | None = None) -> None:
    """Write *df* to Parquet without its index; dictionary encoding only for the columns that
    are not floating point (measured values are nearly all distinct: trying a dictionary on
    them cost ~2/3 of the writing time of a wheel table and saved no space).

    Parameters
    ----------
    df : pandas.DataFrame
        The table.
    path : str or Path
        Output file.
    kind : str, optional
        Output kind recorded as ``gripsense_kind`` in the file's metadata
        (see :func:`is_own_file`).
    """
    import pyarrow as pa
    import pyarrow.parquet as pq

    table = pa.Table.from_pandas(df, preserve_index=False)
    if kind is not None:
        meta = dict(table.schema.metadata or {})
        meta[b"gripsense_kind"] = kind.encode()
        table = table.replace_schema_metadata(meta)
    coded = [f.name for f in table.schema if not pa.types.is_floating(f.type)]
    pq.write_table(table, path, use_dictionary=coded)


@dataclass
class ResultFolder:
    """What a result folder holds once read back.

    Attributes
    ----------
    path : Path
        The folder.
    manifest : dict
        Its manifest (empty for folders written before manifests existed).
    tables : dict
        Name (file stem) → DataFrame, for every ``.parquet`` file listed.
    documents : dict
        Name (file stem) → parsed JSON, for every ``.json`` file listed (not the manifest).
    files : dict
        Name (file name) → Path, for every other file listed.
    """

    path: Path
    manifest: dict
    tables: dict[str, pd.DataFrame] = field(default_factory=dict)
    documents: dict[str, Any] = field(default_factory=dict)
    files: dict[str, Path] = field(default_factory=dict)


class ResultWriter:
    """Build a result folder in a temporary sibling and install it atomically on success.

    Use as a context manager::

        with ResultWriter(out, "fleet", overwrite=False, command="…") as tmp:
            ...write files below tmp...
        # on a clean exit the files are installed into `out` and listed in its manifest;
        # on an exception nothing in `out` changes and the temporary folder is removed

    Parameters
    ----------
    folder : str or Path
        Output folder.
    kind : str
        Result kind, recorded in the manifest and checked on reuse.
    overwrite : bool
        Replace an earlier result of the same kind in *folder*.
    command : str
        Command line recorded in the manifest.
    inputs : list, optional
        Input files recorded with their size and SHA-256.
    extra : dict, optional
        More manifest entries.
    """

    def __init__(
        self,
        folder: str | Path,
        kind: str,
        *,
        overwrite: bool = False,
        command: str = "",
        inputs: Sequence[str | Path] | None = None,
        extra: dict | None = None,
    ):
        self.folder = Path(folder)
        self.kind = kind
        self.overwrite = overwrite
        self.command = command
        self.inputs = list(inputs or [])
        self.extra = dict(extra or {})
        self.tmp: Path | None = None
        self.files: list[str] = []
        _check_folder(self.folder, kind, overwrite=overwrite, files=(), keep_claim=True)

    def __enter__(self) -> Path:
        parent = self.folder.parent
        try:
            parent.mkdir(parents=True, exist_ok=True)
            with signals_deferred():  # the folder and its name together, or neither
                self.tmp = Path(
                    tempfile.mkdtemp(prefix=f".gripsense-{self.folder.name}-", dir=parent)
                )
        except OSError as e:
            raise InputError(
                f"{self.folder}: cannot create the output folder ({e.strerror or e})"
            ) from None
        except BaseException:  # a signal that waited for the folder: it goes with the run
            _remove_tree(self.tmp)
            raise
        return self.tmp

    def __exit__(self, exc_type, exc, tb) -> None:
        # a signal waits until the result is installed (or its temporary folder removed); one
        # that lands before the wait begins still finds the temporary folder removed
        try:
            with signals_deferred():
                try:
                    if exc_type is None:
                        self._finish()
                finally:
                    _CLAIMS.pop(_key(self.folder), None)  # a failed run's check is not the next's
        finally:
            _remove_tree(self.tmp)

    def _finish(self) -> None:
        from gripsense._version import __version__

        tmp = self.tmp
        assert tmp is not None
        (tmp / REGISTRY).unlink(missing_ok=True)  # the manifest is the folder's record
        found = sorted(p for p in tmp.rglob("*") if p.is_file())
        self.files = [p.relative_to(tmp).as_posix() for p in found]
        manifest = {
            "gripsense_result": FORMAT,
            "kind": self.kind,
            "gripsense_version": __version__,
            "command": self.command,
            "inputs": [_describe_input(p) for p in self.inputs],
            "files": self.files,
            "sha256": {n: file_sha256(p) for n, p in zip(self.files, found, strict=True)},
            **self.extra,
        }
        try:
            (tmp / MANIFEST).write_text(json.dumps(manifest, indent=2) + "\n", encoding="utf-8")
            user_mode(tmp, folder=True)  # a new folder is this one, renamed
            with _locked(self.folder.parent):
                claim = _CLAIMS.pop(_key(self.folder), None)
                if claim is not None and _folder_state(self.folder) != claim.state:
                    raise _changed_meanwhile(self.folder)
                overwrite = claim.overwrite if claim is not None else self.overwrite
                _verify_result_folder(self.folder, self.kind, overwrite=overwrite, files=self.files)
                _install(tmp, self.folder)
        except OSError as e:
            raise InputError(
                f"{self.folder}: cannot write the result ({e.strerror or e})"
            ) from None


def _remove_tree(path: Path | None) -> None:
    """Remove a temporary folder of gripsense's whole, even when a signal lands during the
    removal (the removal is finished, then the signal raised).
    """
    pending: BaseException | None = None
    while path is not None:
        try:
            shutil.rmtree(path, ignore_errors=True)
            break
        except BaseException as e:  # KeyboardInterrupt / SystemExit mid-way: finish first
            pending = pending or e
    if pending is not None:
        raise pending


def write_result_folder(
    folder: str | Path,
    kind: str,
    *,
    tables: dict[str, pd.DataFrame] | None = None,
    documents: Mapping[str, Any] | None = None,
    copies: Mapping[str, str | Path] | None = None,
    texts: dict[str, str] | None = None,
    inputs: Sequence[str | Path] | None = None,
    command: str = "",
    extra: dict | None = None,
    overwrite: bool = False,
) -> dict[str, Path]:
    """Write a result folder of tables, JSON documents, texts and copies atomically (see
    :class:`ResultWriter` and the module documentation).

    Parameters
    ----------
    folder : str or Path
        Output folder.
    kind : str
        Result kind, recorded in the manifest and checked on reuse.
    tables : dict, optional
        File stem → DataFrame, written as ``<stem>.parquet``.
    documents : dict, optional
        File stem → JSON-ready object, written as ``<stem>.json``.
    copies : dict, optional
        File name → source path, copied byte for byte (e.g. the vehicle file).
    texts : dict, optional
        File name → text (UTF-8), e.g. ``report.html``.
    inputs : list, optional
        Input files, recorded with their size and SHA-256.
    command : str
        The command line or call that made the result.
    extra : dict, optional
        More manifest entries (e.g. ``{"result": "axle"}``).
    overwrite : bool
        Replace an earlier result of the same kind in *folder*.

    Returns
    -------
    dict
        Name (stem, or file name for copies and texts) → path of every file written, plus
        ``manifest``.
    """
    folder = Path(folder)
    written: dict[str, str] = {}
    with ResultWriter(
        folder, kind, overwrite=overwrite, command=command, inputs=inputs, extra=extra
    ) as tmp:
        for stem, df in (tables or {}).items():
            write_parquet(df, tmp / f"{stem}.parquet")
            written[stem] = f"{stem}.parquet"
        for stem, doc in (documents or {}).items():
            (tmp / f"{stem}.json").write_text(
                json.dumps(doc, indent=2, default=str) + "\n", encoding="utf-8"
            )
            written[stem] = f"{stem}.json"
        for name, src in (copies or {}).items():
            shutil.copyfile(src, tmp / name)
            written[name] = name
        for name, text in (texts or {}).items():
            (tmp / name).write_text(text, encoding="utf-8")
            written[name] = name
    out = {k: folder / v for k, v in written.items()}
    out["manifest"] = folder / MANIFEST
    return out


def add_to_folder(folder: str | Path, name: str, text: str, *, overwrite: bool = False) -> Path:
    """Add (or, with *overwrite*, replace) one text file in a gripsense result folder and list it
    with its SHA-256 in the folder's manifest, so a later ``--overwrite`` of the folder replaces
    it too.

    A file of that name is replaced only when the manifest lists it and its bytes still match
    the recorded SHA-256: a user's own file of that name (or gripsense's, edited) is refused.

    Parameters
    ----------
    folder : str or Path
        A complete gripsense result folder.
    name : str
        File name (no folders).
    text : str
        Content (UTF-8).
    overwrite : bool
        Replace the file when it is gripsense's, unchanged.

    Returns
    -------
    Path
        The file written.
    """
    folder = Path(folder)
    target = folder / name
    if read_manifest(folder) is None:
        raise InputError(f"{folder}: not a result folder of gripsense (no {MANIFEST})")
    try:
        with _locked(folder.parent):
            man = read_manifest(folder)
            if man is None:
                raise InputError(f"{folder}: not a result folder of gripsense (no {MANIFEST})")
            listed = [str(n) for n in man.get("files", [])]
            got = man.get("sha256")
            hashes: dict = got if isinstance(got, dict) else {}
            if os.path.lexists(target):
                if (
                    name not in listed
                    or target.is_symlink()
                    or not target.is_file()
                    or file_sha256(target) != hashes.get(name)
                ):
                    raise InputError(
                        f"{target}: not written by gripsense, or changed since (its "
                        f"{MANIFEST} has no matching fingerprint); move it away or give -o "
                        "another file"
                    )
                if not overwrite:
                    raise InputError(
                        f"{target}: exists; add --overwrite (in Python: overwrite=True) to "
                        "replace it"
                    )
            fd, tmp = tempfile.mkstemp(prefix=f".{name}.", suffix=".gripsense-tmp", dir=folder)
            try:
                with os.fdopen(fd, "w", encoding="utf-8") as fh:
                    fh.write(text)
                user_mode(tmp)
                sha = file_sha256(tmp)
                if os.path.lexists(target):
                    os.replace(tmp, target)
                else:
                    _link_new(Path(tmp), target)
            finally:
                if os.path.exists(tmp):
                    os.unlink(tmp)
            man["files"] = sorted({*listed, name})
            man["sha256"] = {**hashes, name: sha}
            _replace_json(folder / MANIFEST, man, 2)
    except OSError as e:
        raise InputError(f"{target}: cannot write ({e.strerror or e})") from None
    return target


def _describe_input(p: str | Path) -> dict:
    p = Path(p)
    if not p.is_file():
        return {"path": str(p)}
    return {"path": str(p), "bytes": p.stat().st_size, "sha256": file_sha256(p)}


def _install(tmp: Path, folder: Path) -> None:
    """Move the finished files of *tmp* into *folder*: a rename of the whole folder when it does
    not exist yet, else file by file with the old manifest's leftovers removed (only files the
    old manifest lists; folders only when they became empty).
    """
    if not folder.exists():
        try:
            os.rename(tmp, folder)  # onto an empty folder at most: a non-empty one refuses
        except OSError as e:
            if e.errno in (errno.EEXIST, errno.ENOTEMPTY, errno.ENOTDIR):
                raise _changed_meanwhile(folder) from None
            raise
        tmp.mkdir()  # so that the caller's cleanup has something to remove
        return
    old = read_manifest(folder) or {}
    new = json.loads((tmp / MANIFEST).read_text(encoding="utf-8"))
    (folder / MANIFEST).unlink(missing_ok=True)  # incomplete from here until the new manifest
    for name in new["files"]:
        target = folder / name
        target.parent.mkdir(parents=True, exist_ok=True)
        os.replace(tmp / name, target)
    for name in set(old.get("files", [])) - set(new["files"]):
        target = (folder / name).resolve()
        if target.is_file() and folder.resolve() in target.parents:
            target.unlink()
            for d in target.parents:
                if d == folder.resolve() or any(d.iterdir()):
                    break
                d.rmdir()
    os.replace(tmp / MANIFEST, folder / MANIFEST)


def read_result_folder(folder: str | Path, kind: str | None = None) -> ResultFolder:
    """Read back what :func:`write_result_folder` wrote.

    Parameters
    ----------
    folder : str or Path
        Result folder.
    kind : str, optional
        Expected kind; an error names the difference.

    Returns
    -------
    ResultFolder
        Manifest, tables, documents and other files.
    """
    folder = Path(folder)
    if not folder.is_dir():
        raise InputError(f"{folder}: no such result folder")
    man = read_manifest(folder)
    if man is None:
        raise InputError(
            f"{folder}: not a result folder of gripsense (no {MANIFEST}: not written by "
            "gripsense, or a run stopped before it finished)"
        )
    if kind is not None and man.get("kind") != kind:
        raise InputError(f"{folder}: holds a {man.get('kind')!r} result, not {kind!r}")
    res = ResultFolder(path=folder, manifest=man)
    for name in man.get("files", []):
        p = folder / name
        if not p.is_file():
            raise InputError(f"{folder}: {name} is listed in the manifest but missing")
        try:
            if "/" in name:
                res.files[name] = p  # nested (e.g. partitioned tables): read on demand
            elif name.endswith(".parquet"):
                res.tables[name[: -len(".parquet")]] = pd.read_parquet(p)
            elif name.endswith(".json"):
                res.documents[name[: -len(".json")]] = json.loads(p.read_text(encoding="utf-8"))
            else:
                res.files[name] = p
        except (OSError, ValueError) as e:
            raise InputError(f"{p}: cannot be read back ({e})") from None
    return res
