"""The friction estimators, one object each, in one registry (:data:`ESTIMATORS`).

Every estimator starts from the same wheel kinematics (:func:`gripsense.estimate.wheels.
wheel_kinematics`, computed once) and the model-free measured grip; an estimator object carries
what its consumers need, so that none of them asks which method ran:

* :meth:`Estimator.sample_stage` — its per-sample stage (the brush inversion, or marking the
  samples it estimates per axle: nothing is computed to be thrown away);
* :meth:`Estimator.result` — the typed result from the wheel table;
* ``per_window`` and :meth:`Estimator.online` — whether it answers per window and its online
  form (live mode);
* ``needs_receiver`` — whether its noise model always comes from the receiver;
* ``description`` and ``assumptions`` — how reports describe it.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from typing import ClassVar

import numpy as np
import pandas as pd

from gripsense.config import Vehicle
from gripsense.errors import InputError
from gripsense.estimate.axle_window import estimate_windows
from gripsense.estimate.grip import measured_grip
from gripsense.estimate.noise import NoiseModel
from gripsense.estimate.online import OnlineAxleWindow
from gripsense.estimate.options import FrictionOptions, WindowOptions
from gripsense.estimate.per_sample import PRESSURE_MODELS, brush_stage
from gripsense.estimate.results import (
    AxleFriction,
    FrictionResult,
    WheelFriction,
    summarize_axles,
    summarize_wheels,
)
from gripsense.estimate.wheels import FLAGS

__all__ = ["ESTIMATORS", "AxleWindow", "Estimator", "PerSample", "estimator_of", "get_estimator"]


@dataclass(frozen=True)
class Estimator:
    """What every friction estimator offers (use :class:`PerSample` / :class:`AxleWindow`).

    Attributes
    ----------
    name : str
        The method name (``gripsense friction --method``).
    """

    name: str

    per_window: ClassVar[bool] = False
    """Answers per axle and window (else per wheel and sample)."""
    needs_receiver: ClassVar[bool] = False
    """Its noise model always comes from the receiver and the vehicle file."""
    description: ClassVar[str] = ""
    """What it does, for reports (``{G}``, ``{B}``, ``{method}`` filled in)."""
    assumptions: ClassVar[str] = ""
    """The tyre model it assumes, for reports."""

    def sample_stage(self, frames: list[dict], vehicle: Vehicle, options: FrictionOptions) -> None:
        """Its per-sample stage on :func:`~gripsense.estimate.wheels.wheel_kinematics`' frames
        (in place).

        Parameters
        ----------
        frames : list of dict
            Per wheel the kinematics' arrays.
        vehicle : Vehicle
            Vehicle description.
        options : FrictionOptions
            Gates and the noise model.
        """
        raise NotImplementedError

    def result(
        self,
        wheels: pd.DataFrame,
        vehicle: Vehicle,
        *,
        options: FrictionOptions,
        window: WindowOptions,
        meta: dict,
    ) -> FrictionResult:
        """The typed result from a wheel table made with :meth:`sample_stage`.

        Parameters
        ----------
        wheels : pandas.DataFrame
            Wheel table.
        vehicle : Vehicle
            Vehicle description.
        options : FrictionOptions
            Gates and the noise model.
        window : WindowOptions
            Bins and windows (the measured grip's bins for every estimator).
        meta : dict
            Entries to keep in the result's ``meta``.

        Returns
        -------
        FrictionResult
            :class:`~gripsense.estimate.results.WheelFriction` or
            :class:`~gripsense.estimate.results.AxleFriction`.
        """
        raise NotImplementedError

    def online(
        self, vehicle: Vehicle, axle: str, *, noise: NoiseModel, window: WindowOptions
    ) -> OnlineAxleWindow | None:
        """Its online form for one axle, fed sample by sample (None: recompute the window).

        Parameters
        ----------
        vehicle : Vehicle
            Vehicle description.
        axle : str
            ``front`` or ``rear``.
        noise : NoiseModel
            Measurement and parameter uncertainty.
        window : WindowOptions
            Bins and windows.

        Returns
        -------
        OnlineAxleWindow or None
            The online estimator.
        """
        return None


@dataclass(frozen=True)
class PerSample(Estimator):
    """μ per wheel and sample from the brush model (:mod:`gripsense.estimate.per_sample`).

    Attributes
    ----------
    name : str
        The method name.
    pressure : str or None
        Pressure shape (None: the tyre description's).
    model : str
        ``exact`` or ``thesis``.
    """

    pressure: str | None = None
    model: str = "exact"

    description: ClassVar[str] = (
        "Per wheel and sample: brush tyre model ({method}), each wheel carrying its load's "
        "share of the axle force m_axle·a_y (equal friction utilisation — the thesis's "
        "assumption). A value needs σ_μ/μ ≤ 0.5 and steady cornering; the summary reports a "
        "wheel only when most of its steady samples are valid."
    )
    assumptions: ClassVar[str] = (
        "steady cornering, quasi-static load transfer, brush (Fiala) tyre with the stated "
        "pressure shape"
    )

    def sample_stage(self, frames: list[dict], vehicle: Vehicle, options: FrictionOptions) -> None:
        """The brush inversion of every wheel (parameters as :meth:`Estimator.sample_stage`)."""
        for frame in frames:
            brush_stage(frame, vehicle, self.pressure, self.model, options)

    def result(self, wheels, vehicle, *, options, window, meta) -> FrictionResult:
        """Parameters as :meth:`Estimator.result`."""
        grip = measured_grip(wheels, vehicle, noise=options.noise, options=window)
        return WheelFriction(
            wheels=wheels,
            summary=summarize_wheels(wheels, options.min_valid_fraction, grip),
            meta=meta,
            vehicle=vehicle,
            noise=options.noise,
        )


_PER_AXLE = FLAGS.index("per_axle")


@dataclass(frozen=True)
class AxleWindow(Estimator):
    """μ per axle over windows and the drive (:mod:`gripsense.estimate.axle_window`).

    Attributes
    ----------
    name : str
        The method name.
    """

    per_window: ClassVar[bool] = True
    needs_receiver: ClassVar[bool] = True
    description: ClassVar[str] = (
        "One μ per axle over 3 s windows and the whole drive (profile likelihood). The axle "
        "carries m_axle·a_y; both wheels' brush forces from their own slip angles must add up "
        "to it. The tyre stiffness (±{G:.0%}) and a heading bias (±{B:.2f}°) are unknowns with "
        "priors. A value is given only when the 99 % interval is bounded and narrower than "
        "0.3; otherwise the lower bound the data prove."
    )
    assumptions: ClassVar[str] = (
        "a family of tyre-curve shapes (brush and Magic Formula) with uncertain stiffness, "
        "load sensitivity, camber and load transfer; transients through the yaw-acceleration "
        "term and the relaxation length"
    )

    def sample_stage(self, frames: list[dict], vehicle: Vehicle, options: FrictionOptions) -> None:
        """Marks the steady-cornering samples ``per_axle``: μ is estimated per axle and window,
        and a sample without μ is never flagged ``ok`` (parameters as
        :meth:`Estimator.sample_stage`).
        """
        for frame in frames:
            frame["flag"] = np.where(frame["flag"] == 0, np.int8(_PER_AXLE), frame["flag"])

    def result(self, wheels, vehicle, *, options, window, meta) -> FrictionResult:
        """Parameters as :meth:`Estimator.result`."""
        noise = options.noise
        n_straight, spread = meta.get("straight_samples", 0), meta.get("heading_offset_spread_deg")
        if spread is not None and n_straight > 0 and noise.heading_calibration_deg is None:
            # the heading offset's standard error from this drive's own straights
            noise = dataclasses.replace(
                noise, heading_calibration_deg=float(spread) / float(np.sqrt(n_straight))
            )
        windows, axles = estimate_windows(wheels, vehicle, noise=noise, options=window)
        return AxleFriction(
            wheels=wheels,
            summary=summarize_axles(axles),
            meta=meta,
            windows=windows,
            vehicle=vehicle,
            noise=options.noise,
        )

    def online(self, vehicle, axle, *, noise, window) -> OnlineAxleWindow:
        """Parameters as :meth:`Estimator.online`."""
        return OnlineAxleWindow(vehicle, axle, noise=noise, options=window)


ESTIMATORS: dict[str, Estimator] = {
    e.name: e
    for e in (
        *(PerSample(name, pressure, model) for name, (pressure, model) in PRESSURE_MODELS.items()),
        AxleWindow("axle-window"),
    )
}
"""Method name → estimator (``gripsense friction --method``)."""


def get_estimator(method: str, who: str = "") -> Estimator:
    """The estimator of a method name, or an error naming the known ones.

    Parameters
    ----------
    method : str
        A key of :data:`ESTIMATORS`.
    who : str
        What asks (prefixes the error).

    Returns
    -------
    Estimator
        The estimator.
    """
    try:
        return ESTIMATORS[method]
    except (KeyError, TypeError):
        pre = f"{who}: " if who else ""
        raise InputError(f"{pre}method={method!r}; use one of {sorted(ESTIMATORS)}") from None


def estimator_of(result: FrictionResult) -> Estimator:
    """The estimator that made a result (by its ``meta`` method; a result read from a folder
    without one: the first estimator of its kind).

    Parameters
    ----------
    result : FrictionResult
        A friction result.

    Returns
    -------
    Estimator
        Its estimator.
    """
    est = ESTIMATORS.get(result.method)
    if est is not None:
        return est
    per_window = isinstance(result, AxleFriction)
    return next(e for e in ESTIMATORS.values() if e.per_window == per_window)
