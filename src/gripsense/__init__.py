"""gripsense — tyre-road friction, tyre and steering parameters from how a vehicle moves.

The public API is re-exported here; see the README and ``docs/`` for an overview.
"""

from gripsense.config import Tyre, Vehicle
from gripsense.errors import GripsenseError, InputError, NotObservableError
from gripsense.io import NmeaLog, read_nmea
from gripsense.pipeline import FrictionResult, FrictionRun

__version__ = "0.1.0"

__all__ = [
    "FrictionResult",
    "FrictionRun",
    "GripsenseError",
    "InputError",
    "NmeaLog",
    "NotObservableError",
    "Tyre",
    "Vehicle",
    "__version__",
    "read_nmea",
]
