"""The friction the data prove without a tyre model: the measured grip (``docs/physics.md`` §14).

Per sample, each axle's lateral force (m a_y share with the yaw-acceleration term) over its
load (statics: known for any lateral load transfer); per bin and drive, one-sided lower bounds.
They hold for any tyre; they assume a level road without aerodynamic downforce.
"""

from __future__ import annotations

import numpy as np
import pandas as pd
from scipy.stats import norm

from gripsense.config import Vehicle
from gripsense.constants import G0
from gripsense.estimate.bins import AxleBins, axle_bins, axle_pairs
from gripsense.estimate.noise import NoiseModel
from gripsense.estimate.options import WindowOptions

__all__ = [
    "axle_grip",
    "bin_bound",
    "drive_bound",
    "local_slope",
    "measured_grip",
    "unseen_yaw_moment",
]


TIME_SLACK_S = 1e-6
"""A sample this close to a window's edge is inside it: time stamps relative to the log's start
carry float rounding of ~1e-7 s (seconds since 1970 in float64), so a 10 Hz receiver's sample
0.5 s away would fall in or out by chance, and a reconstruction of the same epochs
(``docs/physics.md`` §14.2) with it [s]."""


def local_slope(y: np.ndarray, t: np.ndarray, half_s: float) -> np.ndarray:
    """dy/dt by a least-squares line over the samples within ±half_s of each sample
    (cumulative sums: O(n)); NaN where fewer than 3 samples fall in the window. A sample at
    the window's edge counts within :data:`TIME_SLACK_S` (time stamps carry float rounding).
    """
    n = t.size
    if n < 3:
        return np.full(n, np.nan)
    lo = np.searchsorted(t, t - half_s - TIME_SLACK_S, side="left")
    hi = np.searchsorted(t, t + half_s + TIME_SLACK_S, side="right")
    tc = t - t[0]
    yy = np.where(np.isfinite(y), y, 0.0)
    ok = np.isfinite(y).astype(float)
    cs = [np.concatenate([[0.0], np.cumsum(a)]) for a in (ok, ok * tc, ok * tc**2, yy, yy * tc)]
    c0, c1, c2, cy, cty = (c[hi] - c[lo] for c in cs)
    den = c0 * c2 - c1**2
    with np.errstate(divide="ignore", invalid="ignore"):
        slope = (c0 * cty - c1 * cy) / den
    return np.where((c0 >= 3) & (den > 0), slope, np.nan)


def _local_mean(y: np.ndarray, t: np.ndarray, half_s: float) -> np.ndarray:
    """Mean of the finite samples within ±half_s of each sample (cumulative sums: O(n); NaN
    where none is finite; the edge within :data:`TIME_SLACK_S`).
    """
    lo = np.searchsorted(t, t - half_s - TIME_SLACK_S, side="left")
    hi = np.searchsorted(t, t + half_s + TIME_SLACK_S, side="right")
    ok = np.isfinite(y)
    cn = np.concatenate([[0.0], np.cumsum(ok)])
    cy = np.concatenate([[0.0], np.cumsum(np.where(ok, y, 0.0))])
    n = cn[hi] - cn[lo]
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(n > 0, (cy[hi] - cy[lo]) / n, np.nan)


def _earth_frame_accel(t, speed, course, heading, r, cg) -> tuple[np.ndarray, np.ndarray]:
    """Body-axis acceleration (a_x, a_y) of the CG from the velocity differentiated in the
    earth frame.

    a = d(v_E, v_N)/dt over ±0.5 s at the antenna, projected on the body's axes with the
    heading, moved to the CG with the rigid-body terms ṙ ẑ × d − r² d (d: antenna → CG).
    Unlike U̇ − V r and U r + V̇ in body axes, the smoothing here averages a physical
    acceleration, so its magnitude never exceeds what the tyres delivered — also in a spin.
    """
    ve, vn = speed * np.sin(course), speed * np.cos(course)
    ae, an = local_slope(ve, t, 0.5), local_slope(vn, t, 0.5)
    ax_ant = ae * np.sin(heading) + an * np.cos(heading)
    ay_ant = -ae * np.cos(heading) + an * np.sin(heading)
    rdot = np.nan_to_num(local_slope(r, t, 0.5))
    return ax_ant - rdot * cg[1] - r * r * cg[0], ay_ant + rdot * cg[0] - r * r * cg[1]


UNSEEN_SLIP_RAD = 0.1
"""Without a steering channel, the front wheels' steer is taken within this of the kinematic
L r/U: the axles' slip difference (understeer beyond 0.1 rad is a front axle sliding far past
its peak) [rad]."""
ALIGNING_TRAIL_FACTOR = 1.0
"""The tyres' aligning moments are bounded by this many times the declared zero-slip
pneumatic trail (l/6 of the contact length at the static load) times each axle's force: the
trail is largest near zero slip, and where the force is large it has fallen well below it [-]."""
NEGATIVE_TRAIL_SHARE = 0.25
"""Past the force's peak the pneumatic trail turns negative, to at most this share of the
zero-slip one: the aligning moments then push the other way [-]."""


def unseen_yaw_moment(
    vehicle: Vehicle, f_front, f_rear, steer_lo, steer_hi, side
) -> tuple[np.ndarray, np.ndarray]:
    """The range of the yaw moment the axles' forces leave out of I_z ṙ = l_f F_f − l_r F_r
    [N m].

    Two moments the two-axle balance does not carry, bounded without a tyre model:

    * the steered wheels' forces at half the front track: each front wheel's lateral force
      F_i, turned by the steer δ, pushes along the car by −F_i sin δ at ±t_f/2, a moment
      (t_f/2) sin δ (F_left − F_right). The outer wheel carries at least the inner's force
      (it carries more load), so F_left − F_right lies between 0 and −|F_f| times the side of
      the turn, whatever the share;
    * the tyres' aligning moments, M_z,i = −t_i F_i: self-aligning, with the pneumatic trail t
      at most :data:`ALIGNING_TRAIL_FACTOR` times the declared zero-slip one, and past the peak
      at least −:data:`NEGATIVE_TRAIL_SHARE` of it.

    Parameters
    ----------
    vehicle : Vehicle
        Vehicle description (front track, tyres' contact lengths).
    f_front, f_rear : numpy.ndarray
        The axles' largest lateral forces in magnitude [N].
    steer_lo, steer_hi : numpy.ndarray
        The range of the front road-wheel angle, ISO (positive left) [rad].
    side : numpy.ndarray
        The side of the turn: the sign of the lateral acceleration (+1 left) [-].

    Returns
    -------
    m_lo, m_hi : numpy.ndarray
        The moment's range, ISO [N m].

    References
    ----------
    docs/physics.md §14.1.
    """
    m_front, m_rear = vehicle.axle_masses_kg
    t0 = [
        float(np.max(vehicle.tyres[a].contact_length(m / 2.0))) / 6.0
        for a, m in (("front", m_front), ("rear", m_rear))
    ]
    ff, fr = np.abs(f_front), np.abs(f_rear)
    half = 0.5 * vehicle.track_front_m
    # (t_f/2) sin δ (F_l − F_r) with (F_l − F_r) = −side q |F_f|, q in [0, 1]
    ends = [
        -half * np.sin(np.clip(d, -np.pi / 2, np.pi / 2)) * side * q * ff
        for d in (steer_lo, steer_hi)
        for q in (0.0, 1.0)
    ]
    st_lo, st_hi = np.minimum.reduce(ends), np.maximum.reduce(ends)
    # Σ M_z = −side Σ t_i |F_i|, t_i in [−share, factor] t₀
    align = t0[0] * ff + t0[1] * fr
    al = -side * ALIGNING_TRAIL_FACTOR * align
    ah = side * NEGATIVE_TRAIL_SHARE * align
    return st_lo + np.minimum(al, ah), st_hi + np.maximum(al, ah)


def axle_grip(
    vehicle: Vehicle,
    t,
    u_a,
    v_a,
    r,
    ay,
    *,
    ay_measured,
    noise,
    earth=None,
    steer=None,
    unseen: bool = True,
) -> tuple:
    """Per axle: the lateral force it carries (with the yaw-acceleration term), its nominal
    load, and the friction it used — model-free, ``docs/physics.md`` §14.

    F_front = (m a_y l_r + I_z ṙ)/L, F_rear = (m a_y l_f − I_z ṙ)/L, a_y of the CG from the
    earth-frame velocity (*earth* = (course, heading) known, :func:`_earth_frame_accel`), else
    U r + V̇;
    the grip used is |F| / Fz_axle with the smallest |F| over I_z ± 30 % and the yaw moment the
    balance leaves out (:func:`unseen_yaw_moment`: the steered wheels' forces at half the track,
    the tyres' aligning moments; with the front steer *steer* [rad], else the kinematic one
    within :data:`UNSEEN_SLIP_RAD`; *unseen* False leaves it out — the model-based estimate's
    grip), and the largest axle load the longitudinal transfer allows
    over the declared CG-height range — a lower bound on μ for any tyre and any lateral load
    transfer.
    """
    m = vehicle.mass_kg
    m_ax = dict(zip(("front", "rear"), vehicle.axle_masses_kg, strict=True))
    ok_t = t.size > 2 and bool(np.all(np.diff(t) > 0))
    cg = vehicle.cg_offset
    signed = ok_t and cg is not None and earth is not None
    if signed:
        ax_e, ay_e = _earth_frame_accel(t, np.hypot(u_a, v_a), earth[0], earth[1], r, cg)
    if signed and not np.all(ay_measured):
        ay_tot = np.where(ay_measured | ~np.isfinite(ay_e), ay, ay_e)
    elif ok_t and cg is not None and not np.all(ay_measured):
        v_cg = v_a + r * cg[0]
        vdot = local_slope(v_cg, t, 0.5)
        ay_tot = np.where(ay_measured, ay, ay + np.nan_to_num(vdot))
    else:
        ay_tot = ay
    rdot = np.nan_to_num(local_slope(r, t, 0.5)) if ok_t else np.zeros(t.size)
    wb = vehicle.wheelbase_m
    m_lo = m_hi = np.zeros(t.size)
    if wb is not None and unseen:
        # the front steer's range: the channel's, else the kinematic one within the slip
        speed = np.maximum(np.hypot(u_a, v_a), 1.0)
        d_kin = wb * r / speed
        lo, hi = d_kin - UNSEEN_SLIP_RAD, d_kin + UNSEEN_SLIP_RAD
        if steer is not None:  # the channel's, within a 5 % scale error and 0.01 rad
            d = np.asarray(steer, float)
            e = 0.05 * np.abs(d) + 0.01
            lo = np.where(np.isfinite(d), d - e, lo)
            hi = np.where(np.isfinite(d), d + e, hi)
        iz_hi = 1.3 * abs(vehicle.yaw_inertia) * np.abs(rdot) / wb
        f_abs = {
            a: np.abs(m * ay_tot * sh) + iz_hi
            for a, sh in (
                ("front", vehicle.front_weight_fraction),
                ("rear", 1.0 - vehicle.front_weight_fraction),
            )
        }
        side = np.sign(np.nan_to_num(ay_tot))
        m_lo, m_hi = unseen_yaw_moment(vehicle, f_abs["front"], f_abs["rear"], lo, hi, side)
    force, load, grip = {}, {}, {}
    ax = np.zeros(t.size)
    if ok_t and cg is not None:
        u_cg = u_a - r * cg[1]
        v_cg = v_a + r * cg[0]
        ax = np.nan_to_num(local_slope(u_cg, t, 0.5)) - v_cg * r
    h_lo, h_hi = vehicle.cg_height_range_m or (vehicle.cg_height_m, vehicle.cg_height_m)
    # the longitudinal transfer's a_x for the bound, and its one-sided 95 % margin: the slope of
    # U over ±0.5 s (velocity noise) and V r (V from the heading: its slow error and its white
    # noise over the ~10 samples of ±0.5 s); where the earth-frame a_x is known, the body-axis
    # U̇ − V r differs from it over ±0.5 s by how each is smoothed — in a transient or a spin
    # by far more than the noise, and the margin with it
    psi_sd = np.deg2rad(np.hypot(noise.heading_white_deg / 3.0, noise.heading_slow_deg))
    ax_margin = 1.645 * np.hypot(1.1 * noise.velocity_mps, np.hypot(u_a, v_a) * np.abs(r) * psi_sd)
    if signed:
        ax_b = np.where(np.isfinite(ax_e), ax_e, ax)
        ax_margin = ax_margin + np.abs(np.nan_to_num(_local_mean(ax_b - ax, t, 0.5)))
    else:
        ax_b = ax
    for axle in ("front", "rear"):
        mi = m_ax[axle]
        if wb is not None:
            # front: (m a_y l_r + I_z ṙ)/L; rear: (m a_y l_f − I_z ṙ)/L; l_r/L = weight share
            share = (
                vehicle.front_weight_fraction
                if axle == "front"
                else 1.0 - vehicle.front_weight_fraction
            )
            sgn = 1.0 if axle == "front" else -1.0
            base = m * ay_tot * share
            iz = vehicle.yaw_inertia
            f_nom = base + sgn * iz * rdot / wb  # the model's force: within its 3 % (§14.1)
            f_a = base + sgn * 0.7 * iz * rdot / wb
            f_b = base + sgn * 1.3 * iz * rdot / wb
            # F_f = (m a_y l_r + I_z ṙ − M)/L, F_r = (m a_y l_f − I_z ṙ + M)/L
            f_lo = np.minimum(f_a, f_b) + np.minimum(-sgn * m_lo, -sgn * m_hi) / wb
            f_hi = np.maximum(f_a, f_b) + np.maximum(-sgn * m_lo, -sgn * m_hi) / wb
            crosses = np.sign(f_lo) != np.sign(f_hi)
            f_min = np.where(crosses, 0.0, np.minimum(np.abs(f_lo), np.abs(f_hi)))
            dfz = m * ax * vehicle.cg_height_m / wb
            # the largest load the longitudinal transfer m a_x h / L (onto the rear, off the
            # front) allows over the declared CG-height range and a_x within its margin: where
            # |a_x| exceeds the margin its sign is known — a car sliding at body slip β has
            # a_x ≈ −a_y tan β > 0, load leaves the front axle (docs/physics.md §14)
            q = ((ax_b if axle == "rear" else -ax_b) if signed else np.abs(ax_b)) + ax_margin
            dfz_hi = m * np.maximum(q * h_lo, q * h_hi) / wb
        else:
            f_nom = mi * ay_tot
            f_min = np.abs(f_nom)
            dfz = np.zeros(t.size)
            dfz_hi = np.zeros(t.size)
        fz_nom = mi * G0 + (dfz if axle == "rear" else -dfz)
        force[axle] = f_nom
        load[axle] = fz_nom
        # (a largest load below a fifth of the static one would say a lifted axle: the floor
        # only lowers the bound)
        grip[axle] = f_min / np.maximum(mi * G0 + dfz_hi, 0.2 * mi * G0)
    # white noise of a_y = U r (+ V̇) per sample, relative to g
    sig_ay = np.hypot(
        np.abs(r) * noise.velocity_mps, np.hypot(u_a, v_a) * np.deg2rad(noise.yaw_rate_dps)
    )
    return force, load, grip, sig_ay / G0


def bin_bound(grip: np.ndarray, sigma: np.ndarray, z: float) -> float:
    """Largest one-sided lower bound over the bins (NaN without bins)."""
    if grip.size == 0:
        return np.nan
    return float(max(np.max(grip - z * sigma), 0.0))


def grip_bins(
    wheels: pd.DataFrame, axle: str, vehicle: Vehicle, noise: NoiseModel, o: WindowOptions
) -> AxleBins:
    """The bins of an axle's measured grip: :func:`~gripsense.estimate.bins.axle_bins` over
    the axle's cornering samples, including those where the load-transfer model lifts a wheel
    (the axle's force over its load needs no wheel load; the model-based estimate leaves them
    out). Only their measured grip (column 9) and its noise are meaningful.
    """
    pairs = axle_pairs(wheels, axle, keep_lifted=True)
    return axle_bins(pairs, axle, vehicle, noise, o.bin_s, o.min_samples, grip="grip_proven")


def drive_bound(ab: AxleBins, level: float) -> tuple[float, float]:
    """Largest bin mean of the measured grip and its bound over all bins of a drive (one-sided,
    Bonferroni over the bins so that the maximum holds at *level*).
    """
    n_b = ab.t0.size
    if n_b == 0:
        return np.nan, np.nan
    z_all = float(norm.ppf(1.0 - (1.0 - level) / n_b))
    return float(np.max(ab.data[:, 9])), bin_bound(ab.data[:, 9], ab.grip_sigma, z_all)


def measured_grip(
    wheels: pd.DataFrame,
    vehicle: Vehicle,
    *,
    noise: NoiseModel | None = None,
    options: WindowOptions | None = None,
) -> pd.DataFrame:
    """The friction each axle used, from measurements alone (``docs/physics.md`` §14).

    The axle's lateral force (m a_y share with the yaw-acceleration term) over its total load
    (statics: known for any lateral load transfer), in bins of ``bin_s``; ``grip_used_lower``
    is the largest bin's one-sided ``bound_level`` lower bound, corrected for the number of bins.
    It holds for any tyre; it assumes a level road without aerodynamic downforce.

    Parameters
    ----------
    wheels : pandas.DataFrame
        Wheel table of :func:`gripsense.estimate.friction.friction_from_motion`.
    vehicle : Vehicle
        Vehicle description.
    noise : NoiseModel, optional
        Measurement noise.
    options : WindowOptions, optional
        Bin length, fewest samples, bound level.

    Returns
    -------
    pandas.DataFrame
        Per axle: ``axle``, ``grip_used`` (largest bin mean) [-], ``grip_used_lower`` [-],
        ``n_bins``.
    """
    noise = noise or NoiseModel()
    o = options or WindowOptions()
    rows = []
    for axle in sorted({w.split("_")[0] for w in wheels["wheel"].astype(str).unique()}):
        ab = grip_bins(wheels, axle, vehicle, noise, o)
        g, lo = drive_bound(ab, o.bound_level)
        rows.append({"axle": axle, "grip_used": g, "grip_used_lower": lo, "n_bins": ab.t0.size})
    return pd.DataFrame(rows, columns=["axle", "grip_used", "grip_used_lower", "n_bins"])
