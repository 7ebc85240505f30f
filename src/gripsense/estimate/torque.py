"""Friction from the steering torque: what the front tyres' trail says about μ before the force
saturates (``docs/physics.md`` §16.5–16.6).

Per bin of the front axle (the same clock as :func:`gripsense.estimate.bins.axle_bins`) the
steering moment the tyres ask, M, is measured from the torque channel and compared with

    M = a F + b F W τ(|F| / (μ F_z)) + o + f s,

F the axle force (model-free, from the motion), F_z the axle load, W = Σ_i (F_z,i/F_z)
(F_z,i/F_z,static)^0.75 the load weighting of the zero-slip trail (it grows with the wheel's
load), τ a trail shape of :data:`~gripsense.physics.trail_shapes.TRAIL_FAMILY`, s the steering
friction's state from the steer history (a Dahl model, −1…1). The nuisances a = k t_c (caster
trail), b = k t₀ (zero-slip pneumatic trail), both times the channel's unknown scale k, the
offset o (the sensor's and the tyres' residual moment) and the friction f enter linearly with
Gaussian priors from the vehicle file's ``[steering]`` table, so for every μ and shape the
least-squares profile is exact; μ's profile is the smallest over the family. A vehicle file that
names the front tyre's Magic Formula file (``[steering] tyre_file``) replaces the family by that
tyre's own trail at 0.5–1.5 times the static load (§16.7).
"""

from __future__ import annotations

import dataclasses
import functools
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd
from scipy.ndimage import uniform_filter1d
from scipy.stats import chi2

from gripsense.config import Vehicle
from gripsense.config.tyre_files import load_mf_tyre
from gripsense.config.vehicle import SteeringSystem
from gripsense.constants import G0
from gripsense.errors import InputError
from gripsense.estimate.bins import axle_pairs, bin_starts
from gripsense.physics.steering_balance import backlash, dahl_friction, friction_state
from gripsense.physics.trail_shapes import (
    TRAIL_FAMILY,
    TrailShape,
    fit_trail_shape,
    trail_ratio,
    trail_shape_ids,
    tyre_trail_ratio,
)

__all__ = [
    "TorqueBins",
    "TorqueProfile",
    "TrailFamily",
    "check_channel",
    "merge_torque_bins",
    "past_peak",
    "torque_bins",
    "torque_profile",
    "torque_read",
    "trail_family",
]

TRAIL_LOAD_EXPONENT = 0.75
"""t₀ ∝ F_z^0.75 per wheel (brush: the contact length, ~0.5; Magic Formula D_t ∝ F_z, ~1)."""
TRAIL_FORM_REL = 0.05
"""1σ of the trail the family's shapes miss, relative to t₀ (the shipped ``.tir`` files lie
within 0.05 of the family at 0.5–1.5 times their nominal load)."""
MOMENT_MODEL_REL = 0.03
"""1σ of the steering moment the balance misses (per-wheel utilisation, inertia, damping)."""
RESIDUAL_MOMENT_PER_N = 0.0015
"""1σ of the tyres' residual moment (conicity, ply steer) per newton of axle load [m]."""
UTILISATION_SPREAD_REL = 0.06
"""1σ of a wheel's utilisation about the axle's, relative (load transfer with μ's load
sensitivity η ≈ 0.2 puts the loaded wheel ~5–8 % nearer its limit in a 0.8 g turn)."""
PEAK_FORM_FROM = 0.8
PEAK_FORM_REL = 0.15
"""1σ of the trail near and past the force's peak, relative to t₀: rising from 0 at the axle's
utilisation PEAK_FORM_FROM to PEAK_FORM_REL at 1 (the shipped files' trails at their peak span
−0.1…0.45 of t₀ and keep falling past it)."""
KNOWN_TRAIL_LOADS = (0.5, 0.75, 1.0, 1.25, 1.5)
"""Loads, as multiples of the static front wheel load, at which a known tyre's trail is taken
(load transfer moves the wheels over about this range in a 0.8 g turn) [-]."""
KNOWN_TRAIL_CAMBER_RAD = (-0.07, -0.035, 0.035, 0.07)
"""Inclinations at which a known tyre's trail is also taken, ±2° and ±4° (a car's static camber
and its roll in a turn — the simulated sedan's front wheels lean 2–3° at about 0.8 g; the
file's shapes are at the rig's 0) [rad]."""
KNOWN_TRAIL_STRETCH = (0.9, 1.1)
"""How much earlier or later in the utilisation a known tyre's trail may fall on the car than
on the rig: its shapes are also taken at u × s. Similarity (the slip scaled with μ,
``docs/physics.md`` §15.1) leaves τ(u) as it is; a car's stiffness declared ±10 % off the file's
(inflation, wear, the rim), or a road that scales the force's slip and the trail's differently
(the Magic Formula's own μ scaling leaves the trail's slip scale B_t where it is), moves the
trail's fall against the force's by about as much [-]."""
KNOWN_TRAIL_FORM_FLOOR = 0.03
"""Least 1σ of a known tyre's trail the fitted shapes miss, relative to t₀: the file's own fit
error is 0.01–0.03 (§16.7); the floor carries what a file does not know (wear, inflation, the
road's texture beyond the similarity of the slip with μ) [-]."""
FRICTION_STATE_SD = 0.3
"""1σ of the friction state where the steer drives it one way (:data:`FRICTION_DRIVE_S`): a
hand's dither below the angle channel's noise [-]."""
FRICTION_DRIVE_S = 1.0
"""The steer drives the friction one way where, behind the deadband, it moved on in that
direction by at least the Dahl travel within this trailing window; elsewhere it holds, and a
held steer's friction state is known no better than a reversal's (1σ 1, about the Dahl model's
state): a back-motion of a third of the travel — below the angle channel's noise — reverses half
a built-up friction, so the last correction nobody saw may have moved it anywhere in −1…1. On
the simulator's drives (a controller settling into a circle, a sweep's slow creep) the held
friction ended at −0.25…+0.65 where the Dahl model along the measured steer said +0.4…−1
(docs/physics.md §16.6) [s]."""
STATE_SMOOTHING_S = 1.0
"""The steer is averaged over this window before the deadband and the Dahl model give the
friction's state: the angle channel's noise falls by the square root of the samples, so the
deadband can be narrow and a reversal is placed within half the window [s]."""
STATE_DEADBAND_SD = 4.0
"""Half the deadband the smoothed steer passes before the Dahl model, in its noise's 1σ: the
Dahl model's friction drifts towards 0 under any noise of a held steer (a step back reverses
it, a step on does not build it further), which learned the steering's lever several per cent
high on everyday drives; behind the deadband a hold keeps its friction [-]."""
FRICTION_TRAVEL_RAD = 0.002
"""Road-wheel steer travel over which the steering friction builds up (the Dahl travel of
§16.3): the Dahl model's, and the least band of a confirmed reversal
(:func:`~gripsense.physics.steering_balance.friction_state`) [rad]."""
SIDE_SLIP_OFFSET_RAD = float(np.deg2rad(1.0))
"""Largest common error of the measured slip that :func:`past_peak` allows for when it compares
points on the two sides of the force: a common error adds to one side's |slip| and takes from
the other's (a V100-class receiver's slow heading error, 0.4° 1σ, at 2.5σ, or the heading
calibration's residual and a steering angle's zero offset) [rad]."""
DAMPING_REL = 0.5
"""1σ of the declared kingpin damping, relative: the damping moment C_s δ̇ of a bin is taken
out of the measured moment and this share of it stays as an error [-]."""


@dataclass
class TorqueBins:
    """Bins of the front axle with the measured steering moment.

    Attributes
    ----------
    t0, t1 : numpy.ndarray
        Bin start and end [s].
    n : numpy.ndarray
        Samples per bin.
    force : numpy.ndarray
        Axle force, ISO [N].
    force_sigma : numpy.ndarray
        Its 1σ: white noise, and the spread within a transient bin [N].
    fz_l, fz_r : numpy.ndarray
        Wheel loads [N].
    moment : numpy.ndarray
        Measured steering moment at the steering axes, ISO [N m].
    moment_sigma : numpy.ndarray
        Its 1σ: white noise, and the spread within a transient bin [N m].
    friction_state : numpy.ndarray
        Mean state of the steering friction over the bin (−1…1): the Dahl model along the steer
        at the epochs' rate, smoothed over :data:`STATE_SMOOTHING_S` [-].
    friction_sd : numpy.ndarray
        1σ of that state, the mean over the bin's samples: :data:`FRICTION_STATE_SD` where the
        steer drives the friction one way (:data:`FRICTION_DRIVE_S`), 1 where it holds or a
        reversal the steer confirms is under way
        (:func:`~gripsense.physics.steering_balance.friction_state`) [-].
    grip : numpy.ndarray
        Measured grip of the bin [-].
    fz_static : float
        Static wheel load [N].
    source : str
        What the moment was made of.
    scale_sd, offset_sd : float
        Priors of the channel: relative 1σ of its scale [-], 1σ of its offset at the axes [N m].
    samples : int
        Samples of the channel's own rate behind the bins (the epochs' when it was
        interpolated) [-].
    rate_hz : float
        The channel's rate as read: its samples over the bins' time [Hz].
    slip, slip_sigma : numpy.ndarray or None
        The axle's measured slip angle (mean of its wheels) and its 1σ per sample [rad].
    force_noise : numpy.ndarray or None
        The white-noise part of *force_sigma* (without the transient's spread) [N].
    """

    t0: np.ndarray
    t1: np.ndarray
    n: np.ndarray
    force: np.ndarray
    force_sigma: np.ndarray
    fz_l: np.ndarray
    fz_r: np.ndarray
    moment: np.ndarray
    moment_sigma: np.ndarray
    friction_state: np.ndarray
    friction_sd: np.ndarray
    grip: np.ndarray
    fz_static: float
    source: str
    scale_sd: float
    offset_sd: float
    samples: int = 0
    rate_hz: float = float("nan")
    slip: np.ndarray | None = None
    slip_sigma: np.ndarray | None = None
    force_noise: np.ndarray | None = None


@dataclass(frozen=True)
class TrailFamily:
    """The trail shapes the torque's profile runs over, and what they miss.

    Attributes
    ----------
    shapes : tuple of TrailShape
        The members.
    form_rel : float
        1σ of the trail the members miss, relative to t₀ [-].
    t0_m : float or None
        A known tyre's zero-slip lever at the static load (None: the family's declaration) [m].
    load_exponent : float
        t₀ ∝ F_z^x per wheel: :data:`TRAIL_LOAD_EXPONENT`, or the known tyre's own over
        0.5–1.5 × the static load [-].
    source : str
        ``family`` or the tyre file's name.
    """

    shapes: tuple[TrailShape, ...]
    form_rel: float
    t0_m: float | None
    load_exponent: float
    source: str


@functools.lru_cache(maxsize=16)
def _known_trail(path: str, fz_static: float) -> TrailFamily:
    """A known tyre's own trail shapes at :data:`KNOWN_TRAIL_LOADS` × the static load."""
    tyre = load_mf_tyre(path)
    u = np.linspace(0.05, 0.97, 40)
    shapes, errors, xi0 = [], [], []
    for f in KNOWN_TRAIL_LOADS:
        tau, xi = tyre_trail_ratio(tyre, fz_static * f, u)
        shape, err = fit_trail_shape(u, tau)
        shapes.append(shape)
        errors.append(err)
        xi0.append(xi)
    # a rig's curve carried to a car on a road (docs/physics.md §16.7): its wheels lean, and
    # its trail may fall a little earlier or later against the force than the rig's
    for g in KNOWN_TRAIL_CAMBER_RAD:
        shape, err = fit_trail_shape(u, tyre_trail_ratio(tyre, fz_static, u, gamma_rad=g)[0])
        shapes.append(shape)
        errors.append(err)
    for f in KNOWN_TRAIL_LOADS:
        for stretch in KNOWN_TRAIL_STRETCH:
            us = u[u * stretch <= u[-1]]  # where the rig's curve is known
            tau = tyre_trail_ratio(tyre, fz_static * f, us * stretch)[0]
            shape, err = fit_trail_shape(us, tau)
            shapes.append(shape)
            errors.append(err)
    exponent = np.polyfit(np.log(KNOWN_TRAIL_LOADS), np.log(np.maximum(xi0, 1e-6)), 1)[0]
    return TrailFamily(
        tuple(dict.fromkeys(shapes)),
        max(KNOWN_TRAIL_FORM_FLOOR, *errors),
        xi0[KNOWN_TRAIL_LOADS.index(1.0)],
        float(np.clip(exponent, 0.0, 1.5)),
        Path(path).name,
    )


def trail_family(vehicle: Vehicle) -> TrailFamily:
    """The trail shapes of the front tyre: the known tyre's own (``[steering] tyre_file``),
    else the members of :data:`~gripsense.physics.trail_shapes.TRAIL_FAMILY` its declared
    shape allows (``docs/physics.md`` §16.5, §16.7).

    Parameters
    ----------
    vehicle : Vehicle
        Vehicle description.

    Returns
    -------
    TrailFamily
        Shapes, form error and, for a known tyre, its zero-slip lever.
    """
    s = vehicle.steering or SteeringSystem()
    if s.tyre_file:
        return _known_trail(s.tyre_file, float(vehicle.static_load("front")))
    ids = trail_shape_ids(vehicle.tyres["front"].shape)
    shapes = tuple(TRAIL_FAMILY[i] for i in ids)
    return TrailFamily(shapes, TRAIL_FORM_REL, None, TRAIL_LOAD_EXPONENT, "family")


def _moment(p: dict, vehicle: Vehicle, s: SteeringSystem) -> tuple[np.ndarray, str, float, float]:
    """The steering moment at the axes per sample, what it was made of, and the channel's
    scale and offset priors.
    """
    ratio = vehicle.steering_ratio
    gain = s.assist_gain if s.assist == "linear" else 0.0
    if "rack_n_L" in p and np.isfinite(p["rack_n_L"]).any():
        if s.steering_arm_m is None:
            raise InputError(
                f"{vehicle.source}: a rack-force channel needs [steering] steering_arm_m "
                "(the tie-rod lever about the steering axis, m)"
            )
        return (
            p["rack_n_L"] * s.steering_arm_m,
            "rack force × steering arm",
            s.torque_scale_uncertainty,
            s.torque_offset_uncertainty_Nm * (ratio or 15.0) * (1.0 + gain),
        )
    if not ratio:
        raise InputError(
            f"{vehicle.source}: a steering-torque channel needs the steering ratio "
            "([steering] ratio or [vehicle] steering_ratio)"
        )
    torque = p["torque_nm_L"]
    if "assist_nm_L" in p:
        total, what = torque + p["assist_nm_L"], "(column + assist torque) × ratio"
        scale_sd = s.torque_scale_uncertainty
    else:
        total, what = torque * (1.0 + gain), "column torque × (1 + assist gain) × ratio"
        scale_sd = float(np.hypot(s.torque_scale_uncertainty,
                                  s.assist_gain_uncertainty * gain / (1.0 + gain)))  # fmt: skip
    offset = s.torque_offset_uncertainty_Nm * ratio * (1.0 + gain)
    return total * ratio, what, scale_sd, offset


def torque_bins(
    wheels: pd.DataFrame, vehicle: Vehicle, bin_s: float = 1.0, min_samples: int = 5
) -> TorqueBins | None:
    """Bin the front axle's samples that carry a steering-torque channel.

    Parameters
    ----------
    wheels : pandas.DataFrame
        Wheel table with the steering-torque columns (:data:`gripsense.io.sensors.steer.
        STEERING_TORQUE`) on its front wheels.
    vehicle : Vehicle
        Vehicle description (its ``[steering]`` table; defaults when absent).
    bin_s : float
        Bin length [s].
    min_samples : int
        Fewest samples with a torque value in a bin.

    Returns
    -------
    TorqueBins or None
        None when the table has no steering-torque channel or no front-axle samples.
    """
    if not any(c in wheels.columns for c in ("torque_nm", "rack_n")):
        return None
    p = axle_pairs(wheels, "front")
    if p["t_s_L"].size == 0:
        return None
    s = vehicle.steering or SteeringSystem()
    m, source, scale_sd, offset_sd = _moment(p, vehicle, s)
    ok = np.isfinite(m)
    if "steer_rad_L" in p:
        ok &= np.isfinite(p["steer_rad_L"])
    t = p["t_s_L"][ok]
    if t.size == 0:
        return None
    starts, n = bin_starts(t, bin_s)

    def mean(x):
        return np.add.reduceat(x[ok], starts) / n

    def mean_of(x):  # of samples already selected
        return np.add.reduceat(x, starts) / n

    mm = m[ok]
    # the channel's white noise from successive differences within each bin (robust to the
    # slow change of the moment along the bin)
    d2 = np.concatenate([[0.0], np.diff(mm) ** 2])
    d2[starts] = 0.0
    cnt = np.maximum(n - 1, 1)
    white = np.sqrt(np.add.reduceat(d2, starts) / cnt / 2.0)
    f_white = p["force_sigma_N_L"] + p["force_sigma_N_R"]
    # within a transient bin force and moment change together, through dynamics the balance
    # does not carry (the axle force's yaw-acceleration term resolved only roughly, the
    # steering's inertia, damping and friction switching, the trail's own lag): their spread
    # beyond the white noise is an error of the bin's point, not averaged down
    force = p["axle_force_N_L"][ok]
    m_spread = np.sqrt(np.maximum(mean(m * m) - mean(m) ** 2 - white**2, 0.0))
    f_spread = np.sqrt(np.maximum(
        np.add.reduceat(force * force, starts) / n - (np.add.reduceat(force, starts) / n) ** 2
        - np.add.reduceat(f_white[ok] ** 2, starts) / n, 0.0))  # fmt: skip
    f_noise = np.sqrt(np.add.reduceat(f_white[ok] ** 2, starts)) / n
    # the steering friction per sample, so that a reversal inside a bin — a corner exit, the
    # wheel unwound — is seen where it happens (docs/physics.md §16.6): the Dahl model along
    # the steer smoothed over a second and behind a deadband above its noise (along the noisy
    # samples the friction of a held curve would drift to zero); known only where the steer
    # drives it one way, not where it holds (an unseen correction moves it anywhere) or a
    # reversal the steer confirms is under way
    if "steer_rad_L" in p:
        steer = p["steer_rad_L"][ok]
        noise = _steer_noise(steer)
        smooth, k = _smoothed(steer, t, STATE_SMOOTHING_S)
        played = backlash(smooth, STATE_DEADBAND_SD * noise / np.sqrt(k))
        state_i = dahl_friction(played, 1.0, FRICTION_TRAVEL_RAD)
        _, known = friction_state(steer, noise, FRICTION_TRAVEL_RAD)
        driven = _driven(played, state_i, t, FRICTION_DRIVE_S, FRICTION_TRAVEL_RAD)
        # known where the steer drives it; held or reversing, its whole size
        sd_i = np.where(driven & known, FRICTION_STATE_SD, 1.0)
    else:
        steer, state_i, sd_i = np.zeros(t.size), np.zeros(t.size), np.ones(t.size)
    state = mean_of(state_i)
    f_sd = mean_of(sd_i)
    keep = n >= min_samples
    t_end = np.maximum.reduceat(t, starts)
    # the damping moment C_s δ̇ of the bin (its mean steering rate), taken out with its
    # uncertainty
    last = np.concatenate([starts[1:], [t.size]]) - 1
    dur = t_end - t[starts]
    with np.errstate(invalid="ignore", divide="ignore"):
        rate = np.where(dur > 0, (steer[last] - steer[starts]) / dur, 0.0)
    s_damp = s.kingpin_damping_Nms * rate
    if "torque_samples_L" in p:
        per = np.nan_to_num(p["torque_samples_L"][ok], nan=0.0)
        samples = np.add.reduceat(np.where(per > 0, per, 1.0), starts)
    else:
        samples = n.astype(float)
    step = float(np.median(np.diff(t))) if t.size > 1 else 0.0
    span = float(n[keep].sum()) * step  # the epochs' time the bins cover
    return TorqueBins(
        t0=t[starts][keep],
        t1=t_end[keep],
        n=n[keep],
        force=mean(p["axle_force_N_L"])[keep],
        force_sigma=np.hypot(f_noise, f_spread)[keep],
        fz_l=mean(p["load_N_L"])[keep],
        fz_r=mean(p["load_N_R"])[keep],
        moment=(mean(m) - s_damp)[keep],
        moment_sigma=np.sqrt(white**2 / n + m_spread**2 + (DAMPING_REL * s_damp) ** 2)[keep],
        friction_state=state[keep],
        friction_sd=f_sd[keep],
        grip=mean(p["grip_used_L"])[keep],
        fz_static=vehicle.static_load("front"),
        source=source,
        scale_sd=scale_sd,
        offset_sd=offset_sd,
        samples=int(samples[keep].sum()),
        rate_hz=float(samples[keep].sum() / span) if span > 0 else float("nan"),
        slip=mean(0.5 * (p["slip_angle_rad_L"] + p["slip_angle_rad_R"]))[keep],
        slip_sigma=mean(0.5 * (p["slip_sigma_rad_L"] + p["slip_sigma_rad_R"]))[keep],
        force_noise=f_noise[keep],
    )


def _smoothed(x: np.ndarray, t: np.ndarray, window_s: float) -> tuple[np.ndarray, int]:
    """A centred moving average over about *window_s* of samples (an odd count at the median
    sampling step) [x's unit], and that count.
    """
    if x.size < 3:
        return x, 1
    dt = float(np.median(np.diff(t))) if t.size > 1 else 0.0
    k = round(window_s / dt) if dt > 0 else 1
    k = max(1, min(k, x.size)) | 1
    return uniform_filter1d(x, k, mode="nearest"), k


def _driven(
    played: np.ndarray, state: np.ndarray, t: np.ndarray, window_s: float, travel: float
) -> np.ndarray:
    """Where the steer behind the deadband (*played*) moved on in the friction's direction
    (*state*'s sign) by at least *travel* [rad] within the trailing *window_s* [s]: there the
    friction is built up that way; elsewhere the steer holds (bool).
    """
    if t.size == 0:
        return np.zeros(0, dtype=bool)
    j = np.searchsorted(t, t - window_s, side="left")
    with np.errstate(invalid="ignore"):
        return np.sign(state) * (played - played[j]) >= travel


def _steer_noise(steer: np.ndarray) -> float:
    """1σ white noise of a steer channel's samples, from their second differences (robustly:
    the median absolute deviation) [rad].
    """
    x = steer[np.isfinite(steer)]
    if x.size < 5:
        return 0.0
    d2 = np.diff(x, 2)
    return 1.4826 * float(np.median(np.abs(d2 - np.median(d2)))) / np.sqrt(6.0)


def merge_torque_bins(tb: TorqueBins, tol: float) -> TorqueBins:
    """Merge runs of consecutive bins whose measured grip stays within *tol* of the run's first
    and whose friction state keeps its sign: a steady stretch is one point of the trail curve,
    its friction and model errors shared (not averaged down).

    Parameters
    ----------
    tb : TorqueBins
        The bins.
    tol : float
        Largest change of measured grip within a run [-].

    Returns
    -------
    TorqueBins
        The merged bins (sample-weighted means; white noise combined).
    """
    k = tb.t0.size
    if k == 0:
        return tb
    gid = np.zeros(k, dtype=np.int64)
    g0 = 0
    for i in range(1, k):
        same = (
            abs(tb.grip[i] - tb.grip[g0]) <= tol
            and np.sign(tb.friction_state[i]) == np.sign(tb.friction_state[g0])
            and tb.t0[i] - tb.t1[i - 1] <= 2.0
            and np.sign(tb.force[i]) == np.sign(tb.force[g0])
            and (tb.slip is None or not _slip_apart(tb, i, g0))
        )
        if not same:
            g0 = i
        gid[i] = gid[i - 1] + (0 if same else 1)
    w = tb.n.astype(float)
    sw = np.bincount(gid, w)

    def avg(x):
        return np.bincount(gid, w * x) / sw

    def rss(x):
        return np.sqrt(np.bincount(gid, (w * x) ** 2)) / sw

    first = np.flatnonzero(np.diff(np.concatenate([[-1], gid])))
    last = np.concatenate([first[1:] - 1, [k - 1]])
    return TorqueBins(
        t0=tb.t0[first],
        t1=tb.t1[last],
        n=np.bincount(gid, tb.n).astype(np.int64),
        force=avg(tb.force),
        force_sigma=rss(tb.force_sigma),
        fz_l=avg(tb.fz_l),
        fz_r=avg(tb.fz_r),
        moment=avg(tb.moment),
        moment_sigma=rss(tb.moment_sigma),
        friction_state=avg(tb.friction_state),
        friction_sd=avg(tb.friction_sd),
        grip=avg(tb.grip),
        fz_static=tb.fz_static,
        source=tb.source,
        scale_sd=tb.scale_sd,
        offset_sd=tb.offset_sd,
        samples=tb.samples,
        rate_hz=tb.rate_hz,
        slip=None if tb.slip is None else avg(tb.slip),
        slip_sigma=None if tb.slip_sigma is None else avg(tb.slip_sigma),
        force_noise=None if tb.force_noise is None else rss(tb.force_noise),
    )


@dataclass
class TorqueProfile:
    """What the steering torque says about the front axle's μ.

    Attributes
    ----------
    nll : numpy.ndarray
        Negative log-likelihood on the μ grid, profiled over the nuisances and the trail shapes
        (its minimum 0) [-].
    fit : str
        ``ok`` or ``inconsistent`` (the family explains the moment only beyond its noise: the
        channel is not used).
    bins : int
        Merged bins used.
    shape : str
        The trail shape at the best μ.
    caster_trail_m, pneumatic_trail_m : float
        The fitted caster and zero-slip pneumatic trail at the best μ (the channel's scale
        folded in) [m].
    offset_Nm : float
        The fitted offset at the steering axes [N m].
    limited_by : str
        The nuisance furthest from its prior at the best μ, or ``trail shape``.
    without : TorqueProfile or None
        With a known tyre (``[steering] tyre_file``) or a learned lever (``gripsense
        calibrate``): the profile over the family without them.
    past_peak : int
        Merged points left out because the data show them at or past the force's peak
        (:func:`past_peak`).
    """

    nll: np.ndarray
    fit: str
    bins: int
    shape: str
    caster_trail_m: float
    pneumatic_trail_m: float
    offset_Nm: float
    limited_by: str
    without: TorqueProfile | None = None
    past_peak: int = 0


def _zero_slip_trail(vehicle: Vehicle, s: SteeringSystem) -> float:
    """The declared zero-slip pneumatic trail of a front tyre at its static load [m]."""
    if s.pneumatic_trail_m is not None:
        return s.pneumatic_trail_m
    known = trail_family(vehicle).t0_m if s.tyre_file else None
    if known is not None:
        return known
    tyre = vehicle.tyres["front"]
    return float(tyre.contact_length(vehicle.static_load("front") / G0)) / 6.0


def check_channel(tb: TorqueBins, vehicle: Vehicle, name: str = "steering torque") -> None:
    """Refuse a torque channel whose sign or size contradicts the vehicle file.

    The moment per unit front force on cornering bins (measured grip ≥ 0.1) must be positive
    (it turns the wheels back: ISO, positive to the left in a left turn) and within a factor 5
    of the declared caster plus zero-slip trail.

    Parameters
    ----------
    tb : TorqueBins
        The bins.
    vehicle : Vehicle
        The vehicle description.
    name : str
        The channel, for the message.

    Raises
    ------
    InputError
        A flipped sign or a wrong unit, ratio or assist gain, with how to fix it.
    """
    use = np.abs(tb.grip) >= 0.1
    if use.sum() < 3:
        return
    f, m = tb.force[use], tb.moment[use]
    xi = float(np.sum(m * f) / np.sum(f * f))  # the lever through the origin
    s = vehicle.steering or SteeringSystem()
    expected = s.mechanical_trail_m + _zero_slip_trail(vehicle, s)
    corr = float(np.corrcoef(m, f)[0, 1]) if np.std(m) > 0 and np.std(f) > 0 else 0.0
    if xi < 0 and corr < -0.5:
        raise InputError(
            f"{name}: the steering moment falls as the car turns left (−{-xi * 1e3:.0f} N m per "
            "kN of front force): the channel's sign is flipped; give it as torque=-COLUMN "
            "(--steer-columns) so that steering left reads positive"
        )
    if not 0.2 <= xi / expected <= 5.0:
        raise InputError(
            f"{name}: {tb.source} gives {xi * 1e3:.0f} N m per kN of front force, the vehicle "
            f"file ~{expected * 1e3:.0f} (caster + pneumatic trail); check the channel's unit "
            "(N m, not N cm or kN m), [steering] ratio and assist_gain"
        )


def _points(tb: TorqueBins, keep: np.ndarray) -> TorqueBins:
    """The bins or points where *keep* holds."""
    if keep.all():
        return tb
    per = {
        f.name: getattr(tb, f.name)[keep]
        for f in dataclasses.fields(tb)
        if isinstance(getattr(tb, f.name), np.ndarray)
    }
    return dataclasses.replace(tb, **per)


def _slip_apart(tb: TorqueBins, i: int, j: int) -> bool:
    """Whether bin *i*'s slip is more than twice bin *j*'s, or less than half of it, beyond
    their slips' 3σ (a slide and a hold at the same grip are two points, not one run).
    """
    a, b = abs(tb.slip[i]), abs(tb.slip[j])  # type: ignore[index]
    m = 3.0 * float(np.hypot(tb.slip_sigma[i], tb.slip_sigma[j]))  # type: ignore[index]
    return bool(a > 2.0 * b + m or b > 2.0 * a + m)


def past_peak(tb: TorqueBins) -> np.ndarray:
    """The points at or past the peak of the axle's force, shown by the data alone: another
    point carries at least as much grip at less than half the slip.

    On the rising side the force grows with the slip, so a point whose slip is more than twice
    another's (beyond both slips' 3σ) while its grip is not larger (beyond 2σ of the grips'
    white noise; a slide's spread would let a rising point near the peak pass as "as much
    grip") has passed the peak — a slide, a controller's overshoot into a corner. There the
    trail has fallen further than the rising side's τ(u) at that grip says, towards zero and
    below, and the trail would read the slide as a tyre at its limit on a lower μ; such a point
    is left out of the torque's fit. No tyre model is used, only the measured slip and grip.

    The other point may be on either side of the force: the axle's force is odd in its slip (a
    tyre's is up to conicity and ply steer — a shift of a fraction of a degree and peaks a few
    per cent apart, 7 % on the PAC2002 sedan file, while at half the slip the rising side holds
    far less grip), and a car that spins slides on one side only — its turn-in, at less slip
    and as much grip, was the other way. Across sides a common error of the slip
    (:data:`SIDE_SLIP_OFFSET_RAD`) adds to one side's |slip| and takes from the other's: the
    slip must be more than twice the other's beyond three times that error as well.

    Parameters
    ----------
    tb : TorqueBins
        Bins or merged points with their slip (:func:`torque_bins`).

    Returns
    -------
    numpy.ndarray of bool
        Per point: at or past the peak.

    References
    ----------
    docs/physics.md §16.6.
    """
    k = tb.t0.size
    if tb.slip is None or tb.slip_sigma is None or k < 2:
        return np.zeros(k, dtype=bool)
    a = np.abs(tb.slip)
    g = np.abs(tb.grip)
    noise = tb.force_sigma if tb.force_noise is None else tb.force_noise
    gs = np.abs(noise) / np.maximum(tb.fz_l + tb.fz_r, 1.0)
    side = np.sign(tb.force)
    sa = np.hypot(tb.slip_sigma[:, None], tb.slip_sigma[None, :])
    sg = np.hypot(gs[:, None], gs[None, :])
    # across sides a common slip error δ counts twice against j and once against i
    across = np.where(side[:, None] == side[None, :], 0.0, 3.0 * SIDE_SLIP_OFFSET_RAD)
    # [i, j]: j holds at least i's grip at less than half i's slip
    beaten = (a[:, None] > 2.0 * a[None, :] + 3.0 * sa + across) & (
        g[None, :] >= g[:, None] - 2.0 * sg
    )
    return np.asarray(beaten.any(axis=1) & np.isfinite(a))


def torque_read(tb: TorqueBins, profile: TorqueProfile) -> str:
    """What was read of a steering-torque channel, in words: the moment's source, the channel's
    rate and samples, and the bins and merged points the profile used.

    Parameters
    ----------
    tb : TorqueBins
        The bins (:func:`torque_bins`).
    profile : TorqueProfile
        Their profile (:func:`torque_profile`).

    Returns
    -------
    str
        E.g. ``column torque × (1 + assist gain) × ratio at 100 Hz (4210 samples), 42 bins →
        9 points``.
    """
    rate = f" at {tb.rate_hz:.0f} Hz" if np.isfinite(tb.rate_hz) else ""
    out = f"{tb.source}{rate} ({tb.samples} samples), {tb.t0.size} bins → {profile.bins} points"
    if profile.past_peak:
        out += f" ({profile.past_peak} past the force's peak left out)"
    return out


def torque_profile(
    tb: TorqueBins, vehicle: Vehicle, mu_grid: np.ndarray, *, tol: float = 0.03
) -> TorqueProfile:
    """The profile likelihood of the front axle's μ from the steering moment (``docs/physics.md``
    §16.6).

    Parameters
    ----------
    tb : TorqueBins
        The bins (:func:`torque_bins`).
    vehicle : Vehicle
        Vehicle description: ``[steering]`` priors, the front tyre's shape and contact length.
    mu_grid : numpy.ndarray
        μ values [-].
    tol : float
        Grip tolerance of a steady run (:func:`merge_torque_bins`) [-].

    Returns
    -------
    TorqueProfile
        The profile on *mu_grid* and the nuisances at its best μ.
    """
    mb = merge_torque_bins(tb, tol)
    g = np.asarray(mu_grid, float)
    beyond = past_peak(mb)
    mb = _points(mb, ~beyond)
    if mb.t0.size == 0:
        return TorqueProfile(
            np.zeros(g.size), "no data", 0, "", np.nan, np.nan, np.nan, "",
            past_peak=int(beyond.sum()),
        )  # fmt: skip
    s = vehicle.steering or SteeringSystem()
    res = dataclasses.replace(_profile(mb, vehicle, g), past_peak=int(beyond.sum()))
    if s.tyre_file or s.calibrated_lever_m is not None:
        # what the family says without the tyre's file and the learned lever: the range is kept
        # within it (profile_mu), so that knowing more never says less
        plain = dataclasses.replace(
            s, tyre_file=None, calibrated_lever_m=None, calibrated_lever_uncertainty=None
        )
        without = dataclasses.replace(vehicle, steering=plain)
        res = dataclasses.replace(res, without=_profile(mb, without, g))
    return res


def _profile(mb: TorqueBins, vehicle: Vehicle, g: np.ndarray) -> TorqueProfile:
    """:func:`torque_profile` of merged bins over the vehicle's trail family."""
    s = vehicle.steering or SteeringSystem()
    k = mb.t0.size
    family = trail_family(vehicle)
    ratio = vehicle.steering_ratio or 15.0
    t00 = _zero_slip_trail(vehicle, s)
    tc0 = s.mechanical_trail_m
    fz = mb.fz_l + mb.fz_r
    x = family.load_exponent
    w = (mb.fz_l * (mb.fz_l / mb.fz_static) ** x + mb.fz_r * (mb.fz_r / mb.fz_static) ** x) / fz
    f = mb.force
    y = mb.moment
    # noise of each bin: the channel's white noise, the force's (through the lever), the trail
    # the family misses, the balance's own fidelity, the friction state's error
    mc = s.friction_Nm * ratio
    # the friction state's error: at the declared friction where the state is built up, at its
    # upper 1σ for the share of a bin whose friction is reversing
    mc_hi = mc + s.friction_uncertainty_Nm * ratio
    f_err = np.hypot(FRICTION_STATE_SD * mc, (mb.friction_sd - FRICTION_STATE_SD) * mc_hi)
    sig2 = (
        mb.moment_sigma**2
        + ((tc0 + t00 * w) * mb.force_sigma) ** 2
        + (family.form_rel * t00 * w * f) ** 2
        + (MOMENT_MODEL_REL * (tc0 + t00 * w) * f) ** 2
        + f_err**2
    )
    # priors of θ = (a, b, o, f): a = k t_c, b = k t₀ correlated through the scale k
    sd_t0 = t00 * s.pneumatic_trail_uncertainty
    cov = np.zeros((4, 4))
    cov[0, 0] = s.mechanical_trail_uncertainty_m**2 + (tc0 * mb.scale_sd) ** 2
    cov[1, 1] = sd_t0**2 + (t00 * mb.scale_sd) ** 2
    cov[0, 1] = cov[1, 0] = tc0 * t00 * mb.scale_sd**2
    cov[2, 2] = mb.offset_sd**2 + (RESIDUAL_MOMENT_PER_N * 2.0 * mb.fz_static) ** 2
    cov[3, 3] = (s.friction_uncertainty_Nm * ratio) ** 2 + 1e-9
    prec = np.linalg.inv(cov)
    th0 = np.array([tc0, t00, 0.0, mc])
    # regressors: F, F W τ(u), 1, s; only the second depends on μ and the shape
    u = np.abs(f)[None, :] / (g[:, None] * fz[None, :])  # (G, K): the axle's utilisation
    fam = family.shapes
    # each wheel at its own utilisation: the force shared by load, μ falling with the load
    # (μ_i ∝ F_z,i^−η), so u_i = u (F_z,i/F̄_z)^η — the loaded wheel, which carries most of the
    # trail's moment, works nearer its limit
    eta = vehicle.tyres["front"].friction_load_sensitivity
    fz_mean = 0.5 * fz
    tau = np.zeros((g.size, len(fam), k))
    for fzi in (mb.fz_l, mb.fz_r):
        share = fzi / fz * (fzi / mb.fz_static) ** x
        ui = u * (np.maximum(fzi, 1.0) / fz_mean) ** eta
        tau += share * np.stack([trail_ratio(ui, sh.p, sh.tau1) for sh in fam], axis=1)
    tau /= w  # (G, S, K): the load-weighted trail ratio of the axle
    z = f * w * tau
    # errors of the trail that grow towards the limit, weighted by where the bin can be at
    # most — u ≤ |grip|/max|grip| since μ is at least the largest measured grip — so that no
    # weight depends on μ: the wheels' utilisations spread about the axle's (load transfer, μ's
    # load sensitivity), which the trail's slope turns into an error of the moment, and near
    # the peak, where the family ends but the real trail keeps falling (on some tyres below
    # zero), its shape is known less
    u_up = np.clip(np.abs(mb.grip) / max(float(np.max(np.abs(mb.grip))), 1e-9), 0.0, 1.0)
    slope_rep = (1.0 - 0.2) * 3.0 * u_up**2.0  # a middle member (p 3, τ₁ 0.2)
    near_peak = np.clip((u_up - PEAK_FORM_FROM) / (1.0 - PEAK_FORM_FROM), 0.0, 1.0)
    sig2 = sig2 + (t00 * w * f) ** 2 * (
        (UTILISATION_SPREAD_REL * u_up * slope_rep) ** 2 + (PEAK_FORM_REL * near_peak) ** 2
    )
    iw = 1.0 / sig2
    x_fixed = np.stack([f, np.ones(k), mb.friction_state], axis=1)  # (K, 3) for a, o, f
    a_ff = x_fixed.T @ (iw[:, None] * x_fixed)
    r_f = x_fixed.T @ (iw * y)
    a_zz = np.einsum("gsk,k,gsk->gs", z, iw, z)
    a_zf = np.einsum("gsk,k,kj->gsj", z, iw, x_fixed)
    r_z = np.einsum("gsk,k,k->gs", z, iw, y)
    gs = z.shape[:2]  # the unknowns in the order (a, o, f, b)
    A = np.zeros((*gs, 4, 4))
    A[..., :3, :3] = a_ff
    A[..., :3, 3] = a_zf
    A[..., 3, :3] = a_zf
    A[..., 3, 3] = a_zz
    R = np.zeros((*gs, 4))
    R[..., :3] = r_f
    R[..., 3] = r_z
    # the prior in the (a, o, f, b) order
    perm = np.array([0, 2, 3, 1])
    P = prec[np.ix_(perm, perm)]
    t0p = th0[perm]
    p_all, r_all, c_all = P, P @ t0p, float(t0p @ P @ t0p)
    if s.calibrated_lever_m is not None and s.calibrated_lever_uncertainty is not None:
        # the lever learned from everyday driving (gripsense calibrate, §16.8): a + b = S ± σ
        x_cal = np.array([1.0, 0.0, 0.0, 1.0])
        w_cal = 1.0 / (s.calibrated_lever_uncertainty * s.calibrated_lever_m) ** 2
        p_all = p_all + w_cal * np.outer(x_cal, x_cal)
        r_all = r_all + w_cal * s.calibrated_lever_m * x_cal
        c_all += w_cal * s.calibrated_lever_m**2
    A = A + p_all
    R = R + r_all
    th = np.linalg.solve(A, R[..., None])[..., 0]
    chi = float(np.sum(iw * y * y)) + c_all - np.einsum("gsi,gsi->gs", R, th)
    best_s = np.argmin(chi, axis=1)
    prof = chi[np.arange(g.size), best_s]
    im = int(np.argmin(prof))
    fit = "ok"
    if prof[im] > chi2.ppf(0.999, max(k, 1)) + 4.0:
        fit = "inconsistent"
    tb_best = th[im, best_s[im]]  # (a, o, f, b)
    z_sd = (tb_best - t0p) / np.sqrt(np.diag(np.linalg.inv(P)))
    names = ("caster trail", "torque offset", "steering friction", "pneumatic trail")
    limited = names[int(np.argmax(np.abs(z_sd)))] if np.max(np.abs(z_sd)) > 1.0 else "trail shape"
    return TorqueProfile(
        nll=0.5 * (prof - prof.min()),
        fit=fit,
        bins=k,
        shape=fam[int(best_s[im])].name,
        caster_trail_m=float(tb_best[0]),
        pneumatic_trail_m=float(tb_best[3]),
        offset_Nm=float(tb_best[1]),
        limited_by=limited,
    )
