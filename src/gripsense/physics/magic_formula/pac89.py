"""PAC89 Magic Formula (Bakker, Nyborg & Pacejka 1989), Adams numbering a0..a13 and b0..b10.

Equations as in Project Chrono's ``ChPac89Tire`` (the program the bundled
``HMMWV_Pac89Tire.json`` set was made for), native units Fz [kN], α and γ [deg], κ [%]::

    lateral:       C = a0, D = (a1 Fz + a2) Fz, BCD = a3 sin(2 atan(Fz/a4)) (1 − a5 |γ|),
                   E = a6 Fz + a7, Sh = a8 γ + a9 Fz + a10, Sv = a11 Fz γ + a12 Fz + a13
    longitudinal:  C = b0, D = (b1 Fz + b2) Fz, BCD = (b3 Fz² + b4 Fz) exp(−b5 Fz),
                   E = b6 Fz² + b7 Fz + b8, Sh = b9 Fz + b10, Sv = 0
    F = D sin(C atan(B x − E (B x − atan(B x)))) + Sv,  x = slip + Sh,  B = BCD/(C D)

Published listings order a8–a10 and a11–a13 differently; check a set's source when its shift
coefficients are non-zero (they are zero in the HMMWV set). Signs are the coefficients' own.
The public functions take SI (N, rad, slip ratio) and convert at the edge.
"""

from __future__ import annotations

import numpy as np

from gripsense._arrays import as_float_array, restore
from gripsense.errors import InputError

__all__ = ["magic_formula", "pac89_lateral", "pac89_longitudinal"]

_RAD2DEG = 180.0 / np.pi


def magic_formula(x, b, c, d, e):
    """The Magic Formula sine curve D sin(C atan(B x − E (B x − atan(B x)))).

    Parameters
    ----------
    x : array_like
        Shifted slip [any unit; B carries its inverse].
    b, c, d, e : array_like
        Stiffness, shape, peak and curvature factors.

    Returns
    -------
    ndarray
        Force in the unit of ``d``. Pacejka (2012) eq. (4.49).
    """
    bx = b * x
    return d * np.sin(c * np.arctan(bx - e * (bx - np.arctan(bx))))


def _coef(coeffs: dict, prefix: str, n: int) -> list[float]:
    low = {k.lower(): v for k, v in coeffs.items()}
    out = []
    for i in range(n):
        k = f"{prefix}{i}"
        if k not in low:
            raise InputError(f"PAC89: missing coefficient {k}; give {prefix}0..{prefix}{n - 1}")
        out.append(float(low[k]))
    return out


def pac89_lateral(coeffs: dict, fz, alpha, gamma=0.0):
    """PAC89 lateral force.

    Parameters
    ----------
    coeffs : dict
        ``{"a0": ..., ..., "a13": ...}``.
    fz : array_like
        Vertical load [N].
    alpha, gamma : array_like
        Slip and camber angle [rad].

    Returns
    -------
    fy : float or ndarray [N]
    """
    a = _coef(coeffs, "a", 14)
    fz_kn = as_float_array(fz, "fz") / 1000.0
    al = as_float_array(alpha, "alpha") * _RAD2DEG
    g = as_float_array(gamma, "gamma") * _RAD2DEG
    c = a[0]
    d = (a[1] * fz_kn + a[2]) * fz_kn
    bcd = a[3] * np.sin(2.0 * np.arctan(fz_kn / a[4])) * (1.0 - a[5] * np.abs(g))
    with np.errstate(divide="ignore", invalid="ignore"):
        b = np.where(c * d != 0, bcd / (c * d), 0.0)
    e = a[6] * fz_kn + a[7]
    sh = a[8] * g + a[9] * fz_kn + a[10]
    sv = a[11] * fz_kn * g + a[12] * fz_kn + a[13]
    out = magic_formula(al + sh, b, c, d, e) + sv
    return restore(out, fz, alpha, gamma)


def pac89_longitudinal(coeffs: dict, fz, kappa):
    """PAC89 longitudinal force (slip in percent inside, ratio outside).

    Parameters
    ----------
    coeffs : dict
        ``{"b0": ..., ..., "b10": ...}``.
    fz : array_like
        Vertical load [N].
    kappa : array_like
        Longitudinal slip ratio [-].

    Returns
    -------
    fx : float or ndarray [N]
    """
    bb = _coef(coeffs, "b", 11)
    fz_kn = as_float_array(fz, "fz") / 1000.0
    k = as_float_array(kappa, "kappa") * 100.0
    c = bb[0]
    d = (bb[1] * fz_kn + bb[2]) * fz_kn
    bcd = (bb[3] * fz_kn**2 + bb[4] * fz_kn) * np.exp(-bb[5] * fz_kn)
    with np.errstate(divide="ignore", invalid="ignore"):
        b = np.where(c * d != 0, bcd / (c * d), 0.0)
    e = bb[6] * fz_kn**2 + bb[7] * fz_kn + bb[8]
    sh = bb[9] * fz_kn + bb[10]
    out = magic_formula(k + sh, b, c, d, e)
    return restore(out, fz, kappa)
