"""Synthetic tyre measurements with the narrow, correlated coverage of road driving.

On the road a wheel's slip angle, camber and load all follow the lateral acceleration: the
outside wheel is loaded and cambered by body roll while its slip angle grows (seed 002, Figs. 4
and 16). Points therefore lie near a curve in (α, γ, Fz), unlike a test rig's full grid, and a
one-step fit has to extrapolate along the other directions. These generators make such data from
any force function, with noise, for tests, benchmarks and the documentation.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import pandas as pd

__all__ = ["PAC94_EXAMPLE", "cornering_samples", "rig_samples"]

#: A physical PAC94 (seed 002 a0..a17) set in ISO signs (D, BCD < 0) that satisfies every
#: seed-002 constraint, used to generate synthetic data: C = 1.4, peak ≈ μ 1.0 at 4 kN,
#: cornering stiffness ≈ 1000 N/deg at 4 kN, mild camber effects, no shifts at γ = 0.
PAC94_EXAMPLE = np.array(
    [
        1.4,
        -22.1,
        -1011.0,
        -1078.0,
        1.82,
        0.208,
        -0.2,
        -0.354,
        0.0,
        0.0,
        0.02,
        0.0,
        0.0,
        -0.5,
        -2.5,
        0.01,
        -0.01,
        0.0,
    ]
)


def _frame(force, fz, alpha, gamma, noise_N, rng) -> pd.DataFrame:
    fy_true = force(fz, alpha, gamma)
    return pd.DataFrame(
        {
            "alpha_rad": alpha,
            "gamma_rad": gamma,
            "fz_N": fz,
            "fy_N": fy_true + noise_N * rng.standard_normal(len(fz)),
            "fy_true_N": fy_true,
        }
    )


def cornering_samples(
    force: Callable[[np.ndarray, np.ndarray, np.ndarray], np.ndarray],
    n: int,
    *,
    rng: np.random.Generator,
    fz_static_N: float = 4000.0,
    load_transfer_N_per_g: float = 2600.0,
    camber_static_rad: float = np.deg2rad(-0.5),
    camber_per_g_rad: float = np.deg2rad(2.5),
    ay_max_g: float = 0.85,
    alpha_at_max_rad: float = np.deg2rad(7.0),
    noise_N: float = 40.0,
) -> pd.DataFrame:
    """Samples of one (left) wheel while cornering both ways, ISO axes.

    Parameters
    ----------
    force : callable
        ``force(fz [N], alpha [rad], gamma [rad]) -> Fy [N]``.
    n : int
        Number of samples.
    rng : numpy.random.Generator
        Random source.
    fz_static_N : float
        Static load [N].
    load_transfer_N_per_g : float
        Load change per g of lateral acceleration [N/g] (a left turn, ay > 0, unloads the left
        wheel).
    camber_static_rad, camber_per_g_rad : float
        Static camber and camber change per g from body roll [rad, rad/g].
    ay_max_g : float
        Largest |ay| [g].
    alpha_at_max_rad : float
        |α| at the largest |ay| [rad]; α grows as |ay|^1.5 (stiffer near the origin, saturating).
    noise_N : float
        Force noise 1σ [N]; α, γ, Fz get 0.2°, 0.1° and 3 % scatter.

    Returns
    -------
    pandas.DataFrame
        ``alpha_rad``, ``gamma_rad``, ``fz_N``, ``fy_N`` (noisy) and ``fy_true_N``.
    """
    ay = rng.uniform(-ay_max_g, ay_max_g, n)
    fz = (fz_static_N - load_transfer_N_per_g * ay) * (1 + 0.03 * rng.standard_normal(n))
    gamma = camber_static_rad - camber_per_g_rad * ay + np.deg2rad(0.1) * rng.standard_normal(n)
    alpha = -np.sign(ay) * alpha_at_max_rad * (np.abs(ay) / ay_max_g) ** 1.5 + np.deg2rad(
        0.2
    ) * rng.standard_normal(n)
    return _frame(force, fz, alpha, gamma, noise_N, rng)


def rig_samples(
    force: Callable[[np.ndarray, np.ndarray, np.ndarray], np.ndarray],
    n: int,
    *,
    rng: np.random.Generator,
    fz_range_N: tuple[float, float] = (1500.0, 6500.0),
    alpha_max_rad: float = np.deg2rad(12.0),
    gamma_max_rad: float = np.deg2rad(4.0),
    noise_N: float = 30.0,
) -> pd.DataFrame:
    """Independent uniform (α, γ, Fz) samples, as a flat-track rig sweeps them (same columns as
    :func:`cornering_samples`).
    """
    fz = rng.uniform(*fz_range_N, n)
    alpha = rng.uniform(-alpha_max_rad, alpha_max_rad, n)
    gamma = rng.uniform(-gamma_max_rad, gamma_max_rad, n)
    return _frame(force, fz, alpha, gamma, noise_N, rng)
