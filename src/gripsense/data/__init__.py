"""Small bundled sample data (see README.md in this folder for sources and licences)."""

from __future__ import annotations

from importlib.resources import as_file, files
from pathlib import Path

__all__ = ["sample_path"]


def sample_path(name: str) -> Path:
    """Path of a bundled sample file, e.g. ``sample_path("rst39.log")``."""
    res = files(__name__).joinpath(name)
    if not res.is_file():
        raise FileNotFoundError(f"no bundled sample {name!r}")
    with as_file(res) as p:
        return Path(p)
