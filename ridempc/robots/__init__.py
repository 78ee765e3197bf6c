"""Robot descriptions (MJCF read by MuJoCo and Pinocchio) and their parameters."""

from ridempc.robots.motor_curve import TorqueSpeedCurve
from ridempc.robots.parameters import MotorParameters, RobotParameters, load_robot_parameters
from ridempc.robots.robot import Motor, Robot, load_robot, robot_names

__all__ = [
    "Motor",
    "MotorParameters",
    "Robot",
    "RobotParameters",
    "TorqueSpeedCurve",
    "load_robot",
    "load_robot_parameters",
    "robot_names",
]
