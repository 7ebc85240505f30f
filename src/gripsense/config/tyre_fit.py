"""The result of a tyre fit: coefficients, their uncertainty and how to use them."""

from __future__ import annotations

import json
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from gripsense._arrays import as_float_array
from gripsense.errors import InputError
from gripsense.physics.magic_formula.mf6 import MFTyre
from gripsense.physics.magic_formula.pac94 import N_COEF, pac94_lateral_native

__all__ = ["MF61_LATERAL", "PAC94_NAMES", "TyreFit", "mf61_parameters"]

MF61_LATERAL = (
    "PCY1",
    "PDY1",
    "PDY2",
    "PDY3",
    "PEY1",
    "PEY2",
    "PEY3",
    "PEY4",
    "PEY5",
    "PKY1",
    "PKY2",
    "PKY3",
    "PKY4",
    "PKY5",
    "PKY6",
    "PKY7",
    "PHY1",
    "PHY2",
    "PVY1",
    "PVY2",
    "PVY3",
    "PVY4",
)
PAC94_NAMES = tuple(f"a{i}" for i in range(N_COEF))
_DEG = 180.0 / np.pi


def mf61_parameters(coefs: dict, extra: dict) -> dict:
    """The parameter set of an :class:`~gripsense.physics.magic_formula.MFTyre` that holds
    fitted MF 6.1 lateral coefficients (the longitudinal ones are placeholders).

    Parameters
    ----------
    coefs : dict
        Lateral coefficient name → value (SI, as in a ``.tir``).
    extra : dict
        ``FNOMIN`` [N] and optionally ``LFZO``.

    Returns
    -------
    dict
        ``.tir``-style parameters.
    """
    params = {
        "FITTYP": 61,
        "FNOMIN": extra["FNOMIN"],
        "UNLOADED_RADIUS": 0.3,
        "LFZO": extra.get("LFZO", 1.0),
        "PCX1": 1.0,
        "PDX1": 1.0,
        "PKX1": 1.0,
    }
    params.update(coefs)
    return params


@dataclass
class TyreFit:
    """Result of a tyre fit.

    Attributes
    ----------
    model : str
        ``"pac94"`` or ``"mf61"``.
    coefficients : dict
        Name → value (PAC94: native units kN/deg; MF 6.1: SI, as in a ``.tir``).
    stderr : dict
        Name → 1σ standard error from s²(JᵀJ)⁻¹ over the free coefficients (NaN for coefficients
        fixed or held at a bound by a constraint).
    determined : dict
        Name → False where the data cannot determine the coefficient (fixed, at a bound, or
        relative standard error > 1 / rank-deficient direction).
    covariance : ndarray
        Covariance of the free coefficients (order ``free``).
    free : list of str
    constraints : str
    active : dict
        Constraint name → True if active (within 1e-6 of its limit) at the solution.
    residual_rms_N, n, dof, cost : float, int, int, float
    success : bool
    message : str
    nfev : int
    ranges : dict
        Data ranges the fit is valid for: ``fz_N``, ``alpha_rad``, ``gamma_rad`` (min, max).
    variant : str
        PAC94 Sh/Sv form (``published`` or ``seed``).
    extra : dict
        Model constants (MF 6.1: FNOMIN, LFZO; the sign convention).
    """

    model: str
    coefficients: dict[str, float]
    stderr: dict[str, float]
    determined: dict[str, bool]
    covariance: np.ndarray
    free: list[str]
    constraints: str
    active: dict[str, bool]
    residual_rms_N: float
    n: int
    dof: int
    cost: float
    success: bool
    message: str
    nfev: int
    ranges: dict[str, tuple[float, float]]
    variant: str = "published"
    extra: dict = field(default_factory=dict)

    # ------------------------------------------------------------------ use
    @property
    def model_kwargs(self) -> dict:
        """The keyword arguments of the model function this fit plugs into (pvlib's ``fit``
        convention): PAC94 → ``pac94_lateral(fz, alpha, gamma, **fit.model_kwargs)`` of
        :mod:`gripsense.physics.magic_formula.pac94`; MF 6.1 →
        ``MFTyre(**fit.model_kwargs)``.
        """
        if self.model == "pac94":
            return {
                "a": np.array([self.coefficients[n] for n in PAC94_NAMES]),
                "variant": self.variant,
            }
        return {"params": mf61_parameters(self.coefficients, self.extra), "name": "mf61-fit"}

    def predict(self, fz, alpha, gamma=0.0) -> np.ndarray:
        """Lateral force of the fitted model.

        Parameters
        ----------
        fz : array_like
            Vertical load [N].
        alpha : array_like
            Slip angle [rad].
        gamma : array_like
            Camber angle [rad].

        Returns
        -------
        numpy.ndarray
            Lateral force [N] (the fitted data's sign convention).
        """
        fz = as_float_array(fz, "fz")
        alpha = as_float_array(alpha, "alpha")
        gamma = as_float_array(gamma, "gamma")
        kw = self.model_kwargs
        if self.model == "pac94":
            return pac94_lateral_native(
                kw["a"], fz / 1000.0, alpha * _DEG, gamma * _DEG, kw["variant"]
            )
        return MFTyre(**kw).forces(fz, 0.0, alpha, gamma, combined=False, limits=False).fy

    def physical_checks(self) -> dict[str, bool]:
        """Seed-002 physical conditions over the fit's data box (independent of the constraint
        set used): C in (1, 2); E in (−(1 + C²/2), 1]; peak largest at γ = 0.
        """
        fz_lo, fz_hi = self.ranges["fz_N"]
        g_lo, g_hi = self.ranges["gamma_rad"]
        fz = np.array([fz_lo, fz_lo, fz_hi, fz_hi])
        g = np.array([g_lo, g_hi, g_lo, g_hi])
        if self.model == "pac94":
            a = self.coefficients
            c = a["a0"]
            e = np.concatenate(
                [
                    (a["a6"] * fz / 1000 + a["a7"]) * (1 - (a["a16"] * g * _DEG + a["a17"]) * s)
                    for s in (-1.0, 1.0)
                ]
            )
            camber_peak = a["a15"] >= 0
        else:
            p = self.coefficients
            c = p["PCY1"]
            dfz = (fz - self.extra["FNOMIN"]) / self.extra["FNOMIN"]
            e = np.concatenate(
                [
                    (p["PEY1"] + p["PEY2"] * dfz)
                    * (1 + p["PEY5"] * g**2 - (p["PEY3"] + p["PEY4"] * g) * s)
                    for s in (-1.0, 1.0)
                ]
            )
            camber_peak = p["PDY3"] >= 0
        return {
            "C_in_(1,2)": bool(1 < c < 2),
            "E_in_range": bool(np.all(e <= 1) and np.all(e > -(1 + c * c / 2))),
            "peak_largest_at_zero_camber": bool(camber_peak),
        }

    # ------------------------------------------------------------------ output
    def to_dict(self) -> dict:
        """JSON-ready dictionary."""
        return {
            "generator": "gripsense tyre-fit",
            "model": self.model,
            "variant": self.variant,
            "constraints": self.constraints,
            "coefficients": self.coefficients,
            "stderr": self.stderr,
            "determined": self.determined,
            "free": self.free,
            "active": self.active,
            "covariance": self.covariance.tolist(),
            "residual_rms_N": self.residual_rms_N,
            "n": self.n,
            "dof": self.dof,
            "cost": self.cost,
            "success": self.success,
            "message": self.message,
            "nfev": self.nfev,
            "ranges": {k: list(v) for k, v in self.ranges.items()},
            "physical_checks": self.physical_checks(),
            "extra": self.extra,
            "units": (
                "PAC94 native: Fz kN, angles deg, Fy N"
                if self.model == "pac94"
                else "MF 6.1: SI, ISO-W"
            ),
        }

    @classmethod
    def from_dict(cls, doc: dict, *, source: str = "<dict>") -> TyreFit:
        """A fit back from :meth:`to_dict` (e.g. a ``gripsense tyre fit -o fit.json`` file).

        Parameters
        ----------
        doc : dict
            Parsed JSON.
        source : str
            Name used in error messages.

        Returns
        -------
        TyreFit
            The fit (statistics that the file lacks are left empty).
        """
        model = doc.get("model")
        names = {"pac94": PAC94_NAMES, "mf61": MF61_LATERAL}.get(str(model))
        if model not in ("pac94", "mf61") or names is None:
            raise InputError(f"{source}: model = {model!r}; a gripsense fit file has pac94 or mf61")
        coefs = doc.get("coefficients")
        if not isinstance(coefs, dict):
            raise InputError(f"{source}: no 'coefficients' object")
        missing = [n for n in names if n not in coefs]
        if missing:
            raise InputError(f"{source}: coefficient {missing[0]} missing")
        try:
            values = {n: float(coefs[n]) for n in names}
        except (TypeError, ValueError):
            raise InputError(f"{source}: a coefficient is not a number") from None
        bad = [n for n, v in values.items() if not np.isfinite(v)]
        if bad:
            raise InputError(f"{source}: coefficient {bad[0]} is not finite")
        nan = float("nan")
        ranges = {k: tuple(v) for k, v in (doc.get("ranges") or {}).items()}
        return cls(
            model=model,
            coefficients=values,
            stderr={n: _num(doc.get("stderr", {}).get(n)) for n in names},
            determined={n: bool(doc.get("determined", {}).get(n, False)) for n in names},
            covariance=np.array(doc.get("covariance") or [[nan]], dtype=float),
            free=list(doc.get("free", names)),
            constraints=str(doc.get("constraints", "")),
            active=dict(doc.get("active", {})),
            residual_rms_N=_num(doc.get("residual_rms_N")),
            n=int(doc.get("n", 0)),
            dof=int(doc.get("dof", 0)),
            cost=_num(doc.get("cost")),
            success=bool(doc.get("success", True)),
            message=str(doc.get("message", "")),
            nfev=int(doc.get("nfev", 0)),
            ranges=ranges,
            variant=str(doc.get("variant", "published")),
            extra=dict(doc.get("extra", {})),
        )

    def to_json(self, path: str | Path) -> Path:
        """Write :meth:`to_dict` as JSON (NaN written as null).

        Parameters
        ----------
        path : str or Path
            Output file.

        Returns
        -------
        Path
            The file written.
        """
        path = Path(path)
        d = self.to_dict()
        path.write_text(json.dumps(_nan_to_none(d), indent=2))
        return path

    def to_tir(self, path: str | Path, template: str | Path | None = None) -> Path:
        """Write an MF 6.1 ``.tir`` (MF 6.1 fits only).

        Parameters
        ----------
        path : str or Path
            Output file.
        template : str or Path, optional
            An existing ``.tir``: its lateral coefficients are replaced and everything else is
            kept. Without, a minimal file holding the fitted pure-lateral coefficients (others
            0, scaling 1) is written.

        Returns
        -------
        Path
            The file written.
        """
        from gripsense.config.tir_template import fit_to_tir

        return fit_to_tir(self, path, template)


def _num(v) -> float:
    return float("nan") if v is None else float(v)


def _nan_to_none(obj):
    if isinstance(obj, dict):
        return {k: _nan_to_none(v) for k, v in obj.items()}
    if isinstance(obj, list | tuple):
        return [_nan_to_none(v) for v in obj]
    if isinstance(obj, float) and not np.isfinite(obj):
        return None
    if isinstance(obj, np.floating | np.integer | np.bool_):
        return _nan_to_none(obj.item())
    return obj
