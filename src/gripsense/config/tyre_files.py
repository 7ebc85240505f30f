"""Tyre models from files: a registry of file types, each read by io and built into a physics
model here (physics never reads files; io never builds models).

=================  =============================================================  ===========
file               model                                                          forces
=================  =============================================================  ===========
``*.tir``          Magic Formula 5.2 / 6.1 / 6.2 (:class:`~gripsense.physics.      Fx, Fy
                   magic_formula.MFTyre`), ISO-W
``*.json`` (fit)   a gripsense PAC94 or MF 6.1 fit (``gripsense tyre fit -o``)      Fy
``*.json``         PAC89 coefficients in Project Chrono's layout                  Fx, Fy
=================  =============================================================  ===========
"""

from __future__ import annotations

import json
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from gripsense.config.tyre_fit import TyreFit
from gripsense.errors import InputError
from gripsense.io.text import read_text
from gripsense.io.tyres.pac89 import read_pac89_json
from gripsense.io.tyres.tir import TirFile, read_tir
from gripsense.physics.magic_formula import MFTyre
from gripsense.physics.magic_formula.pac89 import pac89_lateral, pac89_longitudinal

__all__ = ["TYRE_FILE_TYPES", "TyreModel", "load_mf_tyre", "load_tyre_model"]


@dataclass(frozen=True)
class TyreModel:
    """A tyre model read from a file, ready to evaluate.

    Attributes
    ----------
    forces : callable
        ``forces(fz, kappa, alpha, gamma, side=None) -> (fx, fy)`` with SI inputs (N, slip
        ratio, rad, rad) and forces in N (``fx`` NaN for lateral-only models).
    description : str
        What the model is and its sign convention.
    warnings : tuple of str
        What was read leniently (unknown ``.tir`` keys).
    fy_iso : callable or None
        ``fy_iso(fz, alpha, gamma) -> fy``: the pure lateral force in ISO-W axes (positive slip
        → negative force; inclination positive when the wheel's top leans to the right), the
        form the simulator tabulates (None: the model's sign convention is its data's).
    fz_nominal : float
        The model's nominal load [N].
    aligning_iso : callable or None
        ``aligning_iso(fz, alpha, gamma) -> mz``: the aligning moment at zero slip ratio [N m]
        in ISO-W axes (None: the model has no aligning moment).
    limits : dict
        The file's validity limits that ``forces`` clips its inputs to, as MFeval does:
        ``"fz"`` [N], ``"alpha"`` [rad], ``"gamma"`` [rad], ``"kappa"`` [-] → (min, max) (±inf
        where the file gives none; empty: the model clips nothing). ``forces(..., limits=False)``
        evaluates the formula beyond them.
    """

    forces: Callable
    description: str
    warnings: tuple[str, ...] = ()
    fy_iso: Callable | None = None
    fz_nominal: float = 4000.0
    aligning_iso: Callable | None = None
    limits: dict[str, tuple[float, float]] = field(default_factory=dict)


def load_mf_tyre(source: str | Path | TirFile, *, lenient: bool = False) -> MFTyre:
    """A Magic Formula tyre from a ``.tir`` file.

    Parameters
    ----------
    source : str or Path or TirFile
        Path of a ``.tir`` (plain or ``.gz``) or a file already read.
    lenient : bool
        Accept unknown keys with a warning (:func:`gripsense.io.tyres.tir.read_tir`).

    Returns
    -------
    MFTyre
        The model.
    """
    tir = source if isinstance(source, TirFile) else read_tir(source, lenient=lenient)
    return MFTyre(tir.parameters(), name=tir.name)


def _tir(path: Path, lenient: bool) -> TyreModel:
    tir = read_tir(path, lenient=lenient)
    tyre = load_mf_tyre(tir)

    def forces(fz, kappa, alpha, gamma, side=None, limits=True):
        r = tyre.forces(fz, kappa, alpha, gamma, side=side, limits=limits)
        return r.fx, r.fy

    par = tyre.params
    inf = float("inf")
    bounds = {
        "fz": (0.0, float(par.get("FZMAX", inf))),
        "alpha": (float(par.get("ALPMIN", -inf)), float(par.get("ALPMAX", inf))),
        "gamma": (float(par.get("CAMMIN", -inf)), float(par.get("CAMMAX", inf))),
        "kappa": (float(par.get("KPUMIN", -inf)), float(par.get("KPUMAX", inf))),
    }

    def fy_iso(fz, alpha, gamma):
        return tyre.forces(fz, np.zeros_like(fz), alpha, gamma).fy

    def aligning_iso(fz, alpha, gamma):
        return tyre.aligning_moment(fz, np.zeros_like(fz), alpha, gamma).mz

    return TyreModel(
        forces,
        f"MF {tyre.version} ({path.name}; ISO-W axes)",
        tuple(tir.warnings),
        fy_iso=fy_iso,
        fz_nominal=float(tyre.params["FNOMIN"]),
        aligning_iso=aligning_iso,
        limits=bounds,
    )


def _json(path: Path, lenient: bool) -> TyreModel:
    text = read_text(path, "tyre model file")
    try:
        doc = json.loads(text)
    except json.JSONDecodeError:
        doc = None  # PAC89 files carry // comments: read below
    if isinstance(doc, dict) and doc.get("model") in ("pac94", "mf61"):
        fit = TyreFit.from_dict(doc, source=str(path))

        def fit_forces(fz, kappa, alpha, gamma, side=None):
            fy = fit.predict(fz, alpha, gamma)
            return np.full(np.shape(fy), np.nan), fy

        return TyreModel(
            fit_forces,
            f"{fit.model.upper()} fit ({path.name}, {fit.variant} shifts; lateral only; the "
            "fitted data's sign convention)",
        )
    c = read_pac89_json(path)

    def forces(fz, kappa, alpha, gamma, side=None):
        fx = pac89_longitudinal(c["longitudinal"], fz, kappa) if "longitudinal" in c else np.nan
        return fx, pac89_lateral(c["lateral"], fz, alpha, gamma)

    def fy_iso(fz, alpha, gamma):
        # Project Chrono's layout: positive force for positive slip, turned to ISO
        return -pac89_lateral(c["lateral"], fz, alpha, -gamma)

    return TyreModel(
        forces, f"PAC89 ({path.name}; the coefficients' own sign convention)", fy_iso=fy_iso
    )


TYRE_FILE_TYPES: dict[str, Callable[[Path, bool], TyreModel]] = {
    ".tir": _tir,
    ".gz": _tir,
    ".json": _json,
}
"""File suffix → loader."""


def load_tyre_model(path: str | Path, *, lenient: bool = False) -> TyreModel:
    """Read a tyre model file of any registered type (:data:`TYRE_FILE_TYPES`).

    Parameters
    ----------
    path : str or Path
        ``.tir`` (MF 5.2/6.1/6.2), PAC89 ``.json`` or a gripsense fit ``.json``.
    lenient : bool
        Read unknown ``.tir`` keys with a warning instead of an error.

    Returns
    -------
    TyreModel
        The model and its description.
    """
    path = Path(path)
    loader = TYRE_FILE_TYPES.get(path.suffix.lower())
    if loader is None:
        raise InputError(
            f"{path}: unknown model file type {path.suffix!r}; give a .tir (MF 5.2/6.1/6.2), "
            "a PAC89 .json or a gripsense fit .json"
        )
    return loader(path, lenient)
