"""Result folders: written atomically with a manifest, read back, never mixed with other files.

A result folder holds tables (Parquet), JSON documents and copies of small inputs, plus
``manifest.json``: the kind of result, the command, gripsense's version, the inputs with their
SHA-256 and every file the folder's writer created. The manifest is written last, so a folder
without one is incomplete (a killed run) and is never taken for a result.

Rules (``docs/reliability.md``):

* a new folder is written as a temporary sibling and renamed into place (atomic);
* an existing folder is written into only if its manifest says it is gripsense's result of the
  same kind **and** ``overwrite`` is set; then each file is replaced atomically, the files the
  old manifest listed and the new one does not are deleted (nothing else), the manifest last;
* a folder that exists and is not empty and is not a gripsense result is refused.
"""

from __future__ import annotations

import hashlib
import json
import os
import shutil
import tempfile
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import pandas as pd

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


def check_output_folder(folder: str | Path, kind: str, *, overwrite: bool) -> None:
    """Check before any work that *folder* may receive a result of *kind*.

    Parameters
    ----------
    folder : str or Path
        Output folder.
    kind : str
        Result kind (``"friction"``, ``"fleet"`` …).
    overwrite : bool
        Whether the user asked to replace an earlier result of the same kind.

    Raises
    ------
    InputError
        When the path is a file, the folder holds something that is not a gripsense result of
        this kind, or holds one and *overwrite* is not set, or the parent cannot be written.
    """
    folder = Path(folder)
    if folder.exists() and not folder.is_dir():
        raise InputError(f"{folder}: exists and is not a folder; give -o a folder path")
    if folder.is_dir():
        try:
            entries = [p for p in folder.iterdir() if not p.name.startswith(".gripsense-")]
        except PermissionError:
            raise InputError(f"{folder}: permission denied (cannot list the folder)") from None
        if entries:
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
                    f"{folder}: holds an earlier {kind} result; add --overwrite to replace it "
                    "or give -o another folder"
                )
        parent = folder
    else:
        parent = folder.parent
        while not parent.exists() and parent != parent.parent:
            parent = parent.parent
        if not parent.is_dir():
            raise InputError(f"{folder}: {parent} is not a folder")
    if not os.access(parent, os.W_OK | os.X_OK):
        raise InputError(f"{folder}: permission denied ({parent} is not writable)")


def _same_file(a: Path, b: Path) -> bool:
    try:
        return a.resolve() == Path(b).resolve()
    except OSError:
        return False


def is_own_file(path: str | Path, kind: str, *, header: list[str] | None = None) -> bool:
    """Whether *path* is a file gripsense wrote as output of *kind*.

    Parquet files carry ``gripsense_kind`` in their metadata; CSV files are recognised by their
    header (*header*); other formats (HTML, JSON, PNG, ``.tir``) carry ``gripsense <kind>`` in
    their first bytes (a generator tag, a key, a PNG text chunk, a header comment).

    Parameters
    ----------
    path : str or Path
        The existing file.
    kind : str
        Output kind (``"epochs"``, ``"report"`` …).
    header : list of str, optional
        The column names a CSV of this kind starts with.

    Returns
    -------
    bool
        True only when the file is recognisably gripsense's output of that kind.
    """
    path = Path(path)
    try:
        if path.suffix.lower() == ".parquet":
            import pyarrow.parquet as pq

            meta = pq.read_schema(path).metadata or {}
            return meta.get(b"gripsense_kind") == kind.encode()
        with open(path, "rb") as fh:
            head = fh.read(65536)
    except (OSError, ValueError):
        return False
    if header is not None:
        for line in head.decode("utf-8", "replace").splitlines():
            if line.startswith("#") or not line.strip():
                continue
            return line.strip().split(",") == list(header)
        return False
    return f"gripsense {kind}".encode() in head


def check_output_file(
    path: str | Path,
    kind: str,
    *,
    overwrite: bool,
    inputs: Sequence[str | Path] = (),
    header: list[str] | None = None,
) -> None:
    """Check before any work that *path* may receive an output file of *kind*.

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
        CSV header of this kind (:func:`is_own_file`).

    Raises
    ------
    InputError
        When the path is a folder or an input, exists without *overwrite* or is not
        gripsense's output of this kind, or its folder cannot be created or written.
    """
    path = Path(path)
    for inp in inputs:
        if _same_file(path, Path(inp)):
            raise InputError(f"{path}: is also an input; give the output another name")
    if path.is_dir():
        raise InputError(f"{path}: is a folder; give a file name")
    if path.exists():
        if not overwrite:
            raise InputError(f"{path}: exists; add --overwrite to replace it, or give another name")
        if not is_own_file(path, kind, header=header):
            raise InputError(
                f"{path}: exists and is not a gripsense {kind} output; gripsense overwrites only "
                "its own files — give another name"
            )
    parent = path.parent
    while not parent.exists() and parent != parent.parent:
        parent = parent.parent
    if not parent.is_dir():
        raise InputError(f"{path}: {parent} is not a folder")
    if not os.access(parent, os.W_OK | os.X_OK):
        raise InputError(f"{path}: permission denied ({parent} is not writable)")


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


def write_file_atomic(path: str | Path, write) -> Path:
    """Write a file through a temporary sibling renamed into place, so a reader (or a crash)
    never sees half a file; missing parent folders are created.

    Parameters
    ----------
    path : str or Path
        The file.
    write : callable
        ``write(tmp_path)`` writes the content to the temporary path.

    Returns
    -------
    Path
        The file written.
    """
    path = Path(path)
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
        os.replace(tmp, path)
    except OSError as e:
        raise InputError(f"{path}: cannot write ({e.strerror or e})") from None
    finally:
        if os.path.exists(tmp):
            os.unlink(tmp)
    return path


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
        check_output_folder(self.folder, kind, overwrite=overwrite)

    def __enter__(self) -> Path:
        parent = self.folder.parent
        try:
            parent.mkdir(parents=True, exist_ok=True)
            self.tmp = Path(tempfile.mkdtemp(prefix=f".gripsense-{self.folder.name}-", dir=parent))
        except OSError as e:
            raise InputError(
                f"{self.folder}: cannot create the output folder ({e.strerror or e})"
            ) from None
        return self.tmp

    def __exit__(self, exc_type, exc, tb) -> None:
        try:
            if exc_type is None:
                self._finish()
        finally:
            if self.tmp is not None:
                shutil.rmtree(self.tmp, ignore_errors=True)

    def _finish(self) -> None:
        from gripsense._version import __version__

        tmp = self.tmp
        self.files = sorted(p.relative_to(tmp).as_posix() for p in tmp.rglob("*") if p.is_file())
        manifest = {
            "gripsense_result": FORMAT,
            "kind": self.kind,
            "gripsense_version": __version__,
            "command": self.command,
            "inputs": [_describe_input(p) for p in self.inputs],
            "files": self.files,
            **self.extra,
        }
        try:
            (tmp / MANIFEST).write_text(json.dumps(manifest, indent=2) + "\n", encoding="utf-8")
            user_mode(tmp, folder=True)  # a new folder is this one, renamed
            _install(tmp, self.folder)
        except OSError as e:
            raise InputError(
                f"{self.folder}: cannot write the result ({e.strerror or e})"
            ) from None


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
    in the folder's manifest, so a later ``--overwrite`` of the folder replaces it too.

    Parameters
    ----------
    folder : str or Path
        A complete gripsense result folder.
    name : str
        File name (no folders).
    text : str
        Content (UTF-8).
    overwrite : bool
        Replace the file when the manifest already lists it.

    Returns
    -------
    Path
        The file written.
    """
    folder = Path(folder)
    man = read_manifest(folder)
    if man is None:
        raise InputError(f"{folder}: not a result folder of gripsense (no {MANIFEST})")
    target = folder / name
    if target.exists():
        if name not in man.get("files", []):
            raise InputError(f"{target}: exists and was not written by gripsense; give -o")
        if not overwrite:
            raise InputError(f"{target}: exists; add --overwrite to replace it")
    write_file_atomic(target, lambda tmp: tmp.write_text(text, encoding="utf-8"))
    if name not in man["files"]:
        man["files"] = sorted([*man["files"], name])
        write_file_atomic(
            folder / MANIFEST,
            lambda tmp: tmp.write_text(json.dumps(man, indent=2) + "\n", encoding="utf-8"),
        )
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
        os.rename(tmp, folder)
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
