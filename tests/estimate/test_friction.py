"""FrictionRun end to end on steady circles with known μ (tests/estimate/circle.py)."""

from __future__ import annotations

import json

import numpy as np
import pandas as pd
import pytest

from gripsense import FrictionRun, InputError, Vehicle
from gripsense.data import sample_path
from tests.estimate.circle import circle

THESIS = sample_path("corolla_thesis.toml")


def _run(epochs, **kw):
    kw.setdefault("calibrate_heading", False)
    method = kw.pop("method", "brush-2")
    return FrictionRun(THESIS, method=method, **kw).run(epochs)


def test_recovers_mu_near_the_limit():
    epochs, truth = circle(mu=0.5, utilisation=0.92)
    res = _run(epochs)
    w = res.wheels
    rl = w[w["wheel"] == "rear_left"]
    assert (rl["flag"] == "ok").all()
    np.testing.assert_allclose(rl["mu"], 0.5, rtol=1e-6)
    np.testing.assert_allclose(rl["slip_angle_rad"], truth["alpha_rear_left"], rtol=1e-9)
    np.testing.assert_allclose(rl["load_N"], truth["load_rear_left"], rtol=1e-9)
    np.testing.assert_allclose(rl["force_N"], truth["force_rear_left"], rtol=1e-9)
    np.testing.assert_allclose(rl["contact_length_m"], truth["length"], rtol=1e-9)
    assert (rl["mu_sigma"] < 0.5 * rl["mu"]).all()
    s = res.summary.set_index("wheel")
    assert s.loc["rear_left", "mu"] == pytest.approx(0.5, rel=1e-6)
    assert s.loc["rear_left", "mu_low"] < 0.5 < s.loc["rear_left", "mu_high"]
    assert s.loc["rear_left", "n_valid"] == len(rl)
    # the wheel's own |F|/Fz (load-transfer model), and the axle's measured grip (model-free)
    assert s.loc["rear_left", "utilisation_p95"] == pytest.approx(0.92 * 0.5, rel=1e-6)
    assert 0.4 < s.loc["rear_left", "grip_used_lower"] <= 0.5
    assert "rear_left: μ = 0.50" in res.explain()


def test_everyday_cornering_is_not_observable():
    """0.2 g on a μ = 0.9 road: every sample ill-conditioned; only the lower bound is reported."""
    epochs, _ = circle(mu=0.9, utilisation=0.2 / 0.9)
    res = _run(epochs)
    w = res.wheels
    # the truth wheel is ill-conditioned (κ ≈ −11); on the other wheel the rigid-body slip
    # difference r·t/U exceeds the tiny non-linearity deficit: the model has no solution there
    assert set(w.loc[w["wheel"] == "rear_left", "flag"]) == {"ill_conditioned"}
    assert set(w.loc[w["steady"], "flag"]) <= {"ill_conditioned", "no_solution"}
    assert w["mu"].isna().all()
    s = res.summary.set_index("wheel")
    assert (s["n_valid"] == 0).all() and (s["surface"] == "undetermined").all()
    assert s.loc["rear_left", "utilisation_p95"] == pytest.approx(0.2, rel=1e-6)
    assert 0.15 < s.loc["rear_left", "grip_used_lower"] <= 0.2
    assert "not observable" in res.explain() and "the data prove μ ≥ 0.1" in res.explain()
    # the exact inversion still recovers 0.9 for the noise-free sample: flagged, not wrong
    kap = w.loc[w["wheel"] == "rear_left", "kappa_beta"]
    assert (kap < -9).all()


@pytest.mark.parametrize(("method", "expected"), [("brush-2", 0.5), ("thesis-2", None)])
def test_methods(method, expected):
    epochs, truth = circle(mu=0.5, utilisation=0.92)
    rl = _run(epochs, method=method).wheels.query("wheel == 'rear_left'")
    if expected is not None:
        np.testing.assert_allclose(rl["mu"], expected, rtol=1e-6)
    else:
        # eq. (4.15): μ = T² /(3 Fz (T − F)) with T = C tanβ
        T = truth["C"] * np.tan(abs(truth["alpha_rear_left"]))
        F, fz = truth["force_rear_left"], truth["load_rear_left"]
        np.testing.assert_allclose(rl["mu"], T**2 / (3 * fz * (T - F)), rtol=1e-9)


def test_gates():
    straight, _ = circle(mu=0.5, utilisation=0.92)
    straight["yaw_rate_rps"] = 0.0
    straight["course_deg"] = straight["heading_deg"]
    assert set(_run(straight).wheels["flag"]) == {"not_cornering"}
    slow, _ = circle(mu=0.5, utilisation=0.92)
    slow["speed_mps"] = 1.0
    assert set(_run(slow).wheels["flag"]) == {"low_speed"}
    slalom, _ = circle(mu=0.5, utilisation=0.92)
    slalom["yaw_rate_rps"] = 0.4 * np.sin(2 * np.pi * slalom["t_s"] / 4.0) + 0.45
    assert (_run(slalom).wheels["flag"] == "not_steady").mean() > 0.9


def test_wrong_sign_is_no_solution():
    epochs, _ = circle(mu=0.5, utilisation=0.92)
    # course 5° right of the heading in a left turn: the rear wheels slip to the inside, so the
    # lateral force (to the left) and the slip angle (positive) have the same sign
    epochs["course_deg"] = (epochs["heading_deg"] - 5.0) % 360
    w = _run(epochs).wheels
    assert (w.query("wheel == 'rear_left'")["flag"] == "no_solution").all()


def test_heading_offset_calibrated_on_straights():
    epochs, _ = circle(mu=0.5, utilisation=0.92, heading_offset_deg=1.0)
    n = 100  # straight driving before the circle, same heading offset
    straight = pd.DataFrame(
        {
            "t_s": np.arange(n) * 0.1 - n * 0.1,
            "heading_deg": np.full(n, 91.0),
            "course_deg": np.full(n, 90.0),
            "speed_mps": np.full(n, 10.0),
            "yaw_rate_rps": np.zeros(n),
        }
    )
    both = pd.concat([straight, epochs], ignore_index=True)
    res = FrictionRun(THESIS).run(both)
    assert res.meta["heading_offset_deg"] == pytest.approx(1.0, abs=1e-9)
    assert "straight driving (100 samples)" in res.meta["heading_offset_source"]
    rl = res.wheels.query("wheel == 'rear_left' and flag == 'ok'")
    np.testing.assert_allclose(rl["mu"], 0.5, rtol=1e-6)
    # without calibration the 1° offset ruins the estimate (docs/physics.md §1.4)
    bad = _run(both).wheels.query("wheel == 'rear_left' and flag == 'ok'")
    assert bad.empty or not np.allclose(bad["mu"], 0.5, rtol=0.05)


def test_front_wheels_need_steering(tmp_path):
    toml = tmp_path / "car.toml"
    toml.write_text(
        open(THESIS)
        .read()
        .replace(
            "[antenna.wheels]",
            "[antenna.wheels]\nfront_left = [1.84, 1.0]\nfront_right = [1.84, -0.205]",
        )
    )
    epochs, _ = circle(mu=0.5, utilisation=0.92)
    veh = Vehicle.from_toml(toml)
    res = FrictionRun(veh, calibrate_heading=False).run(epochs)
    assert set(res.wheels["wheel"].astype(str)) == {"rear_left", "rear_right"}
    assert "skipped" in res.meta["front_wheels"]
    delta = np.full(len(epochs), np.deg2rad(3.0))
    res = FrictionRun(veh, calibrate_heading=False).run(epochs, steer_rad=delta)
    fl = res.wheels.query("wheel == 'front_left'")
    rl = res.wheels.query("wheel == 'rear_left'")
    # same lateral offset: V differs by r·(dx_f − dx_r), U is equal; then δ is subtracted
    r = epochs["yaw_rate_rps"].to_numpy()
    u = rl["speed_mps"].to_numpy() * np.cos(rl["slip_angle_rad"].to_numpy())
    v = u * np.tan(rl["slip_angle_rad"].to_numpy()) + r * (1.84 + 0.76)
    np.testing.assert_allclose(fl["slip_angle_rad"], np.arctan2(v, u) - np.deg2rad(3.0), rtol=1e-9)


def test_outputs(tmp_path):
    epochs, _ = circle(mu=0.5, utilisation=0.92)
    res = _run(epochs)
    paths = res.to_files(tmp_path / "out")
    w = pd.read_parquet(paths["wheels"])
    assert len(w) == len(res.wheels)
    for col in (
        "wheel",
        "speed_mps",
        "slip_angle_rad",
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
    ):
        assert col in w.columns
    doc = json.loads(paths["summary"].read_text())
    assert doc["meta"]["method"] == "brush-2" and len(doc["wheels"]) == 2
    # mu is NaN exactly where the flag is not ok
    assert (w["mu"].notna() == (w["flag"] == "ok")).all()


def test_bad_input():
    with pytest.raises(InputError, match="method"):
        FrictionRun(THESIS, method="magic")
    with pytest.raises(InputError, match="unknown option"):
        FrictionRun(THESIS, min_speed=3)
    epochs, _ = circle(mu=0.5, utilisation=0.92)
    with pytest.raises(InputError, match="missing columns"):
        FrictionRun(THESIS).run(epochs.drop(columns=["course_deg"]))


def _noisy(epochs, sigma_deg, seed=5):
    rng = np.random.default_rng(seed)
    out = epochs.copy()
    out["heading_deg"] = (out["heading_deg"] + rng.normal(0, sigma_deg, len(out))) % 360
    return out


def test_noise_selected_tail_is_not_reported():
    """Dry road at 0.3 g with 0.5° heading noise: a few samples look well-conditioned by chance;
    their median would read ~0.3 ('SNOW'). The summary must say 'not observable' instead."""
    epochs, _ = circle(mu=0.9, utilisation=0.3 / 0.9, duration=60.0)
    res = _run(_noisy(epochs, 0.5))
    s = res.summary.set_index("wheel")
    assert (s["n_valid"] > 0).any()  # the tail exists ...
    assert not s["observable"].any()  # ... and is not reported as μ
    assert s["mu"].isna().all()
    assert "not observable" in res.explain()


def test_near_limit_with_noise_is_reported():
    epochs, _ = circle(mu=0.5, utilisation=0.97, duration=60.0)
    res = _run(_noisy(epochs, 0.3))
    s = res.summary.set_index("wheel").loc["rear_left"]
    assert s["observable"]
    assert s["mu_low"] <= 0.5 <= s["mu_high"]
    assert s["mu"] == pytest.approx(0.5, abs=0.05)
