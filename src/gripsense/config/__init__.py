"""Descriptions of the things being measured: vehicle, tyres, steering system (TOML in, SI out).

Classes here only hold parameters and fill in arguments of the physics functions; they contain no
algorithms (the pvlib ``Location``/``PVSystem`` rule). All files are read by one TOML reader
(:class:`~gripsense.config.toml_reader.TomlReader`) whose errors name file, table and key.
"""

from gripsense.config.receiver import RECEIVERS, Receiver, receiver_from
from gripsense.config.steering import SteeringCar
from gripsense.config.vehicle import AXLE_OF, PLAUSIBLE, WHEELS, Tyre, Vehicle

__all__ = [
    "AXLE_OF",
    "PLAUSIBLE",
    "RECEIVERS",
    "WHEELS",
    "Receiver",
    "SteeringCar",
    "Tyre",
    "Vehicle",
    "receiver_from",
]
