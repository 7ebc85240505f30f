"""Estimators: combine physics functions over tables; results carry validity flags."""

from gripsense.estimate.friction import FLAGS, METHODS, FrictionOptions
from gripsense.estimate.noise import NoiseModel

__all__ = ["FLAGS", "METHODS", "FrictionOptions", "NoiseModel"]
