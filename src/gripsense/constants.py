"""Physical constants and statistical quantiles used throughout gripsense — one place each.

Every module that needs standard gravity or a normal / χ² quantile imports it from here, so a
value is never typed twice (``docs/physics.md`` §0).
"""

from __future__ import annotations

__all__ = ["CHI2_1_90", "CHI2_1_99", "G0", "Z90", "Z95"]

G0 = 9.80665
"""Standard gravity [m/s^2] (the thesis states no value; ``docs/physics.md`` §0)."""

Z90 = 1.6448536269514722
"""Normal quantile of a two-sided 90 % interval (= one-sided 95 %) [-]."""

Z95 = 1.959963984540054
"""Normal quantile of a two-sided 95 % interval [-]."""

CHI2_1_90 = 2.705543454095404
"""0.90 quantile of χ² with one degree of freedom (90 % profile-likelihood interval) [-]."""

CHI2_1_99 = 6.6348966010212145
"""0.99 quantile of χ² with one degree of freedom [-]."""
