"""Contact patch: pressure distributions and the contact-length (l–m) model.

References: docs/physics.md §1.1 (thesis eq. 4.8–4.9), §2.1 (eq. 10.2), §5 (eq. 6.23, Table 18).
"""

from __future__ import annotations

import numpy as np

from gripsense._arrays import as_float_array, restore

__all__ = [
    "contact_length_lm",
    "edge_pressure_gradient",
    "pressure_parabolic",
    "pressure_quartic",
]


def pressure_parabolic(x, length, width, load):
    """Second-order contact pressure P2(x) = 6 Fz/(l³ w) · x (l − x).

    Parameters
    ----------
    x : array_like
        Distance from the leading edge, 0 <= x <= l [m].
    length, width : array_like
        Contact length l and width w [m].
    load : array_like
        Vertical load Fz [N].

    Returns
    -------
    pressure : array_like
        [N/m^2]; 0 outside the patch.

    References
    ----------
    Seed 000, eq. (4.8)–(4.9); docs/physics.md §1.1.
    """
    x, l, w, fz = (
        as_float_array(v, n)
        for v, n in ((x, "x"), (length, "length"), (width, "width"), (load, "load"))
    )
    p = 6.0 * fz / (l**3 * w) * x * (l - x)
    return restore(np.where((x >= 0) & (x <= l), p, 0.0), x)


def pressure_quartic(x, length, width, load):
    """Fourth-order (flat-topped) contact pressure P4(x) = 20 Fz/(l⁵ w) · x(l − x)(x² − l x + l²/2).

    Parameters
    ----------
    x : array_like
        Distance from the leading edge [m].
    length, width : array_like
        Contact length l and width w [m].
    load : array_like
        Vertical load Fz [N].

    Returns
    -------
    pressure : array_like
        [N/m^2]; 0 outside the patch.

    References
    ----------
    Seed 000, eq. (10.2); docs/physics.md §2.1.
    """
    x, l, w, fz = (
        as_float_array(v, n)
        for v, n in ((x, "x"), (length, "length"), (width, "width"), (load, "load"))
    )
    p = 20.0 * fz / (l**5 * w) * x * (l - x) * (x**2 - l * x + 0.5 * l**2)
    return restore(np.where((x >= 0) & (x <= l), p, 0.0), x)


def edge_pressure_gradient(length, width, load, pressure: str = "parabolic"):
    """|P′| at the trailing edge: 6 Fz/(l² w) (parabolic) or 10 Fz/(l² w) (quartic) [N/m^3].

    At low utilisation μ ≈ G tanβ /(|P′(l)| (1 − F/(C tanβ))), so this unmeasured quantity sets μ.

    Parameters
    ----------
    length : array_like
        Contact length l [m].
    width : array_like
        Contact width w [m].
    load : array_like
        Vertical load Fz [N].
    pressure : str
        ``parabolic`` or ``quartic``.

    References
    ----------
    docs/physics.md §1.4, §2.1.
    """
    k = {"parabolic": 6.0, "quartic": 10.0}[pressure]
    l, w, fz = (
        as_float_array(v, n) for v, n in ((length, "length"), (width, "width"), (load, "load"))
    )
    return restore(k * fz / (l**2 * w), length)


def contact_length_lm(mass_kg, a: float, b: float):
    """Contact length from the wheel's mass: l = a √m + b m (the thesis's l–m model).

    Parameters
    ----------
    mass_kg : array_like
        Mass carried by the wheel, Fz/g [kg].
    a : float
        Coefficient [m/kg^0.5] (thesis: 0.0104).
    b : float
        Coefficient [m/kg] (thesis: −1.017e-4).

    Returns
    -------
    length : array_like
        [m]; NaN for negative mass.

    References
    ----------
    Seed 000, eq. (6.23), Table 18; docs/physics.md §5.
    """
    m = as_float_array(mass_kg, "mass_kg")
    with np.errstate(invalid="ignore"):
        out = a * np.sqrt(m) + b * m
    return restore(np.where(m >= 0, out, np.nan), mass_kg)
