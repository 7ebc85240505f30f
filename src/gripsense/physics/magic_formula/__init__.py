"""Magic Formula tyre models (docs/physics.md §8, §12): MF 5.2/6.1/6.2, PAC89, PAC94."""

from gripsense.physics.magic_formula.mf6 import MFForces, MFTyre

__all__ = ["MFForces", "MFTyre"]
