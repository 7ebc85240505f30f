"""Truth tyres of the simulator: tables against the tyre models they come from, similarity
scaling, roll camber in the vehicle model, and scenario files that pick tyres and receivers."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from gripsense.config import RECEIVERS, Vehicle
from gripsense.config.tyre_files import load_mf_tyre, load_tyre_model
from gripsense.constants import G0
from gripsense.data import sample_path
from gripsense.sim import SimParams, load_sim_tyre, run_scenario
from gripsense.sim import maneuvers as M
from gripsense.sim.drives import axle_truth, truth_tyre, truth_vehicle, user_vehicle

TIR = sample_path("tyres/PacejkaBook_Defaults.tir")


def test_table_reproduces_the_magic_formula():
    tyre = load_sim_tyre(TIR)
    mf = load_mf_tyre(TIR)
    rng = np.random.default_rng(3)
    a = np.deg2rad(rng.uniform(-15, 15, 200))
    fz = rng.uniform(1000, 8000, 200)
    g = np.deg2rad(rng.uniform(-5, 5, 200))
    ref = mf.forces(fz, np.zeros(200), a, g).fy
    got = tyre.force(a, fz, g)
    # trilinear interpolation on a 0.083° × 400 N × 2° grid
    assert np.max(np.abs(got - ref)) < 0.01 * np.max(np.abs(ref))


def test_similarity_keeps_stiffness_and_moves_the_peak():
    tyre = load_sim_tyre(TIR)
    fz0 = tyre.fz_nominal
    assert tyre.mu_ref == pytest.approx(1.0, abs=0.01)  # the book tyre peaks at μ = 1
    a = np.deg2rad(np.linspace(-20, 20, 2001))
    for mu in (0.3, 0.6):
        f = tyre.force(a, fz0, 0.0, mu_road=mu)
        assert np.max(np.abs(f)) / fz0 == pytest.approx(mu, rel=0.01)
        d = np.deg2rad(0.05)
        c = (tyre.force(-d, fz0, 0.0, mu_road=mu) - tyre.force(d, fz0, 0.0, mu_road=mu)) / (2 * d)
        assert c == pytest.approx(float(tyre.cornering_stiffness(fz0)), rel=0.01)


def test_pac89_is_turned_to_iso():
    tyre = load_sim_tyre(sample_path("tyres/HMMWV_Pac89Tire.json"))
    model = load_tyre_model(sample_path("tyres/HMMWV_Pac89Tire.json"))
    a = np.deg2rad(4.0)
    assert tyre.force(a, 4000.0) < 0 < model.forces(4000.0, 0.0, a, 0.0)[1]
    assert tyre.force(a, 4000.0) == pytest.approx(-model.forces(4000.0, 0.0, a, 0.0)[1], rel=0.01)


def test_mf_car_on_a_circle_balances_and_rolls():
    """A steady circle with Magic Formula tyres: ΣF_y = m a_y, inclination = k_γ (dφ/da_y) a_y,
    true μ per wheel near the road μ (load-dependent), axle truth the load-weighted peak."""
    veh = truth_vehicle("sedan")
    t = truth_tyre("mf-book")
    p = SimParams.from_vehicle(veh, sim_tyres={"front": t, "rear": t})
    m = M.circle(40 / 3.6, 30.0, laps=1.0, params=p)
    res = M.run(p, m, mu=0.8)
    w = res.wheels[res.wheels["t_s"] > m.settle_s + 3]
    b = res.body[res.body["t_s"] > m.settle_s + 3]
    ay = b["ay_mps2"].mean()
    assert w.groupby("t_s")["force_N"].sum().mean() == pytest.approx(veh.mass_kg * ay, rel=0.02)
    gamma = np.deg2rad(veh.roll_camber_gain * veh.roll_gradient_deg_per_g) * ay / G0
    assert w["camber_rad"].mean() == pytest.approx(gamma, rel=0.02)
    assert (w["mu_road"] == 0.8).all() and w["mu_true"].between(0.7, 0.9).all()
    # heavier outer wheels have the lower peak (the file's load sensitivity)
    outer = w[w["wheel"] == "front_right"]["mu_true"].mean()
    inner = w[w["wheel"] == "front_left"]["mu_true"].mean()
    assert outer < inner
    ax = axle_truth(res.wheels, m.settle_s + 3).set_index("axle")
    assert inner > ax.loc["front", "mu_true"] > outer


def test_user_vehicle_declares_the_stiffness_at_static_load():
    veh = truth_vehicle("suv")
    uv = user_vehicle(veh, "mf-sedan", stiffness_error=0.1, cg_height_factor=1.25)
    fzs = veh.static_load("front")
    c_true = float(truth_tyre("mf-sedan").cornering_stiffness(fzs))
    assert uv.tyres["front"].cornering_stiffness_N_per_rad == pytest.approx(1.1 * c_true, rel=1e-3)
    assert uv.cg_height_m == pytest.approx(1.25 * veh.cg_height_m, rel=1e-3)
    assert uv.mass_kg == veh.mass_kg and uv.drive == veh.drive


def test_scenario_picks_tyres_and_receivers(tmp_path):
    sc = tmp_path / "sc.toml"
    sc.write_text(
        """
[scenario]
vehicle = "corolla_sim.toml"
tyre = { front = "brush", rear = "PacejkaBook_Defaults.tir" }

[steering]
scale_error = 0.05

[[grid]]
maneuver = "circle"
receiver = ["v100", "rtk"]
tyre = ["brush", "Sedan_Pac02Tire.tir"]
speed_kmh = 30
radius_m = 25
laps = 0.5
"""
    )
    cases = run_scenario(sc, tmp_path / "out")
    assert list(cases["receiver"]) == ["v100", "v100", "rtk", "rtk"]
    # issue 45: the vehicle file of each case names the receiver that recorded it (RTK logs
    # were read as v100): one file per tyre and receiver, each with its [receiver]
    assert set(cases["vehicle_file"]) == {
        "vehicle_v100.toml",
        "vehicle_rtk.toml",
        "vehicle_Sedan_Pac02Tire_v100.toml",
        "vehicle_Sedan_Pac02Tire_rtk.toml",
    }
    for c in cases.to_dict("records"):
        v = Vehicle.from_toml(tmp_path / "out" / c["vehicle_file"])
        assert v.receiver is not None and v.receiver.name == c["receiver"]
        assert v.receiver == RECEIVERS[c["receiver"]]
    v = Vehicle.from_toml(tmp_path / "out" / "vehicle_Sedan_Pac02Tire_rtk.toml")
    assert v.tyres["rear"].cornering_stiffness_N_per_rad is not None
    assert Vehicle.from_toml(tmp_path / "out" / "vehicle.toml").receiver is None  # the truth
    steer = pd.read_csv(tmp_path / "out" / cases["steer"].iloc[0])
    truth = pd.read_parquet(tmp_path / "out" / cases["truth"].iloc[0])
    assert {"t_s", "road_wheel_deg"} <= set(steer.columns)
    assert {"mu_true", "mu_road", "camber_rad"} <= set(truth.columns)
    bad = tmp_path / "bad.toml"
    bad.write_text(sc.read_text().replace('"rtk"]', '"gps"]'))
    with pytest.raises(Exception, match="receiver = 'gps'"):
        run_scenario(bad, tmp_path / "out2")
