"""Integration of a drive: fixed-step RK4 of :mod:`gripsense.sim.dynamics` with the driver of
:mod:`gripsense.sim.control`, in one compiled loop, and :func:`simulate`, which packs the
parameters and unpacks the result.
"""

from __future__ import annotations

import time

import numpy as np
import pandas as pd
from numba import njit

from gripsense.sim.control import controls
from gripsense.sim.dynamics import deriv
from gripsense.sim.vehicle import WHEEL_NAMES, SimParams, SimResult

__all__ = ["integrate", "simulate"]


@njit(cache=True, nogil=True)
def integrate(
    s0, p, wpos, ctrl, steer_t, steer_v, mu0, patches, tabs, dt, n_steps, every, out_body, out_wheel
):
    """Fixed-step RK4 of :func:`~gripsense.sim.dynamics.deriv` with the controller evaluated once
    per step; writes every *every*-th step to the output arrays and returns how many rows it
    wrote (fewer than asked when the state diverged).
    """
    s = s0.copy()
    n_state = s.size
    ow = np.empty((4, 8))
    ax_prev = 0.0
    ay_prev = s[5] * s[3]
    k_out = 0
    for n in range(n_steps + 1):
        t = n * dt
        delta, fx, lock = controls(t, s, ctrl, steer_t, steer_v, p[2], p[3])
        k1 = deriv(s, p, wpos, delta, fx, lock, ax_prev, ay_prev, mu0, patches, tabs, ow)
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
        k2 = deriv(s2, p, wpos, delta, fx, lock, ax_prev, ay_prev, mu0, patches, tabs, ow)
        s3 = s + 0.5 * dt * k2
        k3 = deriv(s3, p, wpos, delta, fx, lock, ax_prev, ay_prev, mu0, patches, tabs, ow)
        s4 = s + dt * k3
        k4 = deriv(s4, p, wpos, delta, fx, lock, ax_prev, ay_prev, mu0, patches, tabs, ow)
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
    p = params.packed()
    wpos = params.wheel_positions
    pt = np.zeros((0, 5)) if patches is None else np.asarray(patches, dtype=float).reshape(-1, 5)
    st, sv = steer_table if steer_table is not None else (np.zeros(1), np.zeros(1))
    n_out = n_steps // every + 1
    ob = np.full((n_out, 11), np.nan)
    ow = np.full((n_out, 4, 8), np.nan)
    t0 = time.perf_counter()
    k = integrate(
        s0,
        p,
        wpos,
        np.asarray(controller, dtype=float),
        np.asarray(st, float),
        np.asarray(sv, float),
        float(mu),
        pt,
        params.tables(),
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
            "force_ss_N": ow[:, :, 5].ravel(),
            "speed_mps": ow[:, :, 4].ravel(),
        }
    )
    meta = {"diverged": k < n_out, "dt_s": dt, "output_hz": output_hz}
    return SimResult(body=body, wheels=wheels, params=params, wall_s=wall, meta=meta)
