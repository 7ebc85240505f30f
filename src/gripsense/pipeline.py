"""Pipelines: a source, a vehicle description and an estimator wired together (like pvlib's
ModelChain). The command line is a thin layer over these."""

from __future__ import annotations

import json
from dataclasses import dataclass, field, fields, replace
from pathlib import Path

import numpy as np
import pandas as pd

from gripsense.config import Vehicle
from gripsense.errors import InputError
from gripsense.estimate.axle_window import WindowOptions, estimate_windows
from gripsense.estimate.friction import (
    FLAGS,
    METHODS,
    FrictionOptions,
    NoiseModel,
    friction_from_motion,
    motion_from_epochs,
)
from gripsense.physics.surface import surface_class_interval

__all__ = ["FrictionResult", "FrictionRun"]

Z90 = 1.6448536269514722  # two-sided 90 % normal quantile


@dataclass
class FrictionResult:
    """Result of :class:`FrictionRun`.

    Attributes
    ----------
    wheels : pandas.DataFrame
        One row per wheel and epoch (see :data:`gripsense.estimate.friction.WHEEL_COLUMNS`).
    summary : pandas.DataFrame
        One row per wheel: ``mu`` (median over valid steady samples), ``mu_low``/``mu_high``
        (90 % interval), ``n_valid``/``n_total``, ``surface``, ``mu_lower_bound`` (what the
        data prove: the 95th percentile of |F|/Fz over steady cornering samples) and one
        ``n_<flag>`` column per flag.
    meta : dict
        Method, vehicle, heading offset and how it was found, counts.
    """

    wheels: pd.DataFrame
    summary: pd.DataFrame
    meta: dict = field(default_factory=dict)
    windows: pd.DataFrame | None = None
    epochs: pd.DataFrame | None = None
    ingest: dict | None = None
    vehicle: Vehicle | None = None
    noise: NoiseModel | None = None

    def explain(self) -> str:
        """One line: what was found, or why nothing was observable."""
        s = self.summary
        if "axle" in s.columns:
            return _explain_axles(s)
        if len(s) == 0:
            return "nothing to analyse: " + self.meta.get(
                "note", "no epoch had heading, course, speed and yaw rate together"
            )
        if s["observable"].any():
            parts = []
            for rec in s.to_dict("records"):
                if rec["observable"]:
                    parts.append(
                        f"{rec['wheel']}: μ = {rec['mu']:.2f} [{rec['mu_low']:.2f}, "
                        f"{rec['mu_high']:.2f}] ({rec['surface']}, {rec['n_valid']}/"
                        f"{rec['n_total']} samples)"
                    )
                else:
                    parts.append(
                        f"{rec['wheel']}: not observable (μ ≥ {rec['mu_lower_bound']:.2f})"
                    )
            return "; ".join(parts)
        if (s["n_valid"] > 0).any():
            frac = float(s["valid_fraction"].max())
            lb = s["mu_lower_bound"].max()
            return (
                f"μ not observable: at most {frac:.0%} of the steady cornering samples are "
                "well-conditioned — a noise-selected tail, not a measurement; the data prove "
                f"only μ ≥ {lb:.2f}"
            )
        flags = self.wheels["flag"].value_counts()
        top = flags.index[0] if len(flags) else "none"
        lb = s["mu_lower_bound"].max()
        bound = f"; the data prove only μ ≥ {lb:.2f}" if np.isfinite(lb) else ""
        why = {
            "ill_conditioned": "lateral utilisation too low for the slip angle to pin μ down",
            "not_steady": "no steady cornering",
            "not_cornering": "no cornering",
            "low_speed": "too slow",
            "no_solution": "slip angles inconsistent with the forces (heading offset, G?)",
            "full_sliding": "tyres fully sliding",
        }.get(str(top), str(top))
        return (
            f"μ not observable: most wheel-epochs are {top} ({why}: {int(flags.iloc[0])} of "
            f"{int(flags.sum())}){bound}"
        )

    def to_files(self, outdir: str | Path) -> dict[str, Path]:
        """Write ``wheels.parquet`` and ``summary.json`` into *outdir*; return their paths."""
        outdir = Path(outdir)
        outdir.mkdir(parents=True, exist_ok=True)
        wp = outdir / "wheels.parquet"
        self.wheels.to_parquet(wp, index=False)
        sp = outdir / "summary.json"
        paths = {"wheels": wp, "summary": sp}
        if self.windows is not None:
            paths["windows"] = outdir / "windows.parquet"
            self.windows.to_parquet(paths["windows"], index=False)
        if self.epochs is not None:
            paths["epochs"] = outdir / "epochs.parquet"
            self.epochs.to_parquet(paths["epochs"], index=False)
        if self.ingest is not None:
            paths["ingest"] = outdir / "ingest.json"
            paths["ingest"].write_text(json.dumps(self.ingest, indent=2) + "\n")
        src = Path(self.vehicle.source) if self.vehicle is not None else None
        if src is not None and src.is_file():
            paths["vehicle"] = outdir / "vehicle.toml"
            if src.resolve() != paths["vehicle"].resolve():
                paths["vehicle"].write_bytes(src.read_bytes())
        recs = json.loads(self.summary.to_json(orient="records"))
        key = "axles" if "axle" in self.summary.columns else "wheels"
        sp.write_text(
            json.dumps(
                {"meta": self.meta, key: recs, "explain": self.explain()},
                indent=2,
                default=str,
            )
            + "\n"
        )
        return paths


def summarize(wheels: pd.DataFrame, min_valid_fraction: float = 0.5) -> pd.DataFrame:
    """Per-wheel summary of a wheel table (see :class:`FrictionResult`).

    The interval is the median of the valid samples' own 90 % intervals (μ ± 1.645 σ_μ), not a
    standard error of the median: the dominant errors (heading offset, G, pressure shape) are
    shared by all samples and do not average out. A μ is given only when at least
    *min_valid_fraction* of the steady cornering samples are valid (see
    :class:`~gripsense.estimate.friction.FrictionOptions`); ``observable`` says whether it was.
    """
    rows = []
    for wname, g in wheels.groupby("wheel", observed=True, sort=False):
        ok = g["flag"] == "ok"
        mu = g.loc[ok, "mu"]
        sig = g.loc[ok, "mu_sigma"]
        cornering = ~g["flag"].isin(["low_speed", "not_cornering", "not_steady"])
        util = g.loc[cornering, "utilisation"]
        rec = {"wheel": str(wname), "n_total": len(g), "n_valid": int(ok.sum())}
        n_corner = int(cornering.sum())
        rec["valid_fraction"] = float(ok.sum() / n_corner) if n_corner else 0.0
        rec["observable"] = bool(ok.any() and rec["valid_fraction"] >= min_valid_fraction)
        if rec["observable"]:
            m = float(mu.median())
            lo = float((mu - Z90 * sig).median())
            hi = float((mu + Z90 * sig).median())
            rec.update(
                mu=m,
                mu_low=max(lo, 0.0),
                mu_high=hi,
                surface=str(surface_class_interval(max(lo, 0.0), hi)),
            )
        else:
            rec.update(mu=np.nan, mu_low=np.nan, mu_high=np.nan, surface="undetermined")
        rec["mu_lower_bound"] = float(util.quantile(0.95)) if len(util) else np.nan
        counts = g["flag"].value_counts()
        for f in FLAGS:
            rec[f"n_{f}"] = int(counts.get(f, 0))
        rows.append(rec)
    cols = [
        "wheel",
        "mu",
        "mu_low",
        "mu_high",
        "surface",
        "observable",
        "n_valid",
        "n_total",
        "valid_fraction",
        "mu_lower_bound",
        *[f"n_{f}" for f in FLAGS],
    ]
    return pd.DataFrame(rows, columns=cols)


def _explain_axles(s: pd.DataFrame) -> str:
    parts = []
    for rec in s.to_dict("records"):
        if rec.get("n", 0) == 0:
            parts.append(f"{rec['axle']} axle: no steady cornering")
        elif rec.get("fit") == "inconsistent":
            parts.append(
                f"{rec['axle']} axle: the data contradict the model (heading offset, "
                f"vehicle or tyre parameters?) — only μ ≥ {rec['mu_lower_bound']:.2f} "
                "(the utilisation) is certain"
            )
        elif rec["observable"]:
            parts.append(
                f"{rec['axle']} axle: μ = {rec['mu']:.2f} [{rec['mu_low']:.2f}, "
                f"{rec['mu_high']:.2f}] ({rec['surface']})"
            )
        else:
            hi = "" if not np.isfinite(rec["mu_high"]) else f" ≤ {rec['mu_high']:.2f}"
            parts.append(
                f"{rec['axle']} axle: μ not observable — the data prove μ ≥ "
                f"{rec['mu_lower_bound']:.2f}{hi} (utilisation {rec['utilisation']:.2f})"
            )
    return "; ".join(parts)


def _axle_summary(summary: pd.DataFrame) -> pd.DataFrame:
    s = summary.copy()
    if len(s) and "mu_low" in s:
        s["surface"] = [
            str(surface_class_interval(lo, hi)) if obs else "undetermined"
            for lo, hi, obs in zip(s["mu_low"], s["mu_high"], s["observable"], strict=True)
        ]
    return s


class FrictionRun:
    """Friction from a GNSS-compass epoch table: vehicle + method + options → result.

    Parameters
    ----------
    vehicle : Vehicle or path
        Vehicle description (or the path of its TOML file).
    method : str
        ``brush-2`` (default), ``brush-4``, ``thesis-2``, ``thesis-4``, ``brush``, ``thesis``.
    noise : NoiseModel, optional
        Uncertainties for σ_μ.
    **options
        Fields of :class:`~gripsense.estimate.friction.FrictionOptions`
        (e.g. ``min_speed_mps=4.0``, ``calibrate_heading=False``).

    Examples
    --------
    >>> run = FrictionRun("car.toml", method="brush-2")        # doctest: +SKIP
    >>> result = run.run(read_nmea("drive.nmea").epochs)     # doctest: +SKIP
    >>> result.summary                                       # doctest: +SKIP
    """

    def __init__(
        self,
        vehicle: Vehicle | str | Path,
        method: str = "brush-2",
        *,
        noise: NoiseModel | None = None,
        window: WindowOptions | None = None,
        **options,
    ):
        if method not in METHODS:
            raise InputError(f"FrictionRun: method={method!r}; use one of {sorted(METHODS)}")
        self.vehicle = vehicle if isinstance(vehicle, Vehicle) else Vehicle.from_toml(vehicle)
        self.method = method
        known = {f.name for f in fields(FrictionOptions)}
        unknown = set(options) - known
        if unknown:
            raise InputError(
                f"FrictionRun: unknown option(s) {sorted(unknown)}; known: {sorted(known)}"
            )
        opts = replace(FrictionOptions(), **options)
        self.options = replace(opts, noise=noise) if noise is not None else opts
        self.window = window or WindowOptions()

    def run(self, epochs: pd.DataFrame, *, steer_rad: np.ndarray | None = None) -> FrictionResult:
        """Estimate μ from a GNSS-compass epoch table (:func:`gripsense.io.read_nmea`).

        *steer_rad* (road-wheel angle per epoch row) enables the front wheels.
        """
        motion, meta = motion_from_epochs(
            epochs, self.vehicle, options=self.options, steer_rad=steer_rad
        )
        result = self.run_motion(motion, meta=meta)
        result.epochs = epochs
        return result

    def run_motion(self, motion: pd.DataFrame, *, meta: dict | None = None) -> FrictionResult:
        """Estimate μ from a motion table of the measurement point (see
        :func:`gripsense.estimate.friction.friction_from_motion` and
        :func:`gripsense.io.table.read_motion_table`)."""
        wheels, meta2 = friction_from_motion(
            motion, self.vehicle, method=self.method, options=self.options
        )
        meta = {**(meta or {}), **meta2}
        if self.method == "axle-window":
            # μ is per axle and window here; the per-sample brush values would contradict it
            wheels = wheels.assign(mu=np.nan, mu_sigma=np.nan)
            windows, axles = estimate_windows(
                wheels, self.vehicle, noise=self.options.noise, options=self.window
            )
            return FrictionResult(
                wheels=wheels,
                summary=_axle_summary(axles),
                meta=meta,
                windows=windows,
                vehicle=self.vehicle,
                noise=self.options.noise,
            )
        summary = summarize(wheels, self.options.min_valid_fraction)
        return FrictionResult(
            wheels=wheels,
            summary=summary,
            meta=meta,
            vehicle=self.vehicle,
            noise=self.options.noise,
        )
