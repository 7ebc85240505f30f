"""Measurement and parameter uncertainty of a friction estimate.

:class:`NoiseModel` holds 1σ values; :meth:`NoiseModel.for_vehicle` builds one from a receiver
(:class:`gripsense.config.Receiver`: ``--receiver v100|white-0.3|rtk|FILE.toml`` or the vehicle
file's ``[receiver]``) and the vehicle's declared uncertainties.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from gripsense.config import Receiver, Vehicle, receiver_from
from gripsense.config.vehicle_schema import CG_HEIGHT_RANGE_FACTORS

__all__ = ["NoiseModel", "receiver_noise"]


@dataclass(frozen=True)
class NoiseModel:
    """Measurement and parameter uncertainty used to propagate σ_μ (1 σ values).

    Attributes
    ----------
    heading_deg : float
        Compass heading, total [deg]; 0.75 is the thesis's stated receiver accuracy (Table 13).
        Used by the per-sample methods.
    heading_white_deg : float
        The part of the heading error that is independent from sample to sample [deg]
        (``axle-window``).
    heading_bias_deg : float
        The part that stays over a window — residual mounting offset after calibration plus
        slowly varying (multipath) error [deg]; ``axle-window`` treats it as a nuisance
        parameter with this prior. After a short straight-line calibration it is the
        difference of two values of the slow error: √2 × ~0.4° for a V100-class receiver.
    heading_slow_deg : float
        The slowly varying heading error itself [deg] (``axle-window``: the offset the
        calibration leaves, and the drift after it).
    heading_slow_tau_s : float
        Correlation time of the slowly varying heading error [s] (``axle-window`` models the
        slip offset as a Gauss–Markov process with it).
    slow_error_margin : float
        Factor on the slow error's drift in ``axle-window`` (real heading errors have heavier
        tails than a Gaussian process) [-].
    velocity_mps : float
        Each horizontal velocity component [m/s]; gives the course noise σ_v / v and the speed
        noise. 0.05 m/s is a typical Doppler velocity accuracy.
    yaw_rate_dps : float
        Yaw rate [deg/s].
    tread_stiffness_rel : float
        Relative uncertainty of G (or of C when C is given) [-]. The thesis's own estimates of G
        range from 2.3e7 to 9.6e7 (Table 23); 0.2 is optimistic.
    contact_length_rel : float
        Relative uncertainty of the contact length [-] (Table 18 fit: 0.29 cm on ~14 cm).
    load_transfer_rel : float
        Relative uncertainty of the lateral load transfer (CG height, roll split) [-]
        (``axle-window``).
    axle_stiffness_rel : tuple of (str, float), optional
        Each axle's own relative stiffness uncertainty [-] (``axle-window``'s prior of that
        axle; :meth:`for_vehicle` sets it from the tyres, so that an axle a calibration learned
        keeps its own uncertainty); None: *tread_stiffness_rel* for both.
    steer_scale_rel : float
        Relative 1σ of the steering channel's scale (the steering ratio is never known
        exactly and varies with the angle) [-].
    axle_force_rel : float
        Relative model error of the steady-state axle force m_i⁰ a_y (docs/physics.md §4.4) [-]
        (``axle-window``). The relation neglects the yaw moment of the front wheels' forces at
        large steering angles, (t/2)(F_y,R − F_y,L) sin δ: a few % at 10° of steer (measured on
        the simulator). Systematic: it does not average out over a window.
    heading_calibration_deg : float or None
        Standard error of the heading offset calibrated on straight driving [deg]: the spread
        of heading − course over the straight samples divided by √n (set by the run from its
        calibration; None: not calibrated, the ``axle-window`` slip-offset prior falls back to
        half the white noise).
    """

    heading_deg: float = 0.75
    heading_white_deg: float = 0.3
    heading_bias_deg: float = 0.6
    heading_slow_deg: float = 0.4
    heading_slow_tau_s: float = 20.0
    slow_error_margin: float = 1.5
    velocity_mps: float = 0.05
    yaw_rate_dps: float = 0.3
    tread_stiffness_rel: float = 0.2
    contact_length_rel: float = 0.02
    load_transfer_rel: float = 0.1
    axle_force_rel: float = 0.03
    steer_scale_rel: float = 0.05
    heading_calibration_deg: float | None = None
    axle_stiffness_rel: tuple[tuple[str, float], ...] | None = None

    @classmethod
    def for_vehicle(
        cls,
        vehicle: Vehicle | None,
        receiver: Receiver | str | Path | None = None,
    ) -> NoiseModel:
        """The noise model of a receiver on a vehicle: heading, velocity and yaw-rate noise
        from the receiver; the stiffness uncertainty from the tyres (each axle's own for
        ``axle-window``, the larger of the two for the per-sample methods); the lateral
        load-transfer uncertainty from the declared CG-height range (taken as a 90 % interval).

        Parameters
        ----------
        vehicle : Vehicle or None
            Vehicle description (None: defaults).
        receiver : Receiver or str or Path, optional
            Receiver, its name or file; default the vehicle file's ``[receiver]``, else
            ``v100``.

        Returns
        -------
        NoiseModel
            The noise model.
        """
        if receiver is None:
            receiver = vehicle.receiver if vehicle is not None and vehicle.receiver else "v100"
        rec = receiver_from(receiver)
        white, slow = rec.heading_white_deg, rec.heading_slow_deg
        kw = {
            "heading_deg": float(np.hypot(white, slow)),
            "heading_white_deg": white,
            # after calibration on a straight the residual offset is the difference of two
            # values of the slow error (√2 σ), or the white noise's mean over the lead-in
            "heading_bias_deg": float(max(np.sqrt(2.0) * slow, 0.05 * white / 0.3, 0.01)),
            "heading_slow_deg": slow,
            "velocity_mps": rec.velocity_mps,
            "yaw_rate_dps": rec.yaw_rate_dps,
            "heading_slow_tau_s": rec.heading_slow_tau_s,
        }
        per_axle = None
        if vehicle is not None:
            kw["tread_stiffness_rel"] = max(t.stiffness_uncertainty for t in vehicle.tyres.values())
            per_axle = tuple(
                (axle, t.stiffness_uncertainty) for axle, t in sorted(vehicle.tyres.items())
            )
            h = vehicle.cg_height_m
            f_lo, f_hi = CG_HEIGHT_RANGE_FACTORS
            lo, hi = vehicle.cg_height_range_m or (f_lo * h, f_hi * h)
            kw["load_transfer_rel"] = max((hi - lo) / (2 * 1.645 * h), 0.02)
        return cls(**kw, axle_stiffness_rel=per_axle)

    @classmethod
    def rtk(cls, *, tread_stiffness_rel: float = 0.05) -> NoiseModel:
        """Noise model for an RTK-class compass (0.05° heading); by default with a calibrated
        tyre (G known to 5 %). Deprecated: use ``NoiseModel.for_vehicle(vehicle, "rtk")``,
        built from the one receiver description.

        Parameters
        ----------
        tread_stiffness_rel : float
            Relative 1σ of the tyre stiffness [-].
        """
        warnings.warn(
            "NoiseModel.rtk() is deprecated; use NoiseModel.for_vehicle(vehicle, 'rtk')",
            DeprecationWarning,
            stacklevel=2,
        )
        return cls(
            heading_deg=0.1,
            heading_white_deg=0.05,
            heading_bias_deg=0.1,
            heading_slow_deg=0.05,
            velocity_mps=0.02,
            yaw_rate_dps=0.1,
            tread_stiffness_rel=tread_stiffness_rel,
        )


def receiver_noise(name: str) -> NoiseModel:
    """The noise model of a named receiver class (:data:`gripsense.config.RECEIVERS`) with the
    default tyre and vehicle uncertainties.

    Parameters
    ----------
    name : str
        ``v100``, ``white-0.3`` or ``rtk`` (or a receiver TOML file).

    Returns
    -------
    NoiseModel
        Its noise model.
    """
    return NoiseModel.for_vehicle(None, receiver_from(name))
