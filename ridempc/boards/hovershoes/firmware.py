"""Hovershoes firmware: each shoe levels its own platform with its own wheel motor.

Each shoe runs its own :class:`ShoeController`, which reads only that shoe's IMU (frame
quaternion and gyro) and wheel encoder, and drives only that shoe's wheel motor; the two
controllers share nothing but the :class:`HovershoesFirmware` object that ticks them, as on
the real product where the two shoes do not talk to each other.

The law is a pitch PD on the wheel torque, with a tilt-back at the speed limit:

.. math::

    \\tau = k_p (\\theta - \\theta_{ref}) + k_d \\dot\\theta, \\qquad
    \\theta_{ref} = -k_{tb} \\max(0, |v| - v_{max}) \\operatorname{sign}(v)

with :math:`\\theta` [rad] the platform's forward (nose-down) tilt, :math:`v = r(\\omega_w +
\\dot\\theta)` [m/s] the ground speed from the wheel encoder (:math:`\\omega_w` [rad/s], the
wheel's speed relative to the platform) and :math:`\\tau` clipped to the motor's envelope: at
most :math:`\\tau_{max}` against the wheel's turning, and at most
:math:`\\tau_{max}(1 - |\\omega_w|/\\omega_{max})` along it (a DC motor's back-EMF, with
:math:`\\omega_{max}` its no-load speed). A rider who pushes harder than the tilt-back can
hold drives the shoe into that envelope, where it can no longer hold the platform level and
noses down, as a real shoe does. There is no speed feedback below the speed limit, so the paper's
behaviour emerges rather than being scripted: a sustained toe torque :math:`u_\\theta` tilts
the platform to a steady :math:`\\theta` where the motor's reaction balances it, and that
steady torque :math:`k_p\\theta` accelerates the shoe, :math:`m\\dot v = c_4\\theta` (eq. 8);
without toe torque the PD brings the platform back to level and the shoe keeps its speed.
"""

from __future__ import annotations

import math

import numpy as np

from ridempc.boards.firmware import BoardIO, Firmware
from ridempc.boards.hovershoes.model import SIDES, shoe_names
from ridempc.boards.hovershoes.parameters import HovershoesParameters
from ridempc.boards.parameters import BoardParameters

__all__ = ["HovershoesFirmware", "ShoeController", "make_firmware", "pitch_from_quaternion"]


def pitch_from_quaternion(quat_wxyz: np.ndarray) -> float:
    """Forward (nose-down) tilt of a platform about its own lateral axis [rad].

    Args:
        quat_wxyz: The platform's orientation in the world, (w, x, y, z).

    Returns:
        :math:`\\theta = \\operatorname{atan2}(-R_{zx}, R_{zz})`, positive when the front
        of the platform dips (a positive rotation about the shoe's +y axis).
    """
    w, x, y, z = np.asarray(quat_wxyz, dtype=float).tolist()  # Python floats: NumPy's scalars
    r_zx = 2.0 * (x * z - w * y)
    r_zz = 1.0 - 2.0 * (x * x + y * y)
    return math.atan2(-r_zx, r_zz)


class ShoeController:
    """One shoe's firmware: pitch PD to its wheel motor, reading only its own sensors.

    Args:
        params: The pair's parameters (both shoes use the same gains).
        io: The board's I/O; only this shoe's sensor and actuator names are used.
        side: ``left`` or ``right``.
    """

    def __init__(self, params: HovershoesParameters, io: BoardIO, side: str) -> None:
        self.params = params
        self.io = io
        self.names = shoe_names(side)
        self.pitch = 0.0
        self.pitch_rate = 0.0
        self.speed = 0.0
        self.torque = 0.0

    def update(self) -> None:
        p = self.params
        self.pitch = pitch_from_quaternion(self.io.sensor(self.names["quat"]))
        self.pitch_rate = float(self.io.sensor(self.names["gyro"])[1])
        wheel_rate = float(self.io.sensor(self.names["wheel_speed"])[0])
        self.speed = p.wheel_radius * (wheel_rate + self.pitch_rate)
        excess = max(0.0, abs(self.speed) - p.speed_limit)
        pitch_ref = -p.tilt_back_gain * excess * math.copysign(1.0, self.speed)
        torque = p.pitch_kp * (self.pitch - pitch_ref) + p.pitch_kd * self.pitch_rate
        self.torque = self.io.actuate(self.names["motor"], self._envelope(torque, wheel_rate))

    def _envelope(self, torque: float, wheel_rate: float) -> float:
        """Clip to the motor's torque-speed envelope [N m]."""
        limit = self.params.motor_torque_limit
        if torque * wheel_rate > 0.0:  # driving along the rotation: back-EMF limits it
            limit *= max(0.0, 1.0 - abs(wheel_rate) / self.params.motor_speed_limit)
        return min(max(torque, -limit), limit)


class HovershoesFirmware(Firmware):
    """The pair's firmware: two independent :class:`ShoeController`, ticked together.

    Args:
        params: The pair's parameters (rate ``firmware_hz``, gains, limits).
        io: The board's own sensors and actuators.
    """

    def __init__(self, params: BoardParameters, io: BoardIO) -> None:
        assert isinstance(params, HovershoesParameters)
        super().__init__(params, io)
        self.shoes = tuple(ShoeController(params, io, side) for side in SIDES)

    def reconfigure(self, params: BoardParameters) -> None:
        assert isinstance(params, HovershoesParameters)
        super().reconfigure(params)
        for shoe in self.shoes:
            shoe.params = params

    def update(self) -> None:
        for shoe in self.shoes:
            shoe.update()

    def diagnostics(self) -> dict[str, float]:
        out: dict[str, float] = {}
        for side, shoe in zip(SIDES, self.shoes, strict=True):
            out[f"{side}_pitch"] = shoe.pitch
            out[f"{side}_speed"] = shoe.speed
            out[f"{side}_torque"] = shoe.torque
        return out


def make_firmware(params: BoardParameters, io: BoardIO) -> Firmware:
    return HovershoesFirmware(params, io)
