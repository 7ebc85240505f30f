"""Brush (Fiala) tyre model with parabolic or quartic contact pressure, and its inversion for μ.

Notation (docs/physics.md §0): load Fz [N], cornering stiffness C = G w l²/2 [N/rad], slip angle β
[rad], T = C |tan β| (the "linear" force), F the lateral force magnitude the tyre carries,
r = F/T the force ratio, θ = T/(3 μ Fz) the adhesion parameter, ξ = s/l the normalised slide
point (adhesion on [0, s), sliding on [s, l]).

Models
------
``pressure``: ``"parabolic"`` (P2, thesis ch. 4) or ``"quartic"`` (P4, thesis ch. 10).
``model``: ``"exact"`` (adhesion integral plus sliding integral — the brush model) or
``"thesis"`` (the thesis's triangle approximation of the deformed area, eq. 4.14 / ch. 10).

Inversion status codes: ``ok``; ``no_solution`` (r ≥ 1: the model cannot carry that force at
that slip angle, a measurement or parameter error); ``full_sliding`` (the whole patch slides —
β carries no information, μ = F/Fz is returned as the value the force proves); ``invalid``
(NaN, non-positive load or stiffness, zero slip angle).

References
----------
Seed 000 (Goda 2018) eqs. (4.8)–(4.16), (9.1), (10.2)–(10.3); docs/physics.md §1.1–§1.4, §2.1–§2.5;
the aligning moment and pneumatic trail: Pacejka (2012) §3.2.2, docs/physics.md §16.1.
"""

from __future__ import annotations

import numpy as np
from numba import njit, prange

from gripsense._arrays import as_float_array, restore
from gripsense.errors import InputError

__all__ = [
    "STATUS",
    "adhesion_parameter",
    "aligning_moment",
    "cornering_stiffness",
    "force_ratio",
    "force_scalar",
    "invert",
    "kappa_beta",
    "lateral_force",
    "mu_from_force",
    "slide_point",
]

STATUS = ("ok", "no_solution", "full_sliding", "invalid")
OK, NO_SOLUTION, FULL_SLIDING, INVALID = 0, 1, 2, 3
PRESSURES = ("parabolic", "quartic")
MODELS = ("exact", "thesis")


def _check(pressure: str, model: str) -> None:
    if pressure not in PRESSURES:
        raise InputError(f"pressure={pressure!r}; use one of {PRESSURES}")
    if model not in MODELS:
        raise InputError(f"model={model!r}; use one of {MODELS}")


def cornering_stiffness(tread_stiffness, width, length):
    """Brush cornering stiffness C = G w l²/2.

    Parameters
    ----------
    tread_stiffness : array_like
        G, tread lateral stiffness per unit area per unit deflection [N/m^3].
    width, length : array_like
        Contact width w and length l [m].

    Returns
    -------
    array_like
        [N/rad].

    References
    ----------
    Seed 000, eq. (9.1); docs/physics.md §0, §1.2.
    """
    g, w, l = (
        as_float_array(v, n)
        for v, n in ((tread_stiffness, "tread_stiffness"), (width, "width"), (length, "length"))
    )
    return restore(0.5 * g * w * l**2, tread_stiffness, length)


def adhesion_parameter(mu, load, cornering_stiffness_N_per_rad, slip_angle):
    """Fiala adhesion parameter θ = C |tan β| /(3 μ Fz) [-]. docs/physics.md §0, §1.2.

    Parameters
    ----------
    mu : array_like
        Friction coefficient [-].
    load : array_like
        Vertical load Fz [N].
    cornering_stiffness_N_per_rad : array_like
        C = G w l²/2 [N/rad].
    slip_angle : array_like
        Slip angle [rad].
    """
    mu, fz, c, b = (
        as_float_array(v, n)
        for v, n in (
            (mu, "mu"),
            (load, "load"),
            (cornering_stiffness_N_per_rad, "C"),
            (slip_angle, "slip_angle"),
        )
    )
    return restore(c * np.abs(np.tan(b)) / (3.0 * mu * fz), mu, slip_angle)


def _xi_quartic_cubic(theta: np.ndarray) -> np.ndarray:
    """Root in [0, 1] of h(ξ) = (1 − ξ)(ξ² − ξ + ½) = 0.3 θ (closed form; 0 beyond θ = 5/3).

    Depressed cubic t³ + t/6 + (0.3θ − 5/54) = 0 with ξ = t + 2/3; one real root (p > 0).
    docs/physics.md §2.2.
    """
    p = 1.0 / 6.0
    q = 0.3 * theta - 5.0 / 54.0
    xi = 2.0 / 3.0 - 2.0 * np.sqrt(p / 3.0) * np.sinh(
        np.arcsinh((3.0 * q / (2.0 * p)) * np.sqrt(3.0 / p)) / 3.0
    )
    return np.where(theta >= 5.0 / 3.0, 0.0, np.clip(xi, 0.0, 1.0))


@njit(cache=True, nogil=True)
def _phi4(xi):
    """Φ4(ξ) = ∫₀^ξ φ4 = 5ξ² − 10ξ³ + 10ξ⁴ − 4ξ⁵ (normalised cumulative quartic pressure).

    docs/physics.md §2.3b; 1 − Φ4 = (1 − ξ)²(4ξ³ − 2ξ² + 2ξ + 1).
    """
    return 5 * xi**2 - 10 * xi**3 + 10 * xi**4 - 4 * xi**5


def slide_point(theta, *, pressure: str = "parabolic", model: str = "exact"):
    """Normalised slide point ξ = s/l for a given adhesion parameter θ.

    Parameters
    ----------
    theta : array_like
        Adhesion parameter θ = C|tanβ|/(3μFz) [-].
    pressure : {"parabolic", "quartic"}
    model : {"exact", "thesis"}
        Both models share the slide condition G s tanβ = μ P(s); they differ in the force.

    Returns
    -------
    xi : array_like
        [-], 0 when the whole patch slides.

    References
    ----------
    Seed 000, eq. (4.12) (with the deflection factor s restored) and (10.3);
    docs/physics.md §1.2 (ξ = 1 − θ), §2.2 (cubic closed form).
    """
    _check(pressure, model)
    th = as_float_array(theta, "theta")
    if pressure == "parabolic":
        xi = np.clip(1.0 - th, 0.0, 1.0)
    else:
        xi = _xi_quartic_cubic(th)
    return restore(np.where(np.isnan(th), np.nan, xi), theta)


@njit(cache=True, nogil=True)
def force_scalar(mu, tan_slip, load, stiffness, which):
    """|F| of one tyre [N] (the compiled core of :func:`lateral_force`).

    Parameters
    ----------
    mu, tan_slip, load, stiffness : float
        μ [-], |tan β| [-], Fz [N], C [N/rad].
    which : int
        0 exact-P2, 1 thesis-P2, 2 exact-P4, 3 thesis-P4.
    """
    if not (mu > 0.0 and load > 0.0):
        return 0.0 if (mu == 0.0 or load <= 0.0) else np.nan
    th = stiffness * abs(tan_slip) / (3.0 * mu * load)
    if which == 0:
        return mu * load * (1.0 - (1.0 - th) ** 3) if th < 1.0 else mu * load
    if which == 1:
        return mu * load * (3.0 * th - 3.0 * th * th) if th <= 1.0 else 0.0
    if th >= 5.0 / 3.0:
        return mu * load if which == 2 else 0.0
    p = 1.0 / 6.0
    q = 0.3 * th - 5.0 / 54.0
    xi = 2.0 / 3.0 - 2.0 * np.sqrt(p / 3.0) * np.sinh(
        np.arcsinh((3.0 * q / (2.0 * p)) * np.sqrt(3.0 / p)) / 3.0
    )
    xi = min(max(xi, 0.0), 1.0)
    if which == 2:
        return mu * load * (3.0 * th * xi * xi + 1.0 - _phi4(xi))
    return 3.0 * mu * load * th * xi


@njit(cache=True, nogil=True)
def force_slope_scalar(mu, tan_slip, load, stiffness, quartic):
    """(|F|, d|F|/d|β|) of the exact brush model for one tyre.

    dF/dθ = 3 μ Fz ξ² for both pressures (docs/physics.md §1.2, §2.3b: ξ = 1 − θ for P2), and
    dθ/dβ = C sec²β /(3 μ Fz), so dF/dβ = C sec²β ξ² (0 in full sliding).

    Parameters
    ----------
    mu, tan_slip, load, stiffness : float
        μ [-], |tan β| [-], Fz [N], C [N/rad].
    quartic : bool
        Quartic (True) or parabolic pressure.
    """
    if not (mu > 0.0 and load > 0.0):
        return 0.0, 0.0
    t = abs(tan_slip)
    th = stiffness * t / (3.0 * mu * load)
    if not quartic:
        if th >= 1.0:
            return mu * load, 0.0
        xi = 1.0 - th
        return mu * load * (1.0 - xi * xi * xi), stiffness * (1.0 + t * t) * xi * xi
    if th >= 5.0 / 3.0:
        return mu * load, 0.0
    p = 1.0 / 6.0
    q = 0.3 * th - 5.0 / 54.0
    xi = 2.0 / 3.0 - 2.0 * np.sqrt(p / 3.0) * np.sinh(
        np.arcsinh((3.0 * q / (2.0 * p)) * np.sqrt(3.0 / p)) / 3.0
    )
    xi = min(max(xi, 0.0), 1.0)
    f = mu * load * (3.0 * th * xi * xi + 1.0 - _phi4(xi))
    return f, stiffness * (1.0 + t * t) * xi * xi


@njit(cache=True, nogil=True)
def _force_loop(mu, tb, fz, c, which, out):
    for i in range(out.size):
        out[i] = force_scalar(mu[i], tb[i], fz[i], c[i], which)


_WHICH = {
    ("parabolic", "exact"): 0,
    ("parabolic", "thesis"): 1,
    ("quartic", "exact"): 2,
    ("quartic", "thesis"): 3,
}


def lateral_force(
    mu, slip_angle, load, cornering_stiffness_N_per_rad, *, pressure="parabolic", model="exact"
):
    """Lateral force magnitude |F| of the brush model [N].

    Parameters
    ----------
    mu : array_like
        Friction coefficient [-].
    slip_angle : array_like
        β [rad] (its magnitude is used).
    load : array_like
        Fz [N].
    cornering_stiffness_N_per_rad : array_like
        C [N/rad].
    pressure : {"parabolic", "quartic"}
    model : {"exact", "thesis"}

    Returns
    -------
    force : array_like
        [N].

    Notes
    -----
    exact, parabolic: F = μFz[1 − (1 − θ)³] for θ < 1, μFz beyond (Fiala).
    thesis, parabolic: F = μFz(3θ − 3θ²) (triangle; peaks at 0.75 μFz for θ = ½, 0 for θ ≥ 1).
    exact, quartic: F = μFz(3θξ² + 1 − Φ4(ξ)) for θ < 5/3, μFz beyond.
    thesis, quartic: F = 3μFzθξ (triangle; peaks at 0.625 μFz).

    References
    ----------
    Seed 000, eq. (4.14), ch. 10; docs/physics.md §1.2, §2.3.
    """
    _check(pressure, model)
    arrs = [
        as_float_array(v, n)
        for v, n in (
            (mu, "mu"),
            (slip_angle, "slip_angle"),
            (load, "load"),
            (cornering_stiffness_N_per_rad, "cornering_stiffness_N_per_rad"),
        )
    ]
    shape = np.broadcast_shapes(*(a.shape for a in arrs))
    m, b, fz, c = (np.ascontiguousarray(np.broadcast_to(a, shape)).ravel() for a in arrs)
    out = np.empty(m.size)
    _force_loop(m, np.tan(b), fz, c, _WHICH[(pressure, model)], out)
    return restore(out.reshape(shape), mu, slip_angle)


def force_ratio(force, slip_angle, cornering_stiffness_N_per_rad):
    """R = |F| /(C |tan β|) [-]: 1 − r is the non-linearity deficit. docs/physics.md §0, §1.3.

    Parameters
    ----------
    force : array_like
        Lateral force [N].
    slip_angle : array_like
        Slip angle [rad].
    cornering_stiffness_N_per_rad : array_like
        C [N/rad].
    """
    f, b, c = (
        as_float_array(v, n)
        for v, n in (
            (force, "force"),
            (slip_angle, "slip_angle"),
            (cornering_stiffness_N_per_rad, "C"),
        )
    )
    with np.errstate(divide="ignore", invalid="ignore"):
        return restore(np.abs(f) / (c * np.abs(np.tan(b))), force, slip_angle)


@njit(cache=True, nogil=True)
def _xi_exact_quartic(target):
    """Root ξ in [0, 1] of r(ξ) = ξ² + (1 − ξ)(4ξ³ − 2ξ² + 2ξ + 1)/(10(ξ² − ξ + ½)) = target.

    r(ξ) rises strictly from 1/5 to 1 (docs/physics.md §2.3); safeguarded Newton inside a bisection
    bracket, to machine precision.
    """
    lo, hi = 0.0, 1.0
    x = 0.5
    for _ in range(100):
        d = x * x - x + 0.5
        poly = 4.0 * x**3 - 2.0 * x**2 + 2.0 * x + 1.0
        num = (1.0 - x) * poly
        f = x * x + num / (10.0 * d) - target
        if f > 0:
            hi = x
        else:
            lo = x
        dnum = -poly + (1.0 - x) * (12.0 * x**2 - 4.0 * x + 2.0)
        df = 2.0 * x + (dnum * d - num * (2.0 * x - 1.0)) / (10.0 * d * d)
        xn = x - f / df if df > 0 else 0.5 * (lo + hi)
        if not (lo < xn < hi):
            xn = 0.5 * (lo + hi)
        if abs(xn - x) <= 1e-15 or hi - lo <= 1e-15:
            return xn
        x = xn
    return x


@njit(cache=True, nogil=True, parallel=True)
def _invert_kernel(f, b, fz, c, which, mu, status, xi, ratio, kap):
    """One fused pass per sample; which: 0 exact-P2, 1 thesis-P2, 2 exact-P4, 3 thesis-P4."""
    nan = np.nan
    r_full = (1.0 / 3.0, 0.5, 0.2, 0.5)[which]
    for i in prange(f.size):
        F = abs(f[i])
        Z = fz[i]
        C = c[i]
        T = C * abs(np.tan(b[i]))
        if not (np.isfinite(F) and np.isfinite(T) and np.isfinite(Z)) or Z <= 0 or C <= 0 or T <= 0:
            status[i] = 3
            mu[i] = nan
            xi[i] = nan
            ratio[i] = nan
            kap[i] = nan
            continue
        r = F / T
        ratio[i] = r
        if r >= 1.0:
            status[i] = 1
            mu[i] = nan
            xi[i] = nan
            kap[i] = nan
            continue
        if r <= r_full:
            status[i] = 2
            mu[i] = F / Z
            xi[i] = 0.0
            kap[i] = 0.0
            continue
        status[i] = 0
        if which == 0:
            q = np.sqrt((4.0 * r - 1.0) / 3.0)
            th = 2.0 * (1.0 - r) / (1.0 + q)  # cancellation-free form of (3/2)(1 − q)
            mu[i] = T * (1.0 + q) / (6.0 * Z * (1.0 - r))
            xi[i] = 1.0 - th
            kap[i] = -3.0 * (1.0 - th) ** 2 / (th * (3.0 - 2.0 * th))
        elif which == 1:
            mu[i] = T / (3.0 * Z * (1.0 - r))
            xi[i] = r
            kap[i] = (1.0 - 2.0 * r) / (1.0 - r)
        elif which == 3:
            g = (1.0 - r) * (r * r - r + 0.5)
            mu[i] = T / (10.0 * Z * g)
            xi[i] = r
            gp = -(r * r - r + 0.5) + (1.0 - r) * (2.0 * r - 1.0)
            kap[i] = 1.0 + r * gp / g
        else:
            x = _xi_exact_quartic(r)
            h = (1.0 - x) * (x * x - x + 0.5)
            m = T / (10.0 * Z * h)
            th = T / (3.0 * m * Z)
            mu[i] = m
            xi[i] = x
            kap[i] = -3.0 * th * x * x / (1.0 - _phi4(x))


def invert(
    force_N,
    slip_angle_rad,
    load_N,
    cornering_stiffness_N_per_rad,
    *,
    pressure="parabolic",
    model="exact",
):
    """Solve the brush model for μ; also return ξ, r and the condition number κ_β.

    Parameters as :func:`mu_from_force`.

    Returns
    -------
    dict of numpy.ndarray
        ``mu`` [-], ``status`` (int codes, see :data:`STATUS`), ``xi`` (slide point s/l) [-],
        ``ratio`` (r = F/T) [-], ``kappa_beta`` [-] ((T/μ)∂μ/∂T at fixed F; 0 in full sliding,
        NaN without a solution).

    Notes
    -----
    With r = F/T:

    * exact, parabolic: r > 1 none; r ≤ 1/3 full sliding; else
      μ = T(1 + q)/(6 Fz (1 − r)), q = √((4r − 1)/3); ξ = 1 − θ;
      κ_β = −3(1 − θ)²/(θ(3 − 2θ)).  (docs/physics.md §1.3, §1.4)
    * thesis, parabolic (eq. 4.15): μ = T²/(3 Fz (T − F)) on its rising branch r > ½ (r ≤ ½ is
      beyond the triangle's peak: full sliding); ξ = r; κ_β = (1 − 2r)/(1 − r).
    * thesis, quartic (ch. 10, explicit): μ = T/(10 Fz (1 − r)(r² − r + ½)) for r > ½; ξ = r;
      κ_β = 1 + r g′(r)/g(r), g = (1 − r)(r² − r + ½).  (docs/physics.md §2.3a)
    * exact, quartic: r ≤ 1/5 full sliding; else ξ solves r(ξ) = r and μ = T/(10 Fz h(ξ)),
      h = (1 − ξ)(ξ² − ξ + ½); κ_β = −3θξ²/(1 − Φ4(ξ)).  (docs/physics.md §2.3b)

    The force F and slip angle enter as magnitudes; whether their signs agree (ISO: F ≈ −Cβ)
    is for the caller to check.
    """
    _check(pressure, model)
    arrs = [
        as_float_array(v, n)
        for v, n in (
            (force_N, "force_N"),
            (slip_angle_rad, "slip_angle_rad"),
            (load_N, "load_N"),
            (cornering_stiffness_N_per_rad, "cornering_stiffness_N_per_rad"),
        )
    ]
    shape = np.broadcast_shapes(*(a.shape for a in arrs))
    f, b, fz, c = (np.ascontiguousarray(np.broadcast_to(a, shape)).ravel() for a in arrs)
    which = {
        ("parabolic", "exact"): 0,
        ("parabolic", "thesis"): 1,
        ("quartic", "exact"): 2,
        ("quartic", "thesis"): 3,
    }[(pressure, model)]
    n = f.size
    mu = np.empty(n)
    status = np.empty(n, dtype=np.int8)
    xi = np.empty(n)
    ratio = np.empty(n)
    kap = np.empty(n)
    _invert_kernel(f, b, fz, c, which, mu, status, xi, ratio, kap)
    return {
        "mu": mu.reshape(shape),
        "status": status.reshape(shape),
        "xi": xi.reshape(shape),
        "ratio": ratio.reshape(shape),
        "kappa_beta": kap.reshape(shape),
    }


def mu_from_force(
    force_N,
    slip_angle_rad,
    load_N,
    cornering_stiffness_N_per_rad,
    *,
    pressure="parabolic",
    model="exact",
):
    """Friction coefficient from the lateral force a tyre carries at a slip angle.

    Parameters
    ----------
    force_N : array_like
        Lateral force F the tyre carries [N] (magnitude used).
    slip_angle_rad : array_like
        Slip angle β [rad] (magnitude used).
    load_N : array_like
        Vertical load Fz [N].
    cornering_stiffness_N_per_rad : array_like
        C = G w l²/2 [N/rad].
    pressure : {"parabolic", "quartic"}
        Contact pressure shape (thesis ch. 4 / ch. 10).
    model : {"exact", "thesis"}
        Exact brush integral, or the thesis's triangle approximation (eq. 4.15 / ch. 10).

    Returns
    -------
    mu : array_like
        [-]; NaN for ``no_solution`` and ``invalid``; F/Fz in ``full_sliding``.
    status : array_like of str
        ``ok``, ``no_solution`` (r ≥ 1), ``full_sliding``, ``invalid``.

    Examples
    --------
    >>> mu, status = mu_from_force(463.0, np.deg2rad(0.437), 2353.6, 83047.0)
    >>> round(mu, 2), status
    (0.3, 'ok')

    References
    ----------
    Seed 000, eq. (4.15), ch. 10; docs/physics.md §1.3, §2.3.
    """
    out = invert(
        force_N,
        slip_angle_rad,
        load_N,
        cornering_stiffness_N_per_rad,
        pressure=pressure,
        model=model,
    )
    names = np.array(STATUS)[out["status"]]
    like = (force_N, slip_angle_rad, load_N, cornering_stiffness_N_per_rad)
    mu = restore(out["mu"], *like)
    st = names.item() if all(np.ndim(v) == 0 for v in like) else restore(names, *like)
    return mu, st


def kappa_beta(
    force_N,
    slip_angle_rad,
    load_N,
    cornering_stiffness_N_per_rad,
    *,
    pressure="parabolic",
    model="exact",
):
    """Relative condition number κ_β = (T/μ) ∂μ/∂T at fixed F [-].

    A 1 % error in tan β, G, w or l² moves μ by κ_β %; κ_F = 1 − κ_β (μ is homogeneous of
    degree one in (F, T)). |κ_β| ≤ 1 only near the friction limit (F ≳ 0.83 μFz for P2).

    Parameters
    ----------
    force_N : array_like
        Lateral force [N].
    slip_angle_rad : array_like
        Slip angle [rad].
    load_N : array_like
        Vertical load [N].
    cornering_stiffness_N_per_rad : array_like
        C [N/rad].
    pressure : str
        ``parabolic`` or ``quartic``.
    model : str
        ``exact`` or ``thesis``.

    References
    ----------
    docs/physics.md §1.4, §2.3.
    """
    out = invert(
        force_N,
        slip_angle_rad,
        load_N,
        cornering_stiffness_N_per_rad,
        pressure=pressure,
        model=model,
    )
    return restore(out["kappa_beta"], force_N, slip_angle_rad)


def aligning_moment(mu, slip_angle, load, cornering_stiffness_N_per_rad, half_length):
    """Aligning moment |Mz| and pneumatic trail of the brush model, parabolic pressure [N m, m].

    Parameters
    ----------
    mu : array_like
        Friction coefficient [-].
    slip_angle : array_like
        β [rad] (its magnitude is used).
    load : array_like
        Fz [N].
    cornering_stiffness_N_per_rad : array_like
        C [N/rad].
    half_length : array_like
        Contact half-length a [m] (l = 2a).

    Returns
    -------
    moment : array_like
        |Mz| = μ Fz a λ (1 − λ)³ for λ = θ < 1, 0 beyond [N m] (it turns the wheel towards the
        slip: restoring).
    trail : array_like
        t = Mz/F = a (1 − λ)³ / (3 − 3λ + λ²) [m]: a/3 at zero slip, 0 at full sliding; as a
        function of the utilisation u = 1 − (1 − λ)³, t/t₀ = 3 (1 − u)/(3 − 3λ + λ²).

    References
    ----------
    Pacejka, *Tire and Vehicle Dynamics* (2012) §3.2.2; docs/physics.md §16.1.
    """
    m, b, fz, c, a = (
        as_float_array(v, n)
        for v, n in (
            (mu, "mu"),
            (slip_angle, "slip_angle"),
            (load, "load"),
            (cornering_stiffness_N_per_rad, "cornering_stiffness_N_per_rad"),
            (half_length, "half_length"),
        )
    )
    with np.errstate(divide="ignore", invalid="ignore"):
        lam = np.minimum(c * np.abs(np.tan(b)) / (3.0 * m * fz), 1.0)
    one = (1.0 - lam) ** 3
    moment = m * fz * a * lam * one
    trail = a * one / (3.0 - 3.0 * lam + lam**2)
    return restore(moment, mu, slip_angle), restore(trail, mu, slip_angle)
