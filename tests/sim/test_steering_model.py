"""Seed-003 vehicle + steering model: regularity, closed forms, an independent bicycle model."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
from scipy.integrate import solve_ivp

import gripsense
from gripsense.config import SteeringCar
from gripsense.identify.steering_metrics import settling_time, yaw_gain
from gripsense.physics.steering_system import (
    descriptor,
    simulate_release,
    simulate_step,
    steady_turn,
)

TOML = Path(gripsense.__file__).parent / "data" / "of18_steering.toml"


@pytest.fixture
def car():
    return SteeringCar.from_toml(TOML)


def test_descriptor_is_regular_with_the_closed_form_determinant(car):
    """Physics §9.2: det M = m I I_s I_h Π K_i / (V³ k_y⁴) (release); no I_h for the step."""
    kf, kr = car.cornering_stiffness_front_N_per_rad, car.cornering_stiffness_rear_N_per_rad
    base = (
        car.mass_kg
        * car.yaw_inertia_kgm2
        * car.kingpin_inertia_kgm2
        * kf**2
        * kr**2
        / (car.speed_mps**3 * car.tyre_lateral_stiffness_N_per_m**4)
    )
    m_step, _, _ = descriptor(car, "step")
    m_rel, _, _ = descriptor(car, "release")
    assert np.linalg.det(m_step) == pytest.approx(base, rel=1e-10)
    assert np.linalg.det(m_rel) == pytest.approx(base * car.ih, rel=1e-10)


def _stability_factor(car, kf):
    """Abe's stability factor A = −m (l_f K_f − l_r K_r) / (2 L² K_f K_r), K per tyre."""
    kr = car.cornering_stiffness_rear_N_per_rad
    L = car.lf_m + car.lr_m
    return -car.mass_kg * (car.lf_m * kf - car.lr_m * kr) / (2 * L**2 * kf * kr)


def test_rigid_steering_gives_the_bicycle_steady_yaw_gain(car):
    rigid = replace(car, ks1_Nm_per_rad=1e12)
    a0 = 0.02
    r = steady_turn(rigid, a0)[1]
    L = car.lf_m + car.lr_m
    v = car.speed_mps
    expect = v / (L * (1 + _stability_factor(car, car.cornering_stiffness_front_N_per_rad) * v**2))
    assert r / a0 == pytest.approx(expect, rel=1e-6)


def test_compliant_steering_reduces_the_front_stiffness_as_in_closed_form(car):
    """Steady state with k_s: δ = α − ξ ΣY_f / k_s, i.e. K_f,eff = K_f / (1 + 2 ξ K_f / k_s)."""
    soft = car.with_ks(2000.0)
    a0 = 0.02
    x = steady_turn(soft, a0)
    kf = car.cornering_stiffness_front_N_per_rad
    kf_eff = kf / (1 + 2 * car.trail_m * kf / soft.ks)
    L = car.lf_m + car.lr_m
    v = car.speed_mps
    # Y_f = K (δ − β − l_f r/V) and δ = α − 2ξY_f/k_s  ⇒  Y_f = K_f,eff (α − β − l_f r/V):
    # the bicycle model with K_f,eff, steered by α
    expect = v / (L * (1 + _stability_factor(car, kf_eff) * v**2))
    assert x[1] / a0 == pytest.approx(expect, rel=1e-9)
    assert x[2] == pytest.approx(a0 - car.trail_m * (x[4] + x[5]) / soft.ks, rel=1e-12)


def test_ramp_response_matches_an_independent_bicycle_model(car):
    """k_s → ∞, fast tyres (k_y → ∞), small I_s: the yaw-rate response to the ramp equals the
    classic 2-state bicycle model integrated with scipy's solve_ivp."""
    fast = replace(
        car,
        ks1_Nm_per_rad=1e9,
        tyre_lateral_stiffness_N_per_m=1e9,
        kingpin_inertia_kgm2=1e-4,
        kingpin_damping_Nms=1.0,
    )
    rate, stop = np.deg2rad(70) / 5, np.deg2rad(90) / 5
    sim = simulate_step(fast, steer_rate_rad_s=rate, stop_rad=stop, duration_s=2.0)
    m, iz, lf, lr, v = car.mass_kg, car.yaw_inertia_kgm2, car.lf_m, car.lr_m, car.speed_mps
    cf, cr = 2 * car.cornering_stiffness_front_N_per_rad, 2 * car.cornering_stiffness_rear_N_per_rad

    def rhs(t, s):
        beta, r = s
        d = np.clip((t - 0.1) * rate, 0, stop)
        yf = cf * (d - beta - lf * r / v)
        yr = cr * (-beta + lr * r / v)
        return [(yf + yr) / (m * v) - r, (lf * yf - lr * yr) / iz]

    ref = solve_ivp(rhs, (0, 2.0), [0, 0], t_eval=sim["t_s"], rtol=1e-10, atol=1e-12, max_step=1e-3)
    scale = np.max(np.abs(ref.y[1]))
    assert np.max(np.abs(sim["yaw_rate_rps"] - ref.y[1])) < 2e-3 * scale


def test_release_returns_to_centre_and_settling_time_closed_form(car):
    r = simulate_release(car.with_cs(60.0), alpha0_rad=0.1, duration_s=6.0)
    assert abs(r["alpha_rad"][-1]) < 1e-3 * 0.1
    # settling_time on an exponential: τ ln 20 for the 5 % band
    t = np.linspace(0, 3, 3001)
    assert settling_time(t, 2.0 * np.exp(-t / 0.3), final=0.0) == pytest.approx(
        0.3 * np.log(20), abs=1e-4
    )
    assert settling_time(
        t, 1 + np.exp(-t / 0.3), reference="converged", final=1.0
    ) == pytest.approx(0.3 * np.log(20), abs=1e-4)


def test_more_damping_settles_slower_on_the_overdamped_branch(car):
    ts = [
        settling_time(
            *(lambda r: (r["t_s"], r["alpha_rad"]))(
                simulate_release(car.with_cs(cs), alpha0_rad=0.1, duration_s=6.0)
            ),
            final=0.0,
        )
        for cs in (40.0, 80.0, 160.0)
    ]
    assert ts[0] < ts[1] < ts[2]


def test_yaw_gain_grows_with_steering_stiffness(car):
    g = []
    for ks in (1500.0, 3000.0, 6000.0):
        s = simulate_step(car.with_ks(ks), steer_rate_rad_s=0.25, stop_rad=0.3, duration_s=2.0)
        g.append(yaw_gain(s["t_s"], s["yaw_rate_rps"], onset_s=s["onset_s"]))
    assert g[0] < g[1] < g[2]


def test_config_errors_name_the_key(tmp_path):
    bad = TOML.read_text().replace("trail_m = 0.03", "trail_m = -0.03")
    (tmp_path / "c.toml").write_text(bad)
    with pytest.raises(gripsense.errors.InputError, match=r"\[steering\] trail_m"):
        SteeringCar.from_toml(tmp_path / "c.toml")
