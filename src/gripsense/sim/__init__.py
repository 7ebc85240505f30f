"""Vehicle simulator and sensor emulators: drives with known friction (ground truth)."""

from gripsense.sim.vehicle import SimParams, SimResult, simulate

__all__ = ["SimParams", "SimResult", "simulate"]
