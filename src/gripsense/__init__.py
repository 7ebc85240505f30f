"""gripsense — tyre-road friction, tyre and steering parameters from how a vehicle moves.

The public API is re-exported here; see the README and ``docs/`` for an overview and
``docs/architecture.md`` for where each kind of thing lives.
"""

from gripsense._version import __version__
from gripsense.config import SteeringCar, Tyre, Vehicle
from gripsense.errors import GripsenseError, InputError, NotObservableError
from gripsense.estimate.noise import NoiseModel
from gripsense.estimate.results import AxleFriction, FrictionResult, WheelFriction, read_result
from gripsense.io import IngestReport, NmeaLog, read_nmea
from gripsense.pipeline import FrictionRun

__all__ = [
    "AxleFriction",
    "FrictionResult",
    "FrictionRun",
    "GripsenseError",
    "IngestReport",
    "InputError",
    "NmeaLog",
    "NoiseModel",
    "NotObservableError",
    "SteeringCar",
    "Tyre",
    "Vehicle",
    "WheelFriction",
    "__version__",
    "read_nmea",
    "read_result",
]
