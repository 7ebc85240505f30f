"""Settings of the friction estimators: the gates of the per-sample stages
(:class:`FrictionOptions`) and the bins and windows of ``axle-window`` (:class:`WindowOptions`).
"""

from __future__ import annotations

from dataclasses import dataclass, field

from gripsense.estimate.noise import NoiseModel

__all__ = ["NOT_PROFILED", "FrictionOptions", "WindowOptions"]

NOT_PROFILED = "not profiled"
"""The summary's ``fit`` where the drive was not profiled (:attr:`WindowOptions.drive`)."""


@dataclass(frozen=True)
class FrictionOptions:
    """Gates and settings of the friction estimator.

    Attributes
    ----------
    min_speed_mps : float
        Below: ``low_speed`` (course undefined) [m/s].
    min_lateral_accel_mps2 : float
        Below: ``not_cornering`` [m/s^2].
    min_yaw_rate_dps : float
        Below: ``not_cornering`` [deg/s].
    steady_window_s : float
        Centred window over which speed and yaw rate must be steady [s].
    steady_speed_std_mps, steady_yaw_rate_std_dps : float
        Largest standard deviation in the window [m/s], [deg/s].
    max_rel_sigma : float
        Largest σ_μ/μ reported as a value (docs/physics.md §11: 0.5) [-].
    min_valid_fraction : float
        The summary reports a wheel's μ only when at least this fraction of its steady
        cornering samples is valid [-]. Below it the valid samples are the tail that noise made
        look well-conditioned (a sample whose slip angle noise pushed up reads as a tyre at its
        limit), and their median is biased towards the lower bound.
    calibrate_heading : bool
        Estimate the heading offset from straight driving; falls back to the vehicle file's
        offset when the log has too little straight driving.
    noise : NoiseModel
    """

    min_speed_mps: float = 3.0
    min_lateral_accel_mps2: float = 0.5
    min_yaw_rate_dps: float = 1.0
    steady_window_s: float = 2.0
    steady_speed_std_mps: float = 0.3
    steady_yaw_rate_std_dps: float = 1.5
    max_rel_sigma: float = 0.5
    min_valid_fraction: float = 0.5
    calibrate_heading: bool = True
    noise: NoiseModel = field(default_factory=NoiseModel)


@dataclass(frozen=True)
class WindowOptions:
    """Settings of the ``axle-window`` estimator.

    Attributes
    ----------
    window_s, step_s : float
        Window length and step [s].
    bin_s : float
        Bin length: the unit of data (means of the samples) [s].
    max_width : float
        Largest width of the ``point_level`` interval for which a value is given [-].
    point_level : float
        Confidence level of the interval that decides abstention.
    min_samples : int
        Fewest usable samples in a bin.
    screen_z : float
        The cornering screen (:func:`~gripsense.estimate.screen.resolvable`,
        ``docs/physics.md`` §15.2): a window is analysed when its slip angle (the one its force
        needs at the declared stiffness) and its lateral acceleration are both at least this
        many 1σ of their noise, whatever its grip; other windows give the measured-grip bound
        only [-].
    screen_utilisation : float
        A window whose measured grip reaches this is analysed too, even where the screen does
        not resolve its slip (stiff tyres at a moderate grip: the profile's nuisances carry
        them, as before issue 41); ``inf``: the compass's screen alone [-].
    steady_tolerance : float
        Consecutive bins whose measured grip stays within this are merged into one point of the
        tyre curve (:func:`merge_steady`) [-].
    steady_slip_z : float
        Bins of steady force stay apart when their slip moves by more than this many 1σ of its
        noise (a tyre past its peak holds its force while the slip grows: not steady) [-].
    mu_min, mu_max : float
        μ grid range [-]; an interval reaching mu_max is unbounded.
    n_mu : int
        μ grid size (log-spaced).
    iterations : int
        Gauss–Newton steps per (μ, shape).
    bound_level : float
        One-sided confidence of the measured-grip bound (per window; the summary's bound holds
        at this level over all windows of the drive together).
    min_utilisation : float
        A value is given only when the measured-grip bound is at least this fraction of the
        interval's upper end (data near the limit) [-].
    drive : bool
        Profile the whole drive per axle (the summary's range and value). ``False`` keeps the
        windows and the summary's measured grip only, with ``fit`` :data:`NOT_PROFILED`: what
        ``gripsense fleet`` needs, which combines the windows' statements per road cell.
    nuisances : bool
        Profile every analysed window over the whole μ grid, also one whose upper end a linear
        tyre explains (its statement is then the measured grip alone, its curve flat): the
        profile's minimum gives that window's nuisances (``stiffness_scale``,
        ``heading_bias_deg``, ``camber_slip_deg_per_g``, ``load_transfer_error``, ``shape``,
        ``mu_best``) and tells an ``edge`` fit from an ``ok`` one. ``False`` profiles such a
        window only as far as its fit's consistency needs (an upper bound of the profile's
        minimum, :func:`~gripsense.estimate._axle_kernel.probe_step`): ``mu``, ``mu_low``,
        ``mu_high``, ``observable`` and ``mu_deviance`` are the same, the nuisances NaN and the
        fit ``ok`` (what ``gripsense fleet`` keeps of a window).
    """

    window_s: float = 3.0
    step_s: float = 1.0
    bin_s: float = 1.0
    max_width: float = 0.3
    point_level: float = 0.99
    min_samples: int = 5
    screen_z: float = 3.0
    screen_utilisation: float = 0.15
    steady_tolerance: float = 0.03
    steady_slip_z: float = 4.0
    mu_min: float = 0.05
    mu_max: float = 3.0
    n_mu: int = 48
    iterations: int = 3
    bound_level: float = 0.99
    min_utilisation: float = 0.5
    drive: bool = True
    nuisances: bool = True
