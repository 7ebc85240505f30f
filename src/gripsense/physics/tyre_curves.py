"""Normalised lateral tyre curves: the family of shapes a friction estimate must not depend on.

A lateral force curve written in normalised units is one function of one variable,

    F / (μ Fz) = f(x),    x = C tan|α| / (μ Fz),    f(0) = 0, f'(0) = 1, max f = 1,

(``docs/physics.md`` §14): C sets the slope at the origin, μ Fz the peak, and f is the *shape*. A
brush tyre with parabolic pressure has f = x − x²/3 + x³/27 (x ≤ 3), one with quartic pressure
the curve of §2.3; a Magic Formula tyre (seed 002 eq. 1 with B = 1/C_s so that f'(0) = 1) has
f = sin(C_s atan(x/C_s − E (x/C_s − atan(x/C_s)))), shape factor C_s and curvature E.

:data:`SHAPE_FAMILY` is made from real tyres (``docs/physics.md`` §14.3): the Magic Formula
shapes of :data:`gripsense.physics.tyre_family.FAMILY_MEMBERS`, which cover every normalised
curve of 15 published tyre property files at 0.5–1.5 × their nominal load and ±3° inclination
(and of their low-grip sweeps), plus both brush shapes. A tyre's ``shape`` selects members
(:func:`shape_members`): ``any``, ``brush``, ``magic-formula`` or a tyre category
(``passenger``, ``suv``, ``performance``, ``racing``, ``truck``). :data:`BOX_FAMILY` is the
earlier box of constants (C_s 1.1–1.95 × E −1.5…0.8), kept for comparison.

Near the friction limit the members differ by a few per cent in x at a given f; at f = 0.5 by
tens of per cent — which is why a μ estimate from moderate cornering depends on the shape
assumed, and why the estimator treats the shape as unknown.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from gripsense._arrays import as_float_array, restore

__all__ = [
    "BOX_FAMILY",
    "PEAK_RANGE",
    "SHAPE_FAMILY",
    "CurveShape",
    "curve_tables",
    "magic_formula_normalised",
    "normalised_force",
    "shape_members",
]


@dataclass(frozen=True)
class CurveShape:
    """One member of the normalised curve family.

    Attributes
    ----------
    name : str
        Label (``brush-2``, ``brush-4``, ``mf C1.5 E-0.5`` …).
    kind : str
        ``brush-2``, ``brush-4`` or ``magic-formula``.
    c : float
        Magic Formula shape factor C_s [-] (NaN for brush shapes).
    e : float
        Magic Formula curvature factor E [-] (NaN for brush shapes).
    """

    name: str
    kind: str
    c: float = float("nan")
    e: float = float("nan")


def magic_formula_normalised(x, c: float, e: float):
    """Magic Formula curve with unit slope and unit peak, f(x) = sin(C atan(Bx − E(Bx − atan Bx))),
    B = 1/C (seed 002 eq. 1; ``docs/physics.md`` §14).

    Parameters
    ----------
    x : array_like
        Normalised slip C_α tan|α| / (μ Fz) [-] (≥ 0).
    c : float
        Shape factor C_s [-] (1 < C_s < 2 for a peak and a positive asymptote).
    e : float
        Curvature factor E [-] (E ≤ 1).

    Returns
    -------
    array_like
        F / (μ Fz) [-].
    """
    x = as_float_array(x, "x")
    b = 1.0 / c
    bx = b * np.abs(x)
    return restore(np.sin(c * np.arctan(bx - e * (bx - np.arctan(bx)))), x)


def normalised_force(x, shape: CurveShape):
    """F / (μ Fz) of a curve of the family at normalised slip *x* (``docs/physics.md`` §14).

    Parameters
    ----------
    x : array_like
        Normalised slip C tan|α| / (μ Fz) [-].
    shape : CurveShape
        The member.

    Returns
    -------
    array_like
        F / (μ Fz) [-], in [0, 1].
    """
    from gripsense.physics.brush import lateral_force

    x = as_float_array(x, "x")
    if shape.kind == "magic-formula":
        return magic_formula_normalised(x, shape.c, shape.e)
    pressure = "parabolic" if shape.kind == "brush-2" else "quartic"
    # brush with μ = Fz = C = 1: θ = tan β / 3 = x / 3 (docs/physics.md §1.2)
    out = lateral_force(1.0, np.arctan(np.abs(x)), 1.0, 1.0, pressure=pressure, model="exact")
    return restore(np.asarray(out, dtype=float), x)


PEAK_RANGE = (1.5, 6.0)
"""Normalised slip of the peak that real tyres show [-]: the nine example ``.tir`` files peak at
x = 2.4–3.6 between half and 1.5 × their nominal load, brush P2 at 3, brush P4 at 5."""


def _box_family() -> tuple[CurveShape, ...]:
    out = [CurveShape("brush-2", "brush-2"), CurveShape("brush-4", "brush-4")]
    x = np.linspace(0.0, 40.0, 8001)
    for c in (1.1, 1.4, 1.7, 1.95):
        for e in (-1.5, -0.5, 0.3, 0.8):
            x_peak = x[int(np.argmax(magic_formula_normalised(x, c, e)))]
            if PEAK_RANGE[0] <= x_peak <= PEAK_RANGE[1]:
                out.append(CurveShape(f"mf C{c:g} E{e:g}", "magic-formula", c, e))
    return tuple(out)


BOX_FAMILY: tuple[CurveShape, ...] = _box_family()
"""The earlier family, a box of constants: brush P2, brush P4 and the Magic Formula curves of
the grid C_s ∈ {1.1, 1.4, 1.7, 1.95} × E ∈ {−1.5, −0.5, 0.3, 0.8} whose peak lies in
:data:`PEAK_RANGE` (13 of the 16). Kept for comparison (``docs/physics.md`` §14.3)."""


def _data_family() -> tuple[CurveShape, ...]:
    from gripsense.physics.tyre_family import FAMILY_MEMBERS

    out = [CurveShape("brush-2", "brush-2"), CurveShape("brush-4", "brush-4")]
    out += [CurveShape(f"mf C{c:g} E{e:g}", "magic-formula", c, e) for c, e in FAMILY_MEMBERS]
    return tuple(out)


SHAPE_FAMILY: tuple[CurveShape, ...] = _data_family()
"""The shapes ``axle-window`` considers: brush P2, brush P4 and the Magic Formula shapes made
from real tyres (:data:`gripsense.physics.tyre_family.FAMILY_MEMBERS`, ``docs/physics.md``
§14.3)."""


def shape_members(prior: str) -> tuple[int, ...]:
    """Indices of the members of :data:`SHAPE_FAMILY` a tyre's ``shape`` allows
    (``docs/physics.md`` §14.3).

    Parameters
    ----------
    prior : str
        ``any`` (every member), ``brush`` (brush P2 and P4), ``magic-formula`` (the shapes made
        from real tyres) or a tyre category of
        :data:`gripsense.physics.tyre_family.CATEGORIES` (the members that cover that
        category's files).

    Returns
    -------
    tuple of int
        The indices.
    """
    from gripsense.physics.tyre_family import CATEGORIES, category_members

    if prior in CATEGORIES:
        keep = set(category_members(prior))
        return tuple(
            i
            for i, s in enumerate(SHAPE_FAMILY)
            if s.kind == "magic-formula" and (s.c, s.e) in keep
        )
    kinds = {"any": None, "brush": ("brush-2", "brush-4"), "magic-formula": ("magic-formula",)}
    if prior not in kinds:
        raise ValueError(
            f"shape {prior!r}: use one of {', '.join(kinds)} or {', '.join(CATEGORIES)}"
        )
    allowed = kinds[prior]
    return tuple(i for i, s in enumerate(SHAPE_FAMILY) if allowed is None or s.kind in allowed)


def curve_tables(
    shapes: tuple[CurveShape, ...] = SHAPE_FAMILY, *, x_max: float = 40.0, n: int = 4001
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Tabulated f and f' of each shape on a uniform grid of x, for fast interpolation.

    Parameters
    ----------
    shapes : tuple of CurveShape
        The members.
    x_max : float
        Largest normalised slip tabulated [-]; beyond it f is taken constant.
    n : int
        Grid points.

    Returns
    -------
    x : numpy.ndarray
        The grid [-], shape (n,).
    f : numpy.ndarray
        F/(μ Fz), shape (len(shapes), n).
    df : numpy.ndarray
        df/dx, shape (len(shapes), n) (central differences of the exact curves).
    """
    x = np.linspace(0.0, x_max, n)
    h = 1e-6
    f = np.empty((len(shapes), n))
    df = np.empty((len(shapes), n))
    for i, s in enumerate(shapes):
        f[i] = normalised_force(x, s)
        df[i] = (normalised_force(x + h, s) - normalised_force(np.maximum(x - h, 0.0), s)) / (
            x + h - np.maximum(x - h, 0.0)
        )
    return x, f, df
