"""Exception hierarchy of gripsense.

Errors name what is wrong (file, line, field, key or argument) and say how to fix it.
"""

from __future__ import annotations

__all__ = ["GripsenseError", "InputError", "NotObservableError"]


class GripsenseError(Exception):
    """Base class of every error gripsense raises on purpose."""


class InputError(GripsenseError, ValueError):
    """Bad input: a file, line, field, key or argument that cannot be used as given."""


class NotObservableError(GripsenseError):
    """The data cannot determine the requested quantity.

    Raised only where returning a flag is wrong; estimators normally return a flag instead.
    """
