"""Estimation by stage: one registry of estimator objects, the shared kinematics computed once,
and no stage computed to be thrown away.

The per-sample stage is checked against the brush inversion written out here from
``gripsense.physics.brush`` (a second path to the same numbers: the kinematics' columns fed to
``brush.invert``), and the window estimator's wheel table against the per-sample one: the same
kinematics, no μ, every steady-cornering sample ``per_axle``.
"""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from gripsense import FrictionRun
from gripsense.demo import demo_dir
from gripsense.errors import InputError
from gripsense.estimate import ESTIMATORS, FLAGS, Estimator, get_estimator
from gripsense.estimate.friction import friction_from_motion
from gripsense.estimate.wheels import NOT_STEADY_CORNERING, motion_from_epochs
from gripsense.io import read_nmea
from gripsense.io.sensors.steer import read_steer_csv, steer_at
from gripsense.physics import brush

DEMO = demo_dir()


@pytest.fixture(scope="module")
def motion():
    run = FrictionRun(DEMO / "vehicle.toml", method="brush-2")
    ep = read_nmea(DEMO / "case022.nmea.gz").epochs
    ch = read_steer_csv(DEMO / "case022_steer.csv", steering_ratio=run.vehicle.steering_ratio)
    steer = steer_at(ch, ep["t_s"].to_numpy())
    m, _ = motion_from_epochs(ep, run.vehicle, options=run.options, steer_rad=steer)
    return run, m


def test_one_registry_of_objects_that_describe_themselves():
    assert set(ESTIMATORS) >= {"axle-window", "brush-2", "brush-4", "thesis-2", "thesis-4"}
    for name, est in ESTIMATORS.items():
        assert isinstance(est, Estimator) and est.name == name
        assert est.description and est.assumptions
        # a per-window estimator has an online form; a per-sample one recomputes its window
        assert (est.online.__func__ is not Estimator.online) == est.per_window
    with pytest.raises(InputError, match="use one of"):
        get_estimator("brush-3")


def test_window_estimator_computes_no_per_sample_mu(motion):
    run, m = motion
    per_sample, _ = friction_from_motion(m, run.vehicle, method="brush-2", options=run.options)
    window, meta = friction_from_motion(m, run.vehicle, method="axle-window", options=run.options)
    assert meta["method"] == "axle-window"
    # the same kinematics, row for row
    shared = [
        "t_s",
        "epoch",
        "wheel",
        "slip_angle_rad",
        "load_N",
        "force_N",
        "grip_used",
        "axle_force_N",
        "cornering_stiffness_N_per_rad",
        "slip_sigma_rad",
        "utilisation",
    ]
    pd.testing.assert_frame_equal(per_sample[shared], window[shared])
    # no brush inversion: nothing that would contradict the per-axle μ
    for c in ("mu", "mu_sigma", "kappa_beta", "slide_point_m", "force_ratio"):
        assert window[c].isna().all(), c
    # a steady-cornering sample is per_axle, never "ok" nor a brush flag; the kinematics' own
    # flags are the per-sample estimator's
    kin = per_sample["flag"].isin([*NOT_STEADY_CORNERING, "wheel_lifted"]).to_numpy()
    assert (window["flag"].to_numpy()[kin] == per_sample["flag"].to_numpy()[kin]).all()
    assert (window["flag"][~kin] == "per_axle").all() and (~kin).sum() > 100
    assert set(window["flag"].cat.categories) == set(FLAGS)


def test_per_sample_stage_is_the_brush_inversion(motion):
    run, m = motion
    w, _ = friction_from_motion(m, run.vehicle, method="brush-4", options=run.options)
    inv = brush.invert(
        w["force_N"].to_numpy(),
        w["slip_angle_rad"].to_numpy(),
        w["load_N"].to_numpy(),
        w["cornering_stiffness_N_per_rad"].to_numpy(),
        pressure="quartic",
        model="exact",
    )
    ok = (w["flag"] == "ok").to_numpy()
    assert ok.sum() > 20
    np.testing.assert_allclose(w["mu"].to_numpy()[ok], inv["mu"][ok], rtol=1e-12)
    np.testing.assert_allclose(w["kappa_beta"].to_numpy(), inv["kappa_beta"], rtol=1e-12)
    # a brush flag only where the kinematics found steady cornering
    brush_flags = w["flag"].isin(["ill_conditioned", "full_sliding", "no_solution"]).to_numpy()
    assert not w["flag"][brush_flags].isin(NOT_STEADY_CORNERING).any()
    assert brush_flags.sum() > 0
