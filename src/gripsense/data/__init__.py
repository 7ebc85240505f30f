"""Small bundled sample data (see README.md in this folder for sources and licences).

``gripsense.data.path("corolla_thesis.toml")`` gives the path of a bundled file or folder
(``"demo"``, ``"tyres/PacejkaBook_Defaults.tir"``) wherever gripsense is installed.
"""

from __future__ import annotations

from importlib.resources import as_file, files
from pathlib import Path

__all__ = ["path", "sample_path"]


def path(name: str) -> Path:
    """Path of a bundled file or folder.

    Parameters
    ----------
    name : str
        Name relative to the data folder, e.g. ``"corolla_thesis.toml"``, ``"demo"`` or
        ``"tyres/PacejkaBook_Defaults.tir"``.

    Returns
    -------
    Path
        The file or folder.

    Raises
    ------
    FileNotFoundError
        When gripsense bundles nothing of that name (the message lists what it bundles).
    """
    res = files(__name__).joinpath(name)
    if not (res.is_file() or res.is_dir()):
        have = sorted(
            p.name for p in files(__name__).iterdir() if not p.name.startswith(("_", "."))
        )
        raise FileNotFoundError(f"no bundled sample {name!r}; bundled: {', '.join(have)}")
    with as_file(res) as p:
        return Path(p)


def sample_path(name: str) -> Path:
    """Path of a bundled sample file, e.g. ``sample_path("rst39.log")``.

    Parameters
    ----------
    name : str
        File name relative to the data folder.

    Returns
    -------
    Path
        The file.
    """
    p = path(name)
    if not p.is_file():
        raise FileNotFoundError(f"no bundled sample {name!r}")
    return p
