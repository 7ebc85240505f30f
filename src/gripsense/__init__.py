"""gripsense — tyre-road friction, tyre and steering parameters from how a vehicle moves.

The public API is re-exported here; see the README and ``docs/`` for an overview and
``docs/architecture.md`` for where each kind of thing lives. The names are imported when
first used (``import gripsense`` alone is quick, so the command line starts at once).

numba's on-disk cache of compiled functions goes beside the package (``__pycache__``) or in
the user's cache folder; when neither is writable (a read-only install and a service account
without a writable HOME) and ``NUMBA_CACHE_DIR`` is not set, it is set here, before numba is
imported, to a private folder in the temporary directory — so importing never fails with
numba's "cannot cache function … no locator available".
"""

from __future__ import annotations

import importlib
import os
import sys

from gripsense._version import __version__

# not ``typing.TYPE_CHECKING``: importing typing (20–50 ms) would lengthen the start of the
# command line before its signal handlers are in place (gripsense.cli.main)
TYPE_CHECKING = False


def _writable(folder: str) -> bool:
    """Whether numba could cache into *folder* (as its own test: it can be created and
    written).
    """
    try:
        os.makedirs(folder, exist_ok=True)
    except OSError:
        return False
    return os.access(folder, os.W_OK | os.X_OK)


def _user_cache_dir() -> str:
    """Numba's user-wide cache folder (``numba.misc.appdirs``, without importing numba)."""
    if sys.platform == "darwin":
        return os.path.expanduser("~/Library/Caches/numba")
    if sys.platform == "win32":
        base = os.environ.get("LOCALAPPDATA") or os.path.expanduser("~/AppData/Local")
        return os.path.join(base, "numba", "Cache")
    return os.path.join(os.environ.get("XDG_CACHE_HOME") or os.path.expanduser("~/.cache"), "numba")


def _private_temp_folder() -> str | None:
    """A folder in the temporary directory only this user can write: the same one each run
    (the cache is kept), or a fresh one when that name is taken by anyone else.
    """
    import tempfile

    uid = os.getuid() if hasattr(os, "getuid") else 0
    path = os.path.join(tempfile.gettempdir(), f"gripsense-numba-cache-{uid}")
    try:
        os.makedirs(path, mode=0o700, exist_ok=True)
        st = os.lstat(path)
        mine = not hasattr(os, "getuid") or st.st_uid == uid
        if os.path.isdir(path) and not os.path.islink(path) and mine and not st.st_mode & 0o022:
            return path
        return tempfile.mkdtemp(prefix="gripsense-numba-cache-")
    except OSError:
        return None


def _numba_cache_fallback() -> str | None:
    """Point numba's cache at a private temporary folder when it has nowhere else to go.

    Only when the user has not set ``NUMBA_CACHE_DIR`` and neither the package's
    ``__pycache__`` nor numba's user-wide cache folder is writable; called when gripsense is
    imported, before numba is (if numba was imported first, its configuration is set too).

    Returns
    -------
    str or None
        The folder now used, or ``None`` when nothing was changed.
    """
    if os.environ.get("NUMBA_CACHE_DIR"):
        return None
    here = os.path.dirname(os.path.abspath(__file__))
    if _writable(os.path.join(here, "__pycache__")) or _writable(_user_cache_dir()):
        return None
    folder = _private_temp_folder()
    if folder is None:
        return None
    os.environ["NUMBA_CACHE_DIR"] = folder
    config = sys.modules.get("numba.core.config")
    if config is not None:  # numba read its environment already
        config.CACHE_DIR = folder  # type: ignore[attr-defined]
    return folder


_numba_cache_fallback()

if TYPE_CHECKING:
    from typing import Any

    from gripsense.config import SteeringCar, Tyre, Vehicle
    from gripsense.errors import GripsenseError, InputError, NotObservableError
    from gripsense.estimate.noise import NoiseModel
    from gripsense.estimate.results import (
        AxleFriction,
        FrictionResult,
        WheelFriction,
        read_result,
    )
    from gripsense.io import IngestReport, NmeaLog, read_nmea
    from gripsense.pipeline import FrictionRun

_WHERE = {
    "AxleFriction": "gripsense.estimate.results",
    "FrictionResult": "gripsense.estimate.results",
    "FrictionRun": "gripsense.pipeline",
    "GripsenseError": "gripsense.errors",
    "IngestReport": "gripsense.io",
    "InputError": "gripsense.errors",
    "NmeaLog": "gripsense.io",
    "NoiseModel": "gripsense.estimate.noise",
    "NotObservableError": "gripsense.errors",
    "SteeringCar": "gripsense.config",
    "Tyre": "gripsense.config",
    "Vehicle": "gripsense.config",
    "WheelFriction": "gripsense.estimate.results",
    "read_nmea": "gripsense.io",
    "read_result": "gripsense.estimate.results",
}

__all__ = [
    "AxleFriction",
    "FrictionResult",
    "FrictionRun",
    "GripsenseError",
    "IngestReport",
    "InputError",
    "NmeaLog",
    "NoiseModel",
    "NotObservableError",
    "SteeringCar",
    "Tyre",
    "Vehicle",
    "WheelFriction",
    "__version__",
    "read_nmea",
    "read_result",
]


def __getattr__(name: str) -> Any:
    """The public names (and subpackages: ``gripsense.sim``) imported when first used."""
    if name in _WHERE:
        value = getattr(importlib.import_module(_WHERE[name]), name)
        globals()[name] = value
        return value
    if not name.startswith("__"):
        try:
            return importlib.import_module(f"{__name__}.{name}")
        except ModuleNotFoundError as e:
            if e.name != f"{__name__}.{name}":
                raise
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted({*globals(), *__all__})
