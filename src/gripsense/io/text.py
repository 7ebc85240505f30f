"""Inputs read once and bounded, and text and TOML files read with one set of clear errors
(file named, cause, how to fix).

Every input gripsense reads goes through :class:`InputStream` (logs) or :func:`read_bytes`
(every other file): a regular file or a pipe (``<(cat log)``, a FIFO, ``/dev/stdin``) is read
**once**, in chunks, gzip decompressed on the fly; the first bytes a reader looks at to
recognise the format (:meth:`InputStream.peek`) are kept and the read continues from them, so
nothing is read twice and a pipe loses nothing. Every read is bounded: by a size
(``max_bytes``, decompressed) and for line-based logs by a number of lines (``max_lines``).
Device files (``/dev/zero``, a terminal), sockets and folders are refused in one line.
"""

from __future__ import annotations

import io
import os
import stat
import sys
import tomllib
import zlib
from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import IO

from gripsense.errors import InputError

__all__ = [
    "MAX_BYTES",
    "MAX_LINES",
    "InputStream",
    "ReadInput",
    "input_kind",
    "read_bytes",
    "read_text",
    "read_toml",
]

MAX_BYTES = 1 << 30
"""Default largest (decompressed) size read from one input [bytes] (``--max-bytes``)."""
MAX_LINES = 5_000_000
"""Default largest number of lines read from a line-based log (≈ 0.5 GB of working memory: 14 h
of a 10 Hz compass sending 6 sentences per epoch; ``--max-lines``)."""
_CHUNK = 1 << 20  # bytes read (and decompressed) at a time
_GZIP = b"\x1f\x8b"


def input_kind(path: str | os.PathLike, what: str = "file") -> str:
    """What *path* is: ``"file"`` (a regular file) or ``"stream"`` (a pipe or FIFO, read once);
    an :class:`~gripsense.errors.InputError` for anything else.

    Device files (``/dev/zero``, a terminal, a disk), sockets and folders are refused in one
    line: a device never ends, and reading it would fill memory or wait forever.

    Parameters
    ----------
    path : str or Path
        The input.
    what : str
        What the file is, for the message (``"vehicle file"``).

    Returns
    -------
    str
        ``"file"`` or ``"stream"``.
    """
    path = Path(path)
    try:
        st = os.stat(path)
    except FileNotFoundError:
        if os.path.islink(path):
            raise InputError(
                f"{path}: a link to nothing (dangling symlink); give the {what}"
            ) from None
        raise InputError(f"{path}: no such {what}") from None
    except PermissionError:
        raise InputError(f"{path}: permission denied (cannot read the {what})") from None
    except OSError as e:
        raise InputError(f"{path}: cannot read the {what} ({e.strerror or e})") from None
    mode = st.st_mode
    if stat.S_ISREG(mode):
        return "file"
    if stat.S_ISFIFO(mode):
        return "stream"
    if stat.S_ISDIR(mode):
        raise InputError(f"{path}: is a folder; give the {what} itself")
    kind = (
        "a character device" if stat.S_ISCHR(mode)
        else "a block device" if stat.S_ISBLK(mode)
        else "a socket" if stat.S_ISSOCK(mode)
        else "not a regular file"
    )  # fmt: skip
    raise InputError(
        f"{path}: is {kind}, not a file: a device is never read (it may never end); give a "
        "regular file or a pipe"
    )


def _open(path: Path, what: str) -> IO[bytes]:
    try:
        return open(path, "rb", buffering=0)
    except FileNotFoundError:
        raise InputError(f"{path}: no such {what}") from None
    except IsADirectoryError:
        raise InputError(f"{path}: is a folder; give the {what} itself") from None
    except PermissionError:
        raise InputError(f"{path}: permission denied (cannot read the {what})") from None
    except OSError as e:
        raise InputError(f"{path}: cannot read the {what} ({e.strerror or e})") from None


@dataclass
class ReadInput:
    """What :meth:`InputStream.read` kept of an input.

    Attributes
    ----------
    data : bytes
        The bytes read (decompressed), ending at a line end when a limit cut them.
    name : str
        The input's name, for messages.
    extra_lines : int
        Lines beyond the limits: counted, not read.
    notes : list of str
        What happened on the way (a gzip stream cut off, the limits).
    """

    data: bytes
    name: str
    extra_lines: int = 0
    notes: list[str] = field(default_factory=list)


class InputStream:
    """One input (a regular file, a pipe, a FIFO, a file object or bytes) read once, in
    chunks, decompressed on the fly when it is gzip (detected from its content).

    :meth:`peek` returns the first bytes without consuming them; :meth:`read` then returns
    everything from the start, bounded by its limits.

    Parameters
    ----------
    source : str, Path, bytes or binary file object
        The input. A path is checked first (:func:`input_kind`): a device is refused; ``-``
        is standard input (a pipe or a redirected file, not a terminal).
    what : str
        What the input is, for messages (``"log"``).
    decompress : bool
        Decompress gzip content (off for a receiver's raw byte stream).
    name : str, optional
        The name in messages (default: the path, or ``<bytes>`` / the file object's name).
    """

    def __init__(
        self,
        source: str | os.PathLike | bytes | IO[bytes],
        what: str = "file",
        *,
        decompress: bool = True,
        name: str | None = None,
    ) -> None:
        self.what = what
        self._close = False
        self.path: Path | None = None
        if isinstance(source, bytes | bytearray | memoryview):
            self._f: IO[bytes] = io.BytesIO(bytes(source))
            self.name = name or "<bytes>"
            self.stream = False
        elif str(source) == "-":  # standard input, read once as a stream
            if sys.stdin is None or sys.stdin.isatty():
                raise InputError(
                    f"-: standard input is a terminal; pipe the {what} into it "
                    "(… | gripsense ingest -) or give its path"
                )
            self._f = sys.stdin.buffer
            self.name = name or "<stdin>"
            self.stream = True
        elif isinstance(source, str | os.PathLike):
            path = Path(source)
            self.stream = input_kind(path, what) == "stream"
            self._f = _open(path, what)
            self._close = True
            self.name = name or str(path)
            self.path = path
        else:
            self._f = source
            self.name = name or str(getattr(source, "name", "<stream>"))
            self.stream = True
        self._raw: list[bytes] = []  # raw chunks kept until the gzip stream gave output
        first = self._read_raw()
        self.gzip = decompress and first[:2] == _GZIP
        self._first = first
        self._pending: list[bytes] = []  # decompressed chunks peeked, not yet consumed
        self._notes: list[str] = []
        self._chunks = self._decompressed() if self.gzip else self._plain()

    def _read_raw(self) -> bytes:
        try:
            b = self._f.read(_CHUNK)
        except OSError as e:
            raise InputError(
                f"{self.name}: cannot read the {self.what} ({e.strerror or e})"
            ) from None
        if isinstance(b, str):
            b = b.encode("utf-8", "surrogateescape")
        return bytes(b or b"")

    def _plain(self) -> Iterator[bytes]:
        b = self._first
        while b:
            yield b
            b = self._read_raw()

    def _decompressed(self) -> Iterator[bytes]:
        d = zlib.decompressobj(16 + zlib.MAX_WBITS)
        out = 0
        buf = self._first
        raw_seen = [buf]
        complete = False
        while True:
            if not buf:
                buf = self._read_raw()
                if not buf:
                    break
                if not out:
                    raw_seen.append(buf)
            try:
                while buf:
                    chunk = d.decompress(buf, _CHUNK)
                    buf = d.unconsumed_tail
                    if d.eof:
                        rest = d.unused_data  # a further gzip member (concatenated files)
                        complete = not rest.strip(b"\x00")
                        if not complete:
                            d = zlib.decompressobj(16 + zlib.MAX_WBITS)
                            buf = rest + buf
                        else:
                            buf = b""
                    else:
                        complete = False
                    if chunk:
                        out += len(chunk)
                        yield chunk
            except zlib.error as e:
                if not out:
                    if self.name.endswith((".gz", ".gzip")):
                        raise InputError(
                            f"{self.name}: named gzip but cannot be decompressed ({e}); check the "
                            "file (damaged at its start?) or give the uncompressed log"
                        ) from None
                    # binary receiver output that happens to start with gzip's magic bytes
                    self._notes.append(
                        f"starts like gzip but is not a gzip stream ({e}): read as plain bytes"
                    )
                    yield from raw_seen
                    b = self._read_raw()
                    while b:
                        yield b
                        b = self._read_raw()
                    return
                self._notes.append(
                    f"the gzip stream is corrupt after {out} bytes ({e}): read up to there"
                )
                return
            if complete:
                # the rest of the input after the last member: NUL padding only
                while True:
                    b = self._read_raw()
                    if not b:
                        return
                    if b.strip(b"\x00"):
                        d = zlib.decompressobj(16 + zlib.MAX_WBITS)
                        buf = b
                        complete = False
                        break
        if not complete and out:
            self._notes.append("the gzip stream ends early (file cut off?): read up to the cut")

    def _next(self) -> bytes | None:
        if self._pending:
            return self._pending.pop(0)
        return next(self._chunks, None)

    def peek(self, size: int = 65536) -> bytes:
        """The first *size* bytes (decompressed), kept for :meth:`read`.

        Parameters
        ----------
        size : int
            How many bytes [bytes].

        Returns
        -------
        bytes
            At most *size* bytes (fewer when the input is shorter).
        """
        have = sum(len(c) for c in self._pending)
        while have < size:
            c = next(self._chunks, None)
            if c is None:
                break
            self._pending.append(c)
            have += len(c)
        return b"".join(self._pending)[:size]

    def read(
        self,
        max_bytes: int = MAX_BYTES,
        max_lines: int | None = None,
        *,
        count_rest: bool = True,
        flags: tuple[str, str] = ("--max-bytes", "--max-lines"),
    ) -> ReadInput:
        """Everything from the start, bounded.

        Parameters
        ----------
        max_bytes : int
            Largest size kept (decompressed) [bytes].
        max_lines : int or None
            Largest number of lines kept (None: no line limit) [lines].
        count_rest : bool
            Beyond a limit, count the lines of the rest (without keeping them) when the input
            is a regular file or bytes; otherwise — a pipe, whose rest may never end, or a
            binary format, whose rest has no lines — the limit is an error naming it.
        flags : tuple of str
            How the user raises the byte and the line limit, for the messages.

        Returns
        -------
        ReadInput
            The bytes kept, the lines counted beyond the limits and the notes.
        """
        out: list[bytes] = []
        size = 0
        lines = 0
        over = flag = ""
        tail = b""
        try:
            while (c := self._next()) is not None:
                if max_lines is not None:
                    n = c.count(b"\n")
                    if lines + n >= max_lines:
                        cut = -1
                        for _ in range(max_lines - lines):
                            cut = c.index(b"\n", cut + 1)
                        rest = c[cut + 1 :]
                        if rest or self._more():
                            c, tail = c[: cut + 1], rest
                            over, flag = f"more than {max_lines} lines", flags[1]
                    lines += c.count(b"\n")
                if size + len(c) > max_bytes:
                    keep = max_bytes - size
                    c, tail = c[:keep], c[keep:] + tail
                    over, flag = f"more than {max_bytes} bytes{self._dec}", flags[0]
                    if self.stream or not count_rest:
                        break  # an error below: nothing more to keep
                    if max_lines is not None:  # keep whole lines: the one cut is counted
                        j = c.rfind(b"\n") + 1
                        if j:
                            c, tail = c[:j], c[j:] + tail
                        else:  # the line began in an earlier chunk
                            prev = b"".join(out)
                            j = prev.rfind(b"\n") + 1
                            c, tail, out, size = b"", prev[j:] + c + tail, [prev[:j]], j
                out.append(c)
                size += len(c)
                if over:
                    break
            extra = 0
            if over:
                fix = (
                    f"raise the limit ({flag}) or give a smaller {self.what.split(';')[0]}"
                    if flag.startswith("--")
                    else f"{flag}; check that this is the right {self.what.split(';')[0]}"
                )
                if self.stream:
                    raise InputError(
                        f"{self.name}: {over} from a pipe, whose rest may never end: not read; "
                        f"{fix}"
                    )
                if not count_rest:
                    raise InputError(f"{self.name}: {over}: not read; {fix}")
                extra = self._count(tail)
                self._notes.append(f"{over}: {extra} lines counted, not read ({flag} reads more)")
        finally:
            self.close()
        return ReadInput(b"".join(out), self.name, extra, list(self._notes))

    @property
    def _dec(self) -> str:
        return " (decompressed)" if self.gzip else ""

    def _more(self) -> bool:
        c = next(self._chunks, None)
        if c is None:
            return False
        self._pending.insert(0, c)
        return True

    def _count(self, tail: bytes) -> int:
        """Lines of *tail* and the rest of the input (a last line without its end counted)."""
        n = tail.count(b"\n")
        last = tail[-1:] if tail else b""
        while (c := self._next()) is not None:
            n += c.count(b"\n")
            last = c[-1:]
        return n + (1 if last and last != b"\n" else 0)

    def close(self) -> None:
        """Close the input (when this object opened it)."""
        if self._close:
            self._close = False
            self._f.close()


def read_bytes(path: str | Path, what: str = "file", max_bytes: int = MAX_BYTES) -> bytes:
    """The bytes of *path*; an :class:`~gripsense.errors.InputError` naming it when it cannot
    be read, is a device (never read) or holds more than *max_bytes*.

    Parameters
    ----------
    path : str or Path
        File to read (a regular file or a pipe, read once).
    what : str
        What the file is, for the message (``"vehicle file"``).
    max_bytes : int
        Largest size read [bytes].

    Returns
    -------
    bytes
        The file's content.
    """
    src = InputStream(path, what, decompress=False)
    return src.read(max_bytes, count_rest=False).data


def read_text(path: str | Path, what: str = "file", *, latin1: bool = False) -> str:
    """The text of *path* decoded as UTF-8 (a leading BOM is dropped).

    Parameters
    ----------
    path : str or Path
        File to read.
    what : str
        What the file is, for the message.
    latin1 : bool
        Fall back to Latin-1 when the file is not UTF-8 (for formats whose files are
        historically Latin-1, such as ``.tir``); otherwise such a file is an error.

    Returns
    -------
    str
        The decoded text.
    """
    data = read_bytes(path, what)
    try:
        return data.decode("utf-8-sig")
    except UnicodeDecodeError as e:
        if latin1:
            return data.decode("latin-1")
        line = data[: e.start].count(b"\n") + 1
        raise InputError(
            f"{path} line {line}: not UTF-8 text (byte 0x{data[e.start]:02x}); save the {what} "
            "as UTF-8"
        ) from None


def read_toml(path: str | Path, what: str = "TOML file") -> dict:
    """A TOML document as a dict, with errors that name the file and line.

    Parameters
    ----------
    path : str or Path
        File to read.
    what : str
        What the file is, for the message (``"vehicle file"``).

    Returns
    -------
    dict
        The parsed document.
    """
    text = read_text(path, what)
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as e:
        raise InputError(f"{path}: not valid TOML ({e})") from None
