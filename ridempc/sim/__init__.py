"""The simulation: scene, sensors, motor drivers, multi-rate loop, judge and outputs.

Import the loop from :mod:`ridempc.sim.simulation`; this package root exports only the
leaf modules, so that scenarios and controllers can use sensor and motor types without
importing the loop.
"""

from ridempc.sim.clock import DEFAULT_PHYSICS_HZ, Rate
from ridempc.sim.motors import MotorCommand, MotorDriver
from ridempc.sim.sensors import SensorNoise, SensorPacket, SensorSuite

__all__ = [
    "DEFAULT_PHYSICS_HZ",
    "MotorCommand",
    "MotorDriver",
    "Rate",
    "SensorNoise",
    "SensorPacket",
    "SensorSuite",
]
