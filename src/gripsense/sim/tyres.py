"""Tyres of the simulator that are not the estimator's: Magic Formula (``.tir``) and PAC89
curves, tabulated for the compiled vehicle model.

A lateral tyre model from a file is evaluated once on a grid of slip angle α, load Fz and
inclination γ (ISO-W: positive when the wheel's top leans to the right) and interpolated
trilinearly during the integration. The road's friction scales the curve by similarity
(``docs/physics.md`` §15.1, after Pacejka, *Tyre and Vehicle Dynamics*, §4.3.2):

    F_y(α, Fz, γ; μ_road) = λ F_0(α / λ, Fz, γ),   λ = μ_road / μ_ref,

with μ_ref the file's own peak |F_y|/Fz at its nominal load without camber. The cornering
stiffness, its growth with load and the camber thrust of the file are kept; the peak becomes
μ_road at the nominal load and follows the file's load and camber dependence elsewhere. The
*true* friction of a wheel is then its peak λ max_α ±F_0/Fz at its current load and
inclination, in the direction of its force — what the benchmark compares with.

The aligning moment of a ``.tir`` file, M_z0(α, Fz, γ) at κ = 0 (:meth:`gripsense.physics.MFTyre.
aligning_moment`), is tabulated on the same grid and scaled by the same similarity,
M_z = λ M_z0(α/λ, Fz, γ), so the trail falls with the utilisation as the file's does
(``docs/physics.md`` §16.2, §16.4).

Combined slip: a wheel that drives or brakes keeps λ √(1 − (F_x/(μ F_z))²) (friction circle),
as the brush tyre of :mod:`gripsense.sim.vehicle` does; the file's own combined-slip functions
need the slip ratio, which the planar model does not integrate.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from functools import cached_property
from pathlib import Path

import numpy as np

from gripsense.config.tyre_files import load_tyre_model
from gripsense.errors import InputError

__all__ = ["SimTyre", "load_sim_tyre", "sim_tyre_from_function"]

ALPHA_MAX = np.deg2rad(30.0)
GAMMA_MAX = np.deg2rad(10.0)


@dataclass(frozen=True)
class SimTyre:
    """A tabulated lateral tyre curve for the simulator.

    Attributes
    ----------
    name : str
        Label (the file name).
    fy : numpy.ndarray
        F_0 on the grid, shape (n_alpha, n_fz, n_gamma) [N] (ISO: positive α → negative force).
    peak : numpy.ndarray
        max_α F_0/Fz and max_α −F_0/Fz per load and inclination, shape (n_fz, n_gamma, 2) [-].
    alpha_step, fz_step, gamma_step : float
        Grid steps [rad], [N], [rad]; α and γ grids are symmetric about 0, Fz starts at 0.
    mu_ref : float
        Peak |F_0|/Fz at the nominal load without camber [-].
    fz_nominal : float
        Nominal load [N].
    mz : numpy.ndarray or None
        Aligning moment M_z0 on the grid [N m] (None: the model has no aligning moment).
    """

    name: str
    fy: np.ndarray
    peak: np.ndarray
    alpha_step: float
    fz_step: float
    gamma_step: float
    mu_ref: float
    fz_nominal: float
    mz: np.ndarray | None = None

    def axes(self) -> np.ndarray:
        """Grid description for the compiled core: α₀, dα, Fz₀, dFz, γ₀, dγ, μ_ref."""
        na, _, ng = self.fy.shape
        return np.array(
            [
                -(na - 1) / 2 * self.alpha_step,
                self.alpha_step,
                0.0,
                self.fz_step,
                -(ng - 1) / 2 * self.gamma_step,
                self.gamma_step,
                self.mu_ref,
            ]
        )

    def force(self, alpha, fz, gamma=0.0, mu_road: float | None = None) -> np.ndarray:
        """Lateral force from the table (for checks; the simulator interpolates the same way).

        Parameters
        ----------
        alpha : array_like
            Slip angle [rad].
        fz : array_like
            Vertical load [N].
        gamma : array_like
            Inclination angle [rad].
        mu_road : float, optional
            Road friction (default: the file's own, λ = 1) [-].

        Returns
        -------
        numpy.ndarray
            F_y [N].
        """
        from gripsense.sim.dynamics import tab_force  # the simulator's own interpolation

        lam = 1.0 if mu_road is None else mu_road / self.mu_ref
        ax = np.concatenate([[1.0], self.axes()])
        a, f, g = np.broadcast_arrays(np.asarray(alpha, float) / lam, fz, gamma)
        out = np.array(
            [
                tab_force(self.fy, ax, x, y, z)
                for x, y, z in zip(a.ravel(), f.ravel(), g.ravel(), strict=True)
            ]
        )
        return lam * out.reshape(a.shape)

    def aligning(self, alpha, fz, gamma=0.0, mu_road=None) -> tuple[np.ndarray, np.ndarray]:
        """Aligning moment and lateral force from the tables, scaled to the road.

        Parameters as :meth:`SimTyre.force`.

        Returns
        -------
        mz : numpy.ndarray
            λ M_z0(α/λ, Fz, γ) [N m], ISO.
        fy : numpy.ndarray
            λ F_0(α/λ, Fz, γ) [N], the force at the same point (interpolated alike).
        """
        if self.mz is None:
            raise InputError(f"{self.name}: the tyre model has no aligning moment")
        from scipy.interpolate import RegularGridInterpolator

        lam = np.ones(1) if mu_road is None else np.asarray(mu_road, float) / self.mu_ref
        a, f, g, lam = np.broadcast_arrays(np.asarray(alpha, float) / lam, fz, gamma, lam)
        grid = self._grid()
        pts = np.column_stack(
            [np.clip(x.ravel(), gr[0], gr[-1]) for x, gr in zip((a, f, g), grid, strict=True)]
        )
        mz = RegularGridInterpolator(grid, self.mz)(pts).reshape(a.shape)
        fy = RegularGridInterpolator(grid, self.fy)(pts).reshape(a.shape)
        return lam * mz, lam * fy

    def trail_by_utilisation(self, utilisation, fz) -> np.ndarray:
        """The file's pneumatic trail at a utilisation of its own peak, for a vehicle model
        whose tyres are not this file's (an aligning moment added to another model's forces).

        Per tabulated load, at zero inclination, the trail t = M_z/F_y of the curve's rising
        side (left and right averaged, which removes the residual moment and the shifts) over
        u = |F_y|/max |F_y|; interpolated in load and utilisation.

        Parameters
        ----------
        utilisation : array_like
            u = |F_y|/(μ F_z), clipped to [0, 1] [-].
        fz : array_like
            Vertical load [N].

        Returns
        -------
        numpy.ndarray
            t [m].
        """
        from scipy.interpolate import RegularGridInterpolator

        fz_grid, u_grid, table = self._trail_table
        uu = np.clip(np.asarray(utilisation, float), 0.0, 1.0)
        ff = np.clip(np.asarray(fz, float), 0.0, fz_grid[-1])
        uu, ff = np.broadcast_arrays(uu, ff)
        pts = np.column_stack([ff.ravel(), uu.ravel()])
        return RegularGridInterpolator((fz_grid, u_grid), table)(pts).reshape(uu.shape)

    def _grid(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The tables' α, Fz and γ grids."""
        ax = self.axes()
        na, nf, ng = self.fy.shape
        return (
            ax[0] + ax[1] * np.arange(na),
            ax[2] + ax[3] * np.arange(nf),
            ax[4] + ax[5] * np.arange(ng),
        )

    @cached_property
    def _trail_table(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Load grid, utilisation grid and the trail on them (:meth:`trail_by_utilisation`)."""
        if self.mz is None:
            raise InputError(f"{self.name}: the tyre model has no aligning moment")
        na, nf, ng = self.fy.shape
        k0, mid = (ng - 1) // 2, (na - 1) // 2
        u_grid = np.linspace(0.0, 1.0, 101)
        table = np.zeros((nf, u_grid.size))
        for j in range(1, nf):
            fy = 0.5 * (self.fy[mid::-1, j, k0] - self.fy[mid:, j, k0])  # α ≥ 0, ISO: F < 0
            mz = 0.5 * (self.mz[mid:, j, k0] - self.mz[mid::-1, j, k0])
            ip = int(np.argmax(fy))
            u = fy[1 : ip + 1] / fy[ip]
            t = mz[1 : ip + 1] / fy[1 : ip + 1]
            table[j] = np.interp(u_grid, np.concatenate([[0.0], u]), np.concatenate([[t[0]], t]))
        table[0] = table[1]
        return self._grid()[1], u_grid, table

    def cornering_stiffness(self, fz) -> np.ndarray:
        """Cornering stiffness |dF_y/dα| at α = 0, γ = 0 [N/rad].

        Parameters
        ----------
        fz : array_like
            Vertical load [N].

        Returns
        -------
        numpy.ndarray
            C [N/rad].
        """
        d = 0.5 * self.alpha_step
        return np.abs(self.force(d, fz) - self.force(-d, fz)) / (2 * d)


def sim_tyre_from_function(
    fy: Callable,
    fz_nominal: float,
    name: str,
    *,
    n_alpha: int = 721,
    n_fz: int = 31,
    n_gamma: int = 11,
    fz_max_factor: float = 3.0,
    aligning: Callable | None = None,
) -> SimTyre:
    """Tabulate a lateral tyre model.

    Parameters
    ----------
    fy : callable
        ``fy(fz, alpha, gamma)`` [N] for arrays of load [N], slip angle [rad] and inclination
        [rad], ISO sign (positive α → negative force).
    fz_nominal : float
        Nominal load [N].
    name : str
        Label.
    n_alpha, n_fz, n_gamma : int
        Grid sizes (α over ±30°, Fz over 0 … fz_max_factor × nominal, γ over ±10°).
    fz_max_factor : float
        Largest tabulated load as a multiple of the nominal load [-].
    aligning : callable, optional
        ``aligning(fz, alpha, gamma) -> mz [N m]`` in ISO-W axes: tabulated on the same grid
        when given.

    Returns
    -------
    SimTyre
        The table.
    """
    a = np.linspace(-ALPHA_MAX, ALPHA_MAX, n_alpha)
    fz = np.linspace(0.0, fz_max_factor * fz_nominal, n_fz)
    g = np.linspace(-GAMMA_MAX, GAMMA_MAX, n_gamma)
    A, F, G = np.meshgrid(a, fz, g, indexing="ij")
    tab = np.asarray(fy(F.ravel(), A.ravel(), G.ravel()), float).reshape(A.shape)
    tab[:, 0, :] = 0.0
    if not np.isfinite(tab).all():
        raise InputError(f"{name}: the tyre model gives non-finite forces on the table grid")
    ratio = tab / np.where(F > 0, F, 1.0)
    peak = np.stack([ratio.max(axis=0), (-ratio).max(axis=0)], axis=-1)
    peak[0] = peak[1]
    j = int(np.argmin(np.abs(fz - fz_nominal)))
    k = (n_gamma - 1) // 2
    mu_ref = float(0.5 * (peak[j, k, 0] + peak[j, k, 1]))
    mz = None
    if aligning is not None:
        mz = np.asarray(aligning(F.ravel(), A.ravel(), G.ravel()), float).reshape(A.shape)
        mz[:, 0, :] = 0.0
        if not np.isfinite(mz).all():
            raise InputError(f"{name}: the tyre model gives non-finite moments on the table grid")
    return SimTyre(name, tab, peak, a[1] - a[0], fz[1] - fz[0], g[1] - g[0], mu_ref, fz_nominal, mz)


def load_sim_tyre(path: str | Path) -> SimTyre:
    """A simulator tyre from a tyre model file of the registry (:func:`gripsense.config.
    tyre_files.load_tyre_model`: ``.tir`` MF 5.2/6.1/6.2 or a PAC89 ``.json``).

    Parameters
    ----------
    path : str or Path
        The file.

    Returns
    -------
    SimTyre
        The tabulated tyre, in ISO-W axes (PAC89 coefficients in Project Chrono's layout, which
        use positive force for positive slip, are turned to ISO by the registry).
    """
    path = Path(path)
    model = load_tyre_model(path)
    if model.fy_iso is None:
        raise InputError(
            f"{path}: {model.description}: the simulator needs a model in known axes (a .tir or "
            "a PAC89 .json)"
        )
    fy = model.fy_iso
    sign = float(np.sign(fy(np.array([4000.0]), np.array([0.05]), np.array([0.0]))[0]))
    if sign > 0:
        raise InputError(f"{path}: positive slip gives positive force; expected ISO-W axes")
    return sim_tyre_from_function(fy, model.fz_nominal, path.name, aligning=model.aligning_iso)
