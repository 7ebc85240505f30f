"""Road-surface classes from the friction coefficient (seed 000, Table 4).

Table 4 gives DRY 1.2–0.7, WET 0.6–0.4, SNOW 0.3–0.2, ICE 0.1–0.0 and leaves gaps between the
classes; gripsense splits each gap in the middle: ICE < 0.15 ≤ SNOW < 0.35 ≤ WET < 0.65 ≤ DRY.
"""

from __future__ import annotations

import numpy as np

from gripsense._arrays import as_float_array

__all__ = [
    "SLIPPERY_MU",
    "SURFACE_BANDS",
    "slippery_call",
    "surface_class",
    "surface_class_interval",
]

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


SLIPPERY_MU = 0.5
"""Friction below which a road is called slippery [-] (the wet band of Table 4 and below)."""
SLIPPERY, NOT_SLIPPERY, UNKNOWN = "slippery", "not slippery", "unknown"


def slippery_call(mu_low, mu_high, threshold: float = SLIPPERY_MU):
    """The answer to "is it slippery?" from a 90 % range of μ: ``slippery`` when the upper end is
    below *threshold* (μ < threshold at 95 %, one-sided), ``not slippery`` when the lower end is
    above it (the lower end is the larger of the model's 95 % end and the 99 % measured-grip
    bound, so μ > threshold at ≥ 95 %), else ``unknown`` (also for a missing range).

    Parameters
    ----------
    mu_low : array_like
        Lower end of the range [-] (the measured-grip bound where there is no estimate).
    mu_high : array_like
        Upper end [-] (inf when unbounded).
    threshold : float
        The friction that separates the calls [-].

    Returns
    -------
    str or numpy.ndarray of str
        ``slippery``, ``not slippery`` or ``unknown``.
    """
    lo = as_float_array(mu_low, "mu_low")
    hi = as_float_array(mu_high, "mu_high")
    lo, hi = np.broadcast_arrays(lo, hi)
    with np.errstate(invalid="ignore"):
        slip = np.isfinite(hi) & (hi < threshold) & ~(lo > hi)
        firm = np.isfinite(lo) & (lo > threshold)
    out = np.where(slip, SLIPPERY, np.where(firm, NOT_SLIPPERY, UNKNOWN)).astype(object)
    return str(out) if np.ndim(mu_low) == 0 and np.ndim(mu_high) == 0 else out
