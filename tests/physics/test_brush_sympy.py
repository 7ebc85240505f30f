"""The brush-model closed forms, derived here with sympy from the pressure distributions and
compared with gripsense's code at random points (docs/physics.md §1.1–§1.4, §2.1–§2.3; seed 000
eqs. 4.8–4.16, 10.2–10.3). Nothing below is copied from the code under test."""

from __future__ import annotations

import numpy as np
import pytest
import sympy as sp

from gripsense.physics import brush

x, s, l, w, G, tb, mu, m, g, Fz = sp.symbols("x s l w G tb mu m g F_z", positive=True)
RNG = np.random.default_rng(20181)


def _p2():
    a = sp.Symbol("a", positive=True)
    P = a * x * (l - x)
    a_val = sp.solve(
        sp.Eq(sp.integrate(sp.integrate(P, (x, 0, l)), (sp.Symbol("y"), 0, w)), Fz), a
    )[0]
    return P.subs(a, a_val)


def _p4():
    a = sp.Symbol("a", positive=True)
    P = a * (
        -(x**4) + 2 * l * x**3 - sp.Rational(3, 2) * l**2 * x**2 + sp.Rational(1, 2) * l**3 * x
    )
    a_val = sp.solve(sp.Eq(sp.integrate(P, (x, 0, l)) * w, Fz), a)[0]
    return P.subs(a, a_val)


P2 = _p2()
P4 = _p4()


def test_pressure_normalisation_and_thesis_constant():
    # eq. (4.8): a = 6 m g /(l^3 w) with Fz = m g
    assert sp.simplify(P2 - 6 * Fz / (l**3 * w) * x * (l - x)) == 0
    # eq. (10.2): 20 m g /(l^5 w) (-x^4 + 2 l x^3 - 1.5 l^2 x^2 + 0.5 l^3 x)
    expected = (
        20
        * Fz
        / (l**5 * w)
        * (-(x**4) + 2 * l * x**3 - sp.Rational(3, 2) * l**2 * x**2 + sp.Rational(1, 2) * l**3 * x)
    )
    assert sp.simplify(P4 - expected) == 0


def test_slide_point_eq_4_12():
    # G s tanβ = μ P2(s) (deflection factor s restored) -> s = l - l^3 w G tanβ /(6 m g μ)
    sol = [r for r in sp.solve(sp.Eq(G * s * tb, mu * P2.subs(x, s)), s) if r != 0]
    assert len(sol) == 1
    target = l - l**3 * w * G * tb / (6 * m * g * mu)
    assert sp.simplify(sol[0].subs(Fz, m * g) - target) == 0


def _numeric_cases(n=40):
    mu_v = RNG.uniform(0.2, 1.3, n)
    fz_v = RNG.uniform(1500.0, 6000.0, n)
    l_v = RNG.uniform(0.08, 0.2, n)
    w_v = RNG.uniform(0.15, 0.3, n)
    g_v = RNG.uniform(1e7, 8e7, n)
    return mu_v, fz_v, l_v, w_v, g_v


@pytest.mark.parametrize("pressure", ["parabolic", "quartic"])
def test_exact_force_integral(pressure):
    """F = w ∫₀^s G x tanβ dx + w ∫_s^l μ P(x) dx with s from the slide condition."""
    P = P2 if pressure == "parabolic" else P4
    f_adh = w * sp.integrate(G * x * tb, (x, 0, s))
    f_sl = w * sp.integrate(mu * P, (x, s, l))
    F = sp.lambdify((s, l, w, G, tb, mu, Fz), f_adh + f_sl, "numpy")
    slide = sp.lambdify((s, l, w, G, tb, mu, Fz), G * s * tb - mu * P.subs(x, s), "numpy")
    from scipy.optimize import brentq

    mu_v, fz_v, l_v, w_v, g_v = _numeric_cases()
    for i in range(mu_v.size):
        C = g_v[i] * w_v[i] * l_v[i] ** 2 / 2
        theta_target = RNG.uniform(0.05, 0.95 if pressure == "parabolic" else 1.6)
        tanb = theta_target * 3 * mu_v[i] * fz_v[i] / C
        args = (l_v[i], w_v[i], g_v[i], tanb, mu_v[i], fz_v[i])
        # the nonzero root of the slide condition in (0, l]
        s_v = brentq(lambda s_, a=args: slide(s_, *a) / s_, 1e-12 * l_v[i], l_v[i])
        f_ref = F(s_v, *args)
        f_code = brush.lateral_force(
            mu_v[i], np.arctan(tanb), fz_v[i], C, pressure=pressure, model="exact"
        )
        assert f_code == pytest.approx(f_ref, rel=1e-9)


@pytest.mark.parametrize("pressure", ["parabolic", "quartic"])
def test_thesis_triangle_inversion(pressure):
    """Triangle area (eq. 4.14): F = ½ w G l s tanβ; solve F = F_measured for μ.

    (eq. 4.15 for the parabolic pressure, chapter 10 for the quartic one)
    """
    P = P2 if pressure == "parabolic" else P4
    # slide point from G s tanβ = μ P(s), as a function of μ, then F_tri(μ) = F
    mu_v, fz_v, l_v, w_v, g_v = _numeric_cases(25)
    slide = sp.lambdify((s, l, w, G, tb, mu, Fz), G * s * tb - mu * P.subs(x, s), "numpy")
    from scipy.optimize import brentq

    for i in range(mu_v.size):
        C = g_v[i] * w_v[i] * l_v[i] ** 2 / 2
        r_target = RNG.uniform(0.55, 0.97)  # rising branch of the triangle model
        tanb = RNG.uniform(0.002, 0.03)
        T = C * tanb
        F_v = r_target * T
        L = l_v[i]

        def slide_point(mu_, L=L, i=i, tanb=tanb):
            def f(s_):
                return slide(s_, L, w_v[i], g_v[i], tanb, mu_, fz_v[i]) / s_

            if f(1e-12 * L) >= 0:  # bristles slide from the leading edge on: s = 0
                return 0.0
            return brentq(f, 1e-12 * L, L, xtol=1e-16, rtol=1e-14)

        def residual(mu_, L=L, i=i, tanb=tanb, F_v=F_v, slide_point=slide_point):
            return 0.5 * w_v[i] * g_v[i] * L * slide_point(mu_) * tanb - F_v

        grid = np.geomspace(1e-3, 1e4, 400)
        vals = [residual(v) for v in grid]
        roots = [
            brentq(residual, grid[k], grid[k + 1], xtol=1e-15, rtol=1e-14)
            for k in range(len(grid) - 1)
            if np.sign(vals[k]) != np.sign(vals[k + 1])
        ]
        mu_ref = max(roots)  # the larger μ has the larger slide point (rising branch)
        mu_code, st = brush.mu_from_force(
            F_v, np.arctan(tanb), fz_v[i], C, pressure=pressure, model="thesis"
        )
        assert st == "ok"
        assert mu_code == pytest.approx(mu_ref, rel=1e-9)


def test_eq_4_15_equals_compact_form():
    R, v, cb = sp.symbols("R v cb", positive=True)  # cb = cos β
    eq415 = (
        R * w**2 * l**4 * G**2 * tb**2 / (6 * m * g * (R * w * l**2 * G * tb - 2 * m * v**2 * cb))
    )
    T = sp.Rational(1, 2) * w * l**2 * G * tb
    F = m * v**2 * cb / R
    compact = T**2 / (3 * m * g * (T - F))
    assert sp.simplify(eq415 - compact) == 0


def test_exact_parabolic_inversion_closed_form():
    """r = F/T = 1 − θ + θ²/3 (exact P2); the root θ in (0, 1) and μ = T/(3 Fz θ)."""
    th, r = sp.symbols("theta r", positive=True)
    roots = sp.solve(sp.Eq(1 - th + th**2 / 3, r), th)
    for rv in RNG.uniform(0.34, 0.999, 50):
        cands = [complex(z.subs(r, rv)) for z in roots]
        theta = next(c.real for c in cands if abs(c.imag) < 1e-12 and 0 < c.real < 1)
        T, fz = 1000.0, 2000.0
        mu_ref = T / (3 * fz * theta)
        out = brush.invert(rv * T, np.arctan(T / 8e4), fz, 8e4, pressure="parabolic", model="exact")
        assert out["mu"][()] == pytest.approx(mu_ref, rel=1e-10)
        assert out["xi"][()] == pytest.approx(1 - theta, rel=1e-9, abs=1e-12)


def test_exact_quartic_inversion_via_slide_point():
    """Pick ξ, get θ from the slide condition h(ξ) = 0.3θ and F/(μFz) from the integrals."""
    xi = sp.Symbol("xi", positive=True)
    phi = P4.subs(x, xi * l) * w * l / Fz  # normalised pressure shape φ(ξ), ∫₀¹ φ = 1
    theta_of_xi = sp.simplify(phi / (6 * xi))  # slide condition 6 θ ξ = φ(ξ)
    Phi = sp.integrate(phi.subs(xi, sp.Symbol("u")), (sp.Symbol("u"), 0, xi))
    f_norm = 3 * theta_of_xi * xi**2 + 1 - Phi  # F/(μ Fz)
    fth = sp.lambdify(xi, theta_of_xi)
    ff = sp.lambdify(xi, f_norm)
    for xv in RNG.uniform(0.02, 0.98, 60):
        theta = float(fth(xv))
        mu_true, fz, C = 0.8, 3000.0, 9e4
        T = 3 * theta * mu_true * fz
        F = float(ff(xv)) * mu_true * fz
        out = brush.invert(F, np.arctan(T / C), fz, C, pressure="quartic", model="exact")
        assert out["status"][()] == brush.OK
        assert out["mu"][()] == pytest.approx(mu_true, rel=1e-9)
        assert out["xi"][()] == pytest.approx(xv, rel=1e-8)


@pytest.mark.parametrize(
    ("pressure", "model"),
    [("parabolic", "exact"), ("parabolic", "thesis"), ("quartic", "exact"), ("quartic", "thesis")],
)
def test_kappa_beta_against_numeric_derivative(pressure, model):
    """κ_β = (T/μ) ∂μ/∂T at fixed F, from a central difference of the (verified) inversion."""
    for _ in range(30):
        fz, C = 2500.0, 8e4
        lo = {"exact": 0.36 if pressure == "parabolic" else 0.22, "thesis": 0.52}[model]
        r = RNG.uniform(lo, 0.98)
        T = C * np.tan(0.01)
        F = r * T
        b = np.arctan(T / C)
        k = brush.kappa_beta(F, b, fz, C, pressure=pressure, model=model)
        h = 1e-6
        mup = brush.mu_from_force(
            F, np.arctan(T * (1 + h) / C), fz, C, pressure=pressure, model=model
        )[0]
        mum = brush.mu_from_force(
            F, np.arctan(T * (1 - h) / C), fz, C, pressure=pressure, model=model
        )[0]
        mu0 = brush.mu_from_force(F, b, fz, C, pressure=pressure, model=model)[0]
        assert k == pytest.approx((mup - mum) / (2 * h) / mu0, rel=1e-5, abs=1e-6)


def test_kappa_exact_parabolic_symbolic():
    """κ_β = −3(1−θ)²/(θ(3−2θ)) from implicit differentiation of F = μFz[1 − (1 − T/(3μFz))³]."""
    T_, F_ = sp.symbols("T F", positive=True)
    mu_f = sp.Function("mu")(T_)
    eq = mu_f * Fz * (1 - (1 - T_ / (3 * mu_f * Fz)) ** 3) - F_
    dmu = sp.solve(sp.diff(eq, T_), sp.diff(mu_f, T_))[0]
    kappa = sp.simplify((T_ / mu_f) * dmu)
    th = sp.Symbol("theta", positive=True)
    k_th = sp.simplify(kappa.subs(mu_f, T_ / (3 * th * Fz)))
    assert sp.simplify(k_th - (-3 * (1 - th) ** 2 / (th * (3 - 2 * th)))) == 0


def test_aligning_moment_and_trail_integral():
    """Mz = w ∫₀^s G x tanβ (x − l/2) dx + w ∫_s^l μ P2 (x − l/2) dx: the moment about the
    contact centre of the force distribution (x from the leading edge; x − l/2 the lever behind
    the centre), s from the slide condition; t = Mz/F. At zero slip t = l/6."""
    arm = x - l / 2
    s_expr = l - l**3 * w * G * tb / (6 * Fz * mu)  # eq. 4.12 with m g = Fz
    m_adh = w * sp.integrate(G * x * tb * arm, (x, 0, s))
    m_sl = w * sp.integrate(mu * P2 * arm, (x, s, l))
    f_adh = w * sp.integrate(G * x * tb, (x, 0, s))
    f_sl = w * sp.integrate(mu * P2, (x, s, l))
    mz = sp.lambdify((l, w, G, tb, mu, Fz), (m_adh + m_sl).subs(s, s_expr), "numpy")
    fy = sp.lambdify((l, w, G, tb, mu, Fz), (f_adh + f_sl).subs(s, s_expr), "numpy")
    # the linear limit: t → l/6 (a/3)
    t0 = sp.limit(sp.simplify(((m_adh + m_sl) / (f_adh + f_sl)).subs(s, s_expr)), tb, 0)
    assert sp.simplify(t0 - l / 6) == 0
    mu_v, fz_v, l_v, w_v, g_v = _numeric_cases()
    for i in range(mu_v.size):
        C = g_v[i] * w_v[i] * l_v[i] ** 2 / 2
        theta = RNG.uniform(0.02, 0.98)
        tanb = theta * 3 * mu_v[i] * fz_v[i] / C
        args = (l_v[i], w_v[i], g_v[i], tanb, mu_v[i], fz_v[i])
        m_code, t_code = brush.aligning_moment(mu_v[i], np.arctan(tanb), fz_v[i], C, l_v[i] / 2)
        assert m_code == pytest.approx(mz(*args), rel=1e-9)
        assert t_code == pytest.approx(mz(*args) / fy(*args), rel=1e-9)
    # beyond full sliding the moment and the trail vanish
    m_sl_full, t_full = brush.aligning_moment(1.0, 0.5, 4000.0, 5e4, 0.07)
    assert m_sl_full == 0.0 and t_full == 0.0
