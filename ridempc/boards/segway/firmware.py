"""The Segway's firmware: balance the platform in pitch, turn by the knee bar.

It reads only the board's own sensors (platform IMU, wheel encoders, knee-bar angle) and sets
only its two wheel motors, like the transporter's controller board:

.. math::

    \\theta = \\arcsin(2 (q_w q_y - q_z q_x)), \\quad
    v = r \\, \\tfrac{1}{2} (\\dot\\phi_L + \\dot\\phi_R + 2 \\omega_y)

    T = k_p \\theta + k_d \\omega_y + k_v v
        + k_{push} \\max(|v| - v_{max}, 0) \\operatorname{sign} v

    \\dot\\psi_{ref} = \\operatorname{clip}(k_{turn} \\delta, \\pm \\dot\\psi_{max}), \\quad
    \\tau_{yaw} = k_{yaw} (\\dot\\psi_{ref} - \\omega_z)

    \\tau_L = T / 2 - \\tau_{yaw}, \\quad \\tau_R = T / 2 + \\tau_{yaw}

with :math:`\\theta` the platform pitch (positive nose down) [rad], :math:`\\omega` the gyro
[rad/s], :math:`\\dot\\phi` the wheel encoder rates relative to the platform [rad/s],
:math:`v` the forward speed [m/s], :math:`\\delta` the knee-bar angle (positive pushed to the
left) [rad] and :math:`T` the total wheel torque [N m], each motor clipped to its limit.
A forward lean of the rider tilts the platform forward, the motors drive forward to hold it
level, so the board accelerates; the speed terms tilt it back as it speeds up, and strongly
above the top speed (the tilt-back of real transporters).
"""

from __future__ import annotations

from ridempc.boards.firmware import BoardIO, Firmware
from ridempc.boards.parameters import BoardParameters
from ridempc.boards.segway.parameters import SegwayParameters
from ridempc.errors import ConfigError
from ridempc.rotations import pitch_of

__all__ = ["SegwayFirmware"]


class SegwayFirmware(Firmware):
    """Pitch balance with speed feedback and tilt-back, yaw-rate loop on the knee bar."""

    def __init__(self, params: BoardParameters, io: BoardIO) -> None:
        if not isinstance(params, SegwayParameters):
            raise ConfigError(f"board '{params.name}': not a Segway's parameters")
        super().__init__(params, io)
        self.segway = params
        self._last: dict[str, float] = {}

    def reconfigure(self, params: BoardParameters) -> None:
        if not isinstance(params, SegwayParameters):
            raise ConfigError(f"board '{params.name}': not a Segway's parameters")
        super().reconfigure(params)
        self.segway = params

    def update(self) -> None:
        p, g, io = self.segway, self.segway.gains, self.io
        pitch = pitch_of(io.sensor("platform_quat"))  # positive nose down
        gyro = io.sensor("platform_gyro")
        wheel_rate = 0.5 * float(io.sensor("left_wheel_vel")[0] + io.sensor("right_wheel_vel")[0])
        speed = p.wheel_radius * (wheel_rate + float(gyro[1]))
        # in Python floats (np.sign and np.clip on a scalar cost 1 and 5 us): the same numbers
        excess = max(abs(speed) - p.top_speed, 0.0) * ((speed > 0.0) - (speed < 0.0))
        total = (
            g.pitch_kp * pitch
            + g.pitch_kd * float(gyro[1])
            + g.speed_kv * speed
            + g.pushback_gain * excess
        )
        knee = float(io.sensor("knee_bar_angle")[0])
        yaw_rate_ref = min(max(g.turn_gain * knee, -g.max_yaw_rate), g.max_yaw_rate)
        yaw = g.yaw_rate_kp * (yaw_rate_ref - float(gyro[2]))
        left = io.actuate("left_wheel", 0.5 * total - yaw)
        right = io.actuate("right_wheel", 0.5 * total + yaw)
        self._last = {
            "pitch": pitch,
            "speed": speed,
            "knee_bar": knee,
            "yaw_rate_ref": yaw_rate_ref,
            "left_torque": left,
            "right_torque": right,
        }

    def diagnostics(self) -> dict[str, float]:
        return (
            dict(self._last)
            if self._last
            else dict.fromkeys(
                ("pitch", "speed", "knee_bar", "yaw_rate_ref", "left_torque", "right_torque"), 0.0
            )
        )
