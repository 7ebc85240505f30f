"""Per-wheel friction μ from a GNSS-compass epoch table during cornering (thesis ch. 4, 6, 10).

The chain, per epoch and wheel (docs/physics.md §11):

1. antenna side-slip β_A = wrap(ψ − ψ₀ − χ) with the heading offset ψ₀ calibrated on straights;
   antenna velocity (U, V) = v (cos β_A, sin β_A); ISO yaw rate r (§3.1);
2. each wheel's velocity U_i = U − r dy_i, V_i = V + r dx_i, slip angle α_i = atan2(V_i, U_i) − δ_i,
   speed and path radius v_i/|r| (§3.1);
3. lateral acceleration of the reference point a_y = U_ref r; static axle masses, the
   steady-state lateral load transfer (§4.2; rigid = the thesis model, §4.3) and, with a
   wheelbase, the longitudinal transfer m a_x h/L (a_x = U̇ − V r) give each wheel's load;
4. contact length from the l–m model (§5), cornering stiffness C = G w l²/2 (eq. 9.1);
5. each wheel carries its load's share of the axle force m_i⁰ a_y (equal friction utilisation on
   both wheels of an axle, the thesis's assumption, §4.4);
6. μ from the brush model of the chosen method (§1.3, §2.3), with κ_β, slide point and a
   first-order σ_μ from the noise model (§1.4);
7. a flag says why μ is not reported: ``low_speed``, ``not_cornering``, ``not_steady``,
   ``no_solution`` (r ≥ 1, or force and slip angle of inconsistent sign), ``full_sliding``,
   ``ill_conditioned`` (σ_μ/μ above ``max_rel_sigma``), else ``ok``.

Why most samples are ``ill_conditioned``: at everyday lateral acceleration the whole difference
between μ = 0.9 and μ = ∞ lies in a few hundredths of a degree of slip angle (§1.4). The
``utilisation`` column, |F|/Fz, is what the data prove in every case: μ ≥ utilisation.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import pandas as pd

from gripsense.config import AXLE_OF, Vehicle
from gripsense.constants import G0
from gripsense.errors import InputError
from gripsense.estimate.noise import NoiseModel
from gripsense.io.nmea.align import align_channels
from gripsense.physics import brush
from gripsense.physics.kinematics import (
    antenna_sideslip,
    heading_offset_from_straight,
    path_radius,
    point_velocity,
    slip_angle,
)
from gripsense.physics.load_transfer import lateral_load_transfer, wheel_loads

__all__ = [
    "FLAGS",
    "METHODS",
    "NOT_STEADY_CORNERING",
    "FrictionOptions",
    "friction_from_motion",
    "motion_from_epochs",
]

# method -> (pressure, model); "brush"/"thesis" take the pressure from the tyre description
METHODS = {
    "thesis-2": ("parabolic", "thesis"),
    "thesis-4": ("quartic", "thesis"),
    "brush-2": ("parabolic", "exact"),
    "brush-4": ("quartic", "exact"),
    "brush": (None, "exact"),
    "thesis": (None, "thesis"),
    "axle-window": (None, "exact"),  # per-sample kinematics here; μ per axle and window in
    # gripsense.estimate.axle_window
}
NOT_STEADY_CORNERING = ("low_speed", "not_cornering", "not_steady")
"""Flags of samples that are not steady cornering: they carry no information on μ and no bound."""
FLAGS = (
    "ok",
    "low_speed",
    "not_cornering",
    "not_steady",
    "no_solution",
    "full_sliding",
    "ill_conditioned",
    "wheel_lifted",
    "per_axle",
)
"""Why a wheel sample has no μ (``ok``: it has one). ``wheel_lifted``: the load-transfer model
puts no load on the wheel; ``per_axle``: an ``axle-window`` sample (μ is in the windows)."""
WHEEL_COLUMNS = [
    "t_s",
    "epoch",
    "wheel",
    "speed_mps",
    "slip_angle_rad",
    "steer_rad",
    "radius_m",
    "mass_kg",
    "contact_length_m",
    "load_N",
    "force_N",
    "slide_point_m",
    "force_ratio",
    "mu",
    "kappa_beta",
    "mu_sigma",
    "flag",
    "lateral_accel_mps2",
    "utilisation",
    "steady",
    "cornering_stiffness_N_per_rad",
    "slip_sigma_rad",
    "force_sigma_N",
    "axle_force_N",
    "axle_load_N",
    "grip_used",
    "grip_sigma",
]


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


_REQUIRED = ("t_s", "heading_deg", "course_deg", "speed_mps", "yaw_rate_rps")


def _steady(t: np.ndarray, speed: np.ndarray, yaw: np.ndarray, o: FrictionOptions) -> np.ndarray:
    """Samples whose centred window has steady speed and yaw rate."""
    if t.size == 0:
        return np.zeros(0, dtype=bool)
    idx = pd.to_timedelta(t - t[0], unit="s")
    df = pd.DataFrame({"v": speed, "r": yaw}, index=idx)
    win = pd.Timedelta(seconds=o.steady_window_s)
    roll = df.rolling(win, center=True, min_periods=3)
    sd = roll.std()
    n = roll.count()["v"].to_numpy()
    return (
        (sd["v"].to_numpy() <= o.steady_speed_std_mps)
        & (sd["r"].to_numpy() <= np.deg2rad(o.steady_yaw_rate_std_dps))
        & (n >= 3)
    )


def _local_slope(y: np.ndarray, t: np.ndarray, half_s: float) -> np.ndarray:
    """dy/dt by a least-squares line over the samples within ±half_s of each sample
    (cumulative sums: O(n)); NaN where fewer than 3 samples fall in the window.
    """
    n = t.size
    if n < 3:
        return np.full(n, np.nan)
    lo = np.searchsorted(t, t - half_s, side="left")
    hi = np.searchsorted(t, t + half_s, side="right")
    tc = t - t[0]
    yy = np.where(np.isfinite(y), y, 0.0)
    ok = np.isfinite(y).astype(float)
    cs = [np.concatenate([[0.0], np.cumsum(a)]) for a in (ok, ok * tc, ok * tc**2, yy, yy * tc)]
    c0, c1, c2, cy, cty = (c[hi] - c[lo] for c in cs)
    den = c0 * c2 - c1**2
    with np.errstate(divide="ignore", invalid="ignore"):
        slope = (c0 * cty - c1 * cy) / den
    return np.where((c0 >= 3) & (den > 0), slope, np.nan)


def _earth_frame_ay(t, speed, course, heading, r, cg) -> np.ndarray:
    """Lateral acceleration of the CG from the velocity differentiated in the earth frame.

    a = d(v_E, v_N)/dt over ±0.5 s at the antenna, projected on the body's y axis with the
    heading, moved to the CG with the rigid-body terms ṙ ẑ × d − r² d (d: antenna → CG).
    Unlike U r + V̇ in body axes, the smoothing here averages a physical acceleration, so its
    magnitude never exceeds what the tyres delivered — also in a spin.
    """
    ve, vn = speed * np.sin(course), speed * np.cos(course)
    ae, an = _local_slope(ve, t, 0.5), _local_slope(vn, t, 0.5)
    ay_ant = -ae * np.cos(heading) + an * np.sin(heading)
    rdot = np.nan_to_num(_local_slope(r, t, 0.5))
    return ay_ant + rdot * cg[0] - r * r * cg[1]


def _axle_grip(vehicle: Vehicle, t, u_a, v_a, r, ay, *, ay_measured, noise, earth=None) -> tuple:
    """Per axle: the lateral force it carries (with the yaw-acceleration term), its nominal
    load, and the friction it used — model-free, ``docs/physics.md`` §14.

    F_front = (m a_y l_r + I_z ṙ)/L, F_rear = (m a_y l_f − I_z ṙ)/L, a_y of the CG from the
    earth-frame velocity (*earth* = (course, heading) known, :func:`_earth_frame_ay`), else
    U r + V̇;
    the grip used is |F| / Fz_axle with the smallest |F| over I_z ± 30 % and the largest axle
    load the longitudinal transfer allows over the declared CG-height range — a lower bound on
    μ for any tyre and any lateral load transfer.
    """
    m = vehicle.mass_kg
    m_ax = dict(zip(("front", "rear"), vehicle.axle_masses_kg, strict=True))
    ok_t = t.size > 2 and bool(np.all(np.diff(t) > 0))
    cg = vehicle.cg_offset
    if ok_t and cg is not None and earth is not None and not np.all(ay_measured):
        ay_e = _earth_frame_ay(t, np.hypot(u_a, v_a), earth[0], earth[1], r, cg)
        ay_tot = np.where(ay_measured | ~np.isfinite(ay_e), ay, ay_e)
    elif ok_t and cg is not None and not np.all(ay_measured):
        v_cg = v_a + r * cg[0]
        vdot = _local_slope(v_cg, t, 0.5)
        ay_tot = np.where(ay_measured, ay, ay + np.nan_to_num(vdot))
    else:
        ay_tot = ay
    rdot = np.nan_to_num(_local_slope(r, t, 0.5)) if ok_t else np.zeros(t.size)
    wb = vehicle.wheelbase_m
    force, load, grip = {}, {}, {}
    ax = np.zeros(t.size)
    if ok_t and cg is not None:
        u_cg = u_a - r * cg[1]
        v_cg = v_a + r * cg[0]
        ax = np.nan_to_num(_local_slope(u_cg, t, 0.5)) - v_cg * r
    h_hi = vehicle.cg_height_range_m[1] if vehicle.cg_height_range_m else vehicle.cg_height_m
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
            f_nom = base + sgn * iz * rdot / wb
            f_lo = base + sgn * 0.7 * iz * rdot / wb
            f_hi = base + sgn * 1.3 * iz * rdot / wb
            crosses = np.sign(f_lo) != np.sign(f_hi)
            f_min = np.where(crosses, 0.0, np.minimum(np.abs(f_lo), np.abs(f_hi)))
            dfz = m * ax * vehicle.cg_height_m / wb
            dfz_hi = m * np.abs(ax) * h_hi / wb
        else:
            f_nom = mi * ay_tot
            f_min = np.abs(f_nom)
            dfz = np.zeros(t.size)
            dfz_hi = np.zeros(t.size)
        fz_nom = mi * G0 + (dfz if axle == "rear" else -dfz)
        force[axle] = f_nom
        load[axle] = fz_nom
        grip[axle] = f_min / (mi * G0 + dfz_hi)
    # white noise of a_y = U r (+ V̇) per sample, relative to g
    sig_ay = np.hypot(
        np.abs(r) * noise.velocity_mps, np.hypot(u_a, v_a) * np.deg2rad(noise.yaw_rate_dps)
    )
    return force, load, grip, sig_ay / G0


def motion_from_epochs(
    epochs: pd.DataFrame,
    vehicle: Vehicle,
    *,
    options: FrictionOptions | None = None,
    steer_rad: np.ndarray | None = None,
) -> tuple[pd.DataFrame, dict]:
    """GNSS-compass epochs -> motion table of the antenna point (body axes).

    The heading offset is calibrated on straight driving (or taken from the vehicle file);
    β_A = wrap(ψ − ψ₀ − χ), (U, V) = v (cos β_A, sin β_A) (docs/physics.md §3.1).

    Parameters
    ----------
    epochs : pandas.DataFrame
        Epoch table of :func:`gripsense.io.read_nmea`.
    vehicle : Vehicle
        Vehicle description (antenna position, heading offset).
    options : FrictionOptions, optional
        Gates and the heading calibration switch.
    steer_rad : numpy.ndarray, optional
        Road-wheel angle per epoch row [rad].

    Returns
    -------
    motion : pandas.DataFrame
        ``t_s``, ``epoch`` (row of *epochs*), ``u_mps``, ``v_mps``, ``yaw_rate_rps``,
        ``ay_mps2`` (NaN: computed from U·r downstream), ``steer_rad`` (NaN without a channel).
    meta : dict
    """
    o = options or FrictionOptions()
    missing = [c for c in _REQUIRED if c not in epochs.columns]
    if missing:
        raise InputError(
            f"epochs: missing columns {missing}; read the log with gripsense.io.read_nmea"
        )
    # course/speed and heading at different rates (OxTS: PASHR 25 Hz, RMC 1 Hz): the course
    # and speed are interpolated onto the heading epochs by the side slip where that is safe
    epochs, alignment = align_channels(epochs)
    have = np.ones(len(epochs), dtype=bool)
    for c in _REQUIRED:
        have &= epochs[c].notna().to_numpy()
    rows = np.flatnonzero(have)
    ep = epochs.iloc[rows]
    ts = ep["t_s"].to_numpy(float)
    ts = ts[np.isfinite(ts)]
    back = np.flatnonzero(np.diff(ts) < 0)
    if back.size:
        raise InputError(
            f"epochs: time goes backwards after t = {ts[back[0]]:.2f} s (to {ts[back[0] + 1]:.2f} s"
            f"; {back.size} such jumps): the log holds several sessions or the receiver clock was"
            " reset; split the log into sessions (gripsense live restarts its window instead)"
        )
    psi = np.deg2rad(ep["heading_deg"].to_numpy(float))
    chi = np.deg2rad(ep["course_deg"].to_numpy(float))
    v = ep["speed_mps"].to_numpy(float)
    r = ep["yaw_rate_rps"].to_numpy(float)
    meta: dict = {
        "vehicle": vehicle.name,
        "epochs_total": len(epochs),
        "epochs_used": int(rows.size),
        "epochs_missing_inputs": int(len(epochs) - rows.size),
        "epochs_aligned": alignment.n_aligned,
    }
    offset = vehicle.heading_offset_rad
    meta["heading_offset_source"] = "vehicle file"
    if o.calibrate_heading:
        cal, n_straight, spread = heading_offset_from_straight(psi, chi, r, v)
        meta["straight_samples"] = n_straight
        if np.isfinite(cal):
            offset = cal
            meta["heading_offset_source"] = f"straight driving ({n_straight} samples)"
            meta["heading_offset_spread_deg"] = float(np.rad2deg(spread))
    meta["heading_offset_deg"] = float(np.rad2deg(offset))
    beta_a = antenna_sideslip(psi, chi, offset)
    steer = (
        np.full(rows.size, np.nan)
        if steer_rad is None
        else np.asarray(steer_rad, dtype=float)[rows]
    )
    motion = pd.DataFrame(
        {
            "t_s": ep["t_s"].to_numpy(float),
            "epoch": rows,
            "u_mps": v * np.cos(beta_a),
            "v_mps": v * np.sin(beta_a),
            "yaw_rate_rps": r,
            "ay_mps2": np.full(rows.size, np.nan),
            "steer_rad": steer,
            # the velocity direction and the vehicle's heading (clockwise from north): the
            # model-free grip differentiates the velocity in the earth frame (_axle_grip)
            "course_rad": chi,
            "heading_rad": psi - offset,
        }
    )
    return motion, meta


def friction_from_motion(
    motion: pd.DataFrame,
    vehicle: Vehicle,
    *,
    method: str = "brush-2",
    options: FrictionOptions | None = None,
) -> tuple[pd.DataFrame, dict]:
    """μ per wheel and sample from a motion table of the measurement point (body axes).

    Parameters
    ----------
    motion : pandas.DataFrame
        ``t_s``, ``epoch``, ``u_mps``, ``v_mps`` (body velocity of the measurement point — the
        antenna of the vehicle file), ``yaw_rate_rps`` (ISO), ``ay_mps2`` (measured lateral
        acceleration of the CG, or NaN: then U·r of the reference point), ``steer_rad``
        (road-wheel angle or NaN).
    vehicle : Vehicle
        Vehicle description.
    method : str
        A key of :data:`METHODS`: ``brush-2`` (default), ``brush-4``, ``thesis-2``
        (eq. 4.15), ``thesis-4`` (ch. 10), ``brush``/``thesis`` (pressure shape from the tyre
        description) or ``axle-window`` (per-sample kinematics for the window estimator).
    options : FrictionOptions
        Gates and the noise model.

    Returns
    -------
    wheels : pandas.DataFrame
        One row per wheel and usable sample (columns :data:`WHEEL_COLUMNS`); ``mu`` is NaN
        unless ``flag == "ok"``.
    meta : dict
        Method, wheels analysed, and notes on wheels left out.
    """
    if method not in METHODS:
        raise InputError(f"method={method!r}; use one of {sorted(METHODS)}")
    o = options or FrictionOptions()
    meta: dict = {"method": method}
    t = motion["t_s"].to_numpy(float)
    rows = motion["epoch"].to_numpy()
    u_a = motion["u_mps"].to_numpy(float)
    v_a = motion["v_mps"].to_numpy(float)
    r = motion["yaw_rate_rps"].to_numpy(float)
    v = np.hypot(u_a, v_a)
    st = motion["steer_rad"].to_numpy(float)
    steer = None if np.isnan(st).all() else st
    # reference point for a_y: the CG if known, else the middle of the known wheels (lateral)
    if vehicle.cg_offset is not None:
        dy_ref = vehicle.cg_offset[1]
    else:
        dy_ref = float(np.mean([o_[1] for o_ in vehicle.wheel_offsets.values()]))
    ay_meas = motion["ay_mps2"].to_numpy(float)
    ay = np.where(np.isfinite(ay_meas), ay_meas, (u_a - r * dy_ref) * r)
    steady = _steady(t, v, r, o)
    # quasi-static longitudinal load transfer m a_x h / L (needs the wheelbase): in a steady
    # turn the body-axis a_x = U̇ − V r is not zero, because the CG moves sideways (V ≠ 0)
    dfz_x = np.zeros(t.size)
    if vehicle.wheelbase_m is not None and vehicle.cg_offset is not None and t.size > 1:
        u_cg = u_a - r * vehicle.cg_offset[1]
        v_cg = v_a + r * vehicle.cg_offset[0]
        ax = np.gradient(u_cg, t) - v_cg * r if np.all(np.diff(t) > 0) else -v_cg * r
        dfz_x = vehicle.mass_kg * ax * vehicle.cg_height_m / vehicle.wheelbase_m / 2.0
    m_axle = dict(zip(("front", "rear"), vehicle.axle_masses_kg, strict=True))
    dfz = dict(
        zip(
            ("front", "rear"),
            lateral_load_transfer(
                ay,
                vehicle.mass_kg,
                vehicle.cg_height_m,
                vehicle.axle_masses_kg,
                (vehicle.track_front_m, vehicle.track_rear_m),
                vehicle.roll_centre_heights_m,
                vehicle.roll_stiffness_front_fraction,
                np.deg2rad(vehicle.roll_gradient_deg_per_g),
            ),
            strict=True,
        )
    )

    earth = None
    if "course_rad" in motion.columns and "heading_rad" in motion.columns:
        earth = (motion["course_rad"].to_numpy(float), motion["heading_rad"].to_numpy(float))
    axle_force, axle_load, grip, grip_sig = _axle_grip(
        vehicle, t, u_a, v_a, r, ay, ay_measured=np.isfinite(ay_meas), noise=o.noise, earth=earth
    )

    nz = o.noise
    sig_v_rel = nz.velocity_mps / np.maximum(v, 1e-9)
    sig_r = np.deg2rad(nz.yaw_rate_dps)
    with np.errstate(divide="ignore", invalid="ignore"):
        sig_f_rel = np.sqrt(sig_v_rel**2 + (sig_r / np.abs(r)) ** 2)

    wheels_done, frames = [], []
    for wname, (dx, dy) in vehicle.wheel_offsets.items():
        axle = AXLE_OF[wname]
        if axle == "front" and steer is None:
            continue
        tyre = vehicle.tyres[axle]
        pressure, model = METHODS[method]
        pressure = pressure or tyre.pressure
        delta = steer if axle == "front" else 0.0
        u_i, v_i = point_velocity(u_a, v_a, r, dx, dy)
        alpha = slip_angle(u_i, v_i, delta)
        spd = np.hypot(u_i, v_i)
        radius = path_radius(spd, r)
        left, right = wheel_loads(m_axle[axle], dfz[axle])
        fz = (left if wname.endswith("left") else right) + (dfz_x if axle == "rear" else -dfz_x)
        mass = fz / G0
        length = tyre.contact_length(mass)
        c = vehicle.cornering_stiffness(axle, fz)
        force = mass * ay  # the wheel's load share of the axle force m⁰ a_y
        inv = brush.invert(force, alpha, fz, c, pressure=pressure, model=model)
        mu_raw, status, kap = inv["mu"], inv["status"], inv["kappa_beta"]
        # first-order uncertainty (docs/physics.md §1.4): T ∝ C tanβ, κ_F = 1 − κ_β
        sig_alpha = np.sqrt(
            np.deg2rad(nz.heading_deg) ** 2
            + sig_v_rel**2
            + (sig_r * dx / np.maximum(np.abs(u_i), 1e-9)) ** 2
        )
        with np.errstate(divide="ignore", invalid="ignore"):
            sig_tan_rel = sig_alpha / np.abs(np.sin(alpha) * np.cos(alpha))
        sig_c_rel = np.hypot(
            nz.tread_stiffness_rel,
            2.0 * nz.contact_length_rel if tyre.cornering_stiffness_N_per_rad is None else 0.0,
        )
        with np.errstate(invalid="ignore"):
            rel = np.sqrt(
                kap**2 * (sig_tan_rel**2 + sig_c_rel**2) + (1.0 - kap) ** 2 * sig_f_rel**2
            )
            mu_sigma = mu_raw * rel

        sig_alpha_white = np.sqrt(
            np.deg2rad(nz.heading_white_deg) ** 2
            + sig_v_rel**2
            + (sig_r * dx / np.maximum(np.abs(u_i), 1e-9)) ** 2
        )
        with np.errstate(invalid="ignore"):
            force_sigma = np.abs(force) * sig_f_rel
        with np.errstate(divide="ignore", invalid="ignore"):
            utilisation = np.where(fz > 0, np.abs(force) / fz, np.nan)
        flag = np.zeros(t.size, dtype=np.int8)  # codes of FLAGS: 0 = "ok"
        sign_bad = force * alpha > 0  # ISO: F ≈ −C α
        conds = [
            ("ill_conditioned", ~(rel <= o.max_rel_sigma)),
            ("full_sliding", status == brush.FULL_SLIDING),
            ("no_solution", (status == brush.NO_SOLUTION) | (status == brush.INVALID) | sign_bad),
            ("wheel_lifted", ~(fz > 0)),
            ("not_steady", ~steady),
            (
                "not_cornering",
                (np.abs(ay) < o.min_lateral_accel_mps2)
                | (np.abs(r) < np.deg2rad(o.min_yaw_rate_dps)),
            ),
            ("low_speed", (spd < o.min_speed_mps) | np.isnan(alpha)),
        ]
        for name, m in conds:  # later entries take precedence
            flag[m] = FLAGS.index(name)
        ok = flag == 0
        frames.append(
            {
                "t_s": t,
                "epoch": rows,
                "wheel": np.full(t.size, list(vehicle.wheel_offsets).index(wname), np.int8),
                "speed_mps": spd,
                "slip_angle_rad": alpha,
                "steer_rad": np.broadcast_to(delta, t.shape).astype(float),
                "radius_m": radius,
                "mass_kg": mass,
                "contact_length_m": length,
                "load_N": fz,
                "force_N": force,
                "slide_point_m": inv["xi"] * length,
                "force_ratio": inv["ratio"],
                "mu": np.where(ok, mu_raw, np.nan),
                "kappa_beta": kap,
                "mu_sigma": np.where(ok, mu_sigma, np.nan),
                "flag": flag,
                "lateral_accel_mps2": ay,
                "utilisation": utilisation,
                "steady": steady,
                "cornering_stiffness_N_per_rad": c,
                "slip_sigma_rad": sig_alpha_white,
                "force_sigma_N": force_sigma,
                "axle_force_N": axle_force[axle],
                "axle_load_N": axle_load[axle],
                "grip_used": grip[axle],
                "grip_sigma": grip_sig,
            }
        )
        wheels_done.append(wname)
    meta["wheels"] = wheels_done
    if not wheels_done:
        meta["note"] = "no wheel could be analysed (front wheels need a steering channel)"
    if steer is None and any(AXLE_OF[w] == "front" for w in vehicle.wheel_offsets):
        meta["front_wheels"] = "skipped: no steering channel (--steer-csv)"
    if not frames:
        wheels = pd.DataFrame({c: [] for c in WHEEL_COLUMNS})
        wheels["wheel"] = pd.Categorical(wheels["wheel"], categories=list(vehicle.wheel_offsets))
        wheels["flag"] = pd.Categorical(wheels["flag"], categories=list(FLAGS))
        return wheels[WHEEL_COLUMNS], meta
    # one table from the wheels' columns (one DataFrame, categories from their codes: the
    # per-wheel frames, their concatenation and the string → category conversion cost ~4 ms
    # of a 75 s log)
    cols = {
        c: np.concatenate([np.broadcast_to(f[c], f["t_s"].shape) for f in frames])
        for c in WHEEL_COLUMNS
    }
    cols["wheel"] = pd.Categorical.from_codes(cols["wheel"], categories=list(vehicle.wheel_offsets))
    cols["flag"] = pd.Categorical.from_codes(cols["flag"], categories=list(FLAGS))
    return pd.DataFrame(cols), meta
