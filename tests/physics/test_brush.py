"""Brush inversion: published worked numbers, round trips, limits, input types.

Reference numbers: docs/physics.md §1.4 tables (computed there independently with the exact model)
and §2.5 (model dependence); seed 000 eq. (4.15).
"""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest
from scipy.optimize import brentq

from gripsense.physics import brush

G0 = 9.80665
# docs/physics.md §1.4 example: m = 240 kg, l = 0.134 m, w = 0.185 m, v = 25 km/h, R = 25 m
M, L, W = 240.0, 0.134, 0.185
FZ = M * G0
F = M * (25 / 3.6) ** 2 / 25.0


def _beta_true(mu, C):
    """Slip angle at which the exact parabolic brush model carries F cos β (thesis eq. 4.5),
    written independently (Fiala); returns (β, the force at β)."""

    def resid(b):
        th = C * np.tan(b) / (3 * mu * FZ)
        return mu * FZ * (1 - (1 - min(th, 1.0)) ** 3) - F * np.cos(b)

    b = brentq(resid, 1e-7, 0.3, xtol=1e-15)
    return b, F * np.cos(b)


# (μ_true, β_true°, μ̂(β+0.1°), μ̂(β−0.1°), μ̂(β+0.75°), thesis 4.15 on β_true) for G = 5e7
TABLE_G5E7 = [
    (0.3, 0.437, 0.228, 1.295, 0.197, 0.333),
    (0.6, 0.3625, 0.271, None, 0.197, 0.626),
    (0.9, 0.346, 0.288, None, 0.197, 0.924),
    (1.2, 0.339, 0.298, None, 0.197, 1.224),
]
# (μ_true, β_true°, κ_β, μ̂(β+0.1°), μ̂(β−0.1°), μ̂(β+0.75°)) for G = 1e7
TABLE_G1E7 = [
    (0.3, 2.182, -2.06, 0.276, 0.334, 0.215),
    (0.6, 1.811, -6.75, 0.448, 1.020, 0.238),
    (0.9, 1.729, -11.35, 0.564, 3.308, 0.246),
    (1.2, 1.692, -15.9, 0.647, None, 0.251),
]


def _mu(force, beta_deg, C, **kw):
    return brush.mu_from_force(force, np.deg2rad(beta_deg), FZ, C, **kw)


@pytest.mark.parametrize("row", TABLE_G5E7)
def test_physics_worked_table_g5e7(row):
    mu_t, b_t, plus, minus, plus75, thesis = row
    C = brush.cornering_stiffness(5e7, W, L)
    assert C == pytest.approx(83047, abs=1)
    b, f = _beta_true(mu_t, C)
    b = np.rad2deg(b)
    assert b == pytest.approx(b_t, abs=5e-4)
    assert _mu(f, b, C)[0] == pytest.approx(mu_t, rel=1e-9)
    assert _mu(f, b + 0.1, C)[0] == pytest.approx(plus, abs=1e-3)
    m, st = _mu(f, b - 0.1, C)
    if minus is None:
        assert st == "no_solution" and np.isnan(m)
    else:
        assert m == pytest.approx(minus, abs=1e-3)
    m, st = _mu(f, b + 0.75, C)
    assert st == "full_sliding" and m == pytest.approx(plus75, abs=1e-3)
    assert _mu(f, b, C, model="thesis")[0] == pytest.approx(thesis, abs=1e-3)


@pytest.mark.parametrize("row", TABLE_G1E7)
def test_physics_worked_table_g1e7(row):
    mu_t, b_t, kap, plus, minus, plus75 = row
    C = brush.cornering_stiffness(1e7, W, L)
    b, f = _beta_true(mu_t, C)
    b = np.rad2deg(b)
    assert b == pytest.approx(b_t, abs=5e-4)
    # printed to 3 significant figures
    assert brush.kappa_beta(f, np.deg2rad(b), FZ, C) == pytest.approx(kap, abs=0.051)
    assert _mu(f, b + 0.1, C)[0] == pytest.approx(plus, abs=1e-3)
    m, st = _mu(f, b - 0.1, C)
    assert (st == "no_solution") if minus is None else m == pytest.approx(minus, abs=1e-3)
    assert _mu(f, b + 0.75, C)[0] == pytest.approx(plus75, abs=1e-3)
    assert _mu(f, b - 0.75, C)[1] == "no_solution"  # "β − 0.75° gives no solution in every row"


def test_model_dependence_physics_2_5():
    """Data from the exact P4 model (μ = 0.9, θ = 0.0765) read by other models (physics §2.5)."""
    C = brush.cornering_stiffness(5e7, W, L)

    def resid(b):
        return brush.lateral_force(0.9, b, FZ, C, pressure="quartic", model="exact") - F

    b = brentq(resid, 1e-7, 0.2, xtol=1e-15)
    assert C * np.tan(b) / (3 * 0.9 * FZ) == pytest.approx(0.0765, abs=5e-4)
    assert brush.mu_from_force(F, b, FZ, C)[0] == pytest.approx(1.404, abs=2e-3)
    assert brush.mu_from_force(F, b, FZ, C, model="thesis")[0] == pytest.approx(1.428, abs=2e-3)
    assert brush.mu_from_force(F, b, FZ, C, pressure="quartic", model="thesis")[0] == (
        pytest.approx(0.943, abs=2e-3)
    )
    k = brush.kappa_beta(F, b, FZ, C, pressure="quartic")
    assert k == pytest.approx(-17.7, abs=0.1)  # docs/physics.md §2.3: worse than P2's −11.4


@pytest.mark.parametrize(
    ("pressure", "model"),
    [("parabolic", "exact"), ("parabolic", "thesis"), ("quartic", "exact"), ("quartic", "thesis")],
)
def test_round_trip(pressure, model):
    rng = np.random.default_rng(7)
    n = 2000
    mu = rng.uniform(0.1, 1.5, n)
    fz = rng.uniform(1000, 8000, n)
    C = rng.uniform(2e4, 2e5, n)
    b = rng.uniform(1e-4, 0.1, n)
    f = brush.lateral_force(mu, b, fz, C, pressure=pressure, model=model)
    out = brush.invert(f, b, fz, C, pressure=pressure, model=model)
    ok = out["status"] == brush.OK
    assert ok.mean() > 0.4
    np.testing.assert_allclose(out["mu"][ok], mu[ok], rtol=1e-9)
    # the samples not returned are exactly those at or past the model's sliding limit
    th = C * np.tan(b) / (3 * mu * fz)
    limit = {
        ("parabolic", "exact"): 1.0,
        ("quartic", "exact"): 5 / 3,
        ("parabolic", "thesis"): 0.5,
        ("quartic", "thesis"): 5 / 12,
    }[(pressure, model)]
    assert np.all(th[~ok] >= limit * (1 - 1e-6))


def test_limits():
    C, fz, b = 8e4, 3000.0, 0.01
    T = C * np.tan(b)
    # r -> 1: μ grows without bound (zero information)
    mus = [brush.mu_from_force(T * (1 - e), b, fz, C)[0] for e in (1e-2, 1e-4, 1e-6)]
    assert mus[0] < mus[1] < mus[2] and mus[2] > 1e4
    assert brush.mu_from_force(T, b, fz, C) == (pytest.approx(np.nan, nan_ok=True), "no_solution")
    assert brush.mu_from_force(1.2 * T, b, fz, C)[1] == "no_solution"
    # full sliding: r <= 1/3 (exact P2), 1/5 (exact P4); μ = F/Fz
    m, st = brush.mu_from_force(0.3 * T, b, fz, C)
    assert st == "full_sliding" and m == pytest.approx(0.3 * T / fz)
    assert brush.mu_from_force(0.25 * T, b, fz, C, pressure="quartic")[1] == "ok"
    assert brush.mu_from_force(0.19 * T, b, fz, C, pressure="quartic")[1] == "full_sliding"
    # thesis formula at r -> 1 agrees with the exact one (μ_exact = μ_thesis (1 + q)/2)
    me = brush.mu_from_force(0.999 * T, b, fz, C)[0]
    mt = brush.mu_from_force(0.999 * T, b, fz, C, model="thesis")[0]
    assert me / mt == pytest.approx((1 + np.sqrt((4 * 0.999 - 1) / 3)) / 2, rel=1e-12)
    # β -> 0, non-positive load or stiffness, NaN: invalid
    for args in ((100.0, 0.0, fz, C), (100.0, b, 0.0, C), (100.0, b, fz, -1.0), (np.nan, b, fz, C)):
        assert brush.mu_from_force(*args)[1] == "invalid"


def test_quartic_slide_point_closed_form_matches_roots():
    for th in np.linspace(0.0, 5 / 3, 40):
        xi = brush.slide_point(th, pressure="quartic")
        # (1 − ξ)(ξ² − ξ + ½) − 0.3θ = −ξ³ + 2ξ² − 1.5ξ + 0.5 − 0.3θ
        roots = np.roots([-1.0, 2.0, -1.5, 0.5 - 0.3 * th])
        real = roots[np.abs(roots.imag) < 1e-9].real
        assert real.size == 1  # h′ < 0: exactly one real root
        assert xi == pytest.approx(real[0], abs=1e-12)


def test_input_types_and_nan():
    C, fz = 8e4, 3000.0
    b = [0.005, 0.01, np.nan]
    f = [300.0, 600.0, 600.0]
    mu_l, _ = brush.mu_from_force(f, b, fz, C)
    mu_a, st_a = brush.mu_from_force(np.array(f), np.array(b), fz, C)
    s = pd.Series(f, index=[10, 11, 12])
    mu_s, _ = brush.mu_from_force(s, pd.Series(b, index=s.index), fz, C)
    np.testing.assert_array_equal(mu_l, mu_a)
    assert isinstance(mu_s, pd.Series) and list(mu_s.index) == [10, 11, 12]
    np.testing.assert_array_equal(mu_s.to_numpy(), mu_a)
    assert list(st_a) == ["ok", "ok", "invalid"] and np.isnan(mu_a[2])
    m0, st0 = brush.mu_from_force(300.0, 0.005, fz, C)
    assert isinstance(m0, float) and isinstance(st0, str) and m0 == mu_a[0]
    with pytest.raises(ValueError, match="pressure"):
        brush.mu_from_force(1.0, 0.01, fz, C, pressure="cubic")


def test_trail_table_of_physics_md_16_1():
    """docs/physics.md §16.1's table (u, r = F/(C tan α), t/t₀) from the code's force and trail:
    the slip angle that gives utilisation u is found on the force, then the trail read there."""
    mu, fz, c, a = 0.9, 4000.0, 60000.0, 0.07
    table = {0.3: (0.89, 0.78), 0.5: (0.81, 0.62), 0.7: (0.71, 0.42), 0.9: (0.56, 0.18)}
    for u, (r_doc, t_doc) in table.items():
        alpha = brentq(lambda b, u=u: brush.lateral_force(mu, b, fz, c) / (mu * fz) - u, 1e-9, 0.3)
        r = brush.lateral_force(mu, alpha, fz, c) / (c * np.tan(alpha))
        _, t = brush.aligning_moment(mu, alpha, fz, c, a)
        assert abs(float(r) - r_doc) <= 0.0051
        assert abs(float(t) / (a / 3) - t_doc) <= 0.0051
