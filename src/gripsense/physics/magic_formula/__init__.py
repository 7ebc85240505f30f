"""Magic Formula tyre models (PHYSICS.md §8): MF 5.2/6.1/6.2 from ``.tir`` files, PAC89, PAC94."""

from gripsense.physics.magic_formula.mf6 import MFForces, MFTyre

__all__ = ["MFForces", "MFTyre"]
