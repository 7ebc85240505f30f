"""``gripsense calibrate`` learns the curve's shape from a drive that took an axle near its limit
(docs/physics.md §15.10, docs/calibration.md), keeps it per tyre set, and ``friction
--calibration`` uses it. Truth: a PAC2002 sedan tyre (Magic Formula) the estimator never sees."""

from __future__ import annotations

import dataclasses
import re

import numpy as np
import pytest
from scipy.stats import chi2

from gripsense import FrictionRun
from gripsense.config.calibration import Calibration, read_calibration
from gripsense.physics.shape_grid import (
    LEARN_GRID,
    learned_evidence,
    member_evidence,
    possible_members,
)
from gripsense.physics.tyre_curves import SHAPE_FAMILY, shape_members
from gripsense.sim import maneuvers as M
from gripsense.sim.drives import limit_speed, simulate_drive

from .test_calibration import TYRE, _car_toml, _write, invoke


def _named(car_text: str, tyre_set: str) -> str:
    """The vehicle file with both axles' tyres named *tyre_set*."""
    out, n = re.subn(r"^(\[tyre\.(front|rear)\].*\n)", rf'\1tyre_set = "{tyre_set}"\n', car_text,
                     flags=re.M)  # fmt: skip
    assert n == 2
    return out


@pytest.fixture(scope="module")
def learned(tmp_path_factory):
    """A calibration of the summer tyres from one everyday drive and one ISO 4138 sweep past
    the limit on μ 1.0."""
    folder = tmp_path_factory.mktemp("shape")
    car = folder / "car.toml"
    car.write_text(_named(_car_toml(0.0), "summer"), encoding="utf-8")
    every = _write(simulate_drive("sedan", TYRE, M.everyday(60 / 3.6, seed=3), 0.9,
                                  receiver="rtk", seed=3), folder, "everyday")  # fmt: skip
    sweep = M.constant_radius(40.0, 5.0, limit_speed(1.3, 40.0, 1.0), accel_mps2=0.1)
    sweep = _write(simulate_drive("sedan", TYRE, sweep, 1.0, receiver="rtk", seed=1),
                   folder, "sweep")  # fmt: skip
    cal = folder / "car.calibration.toml"
    out = invoke("calibrate", every[0], sweep[0], "--vehicle", car, "-o", cal,
                 "--steer-csv", every[1], "--steer-csv", sweep[1])  # fmt: skip
    return folder, car, cal, every, sweep, out


def test_the_sweep_teaches_the_front_curve(learned):
    """The sweep's front record holds one deviance per shape, 0 at its best; the everyday drive
    (linear range only) none; calibrate says what was learned."""
    _, _, cal, _, _, out = learned
    c = read_calibration(cal)
    front = {d.file: d for d in c.drives if d.axle == "front"}
    assert front["everyday.nmea.gz"].shape is None
    ev = front["sweep.nmea.gz"].shape
    assert ev is not None and ev.shape == (len(LEARN_GRID),) and ev.min() == 0.0
    assert np.sum(ev > chi2.ppf(0.95, 2)) > 0  # it tells shapes apart
    assert all(d.tyre_set == "summer" for d in c.drives)
    assert c.axles["front"].tyre_set == "summer"
    assert "front axle: curve shape learned from 1 drive(s)" in " ".join(out.split())


def test_friction_uses_the_learned_shape_and_never_says_less(learned):
    """A steady circle on μ 0.5 at 0.95 of the limit, with and without the learned shape (the
    same calibration without its shape records): both hold the truth, and the learned range lies
    inside the other (knowing more of the tyre never says less)."""
    folder, car, cal, *_ = learned
    d = simulate_drive("sedan", TYRE, None, 0.5, receiver="rtk", seed=5,
                       circle=(limit_speed(0.5, 40.0, 0.95), 40.0))  # fmt: skip
    log, steer = _write(d, folder, "circle")
    full = read_calibration(cal)
    bare = dataclasses.replace(
        full, drives=[dataclasses.replace(x, shape=None) for x in full.drives]
    )
    run = FrictionRun(car, calibration=full)
    kept = run.vehicle.tyres["front"].shape_members
    assert kept is not None and set(kept) <= set(shape_members("any"))
    with_shape = run.run_log(log, steer_csv=steer).summary.set_index("axle").loc["front"]
    without = FrictionRun(car, calibration=bare).run_log(log, steer_csv=steer)
    without = without.summary.set_index("axle").loc["front"]
    truth = float(d.axles.set_index("axle").loc["front", "mu_true"])
    for s in (with_shape, without):
        assert s["mu_low"] <= truth <= s["mu_high"], (s["mu_low"], truth, s["mu_high"])
    assert with_shape["mu_low"] >= without["mu_low"] - 0.005
    assert with_shape["mu_high"] <= without["mu_high"] + 0.005


def test_new_tyres_are_not_given_the_old_learning(learned, tmp_path):
    """The vehicle file names other tyres: the summer learning (stiffness and shape) is not
    applied, and friction says so; calibrate --update on the new tyres keeps the old drives in
    the file but learns from the new ones only; a drive given again is not counted twice."""
    _folder, _car, cal, every, *_ = learned
    winter = tmp_path / "car.toml"
    winter.write_text(_named(_car_toml(0.0), "winter"), encoding="utf-8")
    run = FrictionRun(winter, calibration=cal)
    declared = FrictionRun(winter).vehicle
    for axle in ("front", "rear"):
        t = run.vehicle.tyres[axle]
        assert t.shape_members is None
        assert t.cornering_stiffness_N_per_rad == declared.tyres[axle].cornering_stiffness_N_per_rad
    said = " ".join(run.calibration_notes)
    assert "learned on tyre set 'summer'" in said and "'winter'" in said
    new = _write(simulate_drive("sedan", TYRE, M.everyday(60 / 3.6, seed=8), 0.9,
                                receiver="rtk", seed=8), tmp_path, "winter-drive")  # fmt: skip
    upd = tmp_path / "winter.calibration.toml"
    out = invoke("calibrate", new[0], every[0], "--vehicle", winter, "--update", cal, "-o", upd,
                 "--steer-csv", new[1], "--steer-csv", every[1])  # fmt: skip
    c = read_calibration(upd)
    old = read_calibration(cal)
    assert len(c.drives) == len(old.drives) + 2  # the new drive's two axles; nothing lost
    assert c.axles["rear"].tyre_set == "winter"
    n_winter = sum(d.bins for d in c.drives if d.axle == "rear" and d.tyre_set == "winter")
    assert c.axles["rear"].bins == n_winter
    flat = " ".join(out.split())
    assert "kept but not learned from" in flat
    assert "everyday.nmea.gz: already in the calibration" in flat


def test_a_shape_record_that_does_not_fit_this_grid_is_refused(learned, tmp_path):
    """A shape record of another length (another gripsense's grid) or with a negative
    deviance: one line naming the file and the key, exit 2."""
    _folder, car, cal, every, *_ = learned
    text = cal.read_text(encoding="utf-8")
    for bad in ("shape = [0, 1, 2]", "shape = [" + ", ".join(["-1"] + ["0"] * 140) + "]"):
        broken = tmp_path / "broken.calibration.toml"
        broken.write_text(re.sub(r"shape = \[[^\]]*\]", bad, text, count=1), encoding="utf-8")
        out = invoke("friction", every[0], "--vehicle", car, "--steer-csv", every[1],
                     "--calibration", broken, "-o", tmp_path / "res", code=2)  # fmt: skip
        assert "broken.calibration.toml" in out and "shape" in out
        assert "Traceback" not in out


def test_drives_that_disagree_on_the_shape_are_covered_not_blended():
    """Two learnings whose best shapes no common shape explains at 2σ: the envelope (each
    shape as good as its best drive says), flagged; two that agree: their sum."""
    n = len(LEARN_GRID)
    a, b = np.full(n, 50.0), np.full(n, 50.0)
    a[10], b[100] = 0.0, 0.0
    a[100], b[10] = 40.0, 40.0
    env, disagree = learned_evidence([a, b])
    assert disagree and env[10] == env[100] == 0.0
    a[100], b[10] = 1.0, 1.0  # a shape both allow
    total, disagree = learned_evidence([a, b])
    assert not disagree and total[10] == total[100] == 0.0 and total[50] == 99.0
    # the level: the sum's minimum against χ² of 2 (n − 1) degrees of freedom at 2σ
    edge = chi2.ppf(0.954, 2)
    a[100], b[10] = edge - 0.01, edge - 0.01
    assert not learned_evidence([a, b])[1]
    a[100], b[10] = edge + 0.01, edge + 0.01
    assert learned_evidence([a, b])[1]


def test_learning_only_removes_members_of_the_prior_family():
    """Flat evidence keeps every member the tyre's ``shape`` allows; evidence for one Magic
    Formula shape keeps the members near it (the best always) and removes the far ones, within
    the prior (a category's members stay within the category)."""
    n = len(LEARN_GRID)
    for prior in ("any", "passenger", "brush"):
        assert possible_members(np.zeros(n), prior) == shape_members(prior)
    k = next(i for i, s in enumerate(LEARN_GRID) if s.name == "mf C1.4 E-0.4")
    peaked = np.full(n, 400.0)
    peaked[k] = 0.0
    for prior in ("any", "passenger"):
        kept = possible_members(peaked, prior)
        assert set(kept) < set(shape_members(prior)) and kept
        members, carried = member_evidence(peaked, prior)
        assert members[np.argmin(carried)] in kept
        names = {SHAPE_FAMILY[i].name for i in kept}
        assert "brush-4" not in names  # far from C 1.4, E −0.4
        assert any(abs(SHAPE_FAMILY[i].c - 1.4) <= 0.1 for i in kept)


def test_a_calibration_without_shapes_leaves_the_prior_family():
    """No drive took the axle near its limit: the tyre keeps its ``shape`` prior."""
    from gripsense.config.calibration import apply_calibration
    from gripsense.sim.drives import truth_vehicle, user_vehicle

    uv = user_vehicle(truth_vehicle("sedan"), TYRE)
    v = apply_calibration(uv, Calibration(uv.name, {}))
    assert all(t.shape_members is None for t in v.tyres.values())


def test_a_limit_drive_on_a_slippery_road_does_not_bend_the_stiffness(tmp_path):
    """A sweep past the limit on μ 0.3 added to two everyday drives: it teaches both axles'
    shape and leaves the stiffness the everyday drives learned (its bins up to 0.3 g, the top
    of the everyday range, lie at this road's limit: in the linear-range fit the front axle's
    fit failed and the rear's moved by a third)."""
    from gripsense.pipeline import learn_calibration
    from gripsense.sim.drives import truth_vehicle, user_vehicle

    uv = user_vehicle(truth_vehicle("sedan"), TYRE, stiffness_error=-0.1,
                      stiffness_uncertainty=0.2)  # fmt: skip
    every = [_write(simulate_drive("sedan", TYRE, M.everyday(60 / 3.6, seed=i), 0.9,
                                   receiver="rtk", seed=i), tmp_path, f"e{i}")
             for i in range(2)]  # fmt: skip
    m = M.constant_radius(40.0, 3.0, limit_speed(0.39, 40.0, 1.0), accel_mps2=0.1)
    sweep = _write(simulate_drive("sedan", TYRE, m, 0.3, receiver="rtk", seed=5), tmp_path, "sw")
    base = learn_calibration([e[0] for e in every], uv, receiver="rtk",
                             steer_csvs=[e[1] for e in every])  # fmt: skip
    both = learn_calibration([sweep[0]], uv, receiver="rtk", steer_csvs=[sweep[1]],
                             previous=base)  # fmt: skip
    taught = {d.axle for d in both.drives if d.file == "sw.nmea.gz" and d.shape is not None}
    assert taught == {"front", "rear"}
    for axle in ("front", "rear"):
        a, b = base.axles[axle], both.axles[axle]
        assert b.scale == a.scale and b.bins == a.bins, (axle, a, b)


@pytest.mark.parametrize("keep", ["brush-4", "mf C1.38 E0.14"])
def test_learned_members_never_say_more_than_the_prior_family_allows(tmp_path, keep):
    """Whatever members a calibration leaves (here one, far from the truth tyre or near it), an
    axle's range on a steady circle lies within the prior family's, a value the family gives is
    kept, and a note says when the learned shapes and the drive do not meet."""
    from gripsense.sim.drives import truth_vehicle, user_vehicle

    uv = user_vehicle(truth_vehicle("sedan"), TYRE)
    d = simulate_drive("sedan", TYRE, None, 0.5, receiver="rtk", seed=7,
                       circle=(limit_speed(0.5, 40.0, 0.93), 40.0))  # fmt: skip
    log, steer = _write(d, tmp_path, "circle")
    k = next(i for i, s in enumerate(SHAPE_FAMILY) if s.name == keep)
    one = {a: dataclasses.replace(t, shape_members=(k,)) for a, t in uv.tyres.items()}
    prior = FrictionRun(uv, receiver="rtk").run_log(log, steer_csv=steer).summary
    learned = FrictionRun(dataclasses.replace(uv, tyres=one), receiver="rtk")
    learned = learned.run_log(log, steer_csv=steer).summary
    for p, s in zip(prior.itertuples(), learned.itertuples(), strict=True):
        assert p.mu_low - 1e-9 <= s.mu_low <= s.mu_high <= p.mu_high + 1e-9, (keep, p, s)
        assert s.observable or not p.observable  # a value the family gives is not lost
        if "learned curve shape does not fit" in s.limited_by:
            assert (s.mu_low, s.mu_high) == (p.mu_low, p.mu_high)


def test_an_axle_learned_alone_keeps_its_own_stiffness_uncertainty(tmp_path):
    """A calibration that learned the rear only (no steering channel): the rear's prior is its
    own learned 1σ, not the front's declared ±20 % — and on a steady circle at 0.9 of the limit
    its range lies within the one the ±20 % prior gives (knowing more never says less)."""
    from gripsense.estimate.noise import NoiseModel
    from gripsense.estimate.profile import axle_priors
    from gripsense.sim.drives import truth_vehicle, user_vehicle

    uv = user_vehicle(truth_vehicle("sedan"), TYRE, stiffness_uncertainty=0.2)
    rear = dataclasses.replace(uv.tyres["rear"], stiffness_uncertainty=0.03)
    known = dataclasses.replace(uv, tyres={**uv.tyres, "rear": rear})
    noise = NoiseModel.for_vehicle(known, "rtk")
    assert axle_priors(known, "rear", noise).sd[0] == pytest.approx(np.log1p(0.03))
    assert axle_priors(known, "front", noise).sd[0] == pytest.approx(np.log1p(0.2))
    d = simulate_drive("sedan", TYRE, None, 0.6, receiver="rtk", seed=11,
                       circle=(limit_speed(0.6, 40.0, 0.9), 40.0))  # fmt: skip
    log, steer = _write(d, tmp_path, "circle")
    wide, narrow = (FrictionRun(v, receiver="rtk").run_log(log, steer_csv=steer).summary
                    .set_index("axle").loc["rear"] for v in (uv, known))  # fmt: skip
    truth = float(d.axles.set_index("axle").loc["rear", "mu_true"])
    assert narrow["mu_low"] <= truth <= narrow["mu_high"]
    assert wide["mu_low"] - 1e-9 <= narrow["mu_low"] and narrow["mu_high"] <= wide["mu_high"] + 0.01
