"""Text and TOML files read with one set of clear errors (file named, cause, how to fix)."""

from __future__ import annotations

import tomllib
from pathlib import Path

from gripsense.errors import InputError

__all__ = ["read_bytes", "read_text", "read_toml"]


def read_bytes(path: str | Path, what: str = "file") -> bytes:
    """The bytes of *path*; an :class:`~gripsense.errors.InputError` naming it when it cannot
    be read.

    Parameters
    ----------
    path : str or Path
        File to read.
    what : str
        What the file is, for the message (``"vehicle file"``).

    Returns
    -------
    bytes
        The file's content.
    """
    path = Path(path)
    try:
        return path.read_bytes()
    except FileNotFoundError:
        raise InputError(f"{path}: no such {what}") from None
    except IsADirectoryError:
        raise InputError(f"{path}: is a folder; give the {what} itself") from None
    except PermissionError:
        raise InputError(f"{path}: permission denied (cannot read the {what})") from None
    except OSError as e:
        raise InputError(f"{path}: cannot read the {what} ({e.strerror or e})") from None


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
