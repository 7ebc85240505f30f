"""Road-surface classes from the friction coefficient (seed 000, Table 4).

Table 4 gives DRY 1.2–0.7, WET 0.6–0.4, SNOW 0.3–0.2, ICE 0.1–0.0 and leaves gaps between the
classes; gripsense splits each gap in the middle: ICE < 0.15 ≤ SNOW < 0.35 ≤ WET < 0.65 ≤ DRY.
"""

from __future__ import annotations

import numpy as np

from gripsense._arrays import as_float_array

__all__ = ["SURFACE_BANDS", "surface_class", "surface_class_interval"]

# (name, lower bound, upper bound) of μ, in increasing order; Table 4 with its gaps split
SURFACE_BANDS = (
    ("ICE", 0.0, 0.15),
    ("SNOW", 0.15, 0.35),
    ("WET", 0.35, 0.65),
    ("DRY", 0.65, np.inf),
)
UNDETERMINED = "undetermined"
_NAMES = np.array([b[0] for b in SURFACE_BANDS] + [UNDETERMINED], dtype=object)
_EDGES = np.array([b[2] for b in SURFACE_BANDS[:-1]])


def surface_class(mu):
    """Surface class of a friction coefficient (NaN or negative: ``undetermined``).

    Parameters
    ----------
    mu : array_like
        [-].

    Returns
    -------
    str or numpy.ndarray of str
    """
    m = as_float_array(mu, "mu")
    idx = np.searchsorted(_EDGES, m, side="right")
    idx = np.where(np.isfinite(m) & (m >= 0), idx, len(SURFACE_BANDS))
    out = _NAMES[idx]
    return str(out) if np.ndim(mu) == 0 else out


def surface_class_interval(mu_low, mu_high):
    """Surface class of an interval [mu_low, mu_high]: ``undetermined`` if it spans classes.

    Parameters
    ----------
    mu_low : array_like
        Lower end of the interval [-].
    mu_high : array_like
        Upper end [-].
    """
    lo, hi = surface_class(mu_low), surface_class(mu_high)
    if np.ndim(mu_low) == 0 and np.ndim(mu_high) == 0:
        return lo if lo == hi else UNDETERMINED
    lo_a, hi_a = np.broadcast_arrays(np.asarray(lo, dtype=object), np.asarray(hi, dtype=object))
    return np.where(lo_a == hi_a, lo_a, UNDETERMINED)
