"""Tyre fits from the friction pipeline's per-wheel table: seed 002 with a GNSS compass."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import pandas as pd

from gripsense.config.tyre_fit import TyreFit
from gripsense.errors import InputError
from gripsense.identify.tyre_fit.mf61_fit import fit_mf61_lateral
from gripsense.identify.tyre_fit.pac94_fit import fit_pac94

__all__ = ["FITTERS", "fit_from_wheel_table", "fit_tyre_table", "wheel_fit_points"]

FITTERS: dict[str, Callable[..., TyreFit]] = {"pac94": fit_pac94, "mf61": fit_mf61_lateral}
"""Model name → fitter of scattered (α, γ, Fz, Fy) points."""


def wheel_fit_points(wheels: pd.DataFrame, wheel: str | None = None) -> pd.DataFrame:
    """The points of a per-wheel table a fit uses (:func:`fit_from_wheel_table`'s selection):
    the rows of *wheel* that are steady, finite and loaded, as a tyre table.

    Parameters
    ----------
    wheels : pandas.DataFrame
        :attr:`gripsense.estimate.results.FrictionResult.wheels`.
    wheel : str, optional
        One wheel or an axle, as :func:`fit_from_wheel_table` takes it.

    Returns
    -------
    pandas.DataFrame
        ``alpha_rad`` [rad], ``gamma_rad`` (0) [rad], ``fz_N`` [N], ``fy_N`` [N].
    """
    t, ok, _ = _select(wheels, wheel)
    v = t.loc[ok]
    return pd.DataFrame(
        {
            "alpha_rad": v["slip_angle_rad"].to_numpy(float),
            "gamma_rad": 0.0,
            "fz_N": v["load_N"].to_numpy(float),
            "fy_N": v["force_N"].to_numpy(float),
        }
    )


def _select(wheels: pd.DataFrame, wheel: str | None):
    """The rows of *wheel*, which of them a fit uses, and why the others are not used."""
    need = ("slip_angle_rad", "load_N", "force_N")
    missing = [c for c in need if c not in wheels.columns]
    if missing:
        raise InputError(
            f"wheel table: missing column {missing[0]!r}; give the wheels table "
            "of `gripsense friction -o DIR` (wheels.parquet)"
        )
    t = wheels
    rejected: dict[str, int] = {}
    if wheel is not None:
        sel = t["wheel"].astype(str)
        t = t[(sel == wheel) | sel.str.startswith(wheel + "_")]
        if t.empty:
            have = ", ".join(sorted(set(sel)))
            raise InputError(f"wheel table: no rows for wheel/axle {wheel!r} (it has {have})")
        rejected["other_wheels"] = len(wheels) - len(t)
    elif "wheel" in t.columns:
        axles = sorted({w.split("_")[0] for w in t["wheel"].astype(str)})
        if len(axles) > 1:
            raise InputError(
                f"wheel table: it holds the {' and '.join(axles)} wheels — different tyres and "
                "different slip errors, not one curve; give --wheel front or --wheel rear "
                '(or one wheel, e.g. --wheel rear_left; in Python: wheel="front")'
            )
    ok = np.ones(len(t), bool)
    if "steady" in t.columns:
        m = ~t["steady"].fillna(False).to_numpy(bool)
        rejected["not_steady"] = int(m.sum())
        ok &= ~m
    vals = t[list(need)].to_numpy(float)
    m = ~np.all(np.isfinite(vals), axis=1) & ok
    rejected["not_finite"] = int(m.sum())
    ok &= ~m
    m = (vals[:, 1] <= 0) & ok
    rejected["no_load"] = int(m.sum())
    ok &= ~m
    return t, ok, rejected


def fit_from_wheel_table(
    wheels: pd.DataFrame,
    *,
    model: str = "pac94",
    constraints: str = "all",
    wheel: str | None = None,
    loss: str = "soft_l1",
    **kwargs,
) -> TyreFit:
    """Fit from the friction pipeline's per-wheel table (seed 002 with a GNSS compass).

    Uses ``slip_angle_rad``, ``load_N`` and ``force_N`` (lateral force estimated from vehicle
    motion, ISO) of the rows with finite values and ``steady`` True; camber is not measured, so
    γ = 0 and the camber coefficients come out flagged undetermined. ``force_sigma_N`` (when
    present) weights the points.

    Parameters
    ----------
    wheels : pandas.DataFrame
        :attr:`gripsense.estimate.results.FrictionResult.wheels`.
    model : {"pac94", "mf61"}
    constraints : str
        Constraint set.
    wheel : str, optional
        One wheel (``front_left`` …) or an axle (``front``/``rear``); required when the table
        holds wheels of both axles (their tyres and slip errors differ: one curve through both
        is no tyre).
    loss : str
        Robust loss (default ``soft_l1``: motion-derived forces have outliers).
    **kwargs
        Passed to :func:`fit_pac94` / :func:`fit_mf61_lateral`.

    Returns
    -------
    TyreFit
        ``extra["rows_used"]`` and ``extra["rows_rejected"]`` (reason → count).
    """
    t, ok, rejected = _select(wheels, wheel)
    vals = t[["slip_angle_rad", "load_N", "force_N"]].to_numpy(float)
    weights = None
    if "force_sigma_N" in t.columns:
        s = t["force_sigma_N"].to_numpy(float)[ok]
        if np.all(np.isfinite(s) & (s > 0)):
            weights = 1.0 / s**2
    a, fz, fy = vals[ok, 0], vals[ok, 1], vals[ok, 2]
    fitter = FITTERS.get(model)
    if fitter is None:
        raise InputError(f"model={model!r}; use pac94 or mf61")
    if not ok.any():
        raise InputError(
            "wheel table: no steady cornering rows with slip angle, load and force to fit "
            f"(rejected: {', '.join(f'{k} {v}' for k, v in rejected.items() if v)})"
        )
    fit = fitter(a, 0.0, fz, fy, constraints=constraints, loss=loss, weights=weights, **kwargs)
    fit.extra.update(
        {"rows_used": int(ok.sum()), "rows_rejected": {k: v for k, v in rejected.items() if v}}
    )
    return fit


def fit_tyre_table(
    table: pd.DataFrame,
    info: dict,
    *,
    model: str = "pac94",
    wheel: str | None = None,
    **kwargs,
) -> TyreFit:
    """Fit a table as :func:`gripsense.io.tyres.tyre_table.read_tyre_table` reads it: measured
    points with the model's fitter of :data:`FITTERS`, a friction run's wheel table with
    :func:`fit_from_wheel_table`.

    Parameters
    ----------
    table : pandas.DataFrame
        Points (``alpha_rad`` [rad], ``gamma_rad`` [rad], ``fz_N`` [N], ``fy_N`` [N]) or a
        wheel table.
    info : dict
        The reader's account of the table; its ``source`` (``table`` or ``wheels``) says which
        [-].
    model : {"pac94", "mf61"}
        A key of :data:`FITTERS` [-].
    wheel : str, optional
        Wheel or axle of a wheel table (:func:`fit_from_wheel_table`) [-].
    **kwargs
        Passed to the fitter (``constraints``, ``loss``, ``max_iter`` …).

    Returns
    -------
    TyreFit
        The fit.
    """
    if info["source"] == "wheels":
        return fit_from_wheel_table(table, model=model, wheel=wheel, **kwargs)
    return FITTERS[model](
        table["alpha_rad"], table["gamma_rad"], table["fz_N"], table["fy_N"], **kwargs
    )
