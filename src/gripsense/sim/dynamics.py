"""The equations of motion of the simulated vehicle, compiled (:mod:`gripsense.sim.vehicle` has
the model's description): tyre forces (brush or tabulated), loads with lateral and longitudinal
transfer, roll-induced camber, road friction patches and the state derivative.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from gripsense.constants import G0
from gripsense.physics.brush import force_scalar

__all__ = [
    "deriv",
    "drive_forces",
    "road_mu",
    "tab_force",
    "tyre_stiffness",
    "wheel_force",
    "wheel_loads",
]


@njit(cache=True, nogil=True)
def road_mu(x, y, mu0, patches):
    """The road's μ at (x, y): the last patch ``x_min, x_max, y_min, y_max, μ`` that holds the
    point, else *mu0*.
    """
    mu = mu0
    for k in range(patches.shape[0]):
        if patches[k, 0] <= x <= patches[k, 1] and patches[k, 2] <= y <= patches[k, 3]:
            mu = patches[k, 4]
    return mu


@njit(cache=True, nogil=True)
def tyre_stiffness(p, axle, mass):
    """Cornering stiffness [N/rad] of a brush tyre of *axle* (0 front, 1 rear) carrying *mass*
    [kg], from the packed parameters: a declared C, or G w l²/2 with a fixed or l–m contact
    length.
    """
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
def wheel_loads(p, ax_prev, ay_prev):
    """Quasi-static wheel loads [N] (front left, front right, rear left, rear right) and the
    wheels' camber [rad] from the previous step's accelerations (docs/physics.md §4.2).

    The body rolls by φ = (dφ/da_y) a_y, which also moves the CG sideways: the roll moment is
    m (h − h_ra)(a_y + g φ). The wheels lean with the body (quasi-static roll, the same
    inclination for all four). A lifted wheel carries nothing and the axle keeps its load (the
    transfer saturates: the outer wheel carries the axle; the model has no roll-over): the loads
    always sum to m g.
    """
    m, lf, lr, h = p[0], p[2], p[3], p[4]
    tf, tr, kf, hf, hr, mf, mr = p[5], p[6], p[7], p[8], p[9], p[10], p[11]
    L = lf + lr
    h_ra = (mf * hf + mr * hr) / m
    arm = m * (h - h_ra)
    ay_roll = ay_prev * (1.0 + p[27])
    dfz_f = (ay_prev * mf * hf + kf * arm * ay_roll) / tf
    dfz_r = (ay_prev * mr * hr + (1.0 - kf) * arm * ay_roll) / tr
    dfx = m * ax_prev * h / L / 2.0
    gamma = p[28] * p[27] * ay_prev / G0
    fz = np.empty(4)
    fz[0] = mf * G0 / 2 - dfz_f - dfx
    fz[1] = mf * G0 / 2 + dfz_f - dfx
    fz[2] = mr * G0 / 2 - dfz_r + dfx
    fz[3] = mr * G0 / 2 + dfz_r + dfx
    for a in (0, 2):
        if fz[a] < 0.0:
            fz[a + 1] += fz[a]
            fz[a] = 0.0
        elif fz[a + 1] < 0.0:
            fz[a] += fz[a + 1]
            fz[a + 1] = 0.0
    return fz, gamma


@njit(cache=True, nogil=True)
def drive_forces(drive, fx_total, lock):
    """Driving force per wheel [N] (wheel axes): *fx_total* split over the driven wheels
    (*drive* 0 front, 1 rear, else all four); none while the wheels are locked.
    """
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
    return fxw


@njit(cache=True, nogil=True)
def wheel_force(p, tabs, i, alpha, load, mu, gamma, fx_demand, lock, uw, vw, speed):
    """A wheel's longitudinal force, steady-state lateral force [N] and peak μ on road μ *mu*.

    A locked wheel slides with μ load against its velocity (*uw*, *vw*, *speed*). A rolling
    wheel's driving force *fx_demand* is held within μ load and leaves the friction circle's
    rest, μ_y, to the lateral force: a tyre from a file (tables in *tabs*) scaled to μ_y by
    similarity, or the brush tyre of the packed parameters *p* (docs/physics.md §2, §8).
    """
    tab_f, tab_r, peak_f, peak_r, tax = tabs
    which = int(p[14])
    mu_peak = mu
    if lock == 1:
        if speed > 1e-6:
            fxi = -mu * load * uw / speed
            fy_ss = -mu * load * vw / speed
        else:
            fxi = 0.0
            fy_ss = 0.0
        return fxi, fy_ss, mu_peak
    fxi = fx_demand
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
        c = tyre_stiffness(p, axle, load / G0)
        mag = force_scalar(mu_y, np.tan(alpha) if abs(alpha) < 1.5 else 1e3, load, c, which)
        fy_ss = -mag if alpha > 0 else mag
        if alpha == 0.0:
            fy_ss = 0.0
    return fxi, fy_ss, mu_peak


@njit(cache=True, nogil=True)
def deriv(s, p, wpos, delta, fx_total, lock, ax_prev, ay_prev, mu0, patches, tabs, out_w):
    """State derivative; out_w[i] = (alpha, Fz, Fy_wheel, μ peak, speed, Fy_ss, γ, μ road).

    The loads (:func:`wheel_loads`), the drive's split (:func:`drive_forces`) and each wheel's
    force (:func:`wheel_force`) are compiled functions of their own. Split so, the demo
    scenario's 24 integrations give the same numbers to the bit and take 1–2 % longer than as
    one body (1.17 against 1.15 s, best of five, alternated in one sitting).
    """
    m, iz, sigma = p[0], p[1], p[12]
    drive = int(p[13])
    X, Y, psi, U, V, r = s[0], s[1], s[2], s[3], s[4], s[5]
    fz, gamma = wheel_loads(p, ax_prev, ay_prev)
    fxw = drive_forces(drive, fx_total, lock)
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
        mu = road_mu(wx, wy, mu0, patches)
        load = max(fz[i], 0.0)
        speed = np.sqrt(uw * uw + vw * vw)
        fxi, fy_ss, mu_peak = wheel_force(
            p, tabs, i, alpha, load, mu, gamma, fxw[i], lock, uw, vw, speed
        )
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
