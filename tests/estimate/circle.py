"""A steady left circle of the thesis Corolla with known μ, built independently of gripsense.

The rear-left wheel is the "truth" wheel: its slip angle is solved here (scipy brentq on the
Fiala force of the parabolic brush model) so that it carries its load's share of the rear-axle
force m_r a_y at the given μ; the antenna's velocity follows by rigid-body kinematics.
"""

from __future__ import annotations

import numpy as np
import pandas as pd
from scipy.optimize import brentq

G = 9.80665
M_REAR, H, T = 480.0, 0.75, 1.10  # thesis: 1200 kg at 6:4, CG height, 2b
A_LM, B_LM, W, GT = 0.0104, -1.017e-4, 0.185, 5e7
RL, RR = (-0.76, 1.0), (-0.76, -0.205)  # wheel offsets from the antenna (x fwd, y left)
DY_REF = (RL[1] + RR[1]) / 2


def circle(
    mu: float,
    utilisation: float,
    radius: float = 25.0,
    duration: float = 20.0,
    rate_hz: float = 10.0,
    heading_offset_deg: float = 0.0,
):
    """Epoch table and the truth (dict) for a steady circle at a_y = utilisation·μ·g."""
    ay = utilisation * mu * G
    u_ref = np.sqrt(ay * radius)
    r = u_ref / radius
    u_a = u_ref + r * DY_REF
    dfz = M_REAR * ay * H / T  # rigid vehicle: roll centres at CG height (the thesis model)
    fz_l = M_REAR * G / 2 - dfz
    m_l = fz_l / G
    f_l = m_l * ay
    length = A_LM * np.sqrt(m_l) + B_LM * m_l
    C = 0.5 * GT * W * length**2

    def fiala(b):
        th = C * np.tan(b) / (3 * mu * fz_l)
        return mu * fz_l * (1 - (1 - min(th, 1.0)) ** 3) - f_l

    alpha_l = -brentq(fiala, 1e-9, 0.5, xtol=1e-16, rtol=1e-15)
    u_l = u_a - r * RL[1]
    v_l = u_l * np.tan(alpha_l)
    v_a = v_l - r * RL[0]
    beta_a = np.arctan2(v_a, u_a)
    t = np.arange(0.0, duration, 1.0 / rate_hz)
    psi = 90.0 - np.rad2deg(r) * t  # a left turn: compass heading falls
    chi = psi - np.rad2deg(beta_a)
    epochs = pd.DataFrame(
        {
            "t_s": t,
            "heading_deg": np.mod(psi + heading_offset_deg, 360.0),
            "course_deg": np.mod(chi, 360.0),
            "speed_mps": np.full(t.size, np.hypot(u_a, v_a)),
            "yaw_rate_rps": np.full(t.size, r),
        }
    )
    truth = {
        "alpha_rear_left": alpha_l,
        "load_rear_left": fz_l,
        "force_rear_left": f_l,
        "ay": ay,
        "r": r,
        "speed": float(np.hypot(u_a, v_a)),
        "C": C,
        "length": length,
    }
    return epochs, truth
