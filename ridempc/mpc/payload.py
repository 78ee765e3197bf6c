"""The rider's mass and centre-of-mass offset, estimated online from its stance's loads.

A payload (a backpack, a lighter or heavier rider) changes what the models assume: the
total mass :math:`m_0` [kg] and the centre of mass :math:`c` [m]. Standing on its feet the
rider carries all of it, so both are read off the contact wrench, from the sensors alone
(the feet's loads from the contact signal, :mod:`ridempc.estimation.contact`, the motor
torques and the IMU):

- **mass**: each foot :math:`i` of :math:`n` carries
  :math:`F_i = \\ell_i\\, m_0 g / n` [N] (its load fraction :math:`\\ell_i` of its standing
  share); the feet together carry the mass times the vertical specific force the IMU
  measures, :math:`f_z = g + \\ddot c_z` [m/s^2] (world axes), so

  .. math:: \\hat m = \\sum_i F_i / f_z;

- **centre of mass**: a foot's load is split between its contact sites (Cassie's toe
  line: two sites) by the torque of the last motor on its chain (its ankle),
  :math:`\\sum_s a_s f_s = g_a(q) - \\tau_a`, :math:`\\sum_s f_s = F_i`, with
  :math:`a_s = \\partial z_s / \\partial q_a` [m/rad] the site's vertical Jacobian column
  (one site: all of it there). The sites' centre of pressure
  :math:`p = \\sum f_s p_s / \\sum f_s` stands under the centre of mass in a static
  balance; swaying, the zero-moment point's term carries its acceleration,
  :math:`c_{xy} = p_{xy} + h\\, \\ddot c_{xy} / f_z` (:math:`h` [m] the centre of mass
  above the feet), with :math:`\\ddot c` the difference of the model's centre-of-mass
  velocity over the MPC step. One step's difference is noisy (the velocity's noise over
  1/30 s: several centimetres), but summed over the steps it telescopes to
  :math:`h\\,(\\dot c_k - \\dot c_0) / (f_z\\, t_k)`: a mean of the readings needs only
  that the sway's velocity stays bounded. The offset is what the corrected reading differs
  by from the model's centre of mass (the estimate already in it). Only the directions the
  sites span are seen (a line of sites: only along it); :math:`c_z` is not observed.

Both are averaged over an MPC step, only while every foot is in contact and the rider is not
falling (:math:`f_z > g/2`), and (by the rider) only while it balances, holding or coasting:
a manoeuvre's accelerations move the centre of pressure off the centre of mass. The mass
ratio :math:`\\hat m / m_0` is low-passed with the time constant :data:`TIME_CONSTANT_S`,
its excess over 1 shrunk by :data:`MASS_DEADBAND` (the load signals' calibration) and held
within :data:`MASS_BOUND`; the offset's error, shrunk by :data:`SHIFT_DEADBAND_M`, is
integrated with the time constant :data:`SHIFT_TIME_CONSTANT_S`. That slow loop is for the
MPC's own ride, where the estimate closes a loop through the balance (a faster one fed the
sway back). While the backup balance rides (:mod:`ridempc.mpc.handover`: the ride's start,
a handover) the estimate closes no loop, and both are the *running mean* of the readings
taken so far, the least-squares estimate of a constant (gain :math:`1/k` at the
:math:`k`-th reading, never below the slow loop's :math:`\\Delta t / T`): the error of a
mean of :math:`k` readings falls as :math:`1/\\sqrt k`, where a low pass keeps its time
constant's noise for good (:meth:`PayloadEstimator.update`'s ``open_loop``). The mean's
offset enters the models shortened by :data:`MEAN_DEADBAND_M` (half the slow loop's dead
band), the mass by the same :data:`MASS_DEADBAND`. The estimate enters the
models' body inertias (:meth:`PayloadEstimate.inertias`): a heavier rider carries
:math:`\\Delta m = \\hat m - m_0` on its base (a payload), a lighter one is lighter
throughout (every body scaled), and the base's centre of mass is moved by :math:`\\delta` so
that the whole one moves by the estimated offset :math:`s`,
:math:`m_b' \\delta = (m_0 + \\Delta m)\\, s`. The whole-body controller's dynamics then
carry the payload's weight and its moment, the MPC's state the shifted centre of mass, and
the MPC's vertical rate the extra weight,
:math:`\\dot v_z = \\sum f_z / m_0 - g - g\\, \\Delta m / m_0`
(:meth:`PayloadEstimate.drift`), so that its forces hold :math:`m_0 + \\Delta m`.

The feet must be the rider's only support: where the board takes weight elsewhere (the
Segway's knee bar, through the shins) the feet's loads do not weigh the rider and the
estimate runs away; a pair uses it through its ``[stages.payload]``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np
import pinocchio as pin
from numpy.typing import NDArray

from ridempc.estimation.legs import LegKinematics
from ridempc.gravity import GRAVITY
from ridempc.robots.pinocchio_model import PinocchioRobot
from ridempc.robots.robot import Robot

if TYPE_CHECKING:
    from ridempc.sim.sensors import ImuReading

__all__ = [
    "MASS_BOUND",
    "MASS_DEADBAND",
    "MEAN_DEADBAND_M",
    "PayloadEstimate",
    "PayloadEstimator",
    "SHIFT_DEADBAND_M",
    "SHIFT_TIME_CONSTANT_S",
    "TIME_CONSTANT_S",
]

Array = NDArray[np.float64]
# A third of the balance's own time, sqrt(h/g) ~ 0.3 s for a 0.9 m centre of mass: the
# estimate settles before the fall it is there to prevent.
TIME_CONSTANT_S: float = 0.1
# [-] the load signals are calibrated in the standing keyframe: in a riding crouch without a
# payload they read 1.04-1.10 of the rider's weight, so a mass within this fraction of the
# model's is the model's.
MASS_DEADBAND: float = 0.1
# [-] a larger reading is the load signals' error, not a payload: the sweeps' payloads reach
# 30 %, and where the feet were not the rider's only support (the Segway's knee bar) the
# reading ran to 1.8 with +30 %.
MASS_BOUND: float = 0.4
# [m] the centre of pressure sways with the balance (1-3 cm across the feet over an MPC step
# on the Hovershoes without a payload, 0.5 cm behind along them): a smaller offset is the
# model's.
SHIFT_DEADBAND_M: float = 0.01
# [s] the offset integrates the sway's centre of pressure: at 0.3-0.5 s the integration fed
# the sway back (the estimate swung +-7 cm across the feet); about seven times the balance's
# own time (0.3 s) keeps it to the steady part.
SHIFT_TIME_CONSTANT_S: float = 2.0
# [m] the running mean's own dead band, applied to what enters the models: over the start's
# first second the mean reads up to 4 mm without a payload (the PD's landing and settling;
# library yaw-steps seed 0: -0.4 cm at the takeover), and fed in, that bias cost the
# library's tracking.
MEAN_DEADBAND_M: float = 0.005
WORLD_ALIGNED = pin.ReferenceFrame.LOCAL_WORLD_ALIGNED


@dataclass(frozen=True)
class PayloadEstimate:
    """The estimated payload.

    Attributes:
        mass: :math:`\\Delta m` [kg], the rider's mass beyond the model's (negative: lighter).
        shift: :math:`s` [m], the whole centre of mass's offset from the model's, base frame.
        model_mass: :math:`m_0` [kg], the model's total mass.
    """

    mass: float = 0.0
    shift: Array = field(default_factory=lambda: np.zeros(3))
    model_mass: float = 1.0

    def inertias(self, nominal: list[pin.Inertia]) -> list[pin.Inertia]:
        """The model's body inertias (joint order, ``nominal[1]`` the base's) carrying the
        estimate: a heavier rider carries :math:`\\Delta m` on the base at its centre of
        mass (a payload); a lighter one is lighter throughout, every body scaled by
        :math:`(m_0 + \\Delta m) / m_0` about its own centre of mass (the loads cannot tell
        where along the legs a mass is: these are the priors); then the base's centre of
        mass is moved by :math:`\\delta`, :math:`m_b' \\delta = (m_0 + \\Delta m)\\, s`."""
        out = list(nominal)
        if self.mass >= 0.0:
            base = nominal[1]
            out[1] = pin.Inertia(base.mass + self.mass, base.lever, base.inertia)
        else:
            scale = (self.model_mass + self.mass) / self.model_mass
            out = [pin.Inertia(i.mass * scale, i.lever, i.inertia * scale) for i in nominal]
        base = out[1]
        lever = base.lever + (self.model_mass + self.mass) * self.shift / base.mass
        out[1] = pin.Inertia(base.mass, lever, base.inertia)
        return out

    def settling(self) -> Array:
        """What the takeover watches settle (:mod:`ridempc.mpc.readiness`): the mass
        beyond the model's as a fraction of it [-], and the offset along and across the
        base [m] (its height is not observed)."""
        return np.array([self.mass / self.model_mass, self.shift[0], self.shift[1]])

    def drift(self, nx: int, vz: int) -> Array:
        """The payload's weight as a constant term of the MPC's rates (nx): on the vertical
        velocity's row ``vz``, :math:`-g \\Delta m / m_0` [m/s^2]."""
        out = np.zeros(nx)
        out[vz] = -GRAVITY * self.mass / self.model_mass
        return out


def _shrunk(offset: Array, deadband: float) -> Array:
    """``offset`` [m] shortened by ``deadband`` [m] (zero within it)."""
    length = max(float(np.linalg.norm(offset)), 1e-9)
    return offset * max(0.0, 1.0 - deadband / length)


class PayloadEstimator:
    """Estimates :class:`PayloadEstimate` from the stance's loads (module docstring).

    Args:
        robot: The rider.
        pinocchio: Its model (nominal; read, not changed).
        dt: The MPC step, the time between :meth:`update` calls [s].
    """

    def __init__(self, robot: Robot, pinocchio: PinocchioRobot, dt: float) -> None:
        self.model = pin.Model(pinocchio.model)
        self.data = self.model.createData()
        self.legs = LegKinematics.build(robot, pinocchio)
        self.mass0 = float(pin.computeTotalMass(self.model))
        self.share = self.mass0 * GRAVITY / len(self.legs.feet)  # [N] a foot's standing load
        self.alpha = min(1.0, dt / TIME_CONSTANT_S)
        self.alpha_shift = min(1.0, dt / SHIFT_TIME_CONSTANT_S)
        motor_v = [
            int(self.model.joints[self.model.getJointId(m.joint)].idx_v) for m in robot.motors
        ]
        # each foot's ankle: the last motor on its chain, and that motor's index
        self.ankles: list[tuple[int, int] | None] = []
        for foot in self.legs.feet:
            on_chain = [v for v in foot.chain_v if int(v) in motor_v]
            if len(foot.sites) < 2 or not on_chain:
                self.ankles.append(None)
            else:
                v = int(max(on_chain))
                self.ankles.append((v, motor_v.index(v)))
        self.nominal_inertias = [pin.Inertia(i) for i in self.model.inertias]
        self.estimate = PayloadEstimate(model_mass=self.mass0)
        self._ratio = 1.0  # [-] the low-passed measured mass over the model's
        self._sum: Array | None = None  # the readings since the last update, summed
        self._count = 0
        self.dt = dt
        self._vcom: Array | None = None  # [m/s] the model's centre-of-mass velocity, last step
        self._readings = 0  # the readings taken while the backup rode (the running mean's k)
        self.mean_shift = np.zeros(3)  # [m] the offset readings' running mean, base frame
        self._weighed: float | None = None  # [kg] the mass weighed another way, if any

    def weigh(self, mass: float) -> None:
        """Take the rider's mass beyond the model's, :math:`\\Delta m` [kg], from another
        reading than the feet's loads (:mod:`ridempc.mpc.vertical_weight`): the loads are
        not read from then on, and the centre of mass's offset stays the model's (it is
        read from the loads' split between heel and toe, which needs their scale)."""
        self._weighed = mass
        self.estimate = PayloadEstimate(mass, self.estimate.shift, self.mass0)

    def _com_velocity(self, q: Array, v: Array | None) -> Array | None:
        """The nominal model's centre-of-mass velocity [m/s] (world), None without ``v``."""
        if v is None:
            return None
        pin.centerOfMass(self.model, self.data, q, v)
        return np.array(self.data.vcom[0])

    def reading(self) -> float | None:
        """The mean of the readings since the last :meth:`update` as a mass ratio,
        :math:`\\sum_i \\ell_i\\, m_0 g / n / (m_0 f_z)` [-] (module docstring; the load
        signals uncalibrated), None without one or with :math:`f_z \\le g/2` (falling)."""
        if self._sum is None:
            return None
        n = len(self.legs.feet)
        mean = self._sum / self._count
        if mean[-1] <= 0.5 * GRAVITY:
            return None
        return float(np.sum(mean[:n]) * self.share / (self.mass0 * mean[-1]))

    def reset(self) -> None:
        """Forget the readings since the last :meth:`update`."""
        self._sum, self._count = None, 0

    def accumulate(
        self, loads: Array, contact: NDArray[np.bool_], motor_torque: Array, imu: ImuReading
    ) -> None:
        """One control tick's reading: each foot's load fraction [-], its contact flag, the
        motor torques [N m] and the IMU; a foot off contact drops the step's readings; none
        taken once the mass is weighed another way (:meth:`weigh`: :meth:`update` drops them)."""
        if self._weighed is not None:
            return
        if not np.all(contact):
            self.reset()
            return
        w, x, y, z = (float(c) for c in imu.quaternion)
        rotation = pin.Quaternion(w, x, y, z).toRotationMatrix()  # body to world
        specific = rotation @ np.asarray(imu.linear_acceleration, dtype=np.float64)
        reading = np.concatenate([loads, motor_torque, specific])
        self._sum = reading if self._sum is None else self._sum + reading
        self._count += 1

    def update(
        self, q: Array, com: Array, v: Array | None = None, open_loop: bool = False
    ) -> PayloadEstimate:
        """The estimate after one MPC step's readings, at the configuration ``q``
        (Pinocchio), with the model's centre of mass ``com`` [m] (world, with the estimate
        in it) and the velocity ``v`` (Pinocchio; None: no sway's acceleration term);
        held where no reading came in with every foot in contact. ``open_loop``: the
        estimate closes no loop through the balance (the backup rides): the running mean
        (module docstring)."""
        if self._weighed is not None:  # weighed another way: the loads are not read
            self.reset()
            return self.estimate
        vcom = self._com_velocity(q, v)
        if self._sum is None:
            self._vcom = None  # a gap: the next reading starts a new run
            return self.estimate
        n = len(self.legs.feet)
        mean = self._sum / self._count
        self.reset()
        loads, torque, specific = mean[:n], mean[n:-3], mean[-3:]
        if specific[2] < 0.5 * GRAVITY or np.sum(loads) <= 0.0:
            self._vcom = None
            return self.estimate
        accel = np.zeros(3) if self._vcom is None or vcom is None else (vcom - self._vcom) / self.dt
        self._vcom = vcom
        self._readings += 1 if open_loop else 0
        fast = 1.0 / self._readings if open_loop else 0.0  # the running mean's gain
        forces = loads * self.share  # [N] per foot
        ratio = float(np.sum(forces) / (self.mass0 * specific[2]))
        slow = max(fast, self.alpha_shift)  # open loop: the mean, then the offset's low pass
        self._ratio += (slow if open_loop else self.alpha) * (ratio - self._ratio)
        excess = self._ratio - 1.0
        excess = math.copysign(min(MASS_BOUND, max(0.0, abs(excess) - MASS_DEADBAND)), excess)
        pin.computeJointJacobians(self.model, self.data, q)
        gravity = pin.computeGeneralizedGravity(self.model, self.data, q)
        points, weights = [], []
        for foot, ankle, force in zip(self.legs.feet, self.ankles, forces, strict=True):
            sites = [
                pin.updateFramePlacement(self.model, self.data, f).translation for f in foot.sites
            ]
            if ankle is None:
                points.append(np.mean(sites, axis=0))
                weights.append(force)
                continue
            column, motor = ankle
            arms = [
                pin.getFrameJacobian(self.model, self.data, f, WORLD_ALIGNED)[2, column]
                for f in foot.sites
            ]
            rows = np.vstack([np.ones(len(arms)), arms])
            split = np.linalg.lstsq(rows, [force, gravity[column] - torque[motor]], rcond=None)[0]
            points.extend(sites)
            weights.extend(split)
        w = np.asarray(weights)
        p = np.asarray(points)
        pressure = w @ p / np.sum(w)
        height = float(com[2] - np.mean(p[:, 2]))  # [m] the centre of mass over the sites
        offset = np.zeros(3)
        offset[:2] = pressure[:2] + height * accel[:2] / specific[2] - com[:2]
        base_rotation = pin.XYZQUATToSE3(np.asarray(q[:7])).rotation
        if open_loop:  # the mean of the readings (the estimate in force added back)
            reading = self.estimate.shift + base_rotation.T @ offset
            self.mean_shift = self.mean_shift + slow * (reading - self.mean_shift)
            shift = _shrunk(self.mean_shift, MEAN_DEADBAND_M)
        else:
            shift = self.estimate.shift + self.alpha_shift * base_rotation.T @ _shrunk(
                offset, SHIFT_DEADBAND_M
            )
            self.mean_shift = shift.copy()
        self.estimate = PayloadEstimate(float(excess * self.mass0), shift, self.mass0)
        return self.estimate
