"""The grid of normalised lateral curve shapes a car's own limits can teach
(``docs/physics.md`` §15.10).

The estimator's prior family (:data:`gripsense.physics.tyre_curves.SHAPE_FAMILY`) holds a few
shapes spread over what tyres span; learning needs a grid fine enough that the shape a drive
pins lies close to one of its members: the Magic Formula normalised curves
f(x) = sin(C_s atan(x/C_s − E (x/C_s − atan(x/C_s)))) (§14) on C_s ∈ 1.1…2.0 (step 0.1) ×
E ∈ −2.0…0.9 (step 0.2) whose peak lies in :data:`~gripsense.physics.tyre_curves.PEAK_RANGE`,
and both brush shapes. Up to 1.5 × the peak's slip neighbouring members differ by at most 0.04
in f (median 0.02), so any Magic Formula shape inside the grid lies within about 0.02 of a
member (``tests/physics/test_shape_grid.py``).
"""

from __future__ import annotations

from functools import cache

import numpy as np

from gripsense.physics.tyre_curves import (
    PEAK_RANGE,
    CurveShape,
    curve_tables,
    magic_formula_normalised,
)

__all__ = ["LEARN_C", "LEARN_E", "LEARN_GRID", "learn_tables"]

LEARN_C = tuple(float(c) for c in np.round(np.arange(1.1, 2.0001, 0.1), 2))
"""Shape factors C_s of the grid [-]."""
LEARN_E = tuple(float(e) for e in np.round(np.arange(-2.0, 0.9001, 0.2), 2))
"""Curvature factors E of the grid [-]."""


def _grid() -> tuple[CurveShape, ...]:
    out = [CurveShape("brush-2", "brush-2"), CurveShape("brush-4", "brush-4")]
    x = np.linspace(0.0, 40.0, 8001)
    for c in LEARN_C:
        for e in LEARN_E:
            x_peak = x[int(np.argmax(magic_formula_normalised(x, c, e)))]
            if PEAK_RANGE[0] <= x_peak <= PEAK_RANGE[1]:
                out.append(CurveShape(f"mf C{c:g} E{e:g}", "magic-formula", c, e))
    return tuple(out)


LEARN_GRID: tuple[CurveShape, ...] = _grid()
"""The shapes a calibration's learned evidence is given over (brush P2, brush P4, then the
Magic Formula grid in C_s-major order)."""


@cache
def learn_tables() -> tuple[np.ndarray, np.ndarray, float]:
    """Force tables of :data:`LEARN_GRID`, their slopes and 1/Δx of the table grid (computed
    once; :func:`~gripsense.physics.tyre_curves.curve_tables`).

    Returns
    -------
    f : numpy.ndarray
        F/(μ Fz) per shape and x [-].
    df : numpy.ndarray
        df/dx [-].
    inv_dx : float
        1 / grid step of x [-].
    """
    x, f, df = curve_tables(LEARN_GRID)
    return f, df, 1.0 / (x[1] - x[0])
