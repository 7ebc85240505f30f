"""Vehicle simulator and sensor emulators: drives with known friction (ground truth)."""

from gripsense.physics.steering_system import descriptor, simulate_release, simulate_step
from gripsense.sim.gnss import CompassLog, CompassNoise, emulate_compass
from gripsense.sim.integrate import simulate
from gripsense.sim.maneuvers import Maneuver
from gripsense.sim.scenario import run_scenario
from gripsense.sim.sensors import emulate_accelerometer, emulate_steering
from gripsense.sim.steering_torque import aligning_moments, emulate_torque
from gripsense.sim.tyres import SimTyre, load_sim_tyre
from gripsense.sim.vehicle import SimParams, SimResult

__all__ = [
    "CompassLog",
    "CompassNoise",
    "Maneuver",
    "SimParams",
    "SimResult",
    "SimTyre",
    "aligning_moments",
    "descriptor",
    "emulate_accelerometer",
    "emulate_compass",
    "emulate_steering",
    "emulate_torque",
    "load_sim_tyre",
    "run_scenario",
    "simulate",
    "simulate_release",
    "simulate_step",
]
