"""Measurement and parameter uncertainty of a friction estimate, and the named receivers.

:class:`NoiseModel` holds 1σ values; :data:`RECEIVERS` maps the names users give
(``--receiver v100|rtk``) to noise models.
"""

from __future__ import annotations

from dataclasses import dataclass

from gripsense.errors import InputError

__all__ = ["RECEIVERS", "NoiseModel", "receiver_noise"]


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
    axle_force_rel : float
        Relative model error of the steady-state axle force m_i⁰ a_y (docs/physics.md §4.4) [-]
        (``axle-window``). The relation neglects the yaw moment of the front wheels' forces at
        large steering angles, (t/2)(F_y,R − F_y,L) sin δ: a few % at 10° of steer (measured on
        the simulator). Systematic: it does not average out over a window.
    """

    heading_deg: float = 0.75
    heading_white_deg: float = 0.3
    heading_bias_deg: float = 0.6
    velocity_mps: float = 0.05
    yaw_rate_dps: float = 0.3
    tread_stiffness_rel: float = 0.2
    contact_length_rel: float = 0.02
    load_transfer_rel: float = 0.1
    axle_force_rel: float = 0.03

    @classmethod
    def rtk(cls, *, tread_stiffness_rel: float = 0.05) -> NoiseModel:
        """Noise model for an RTK-class compass (0.05° heading); by default with a calibrated
        tyre (G known to 5 %).

        Parameters
        ----------
        tread_stiffness_rel : float
            Relative 1σ of the tyre stiffness [-].
        """
        return cls(
            heading_deg=0.1,
            heading_white_deg=0.05,
            heading_bias_deg=0.1,
            velocity_mps=0.02,
            yaw_rate_dps=0.1,
            tread_stiffness_rel=tread_stiffness_rel,
        )


RECEIVERS = {
    "v100": NoiseModel,  # Hemisphere V100-class dual-antenna compass: the defaults
    "rtk": NoiseModel.rtk,  # RTK-class compass with a calibrated tyre
}


def receiver_noise(name: str) -> NoiseModel:
    """The noise model of a named receiver class.

    Parameters
    ----------
    name : str
        A key of :data:`RECEIVERS` (``v100``, ``rtk``).

    Returns
    -------
    NoiseModel
        Its noise model.
    """
    try:
        return RECEIVERS[name]()
    except KeyError:
        raise InputError(f"receiver {name!r}; use one of {', '.join(RECEIVERS)}") from None
