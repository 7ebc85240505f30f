"""The simulated driver: path following (pure pursuit on a circle or a line, or an open-loop
steering table) and speed (hold, free, ramp, locked braking), evaluated once per step of the
integration. The controller array's layout (``C_*``) is filled by :mod:`gripsense.sim.maneuvers`.
"""

from __future__ import annotations

import numpy as np
from numba import njit

__all__ = ["N_CTRL", "controls"]

# controller array layout (see maneuvers.py, which fills it)
C_STEER_MODE, C_CX, C_CY, C_R, C_DIR, C_LOOK = 0, 1, 2, 3, 4, 5
C_SPEED_MODE, C_V, C_KP, C_FXMAX, C_T_BRAKE, C_RATIO, C_T_LEAD = 6, 7, 8, 9, 10, 11, 12
C_ACCEL = 13  # speed ramp [m/s²] (SPEED_RAMP, from C_T_BRAKE on)
C_V_END = 14  # the ramp's last speed [m/s] (0: no end)
N_CTRL = 15
STEER_TABLE, STEER_CIRCLE, STEER_LINE = 0, 1, 2
SPEED_HOLD, SPEED_FREE, SPEED_BRAKE_LOCK, SPEED_RAMP = 0, 1, 2, 3


@njit(cache=True, nogil=True)
def controls(t, s, ctrl, steer_t, steer_v, lf, lr):
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
        if ctrl[C_V_END] > 0.0:
            v_t = min(v_t, ctrl[C_V_END])
        fx = ctrl[C_KP] * (v_t - U)
        fx = max(min(fx, ctrl[C_FXMAX]), -ctrl[C_FXMAX])
    return delta, fx, lock
