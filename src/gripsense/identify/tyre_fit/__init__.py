"""One-step constrained identification of Magic Formula lateral coefficients (seed 002).

Seed ``002_0ffa298cd6a17b3b.txt`` fits all coefficients at once to scattered on-road points
(α, γ, Fz, Fy) — every point has its own conditions, so the usual staged fit (one load and camber
at a time) is impossible — and adds constraints that keep the curve physical (docs/physics.md §8.2):

==========  ==========================================================================
set         meaning (PAC94 coefficient names; the MF 6.1 analogue in brackets)
==========  ==========================================================================
shape       eq. 10–11: 1 < C < 2 and −(1 + C²/2) < E < 1 over the data's (Fz, γ) box
            [PCY1; Ey]
symmetric   eq. 12–13: E symmetric and no shifts at γ = 0: a8 = a9 = a11 = a12 = a17 = 0
            [PHY1 = PHY2 = PVY1 = PVY2 = PEY3 = 0]
camber      eq. 14–16: |Sh/γ| < 0.1 deg/deg and |Sv/γ| < 25 N/deg per kN over the data's
            loads, and a15 ≥ 0 (D largest at γ = 0) [PVY3/PVY4, PKY6/PKY7 via Sh; PDY3 ≥ 0]
all         shape + symmetric + camber
none        only the box bounds
==========  ==========================================================================

E is bilinear in (Fz, γ) for a given sign of the shifted slip, so its extremes over the data's
(Fz, γ) box are at the box corners: the shape constraint is enforced there exactly (PAC94);
for MF 6.1 (γ² term) it is enforced on a 5-point camber grid.

The solver is :func:`gripsense.identify.constrained_lsq.solve_constrained_lsq` with the models'
exact Jacobian (PAC94: analytic, sympy-checked; MF 6.1: central differences).
"""

from gripsense.config.tyre_fit import MF61_LATERAL, PAC94_NAMES, TyreFit
from gripsense.identify.tyre_fit._solve import CONSTRAINT_SETS
from gripsense.identify.tyre_fit.from_wheels import (
    FITTERS,
    fit_from_wheel_table,
    fit_tyre_table,
)
from gripsense.identify.tyre_fit.mf61_fit import fit_mf61_lateral
from gripsense.identify.tyre_fit.pac94_fit import fit_pac94

__all__ = [
    "CONSTRAINT_SETS",
    "FITTERS",
    "MF61_LATERAL",
    "PAC94_NAMES",
    "TyreFit",
    "fit_from_wheel_table",
    "fit_mf61_lateral",
    "fit_pac94",
    "fit_tyre_table",
]
