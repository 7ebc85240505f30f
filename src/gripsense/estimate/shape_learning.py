"""Learning an axle's normalised curve shape from the car's own limits (``docs/physics.md``
§15.10).

A drive that takes an axle up its curve says which normalised shapes f(x) (§14) can carry its
points. Per shape of :data:`~gripsense.physics.shape_grid.LEARN_GRID` the drive's profile
likelihood is minimised over the road's μ (a nuisance of each drive: similarity — the curve
normalised by μFz and the cornering stiffness keeps its form across roads) and every nuisance
of the axle window (stiffness scale, slip offsets, load transfer, load sensitivities):

    D_k = 2 (min_μ,θ NLL(μ, θ | shape k) − min_j min_μ,θ NLL(μ, θ | shape j)).

The drive's evidence is the vector D; independent drives add. A drive that never left the
linear range leaves D flat (every shape explains it) and is not kept. Today's drive on another
road then profiles μ over the shapes with the evidence as a prior weight ½ D_k / T, tempered by
T = :data:`~gripsense.estimate.profile.SIMILARITY_TEMPER` (the shape is not quite the same on
another surface), on top of the prior family's own weight of the peak's position.

Each (μ, shape) is minimised from the priors' means (a cold start): the warm-started path of
:func:`~gripsense.estimate._axle_kernel.profile_grid` follows the best shapes well but can lose
a poor one's nuisances, which would overstate its NLL and so a shape's exclusion.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from gripsense.config import Vehicle
from gripsense.estimate import _axle_kernel as K
from gripsense.estimate.bins import axle_bins
from gripsense.estimate.noise import NoiseModel
from gripsense.estimate.options import WindowOptions
from gripsense.estimate.profile import Priors, axle_priors, merge_bins, slow_correlation
from gripsense.physics.shape_grid import LEARN_GRID, combine_evidence, learn_tables

__all__ = [
    "CLEAR_Z",
    "EVIDENCE_FLAT",
    "combine_evidence",
    "shape_evidence",
]

EVIDENCE_FLAT = 2.0
"""A drive whose deviance over the grid stays below this everywhere says nothing about the
shape (the χ² of one parameter at 84 %): it is not kept [-]."""
CLEAR_Z = 3.0
"""A bin enters when its measured grip is at least this many 1σ of its noise [-]."""
_ITERS = 40  # Levenberg–Marquardt steps of a cold-started minimisation
_N_SCAN = 12  # μ of the coarse scan per shape
_N_REFINE = 8  # golden-section steps around the scan's best μ
_GOLD = 0.5 * (np.sqrt(5.0) - 1.0)


def _nll_at(mu, k, b, rho, pri: Priors, p0, tabs, work) -> float:
    f, df, inv_dx = tabs
    ws, wm, wj, th, dl = work
    n = b.shape[0]
    return float(
        K.profile_nll(
            mu, k, b, rho, pri.mean, pri.sd, pri.delta, f, df, inv_dx, p0,
            pri.mean.copy(), np.zeros(n), _ITERS, th, dl, ws, wm, wj, np.inf,
        )
    )  # fmt: skip


def _shape_min(k, b, rho, pri, p0, tabs, work, lo: float, hi: float) -> float:
    """Min over μ ∈ [lo, hi] of the profile NLL of shape *k*: a log-spaced scan, then a golden
    section search between the neighbours of the scan's best.
    """
    ln = np.linspace(np.log(lo), np.log(hi), _N_SCAN)
    vals = np.array([_nll_at(float(np.exp(x)), k, b, rho, pri, p0, tabs, work) for x in ln])
    if not np.isfinite(vals).any():
        return np.inf
    i = int(np.nanargmin(vals))
    a, c = ln[max(i - 1, 0)], ln[min(i + 1, ln.size - 1)]
    best = float(vals[i])
    x1, x2 = c - _GOLD * (c - a), a + _GOLD * (c - a)
    f1 = _nll_at(float(np.exp(x1)), k, b, rho, pri, p0, tabs, work)
    f2 = _nll_at(float(np.exp(x2)), k, b, rho, pri, p0, tabs, work)
    for _ in range(_N_REFINE):
        if f1 < f2:
            c, x2, f2 = x2, x1, f1
            x1 = c - _GOLD * (c - a)
            f1 = _nll_at(float(np.exp(x1)), k, b, rho, pri, p0, tabs, work)
        else:
            a, x1, f1 = x1, x2, f2
            x2 = a + _GOLD * (c - a)
            f2 = _nll_at(float(np.exp(x2)), k, b, rho, pri, p0, tabs, work)
    return float(np.nanmin([best, f1, f2]))


def shape_evidence(
    wheels: pd.DataFrame,
    vehicle: Vehicle,
    axle: str,
    *,
    noise: NoiseModel | None = None,
    options: WindowOptions | None = None,
) -> np.ndarray | None:
    """What one drive says about an axle's normalised curve shape (``docs/physics.md`` §15.10).

    Parameters
    ----------
    wheels : pandas.DataFrame
        Wheel table of :func:`gripsense.estimate.friction.friction_from_motion`.
    vehicle : Vehicle
        Vehicle description (its stiffness: declared, or learned by a calibration).
    axle : str
        ``front`` or ``rear``.
    noise : NoiseModel, optional
        Measurement and parameter uncertainty.
    options : WindowOptions, optional
        Bins, merging, screening and the μ grid's range.

    Returns
    -------
    numpy.ndarray or None
        The deviance D_k ≥ 0 of each shape of :data:`~gripsense.physics.shape_grid.LEARN_GRID`
        (0 for the best) [-]; None when the drive has no cornering bins or does not tell the
        shapes apart (every D_k below :data:`EVIDENCE_FLAT`).
    """
    noise = noise or NoiseModel()
    o = options or WindowOptions()
    ab = axle_bins(wheels, axle, vehicle, noise, o.bin_s, o.min_samples)
    # cornering bins: measured grip clear of its noise (the shape's evidence lies in the high
    # ones; the low ones pin the stiffness scale the shape trades off against)
    sel = ab.data[:, 9] >= CLEAR_Z * ab.grip_sigma if ab.t0.size else np.zeros(0, bool)
    if not sel.any():
        return None
    pri = axle_priors(vehicle, axle, noise)
    mid, merged = merge_bins(ab.t0[sel], ab.t1[sel], ab.n[sel], ab.data[sel], pri, o)
    b = np.ascontiguousarray(merged)
    n = b.shape[0]
    if n == 0:
        return None
    rho = slow_correlation(mid, pri.tau_s)
    tabs = learn_tables()
    ws, wm, wj = K.workspace(b)
    work = (ws, wm, wj, np.empty(K.NG), np.zeros(n))
    lo = max(float(np.max(b[:, 9])), float(o.mu_min))  # μ below the measured grip: not carried
    hi = float(o.mu_max)
    nll = np.array(
        [_shape_min(k, b, rho, pri, ab.p0, tabs, work, lo, hi) for k in range(len(LEARN_GRID))]
    )
    if not np.isfinite(nll).any():
        return None
    dev = 2.0 * (nll - np.nanmin(nll))
    dev = np.where(np.isfinite(dev), dev, np.inf)
    if np.all(dev < EVIDENCE_FLAT):
        return None
    return dev
