"""The profile likelihood of an axle's μ under a family of tyre-curve shapes
(``docs/physics.md`` §15): the nuisances' priors, the profile over a μ grid with every shape,
the interval it gives and why it is limited — shared by the batch and the online window
estimators.

Nuisances enter linearly after linearisation and are profiled by a few Gauss–Newton steps
(:mod:`._axle_kernel`), so the cost does not grow with their number; the shape is profiled over
the family.
"""

from __future__ import annotations

import math
from dataclasses import astuple, dataclass
from functools import cache

import numpy as np
from scipy.special import ndtri
from scipy.stats import chi2

from gripsense.config import Tyre, Vehicle
from gripsense.constants import CHI2_1_90
from gripsense.estimate import _axle_kernel as K
from gripsense.estimate.bins import force_and_linear, merge_steady, on_the_curve
from gripsense.estimate.noise import NoiseModel
from gripsense.estimate.options import WindowOptions
from gripsense.estimate.torque import TorqueProfile
from gripsense.physics.friction_limit import linear_explains
from gripsense.physics.shape_grid import LEARN_GRID, learn_tables
from gripsense.physics.tyre_curves import SHAPE_FAMILY, CurveShape, curve_tables, shape_members

__all__ = [
    "DEVIANCE_CAP",
    "DEVIANCE_STEP",
    "SHAPE_PRIOR_PEAK",
    "SIMILARITY_TEMPER",
    "STRAINED_REL",
    "Priors",
    "ProfileCache",
    "ShapeFamily",
    "axle_priors",
    "curve_lookup",
    "deviance_curve",
    "learned_family",
    "merge_bins",
    "mu_grid",
    "profile_learned",
    "profile_mu",
    "shape_ids",
    "slow_correlation",
    "torque_only",
    "tyre_family",
]

STRAINED_REL = 0.02
"""A model interval whose upper end lies within this fraction above the measured-grip bound is
strained: its range would be (nearly) zero-width, narrower than the force model's own fidelity
(:data:`FORCE_MODEL_REL`), so the upper end is dropped and the fit flagged ``strained``."""

DEVIANCE_STEP = 0.1
"""Resolution of a stored deviance curve (:func:`deviance_curve`): one byte per point of the
profile's μ grid, the deviance rounded down to a multiple of this [-]."""

DEVIANCE_CAP = 255
"""A stored deviance of this many steps means "at least 25.5" (a point the profile excluded)."""


def deviance_curve(
    dev: np.ndarray, i_best: int, *, lower_trusted: bool, upper_trusted: bool
) -> bytes:
    """What a profile says about μ, stored compactly: its deviance on the profile's μ grid
    (:func:`mu_grid`) as one byte per point, with each side that its stated range does not
    trust flattened to zero (``docs/physics.md`` §15.12).

    A range without a value starts at the measured grip, not at the profile's lower crossing,
    and a range without an upper end (a linear tyre explains the data; the model strained) has
    none: the curve says the same — zero below the best μ, resp. above it. Rounded down (and
    capped at :data:`DEVIANCE_CAP` steps), so that the range read back from the curve at any
    level holds the one the profile states.

    Parameters
    ----------
    dev : numpy.ndarray
        Deviance 2 (nll − min nll) per grid point; ``inf`` where the profile stopped [-].
    i_best : int
        Index of the profile's minimum.
    lower_trusted, upper_trusted : bool
        Whether the stated range takes the profile's lower, resp. upper crossing.

    Returns
    -------
    bytes
        One unsigned byte per grid point: the deviance in steps of :data:`DEVIANCE_STEP`.
    """
    q = np.floor(np.minimum(np.where(np.isnan(dev), np.inf, dev), 1e6) / DEVIANCE_STEP)
    q = np.clip(q, 0, DEVIANCE_CAP).astype(np.uint8)
    if not lower_trusted:
        q[:i_best] = 0
    if not upper_trusted:
        q[i_best + 1 :] = 0
    return q.tobytes()


@cache
def curve_lookup() -> tuple[np.ndarray, np.ndarray, float]:
    """The family's force tables, their slopes and 1/Δx of the table grid (computed once)."""
    x, f, df = curve_tables()
    return f, df, 1.0 / (x[1] - x[0])


SHAPE_PRIOR_PEAK = (2.9, 0.35)
"""Prior of a curve's peak position: ln x_peak ~ N(ln 2.9, 0.35²) — the nine example ``.tir``
files of ``tests/data/tyre/tir`` peak at x = 2.2–3.6 (brush P2 at 3, brush P4 at 5)."""


def shape_ids(prior: str) -> np.ndarray:
    """Indices of the shapes of :data:`~gripsense.physics.tyre_curves.SHAPE_FAMILY` a tyre's
    ``shape`` allows (``any``, ``brush``, ``magic-formula`` or a tyre category,
    :func:`~gripsense.physics.tyre_curves.shape_members`; ``docs/physics.md`` §14.3).

    Parameters
    ----------
    prior : str
        The tyre description's shape prior.

    Returns
    -------
    numpy.ndarray
        Shape indices (int64).
    """
    return np.array(shape_members(prior), dtype=np.int64)


@cache
def _shape_penalty() -> np.ndarray:
    """−log prior weight of every shape of the family (:data:`SHAPE_PRIOR_PEAK`)."""
    x, f, _ = curve_tables()
    return _peak_penalty(f, x)


@dataclass(frozen=True)
class ShapeFamily:
    """The curve shapes an axle's μ is profiled over (``docs/physics.md`` §15, §15.10): their
    force tables, each shape's prior weight and the shapes allowed.

    Attributes
    ----------
    shapes : tuple of CurveShape
        Every shape of the tables.
    f, df : numpy.ndarray
        F/(μ Fz) and its slope per shape on the table grid [-].
    inv_dx : float
        1 / the table grid's step [-].
    penalty : numpy.ndarray
        −log prior weight of each shape [-].
    ids : numpy.ndarray
        Indices of the shapes allowed (int64).
    learned : bool
        Whether the weights include a calibration's learned evidence.
    """

    shapes: tuple[CurveShape, ...]
    f: np.ndarray
    df: np.ndarray
    inv_dx: float
    penalty: np.ndarray
    ids: np.ndarray
    learned: bool = False


def _peak_penalty(f: np.ndarray, x: np.ndarray) -> np.ndarray:
    """−log prior weight of each tabulated shape's peak position (:data:`SHAPE_PRIOR_PEAK`)."""
    x_peak = x[np.argmax(f, axis=1)]
    z = (np.log(x_peak) - np.log(SHAPE_PRIOR_PEAK[0])) / SHAPE_PRIOR_PEAK[1]
    return 0.5 * z * z


SIMILARITY_TEMPER = 2.0
"""A calibration's learned shape evidence counts 1/T as much on another road: real tyres keep
their normalised shape across surfaces only approximately (flatter peaks on wet and snow) [-]."""


def tyre_family(tyre: Tyre) -> np.ndarray | ShapeFamily:
    """The shapes an axle's μ is profiled over: the prior family's members a calibration's
    drives left possible (``shape_members``), else the learnable grid weighted by learned
    evidence (``shape_evidence``; ``docs/physics.md`` §15.10), else the prior family's shapes
    its ``shape`` allows.

    Parameters
    ----------
    tyre : Tyre
        The axle's tyre description (``shape``, ``shape_evidence``).

    Returns
    -------
    numpy.ndarray or ShapeFamily
        Indices into the prior family (:func:`shape_ids`), or a learned family.
    """
    if tyre.shape_members is not None:  # a calibration's drives left these possible
        return np.asarray(tyre.shape_members, dtype=np.int64)
    if tyre.shape_evidence is None:
        return shape_ids(tyre.shape)
    return learned_family(np.asarray(tyre.shape_evidence, dtype=float), SIMILARITY_TEMPER)


LEARNED_CAP = 30.0
"""Shapes whose learned weight exceeds this (−log L units) are not profiled at all: far beyond
every interval level, they cannot change a range [-]."""


def learned_family(deviance: np.ndarray, temper: float) -> ShapeFamily:
    """The grid of learnable shapes weighted by a calibration's evidence (``docs/physics.md``
    §15.10): −log weight ½ D_k / T plus the peak position's prior.

    Parameters
    ----------
    deviance : numpy.ndarray
        The learned deviance per shape of :data:`~gripsense.physics.shape_grid.LEARN_GRID`
        (:func:`gripsense.estimate.shape_learning.combine_evidence`) [-].
    temper : float
        How much less the evidence counts on another road, T ≥ 1 [-].

    Returns
    -------
    ShapeFamily
        Tables of the learnable grid; the shapes within :data:`LEARNED_CAP` allowed.
    """
    f, df, inv_dx = learn_tables()
    d = np.asarray(deviance, dtype=float)
    if d.shape != (len(LEARN_GRID),):
        raise ValueError(f"{d.size} learned weights for a grid of {len(LEARN_GRID)} shapes")
    x = np.arange(f.shape[1]) / inv_dx
    pen = 0.5 * d / max(float(temper), 1.0) + _peak_penalty(f, x)
    pen = pen - np.min(pen[np.isfinite(pen)])
    ids = np.flatnonzero(np.isfinite(pen) & (pen <= LEARNED_CAP)).astype(np.int64)
    return ShapeFamily(LEARN_GRID, f, df, inv_dx, np.where(np.isfinite(pen), pen, 1e9), ids,
                       learned=True)  # fmt: skip


@dataclass(frozen=True)
class Priors:
    """Gaussian priors of the nuisances of one axle: means and 1σ of ln s, κ, λ, q, ε, the
    slip offset c, the steering scale ς, μ's load sensitivity η and the drive exponent d; the
    slow slip offset's drift 1σ [rad] and correlation time [s].
    """

    mean: np.ndarray  # ln s, κ, λ, q, ε
    sd: np.ndarray
    delta: float  # slip offset [rad]
    tau_s: float  # its correlation time [s]


def axle_priors(vehicle: Vehicle, axle: str, noise: NoiseModel) -> Priors:
    """The nuisances' priors of one axle from the vehicle file and the noise model.

    Parameters
    ----------
    vehicle : Vehicle
        Vehicle description (tyre, roll gradient, camber gain).
    axle : str
        ``front`` or ``rear``.
    noise : NoiseModel
        Stiffness, load-transfer, force and heading uncertainties.

    Returns
    -------
    Priors
        The priors.
    """
    tyre = vehicle.tyres[axle]
    own = dict(noise.axle_stiffness_rel or ())  # an axle's own (a calibration's), if known
    s_rel = max(own.get(axle, noise.tread_stiffness_rel), 1e-3)
    # camber thrust: body roll (gradient, deg/g) leans the wheels (gain) and the thrust needs
    # a slip of |C_γ/C_α| × inclination to balance: an effective slip shift per g
    kap0 = np.deg2rad(
        tyre.camber_thrust_ratio * vehicle.roll_camber_gain * vehicle.roll_gradient_deg_per_g
    )
    lam_sd = max(noise.load_transfer_rel, 0.02)
    # slip offsets: what the heading calibration left (constant) and the slow error's drift
    # (a Gauss–Markov process, widened by slow_error_margin: real heading errors have heavier
    # tails than a Gaussian, and slip drift at constant force must not pass for saturation)
    floor = np.deg2rad(max(0.5 * noise.heading_white_deg, 0.02))
    # the calibration's own standard error when the offset was calibrated on straights (the
    # white noise averaged over them, and ~0.03° for straights that are not quite straight);
    # a longer straight or a better receiver then narrows the prior instead of a fixed floor
    cal = noise.heading_calibration_deg
    floor_cal = floor if cal is None else np.deg2rad(float(np.hypot(cal, 0.03)))
    sd_cal = max(np.deg2rad(noise.heading_slow_deg), floor_cal)
    # the drift is the declared slow error's (a receiver declared better than its data are is
    # caught by the fit check); a small floor for a receiver declared without one
    floor_drift = np.deg2rad(max(0.1 * noise.heading_white_deg, 0.02))
    sd_drift = max(np.deg2rad(noise.slow_error_margin * noise.heading_slow_deg), floor_drift)
    # a steered axle's body-axis force is F_y cos δ + F_x sin δ: undriven (F_x ≈ 0) F_y = F/cos δ,
    # driven, roughly F cos δ (the drive force balances the turn's drag); the drive force is not
    # measured, so the exponent d of cos^d δ is a nuisance around 0 (±1)
    d0, d_sd = (0.0, 1.0) if axle == "front" else (0.0, 1e-3)
    mean = np.array([0.0, kap0, 0.0, 0.0, 0.0, 0.0, 0.0, tyre.friction_load_sensitivity, d0])
    sd = np.array(
        [
            np.log1p(s_rel),
            max(kap0, np.deg2rad(0.2)),
            lam_sd,
            max(tyre.load_sensitivity_uncertainty, 1e-3),
            max(noise.axle_force_rel, 1e-3),
            sd_cal,
            max(noise.steer_scale_rel, 1e-3),
            max(tyre.friction_load_sensitivity_uncertainty, 1e-3),
            d_sd,
        ]
    )
    return Priors(mean, sd, sd_drift, noise.heading_slow_tau_s)


def merge_bins(
    t0: np.ndarray, t1: np.ndarray, n: np.ndarray, data: np.ndarray, pri: Priors, o: WindowOptions
) -> tuple[np.ndarray, np.ndarray]:
    """The points of the tyre curve that bins give: :func:`~gripsense.estimate.bins.
    merge_steady` (whose parameters and returns these are) with the options' tolerances
    (``steady_tolerance``, ``steady_slip_z``) and the priors' slip drift (its 1σ and correlation
    time), over the bins that are points of the tyre's curve (:func:`~gripsense.estimate.bins.
    on_the_curve`: a spinning axle's are not).
    """
    on = on_the_curve(data)
    return merge_steady(
        t0[on], t1[on], n[on], data[on], o.steady_tolerance, slip_z=o.steady_slip_z,
        drift_sd=pri.delta, tau_s=pri.tau_s,
    )  # fmt: skip


def _crossing(x: np.ndarray, y: np.ndarray, level: float, step: int) -> float:
    """The range's end on the side *step* (−1 below, +1 above) of a profile whose deviance *y*
    is taken from its minimum: the outermost point of the grid within *level*, interpolated in
    log μ to where the deviance crosses it — every μ the data do not exclude, not only the
    stretch around the minimum (a profile that dips again beyond a bump keeps that μ in the
    range, ``docs/physics.md`` §15.3); ``x[0]`` or ``inf`` where the grid's own end is within it.
    """
    inside = np.flatnonzero(y <= level)  # holds the minimum (deviance 0)
    j = int(inside[0]) if step < 0 else int(inside[-1])
    i = j + step  # the first point outside
    if not 0 <= i < x.size:
        return float("inf") if step > 0 else float(x[0])
    f = (level - y[j]) / (y[i] - y[j])
    return float(np.exp(np.log(x[j]) + f * (np.log(x[i]) - np.log(x[j]))))


def slow_correlation(t0: np.ndarray, tau_s: float) -> np.ndarray:
    """Correlation of the slow heading error between consecutive bins (0 after the last).

    Parameters
    ----------
    t0 : numpy.ndarray
        The bins' mid times [s].
    tau_s : float
        The slow error's correlation time [s].

    Returns
    -------
    numpy.ndarray
        exp(−Δt/τ) to the next bin, 0 after the last [-].
    """
    rho = np.zeros(t0.size)
    if t0.size > 1:
        rho[:-1] = np.exp(-np.maximum(np.diff(t0), 1e-3) / tau_s)
    return rho


@cache
def _chi2_ppf(q: float, dof: int) -> float:
    """χ² quantile, computed once per (q, dof): scipy's ppf costs ~0.15 ms a call."""
    return float(chi2.ppf(q, dof))


@cache
def mu_grid(mu_min: float, mu_max: float, n: int) -> np.ndarray:
    """The fine μ grid of the profile (read-only, shared between windows).

    Parameters
    ----------
    mu_min, mu_max : float
        Its ends [-].
    n : int
        Points, geometrically spaced.

    Returns
    -------
    numpy.ndarray
        μ [-].
    """
    g = np.geomspace(mu_min, mu_max, n)
    g.flags.writeable = False
    return g


@cache
def _joint_z(n: int, level: float = 0.9) -> float:
    """The two-sided normal edge that *n* independent errors all stay within with probability
    *level* (Šidák): 1.645 for one, 2.23 for four, 2.8 for twenty [-].
    """
    return float(ndtri(0.5 + 0.5 * level ** (1.0 / max(n, 1))))


def _linear_explains(bins: np.ndarray, pri: Priors) -> bool:
    """Whether a linear tyre explains the bins within their 90 % noise (:func:`~gripsense.
    physics.friction_limit.linear_explains`): per bin the force per load, the declared linear
    prediction, and a tolerance from the force's noise and model fidelity and the slip's white
    noise, offset and drift (the slip's offset and drift are the receiver's declared slow
    heading error, so a receiver declared with one is given more room here than one declared
    without: ``docs/physics.md`` §15.11). The white parts, independent from bin to bin, are
    taken at the edge all the bins stay within together (:func:`_joint_z`): at each bin's own
    90 % edge one bin of many lands outside by chance, and a noisier recording read as a bend
    more often (§15.8). The bin's errors are nearly independent of one another and combine in
    quadrature, as the likelihood's bin variance combines them: the force's (from the speed,
    the yaw rate and the velocity's rate of turn), the slip's (heading and course), and in a
    transient the timing's — force and slip ~0.1 s apart, which moves a linear tyre's force by
    its stiffness times :data:`~gripsense.estimate._axle_kernel.TIMING_SPREAD` of the bin's slip
    spread (a white part: it changes with each bin's slip rate).
    """
    if bins.shape[0] == 0:
        return False
    z = 1.645
    n = bins.shape[0]
    w = _joint_z(n) / z  # the white parts' edge for all n bins at once
    fz = bins[:, 2] + bins[:, 3]
    y, k = force_and_linear(bins)
    y, k = np.abs(y), np.abs(k)
    c_sum = bins[:, 4] + bins[:, 5]
    slip_sd = np.sqrt((w * bins[:, 8]) ** 2 + pri.sd[5] ** 2 + pri.delta**2)
    force_part = np.hypot(w * bins[:, 7], bins[:, 14]) / fz
    slip_part = c_sum / fz * slip_sd
    # column 13: the slip's spread within the bin; the timing error varies from bin to bin
    timing_part = c_sum / fz * w * K.TIMING_SPREAD * bins[:, 13]
    tol = z * np.sqrt(force_part**2 + slip_part**2 + timing_part**2)
    band = (float(np.exp(-z * pri.sd[0])), float(np.exp(z * pri.sd[0])))
    return linear_explains(y, k, band, tol)


def profile_mu(
    bins: np.ndarray,
    t0: np.ndarray,
    pri: Priors,
    shapes: np.ndarray | ShapeFamily,
    p0: float,
    o: WindowOptions,
    grip_lower: float,
    torque: TorqueProfile | None = None,
) -> dict:
    """The profile likelihood of μ over merged bins and what it says (``docs/physics.md`` §15;
    with a steering-torque channel, §16.6).

    Parameters
    ----------
    bins : numpy.ndarray
        Merged bins in :data:`~gripsense.estimate.bins.BIN_COLUMNS` order.
    t0 : numpy.ndarray
        Their mid times [s] (the slow slip offset's correlation).
    pri : Priors
        The nuisances' priors (:func:`axle_priors`).
    shapes : numpy.ndarray or ShapeFamily
        Shapes of the prior family to profile over (:func:`shape_ids`), or a family with its
        own tables and weights (:func:`learned_family`).
    p0 : float
        Local load-sensitivity exponent of the declared stiffness [-].
    o : WindowOptions
        Grid, levels and the rules for a value.
    grip_lower : float
        The model-free measured-grip bound of the same data (NaN: none) [-].
    torque : TorqueProfile, optional
        What the steering torque says (:func:`gripsense.estimate.torque.torque_profile`, on
        the same μ grid): its likelihood multiplies the compass's, and the range stays
        within the compass's own. Where the compass's upper end is not trusted (a linear tyre
        explains its data, or its model is strained) the compass contributes nothing; the
        measured grip stays the lower end.

    Returns
    -------
    dict
        ``mu``, ``mu_low``, ``mu_high``, ``observable``, ``fit``, ``mu_best``,
        ``stiffness_scale``, ``heading_bias_deg``, ``camber_slip_deg_per_g``,
        ``load_transfer_error``, ``shape``, ``limited_by``, ``torque_note`` (with *torque*: what
        it did to the range — :data:`UNCHANGED`, the ends it moved, or why it was not used;
        empty without), ``mu_deviance`` (the statement as a curve on the μ grid,
        :func:`deviance_curve`; None with *torque* or an inconsistent fit).
    """
    if isinstance(shapes, ShapeFamily):
        f, df, inv_dx, members = shapes.f, shapes.df, shapes.inv_dx, shapes.shapes
        ids, weight = shapes.ids, shapes.penalty
    else:
        f, df, inv_dx = curve_lookup()
        members, ids, weight = SHAPE_FAMILY, shapes, _shape_penalty()
    pen = np.ascontiguousarray(weight[ids])
    fine = mu_grid(float(o.mu_min), float(o.mu_max), int(o.n_mu))
    b = np.ascontiguousarray(bins)
    n, m = b.shape[0], fine.size
    if n == 0:  # every bin a spinning axle's (merge_bins): no point of the curve
        return _no_curve_statement(grip_lower, m, NO_CURVE_POINT)
    nll_f, th_f, dl_f = np.empty(m), np.empty((m, K.NG)), np.zeros((m, n))
    shp_f = np.empty(m, dtype=np.int64)
    # every μ of the grid, warm-started upwards (a coarser pass lets the nuisances fall behind:
    # docs/physics.md §15.3); the probe just above the measured grip bounds the minimum
    probe = min(max(1.1 * float(b[:, 9].max()), float(fine[0])), float(fine[-1])) if n else -1.0
    rho = slow_correlation(t0, pri.tau_s)
    lin = None if o.nuisances or torque is not None else _linear_explains(bins, pri)
    if lin and 0 < n <= K.NFEW:
        # a linear tyre explains the data: the statement is the measured grip and a flat curve
        # whatever the profile's shape; only the fit's consistency needs the profile, and an
        # upper bound of its minimum below the level settles it
        i0 = int(np.searchsorted(fine, probe))
        args = (ids, pen, b, rho, pri.mean, pri.sd, pri.delta, f, df, inv_dx, p0, o.iterations)
        if 2.0 * K.probe_step(probe, float(fine[i0]), *args, K.STOP_ABOVE) <= _chi2_ppf(0.999, n):
            return _linear_statement(grip_lower, m)
    K.profile_grid(
        fine, ids, pen, b, rho, pri.mean, pri.sd, pri.delta, f, df, inv_dx,
        p0, o.iterations, nll_f, th_f, dl_f, shp_f, np.inf, probe, K.STOP_ABOVE,
    )  # fmt: skip
    level = _chi2_ppf(float(o.point_level), 1)
    done = np.flatnonzero(np.isfinite(nll_f))
    mu_g, nll, th, dl, shp = fine[done], nll_f[done], th_f[done], dl_f[done], shp_f[done]
    n_mu = done.size
    dev = 2.0 * (nll - nll.min())
    im = int(np.argmin(nll))
    mu_hat = _best_mu(mu_g, nll, im)
    lo = _crossing(mu_g, dev, CHI2_1_90, -1)
    hi = _crossing(mu_g, dev, CHI2_1_90, +1)
    lo_p = _crossing(mu_g, dev, level, -1)
    hi_p = _crossing(mu_g, dev, level, +1)
    n_bins = bins.shape[0]
    z = (th[im] - pri.mean) / pri.sd
    az = np.abs(z)
    z_max = float(az.max())
    fit = "ok"
    if 2.0 * nll[im] > _chi2_ppf(0.999, max(n_bins, 1)) + float(np.sum(z**2)):
        fit = "inconsistent"
    elif im == 0 or z_max > 3.0 or float(np.abs(dl[im]).max()) > 3.5 * pri.delta:
        fit = "edge"  # the data are explained only at the edge of what the priors allow
    observable = bool(fit == "ok" and np.isfinite(hi_p) and hi_p - lo_p <= o.max_width)
    linear = bool(np.isfinite(hi)) and (_linear_explains(bins, pri) if lin is None else lin)
    r = _range_rules(lo, hi, observable, fit, linear, grip_lower, o)
    lo, hi, observable, fit, strained, far_from_limit = r
    limited = _limited_by(az, strained, observable, fit, far_from_limit, hi, o)
    torque_note = ""
    if torque is not None:
        st = _Statement(lo, hi, mu_hat, observable, fit, strained, limited)
        st, torque_note = _with_torque_channel(
            st, torque, mu_g, nll, done, level, grip_lower, o, n_mu
        )
        lo, hi, mu_hat, observable, fit, strained, limited = astuple(st)
    if np.isfinite(grip_lower):
        # the estimate never below what the data prove without a model
        mu_hat = max(mu_hat, float(grip_lower))
    if limited == _far_text(o.min_utilisation) and not (
        np.isfinite(hi) and not (np.isfinite(grip_lower) and hi * o.min_utilisation <= grip_lower)
    ):  # the steering torque moved the upper end: the text says what the row's numbers say
        limited = LINEAR_EXPLAINS if not np.isfinite(hi) else "tyre shape"
    mu_low = float(max(lo, grip_lower))
    # the value is the centre of the stated range on the log-μ grid, not the profile's best μ:
    # the profile is skewed (a nuisance at its prior's edge lets μ rise more easily than fall,
    # the measured grip cuts the range from below), so its best μ sits low in the range — biased
    # low by 1–2 % of μ near the limit, more at high grip (docs/physics.md §15.9)
    value = float(np.sqrt(mu_low * hi)) if observable else np.nan
    curve = None
    if torque is None and fit != "inconsistent":
        curve = _grid_curve(m, done, dev, int(done[im]), observable, bool(np.isfinite(hi)))
    return {
        "mu": value,
        "mu_low": mu_low if fit != "inconsistent" else np.nan,
        "mu_high": float(hi) if fit != "inconsistent" else np.nan,
        "observable": observable,
        "fit": fit,
        "mu_best": mu_hat,
        "stiffness_scale": float(np.exp(th[im, 0])),
        "heading_bias_deg": math.degrees(float(dl[im].sum()) / dl.shape[1]),
        "camber_slip_deg_per_g": float(np.rad2deg(th[im, 1])),
        "load_transfer_error": float(th[im, 2]),
        "shape": members[int(shp[im])].name,
        "limited_by": limited,
        "torque_note": torque_note,
        "mu_deviance": curve,
    }


_NUISANCE_NAMES = (
    "stiffness",
    "camber",
    "load transfer",
    "load sensitivity",
    "axle force",
    "heading offset",
    "steering scale",
    "friction load sensitivity",
    "drive force on the steered axle",
)
"""The nuisances in the profile's order, as ``limited_by`` names one."""


def _best_mu(mu_g: np.ndarray, nll: np.ndarray, im: int) -> float:
    """The profile's best μ: the grid point *im* refined by a parabola in ln μ through it and
    its neighbours (kept between them).
    """
    mu_hat = float(mu_g[im])
    if 0 < im < mu_g.size - 1:
        x0, x1, x2 = (math.log(float(x)) for x in mu_g[im - 1 : im + 2])
        y0, y1, y2 = (float(y) for y in nll[im - 1 : im + 2])
        den = (x0 - x1) * (x0 - x2) * (x1 - x2)
        a = (x2 * (y1 - y0) + x1 * (y0 - y2) + x0 * (y2 - y1)) / den
        bq = (x2**2 * (y0 - y1) + x1**2 * (y2 - y0) + x0**2 * (y1 - y2)) / den
        if a > 0:
            mu_hat = math.exp(min(max(-bq / (2 * a), x0), x2))
    return mu_hat


def _range_rules(
    lo: float,
    hi: float,
    observable: bool,
    fit: str,
    linear: bool,
    grip_lower: float,
    o: WindowOptions,
) -> tuple[float, float, bool, str, bool, bool]:
    """The profile's crossings (*lo*, *hi*) as the rules of ``docs/physics.md`` §15.5, §15.8
    and §15.11 let them stand: no upper end where a linear tyre explains the data (*linear*),
    the measured grip as the lower end without a value or far from the limit, an upper end at
    the measured grip strained, one below it inconsistent. Returns lo, hi, observable, fit,
    strained and whether the range is far from the limit.
    """
    # a value needs data near the limit: below utilisation ~0.5 every curve of the family is
    # nearly linear, so an interval bounded far above the measured grip comes from the model's
    # form (a nuisance degeneracy), not from the data
    far_from_limit = bool(
        np.isfinite(hi) and not (np.isfinite(grip_lower) and hi * o.min_utilisation <= grip_lower)
    )
    # no upper end where the physics allows none: a tyre still linear at every point, with a
    # stiffness inside the prior's 90 % band, explains the data within their noise (the
    # slip's white noise and offsets, the force's noise and the model's fidelity) — a finite
    # upper end there comes from a degeneracy of the other nuisances (docs/physics.md §15.8)
    if linear:
        hi, observable = np.inf, False
        far_from_limit = False
    if far_from_limit:
        # no value: the interval's lower end is not trusted (far from the limit it can come
        # from a degeneracy of the nuisances), so the range starts at what the data prove; its
        # upper end stays — the data exclude a tyre that linear, and dropping it would say
        # less than the physics allows (docs/physics.md §15.5)
        lo, observable = (grip_lower if np.isfinite(grip_lower) else 0.0), False
    # a model interval that lies below what the data prove without a model contradicts itself
    strained = False
    if np.isfinite(grip_lower) and hi < grip_lower - 0.01:
        fit, observable = "inconsistent", False
    elif np.isfinite(grip_lower) and hi <= (1.0 + STRAINED_REL) * grip_lower:
        # the model's upper end reaches what the data prove: no curve of the family carries
        # the measured force with room to spare — the model is strained, its upper end is not
        # trusted (a zero-width or inverted range would be the result)
        strained, observable, hi = True, False, np.inf
        if fit == "ok":
            fit = "strained"
    if not observable:
        # without a value the lower end is what the data prove, not the model's crossing: that
        # is measured from the profile's minimum, which moves with the data's noise where no
        # value is given (a better receiver's lower end could fall below a worse one's on the
        # same drive) — the model's lower end is stated only with a value (docs/physics.md
        # §15.11)
        lo = grip_lower if np.isfinite(grip_lower) else 0.0
    return lo, hi, observable, fit, strained, far_from_limit


def _limited_by(
    az: np.ndarray,
    strained: bool,
    observable: bool,
    fit: str,
    far_from_limit: bool,
    hi: float,
    o: WindowOptions,
) -> str:
    """What limits a profile's statement: the nuisance furthest out in its prior (|z| > 1;
    else the tyre's shape), unless the model is strained, the range is far from the limit or a
    linear tyre explains the data.
    """
    if strained:
        return "tyre model strained (its upper end reaches the measured grip)"
    if not observable and fit == "ok" and far_from_limit:
        return _far_text(o.min_utilisation)
    if not observable and fit == "ok" and not np.isfinite(hi):
        return LINEAR_EXPLAINS
    return _NUISANCE_NAMES[int(np.argmax(az))] if float(az.max()) > 1.0 else "tyre shape"


def _grid_curve(
    m: int, done: np.ndarray, dev: np.ndarray, i_best: int, lower: bool, upper: bool
) -> bytes:
    """The statement as a curve on the whole grid of *m* points (:func:`deviance_curve`):
    points between two the profile reached as they say, points beyond them at the cap.
    """
    full = np.full(m, np.inf)
    inner = np.arange(done[0], done[-1] + 1)
    full[inner] = np.interp(inner, done, dev)
    return deviance_curve(full, i_best, lower_trusted=lower, upper_trusted=upper)


@dataclass
class _Statement:
    """What a profile states: the range, the best μ, whether a value is given, the fit, whether
    the model is strained, and what limits it.
    """

    lo: float
    hi: float
    mu_hat: float
    observable: bool
    fit: str
    strained: bool
    limited: str


def _with_torque_channel(
    st: _Statement,
    torque: TorqueProfile,
    mu_g: np.ndarray,
    nll: np.ndarray,
    done: np.ndarray,
    level: float,
    grip_lower: float,
    o: WindowOptions,
    n_mu: int,
) -> tuple[_Statement, str]:
    """The compass's statement *st* with the steering torque's likelihood (``docs/physics.md``
    §16.6): never wider than the compass's own range; the torque's note says what it did or
    why it was not used.
    """
    torque_note = ""
    lo, hi, mu_hat, observable = st.lo, st.hi, st.mu_hat, st.observable
    fit, strained, limited = st.fit, st.strained, st.limited
    if torque.fit != "ok":
        torque_note = f"not used (its fit is {torque.fit})"
    elif fit == "inconsistent":
        torque_note = "not used (the compass's fit is inconsistent)"
    else:
        # the compass's likelihood where its upper end is trusted, else flat (it says nothing
        # above what the data prove); times the torque's
        trusted = np.isfinite(hi) and not strained
        compass = nll - nll.min() if trusted else np.zeros(n_mu)
        c = _with_torque(mu_g, compass, torque, done, level, grip_lower, o)
        torque_note = "not used (its range contradicts the measured grip)"
        if c is not None and trusted and not (c[0] < hi and lo < c[1]):
            c = None  # the two channels' ranges do not meet: the compass's stands alone
            torque_note = "not used (its range does not meet the compass's)"
        if c is not None:
            before = (max(lo, grip_lower) if np.isfinite(grip_lower) else lo, hi, observable)
            lo_c, hi_c, before_best = lo, hi, mu_hat
            fit_c, strained_c, torque_note = fit, strained, ""
            lo, hi, mu_hat, observable, torque_says = c
            # never wider than the compass's own range (an untrusted upper end is already
            # unbounded): more data never say less
            lo, hi = max(lo, lo_c), min(hi, hi_c)
            if strained and torque_says:
                fit = "ok"  # the torque bounds what the compass's family could not
            strained = strained and not torque_says
            observable = observable and fit == "ok"
            if not observable:
                # the lower end is a model's only with a value (as the compass's own, far from
                # the limit): without one it stays the compass's — the measured grip unless the
                # compass gave a value (docs/friction.md, "the lower end")
                lo = lo_c
            if np.isfinite(grip_lower) and hi <= (1.0 + STRAINED_REL) * max(lo, grip_lower):
                # the combined upper end reaches the lower: not a range (strained); the
                # compass's stands
                lo, hi, mu_hat, observable = lo_c, hi_c, before_best, before[2]
                fit, strained = fit_c, strained_c
                torque_note = "not used (its upper end reaches the measured grip)"
            after = (max(lo, grip_lower) if np.isfinite(grip_lower) else lo, hi, observable)
            if not torque_note.startswith("not used"):
                torque_note = _range_change(before, after)
            if torque_says and torque_note.startswith(("gave", "raised", "lowered")):
                limited = f"steering torque: {torque.limited_by}"
    return _Statement(lo, hi, mu_hat, observable, fit, strained, limited), torque_note


LINEAR_EXPLAINS = (
    "no upper end: a tyre still linear at every point (shape and stiffness within their priors) "
    "explains the data"
)
"""``limited_by`` where no curve of the family is excluded above the measured grip. It says
what the data do not exclude, never that they were far from the limit (a slippery road driven
at 0.9 of its grip can look linear to a noisy compass: docs/friction.md, "what limits")."""


def _far_text(min_utilisation: float) -> str:
    """``limited_by`` of a range without a value because its upper end is above
    1 / *min_utilisation* times the measured-grip bound: the comparison the rule makes, not a
    claim that the data were far from the limit (at their utilisation the range cannot say).
    """
    times = f"over {1.0 / min_utilisation:g} ×" if min_utilisation > 0 else "above"
    return (
        f"no value: the range's upper end is {times} what the data prove (they do not show "
        "how near the limit they were)"
    )


UNCHANGED = "did not change the range"
"""``torque_note`` of a front axle whose stated range the steering torque left as it was."""


def _range_change(before: tuple, after: tuple, tol: float = 0.005) -> str:
    """What the steering torque did to a stated range (low, high, value given): the parts that
    moved by more than *tol* (absolute, in μ), or :data:`UNCHANGED`.
    """
    (l0, h0, o0), (l1, h1, o1) = before, after
    parts = []
    if o1 and not o0:
        parts.append("gave a value")
    if l1 - l0 > tol:
        parts.append(f"raised the lower end {l0:.2f} → {l1:.2f}")
    if np.isfinite(h1) and (not np.isfinite(h0) or h0 - h1 > tol):
        parts.append(f"lowered the upper end {h0:.2f} → {h1:.2f}".replace("inf", "∞"))
    return "; ".join(parts) if parts else UNCHANGED


def _torque_range(
    mu_g: np.ndarray, nll: np.ndarray, level: float, grip_lower: float, o: WindowOptions
) -> tuple[float, float, float, bool, bool] | None:
    """The interval a combined likelihood gives: (low, high, best μ, whether a value is given,
    whether it is bounded above), or None when it contradicts the measured grip (its upper end
    below the bound: the torque is not used). The likelihood ratio is taken against its best
    μ at or above the measured grip: a μ the data disprove without a model is no reference (a
    trail that fits best "past the limit" would otherwise make every μ allowed look unlikely).
    """
    allowed = mu_g >= grip_lower if np.isfinite(grip_lower) else np.ones(mu_g.size, bool)
    if not allowed.any():
        return None
    im = int(np.flatnonzero(allowed)[np.argmin(nll[allowed])])
    dev = 2.0 * (nll - nll[im])
    lo = _crossing(mu_g, dev, CHI2_1_90, -1)
    hi = _crossing(mu_g, dev, CHI2_1_90, +1)
    lo_p = _crossing(mu_g, dev, level, -1)
    hi_p = _crossing(mu_g, dev, level, +1)
    if np.isfinite(grip_lower) and hi < grip_lower - 0.01:
        return None
    if np.isfinite(grip_lower) and hi <= (1.0 + STRAINED_REL) * grip_lower:
        hi = hi_p = np.inf  # strained: no upper end (docs/physics.md §15)
    lo_p = max(lo_p, grip_lower) if np.isfinite(grip_lower) else lo_p
    observable = bool(np.isfinite(hi_p) and hi_p - lo_p <= o.max_width)
    return float(lo), float(hi), float(mu_g[im]), observable, bool(np.isfinite(hi))


def _with_torque(
    mu_g: np.ndarray,
    compass: np.ndarray,
    torque: TorqueProfile,
    done: np.ndarray,
    level: float,
    grip_lower: float,
    o: WindowOptions,
) -> tuple[float, float, float, bool, bool] | None:
    """:func:`_torque_range` of the compass's likelihood times the torque's. With a known tyre
    or a learned lever the range stays within what the family says without them (the overlap;
    the family's alone where they do not meet): knowing more never says less.
    """

    def one(t: TorqueProfile | None):
        if t is None or t.fit != "ok":
            return None
        return _torque_range(mu_g, compass + t.nll[done], level, grip_lower, o)

    c = one(torque)
    if torque.without is None or torque.without.fit != "ok":
        return c
    cf = one(torque.without)
    if c is None or cf is None:
        return cf if c is None else c
    lo, hi = max(c[0], cf[0]), min(c[1], cf[1])
    if not lo < hi:
        return cf
    return lo, hi, float(np.clip(c[2], lo, hi)), c[3] or cf[3], c[4] or cf[4]


def torque_only(torque: TorqueProfile, o: WindowOptions, grip_lower: float) -> dict | None:
    """What the steering torque alone says of the front axle, for a drive whose compass data
    never passed the screen (``docs/physics.md`` §16.6).

    Parameters
    ----------
    torque : TorqueProfile
        The torque's profile on the μ grid of *o*.
    o : WindowOptions
        Grid, levels and the rules for a value.
    grip_lower : float
        The measured-grip bound (NaN: none) [-].

    Returns
    -------
    dict or None
        ``mu``, ``mu_low``, ``mu_high``, ``observable``, ``fit``, ``mu_best``, ``shape``,
        ``limited_by``, ``torque_note`` (the compass's nuisances NaN); None when the torque
        says nothing beyond the measured grip (no upper end, the same lower end).
    """
    grid = mu_grid(float(o.mu_min), float(o.mu_max), int(o.n_mu))
    level = _chi2_ppf(float(o.point_level), 1)
    c = _with_torque(grid, np.zeros(grid.size), torque, np.arange(grid.size), level, grip_lower, o)
    lower = float(grip_lower) if np.isfinite(grip_lower) else 0.0
    if c is None:
        return {
            "mu": np.nan,
            "mu_low": lower,
            "mu_high": np.inf,
            "observable": False,
            "fit": torque.fit if torque.fit != "ok" else "inconsistent",
            "limited_by": "steering torque contradicts the measured grip",
            "torque_note": "not used (its range contradicts the measured grip)",
        }
    lo, hi, best, observable, _ = c
    mu_low = max(lo, lower) if observable else lower  # a model's lower end only with a value
    if not np.isfinite(hi) and not observable and mu_low <= lower + 0.005:
        return None  # the torque says nothing the measured grip does not: compass-only stands
    return {
        "mu": float(np.sqrt(mu_low * hi)) if observable else np.nan,
        "mu_low": mu_low,
        "mu_high": hi,
        "observable": observable,
        "fit": "ok",
        "mu_best": max(best, lower),
        "shape": torque.shape,
        "limited_by": f"steering torque: {torque.limited_by}"
        if np.isfinite(hi)
        else "no cornering the compass resolves",
        "torque_note": _range_change((lower, np.inf, False), (mu_low, hi, observable)),
    }


class ProfileCache:
    """The previous window's answer, for a window whose merged data cannot be told apart from
    it: the same number of points, every slip within its white-noise 1σ, every force within
    its 1σ (a steady run seen through overlapping windows). Batch and online windows use it
    the same way, so they stay equal.
    """

    def __init__(self) -> None:
        self.data: np.ndarray | None = None
        self.est: dict | None = None

    def profile(self, merged, mid, pri, shapes, p0, o, lower) -> dict:
        """:func:`profile_mu` of a window, or the previous window's answer when the data are
        the same within their noise (parameters as :func:`profile_mu`; *shapes* may be the
        axle's :class:`~gripsense.config.vehicle.Tyre`, then :func:`profile_learned`).
        """
        d, prev = self.data, self.est
        if (
            d is not None
            and prev is not None
            and d.shape == merged.shape
            and np.all(np.abs(d[:, :2] - merged[:, :2]) <= merged[:, 8:9])
            and np.all(np.abs(d[:, 6] - merged[:, 6]) <= merged[:, 7])
            and prev["fit"] != "inconsistent"
        ):
            est = dict(prev)
            if np.isfinite(lower):
                est["mu_low"] = max(est["mu_low"], lower)
                if est["observable"]:  # the centre of the range this window states
                    est["mu"] = float(np.sqrt(est["mu_low"] * est["mu_high"]))
            if not est["mu_high"] <= (1.0 + STRAINED_REL) * est["mu_low"]:
                return est
            # this window's bound strains the previous answer: its own profile decides
        if isinstance(shapes, Tyre):
            est = profile_learned(merged, mid, pri, shapes, p0, o, lower)
        else:
            est = profile_mu(merged, mid, pri, shapes, p0, o, lower)
        est.pop("torque_note", None)  # windows are compass-only (docs/physics.md §16.6)
        self.data, self.est = merged.copy(), est
        return dict(est)


def profile_learned(
    bins: np.ndarray,
    t0: np.ndarray,
    pri: Priors,
    tyre: Tyre,
    p0: float,
    o: WindowOptions,
    grip_lower: float,
    torque: TorqueProfile | None = None,
) -> dict:
    """:func:`profile_mu` over the shapes an axle's tyre allows (:func:`tyre_family`); where a
    calibration's drives left only some members of the prior family possible
    (``shape_members``, ``docs/physics.md`` §15.10), the range stays within what the whole
    prior family says (the overlap; the family's alone where they do not meet, with a note in
    ``limited_by``): knowing more of the tyre never says less.

    Parameters
    ----------
    bins, t0, pri, p0, o, grip_lower, torque
        As :func:`profile_mu`.
    tyre : Tyre
        The axle's tyre description.

    Returns
    -------
    dict
        As :func:`profile_mu`.
    """
    est = profile_mu(bins, t0, pri, tyre_family(tyre), p0, o, grip_lower, torque=torque)
    if tyre.shape_members is None:
        return est
    prior = profile_mu(bins, t0, pri, shape_ids(tyre.shape), p0, o, grip_lower, torque=torque)
    lo, hi = max(est["mu_low"], prior["mu_low"]), min(est["mu_high"], prior["mu_high"])
    if not lo < hi:  # the learned shapes do not fit this drive: the prior family's range
        note = "the learned curve shape does not fit this drive (the tyre's prior family used)"
        return {**prior, "limited_by": "; ".join(x for x in (prior["limited_by"], note) if x)}
    # the overlap's curve: where both hold (the larger deviance of the two)
    curve = _both(est["mu_deviance"], prior["mu_deviance"])
    if est["observable"] or not prior["observable"]:
        if (lo, hi) == (est["mu_low"], est["mu_high"]):
            return est
        mu = float(np.clip(est["mu"], lo, hi)) if np.isfinite(est["mu"]) else est["mu"]
        return {**est, "mu_low": lo, "mu_high": hi, "mu": mu, "mu_deviance": curve}
    # the family gave a value and the overlap is no wider than its range: the value stays
    return {**est, "mu_low": lo, "mu_high": hi, "observable": True, "mu_deviance": curve,
            "mu": float(np.clip(prior["mu"], lo, hi))}  # fmt: skip


NO_CURVE_POINT = (
    "no point of the tyre's curve: the axle spun (every bin's slip beyond 30° or sweeping)"
)
"""``limited_by`` of a profile none of whose bins is a point of the tyre's lateral curve."""


def _linear_statement(grip_lower: float, m: int) -> dict:
    """:func:`profile_mu`'s answer for a window a linear tyre explains, with a consistent fit,
    where the nuisances are not wanted (:attr:`WindowOptions.nuisances`): the measured grip as
    the lower end, no upper end, no value, a flat curve of *m* grid points.
    """
    return _no_curve_statement(grip_lower, m, LINEAR_EXPLAINS)


def _no_curve_statement(grip_lower: float, m: int, why: str) -> dict:
    """The measured grip as the lower end, no upper end, no value, a flat curve of *m* grid
    points, and *why* as ``limited_by``.
    """
    nan = float("nan")
    return {
        "mu": nan,
        "mu_low": float(grip_lower) if np.isfinite(grip_lower) else 0.0,
        "mu_high": float("inf"),
        "observable": False,
        "fit": "ok",
        "mu_best": nan,
        "stiffness_scale": nan,
        "heading_bias_deg": nan,
        "camber_slip_deg_per_g": nan,
        "load_transfer_error": nan,
        "shape": "",
        "limited_by": why,
        "torque_note": "",
        "mu_deviance": bytes(m),
    }


def _both(a: bytes | None, b: bytes | None) -> bytes | None:
    """The curve of two statements that both hold (:func:`deviance_curve`s): their pointwise
    larger deviance; one alone where the other has none.
    """
    if a is None or b is None:
        return a if b is None else b
    return np.maximum(np.frombuffer(a, np.uint8), np.frombuffer(b, np.uint8)).tobytes()
