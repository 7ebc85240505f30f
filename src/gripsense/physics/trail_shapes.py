"""How the pneumatic trail falls with the utilisation: a family of shapes for estimators that do
not know the tyre (``docs/physics.md`` §16.5).

The trail normalised by its zero-slip value, as a function of the utilisation u = |F_y|/(μ F_z)
on the rising side of the force curve, is written

    τ(u) = t/t₀ = 1 − (1 − τ₁) u^p,        0 ≤ u ≤ 1,

with p how late the trail starts to fall and τ₁ what is left of it at the force's peak. The
brush model with parabolic pressure (§16.1) lies within 0.06 of the members with p ≤ 1.9,
τ₁ ≤ 0.15; the Magic Formula files the project ships (their Q*Z coefficients, at 0.5–1.5 times
their nominal load) within 0.065 of members with p ≥ 1.9. :data:`TRAIL_FAMILY` covers both; a
vehicle file that says its tyre is ``brush`` or ``magic-formula`` narrows it
(:func:`trail_shape_ids`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from gripsense._arrays import as_float_array

__all__ = ["TRAIL_FAMILY", "TrailShape", "trail_ratio", "trail_shape_ids"]


@dataclass(frozen=True)
class TrailShape:
    """One member of the trail family.

    Attributes
    ----------
    p : float
        Exponent: how late the trail starts to fall [-].
    tau1 : float
        Trail left at the force's peak, over its zero-slip value [-].
    """

    p: float
    tau1: float

    @property
    def name(self) -> str:
        """A label (``trail p=2.4 τ1=0.15``)."""
        return f"trail p={self.p:g} τ1={self.tau1:g}"


def trail_ratio(utilisation, p, tau1):
    """t/t₀ = 1 − (1 − τ₁) u^p for the utilisation clipped to [0, 1] [-].

    Parameters
    ----------
    utilisation : array_like
        u = |F_y|/(μ F_z) [-].
    p : array_like
        Exponent of the family [-].
    tau1 : array_like
        Trail left at the peak [-].

    Returns
    -------
    numpy.ndarray
        τ [-].

    References
    ----------
    docs/physics.md §16.5.
    """
    u = np.clip(as_float_array(utilisation, "utilisation"), 0.0, 1.0)
    p = as_float_array(p, "p")
    tau1 = as_float_array(tau1, "tau1")
    return 1.0 - (1.0 - tau1) * u**p


def _family() -> tuple[TrailShape, ...]:
    return tuple(
        TrailShape(p, t1)
        for p in (1.2, 1.5, 1.9, 2.4, 3.0, 3.8, 4.8)
        for t1 in (0.0, 0.15, 0.3, 0.45)
    )


TRAIL_FAMILY: tuple[TrailShape, ...] = _family()
"""The trail shapes an estimator profiles over: p 1.2–4.8 × τ₁ 0–0.45."""


def trail_shape_ids(shape: str) -> np.ndarray:
    """The members of :data:`TRAIL_FAMILY` a declared tyre shape allows.

    Parameters
    ----------
    shape : str
        The vehicle file's ``[tyre.front] shape``: ``any``, ``brush`` or ``magic-formula``.

    Returns
    -------
    numpy.ndarray
        Indices into :data:`TRAIL_FAMILY`.
    """
    ids = []
    for i, s in enumerate(TRAIL_FAMILY):
        if shape == "brush" and not (s.p <= 1.9 and s.tau1 <= 0.15):
            continue
        if shape == "magic-formula" and s.p < 1.9:
            continue
        ids.append(i)
    return np.array(ids, dtype=np.int64)
