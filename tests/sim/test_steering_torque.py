"""The simulator's steering-torque channel (docs/physics.md §16.3–16.4) against hand
calculations: at small utilisation the trail is its zero-slip value, so the column torque of a
steady circle is (t_c + t₀) ΣF_front/(i_s (1 + g)) (friction set to zero: its value depends on
the steer history, which the Dahl model's own test covers)."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from gripsense.config.tyre_files import load_mf_tyre
from gripsense.constants import G0
from gripsense.data import sample_path
from gripsense.errors import InputError
from gripsense.sim import maneuvers as M
from gripsense.sim.drives import truth_tyre, truth_vehicle
from gripsense.sim.steering_torque import aligning_moments, emulate_torque
from gripsense.sim.vehicle import SimParams


def _circle(tyre: str | None, speed: float, mu: float = 0.9):
    veh = truth_vehicle("sedan")
    t = truth_tyre(tyre) if tyre else None
    p = SimParams.from_vehicle(
        veh, relaxation_length_m=0.5, sim_tyres={} if t is None else {"front": t, "rear": t}
    )
    res = M.run(p, M.circle(speed, 40.0, laps=0.6, params=p), mu=mu)
    return veh, res


def _steady(res):
    n = len(res.body)
    return slice(int(0.75 * n), n)


def test_small_utilisation_torque_by_hand():
    """Brush tyres: t₀ = l/6 from the contact length at each wheel's load (§16.1)."""
    veh, res = _circle(None, 5.5)  # 0.08 g: u ≈ 0.07
    s = dataclasses.replace(veh.steering, friction_Nm=0.0)
    tq = emulate_torque(res, s, veh.steering_ratio, noise_Nm=0.0)
    sel = _steady(res)
    w = res.wheels
    hand = np.zeros(len(res.body))
    for name in ("front_left", "front_right"):
        r = w[w["wheel"] == name]
        f, fz = r["force_N"].to_numpy(), r["load_N"].to_numpy()
        t0 = veh.tyres["front"].contact_length(fz / G0) / 6.0
        hand += (s.mechanical_trail_m + t0) * f
    g = s.assist_gain
    expected = hand / (veh.steering_ratio * (1 + g))
    got = tq["torque_Nm"].to_numpy()[sel]
    # at u ≈ 0.07 the trail is within ~5 % of t₀ (§16.1: t/t₀ ≈ 1 − 2u/3)
    assert np.mean(got) == pytest.approx(np.mean(expected[sel]), rel=0.06)
    assert np.mean(got) < np.mean(expected[sel])  # the trail has begun to fall, never risen


def test_mf_aligning_moment_is_the_files():
    """On a road of the file's own friction (similarity factor 1) the tabulated aligning moment
    of each front wheel is the MF equations' at its slip angle, load and inclination."""
    mf = load_mf_tyre(sample_path("tyres/MagicFormula61_Paramerters.tir"))
    _veh, res = _circle("mf61", 14.0, mu=truth_tyre("mf61").mu_ref)
    mz = aligning_moments(res)
    sel = _steady(res)
    w = res.wheels
    for name in ("front_left", "front_right"):
        r = w[w["wheel"] == name].iloc[sel]
        direct = mf.aligning_moment(
            r["load_N"].to_numpy(), 0.0, r["slip_angle_rad"].to_numpy(), r["camber_rad"].to_numpy()
        ).mz
        np.testing.assert_allclose(mz[name].to_numpy()[sel], direct, rtol=0.02, atol=0.3)


def test_torque_falls_behind_the_force_near_the_limit():
    """Torque per unit front force falls as the utilisation rises past ~0.4 (§16.1; below,
    the MF 6.1 file's residual moment, a constant, makes the ratio rise first)."""
    ratios = []
    for v in (12.0, 15.5, 17.5):
        veh, res = _circle("mf61", v)
        s = dataclasses.replace(veh.steering, friction_Nm=0.0)
        tq = emulate_torque(res, s, veh.steering_ratio, noise_Nm=0.0)
        sel = _steady(res)
        w = res.wheels
        f = sum(
            w.loc[w["wheel"] == n, "force_N"].to_numpy()[sel] for n in ("front_left", "front_right")
        )
        ratios.append(np.mean(tq["torque_Nm"].to_numpy()[sel]) / np.mean(f))
    assert ratios[0] > ratios[1] > ratios[2]
    assert ratios[2] < 0.85 * ratios[0]


def test_sensor_errors_and_assist_channel():
    veh, res = _circle(None, 10.0)
    clean = emulate_torque(res, veh.steering, veh.steering_ratio, noise_Nm=0.0)
    bad = emulate_torque(
        res, veh.steering, veh.steering_ratio, noise_Nm=0.0, scale_error=0.1, offset_Nm=0.3,
        assist_channel=True,
    )  # fmt: skip
    np.testing.assert_allclose(bad["torque_Nm"], 1.1 * clean["torque_Nm"] + 0.3)
    np.testing.assert_allclose(bad["assist_Nm"], veh.steering.assist_gain * clean["torque_Nm"])
    fast = emulate_torque(res, veh.steering, veh.steering_ratio, rate_hz=50.0)
    assert len(fast) == len(clean[::2])


def test_a_tyre_without_aligning_moment_is_refused():
    _veh, res = _circle(None, 10.0)
    quartic = dataclasses.replace(
        res.params,
        tyres={k: dataclasses.replace(t, pressure="quartic") for k, t in res.params.tyres.items()},
    )
    with pytest.raises(InputError, match="parabolic"):
        aligning_moments(dataclasses.replace(res, params=quartic))


def test_trail_by_utilisation_is_the_files():
    """The trail added to another vehicle model's forces: at a utilisation u of the file's own
    peak, the MF equations' M_z/F_y where the pure-slip force reaches u of its peak (left and
    right averaged), within 3 %."""
    from scipy.optimize import brentq

    mf = load_mf_tyre(sample_path("tyres/Sedan_Pac02Tire.tir"))
    st = truth_tyre("mf-sedan")
    fz = 4000.0
    a = np.deg2rad(np.linspace(0.01, 25, 5000))

    def sym(alpha):
        neg, pos = mf.aligning_moment(fz, 0, -alpha), mf.aligning_moment(fz, 0, alpha)
        return 0.5 * (neg.fy - pos.fy), 0.5 * (pos.mz - neg.mz)  # both positive

    fy_all, _ = sym(a)
    peak = float(fy_all.max())
    a_peak = float(a[np.argmax(fy_all)])
    for u in (0.3, 0.6, 0.9):
        alpha = brentq(lambda x, u=u: sym(x)[0] / peak - u, 1e-5, a_peak)
        fy, mz = sym(alpha)
        assert st.trail_by_utilisation(u, fz) == pytest.approx(mz / fy, rel=0.03)
