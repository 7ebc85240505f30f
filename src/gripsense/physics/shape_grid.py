"""The grid of normalised lateral curve shapes a car's own limits can teach
(``docs/physics.md`` §15.10).

The estimator's prior family (:data:`gripsense.physics.tyre_curves.SHAPE_FAMILY`) holds a few
shapes spread over what tyres span; learning needs a grid fine enough that the shape a drive
pins lies close to one of its members: the Magic Formula normalised curves
f(x) = sin(C_s atan(x/C_s − E (x/C_s − atan(x/C_s)))) (§14) on C_s ∈ 1.1…2.0 (step 0.1) ×
E ∈ −2.0…0.9 (step 0.2) whose peak lies in :data:`~gripsense.physics.tyre_curves.PEAK_RANGE`,
and both brush shapes. Up to 1.5 × the peak's slip neighbouring members differ by at most 0.04
in f (median 0.02), so any Magic Formula shape inside the grid lies within about 0.02 of a
member (``tests/physics/test_shape_grid.py``).
"""

from __future__ import annotations

from functools import cache

import numpy as np

from gripsense.physics.tyre_curves import (
    PEAK_RANGE,
    CurveShape,
    curve_tables,
    magic_formula_normalised,
)

__all__ = [
    "LEARN_C",
    "LEARN_E",
    "LEARN_GRID",
    "SHAPES_DISAGREE_LEVEL",
    "SHAPE_DRIFT",
    "combine_evidence",
    "learn_tables",
    "learned_evidence",
]

LEARN_C = tuple(float(c) for c in np.round(np.arange(1.1, 2.0001, 0.1), 2))
"""Shape factors C_s of the grid [-]."""
LEARN_E = tuple(float(e) for e in np.round(np.arange(-2.0, 0.9001, 0.2), 2))
"""Curvature factors E of the grid [-]."""


def _grid() -> tuple[CurveShape, ...]:
    out = [CurveShape("brush-2", "brush-2"), CurveShape("brush-4", "brush-4")]
    x = np.linspace(0.0, 40.0, 8001)
    for c in LEARN_C:
        for e in LEARN_E:
            x_peak = x[int(np.argmax(magic_formula_normalised(x, c, e)))]
            if PEAK_RANGE[0] <= x_peak <= PEAK_RANGE[1]:
                out.append(CurveShape(f"mf C{c:g} E{e:g}", "magic-formula", c, e))
    return tuple(out)


LEARN_GRID: tuple[CurveShape, ...] = _grid()
"""The shapes a calibration's learned evidence is given over (brush P2, brush P4, then the
Magic Formula grid in C_s-major order)."""


@cache
def learn_tables() -> tuple[np.ndarray, np.ndarray, float]:
    """Force tables of :data:`LEARN_GRID`, their slopes and 1/Δx of the table grid (computed
    once; :func:`~gripsense.physics.tyre_curves.curve_tables`).

    Returns
    -------
    f : numpy.ndarray
        F/(μ Fz) per shape and x [-].
    df : numpy.ndarray
        df/dx [-].
    inv_dx : float
        1 / grid step of x [-].
    """
    x, f, df = curve_tables(LEARN_GRID)
    return f, df, 1.0 / (x[1] - x[0])


SHAPES_DISAGREE_LEVEL = 0.954
"""Drives' shape learnings disagree when no shape of the grid explains them all at this level
(2σ): the minimum of their summed deviances beyond the χ² quantile of 2 (n − 1) degrees of
freedom (each drive pins the shape's two factors) [-]."""


def combine_evidence(drives: list[np.ndarray]) -> np.ndarray:
    """The evidence of independent drives together: their deviances added, 0 at the best shape
    (``docs/physics.md`` §15.10).

    Parameters
    ----------
    drives : list of numpy.ndarray
        Each drive's deviance per shape of :data:`LEARN_GRID` [-].

    Returns
    -------
    numpy.ndarray
        The combined deviance per shape [-] (inf where no drive's shape could carry its data).
    """
    if not drives:
        raise ValueError("no drive's evidence to combine")
    total = np.sum(np.vstack(drives), axis=0)
    best = np.min(total[np.isfinite(total)]) if np.isfinite(total).any() else 0.0
    return total - best


def learned_evidence(drives: list[np.ndarray]) -> tuple[np.ndarray, bool]:
    """What several drives together say of an axle's shape (``docs/physics.md`` §15.10): their
    deviances added (:func:`combine_evidence`) — unless they disagree (no shape explains them
    all at :data:`SHAPES_DISAGREE_LEVEL`), then each shape's smallest deviance over the drives,
    so that the learned shape covers every drive's learning instead of a shape none supports.

    Parameters
    ----------
    drives : list of numpy.ndarray
        Each drive's deviance per shape of :data:`LEARN_GRID` [-].

    Returns
    -------
    deviance : numpy.ndarray
        Per shape, 0 at the best [-].
    disagree : bool
        True when the drives disagreed (the deviance is their envelope).
    """
    from scipy.stats import chi2

    total = np.sum(np.vstack(drives), axis=0) if drives else np.zeros(0)
    n = len(drives)
    finite = total[np.isfinite(total)]
    if n < 2 or (finite.size and finite.min() <= chi2.ppf(SHAPES_DISAGREE_LEVEL, 2 * (n - 1))):
        return combine_evidence(drives), False
    env = np.min(np.vstack(drives), axis=0)
    return env - np.min(env[np.isfinite(env)]), True


SHAPE_DRIFT = 0.05
"""How far an axle's normalised curve may move from one road to another, as the largest
difference in F/(μ Fz) up to 1.5 × the peak's slip [-]: each library tyre's own curve on μ
0.3–0.5 against its dry one (LMUY scaled; loads 0.5–1.5 × nominal, camber ±3°) moved by a median
0.002, 0.043 at the 90th percentile, 0.059 at the 95th and 0.118 at most (a truck tyre); real
low-grip surfaces move it more than LMUY does (``docs/physics.md`` §14.3, §15.10)."""


def _distances(fa: np.ndarray, fb: np.ndarray, x: np.ndarray) -> np.ndarray:
    """Largest |f_a − f_b| for x up to 1.5 × the later peak of each pair of tabulated shapes."""
    step = max(round(0.04 / (x[1] - x[0])), 1)  # every 0.04 in x: f moves < 0.01
    peak_a, peak_b = x[np.argmax(fa, axis=1)], x[np.argmax(fb, axis=1)]
    fa, fb, x = fa[:, ::step], fb[:, ::step], x[::step]
    out = np.zeros((fa.shape[0], fb.shape[0]))
    for j in range(fa.shape[0]):
        reach = 1.5 * np.maximum(peak_a[j], peak_b)
        diff = np.abs(fa[j][None, :] - fb)
        out[j] = np.where(x[None, :] <= reach[:, None], diff, 0.0).max(axis=1)
    return out


KEEP_LEVEL = 0.95
"""A prior member stays possible while a shape within :data:`SHAPE_DRIFT` of it is within the
χ² quantile of two degrees of freedom (the shape's two factors) at this level [-]."""


def member_evidence(deviance: np.ndarray, prior: str) -> tuple[np.ndarray, np.ndarray]:
    """Learned evidence carried to the members of a tyre's prior family on another road
    (``docs/physics.md`` §15.10): D_m = min D_k over the grid's shapes k within
    :data:`SHAPE_DRIFT` of member m (inf when none is), less the smallest.

    Parameters
    ----------
    deviance : numpy.ndarray
        Learned deviance per shape of :data:`LEARN_GRID` [-].
    prior : str
        The tyre's ``shape`` (``any``, ``brush``, ``magic-formula`` or a category).

    Returns
    -------
    members : numpy.ndarray
        Indices into :data:`~gripsense.physics.tyre_curves.SHAPE_FAMILY` of the prior's members.
    carried : numpy.ndarray
        Their carried deviance [-].
    """
    members, dist = _member_distances(prior)
    d = np.asarray(deviance, dtype=float)
    carried = np.min(np.where(dist <= SHAPE_DRIFT, d[:, None], np.inf), axis=0)
    if not np.isfinite(carried).any():  # no member near a learnable shape: the nearest member
        carried = np.where(np.arange(members.size) == np.argmin(dist[np.argmin(d)]), 0.0, np.inf)
    return members, carried - np.min(carried)


def possible_members(deviance: np.ndarray, prior: str) -> tuple[int, ...]:
    """The members of a tyre's prior family its learned evidence leaves possible on another road
    (``docs/physics.md`` §15.10): carried deviance (:func:`member_evidence`) within the χ²
    quantile of 2 degrees of freedom at :data:`KEEP_LEVEL`. Learning only removes members: the
    set is never wider than the prior's, and holds its best member.

    Parameters
    ----------
    deviance : numpy.ndarray
        Learned deviance per shape of :data:`LEARN_GRID` [-].
    prior : str
        The tyre's ``shape``.

    Returns
    -------
    tuple of int
        Indices into :data:`~gripsense.physics.tyre_curves.SHAPE_FAMILY`.
    """
    from scipy.stats import chi2

    members, carried = member_evidence(deviance, prior)
    return tuple(int(m) for m in members[carried <= chi2.ppf(KEEP_LEVEL, 2)])


@cache
def _member_distances(prior: str) -> tuple[np.ndarray, np.ndarray]:
    """The prior's member indices and the distance of every grid shape to each (grid × members)."""
    from gripsense.physics.tyre_curves import SHAPE_FAMILY, shape_members

    members = np.array(shape_members(prior), dtype=np.int64)
    x, fm, _ = curve_tables(tuple(SHAPE_FAMILY[i] for i in members))
    f, _, _ = learn_tables()
    return members, _distances(f, fm, x)
