"""gripsense's simulator against an independent multi-body model: CommonRoad's
``vehicle_dynamics_mb`` (TUM; 29 states: sprung mass with roll and pitch, unsprung masses,
suspension springs and dampers, wheel spin, per-wheel Pacejka tyres).

Parameters matched: CommonRoad's vehicle 2 (mass, yaw inertia, CG position and height, tracks,
roll centres at the ground) with its own tyre (camber and offset terms set to zero in both
models) tabulated as a gripsense truth tyre; the roll-stiffness split from its suspension
springs K_s T²/2 per axle; the roll gradient as CommonRoad's own steady roll per g. What
differs (docs/simulation.md): CommonRoad carries the unsprung masses' own load transfer,
suspension and tyre vertical dynamics, wheel spin and the roll axis's lateral compliance;
gripsense's loads are quasi-static. CommonRoad's axes are SAE-like (y right, z down): its
δ > 0 and r > 0 are a right turn, gripsense's (ISO) −δ and −r.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from vehiclemodels.init_mb import init_mb
from vehiclemodels.parameters_vehicle2 import parameters_vehicle2
from vehiclemodels.utils import tire_model
from vehiclemodels.vehicle_dynamics_mb import vehicle_dynamics_mb

from gripsense.config import Vehicle
from gripsense.data import sample_path
from gripsense.sim import SimParams
from gripsense.sim import maneuvers as M
from gripsense.sim.tyres import sim_tyre_from_function

G_CR = 9.81  # CommonRoad's gravity


def _commonroad(v0, steer_rate, steer0, t_end):
    p = parameters_vehicle2()
    for k in ("p_dy3", "p_hy1", "p_hy3", "p_vy1", "p_vy3", "p_ey1"):
        setattr(p.tire, k, 0.0)
    x0 = init_mb([0, 0, steer0, v0, 0, 0, 0], p)

    def f(t, x):
        return vehicle_dynamics_mb(x, [steer_rate, 20.0 * (v0 - x[3])], p)

    sol = solve_ivp(f, (0, t_end), x0, method="LSODA", rtol=1e-6, atol=1e-8, max_step=0.01)
    assert sol.status == 0
    return p, sol


def _loads(p, x):
    front = [(x[16] + p.R_w * (math.cos(x[13]) - 1) - s * 0.5 * p.T_f * math.sin(x[13])) * p.K_zt
             for s in (1, -1)]  # fmt: skip
    rear = [(x[21] + p.R_w * (math.cos(x[18]) - 1) - s * 0.5 * p.T_r * math.sin(x[18])) * p.K_zt
            for s in (1, -1)]  # fmt: skip
    return front + rear  # LF, RF, LR, RR


def _gripsense(p, roll_per_g):
    def fy(fz, a, g):
        return np.array(
            [
                tire_model.formula_lateral(ai, 0.0, fi, p.tire)[0]
                for fi, ai in zip(fz, a, strict=True)
            ]
        )

    tyre = sim_tyre_from_function(
        fy, 3000.0, "commonroad vehicle 2", n_alpha=241, n_fz=21, n_gamma=3
    )
    wb = p.a + p.b
    kf, kr = p.K_sf * p.T_f**2 / 2, p.K_sr * p.T_r**2 / 2
    base = Vehicle.from_toml(sample_path("corolla_sim.toml"))
    veh = dataclasses.replace(
        base, mass_kg=p.m, front_weight_fraction=p.b / wb, wheelbase_m=wb, cg_height_m=p.h_cg,
        track_front_m=p.T_f, track_rear_m=p.T_r, roll_stiffness_front_fraction=kf / (kf + kr),
        roll_centre_heights_m=(0.0, 0.0), yaw_inertia_kgm2=p.I_z, drive="rear",
        roll_gradient_deg_per_g=roll_per_g, roll_camber_gain=0.0,
    )  # fmt: skip
    return SimParams.from_vehicle(veh, sim_tyres={"front": tyre, "rear": tyre}), tyre


def test_steady_turn_loads_yaw_rate_and_lateral_acceleration():
    v0, delta = 15.0, math.radians(2.0)
    p, sol = _commonroad(v0, 0.0, delta, 12.0)
    x = sol.y[:, -1]
    r_cr, ay_cr = x[5], x[3] * x[5]
    fz_cr = _loads(p, x)
    roll_per_g = abs(math.degrees(x[6])) / (ay_cr / G_CR)
    params, tyre = _gripsense(p, roll_per_g)
    res = M.run(params, M.fixed_steer(v0, -delta, duration_s=10.0), mu=tyre.mu_ref)
    w = res.wheels[res.wheels["t_s"] > 12]
    b = res.body[res.body["t_s"] > 12]
    assert -b["yaw_rate_rps"].mean() == pytest.approx(r_cr, rel=0.02)
    assert -b["ay_mps2"].mean() == pytest.approx(ay_cr, rel=0.02)
    ours = w.groupby("wheel", observed=True)["load_N"].mean()
    # the same right turn: CommonRoad's left wheels are gripsense's left wheels (outer)
    mine = [ours["front_left"], ours["front_right"], ours["rear_left"], ours["rear_right"]]
    # loads differ by the total gravity convention (9.81 vs 9.80665) and the unsprung masses
    np.testing.assert_allclose(mine, fz_cr, rtol=0.05)
    assert sum(mine) == pytest.approx(sum(fz_cr), rel=1e-3)


def test_ramp_steer_follows_the_multi_body_model():
    """A slow steering ramp (0 → 4° at 0.5°/s, 15 m/s): yaw rate and lateral acceleration
    within a few per cent along the way, into the non-linear range of the tyres."""
    v0, rate = 15.0, math.radians(0.5)
    p, sol = _commonroad(v0, rate, 0.0, 8.0)
    _, roll = _commonroad(v0, 0.0, math.radians(2.0), 12.0)
    xs = roll.y[:, -1]
    params, tyre = _gripsense(p, abs(math.degrees(xs[6])) / (xs[3] * xs[5] / G_CR))
    m = M.ramp_steer(v0, rate_rad_s=-rate, max_steer_rad=-math.radians(4.0), hold_s=0.0)
    res = M.run(params, m, mu=tyre.mu_ref)
    b = res.body
    for t in (3.0, 5.0, 7.5):
        k = int(np.searchsorted(sol.t, t))
        r_cr, ay_cr = sol.y[5, k], sol.y[3, k] * sol.y[5, k]
        j = int(np.searchsorted(b["t_s"].to_numpy(), sol.t[k]))
        assert -b["yaw_rate_rps"].iloc[j] == pytest.approx(r_cr, rel=0.04), t
        assert -b["ay_mps2"].iloc[j] == pytest.approx(ay_cr, rel=0.04), t
