"""The rider's whole-body QP and its motors' tracking gains, as a pair file sets them
(:class:`~ridempc.mpc.rider.MpcRider`'s wiring)."""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from ridempc.boards.board import Board
from ridempc.mpc.pairs import MpcPair
from ridempc.mpc.platform_feet import rolling_platforms
from ridempc.mpc.riding_posture import ride_qpos
from ridempc.robots.delay_margin import tracking_damping
from ridempc.robots.pinocchio_model import PinocchioRobot
from ridempc.robots.robot import Robot
from ridempc.sim.clock import DEFAULT_PHYSICS_HZ
from ridempc.solvers import solver_for
from ridempc.wbc import WholeBodyController
from ridempc.wbc.controller import motor_posture
from ridempc.wbc.settings import WbcSettings

__all__ = ["rider_wbc", "tracking_gains"]

Array = NDArray[np.float64]


def rider_wbc(
    robot: Robot,
    board: str,
    loaded: Board | None,
    pinocchio: PinocchioRobot,
    pair: MpcPair,
    solver: str | None,
) -> WholeBodyController:
    """The whole-body QP of ``robot`` riding ``board`` (``loaded``: its description, or
    None), its posture task holding the robot's riding posture, the board's rolling
    platforms in its model.

    Cassie's leaf springs are rigid joints held at their deflection: as passive torques the
    estimator's spring deflection (about twice the true one, through the soft achilles-rod
    constraint) drives the QP off (see the WBC's tests). The MPC's forces weigh the pair
    file's ``wbc.force_weight`` (the WBC's own default is 1): their distribution over the
    feet is what rolls a deck or a platform, and the CoM and orientation tasks leave it
    free (measurements: docs/tuning.md, "Pair files"). ``solver``: None for the registry's.
    """
    sprung = bool(np.any(pinocchio.spring_stiffness > 0.0))
    settings = WbcSettings(
        springs="rigid" if sprung else "passive",
        force_weight=pair.description.wbc.force_weight,
        pyramid=pair.pyramid,
        solver=solver or solver_for("wbc"),
    )
    return WholeBodyController(
        robot,
        settings,
        pinocchio=pinocchio,
        posture=motor_posture(pinocchio, robot, ride_qpos(robot, board)),
        platforms=rolling_platforms(loaded),
    )


def tracking_gains(robot: Robot, board: str, scale: float) -> tuple[Array, Array]:
    """The motor PD's stiffnesses [N m/rad] and dampings [N m s/rad] under the QP's
    torques: ``scale`` of the defaults (the QP's torques lead, the PD follows), each
    delayed motor damped at the largest phase margin for its stiffness at the joint's
    inertia in the riding posture (:func:`~ridempc.robots.delay_margin.tracking_damping`)."""
    kp = scale * np.array([m.kp for m in robot.motors])
    kd = tracking_damping(
        robot.mj_model,
        ride_qpos(robot, board),
        robot.motors,
        kp,
        scale * np.array([m.kd for m in robot.motors]),
        1.0 / DEFAULT_PHYSICS_HZ,
    )
    return kp, kd
