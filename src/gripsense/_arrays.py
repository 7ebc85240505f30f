"""Small helpers that let physics functions take scalars, lists, arrays and pandas Series."""

from __future__ import annotations

import numpy as np

__all__ = ["as_float_array", "restore"]


def as_float_array(x, name: str) -> np.ndarray:
    """*x* as a float64 array; a clear error naming the argument if it cannot be one."""
    try:
        return np.asarray(x, dtype=np.float64)
    except (TypeError, ValueError) as e:
        from gripsense.errors import InputError

        raise InputError(
            f"{name}: cannot be read as numbers ({e}); give floats in SI units"
        ) from None


def restore(out: np.ndarray, *like):
    """Return a Python float for all-scalar input, a Series when the first input was a Series."""
    first = like[0] if like else None
    if all(np.ndim(v) == 0 for v in like):
        return out.item() if isinstance(out, np.ndarray) and out.ndim == 0 else out
    try:
        import pandas as pd

        if isinstance(first, pd.Series):
            return pd.Series(out, index=first.index)
    except ImportError:  # pragma: no cover
        pass
    return out
