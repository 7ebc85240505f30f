"""The a0…a17 lateral Magic Formula of seed 002 ("PAC94", Pacejka & Bakker 1993) with its Jacobian.

docs/physics.md §8.1, seed ``002_0ffa298cd6a17b3b.txt`` eqs. (1)–(9)::

    Fy = D sin(C atan(B x − E (B x − atan(B x)))) + Sv,   x = α + Sh
    C  = a0
    D  = (a1 Fz² + a2 Fz)(1 − a15 γ²)
    BCD = a3 sin(2 atan(Fz / a4)) (1 − a5 |γ|),   B = BCD / (C D)
    E  = (a6 Fz + a7)(1 − (a16 γ + a17) sgn(x))

Two forms of the shifts exist (docs/physics.md §8.1 could not decide which the seed meant):

* ``"published"`` (default): Sh = a8 Fz + a9 + a10 γ; Sv = a11 Fz + a12 + (a13 Fz + a14) γ Fz —
  the PAC94 form of MSC Adams and the literature, so coefficient sets exchanged with other tools
  mean the same thing here;
* ``"seed"``: Sh = (a8 Fz + a9 + a10 γ) Fz; Sv = a11 Fz² + a12 Fz + (a13 Fz² + a14 Fz) γ, as the
  seed prints them.

Both carry the same camber part of Sv, and the symmetric constraint a8 = a9 = a11 = a12 = 0 means
the same in both.

Units of this family: Fz in kN, α and γ in degrees, Fy in N. The public functions take SI
(N, rad) and convert at the edge; :func:`pac94_lateral_native` works in the native units.
The sign convention is the coefficients' own: a curve with D, BCD < 0 has the ISO/SAE negative
slope, one with D, BCD > 0 the adapted-SAE positive slope.
"""

from __future__ import annotations

import numpy as np

from gripsense._arrays import as_float_array, restore

__all__ = ["N_COEF", "VARIANTS", "pac94_lateral", "pac94_lateral_native"]

N_COEF = 18
VARIANTS = ("published", "seed")
_RAD2DEG = 180.0 / np.pi


def _check(a: np.ndarray, variant: str) -> None:
    if a.shape != (N_COEF,):
        from gripsense.errors import InputError

        raise InputError(f"PAC94 needs 18 coefficients a0..a17, got shape {a.shape}")
    if variant not in VARIANTS:
        from gripsense.errors import InputError

        raise InputError(f"variant must be one of {VARIANTS}, not {variant!r}")


def pac94_lateral_native(
    a, fz_kn, alpha_deg, gamma_deg, variant: str = "published", jacobian: bool = False
):
    """Fy [N] of the a0..a17 formula in its native units (Fz kN, angles deg).

    Parameters
    ----------
    a : array_like, shape (18,)
        Coefficients a0..a17.
    fz_kn : array_like
        Vertical load [kN].
    alpha_deg, gamma_deg : array_like
        Slip and camber angles [deg].
    variant : {"published", "seed"}
        Form of Sh and Sv (module documentation).
    jacobian : bool
        Also return dFy/da, shape (n, 18).

    Returns
    -------
    fy : ndarray [N]
    jac : ndarray, only when ``jacobian``
    """
    a = np.asarray(a, dtype=float)
    _check(a, variant)
    fz, al, g = np.broadcast_arrays(
        np.asarray(fz_kn, float), np.asarray(alpha_deg, float), np.asarray(gamma_deg, float)
    )
    ag = np.abs(g)
    c = a[0]
    g15 = 1.0 - a[15] * g * g
    d0 = a[1] * fz * fz + a[2] * fz
    d = d0 * g15
    r4 = fz / a[4]
    s4 = np.sin(2.0 * np.arctan(r4))
    g5 = 1.0 - a[5] * ag
    bcd = a[3] * s4 * g5
    cd = c * d
    with np.errstate(divide="ignore", invalid="ignore"):
        b = np.where(cd != 0, bcd / cd, 0.0)
    if variant == "published":
        sh = a[8] * fz + a[9] + a[10] * g
        sv = a[11] * fz + a[12] + (a[13] * fz + a[14]) * g * fz
    else:
        sh = (a[8] * fz + a[9] + a[10] * g) * fz
        sv = a[11] * fz * fz + a[12] * fz + (a[13] * fz * fz + a[14] * fz) * g
    x = al + sh
    sg = np.where(x < 0, -1.0, 1.0)
    e0 = a[6] * fz + a[7]
    h = 1.0 - (a[16] * g + a[17]) * sg
    e = e0 * h
    u = b * x
    atu = np.arctan(u)
    w = u - e * (u - atu)
    phi = np.arctan(w)
    s_cphi = np.sin(c * phi)
    fy = d * s_cphi + sv
    if not jacobian:
        return fy
    c_cphi = np.cos(c * phi)
    dfw = d * c_cphi * c / (1.0 + w * w)  # dF/dw
    dwu = 1.0 - e + e / (1.0 + u * u)  # dw/du
    dfu = dfw * dwu
    with np.errstate(divide="ignore", invalid="ignore"):
        inv_cd = np.where(cd != 0, 1.0 / cd, 0.0)
        inv_d = np.where(d != 0, 1.0 / d, 0.0)
    df_dc = d * c_cphi * phi + dfu * x * (-b / c)
    df_dd = s_cphi + dfu * x * (-b * inv_d)
    df_dbcd = dfu * x * inv_cd
    df_de = -dfw * (u - atu)
    df_dx = dfu * b
    jac = np.empty((*fz.shape, N_COEF))
    jac[..., 0] = df_dc
    jac[..., 1] = df_dd * fz * fz * g15
    jac[..., 2] = df_dd * fz * g15
    jac[..., 15] = df_dd * (-d0 * g * g)
    jac[..., 3] = df_dbcd * s4 * g5
    ds4 = np.cos(2.0 * np.arctan(r4)) * 2.0 / (1.0 + r4 * r4) * (-fz / (a[4] * a[4]))
    jac[..., 4] = df_dbcd * a[3] * g5 * ds4
    jac[..., 5] = df_dbcd * a[3] * s4 * (-ag)
    jac[..., 6] = df_de * fz * h
    jac[..., 7] = df_de * h
    jac[..., 16] = df_de * (-e0 * g * sg)
    jac[..., 17] = df_de * (-e0 * sg)
    k = fz if variant == "seed" else 1.0
    jac[..., 8] = df_dx * fz * k
    jac[..., 9] = df_dx * k
    jac[..., 10] = df_dx * g * k
    if variant == "published":
        jac[..., 11] = fz
        jac[..., 12] = 1.0
        jac[..., 13] = g * fz * fz
        jac[..., 14] = g * fz
    else:
        jac[..., 11] = fz * fz
        jac[..., 12] = fz
        jac[..., 13] = fz * fz * g
        jac[..., 14] = fz * g
    return fy, jac


def pac94_lateral(a, fz, alpha, gamma=0.0, variant: str = "published"):
    """Lateral force of the seed-002 / PAC94 Magic Formula, SI in and out.

    Parameters
    ----------
    a : array_like, shape (18,)
        Coefficients a0..a17 (native units: kN, deg).
    fz : array_like
        Vertical load [N].
    alpha : array_like
        Slip angle [rad].
    gamma : array_like
        Camber angle [rad].
    variant : {"published", "seed"}
        Form of Sh and Sv; docs/physics.md §8.1.

    Returns
    -------
    fy : float or ndarray
        Lateral force [N], in the coefficients' own sign convention.
    """
    fz_a = as_float_array(fz, "fz")
    al = as_float_array(alpha, "alpha")
    ga = as_float_array(gamma, "gamma")
    out = pac94_lateral_native(a, fz_a / 1000.0, al * _RAD2DEG, ga * _RAD2DEG, variant)
    return restore(out, fz, alpha, gamma)
