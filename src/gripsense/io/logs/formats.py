"""The optional libraries of the field's log formats (``pip install 'gripsense[formats]'``)."""

from __future__ import annotations

import importlib
from types import ModuleType

from gripsense.errors import InputError

__all__ = ["FORMAT_LIBRARIES", "require"]

FORMAT_LIBRARIES = {
    "pyubx2": "pyubx2",
    "asammdf": "asammdf",
    "can": "python-can",
    "cantools": "cantools",
    "rosbags": "rosbags",
}
"""Module -> PyPI distribution of the ``formats`` extra."""


def require(module: str, what: str) -> ModuleType:
    """Import an optional format library, or fail with one line naming the extra.

    Parameters
    ----------
    module : str
        Module name (``"asammdf"``).
    what : str
        What needs it, for the message (``"reading MDF4"``).

    Returns
    -------
    module
        The imported module.
    """
    try:
        return importlib.import_module(module)
    except ImportError:
        dist = FORMAT_LIBRARIES.get(module, module)
        raise InputError(
            f"{what} needs {dist}, which is not installed; install the formats extra: "
            "pip install 'gripsense[formats]'"
        ) from None
