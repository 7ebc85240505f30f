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
(:func:`trail_shape_ids`). A tyre whose Magic Formula file is known has its own members
(:func:`tyre_trail_ratio`, :func:`fit_trail_shape`; §16.7).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
from scipy.optimize import least_squares, minimize

from gripsense._arrays import as_float_array

if TYPE_CHECKING:
    from gripsense.physics.magic_formula import MFTyre

__all__ = [
    "TRAIL_FAMILY",
    "TrailShape",
    "fit_trail_shape",
    "trail_ratio",
    "trail_shape_ids",
    "tyre_trail_ratio",
]


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


def tyre_trail_ratio(
    tyre: MFTyre,
    fz: float,
    utilisation: np.ndarray,
    *,
    max_slip_deg: float = 25.0,
    gamma_rad: float = 0.0,
) -> tuple[np.ndarray, float]:
    """A Magic Formula tyre's lever of the lateral force over the utilisation of its rising
    side, relative to its value at zero slip, and that zero-slip lever.

    The lever is ξ = −M_z/F_y (pneumatic trail with the residual moment's share, as a steering
    system feels it), the mean of a left and a right slip so that the residual moment's and the
    shifts' asymmetry (conicity, ply steer) drops out; u = F_y/F_y,peak on the rising side.

    Parameters
    ----------
    tyre : MFTyre
        The tyre (:meth:`MFTyre.aligning_moment`).
    fz : float
        Vertical load [N].
    utilisation : numpy.ndarray
        Utilisations to evaluate, 0–1 [-].
    max_slip_deg : float
        Largest slip angle searched for the force's peak [deg].
    gamma_rad : float
        Inclination of the wheel (both slips at the same one) [rad].

    Returns
    -------
    tau : numpy.ndarray
        ξ(u)/ξ(0) [-].
    xi0 : float
        ξ at zero slip (the zero-slip trail with the residual moment's share) [m].

    References
    ----------
    Pacejka (2012) (4.E71)–(4.E76), M_z = −t F_y' + M_zr, through
    :meth:`MFTyre.aligning_moment`; docs/physics.md §16.2 and §16.7.
    """
    alpha = np.deg2rad(np.geomspace(0.005, max_slip_deg, 4000))
    left = tyre.aligning_moment(fz, 0.0, -alpha, gamma_rad)
    right = tyre.aligning_moment(fz, 0.0, alpha, gamma_rad)
    force = 0.5 * (left.fy - right.fy)
    moment = 0.5 * (left.mz - right.mz)
    peak = int(np.argmax(force))
    lever = -moment[: peak + 1] / force[: peak + 1]
    u = force[: peak + 1] / force[peak]
    tau = np.interp(np.clip(as_float_array(utilisation, "utilisation"), 0, 1), u, lever / lever[0])
    return tau, float(lever[0])


def fit_trail_shape(utilisation, tau) -> tuple[TrailShape, float]:
    """The member of the family's form τ = 1 − (1 − τ₁) u^p nearest a trail curve.

    Parameters
    ----------
    utilisation : array_like
        u, 0–1 [-].
    tau : array_like
        The curve's t/t₀ at *utilisation* [-].

    Returns
    -------
    shape : TrailShape
        p (0.5–10) and τ₁ making the largest error least (from the least-squares fit).
    max_error : float
        The largest |τ − τ_shape| over the points [-].

    References
    ----------
    docs/physics.md §16.5, §16.7.
    """
    u = as_float_array(utilisation, "utilisation")
    y = as_float_array(tau, "tau")
    fit = least_squares(
        lambda x: trail_ratio(u, x[0], x[1]) - y, x0=(3.0, 0.2), bounds=((0.5, -0.5), (10.0, 1.0))
    )
    # then the largest error made least (the form error is stated as that largest error)
    worst = minimize(
        lambda x: float(np.max(np.abs(trail_ratio(u, np.clip(x[0], 0.5, 10.0), x[1]) - y))),
        fit.x,
        method="Nelder-Mead",
        options={"xatol": 1e-4, "fatol": 1e-6},
    )
    x = worst.x if worst.fun < np.max(np.abs(fit.fun)) else fit.x
    shape = TrailShape(round(float(np.clip(x[0], 0.5, 10.0)), 3), round(float(x[1]), 3) + 0.0)
    return shape, float(np.max(np.abs(trail_ratio(u, shape.p, shape.tau1) - y)))
