"""What several statements about μ say together: each window's (or pass's) profile likelihood
stored as a deviance curve on the μ grid (:func:`~gripsense.estimate.profile.deviance_curve`),
combined as a fleet cell combines them (``docs/physics.md`` §15.12, ``docs/fleet.md``).

* **One vehicle**: its statements share the vehicle's tyre and model-form nuisances (stiffness,
  curve shape, load transfer), so they are not multiplied — its curve is the pointwise largest
  deviance of its statements (every one of them holds). Ten passes of one car therefore never
  say more than the same windows in one long drive of that car, and one statement repeated says
  what it said once.
* **Different vehicles** are independent: their curves add (their likelihoods multiply), and
  the range is where the sum is within the 90 % level of its minimum (a profile-likelihood
  interval).
* **The measured grip** is model-free: the largest bound any statement proves, the lower end of
  every range.
* **A contradiction**: no μ at or above the measured grip lies inside every statement's own
  90 % range — flagged, never combined into a number none of them supports.

All functions are vectorised over rows (one curve per row).
"""

from __future__ import annotations

import numpy as np

from gripsense.constants import CHI2_1_90
from gripsense.estimate.options import WindowOptions
from gripsense.estimate.profile import DEVIANCE_CAP, DEVIANCE_STEP, mu_grid

__all__ = [
    "CONTRADICTION_TOL",
    "curve_grid",
    "curve_range",
    "curves_from_bytes",
    "gaussian_curves",
    "reduce_groups",
]

CONTRADICTION_TOL = 0.01
"""A range whose upper end lies this far [-] below another's lower end (or below the measured
grip) contradicts it; as a drive's model interval below its measured grip (``docs/friction.md``)."""


def curve_grid(options: WindowOptions | None = None) -> np.ndarray:
    """The μ grid the curves are stored on: the profile's (:func:`~gripsense.estimate.profile.
    mu_grid` of the window options) [-].
    """
    o = options or WindowOptions()
    return mu_grid(float(o.mu_min), float(o.mu_max), int(o.n_mu))


def curves_from_bytes(blobs, n_mu: int) -> np.ndarray:
    """Stored curves (one ``bytes`` of *n_mu* unsigned bytes per row) as an array of deviance
    steps.

    Parameters
    ----------
    blobs : sequence of bytes
        The rows' ``mu_deviance``.
    n_mu : int
        Points of the grid.

    Returns
    -------
    numpy.ndarray
        ``(rows, n_mu)`` int32, in steps of :data:`~gripsense.estimate.profile.DEVIANCE_STEP`.

    Raises
    ------
    ValueError
        When a curve has another length (written on another μ grid).
    """
    blobs = list(blobs)
    if not blobs:
        return np.zeros((0, n_mu), np.int32)
    flat = np.frombuffer(b"".join(blobs), np.uint8)
    if any(len(b) != n_mu for b in blobs):
        raise ValueError(f"a deviance curve is not {n_mu} points long (another μ grid)")
    return flat.reshape(len(blobs), n_mu).astype(np.int32)


def gaussian_curves(mu: np.ndarray, sigma: np.ndarray, grid: np.ndarray) -> np.ndarray:
    """Curves of Gaussian statements μ̂ ± σ (a per-sample method's pass): ((μ − μ̂)/σ)² in
    deviance steps, rounded down and capped as stored curves are.

    Parameters
    ----------
    mu, sigma : numpy.ndarray
        Values and their 1σ [-].
    grid : numpy.ndarray
        μ grid [-].

    Returns
    -------
    numpy.ndarray
        ``(rows, grid.size)`` int32.
    """
    z = (grid[None, :] - np.asarray(mu, float)[:, None]) / np.asarray(sigma, float)[:, None]
    return np.clip(np.floor(z**2 / DEVIANCE_STEP), 0, DEVIANCE_CAP).astype(np.int32)


def reduce_groups(curves: np.ndarray, codes: np.ndarray, how: str) -> tuple[np.ndarray, np.ndarray]:
    """Pointwise maximum or sum of the curves of each group.

    Parameters
    ----------
    curves : numpy.ndarray
        ``(rows, n)`` curves.
    codes : numpy.ndarray
        Group code per row (any integers).
    how : {"max", "sum"}
        ``max``: statements that share nuisances (one vehicle); ``sum``: independent ones.

    Returns
    -------
    groups : numpy.ndarray
        The distinct codes, sorted.
    reduced : numpy.ndarray
        ``(groups, n)`` curves.
    """
    order = np.argsort(codes, kind="stable")
    c = np.asarray(codes)[order]
    groups, start = np.unique(c, return_index=True)
    if not groups.size:
        return groups, np.zeros((0, curves.shape[1]), curves.dtype)
    ufunc = np.maximum if how == "max" else np.add
    return groups, ufunc.reduceat(curves[order], start, axis=0)


def curve_range(
    steps: np.ndarray, grid: np.ndarray, level: float = CHI2_1_90
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The range a curve states: every μ where its deviance, taken from its minimum, is within
    *level* — from the first such point of the grid to the last, the ends interpolated in log μ
    (as the profile's own range, :func:`~gripsense.estimate.profile.profile_mu`: a curve that
    dips again beyond a bump keeps that μ).

    Parameters
    ----------
    steps : numpy.ndarray
        ``(rows, n)`` curves in deviance steps.
    grid : numpy.ndarray
        μ grid [-].
    level : float
        Deviance level (90 %: χ²₁ 0.90) [-].

    Returns
    -------
    low, high : numpy.ndarray
        The ends [-]: the grid's first point where the curve is within the level at the grid's
        start, ``inf`` where it is at the grid's end.
    minimum : numpy.ndarray
        The curve's smallest deviance [-] (0 for one statement; above 0 where combined ones
        pull apart).
    """
    dev = np.asarray(steps, float) * DEVIANCE_STEP
    n, m = dev.shape
    if n == 0:
        e = np.zeros(0)
        return e, e, e
    mn = dev.min(axis=1)
    d = dev - mn[:, None]
    inside = d <= level  # every row has one: its minimum
    lx = np.log(grid)
    rows = np.arange(n)
    # lower: the first point within the level, and the one before it (outside)
    j = np.argmax(inside, axis=1)
    has_lo = j > 0
    low = np.where(has_lo, _interp(lx, d, rows, j, np.maximum(j - 1, 0), level), grid[0])
    # upper: the last point within the level, and the one after it (outside)
    j = m - 1 - np.argmax(inside[:, ::-1], axis=1)
    has_hi = j < m - 1
    high = np.where(has_hi, _interp(lx, d, rows, j, np.minimum(j + 1, m - 1), level), np.inf)
    return low, high, mn


def _interp(lx, d, rows, i, j, level):
    """μ where the deviance crosses *level* between the inner point *i* and the outer *j*."""
    yi, yj = d[rows, i], d[rows, j]
    with np.errstate(invalid="ignore", divide="ignore"):
        f = np.clip((level - yi) / (yj - yi), 0.0, 1.0)
    return np.exp(lx[i] + np.nan_to_num(f) * (lx[j] - lx[i]))
