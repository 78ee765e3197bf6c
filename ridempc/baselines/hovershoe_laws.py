"""The decoupled feedback laws of the hovershoe paper, eq. (10)-(22), as pure functions.

Each function is one of the paper's sub-controllers, stateless and free of the robot, so it
can be checked by hand; :class:`~ridempc.baselines.cassie_hovershoes.CassieHovershoes` feeds
them the estimated signals and adds their outputs to the standing controller (eq. 23-27).

**Signs.** Everything is written in this model's conventions, chosen so that every loop is
stabilising with positive gains: the heading frame has x forward, y to the left and yaw
positive to the left; Cassie's toe joint (``q7``) is positive with the toe raised (nose up),
so a positive toe torque pitches the shoe's platform back and slows the shoe (eq. 8); the
hip-yaw joint (``q2``) of either leg is positive with the toe turned left. Where the paper
prints a different sign it cannot be reconciled with these for all its equations at once:

- eq. (10) prints :math:`-K_p^x`: the leading shoe has to be slowed, which needs its toe
  raised, :math:`q_{\\Delta toe}^{des} = +K_p^x (x_{footL} - x_{footR})` here;
- eq. (22) prints :math:`-K_p^{shift}`: the rider leans into the turn, to the left for a
  left turn forward (:math:`\\theta_{tilt} > 0`), :math:`COM_y^{des} = +K_p^{shift} L
  \\theta_{tilt}` here.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from ridempc.baselines.hovershoe_gains import TurningGains, VelocityGains, XAxisGains, YAxisGains
from ridempc.gravity import GRAVITY

__all__ = [
    "GRAVITY",
    "TurningOutput",
    "com_x_target",
    "hip_yaw_targets",
    "toe_difference_target",
    "toe_difference_torque",
    "turning",
]


def _clip(value: float, bound: float) -> float:
    return min(max(value, -bound), bound)


def toe_difference_target(gains: XAxisGains, x_left: float, x_right: float) -> float:
    """Outer loop of the x-axis controller, eq. (10) [rad].

    .. math:: q_{\\Delta toe}^{des} = K_p^x (x_{footL} - x_{footR})

    clipped to ``max_toe_difference``: the leading shoe's toe is raised, which pitches its
    platform back and slows it.

    Args:
        gains: x-axis gains.
        x_left: Left foot's x in the shoes' frame [m].
        x_right: Right foot's x [m].
    """
    return _clip(gains.kp * (x_left - x_right), gains.max_toe_difference)


def toe_difference_torque(
    gains: XAxisGains, toe_difference: float, toe_difference_rate: float, target: float
) -> float:
    """Inner loop of the x-axis controller, eq. (11)-(13): :math:`u_5^{\\Delta toe}` [N m].

    .. math:: e_{\\Delta toe} = (q_{7L} - q_{7R}) - q_{\\Delta toe}^{des}, \\qquad
        u_5^{\\Delta toe} = -K_p^{\\Delta toe} e_{\\Delta toe} - K_d^{\\Delta toe}
        \\dot e_{\\Delta toe}

    clipped to ``max_torque``; added to the left toe and subtracted from the right. The
    target moves slowly, so :math:`\\dot e_{\\Delta toe} = \\dot q_{7L} - \\dot q_{7R}`.

    Args:
        gains: x-axis gains.
        toe_difference: :math:`q_{7L} - q_{7R}` [rad].
        toe_difference_rate: :math:`\\dot q_{7L} - \\dot q_{7R}` [rad/s].
        target: :math:`q_{\\Delta toe}^{des}` of eq. (10) [rad].
    """
    error = toe_difference - target
    return _clip(-gains.kp_toe * error - gains.kd_toe * toe_difference_rate, gains.max_torque)


def hip_yaw_targets(
    gains: YAxisGains, y_left: float, y_right: float, y_offset: float
) -> tuple[float, float]:
    """Outer loop of the y-axis controller, eq. (14)-(15): hip-yaw targets about the
    posture (left, right) [rad], joint coordinates.

    .. math:: e_{y,L} = y_{footL} - y_{offset}, \\quad e_{y,R} = y_{footR} + y_{offset},
        \\qquad q_2^{des} = -K_p^y e_y

    each clipped to ``max_hip_yaw``. A foot too far out turns its toe in, so that the shoe,
    rolling forward, comes back in. The inner loop, eq. (16),
    :math:`u_2^y = -K_p^{q_2}(q_2 - q_2^{des})`, is run by the hip-yaw motor's driver.

    Args:
        gains: y-axis gains.
        y_left: Left foot's y in the shoes' frame [m] (+ left).
        y_right: Right foot's y [m].
        y_offset: Desired distance of each foot from the centre line [m].
    """
    return (
        _clip(-gains.kp * (y_left - y_offset), gains.max_hip_yaw),
        _clip(-gains.kp * (y_right + y_offset), gains.max_hip_yaw),
    )


def com_x_target(gains: VelocityGains, velocity: float, velocity_desired: float) -> float:
    """Velocity controller, eq. (17): the CoM x target relative to the feet [m].

    .. math:: COM_x^{des} = -K_p^{vel} (vel_{vision} - vel^{des})

    clipped to ``max_com_x``. The standing controller's toe pitch moves the centre of
    mass there, both shoes tilt forward together and accelerate (eq. 8).

    Args:
        gains: Velocity gains.
        velocity: Estimated forward speed [m/s].
        velocity_desired: Commanded forward speed [m/s].
    """
    return _clip(-gains.kp * (velocity - velocity_desired), gains.max_com_x)


@dataclass(frozen=True)
class TurningOutput:
    """The turning controller's outputs, eq. (18)-(22).

    Attributes:
        yaw_rate_error: :math:`e_{yaw}` [rad/s].
        hip_yaw_torque: :math:`u_2^{turn}`, added to both hip-yaw motors [N m].
        toe_torque: :math:`u_5^{turn}`, added to the left toe, subtracted from the right
            [N m].
        tilt: :math:`\\theta_{tilt}` [rad], positive leaning left.
        com_y: :math:`COM_y^{des}` [m], positive to the left.
    """

    yaw_rate_error: float
    hip_yaw_torque: float
    toe_torque: float
    tilt: float
    com_y: float


def turning(
    gains: TurningGains,
    yaw_rate: float,
    yaw_rate_desired: float,
    velocity: float,
    com_height: float,
    error_integral: float = 0.0,
) -> TurningOutput:
    """Turning controller, eq. (18)-(22).

    .. math::
        e_{yaw} = \\dot\\psi - \\dot\\psi^{des}, \\quad
        u_2^{turn} = -K_p^{yaw} e_{yaw}, \\quad
        u_5^{turn} = -K_p^{pitch} e_{yaw} - K_i^{pitch} \\textstyle\\int e_{yaw} dt, \\\\
        \\theta_{tilt} = \\arctan\\frac{\\dot\\psi\\, v}{9.81}, \\quad
        COM_y^{des} = K_p^{shift} L \\theta_{tilt}

    A left turn wanted (:math:`e_{yaw} < 0`) twists both shoes left through the hip-yaw
    motors, against the tyres' scrub (the paper's sign: the torque on the legs), and raises
    the left (inner) toe, lowering the right (outer) one, so the outer shoe runs faster;
    the CoM shifts into the turn by the lean that balances the centripetal acceleration
    :math:`\\dot\\psi v` at the CoM height :math:`L` over the platforms. The toe torque
    is clipped to ``max_toe_torque`` and the shift to ``max_com_y``.

    Args:
        gains: Turning gains.
        yaw_rate: Estimated yaw rate [rad/s] (+ left).
        yaw_rate_desired: Commanded yaw rate [rad/s].
        velocity: Estimated forward speed [m/s].
        com_height: :math:`L`, the CoM's height over the platforms [m].
        error_integral: :math:`\\int e_{yaw} dt` [rad], kept by the caller (the paper's
            suggested integral feedback; its term is inside the toe-torque bound).
    """
    error = yaw_rate - yaw_rate_desired
    tilt = math.atan(yaw_rate * velocity / GRAVITY)
    return TurningOutput(
        yaw_rate_error=error,
        hip_yaw_torque=-gains.kp_yaw * error,
        toe_torque=_clip(
            -gains.kp_pitch * error - gains.ki_pitch * error_integral, gains.max_toe_torque
        ),
        tilt=tilt,
        com_y=_clip(gains.kp_shift * com_height * tilt, gains.max_com_y),
    )
