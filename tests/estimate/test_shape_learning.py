"""The curve's shape learned from the car's own limits (docs/physics.md §15.10): a sweep on one
road teaches the normalised shape, which carries to a steady drive on another road. Truth: a
PAC2002 sedan tyre (Magic Formula, ``Sedan_Pac02Tire.tir``) the estimator never sees."""

from __future__ import annotations

import dataclasses
import functools

import numpy as np
import pytest

from gripsense import FrictionRun
from gripsense.config.tyre_files import load_mf_tyre
from gripsense.estimate.noise import NoiseModel
from gripsense.estimate.profile import learned_family, shape_ids, tyre_family
from gripsense.estimate.shape_learning import combine_evidence, shape_evidence
from gripsense.io import read_nmea
from gripsense.io.sensors.steer import steer_at
from gripsense.physics.shape_grid import LEARN_GRID
from gripsense.physics.tyre_curves import magic_formula_normalised
from gripsense.sim import maneuvers as M
from gripsense.sim.drives import limit_speed, simulate_drive, truth_vehicle, user_vehicle

TYRE = "mf-sedan"
RECEIVER = "rtk"


def _run(d, uv):
    ep = read_nmea(d.lines).epochs
    ch = d.steer.assign(steer_rad=np.deg2rad(d.steer["road_wheel_deg"]))
    steer = steer_at(ch, ep["t_s"].to_numpy(float))
    noise = NoiseModel.for_vehicle(uv, RECEIVER)
    return FrictionRun(uv, method="axle-window", noise=noise).run(ep, steer_rad=steer), noise


@functools.cache
def _vehicle():
    return user_vehicle(truth_vehicle("sedan"), TYRE)


@functools.cache
def _sweep_evidence(mu: float) -> np.ndarray:
    """ISO 4138 constant radius with the speed rising past the limit, on a road of *mu*."""
    uv = _vehicle()
    m = M.constant_radius(40.0, 5.0, limit_speed(1.3 * mu, 40.0, 1.0), accel_mps2=0.1)
    d = simulate_drive("sedan", TYRE, m, mu, receiver=RECEIVER, seed=1)
    res, noise = _run(d, uv)
    ev = shape_evidence(res.wheels, uv, "front", noise=noise)
    assert ev is not None
    return ev


def _truth_shape() -> tuple[float, float]:
    """The truth tyre's normalised lateral curve at its nominal load, as the Magic Formula
    (C_s, E) that fits it best (its own F/(μFz) against Kα/(μFz))."""
    from gripsense.data import path as data_path

    tyre = load_mf_tyre(data_path("tyres") / "Sedan_Pac02Tire.tir")
    fz = float(tyre.params["FNOMIN"])
    alpha = np.deg2rad(np.linspace(0.01, 20.0, 400))

    def fy(a):
        return tyre.forces(np.full_like(a, fz), alpha=a, combined=False).fy

    fy = np.abs(fy(alpha) - fy(-alpha)) / 2.0  # its offsets (ply steer, conicity) taken out
    k = fy[0] / np.tan(alpha[0])
    x, f = k * np.tan(alpha) / fy.max(), fy / fy.max()
    c_grid, e_grid = np.linspace(1.05, 2.0, 96), np.linspace(-2.0, 0.95, 119)
    err = [(np.max(np.abs(magic_formula_normalised(x, c, e) - f)), c, e)
           for c in c_grid for e in e_grid]  # fmt: skip
    _, c, e = min(err)
    return float(c), float(e)


def test_without_learning_the_tyre_keeps_its_prior_family():
    tyre = _vehicle().tyres["front"]
    assert tyre.shape_evidence is None
    assert np.array_equal(tyre_family(tyre), shape_ids(tyre.shape))


def test_combined_evidence_adds_drives_and_is_zero_at_its_best():
    a = np.array([0.0, 1.0, 5.0, np.inf])
    b = np.array([3.0, 0.0, 1.0, 2.0])
    assert np.array_equal(combine_evidence([a, b]), np.array([2.0, 0.0, 5.0, np.inf]))
    with pytest.raises(ValueError):
        combine_evidence([])


def test_a_learned_family_weights_every_grid_shape_by_its_evidence():
    d = np.full(len(LEARN_GRID), 400.0)
    d[5] = 0.0
    fam = learned_family(d, temper=2.0)
    assert fam.learned and fam.ids.size >= 1 and 5 in fam.ids
    assert all(fam.penalty[i] <= 30.0 for i in fam.ids)
    with pytest.raises(ValueError, match="grid"):
        learned_family(d[:-1], temper=2.0)


@pytest.mark.slow
def test_a_sweep_learns_the_truth_tyres_shape():
    """The front axle's evidence from a sweep on μ 1.0 and on μ 0.5: the truth tyre's own
    normalised shape (the grid member nearest its best Magic Formula fit) is among the shapes
    the evidence keeps (deviance within the 99 % level of two parameters), and shapes far from
    it are excluded."""
    c, e = _truth_shape()

    def dist(k: int) -> float:
        return (LEARN_GRID[k].c - c) ** 2 + ((LEARN_GRID[k].e - e) / 2) ** 2

    near = min(range(2, len(LEARN_GRID)), key=dist)
    both = combine_evidence([_sweep_evidence(1.0), _sweep_evidence(0.5)])
    assert both[near] <= 9.21, (LEARN_GRID[near].name, both[near])
    assert np.sum(both > 9.21) >= 0.2 * len(LEARN_GRID)  # it does tell shapes apart


@pytest.mark.slow
def test_the_learned_shape_carries_to_another_road():
    """Learned on μ 1.0, applied on a μ 0.5 steady circle at 0.95 of the limit, both ways a
    calibration can carry it — the evidence weighting the whole grid (``shape_evidence``) and
    the real-tyre members it leaves possible (``shape_members``, what ``calibrate`` applies):
    the front axle's range holds the truth and states a value within 0.05 of it, and the
    members' range lies within the prior family's (docs/physics.md §15.10)."""
    from gripsense.physics.shape_grid import possible_members

    uv = _vehicle()
    ev = _sweep_evidence(1.0)
    d = simulate_drive("sedan", TYRE, None, 0.5, receiver=RECEIVER, seed=5,
                       circle=(limit_speed(0.5, 40.0, 0.95), 40.0))  # fmt: skip
    truth = float(d.axles.set_index("axle").loc["front", "mu_true"])
    prior = _run(d, uv)[0].summary.set_index("axle").loc["front"]
    tyre = uv.tyres["front"]
    for front in (
        dataclasses.replace(tyre, shape_evidence=tuple(ev)),
        dataclasses.replace(tyre, shape_members=possible_members(ev, tyre.shape)),
    ):
        res, _ = _run(d, dataclasses.replace(uv, tyres={**uv.tyres, "front": front}))
        s = res.summary.set_index("axle").loc["front"]
        assert s["mu_low"] <= truth <= s["mu_high"], (s["mu_low"], truth, s["mu_high"])
        assert s["observable"] and abs(s["mu"] - truth) <= 0.05, (s["mu"], truth)
        assert str(s["shape"]).startswith(("mf ", "brush"))
    assert prior["mu_low"] - 1e-9 <= s["mu_low"] and s["mu_high"] <= prior["mu_high"] + 1e-9
