"""Small helpers that let physics functions take scalars, lists, arrays and pandas Series."""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

__all__ = ["as_float_array", "restore", "sample_step"]


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


def sample_step(t: npt.ArrayLike, *, source: str, what: str = "time") -> float:
    """The typical step of sample times that strictly increase [s] (their median difference).

    Everything that divides by a time step or counts samples per second asks here, so time
    stamps that cannot define a step are one clear input error, never a division by zero:
    too few samples, non-finite times, times that go back, or times that repeat (duplicated
    rows, or a time column coarser than the sampling: 0.1 s stamps on a 1 kHz trace).

    Parameters
    ----------
    t : array_like
        Sample times [s], in recorded order.
    source : str
        The file or trace named in the error [-].
    what : str
        The column's name in the error [-].

    Returns
    -------
    float
        The median difference of consecutive times [s], > 0.

    Raises
    ------
    InputError
        When the times cannot define a step (the message says which and how to fix it).
    """
    from gripsense.errors import InputError

    t = as_float_array(t, what).ravel()
    if t.size < 2:
        raise InputError(f"{source}: {t.size} sample(s); a step between times needs at least 2")
    bad = ~np.isfinite(t)
    if bad.any():
        i = int(np.flatnonzero(bad)[0])
        raise InputError(f"{source}: {what} of sample {i + 1} is {t[i]}; give finite times")
    d = np.diff(t)
    back = np.flatnonzero(d < 0)
    if back.size:
        i = int(back[0])
        raise InputError(
            f"{source}: {what} goes back at sample {i + 2} ({t[i + 1]:.6g} s after "
            f"{t[i]:.6g} s); sort the rows by time or fix the time column"
        )
    same = np.flatnonzero(d == 0)
    if same.size:
        i = int(same[0])
        steps = d[d > 0]
        res = f"; its smallest step is {steps.min():.6g} s" if steps.size else ""
        raise InputError(
            f"{source}: {same.size} of {t.size} samples repeat the {what} of the sample "
            f"before them (first: sample {i + 2} at {t[i + 1]:.6g} s){res} — rows are "
            "duplicated, or the time column is coarser than the sampling; remove the "
            "repeated rows or write the time with more digits"
        )
    return float(np.median(d))
