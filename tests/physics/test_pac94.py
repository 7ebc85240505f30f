"""Seed-002 / PAC94 a0..a17 formula: Jacobian vs sympy, closed forms, variants."""

from __future__ import annotations

import numpy as np
import pytest
import sympy as sp

from gripsense.physics.magic_formula.pac94 import pac94_lateral, pac94_lateral_native

A_TYPICAL = np.array(
    [
        1.4,
        -22.1,
        1011.0,
        1078.0,
        1.82,
        0.208,
        0.0,
        -0.354,
        0.707,
        0.028,
        0.0,
        13.8,
        -0.10,
        0.5,
        2.5,
        0.01,
        -0.01,
        0.05,
    ]
)


def _sympy_fy(variant):
    a = sp.symbols("a0:18")
    fz, al, g, s = sp.symbols("fz al g s")  # s = sgn(x), piecewise constant
    c = a[0]
    d = (a[1] * fz**2 + a[2] * fz) * (1 - a[15] * g**2)
    bcd = a[3] * sp.sin(2 * sp.atan(fz / a[4])) * (1 - a[5] * sp.Abs(g))
    b = bcd / (c * d)
    if variant == "published":
        sh = a[8] * fz + a[9] + a[10] * g
        sv = a[11] * fz + a[12] + (a[13] * fz + a[14]) * g * fz
    else:
        sh = (a[8] * fz + a[9] + a[10] * g) * fz
        sv = a[11] * fz**2 + a[12] * fz + (a[13] * fz**2 + a[14] * fz) * g
    x = al + sh
    e = (a[6] * fz + a[7]) * (1 - (a[16] * g + a[17]) * s)
    fy = d * sp.sin(c * sp.atan(b * x - e * (b * x - sp.atan(b * x)))) + sv
    return a, (fz, al, g, s), fy


@pytest.mark.parametrize("variant", ["published", "seed"])
def test_jacobian_matches_sympy(variant):
    a, (fz, al, g, s), fy = _sympy_fy(variant)
    grads = [sp.lambdify((a, fz, al, g, s), sp.diff(fy, ai), "numpy") for ai in a]
    f_val = sp.lambdify((a, fz, al, g, s), fy, "numpy")
    rng = np.random.default_rng(1)
    coef = A_TYPICAL + rng.normal(0, 0.01, 18)
    fzv = rng.uniform(2, 6, 40)
    alv = rng.uniform(-10, 10, 40)
    gv = rng.uniform(-3, 3, 40)
    fy_num, jac = pac94_lateral_native(coef, fzv, alv, gv, variant, jacobian=True)
    if variant == "published":
        x = alv + coef[8] * fzv + coef[9] + coef[10] * gv
    else:
        x = alv + (coef[8] * fzv + coef[9] + coef[10] * gv) * fzv
    sv = np.where(x < 0, -1.0, 1.0)
    np.testing.assert_allclose(fy_num, f_val(coef, fzv, alv, gv, sv), rtol=1e-11, atol=1e-9)
    for i, gfun in enumerate(grads):
        ref = np.broadcast_to(gfun(coef, fzv, alv, gv, sv), fzv.shape)
        np.testing.assert_allclose(
            jac[:, i], ref, rtol=1e-8, atol=1e-8 * np.max(np.abs(ref)) + 1e-12, err_msg=f"a{i}"
        )


def test_closed_form_slope_and_peak():
    """γ = 0, no shifts: slope at the origin BCD [N/deg], peak D (C > 1, E < 1)."""
    a = A_TYPICAL.copy()
    a[[8, 9, 10, 11, 12, 13, 14, 16, 17]] = 0
    fz = 4.0
    bcd = a[3] * np.sin(2 * np.arctan(fz / a[4]))
    h = 1e-6
    slope = (pac94_lateral_native(a, fz, h, 0.0) - pac94_lateral_native(a, fz, -h, 0.0)) / (2 * h)
    assert slope == pytest.approx(bcd, rel=1e-7)
    al = np.linspace(0, 40, 400001)
    d = (a[1] * fz + a[2]) * fz
    assert np.max(pac94_lateral_native(a, fz, al, 0.0)) == pytest.approx(d, rel=1e-8)


def test_variants_agree_without_non_camber_shifts():
    """a8 = a9 = a10 = a11 = a12 = 0: the two Sh/Sv forms are the same function (physics §8.1)."""
    a = A_TYPICAL.copy()
    a[[8, 9, 10, 11, 12]] = 0
    al = np.linspace(-0.2, 0.2, 41)
    pub = pac94_lateral(a, 4500.0, al, 0.03, "published")
    seed = pac94_lateral(a, 4500.0, al, 0.03, "seed")
    np.testing.assert_allclose(pub, seed, rtol=1e-13)
    a[9] = 0.2
    assert not np.allclose(
        pac94_lateral(a, 4500.0, al, 0.0, "published"), pac94_lateral(a, 4500.0, al, 0.0, "seed")
    )


def test_si_edges():
    fy_si = pac94_lateral(A_TYPICAL, 4000.0, np.deg2rad(3.0), np.deg2rad(1.0))
    assert fy_si == pytest.approx(float(pac94_lateral_native(A_TYPICAL, 4.0, 3.0, 1.0)))
    assert isinstance(fy_si, float)
