"""Planar two-track vehicle model with brush or tabulated (Magic Formula, PAC89) tyres, load
transfer, roll-induced camber and friction patches.

States: world position X, Y (east, north) [m], yaw ψ (counter-clockwise from east) [rad], body
velocities U, V [m/s], yaw rate r [rad/s], and, with a relaxation length, the four lateral tyre
forces (first-order lag, seed 003 eq. 4 / docs/physics.md §9.1: (σ/U) Ḟ + F = F_ss).

Forces (ISO 8855 body axes):

* tyre lateral force from the exact brush model of :mod:`gripsense.physics.brush` (parabolic or
  quartic pressure), with the local road μ, the wheel's load and C = G w l(m)²/2;
  a driven or braked wheel keeps the lateral friction left by its longitudinal force,
  μ_y = √(μ² − (F_x/F_z)²) (friction circle);
* or, per axle, a tyre from a file (:mod:`gripsense.sim.tyres`: Magic Formula ``.tir`` or
  PAC89) with its own load dependence and camber thrust, scaled to the road μ by similarity;
  the wheels lean with the body: inclination γ = k_γ φ, roll φ = (dφ/da_y) a_y (the vehicle
  file's ``roll_gradient_deg_per_g`` and ``roll_camber_gain``), the same for all four wheels;
* locked wheels (straight braking) slide: F = −μ F_z along the wheel's velocity;
* quasi-static loads: longitudinal transfer m a_x h / L and the steady-state lateral transfer of
  docs/physics.md §4.2 (roll-stiffness split and roll-centre heights) with the body's roll
  φ = (dφ/da_y) a_y moving the CG sideways (roll moment m (h − h_ra)(a_y + g φ)), from the
  previous step's accelerations; no aerodynamic drag, no rolling resistance.

Equations: m(U̇ − V r) = ΣF_x, m(V̇ + U r) = ΣF_y, I_z ṙ = Σ(x_i F_y,i − y_i F_x,i).
Integration: fixed-step RK4 (default 2 ms) in one compiled loop; controllers are evaluated once
per step.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np
import pandas as pd
from numba import njit

from gripsense.config import Vehicle
from gripsense.constants import G0
from gripsense.errors import InputError
from gripsense.physics.brush import force_scalar

__all__ = ["SimParams", "SimResult", "simulate"]

WHEEL_NAMES = ("front_left", "front_right", "rear_left", "rear_right")
DRIVES = {"front": 0, "rear": 1, "all": 2}


@dataclass(frozen=True)
class SimParams:
    """Parameters of the simulated vehicle (SI).

    Built from a :class:`~gripsense.config.Vehicle` with :meth:`from_vehicle`; the vehicle needs
    a wheelbase and G-or-C tyres for both axles.

    Attributes
    ----------
    mass_kg : float
        Mass [kg].
    yaw_inertia_kgm2 : float
        Yaw inertia [kg m^2].
    l_f : float
        CG to front axle [m].
    l_r : float
        CG to rear axle [m].
    cg_height_m : float
        CG height [m].
    track_front_m : float
        Front track [m].
    track_rear_m : float
        Rear track [m].
    roll_front_fraction : float
        Front share of the roll stiffness [-].
    roll_centre_heights_m : tuple of float
        Front and rear roll-centre heights [m].
    tyres : dict
        Axle → :class:`~gripsense.config.Tyre`.
    relaxation_length_m : float
        Tyre relaxation length (0: no lag) [m].
    drive : str
        Driven axle: ``front``, ``rear`` or ``all``.
    pressure : str
        Pressure shape of the brush tyres.
    sim_tyres : dict
        Axle → :class:`~gripsense.sim.tyres.SimTyre` for axles whose tyres come from a file
        (others are brush tyres).
    roll_gradient_rad_per_g : float
        Body roll per g of lateral acceleration [rad].
    roll_camber_gain : float
        Wheel inclination per radian of body roll [-].
    """

    mass_kg: float
    yaw_inertia_kgm2: float
    l_f: float
    l_r: float
    cg_height_m: float
    track_front_m: float
    track_rear_m: float
    roll_front_fraction: float
    roll_centre_heights_m: tuple[float, float]
    tyres: dict  # axle -> gripsense.config.Tyre
    relaxation_length_m: float = 0.0
    drive: str = "rear"
    pressure: str = "parabolic"
    sim_tyres: dict = field(default_factory=dict)
    roll_gradient_rad_per_g: float = 0.0
    roll_camber_gain: float = 0.0

    @classmethod
    def from_vehicle(
        cls,
        v: Vehicle,
        *,
        yaw_inertia_kgm2: float | None = None,
        relaxation_length_m: float = 0.0,
        drive: str | None = None,
        sim_tyres: dict | None = None,
    ) -> SimParams:
        """Simulation parameters from a vehicle description.

        The yaw inertia defaults to m·l_f·l_r (a common estimate: radius of gyration² ≈ l_f l_r).

        Parameters
        ----------
        v : Vehicle
            Vehicle description (needs a wheelbase).
        yaw_inertia_kgm2 : float, optional
            Yaw inertia [kg m^2]; default m l_f l_r.
        relaxation_length_m : float
            Tyre relaxation length [m].
        drive : str, optional
            Driven axle (default the vehicle file's ``drive``, else ``front``).
        sim_tyres : dict, optional
            Axle → :class:`~gripsense.sim.tyres.SimTyre` (tyres from files; others brush).
        """
        if v.wheelbase_m is None:
            raise InputError(f"{v.source}: [vehicle] wheelbase_m is needed to simulate")
        for axle in ("front", "rear"):
            if axle not in v.tyres:
                raise InputError(f"{v.source}: [tyre.{axle}] is needed to simulate")
        drive = drive or v.drive or "front"
        if drive not in DRIVES:
            raise InputError(f"drive={drive!r}; use one of {sorted(DRIVES)}")
        L = v.wheelbase_m
        l_f = L * (1.0 - v.front_weight_fraction)
        l_r = L - l_f
        kf = (
            v.roll_stiffness_front_fraction
            if v.roll_stiffness_front_fraction is not None
            else v.front_weight_fraction
        )
        rc = v.roll_centre_heights_m or (v.cg_height_m, v.cg_height_m)
        pressures = {t.pressure for t in v.tyres.values()}
        return cls(
            mass_kg=v.mass_kg,
            yaw_inertia_kgm2=yaw_inertia_kgm2 or v.yaw_inertia,
            l_f=l_f,
            l_r=l_r,
            cg_height_m=v.cg_height_m,
            track_front_m=v.track_front_m,
            track_rear_m=v.track_rear_m,
            roll_front_fraction=kf,
            roll_centre_heights_m=tuple(rc),
            tyres=dict(v.tyres),
            relaxation_length_m=relaxation_length_m,
            drive=drive,
            pressure="quartic" if pressures == {"quartic"} else "parabolic",
            sim_tyres=dict(sim_tyres or {}),
            roll_gradient_rad_per_g=np.deg2rad(v.roll_gradient_deg_per_g),
            roll_camber_gain=v.roll_camber_gain,
        )

    @property
    def wheel_positions(self) -> np.ndarray:
        """(4, 2) wheel positions relative to the CG, x forward, y left [m] (FL, FR, RL, RR)."""
        tf, tr = self.track_front_m / 2, self.track_rear_m / 2
        return np.array([[self.l_f, tf], [self.l_f, -tf], [-self.l_r, tr], [-self.l_r, -tr]])

    def _packed(self) -> np.ndarray:
        """Parameters as one float array for the compiled core."""
        m = self.mass_kg
        mf = m * self.l_r / (self.l_f + self.l_r)
        mr = m - mf
        hf, hr = self.roll_centre_heights_m
        tyre_cols = []
        for axle in ("front", "rear"):
            t = self.tyres[axle]
            fixed_c = t.cornering_stiffness_N_per_rad if t.cornering_stiffness_N_per_rad else -1.0
            tyre_cols += [
                t.width_m,
                t.tread_stiffness_N_per_m3 or 0.0,
                fixed_c,
                t.contact_a if t.contact_a is not None else 0.0,
                t.contact_b if t.contact_b is not None else 0.0,
                t.contact_length_m if t.contact_length_m is not None else -1.0,
            ]
        return np.array(
            [
                m,
                self.yaw_inertia_kgm2,
                self.l_f,
                self.l_r,
                self.cg_height_m,
                self.track_front_m,
                self.track_rear_m,
                self.roll_front_fraction,
                hf,
                hr,
                mf,
                mr,
                self.relaxation_length_m,
                DRIVES[self.drive],
                0.0 if self.pressure == "parabolic" else 2.0,
                *tyre_cols,
                self.roll_gradient_rad_per_g,
                self.roll_camber_gain,
            ]
        )

    def _tables(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """Tyre tables for the compiled core: front and rear F_0, their peaks, and per axle
        (kind, grid description); a brush axle gets a 2×2×2 dummy table.
        """
        tabs, peaks = [], []
        ax = np.zeros((2, 8))
        for k, axle in enumerate(("front", "rear")):
            t = self.sim_tyres.get(axle)
            if t is None:
                tabs.append(np.zeros((2, 2, 2)))
                peaks.append(np.zeros((2, 2, 2)))
            else:
                tabs.append(np.ascontiguousarray(t.fy))
                peaks.append(np.ascontiguousarray(t.peak))
                ax[k, 0] = 1.0
                ax[k, 1:] = t.axes()
        return tabs[0], tabs[1], peaks[0], peaks[1], ax


@dataclass
class SimResult:
    """Simulated drive.

    Attributes
    ----------
    body : pandas.DataFrame
        At the output rate: ``t_s``, ``x_m``, ``y_m`` (east, north), ``yaw_rad``, ``u_mps``,
        ``v_mps``, ``yaw_rate_rps``, ``ax_mps2``, ``ay_mps2`` (body-axis accelerations),
        ``steer_rad`` (road-wheel angle, front), ``fx_N`` (total longitudinal tyre force).
    wheels : pandas.DataFrame
        Long table per output time and wheel: ``t_s``, ``wheel``, ``mu_true`` (the wheel's
        peak friction at its load and inclination, in the direction of its force: the road μ for
        a brush tyre), ``mu_road`` (road μ at the wheel), ``camber_rad`` (inclination, ISO),
        ``slip_angle_rad``, ``load_N``, ``force_N`` (lateral, wheel axes, ISO sign),
        ``speed_mps``.
    params : SimParams
    wall_s : float
        Wall-clock time of the integration [s].
    meta : dict
        Notes on the run (manoeuvre, tyre models).
    """

    body: pd.DataFrame
    wheels: pd.DataFrame
    params: SimParams
    wall_s: float = 0.0
    meta: dict = field(default_factory=dict)

    @property
    def realtime_factor(self) -> float:
        """Simulated seconds per wall-clock second."""
        dur = float(self.body["t_s"].iloc[-1] - self.body["t_s"].iloc[0]) if len(self.body) else 0
        return dur / self.wall_s if self.wall_s > 0 else float("inf")


# ---- compiled core -----------------------------------------------------------------------
# controller array layout (see maneuvers.py, which fills it)
C_STEER_MODE, C_CX, C_CY, C_R, C_DIR, C_LOOK = 0, 1, 2, 3, 4, 5
C_SPEED_MODE, C_V, C_KP, C_FXMAX, C_T_BRAKE, C_RATIO, C_T_LEAD = 6, 7, 8, 9, 10, 11, 12
C_ACCEL = 13  # speed ramp [m/s²] (SPEED_RAMP, from C_T_BRAKE on)
N_CTRL = 14
STEER_TABLE, STEER_CIRCLE, STEER_LINE = 0, 1, 2
SPEED_HOLD, SPEED_FREE, SPEED_BRAKE_LOCK, SPEED_RAMP = 0, 1, 2, 3


@njit(cache=True, nogil=True)
def _road_mu(x, y, mu0, patches):
    mu = mu0
    for k in range(patches.shape[0]):
        if patches[k, 0] <= x <= patches[k, 1] and patches[k, 2] <= y <= patches[k, 3]:
            mu = patches[k, 4]
    return mu


@njit(cache=True, nogil=True)
def _tyre_c(p, axle, mass):
    base = 15 + 6 * axle
    w, g, fixed_c, a, b, fixed_l = (
        p[base],
        p[base + 1],
        p[base + 2],
        p[base + 3],
        p[base + 4],
        p[base + 5],
    )
    if fixed_c > 0:
        return fixed_c
    if fixed_l > 0:
        length = fixed_l
    else:
        length = a * np.sqrt(max(mass, 0.0)) + b * mass
    return 0.5 * g * w * length * length


@njit(cache=True, nogil=True)
def _cell(v, v0, dv, n):
    x = min(max((v - v0) / dv, 0.0), n - 1.000001)
    i = int(x)
    return i, x - i


@njit(cache=True, nogil=True)
def tab_force(tab, ax, alpha, fz, gamma):
    """Trilinear interpolation of F_0(α, Fz, γ) (:mod:`gripsense.sim.tyres`)."""
    i, u = _cell(alpha, ax[1], ax[2], tab.shape[0])
    j, v = _cell(fz, ax[3], ax[4], tab.shape[1])
    k, w = _cell(gamma, ax[5], ax[6], tab.shape[2])
    out = 0.0
    for di in range(2):
        wi = u if di else 1.0 - u
        for dj in range(2):
            wj = v if dj else 1.0 - v
            for dk in range(2):
                wk = w if dk else 1.0 - w
                out += wi * wj * wk * tab[i + di, j + dj, k + dk]
    return out


@njit(cache=True, nogil=True)
def _tab_peak(peak, ax, fz, gamma, side):
    """Peak ±F_0/Fz at a load and inclination (bilinear)."""
    j, v = _cell(fz, ax[3], ax[4], peak.shape[0])
    k, w = _cell(gamma, ax[5], ax[6], peak.shape[1])
    return (
        (1 - v) * (1 - w) * peak[j, k, side]
        + v * (1 - w) * peak[j + 1, k, side]
        + (1 - v) * w * peak[j, k + 1, side]
        + v * w * peak[j + 1, k + 1, side]
    )


@njit(cache=True, nogil=True)
def _deriv(s, p, wpos, delta, fx_total, lock, ax_prev, ay_prev, mu0, patches, tabs, out_w):
    """State derivative; out_w[i] = (alpha, Fz, Fy_wheel, μ peak, speed, Fy_ss, γ, μ road)."""
    tab_f, tab_r, peak_f, peak_r, tax = tabs
    m, iz, lf, lr, h = p[0], p[1], p[2], p[3], p[4]
    tf, tr, kf, hf, hr, mf, mr, sigma = p[5], p[6], p[7], p[8], p[9], p[10], p[11], p[12]
    drive, which = int(p[13]), int(p[14])
    X, Y, psi, U, V, r = s[0], s[1], s[2], s[3], s[4], s[5]
    L = lf + lr
    # quasi-static loads (docs/physics.md §4.2) from the previous step's accelerations
    h_ra = (mf * hf + mr * hr) / m
    arm = m * (h - h_ra)
    # the body rolls by φ = (dφ/da_y) a_y, which also moves the CG sideways: the roll moment is
    # m (h − h_ra)(a_y + g φ) (docs/physics.md §4.2)
    ay_roll = ay_prev * (1.0 + p[27])
    dfz_f = (ay_prev * mf * hf + kf * arm * ay_roll) / tf
    dfz_r = (ay_prev * mr * hr + (1.0 - kf) * arm * ay_roll) / tr
    dfx = m * ax_prev * h / L / 2.0
    # the wheels lean with the body (quasi-static roll, same inclination for all four)
    gamma = p[28] * p[27] * ay_prev / G0
    fz = np.empty(4)
    fz[0] = mf * G0 / 2 - dfz_f - dfx
    fz[1] = mf * G0 / 2 + dfz_f - dfx
    fz[2] = mr * G0 / 2 - dfz_r + dfx
    fz[3] = mr * G0 / 2 + dfz_r + dfx
    # driving force per wheel (wheel axes)
    fxw = np.zeros(4)
    if lock == 0:
        if drive == 0:
            fxw[0] = fx_total / 2
            fxw[1] = fx_total / 2
        elif drive == 1:
            fxw[2] = fx_total / 2
            fxw[3] = fx_total / 2
        else:
            for i in range(4):
                fxw[i] = fx_total / 4
    sfx = 0.0
    sfy = 0.0
    mz = 0.0
    ds = np.zeros(s.size)
    cpsi, spsi = np.cos(psi), np.sin(psi)
    for i in range(4):
        xi, yi = wpos[i, 0], wpos[i, 1]
        d = delta if i < 2 else 0.0
        ui = U - r * yi
        vi = V + r * xi
        cd, sd = np.cos(d), np.sin(d)
        uw = ui * cd + vi * sd
        vw = -ui * sd + vi * cd
        alpha = np.arctan2(vw, uw) if (uw != 0.0 or vw != 0.0) else 0.0
        wx = X + xi * cpsi - yi * spsi
        wy = Y + xi * spsi + yi * cpsi
        mu = _road_mu(wx, wy, mu0, patches)
        load = max(fz[i], 0.0)
        speed = np.sqrt(uw * uw + vw * vw)
        mu_peak = mu
        if lock == 1:
            if speed > 1e-6:
                fxi = -mu * load * uw / speed
                fy_ss = -mu * load * vw / speed
            else:
                fxi = 0.0
                fy_ss = 0.0
        else:
            fxi = fxw[i]
            if load > 0:
                fxi = max(min(fxi, mu * load), -mu * load)
                mu_y = np.sqrt(max(mu * mu - (fxi / load) ** 2, 0.0))
            else:
                fxi = 0.0
                mu_y = 0.0
            axle = 0 if i < 2 else 1
            if tax[axle, 0] > 0:
                # tyre from a file: similarity scaling to the road (and friction-circle) μ
                lam = mu_y / tax[axle, 7]
                tab = tab_f if axle == 0 else tab_r
                if lam > 1e-6 and load > 0:
                    fy_ss = lam * tab_force(tab, tax[axle], alpha / lam, load, gamma)
                else:
                    fy_ss = 0.0
                pk = peak_f if axle == 0 else peak_r
                side = 0 if fy_ss >= 0 else 1
                mu_peak = mu / tax[axle, 7] * _tab_peak(pk, tax[axle], load, gamma, side)
            else:
                c = _tyre_c(p, axle, load / G0)
                mag = force_scalar(mu_y, np.tan(alpha) if abs(alpha) < 1.5 else 1e3, load, c, which)
                fy_ss = -mag if alpha > 0 else mag
                if alpha == 0.0:
                    fy_ss = 0.0
        if sigma > 0 and lock == 0:
            fyw = s[6 + i]
            ds[6 + i] = abs(uw) / sigma * (fy_ss - fyw)
        else:
            fyw = fy_ss
        fxb = fxi * cd - fyw * sd
        fyb = fxi * sd + fyw * cd
        sfx += fxb
        sfy += fyb
        mz += xi * fyb - yi * fxb
        out_w[i, 0] = alpha
        out_w[i, 1] = load
        out_w[i, 2] = fyw
        out_w[i, 3] = mu_peak
        out_w[i, 4] = speed
        out_w[i, 5] = fy_ss
        out_w[i, 6] = gamma
        out_w[i, 7] = mu
    ds[0] = U * cpsi - V * spsi
    ds[1] = U * spsi + V * cpsi
    ds[2] = r
    ds[3] = sfx / m + V * r
    ds[4] = sfy / m - U * r
    ds[5] = mz / iz
    return ds


@njit(cache=True, nogil=True)
def _controls(t, s, ctrl, steer_t, steer_v, lf, lr):
    """Steering (road-wheel angle) and longitudinal force command; lock flag."""
    X, Y, psi, U = s[0], s[1], s[2], s[3]
    mode = int(ctrl[C_STEER_MODE])
    if mode == STEER_TABLE:
        delta = np.interp(t, steer_t, steer_v)
    else:
        # pure pursuit (rear-axle reference) towards a look-ahead point on the path
        rx = X - lr * np.cos(psi)
        ry = Y - lr * np.sin(psi)
        look = max(ctrl[C_LOOK], 1.0)
        if mode == STEER_CIRCLE and t < ctrl[C_T_LEAD]:
            mode = STEER_LINE  # straight lead-in along +x through the origin
        if mode == STEER_CIRCLE:
            cx, cy, R, sgn = ctrl[C_CX], ctrl[C_CY], ctrl[C_R], ctrl[C_DIR]
            ang = np.arctan2(ry - cy, rx - cx) + sgn * look / R
            tx, ty = cx + R * np.cos(ang), cy + R * np.sin(ang)
        elif int(ctrl[C_STEER_MODE]) == STEER_CIRCLE:  # lead-in line y = 0
            tx, ty = rx + look, 0.0
        else:  # straight line through (cx, cy) with direction angle ctrl[C_R]
            dirn = ctrl[C_R]
            along = (rx - ctrl[C_CX]) * np.cos(dirn) + (ry - ctrl[C_CY]) * np.sin(dirn) + look
            tx, ty = ctrl[C_CX] + along * np.cos(dirn), ctrl[C_CY] + along * np.sin(dirn)
        eta = np.arctan2(ty - ry, tx - rx) - psi
        eta = (eta + np.pi) % (2 * np.pi) - np.pi
        ld = max(np.hypot(tx - rx, ty - ry), 0.5)
        delta = np.arctan2(2.0 * (lf + lr) * np.sin(eta), ld)
        delta = max(min(delta, 0.6), -0.6)
    smode = int(ctrl[C_SPEED_MODE])
    lock = 0
    fx = 0.0
    if smode == SPEED_BRAKE_LOCK and t >= ctrl[C_T_BRAKE]:
        lock = 1
    elif smode == SPEED_HOLD or smode == SPEED_BRAKE_LOCK:
        fx = ctrl[C_KP] * (ctrl[C_V] - U)
        fx = max(min(fx, ctrl[C_FXMAX]), -ctrl[C_FXMAX])
    elif smode == SPEED_RAMP:  # ISO 4138 constant radius: the speed raised slowly
        v_t = ctrl[C_V] + ctrl[C_ACCEL] * max(t - ctrl[C_T_BRAKE], 0.0)
        fx = ctrl[C_KP] * (v_t - U)
        fx = max(min(fx, ctrl[C_FXMAX]), -ctrl[C_FXMAX])
    return delta, fx, lock


@njit(cache=True, nogil=True)
def _integrate(
    s0, p, wpos, ctrl, steer_t, steer_v, mu0, patches, tabs, dt, n_steps, every, out_body, out_wheel
):
    s = s0.copy()
    n_state = s.size
    ow = np.empty((4, 8))
    ax_prev = 0.0
    ay_prev = s[5] * s[3]
    k_out = 0
    for n in range(n_steps + 1):
        t = n * dt
        delta, fx, lock = _controls(t, s, ctrl, steer_t, steer_v, p[2], p[3])
        k1 = _deriv(s, p, wpos, delta, fx, lock, ax_prev, ay_prev, mu0, patches, tabs, ow)
        if n % every == 0 and k_out < out_body.shape[0]:
            out_body[k_out, 0] = t
            for j in range(6):
                out_body[k_out, 1 + j] = s[j]
            ax = k1[3] - s[4] * s[5]
            ay = k1[4] + s[3] * s[5]
            out_body[k_out, 7] = ax
            out_body[k_out, 8] = ay
            out_body[k_out, 9] = delta
            out_body[k_out, 10] = fx
            for i in range(4):
                for j in range(8):
                    out_wheel[k_out, i, j] = ow[i, j]
            k_out += 1
        if n == n_steps:
            break
        s2 = s + 0.5 * dt * k1
        k2 = _deriv(s2, p, wpos, delta, fx, lock, ax_prev, ay_prev, mu0, patches, tabs, ow)
        s3 = s + 0.5 * dt * k2
        k3 = _deriv(s3, p, wpos, delta, fx, lock, ax_prev, ay_prev, mu0, patches, tabs, ow)
        s4 = s + dt * k3
        k4 = _deriv(s4, p, wpos, delta, fx, lock, ax_prev, ay_prev, mu0, patches, tabs, ow)
        s = s + dt / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4)
        ax_prev = k1[3] - s[4] * s[5]
        ay_prev = k1[4] + s[3] * s[5]
        if lock == 1 and s[3] < 0.05:  # stopped
            s[3] = 0.0
            s[4] = 0.0
            s[5] = 0.0
        for j in range(n_state):
            if not np.isfinite(s[j]):
                return k_out
    return k_out


def simulate(
    params: SimParams,
    controller: np.ndarray,
    duration_s: float,
    *,
    mu: float = 0.9,
    patches: np.ndarray | None = None,
    initial: dict | None = None,
    steer_table: tuple[np.ndarray, np.ndarray] | None = None,
    dt: float = 0.002,
    output_hz: float = 100.0,
) -> SimResult:
    """Integrate a drive.

    Parameters
    ----------
    params : SimParams
    controller : numpy.ndarray
        Controller settings (see :mod:`gripsense.sim.maneuvers`, which builds them).
    duration_s : float
        [s].
    mu : float
        Road friction outside the patches [-].
    patches : array (n, 5) or None
        Rectangles ``x_min, x_max, y_min, y_max, mu`` in world coordinates [m], later wins.
    initial : dict
        ``x_m, y_m, yaw_rad, u_mps, v_mps, yaw_rate_rps`` (defaults 0, except u 10 m/s).
    steer_table : (t_s, road-wheel angle rad) or None
        For the open-loop steering mode.
    dt : float
        Integration step [s].
    output_hz : float
        Output rate [Hz]; must divide 1/dt.

    Returns
    -------
    SimResult
    """
    every = max(1, round(1.0 / (output_hz * dt)))
    n_steps = round(duration_s / dt)
    init = {
        "x_m": 0.0,
        "y_m": 0.0,
        "yaw_rad": 0.0,
        "u_mps": 10.0,
        "v_mps": 0.0,
        "yaw_rate_rps": 0.0,
        **(initial or {}),
    }
    s0 = np.zeros(10)
    s0[:6] = [
        init["x_m"],
        init["y_m"],
        init["yaw_rad"],
        init["u_mps"],
        init["v_mps"],
        init["yaw_rate_rps"],
    ]
    p = params._packed()
    wpos = params.wheel_positions
    pt = np.zeros((0, 5)) if patches is None else np.asarray(patches, dtype=float).reshape(-1, 5)
    st, sv = steer_table if steer_table is not None else (np.zeros(1), np.zeros(1))
    n_out = n_steps // every + 1
    ob = np.full((n_out, 11), np.nan)
    ow = np.full((n_out, 4, 8), np.nan)
    t0 = time.perf_counter()
    k = _integrate(
        s0,
        p,
        wpos,
        np.asarray(controller, dtype=float),
        np.asarray(st, float),
        np.asarray(sv, float),
        float(mu),
        pt,
        params._tables(),
        dt,
        n_steps,
        every,
        ob,
        ow,
    )
    wall = time.perf_counter() - t0
    ob, ow = ob[:k], ow[:k]
    body = pd.DataFrame(
        {
            "t_s": ob[:, 0],
            "x_m": ob[:, 1],
            "y_m": ob[:, 2],
            "yaw_rad": ob[:, 3],
            "u_mps": ob[:, 4],
            "v_mps": ob[:, 5],
            "yaw_rate_rps": ob[:, 6],
            "ax_mps2": ob[:, 7],
            "ay_mps2": ob[:, 8],
            "steer_rad": ob[:, 9],
            "fx_N": ob[:, 10],
        }
    )
    n = ob.shape[0]
    wheels = pd.DataFrame(
        {
            "t_s": np.repeat(ob[:, 0], 4),
            "wheel": pd.Categorical(
                np.tile(np.array(WHEEL_NAMES), n), categories=list(WHEEL_NAMES)
            ),
            "mu_true": ow[:, :, 3].ravel(),
            "mu_road": ow[:, :, 7].ravel(),
            "camber_rad": ow[:, :, 6].ravel(),
            "slip_angle_rad": ow[:, :, 0].ravel(),
            "load_N": ow[:, :, 1].ravel(),
            "force_N": ow[:, :, 2].ravel(),
            "speed_mps": ow[:, :, 4].ravel(),
        }
    )
    meta = {"diverged": k < n_out, "dt_s": dt, "output_hz": output_hz}
    return SimResult(body=body, wheels=wheels, params=params, wall_s=wall, meta=meta)
