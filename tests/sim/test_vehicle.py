"""Simulator checks: linear bicycle-model formulas, saturation at μg, CommonRoad's ST model."""

from __future__ import annotations

import numpy as np
import pytest

from gripsense.config import Tyre, Vehicle
from gripsense.constants import G0
from gripsense.data import sample_path
from gripsense.sim import SimParams
from gripsense.sim import maneuvers as M

VEH = Vehicle.from_toml(sample_path("corolla_sim.toml"))


def _linear_params(c_front: float = 15.0, c_rear: float | None = None) -> SimParams:
    """The sim vehicle with load-independent cornering stiffness C = c · Fz_static per axle
    (equal c front and rear: neutral steer)."""
    p = SimParams.from_vehicle(VEH)
    mf = p.mass_kg * p.l_r / (p.l_f + p.l_r)
    mr = p.mass_kg - mf
    tyres = {}
    for axle, m, c in (("front", mf, c_front), ("rear", mr, c_rear or c_front)):
        tyres[axle] = Tyre(
            width_m=0.185, cornering_stiffness_N_per_rad=c * m * G0 / 2, contact_length_m=0.14
        )
    return SimParams(**{**p.__dict__, "tyres": tyres})


def _steady(res, t0):
    b = res.body[res.body["t_s"] > t0]
    return b["yaw_rate_rps"].mean(), b["ay_mps2"].mean(), b["u_mps"].mean()


@pytest.mark.parametrize("speed", [10.0, 20.0])
def test_linear_yaw_rate_gain_and_understeer(speed):
    """r/δ = (U/L)/(1 + K U²), K = (m/L²)(l_r/C_f − l_f/C_r) (bicycle model, linear tyres)."""
    p = _linear_params(12.0, 18.0)  # understeer
    delta = np.deg2rad(0.5)
    # a large μ keeps the brush tyre linear (its deficit 1 − F/(Cα) ≈ θ ∝ 1/μ)
    res = M.run(p, M.fixed_steer(speed, delta, duration_s=15.0), mu=20.0)
    r, ay, u = _steady(res, 15.0)
    L = p.l_f + p.l_r
    cf = 2 * p.tyres["front"].cornering_stiffness_N_per_rad
    cr = 2 * p.tyres["rear"].cornering_stiffness_N_per_rad
    K = p.mass_kg / L**2 * (p.l_r / cf - p.l_f / cr)
    assert r / delta == pytest.approx((u / L) / (1 + K * u**2), rel=2e-3)
    # understeer gradient: δ = L/R + K_us a_y with K_us = L K
    R = u / r
    assert (delta - L / R) / ay == pytest.approx(L * K, rel=0.03)


def test_saturation_at_mu_g():
    """Ramp steer to the limit: the largest lateral acceleration is μg within load-transfer and
    friction-circle effects (the brush model saturates at μ·Fz on every wheel)."""
    p = SimParams.from_vehicle(VEH)
    for mu in (0.5, 0.9):
        res = M.run(p, M.ramp_steer(16.0, rate_rad_s=np.deg2rad(0.5)), mu=mu)
        ay = res.body["ay_mps2"].rolling(50, center=True).mean()
        peak = ay.max() / (mu * G0)
        assert 0.92 <= peak <= 1.001, peak


def test_steady_circle_follows_radius_and_truth_is_consistent():
    p = SimParams.from_vehicle(VEH)
    m = M.circle(30 / 3.6, 25.0, laps=1.5, params=p)
    res = M.run(p, m, mu=0.9)
    b = res.body[res.body["t_s"] > m.settle_s]
    cx, cy = m.controller[1], m.controller[2]
    radius = np.hypot(b["x_m"] - cx, b["y_m"] - cy)
    assert radius.mean() == pytest.approx(25.0, abs=0.3)
    assert b["u_mps"].mean() == pytest.approx(30 / 3.6, rel=2e-3)
    # steady state: Σ F_y = m a_y and Σ x F_y = 0 (no yaw acceleration)
    w = res.wheels[res.wheels["t_s"] > m.settle_s]
    fy = w.pivot(index="t_s", columns="wheel", values="force_N")
    steer = b.set_index("t_s")["steer_rad"]
    total = (
        (fy["front_left"] + fy["front_right"]) * np.cos(steer) + fy["rear_left"] + fy["rear_right"]
    )
    np.testing.assert_allclose(total.mean(), p.mass_kg * b["ay_mps2"].mean(), rtol=1e-2)


def test_against_commonroad_single_track():
    """CommonRoad's ST model (TUM, linear tyres F = μ C_S F_z α per axle, no lateral load
    transfer) and gripsense's two-track model with matching linear tyres agree in the linear
    range on a fixed-steer steady turn: yaw rate and lateral acceleration within 1 %."""
    from scipy.integrate import solve_ivp
    from vehiclemodels.parameters_vehicle1 import parameters_vehicle1
    from vehiclemodels.vehicle_dynamics_st import vehicle_dynamics_st

    c_norm = 15.0  # C/Fz [1/rad]
    p = _linear_params(c_norm)
    cr = parameters_vehicle1()
    cr.m, cr.I_z, cr.a, cr.b, cr.h_s = p.mass_kg, p.yaw_inertia_kgm2, p.l_f, p.l_r, 0.55
    cr.tire.p_dy1 = 1.0
    cr.tire.p_ky1 = -c_norm  # C_S = -p_ky1 / p_dy1
    speed, delta = 15.0, np.deg2rad(0.8)
    x0 = [0.0, 0.0, delta, speed, 0.0, 0.0, 0.0]
    sol = solve_ivp(
        lambda t, x: vehicle_dynamics_st(x, [0.0, 0.0], cr), (0.0, 20.0), x0, rtol=1e-9, atol=1e-9
    )
    r_cr = sol.y[5, -1]
    ay_cr = sol.y[3, -1] * r_cr  # steady state: a_y = v r
    # CommonRoad uses g = 9.81; give gripsense's tyres the same axle stiffness
    res = M.run(p, M.fixed_steer(speed * np.cos(sol.y[6, -1]), delta, duration_s=14.0), mu=20.0)
    r, ay, _ = _steady(res, 15.0)
    k = 9.81 / G0  # C_S μ F_z with F_z = m g l/L: CommonRoad's g
    assert r == pytest.approx(r_cr, rel=0.01 + abs(1 - k))
    assert ay == pytest.approx(ay_cr, rel=0.01 + abs(1 - k))


def test_a_lifted_wheel_leaves_its_axle_the_load():
    """A tall SUV on μ 1.1 lifts its inner wheels in a ramp steer: statics still hold — the
    wheel loads sum to m g at every step (a lifted wheel carries nothing, its axle partner the
    axle's load) — and the tyres never deliver more than μ times the load they carry."""
    from gripsense.sim.drives import simulate_drive, truth_vehicle

    m = M.ramp_steer(70 / 3.6, rate_rad_s=np.deg2rad(1.0), max_steer_rad=np.deg2rad(14.0),
                     hold_s=6.0)  # fmt: skip
    d = simulate_drive("suv", "brush", m, 1.1, receiver="rtk", seed=25)
    t = d.truth
    assert (t["load_N"] == 0.0).any(), "no wheel lifted: the test drives past nothing"
    g = t.groupby("t_s")
    np.testing.assert_allclose(g["load_N"].sum(), truth_vehicle("suv").mass_kg * G0, rtol=1e-9)
    assert (g["force_N"].sum().abs() <= 1.1 * g["load_N"].sum() * (1 + 1e-9)).all()


def test_the_sedans_wheels_lean_within_the_known_tyres_cambers():
    """The simulated sedan's front wheels lean 2–3° with its roll at about 0.8 g (ISO 8855
    inclination, both away from the turn): within the cambers at which a known tyre's trail is
    also taken (docs/physics.md §16.7)."""
    from gripsense.estimate.torque import KNOWN_TRAIL_CAMBER_RAD
    from gripsense.sim.drives import truth_tyre, truth_vehicle

    tv, t = truth_vehicle("sedan"), truth_tyre("mf61")
    p = SimParams.from_vehicle(tv, relaxation_length_m=0.5, sim_tyres={"front": t, "rear": t})
    res = M.run(p, M.circle(np.sqrt(0.8 * G0 * 40.0), 40.0, laps=0.5, params=p), mu=1.1)
    w = res.wheels[res.wheels["t_s"] > res.wheels["t_s"].max() - 2.0]
    front = w[w["wheel"].str.startswith("front")]
    lean = np.rad2deg(front.groupby("wheel")["camber_rad"].mean())
    ay_g = res.body["ay_mps2"].iloc[-200:].mean() / G0
    assert 0.7 < ay_g < 0.85
    assert ((lean > 2.0) & (lean < 3.0)).all(), lean
    assert lean.abs().max() < np.rad2deg(max(np.abs(KNOWN_TRAIL_CAMBER_RAD)))
