"""The trail-shape family (docs/physics.md §16.5) against the tyres it must cover: the shipped
Magic Formula files' own aligning moments (MFeval-exact, tests/physics/test_magic_formula.py) and
the brush closed form — none of them used to build it."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from gripsense.config.tyre_files import load_mf_tyre
from gripsense.physics.brush import aligning_moment, lateral_force
from gripsense.physics.trail_shapes import TRAIL_FAMILY, trail_ratio, trail_shape_ids

TIR = Path(__file__).parents[1] / "data" / "tyre" / "tir"
U = np.linspace(0.05, 0.97, 40)


def _closest(tau: np.ndarray, ids=None) -> float:
    members = [TRAIL_FAMILY[i] for i in (range(len(TRAIL_FAMILY)) if ids is None else ids)]
    return min(float(np.max(np.abs(trail_ratio(U, s.p, s.tau1) - tau))) for s in members)


def _mf_trail(path: Path, load_factor: float) -> np.ndarray:
    """t/t₀ of a file over the utilisation of its rising side (left and right averaged, which
    removes the residual moment's and the shifts' asymmetry)."""
    tyre = load_mf_tyre(path)
    fz = tyre.params["FNOMIN"] * load_factor
    a = np.deg2rad(np.linspace(0.01, 25, 5000))
    neg, pos = tyre.aligning_moment(fz, 0, -a), tyre.aligning_moment(fz, 0, a)
    fy, mz = 0.5 * (neg.fy - pos.fy), 0.5 * (neg.mz - pos.mz)
    ip = int(np.argmax(fy))
    xi = (mz / fy)[: ip + 1]
    return np.interp(U, fy[: ip + 1] / fy[ip], xi / xi[0])


@pytest.mark.parametrize(
    "name",
    ["FSAE_Defaults", "MagicFormula61_Paramerters", "PacejkaBook_Defaults", "Sedan_Pac02Tire",
     "mf_185_80R14", "335_65R22_5_G275MSA_40psi"],
)  # fmt: skip
@pytest.mark.parametrize("load_factor", [0.5, 1.0, 1.5])
def test_mf_files_lie_within_the_form_error(name, load_factor):
    """Every file at 0.5–1.5 × its nominal load is within 0.065 of a member with p ≥ 1.9 (the
    ``magic-formula`` family); the estimator's TRAIL_FORM_REL (0.05 of t₀) is that error's 1σ."""
    tau = _mf_trail(TIR / f"{name}.tir", load_factor)
    assert _closest(tau, trail_shape_ids("magic-formula")) <= 0.065
    if load_factor == 1.0:  # docs/physics.md §16.5: at half the grip 0.82–0.93 of t₀ is left
        assert 0.815 <= float(np.interp(0.5, U, tau)) <= 0.935


def test_brush_trail_is_in_the_brush_family():
    mu, fz, c, a = 0.9, 4000.0, 60000.0, 0.07
    alpha = np.arctan(np.linspace(1e-4, 0.999, 400) * 3 * mu * fz / c)
    u = lateral_force(mu, alpha, fz, c) / (mu * fz)
    tau = np.interp(U, u, aligning_moment(mu, alpha, fz, c, a)[1] / (a / 3))
    assert _closest(tau, trail_shape_ids("brush")) <= 0.06
    assert float(np.interp(0.5, U, tau)) == pytest.approx(0.62, abs=0.005)  # §16.5
    assert _closest(tau, trail_shape_ids("magic-formula")) > 0.1  # a real tyre is not a brush


def test_family_limits():
    assert trail_ratio(0.0, 3.0, 0.2) == 1.0 and trail_ratio(1.0, 3.0, 0.2) == pytest.approx(0.2)
    assert trail_ratio(1.7, 3.0, 0.2) == trail_ratio(1.0, 3.0, 0.2)  # past the peak: clipped
    assert len(trail_shape_ids("any")) == len(TRAIL_FAMILY)


def test_fit_recovers_a_member():
    """A curve of the family's own form is fitted back exactly."""
    from gripsense.physics.trail_shapes import fit_trail_shape

    shape, err = fit_trail_shape(U, trail_ratio(U, 2.7, 0.33))
    assert (shape.p, shape.tau1) == pytest.approx((2.7, 0.33), abs=2e-3) and err < 2e-3


@pytest.mark.parametrize("name", ["MagicFormula61_Paramerters", "PacejkaBook_Defaults"])
def test_a_known_tyres_trail(name):
    """tyre_trail_ratio gives the file's trail (this module's own evaluation, on another slip
    grid); its fitted member is within 0.03 of it (docs/physics.md §16.7)."""
    from gripsense.physics.trail_shapes import fit_trail_shape, tyre_trail_ratio

    tyre = load_mf_tyre(TIR / f"{name}.tir")
    tau, xi0 = tyre_trail_ratio(tyre, tyre.params["FNOMIN"], U)
    assert np.max(np.abs(tau - _mf_trail(TIR / f"{name}.tir", 1.0))) < 0.01
    # the zero-slip lever: the moment per force of a small slip, on both sides
    a = np.deg2rad(0.05)
    m = tyre.aligning_moment(tyre.params["FNOMIN"], 0, np.array([-a, a]))
    assert xi0 == pytest.approx(-(m.mz[0] - m.mz[1]) / (m.fy[0] - m.fy[1]), rel=0.01)
    assert 0.01 < xi0 < 0.08
    shape, err = fit_trail_shape(U, tau)
    assert err <= 0.03
    assert np.max(np.abs(trail_ratio(U, shape.p, shape.tau1) - tau)) == pytest.approx(err)


@pytest.mark.parametrize(
    ("name", "low", "high"),
    [("MagicFormula61_Paramerters", 1.0, 1.1), ("PacejkaBook_Defaults", 0.95, 1.05),
     ("Sedan_Pac02Tire", 0.88, 0.96)],
)  # fmt: skip
def test_a_known_tyres_trail_grows_with_load(name, low, high):
    """docs/physics.md §16.7: the files' zero-slip lever grows about in proportion to the load
    (x = 1.06, 1.00, 0.92 over 0.5–1.5 × the sedan's static front load, against the family's
    0.75). trail_family's fit over five loads against the two-point slope of the file's own
    moment at a small slip."""
    import dataclasses

    from gripsense.estimate.torque import trail_family
    from gripsense.sim.drives import truth_vehicle

    veh = truth_vehicle("sedan")
    tir = TIR / f"{name}.tir"
    known = trail_family(
        dataclasses.replace(veh, steering=dataclasses.replace(veh.steering, tyre_file=str(tir)))
    )
    tyre, a = load_mf_tyre(tir), np.deg2rad(np.array([-0.05, 0.05]))

    def lever(fz):
        m = tyre.aligning_moment(fz, 0, a)
        return -(m.mz[0] - m.mz[1]) / (m.fy[0] - m.fy[1])

    fz = veh.static_load("front")
    two_point = np.log(lever(1.5 * fz) / lever(0.5 * fz)) / np.log(3.0)
    assert low <= known.load_exponent <= high
    assert known.load_exponent == pytest.approx(two_point, abs=0.05)
    assert known.t0_m == pytest.approx(lever(fz), rel=0.01)
    assert known.form_rel <= 0.03 + 1e-12
