"""Typed, immutable results of the friction estimators: one class per kind of answer.

* :class:`WheelFriction` — the per-sample methods (``brush-2``, ``thesis-2`` …): μ per wheel
  and sample, summarised per wheel;
* :class:`AxleFriction` — ``axle-window``: μ per axle and window with profile-likelihood
  intervals, summarised per axle.

Both share :class:`FrictionResult`'s interface — ``unit`` (``"wheel"`` or ``"axle"``),
``summary``, :meth:`~FrictionResult.explain`, :meth:`~FrictionResult.estimates` (one row per
estimate, the same columns for every method: what live mode and the fleet consume),
:meth:`~FrictionResult.to_files` and :meth:`FrictionResult.from_files` — so no consumer needs to
know which method ran.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any, ClassVar

import numpy as np
import pandas as pd

from gripsense.config import Vehicle
from gripsense.constants import Z90
from gripsense.errors import InputError
from gripsense.estimate.conditions import condition_table, conditions
from gripsense.estimate.noise import NoiseModel
from gripsense.estimate.wheels import FLAGS, NOT_STEADY_CORNERING
from gripsense.io.output_folder import read_result_folder, write_result_folder
from gripsense.physics.surface import slippery_call, surface_class_interval

__all__ = [
    "COLUMN_KINDS",
    "ESTIMATE_COLUMNS",
    "UNIT_COLUMNS",
    "AxleFriction",
    "FrictionResult",
    "WheelFriction",
    "calibration_record",
    "read_result",
    "slippery_from_range",
    "stiffness_lines",
    "summarize_axles",
    "summarize_wheels",
]

ESTIMATE_COLUMNS = [
    "unit",
    "t_start",
    "t_end",
    "epoch",
    "observable",
    "mu",
    "mu_sigma",
    "mu_low",
    "mu_high",
    "grip_used",
    "grip_used_lower",
    "mu_deviance",
]
"""Columns of :meth:`FrictionResult.estimates` (same for every method). Two kinds of number
(``docs/physics.md`` §14): ``grip_used`` / ``grip_used_lower`` are *measured* (the friction the
axle used, and its model-free one-sided lower bound: "the data prove μ ≥ …", level road
assumed); ``mu``, ``mu_sigma``, ``mu_low``, ``mu_high`` are *estimated* under a tyre model, and
``mu_deviance`` is the estimate's statement as a curve on the μ grid (``axle-window``:
:func:`~gripsense.estimate.profile.deviance_curve`; None where there is none, and for
per-sample methods)."""

UNIT_COLUMNS = [
    "unit",
    "mu",
    "mu_low",
    "mu_high",
    "surface",
    "slippery",
    "observable",
    "grip_used",
    "grip_used_lower",
    "n_valid",
]
"""Columns of :meth:`FrictionResult.unit_table` (same for every method)."""

RESULT_KIND = "friction"

COLUMN_KINDS: dict[str, str] = {
    "mu": "estimated",
    "mu_low": "estimated",
    "mu_high": "estimated",
    "mu_best": "estimated",
    "surface": "estimated",
    "slippery": "measured and estimated",
    "observable": "estimated",
    "grip_used": "measured",
    "grip_used_lower": "measured",
    "utilisation_p95": "measured, load-transfer model",
    "valid_fraction": "count",
    "fit": "estimated",
    "shape": "estimated",
    "stiffness_scale": "estimated",
    "cornering_stiffness_N_per_rad": "estimated",
    "heading_bias_deg": "estimated",
    "camber_slip_deg_per_g": "estimated",
    "load_transfer_error": "estimated",
    "limited_by": "why",
    "steering_torque": "input",
    "note": "why",
}
"""The kind of each summary column (``n…`` columns are counts): *measured* (model-free, level
road assumed: ``docs/physics.md`` §14), *estimated* (under a tyre model), counts and reasons.
``summary.json`` lists them under ``kinds``; the report's headers name them."""


@dataclass(frozen=True, kw_only=True)
class FrictionResult:
    """What every friction result offers (use :class:`WheelFriction` / :class:`AxleFriction`).

    Attributes
    ----------
    wheels : pandas.DataFrame
        One row per wheel and epoch (:data:`gripsense.estimate.wheels.WHEEL_COLUMNS`).
    summary : pandas.DataFrame
        One row per wheel (:class:`WheelFriction`) or axle (:class:`AxleFriction`).
    meta : dict
        Method, vehicle, heading offset and how it was found, counts.
    epochs : pandas.DataFrame or None
        The epoch table the result was computed from (when it came from NMEA).
    ingest : dict or None
        The ingest line accounting (:meth:`gripsense.io.IngestReport.to_dict`).
    vehicle : Vehicle or None
        The vehicle description used.
    noise : NoiseModel or None
        The noise model used.
    """

    unit: ClassVar[str] = ""
    windows: ClassVar[pd.DataFrame | None] = None  # per-window estimates (AxleFriction only)

    wheels: pd.DataFrame
    summary: pd.DataFrame
    meta: dict = field(default_factory=dict)
    epochs: pd.DataFrame | None = None
    ingest: dict | None = None
    vehicle: Vehicle | None = None
    noise: NoiseModel | None = None

    # ------------------------------------------------------------------ shared interface
    @property
    def method(self) -> str:
        """The method that made the result."""
        return str(self.meta.get("method", ""))

    @property
    def observable(self) -> bool:
        """Whether any wheel or axle has a value (not only a bound)."""
        s = self.summary
        return bool(len(s) and s["observable"].fillna(False).astype(bool).any())

    def explain(self) -> str:
        """One line: what was found, or why nothing was observable."""
        raise NotImplementedError

    def estimates(self) -> pd.DataFrame:
        """One row per estimate (a window or a sample), columns :data:`ESTIMATE_COLUMNS`.

        ``observable`` rows carry the estimate ``mu``, its 1σ ``mu_sigma`` and 90 % interval
        ``mu_low``/``mu_high`` (model-based); every row carries the measured ``grip_used`` and
        its model-free lower bound ``grip_used_lower`` (per sample: one-sided 95 %; per window:
        the window's bound); ``epoch`` is the row of the epoch table nearest the estimate's
        middle.
        """
        raise NotImplementedError

    def conditions(self, min_duration_s: float = 3.0) -> list[tuple[float, float]]:
        """Steady cornering conditions of the drive (:func:`~gripsense.estimate.conditions.
        conditions`).

        Parameters
        ----------
        min_duration_s : float
            Shortest condition [s].

        Returns
        -------
        list of (float, float)
            Start and end of each condition [s].
        """
        return conditions(self.wheels, min_duration_s=min_duration_s)

    def condition_table(self, conds: list[tuple[float, float]] | None = None) -> pd.DataFrame:
        """Per condition and wheel: speed, radius, yaw rate, a_y and μ
        (:func:`~gripsense.estimate.conditions.condition_table`).

        Parameters
        ----------
        conds : list of (float, float), optional
            Conditions [s]; default :meth:`conditions`.

        Returns
        -------
        pandas.DataFrame
            One row per condition and wheel.
        """
        conds = self.conditions() if conds is None else conds
        return condition_table(self.wheels, conds, self.windows)

    def unit_table(self) -> pd.DataFrame:
        """The summary in the same columns for every method (:data:`UNIT_COLUMNS`)."""
        s = self.summary.rename(columns={self.unit: "unit"})
        if "slippery" not in s and {"mu_low", "mu_high"} <= set(s.columns):
            s = s.assign(slippery=slippery_from_range(s))
        return s.reindex(columns=UNIT_COLUMNS)

    def replace(self, **changes) -> FrictionResult:
        """A copy with some attributes changed (the result itself is immutable).

        Parameters
        ----------
        **changes
            Attribute → new value.

        Returns
        -------
        FrictionResult
            The same kind of result.
        """
        return replace(self, **changes)

    def record(self) -> dict[str, Any]:
        """What the run used, as every rendering of the result states it: ``source`` (the log
        or table), ``receiver``, ``noise`` (the priors: :class:`~gripsense.estimate.noise.
        NoiseModel`'s fields), ``stiffness`` per axle — ``declared`` in the vehicle file and
        ``used`` as the estimator's prior (after a calibration), each ``[C, relative 1σ]``
        [N/rad, -] — and ``calibration`` (the file, what it learned, its notes) when the run
        recorded one in ``meta``. A result read back from its folder returns the recorded one.

        Returns
        -------
        dict
            JSON-ready.
        """
        if isinstance(self.meta.get("record"), dict):
            return self.meta["record"]
        ingest = self.ingest or {}
        rec: dict[str, Any] = {
            "source": Path(str(ingest.get("source") or self.meta.get("source") or "")).name,
            "receiver": str(self.meta.get("receiver", "")),
            "noise": dataclasses.asdict(self.noise) if self.noise is not None else None,
        }
        veh = self.vehicle
        if veh is not None:
            declared = None
            if veh.source and Path(veh.source).is_file():
                try:
                    declared = Vehicle.from_toml(veh.source)
                except (InputError, OSError):  # changed since the run: not stated
                    declared = None
            nm = self.noise
            own = dict(nm.axle_stiffness_rel or ()) if nm is not None else {}
            rec["stiffness"] = {
                axle: {
                    "declared": _stiffness(declared, axle),
                    "used": _stiffness(
                        veh, axle, own.get(axle, nm.tread_stiffness_rel) if nm else None
                    ),
                }
                for axle in veh.tyres
            }
        if isinstance(self.meta.get("calibration"), dict):
            rec["calibration"] = self.meta["calibration"]
        elif veh is not None and declared is not None and declared.calibration_file:
            # the vehicle file names a calibration: stated when applying it gives the stiffness
            # the run used (FrictionRun(calibration=…) may have given another)
            from gripsense.config.calibration import calibrated_vehicle

            try:
                applied = calibrated_vehicle(declared)
                same = all(
                    np.isclose(_stiffness(applied, a)[0], _stiffness(veh, a)[0], rtol=1e-9)  # type: ignore[index]
                    for a in veh.tyres
                )
                if same:
                    rec["calibration"] = calibration_record(declared.calibration_file, veh)
            except (InputError, OSError):  # changed since the run: not stated
                pass
        return rec

    # ------------------------------------------------------------------ files
    def _tables(self) -> dict[str, pd.DataFrame]:
        out = {"wheels": self.wheels}
        if self.epochs is not None:
            out["epochs"] = self.epochs
        return out

    def to_files(
        self,
        outdir: str | Path,
        *,
        overwrite: bool = False,
        command: str = "",
        inputs: Sequence[str | Path] | None = None,
        texts: dict[str, str] | None = None,
    ) -> dict[str, Path]:
        """Write the result folder: ``wheels.parquet``, ``summary.json`` (and
        ``windows.parquet``, ``epochs.parquet``, ``ingest.json``, ``vehicle.toml`` when known)
        plus ``manifest.json``, atomically (:func:`gripsense.io.output_folder.write_result_folder`).

        Parameters
        ----------
        outdir : str or Path
            Output folder.
        overwrite : bool
            Replace an earlier friction result in *outdir*.
        command : str
            Command line recorded in the manifest.
        inputs : list, optional
            Input files recorded (with their SHA-256) in the manifest.
        texts : dict, optional
            More files of the folder: name → text (e.g. ``report.html``).

        Returns
        -------
        dict
            Name → path of each file written.
        """
        recs = _records(self.summary)
        meta = {k: v for k, v in self.meta.items() if k not in ("record", "calibration")}
        summary: dict[str, object] = {
            "meta": meta,
            f"{self.unit}s": recs,
            "explain": self.explain(),
            "kinds": {
                str(c): COLUMN_KINDS.get(str(c), "count" if str(c).startswith("n") else "")
                for c in self.summary.columns
                if str(c) != self.unit
            },
            # what the run used (priors, stiffness, calibration): a report written later from
            # the folder states the same as one written with the run
            "record": self.record(),
        }
        docs: dict[str, object] = {"summary": summary}
        if self.ingest is not None:
            docs["ingest"] = self.ingest
        copies = {}
        src = Path(self.vehicle.source) if self.vehicle is not None else None
        if src is not None and src.is_file():
            copies["vehicle.toml"] = src
        return write_result_folder(
            outdir,
            RESULT_KIND,
            tables=self._tables(),
            documents=docs,
            copies=copies,
            texts=texts,
            inputs=inputs,
            command=command,
            extra={"result": self.unit},
            overwrite=overwrite,
        )

    @classmethod
    def from_files(cls, folder: str | Path) -> FrictionResult:
        """Read a result folder written by :meth:`to_files` (``gripsense friction -o``).

        Parameters
        ----------
        folder : str or Path
            Result folder.

        Returns
        -------
        WheelFriction or AxleFriction
            The kind recorded in the folder.
        """
        return read_result(folder)


def calibration_record(
    path: str | Path, vehicle: Vehicle, notes: list[str] | None = None
) -> dict[str, Any]:
    """What a calibration file in use taught, for a result's ``meta["calibration"]`` (and so
    its :meth:`FrictionResult.record`): the file's name, the learned stiffness per axle of
    *vehicle* (``[C, relative 1σ]`` [N/rad, -]), how many drives it came from and the lines
    said when it was applied.

    Parameters
    ----------
    path : str or Path
        The calibration file [-].
    vehicle : Vehicle
        The vehicle it calibrates [-].
    notes : list of str, optional
        The lines applying it said (``FrictionRun.calibration_notes``) [-].

    Returns
    -------
    dict
        JSON-ready.
    """
    from gripsense.config.calibration import read_calibration

    cal = read_calibration(path)
    return {
        "file": Path(path).name,
        "learned": {
            axle: [float(a.cornering_stiffness_N_per_rad), float(a.stiffness_uncertainty)]
            for axle, a in cal.axles.items()
            if axle in vehicle.tyres
        },
        "drives": len({d.sha256 for d in cal.drives}),
        "notes": list(notes or []),
    }


def _stiffness(
    vehicle: Vehicle | None, axle: str, width: float | None = None
) -> list[float] | None:
    """One wheel's cornering stiffness at its static load and its relative 1σ [N/rad, -]
    (*width*: the one the estimator's prior has, else the tyre's).
    """
    if vehicle is None or axle not in vehicle.tyres:
        return None
    c = float(vehicle.cornering_stiffness(axle, vehicle.static_load(axle)))
    u = width if width is not None else vehicle.tyres[axle].stiffness_uncertainty
    return [c, float(u)]


def _c(x: list | None) -> str:
    """``[C, u]`` as "44 287 N/rad ± 20 %" (— when not known)."""
    if not (isinstance(x, list | tuple) and len(x) == 2):
        return "—"
    c, u = x
    return f"{c:,.0f} N/rad ± {100 * u:.0f} %".replace(",", " ")


def stiffness_lines(record: dict) -> list[str]:
    """The tyre stiffness a run used, one line per axle, every number named with its kind:
    *declared* (the vehicle file), *learned* (the calibration file, from the car's own drives)
    and *used* (the estimator's prior: both combined, ``docs/calibration.md``); and which
    calibration file changed it, or that none did.

    Parameters
    ----------
    record : dict
        :meth:`FrictionResult.record`.

    Returns
    -------
    list of str
        Plain text lines (empty when the run recorded no vehicle).
    """
    stiff = record.get("stiffness") or {}
    cal = record.get("calibration") if isinstance(record.get("calibration"), dict) else None
    learned = (cal or {}).get("learned") or {}
    lines = []
    if cal:
        n = cal.get("drives")
        lines.append(
            f"calibration in use: {cal.get('file', '?')}"
            + (f" (learned from {n} drive{'s' if n != 1 else ''})" if n else "")
        )
    for axle, st in stiff.items():
        st = st if isinstance(st, dict) else {}
        parts = [f"declared (vehicle file) {_c(st.get('declared'))}"]
        if axle in learned:
            parts.append(f"learned (calibration) {_c(learned[axle])}")
        parts.append(f"used (the estimator's prior) {_c(st.get('used'))}")
        if cal and len(stiff) > 1:
            parts[-1] += " (its width: the larger of the axles')"
        lines.append(f"{axle} tyre cornering stiffness at the static load: " + "; ".join(parts))
    if (
        stiff
        and not cal
        and any(
            not (isinstance(v, dict) and isinstance(v.get("declared"), list))
            for v in stiff.values()
        )
    ):
        lines.append("no calibration recorded; the vehicle was not read from a file")
    elif stiff and not cal:
        same = all(
            isinstance(v, dict)
            and isinstance(v.get("declared"), list)
            and isinstance(v.get("used"), list)
            and np.isclose(v["declared"][0], v["used"][0], rtol=1e-9)
            for v in stiff.values()
        )
        lines.append(
            "no calibration file: the vehicle file's stiffness is used as declared"
            if same
            else "the stiffness used differs from the vehicle file's (a calibration the run "
            "did not record)"
        )
    return lines


_INPUTS = {  # epoch-table column -> what it is, the --columns key that maps it, NMEA sentences
    "heading_deg": ("true heading", "heading", "HDT, PASHR"),
    "course_deg": ("course over ground", "course", "RMC, VTG"),
    "speed_mps": ("speed over ground", "speed", "RMC, VTG"),
    "yaw_rate_rps": ("yaw rate", "yaw_rate", "a heading channel gives it"),
}


def missing_inputs(epochs: pd.DataFrame | None, meta: dict) -> str:
    """Why no epoch was usable, when a whole input channel is missing: which, and the
    ``--columns`` that would map it (``""`` when epochs were used or every channel has
    values).

    Parameters
    ----------
    epochs : pandas.DataFrame or None
        The epoch table of the run.
    meta : dict
        The run's meta (``epochs_used``).

    Returns
    -------
    str
    """
    if epochs is None or len(epochs) == 0 or meta.get("epochs_used", 1) != 0:
        return ""
    gone = [
        c for c in _INPUTS
        if c not in epochs.columns or not np.isfinite(epochs[c].to_numpy(float)).any()
    ]  # fmt: skip
    if not gone:
        return ""
    what = ", ".join(f"{_INPUTS[c][0]} ({c})" for c in gone)
    maps = ",".join(f"{_INPUTS[c][1]}=CHANNEL" for c in gone)
    nmea = "; ".join(f"{_INPUTS[c][0]}: {_INPUTS[c][2]}" for c in gone)
    return (
        f"no epoch usable: the log gives no {what}; map the channel that carries it with "
        f"--columns {maps} (VBOX, MDF4, CAN logs; docs/ingest.md), or log the NMEA sentences "
        f"that do ({nmea})"
    )


def _proven(rec: dict) -> str:
    """The model-free statement of a summary row (empty when there is none)."""
    lo = rec.get("grip_used_lower", np.nan)
    if lo is None or not np.isfinite(lo) or lo <= 0:
        return ""
    return f"; the data prove μ ≥ {lo:.2f} (measured grip, model-free, level road assumed)"


def _best(s: pd.DataFrame) -> dict:
    """The summary row with the highest measured-grip bound."""
    if "grip_used_lower" not in s or s["grip_used_lower"].isna().all():
        return {}
    return s.loc[s["grip_used_lower"].idxmax()].to_dict()


def _records(df: pd.DataFrame) -> list[dict]:
    import json

    return json.loads(df.to_json(orient="records"))


@dataclass(frozen=True, kw_only=True)
class WheelFriction(FrictionResult):
    """μ per wheel and sample (the per-sample methods); ``summary`` has one row per wheel:
    ``mu`` (median over valid steady samples), ``mu_low``/``mu_high`` (90 % interval),
    ``n_valid``/``n_total``, ``surface``, the measured grip of the wheel's axle (``grip_used``,
    largest bin mean, and ``grip_used_lower``, its model-free bound; see
    :func:`gripsense.estimate.grip.measured_grip`), ``utilisation_p95`` (95th percentile of
    the wheel's own |F|/Fz, which depends on the load-transfer model) and one ``n_<flag>``
    column per flag.
    """

    unit: ClassVar[str] = "wheel"

    def explain(self) -> str:
        """One line: what was found, or why nothing was observable."""
        s = self.summary
        if len(s) == 0:
            gone = missing_inputs(self.epochs, self.meta)
            return "nothing to analyse: " + (gone or self.meta.get(
                "note", "no epoch had heading, course, speed and yaw rate together"
            ))  # fmt: skip
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
                    why = f"; {rec['note']}" if rec.get("note") else ""
                    parts.append(f"{rec['wheel']}: not observable{_proven(rec)}{why}")
            return "; ".join(parts)
        if (s["n_valid"] > 0).any():
            frac = float(s["valid_fraction"].max())
            return (
                f"μ not observable: at most {frac:.0%} of the steady cornering samples are "
                "well-conditioned — a noise-selected tail, not a measurement"
                f"{_proven(_best(s))}"
            )
        flags = self.wheels["flag"].value_counts()
        top = flags.index[0] if len(flags) else "none"
        bound = _proven(_best(s))
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

    def estimates(self) -> pd.DataFrame:
        """One row per estimate (:meth:`FrictionResult.estimates`)."""
        wh = self.wheels
        sc = ~wh["flag"].isin(NOT_STEADY_CORNERING).to_numpy()
        w = wh[sc]
        ok = (w["flag"] == "ok").to_numpy()
        t = w["t_s"].to_numpy(float)
        # the bound's grip: the split with the yaw moment it leaves out (docs/physics.md §14.1;
        # a table of an earlier version has none: the model's)
        grip = w["grip_proven" if "grip_proven" in w else "grip_used"].to_numpy(float)
        return pd.DataFrame(
            {
                "unit": w["wheel"].astype(str).to_numpy(),
                "t_start": t,
                "t_end": t,
                "epoch": w["epoch"].to_numpy(int),
                "observable": ok,
                "mu": np.where(ok, w["mu"].to_numpy(float), np.nan),
                "mu_sigma": np.where(ok, w["mu_sigma"].to_numpy(float), np.nan),
                "mu_low": np.where(ok, w["mu"] - Z90 * w["mu_sigma"], np.nan),
                "mu_high": np.where(ok, w["mu"] + Z90 * w["mu_sigma"], np.nan),
                "grip_used": grip,
                "grip_used_lower": np.maximum(grip - Z90 * w["grip_sigma"].to_numpy(float), 0.0),
                "mu_deviance": None,
            },
            columns=ESTIMATE_COLUMNS,
        )


@dataclass(frozen=True, kw_only=True)
class AxleFriction(FrictionResult):
    """μ per axle over windows (``axle-window``); ``summary`` has one row per axle and
    ``windows`` one row per axle and window (see
    :func:`gripsense.estimate.axle_window.estimate_windows`).

    Attributes
    ----------
    windows : pandas.DataFrame
        Windowed estimates.
    """

    unit: ClassVar[str] = "axle"

    # an instance field where the base class has a class-level None (WheelFriction has none)
    windows: pd.DataFrame = field(default_factory=pd.DataFrame)  # type: ignore[misc]

    def _tables(self) -> dict[str, pd.DataFrame]:
        return {**super()._tables(), "windows": self.windows}

    def explain(self) -> str:
        """One line: what was found, or why nothing was observable."""
        parts = []
        for rec in self.summary.to_dict("records"):
            ax = f"{rec['axle']} axle"
            if rec.get("n", 0) == 0:
                parts.append(f"{ax}: no cornering to analyse")
                continue
            proven = _proven(rec)
            call = rec.get("slippery") or "unknown"
            # the answer to "is it slippery?" is said also when it is "unknown"
            said = f" — {call}" if call in ("slippery", "not slippery") else " — slippery: unknown"
            if rec.get("fit") == "inconsistent":
                parts.append(
                    f"{ax}: no estimate — the data contradict the tyre model (heading offset, "
                    f"vehicle or tyre parameters?){proven}{said}"
                )
            elif rec["observable"]:
                parts.append(
                    f"{ax}: μ ≈ {rec['mu']:.2f} [{rec['mu_low']:.2f}, {rec['mu_high']:.2f}] "
                    f"(estimate, 90 %, tyre-shape uncertainty included; {rec['surface']})"
                    f"{proven}{said}"
                )
            else:
                hi = rec.get("mu_high", np.nan)
                est = (
                    f"; estimate μ ≤ {hi:.2f} (90 %)"
                    if np.isfinite(hi) and hi > rec.get("grip_used_lower", 0)
                    else ""
                )
                why = rec.get("limited_by") or "not enough near-limit data"
                parts.append(f"{ax}: no value ({why}){proven}{est}{said}")
            read = rec.get("steering_torque")
            if isinstance(read, str) and read:
                parts[-1] += f" [steering torque read: {read}]"
        gone = missing_inputs(self.epochs, self.meta)
        if gone:  # an empty table says why: the channel missing and how to map it
            parts.insert(0, gone)
        if self.meta.get("front_axle"):  # the front axle never disappears without a word
            parts.append(str(self.meta["front_axle"]))
        if self.meta.get("epochs_collapsed"):  # a logger's copies, counted once
            parts.append(str(self.meta["epochs_collapsed"]))
        return "; ".join(parts)

    def estimates(self) -> pd.DataFrame:
        """One row per estimate (:meth:`FrictionResult.estimates`)."""
        w = self.windows
        if w is None or w.empty:
            return pd.DataFrame(columns=ESTIMATE_COLUMNS)
        mid = 0.5 * (w["t_start"].to_numpy(float) + w["t_end"].to_numpy(float))
        ep = self.wheels.drop_duplicates("epoch").sort_values("t_s")
        te, ee = ep["t_s"].to_numpy(float), ep["epoch"].to_numpy(int)
        idx = np.clip(np.searchsorted(te, mid), 0, max(len(te) - 1, 0))
        obs = w["observable"].to_numpy(bool)
        with np.errstate(invalid="ignore"):
            sig = (w["mu_high"].to_numpy(float) - w["mu_low"].to_numpy(float)) / (2 * Z90)
        return pd.DataFrame(
            {
                "unit": w["axle"].astype(str).to_numpy(),
                "t_start": w["t_start"].to_numpy(float),
                "t_end": w["t_end"].to_numpy(float),
                "epoch": ee[idx] if len(ee) else np.zeros(len(w), int),
                "observable": obs,
                "mu": np.where(obs, w["mu"].to_numpy(float), np.nan),
                "mu_sigma": np.where(obs, sig, np.nan),
                "mu_low": w["mu_low"].to_numpy(float),
                "mu_high": w["mu_high"].to_numpy(float),
                "grip_used": w["grip_used"].to_numpy(float),
                "grip_used_lower": w["grip_used_lower"].to_numpy(float),
                # a result folder of an earlier version has no curves
                "mu_deviance": w["mu_deviance"].to_numpy(object) if "mu_deviance" in w else None,
            },
            columns=ESTIMATE_COLUMNS,
        )

    def unit_table(self) -> pd.DataFrame:
        """The summary in :data:`UNIT_COLUMNS` (``n_valid``: samples used)."""
        s = self.summary
        return super().unit_table().assign(n_valid=s["n"].to_numpy() if "n" in s else np.nan)


RESULT_TYPES: dict[str, type[FrictionResult]] = {
    WheelFriction.unit: WheelFriction,
    AxleFriction.unit: AxleFriction,
}
"""Result class per ``unit`` (recorded in a result folder's manifest)."""


def summarize_wheels(
    wheels: pd.DataFrame,
    min_valid_fraction: float = 0.5,
    measured: pd.DataFrame | None = None,
) -> pd.DataFrame:
    """Per-wheel summary of a wheel table (see :class:`WheelFriction`).

    The interval is the median of the valid samples' own 90 % intervals (μ ± 1.645 σ_μ), not a
    standard error of the median: the dominant errors (heading offset, G, pressure shape) are
    shared by all samples and do not average out. A μ is given only when at least
    *min_valid_fraction* of the steady cornering samples are valid (see
    :class:`~gripsense.estimate.options.FrictionOptions`); ``observable`` says whether it was.

    Parameters
    ----------
    wheels : pandas.DataFrame
        Wheel table of :func:`gripsense.estimate.friction.friction_from_motion`.
    min_valid_fraction : float
        Fewest valid samples, as a fraction of the steady cornering ones, for a value [-].
    measured : pandas.DataFrame, optional
        Measured grip per axle (:func:`gripsense.estimate.grip.measured_grip`).

    Returns
    -------
    pandas.DataFrame
        One row per wheel.
    """
    rows = []
    for wname, g in wheels.groupby("wheel", observed=True, sort=False):
        ok = g["flag"] == "ok"
        mu = g.loc[ok, "mu"]
        sig = g.loc[ok, "mu_sigma"]
        cornering = ~g["flag"].isin(NOT_STEADY_CORNERING)
        util = g.loc[cornering, "utilisation"]
        rec: dict[str, Any] = {"wheel": str(wname), "n_total": len(g), "n_valid": int(ok.sum())}
        n_corner = int(cornering.sum())
        rec["valid_fraction"] = float(ok.sum() / n_corner) if n_corner else 0.0
        rec["observable"] = bool(ok.any() and rec["valid_fraction"] >= min_valid_fraction)
        rec["utilisation_p95"] = float(util.quantile(0.95)) if len(util) else np.nan
        axle = str(wname).split("_")[0]
        grip = (
            measured.set_index("axle").reindex([axle]).iloc[0]
            if measured is not None and len(measured)
            else {}
        )
        rec["grip_used"] = float(grip.get("grip_used", np.nan))
        rec["grip_used_lower"] = float(grip.get("grip_used_lower", np.nan))
        rec["note"] = ""
        lower = rec["grip_used_lower"]
        if rec["observable"] and np.isfinite(lower) and float(mu.median()) < lower:
            # a value below what the same data prove contradicts itself: not a measurement
            rec["observable"] = False
            rec["note"] = "value below the bound the data prove: model inconsistent"
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
        "grip_used",
        "grip_used_lower",
        "utilisation_p95",
        "note",
        *[f"n_{f}" for f in FLAGS],
    ]
    return pd.DataFrame(rows, columns=cols)


def slippery_from_range(table: pd.DataFrame) -> np.ndarray:
    """The answer to "is it slippery?" per row of a table with ``mu_low``, ``mu_high`` and
    (optionally) ``grip_used_lower``: :func:`~gripsense.physics.surface.slippery_call` of the
    range, whose
    lower end is at least the measured grip (the data alone can prove "not slippery", also where
    the model gave no range).

    Parameters
    ----------
    table : pandas.DataFrame
        Summary rows.

    Returns
    -------
    numpy.ndarray of str
        ``slippery``, ``not slippery`` or ``unknown`` per row.
    """
    lo = table["mu_low"].to_numpy(float)
    if "grip_used_lower" in table:
        lo = np.fmax(lo, table["grip_used_lower"].to_numpy(float))
    return np.asarray(slippery_call(lo, table["mu_high"].to_numpy(float)), dtype=str)


def summarize_axles(summary: pd.DataFrame) -> pd.DataFrame:
    """The per-axle summary of :func:`gripsense.estimate.axle_window.estimate_windows` with
    the Table-4 surface class of each observable axle's interval.

    Parameters
    ----------
    summary : pandas.DataFrame
        Per-axle summary.

    Returns
    -------
    pandas.DataFrame
        The same with ``surface`` and ``slippery`` columns.
    """
    s = summary.copy()
    if len(s) and "mu_low" in s:
        s["surface"] = [
            str(surface_class_interval(lo, hi)) if obs else "undetermined"
            for lo, hi, obs in zip(s["mu_low"], s["mu_high"], s["observable"], strict=True)
        ]
        s["slippery"] = slippery_from_range(s)
    return s


def read_result(folder: str | Path) -> FrictionResult:
    """A friction result back from its folder (``gripsense friction -o``).

    Parameters
    ----------
    folder : str or Path
        Result folder.

    Returns
    -------
    WheelFriction or AxleFriction
        The kind recorded in the folder; only the files its manifest lists are read.
    """
    rf = read_result_folder(folder, RESULT_KIND)
    kind = rf.manifest.get("result")
    if kind not in RESULT_TYPES:
        raise InputError(f"{folder}: unknown friction result kind {kind!r}")
    doc = rf.documents.get("summary", {})
    vehicle = None
    if "vehicle.toml" in rf.files:
        vehicle = Vehicle.from_toml(rf.files["vehicle.toml"])
    kw = {}
    if kind == AxleFriction.unit:
        kw["windows"] = rf.tables.get("windows", pd.DataFrame())
    meta = dict(doc.get("meta", {}))
    record = doc.get("record")
    noise = None
    if isinstance(record, dict):  # a folder of an earlier version has none
        meta["record"] = record
        noise = _noise(record.get("noise"), folder)
    return RESULT_TYPES[kind](
        wheels=rf.tables["wheels"],
        summary=_summary_frame(doc.get(f"{kind}s", [])),
        meta=meta,
        epochs=rf.tables.get("epochs"),
        ingest=rf.documents.get("ingest"),
        vehicle=vehicle,
        noise=noise,
        **kw,
    )


def _noise(doc: object, folder: str | Path) -> NoiseModel | None:
    """The noise model a result folder records (None: a folder of an earlier version)."""
    if doc is None:
        return None
    known = {f.name for f in dataclasses.fields(NoiseModel)}
    per_axle = None
    if isinstance(doc, dict) and "axle_stiffness_rel" in doc:  # [[axle, 1σ], …]
        doc = dict(doc)
        pairs = doc.pop("axle_stiffness_rel")
        ok = pairs is None or (
            isinstance(pairs, list)
            and all(
                isinstance(p, list) and len(p) == 2 and isinstance(p[0], str)
                and isinstance(p[1], int | float) and not isinstance(p[1], bool)
                for p in pairs
            )
        )  # fmt: skip
        if not ok:
            raise InputError(
                f"{folder}/summary.json: record.noise axle_stiffness_rel = {pairs!r}, not what "
                "gripsense wrote ([[axle, number], …]); restore it or run gripsense friction again"
            )
        per_axle = tuple((str(a), float(v)) for a, v in pairs) if pairs is not None else None
    bad = (
        "is not a table"
        if not isinstance(doc, dict)
        else next(
            (
                f"has {k!r} = {v!r}"
                for k, v in doc.items()
                if k not in known
                or not (v is None or (isinstance(v, int | float) and not isinstance(v, bool)))
            ),
            "",
        )
    )
    if bad:
        raise InputError(
            f"{folder}/summary.json: record.noise {bad}, not what gripsense wrote (a number "
            "per known key); restore it or run gripsense friction again"
        )
    return NoiseModel(**doc, axle_stiffness_rel=per_axle)  # type: ignore[arg-type]


def _summary_frame(records: list[dict]) -> pd.DataFrame:
    s = pd.DataFrame(records)
    for col in ("mu", "mu_low", "mu_high", "grip_used", "grip_used_lower"):
        if col in s:
            s[col] = pd.to_numeric(s[col], errors="coerce").astype(float)
    return s
