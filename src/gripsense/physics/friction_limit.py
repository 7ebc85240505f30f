"""The range of μ that operating points allow: the physical limit of any estimate from them.

Normalise a lateral curve by its peak (``docs/physics.md`` §14): F/(μ Fz) = f(x),
x = C tan|α| / (μ Fz). At an operating point the force per load y = F/Fz and the linear
prediction per unit slope k = C₀ tan|α| / Fz (C₀ the declared cornering stiffness) are measured;
the true stiffness is s C₀ with s in a band. A friction coefficient μ is consistent with the point
for a shape f and a scale s when μ f(s k/μ) = y (within a tolerance). Over a family of shapes
and the band of s, the consistent μ form the range no estimator can narrow without more
information — a second point higher up the same curve, a better-known stiffness, or a second
channel (``docs/physics.md`` §15.5).

For fixed f and s, h(μ) = μ f(s k/μ) grows with μ (dh/dμ = f(x) − x f'(x) > 0 for the concave,
unit-slope curves of the family), from 0 to the linear force s k: the μ consistent with one
point within ±tol form one interval, found by inverting f(x)/x (monotone decreasing from 1).
Several points share μ, f and s: their intervals intersect. The range is the hull of the
intersections over the family and a grid of s.
"""

from __future__ import annotations

from functools import cache

import numpy as np

from gripsense.physics.tyre_curves import SHAPE_FAMILY, CurveShape, curve_tables

__all__ = ["linear_explains", "mu_range_limit", "shape_grid"]


def shape_grid(
    c_range: tuple[float, float] = (1.1, 1.95),
    e_range: tuple[float, float] = (-1.5, 0.8),
    n: int = 12,
) -> tuple[CurveShape, ...]:
    """Magic Formula shapes on an n × n grid of C_s and E (unit slope and peak).

    Parameters
    ----------
    c_range : (float, float)
        Shape factor C_s range [-].
    e_range : (float, float)
        Curvature factor E range [-].
    n : int
        Grid points per factor.

    Returns
    -------
    tuple of CurveShape
        The members.
    """
    return tuple(
        CurveShape(f"mf C{c:.3g} E{e:.3g}", "magic-formula", float(c), float(e))
        for c in np.linspace(*c_range, n)
        for e in np.linspace(*e_range, n)
    )


@cache
def _inverse_tables(shapes: tuple[CurveShape, ...]):
    """Per shape: q = f(x)/x on the table (decreasing) for inversion, and f at the table's end."""
    x, f, _ = curve_tables(shapes, x_max=60.0, n=12001)
    with np.errstate(divide="ignore", invalid="ignore"):
        q = np.where(x > 0, f / x, 1.0)
    # strictly decreasing for np.interp on the reversed arrays
    q = np.minimum.accumulate(q, axis=1)
    return x, q, f[:, -1]


def _x_of_q(x: np.ndarray, q_row: np.ndarray, f_end: float, q: np.ndarray) -> np.ndarray:
    """X with f(x)/x = q (q in (0, 1]); beyond the table f is constant."""
    out = np.interp(q, q_row[::-1], x[::-1])
    beyond = q < q_row[-1]
    return np.where(beyond, f_end / np.maximum(q, 1e-300), out)


def linear_explains(grip, linear, stiffness_band, tolerance=0.0) -> bool:
    """Whether a tyre that is still linear at every point — μ → ∞, every curve of the family's
    limit — explains the points for some stiffness scale in the band (then no upper end of μ
    exists, ``docs/physics.md`` §15.5).

    Parameters
    ----------
    grip : array_like
        Force per load y = |F| / Fz at each point [-].
    linear : array_like
        Linear prediction per unit stiffness scale, k = C₀ tan|α| / Fz, at each point [-].
    stiffness_band : (float, float)
        Smallest and largest true stiffness over the declared one [-].
    tolerance : float or array_like
        Allowed |s k − y| at each point [-].

    Returns
    -------
    bool
        True when some s in the band gives |s k_i − y_i| ≤ tol_i at every point.
    """
    y = np.atleast_1d(np.abs(np.asarray(grip, dtype=float)))
    k = np.atleast_1d(np.asarray(linear, dtype=float))
    if y.shape != k.shape:
        y, k = np.broadcast_arrays(y, k)
    tol = np.asarray(tolerance, dtype=float)
    if tol.shape != y.shape:
        tol = np.broadcast_to(tol, y.shape)
    pos = k > 0
    if not np.all(pos | (y <= tol)):
        return False
    if not pos.any():  # every point explained by a zero force: any stiffness of the band
        return bool(stiffness_band[0] <= stiffness_band[1])
    kp = k[pos]  # (a small-array path: this runs once per window of the profile)
    s_lo = max(float(np.max((y[pos] - tol[pos]) / kp)), stiffness_band[0])
    s_hi = min(float(np.min((y[pos] + tol[pos]) / kp)), stiffness_band[1])
    return bool(s_lo <= s_hi)


def mu_range_limit(
    grip,
    slip_rad,
    stiffness_per_load,
    *,
    stiffness_band: tuple[float, float] = (0.9, 1.1),
    tolerance=0.0,
    shapes: tuple[CurveShape, ...] = SHAPE_FAMILY,
    n_scale: int = 41,
    slip_offset: float = 0.0,
    n_offset: int = 9,
) -> tuple[float, float]:
    """The smallest and largest μ consistent with operating points for any curve of a family and
    any stiffness in a band (``docs/physics.md`` §15.5), and — with *slip_offset* — any common
    error of the measured slips up to that size (the receiver's share: a heading offset shifts
    every slip alike).

    Parameters
    ----------
    grip : array_like
        Force per load y = |F| / Fz at each point [-].
    slip_rad : array_like
        Slip angle at each point [rad].
    stiffness_per_load : array_like
        Declared cornering stiffness over load, C₀ / Fz, at each point [1/rad].
    stiffness_band : (float, float)
        Smallest and largest true stiffness over the declared one [-].
    tolerance : float or array_like
        Allowed |μ f(s k/μ) − y| at each point [-] (measurement error of y; 0 for exact points).
    shapes : tuple of CurveShape
        The family (default: the estimator's :data:`~gripsense.physics.tyre_curves.SHAPE_FAMILY`;
        :func:`shape_grid` for a dense Magic Formula grid).
    n_scale : int
        Stiffness scales tried across the band (log-spaced).
    slip_offset : float
        Largest common error δ of the slips: the true slips are α − δ for one δ in
        [−slip_offset, slip_offset] [rad] (ISO signs: a heading offset adds to every slip).
    n_offset : int
        Offsets tried across that interval (the range is the hull over them).

    Returns
    -------
    mu_low, mu_high : float
        The range [-]; ``mu_high`` is inf when a tyre linear at the points explains them (far
        from the limit), both NaN when no member and scale explain the points together.
    """
    if slip_offset > 0.0:
        ranges = np.array(
            [
                mu_range_limit(
                    grip,
                    np.asarray(slip_rad, dtype=float) - d,
                    stiffness_per_load,
                    stiffness_band=stiffness_band,
                    tolerance=tolerance,
                    shapes=shapes,
                    n_scale=n_scale,
                )
                for d in np.linspace(-slip_offset, slip_offset, max(int(n_offset), 2))
            ]
        )
        ok = np.isfinite(ranges[:, 0])
        if not ok.any():
            return float("nan"), float("nan")
        return float(ranges[ok, 0].min()), float(ranges[ok, 1].max())
    y = np.atleast_1d(np.abs(np.asarray(grip, dtype=float)))
    k = np.atleast_1d(np.abs(np.tan(np.asarray(slip_rad, dtype=float)))) * np.atleast_1d(
        np.asarray(stiffness_per_load, dtype=float)
    )
    y, k = np.broadcast_arrays(y, k)
    tol = np.broadcast_to(np.asarray(tolerance, dtype=float), y.shape)
    s = np.geomspace(stiffness_band[0], stiffness_band[1], max(int(n_scale), 1))
    x, qtab, f_end = _inverse_tables(tuple(shapes))
    sk = s[:, None] * k[None, :]  # (n_s, n_points): the linear force per load
    lo_t = np.maximum(y - tol, 0.0)[None, :]
    hi_t = (y + tol)[None, :]
    best_lo, best_hi = np.inf, -np.inf
    for j in range(qtab.shape[0]):
        with np.errstate(divide="ignore", invalid="ignore"):
            # h(μ) = lo_t: the smallest μ; h(μ) = hi_t: the largest (inf at or above linear)
            q_lo = lo_t / sk
            q_hi = hi_t / sk
            mu_a = np.where(
                q_lo > 0, sk / _x_of_q(x, qtab[j], f_end[j], np.clip(q_lo, 0.0, 1.0)), 0.0
            )
            # above the linear force (q > 1) no μ explains the point
            mu_a = np.where(q_lo > 1.0, np.inf, mu_a)
            mu_b = np.where(
                q_hi >= 1.0, np.inf, sk / _x_of_q(x, qtab[j], f_end[j], np.minimum(q_hi, 1.0))
            )
        # f ≤ 1: μ ≥ y − tol at every point
        mu_a = np.maximum(mu_a, lo_t)
        a, b = mu_a.max(axis=1), mu_b.min(axis=1)
        ok = (a <= b) & np.isfinite(a)
        if ok.any():
            best_lo = min(best_lo, float(a[ok].min()))
            best_hi = max(best_hi, float(b[ok].max()))
    # the limit μ → ∞ of every shape is the linear tyre: unbounded when some scale of the
    # band makes the linear force match every point (continuous in s, so not left to the grid)
    if linear_explains(y, k, stiffness_band, tol):
        best_hi = np.inf
        best_lo = min(best_lo, float(np.max(np.maximum(y - tol, 0.0))))
    if best_lo > best_hi:
        return float("nan"), float("nan")
    return best_lo, best_hi
