"""Robot descriptions (MJCF read by MuJoCo and Pinocchio) and their parameters."""

from ridempc.robots.parameters import MotorParameters, RobotParameters, load_robot_parameters
from ridempc.robots.robot import Motor, Robot, load_robot, robot_names

__all__ = [
    "Motor",
    "MotorParameters",
    "Robot",
    "RobotParameters",
    "load_robot",
    "load_robot_parameters",
    "robot_names",
]
