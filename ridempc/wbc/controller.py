"""The 500 Hz whole-body controller: the MPC's references to motor torques and joint targets.

Per tick (skateboard paper, Sec. V: "a whole body controller computes references for
actuators", after the MIT Cheetah's [26]):

1. :class:`~ridempc.wbc.model.WholeBodyModel` evaluates :math:`M, h, \\tau_p` and the
   kinematics of the contact sites, base, centre of mass and closed chains at the
   estimated :math:`(q, v)` (Pinocchio);
2. :func:`~ridempc.wbc.contacts.build_contact_set` places the planned contacts on the
   ground or on the estimated board platforms, which move with the rider's push where
   they roll freely (:mod:`ridempc.wbc.platforms`);
3. :class:`~ridempc.wbc.qp.WholeBodyQP` builds the QP on
   :math:`z = (\\ddot q, f, \\tau, \\lambda)` from the tasks (base orientation, centre of mass
   or base position, contact forces, swing feet, posture, regularisation) and constraints
   (dynamics, closed chains, contact accelerations, friction pyramids, torque limits; a
   line foot's sites kept pressing against the torques still in flight through the motors'
   delay, :mod:`ridempc.wbc.in_flight`) and solves it with OSQP;
4. the motor torques :math:`\\tau` go out as feedforward, with joint targets integrated
   over one tick, :math:`q^* = q + v\\,\\Delta t + \\tfrac12 \\ddot q\\,\\Delta t^2`,
   :math:`\\dot q^* = v + \\ddot q\\,\\Delta t`, for the motor drivers' PD
   (:func:`to_motor_command`).
"""

from __future__ import annotations

import time
from collections.abc import Sequence
from dataclasses import replace

import numpy as np
import pinocchio as pin
from numpy.typing import NDArray

from ridempc.errors import ConfigError
from ridempc.estimation.state import EstimatedState
from ridempc.frozen import changed
from ridempc.gravity import GRAVITY
from ridempc.robots.motor_curve import TorqueSpeedCurve
from ridempc.robots.pinocchio_model import PinocchioRobot
from ridempc.robots.robot import Robot
from ridempc.sim.motors import MotorCommand
from ridempc.wbc.constraints import (
    ClosedChainConstraint,
    Constraint,
    ContactAccelerationConstraint,
    DynamicsConstraint,
    FrictionPyramidConstraint,
    PlatformTipConstraint,
    RigidSpringConstraint,
    TorqueSpeedConstraint,
    WheelGripConstraint,
)
from ridempc.wbc.contacts import ContactSet, build_contact_set
from ridempc.wbc.in_flight import TorquesInFlight
from ridempc.wbc.model import ModelTerms, WholeBodyModel
from ridempc.wbc.platforms import RollingPlatform
from ridempc.wbc.qp import QpProblem, QpSolution, WholeBodyQP
from ridempc.wbc.settings import WbcSettings
from ridempc.wbc.targets import WbcOutput, WbcTargets
from ridempc.wbc.tasks import (
    BaseOrientationTask,
    BasePositionTask,
    CenterOfMassTask,
    ContactForceTask,
    PostureTask,
    RegularizationTask,
    SwingFootTask,
    Task,
    TranslationTask,
)

__all__ = ["TRACKED_POINTS", "WholeBodyController", "motor_posture", "to_motor_command"]

Array = NDArray[np.float64]

TRACKED_POINTS: dict[str, type[TranslationTask]] = {
    "com": CenterOfMassTask,
    "base": BasePositionTask,
}


def _motor_q(pinocchio: PinocchioRobot, robot: Robot) -> NDArray[np.int64]:
    """Each motor joint's index in Pinocchio's configuration, actuator order."""
    model = pinocchio.model
    return np.array(
        [model.joints[model.getJointId(m.joint)].idx_q for m in robot.motors], dtype=np.int64
    )


def motor_posture(pinocchio: PinocchioRobot, robot: Robot, qpos: Array) -> Array:
    """The motor joint angles [rad] of a MuJoCo configuration ``qpos``, actuator order (a
    posture for :class:`WholeBodyController`)."""
    return pinocchio.coordinates.qpos_to_pinocchio(qpos)[_motor_q(pinocchio, robot)]


class WholeBodyController:
    """The whole-body QP for one robot, with its persistent solver.

    Args:
        robot: The robot (any description: tree or closed chains, point or line feet).
        settings: Weights, gains, friction and solver settings.
        pinocchio: The robot's Pinocchio model (built from ``robot`` if not given).
        posture: Default nominal posture, motor joint angles [rad] (default: the robot's
            stand keyframe).
        platforms: Per board platform of the estimate (``EstimatedState.boards`` order), how
            the rider's forces move it (:mod:`ridempc.wbc.platforms`); None or missing: a
            rigid support.

    Attributes:
        model: The Pinocchio side (:class:`~ridempc.wbc.model.WholeBodyModel`).
        qp: The QP and its OSQP workspace.
        last_problem: The last tick's QP, or None.
        last_solution: The last tick's solution, or None.
        in_flight: The last ticks' torques, still on their way through the motors' delay,
            and the least site forces that keep the line feet flat against them.
    """

    def __init__(
        self,
        robot: Robot,
        settings: WbcSettings | None = None,
        pinocchio: PinocchioRobot | None = None,
        posture: Array | None = None,
        platforms: Sequence[RollingPlatform | None] = (),
    ) -> None:
        self.robot = robot
        self.platforms = tuple(platforms)
        # How many platforms tip over their tread (PlatformTipConstraint's rows for each).
        self._tipping = sum(p is not None and p.tread is not None for p in self.platforms)
        self.settings = settings or WbcSettings()
        self.model = WholeBodyModel(robot, pinocchio)
        self.motor_q = _motor_q(self.model.pinocchio, robot)
        self.motor_v = self.model.motor_v
        stand = self.model.pinocchio.coordinates.qpos_to_pinocchio(robot.stand_qpos)
        self.posture = np.asarray(stand[self.motor_q] if posture is None else posture, dtype=float)
        if self.posture.shape != (len(robot.motors),):
            raise ConfigError(
                f"WBC: posture has {self.posture.size} angles, robot '{robot.name}' has "
                f"{len(robot.motors)} motors"
            )
        self.qp = WholeBodyQP(
            self.model.layout,
            self._tasks(),
            self._constraints(),
            self.settings.osqp,
            self.settings.solver,
        )
        for problem in self._probe_problems(stand):
            self.qp.include_pattern(problem)
        site_foot = self.model.site_foot
        self._site_to_foot = np.zeros((len(self.foot_names), len(site_foot)))
        self._site_to_foot[site_foot, np.arange(len(site_foot))] = 1.0
        self.in_flight = TorquesInFlight(self.model, robot, self.settings.dt)
        self.last_problem: QpProblem | None = None
        self.last_solution: QpSolution | None = None

    def _tasks(self) -> list[Task]:
        s, layout, site_foot = self.settings, self.model.layout, self.model.site_foot
        return [
            BaseOrientationTask(layout, s.orientation),
            TRACKED_POINTS[s.track](layout, s.position),
            ContactForceTask(
                layout, site_foot, self.model.mass, s.force_weight, s.site_force_weight
            ),
            SwingFootTask(layout, site_foot, s.swing),
            PostureTask(layout, self.motor_q, self.motor_v, self.posture, s.posture),
            RegularizationTask(
                layout,
                s.acceleration_regularisation,
                s.force_regularisation,
                s.torque_regularisation,
                s.loop_force_regularisation,
            ),
        ]

    def _constraints(self) -> list[Constraint]:
        s, layout = self.settings, self.model.layout
        weight = self.model.mass * GRAVITY
        rigid = self.model.spring_v if s.springs == "rigid" else np.zeros(0, dtype=np.int64)
        return [
            DynamicsConstraint(layout, self.motor_v, free_rows=rigid),
            RigidSpringConstraint(layout, rigid, s.spring_damping),
            ClosedChainConstraint(layout),
            ContactAccelerationConstraint(layout, self.model.site_partner, self.model.line_basis),
            FrictionPyramidConstraint(
                layout, s.friction, s.min_normal_force, s.max_normal_force * weight, s.pyramid
            ),
            TorqueSpeedConstraint(layout, TorqueSpeedCurve.of(self.robot.motors), self.motor_v),
            PlatformTipConstraint(layout, self._tipping),
            WheelGripConstraint(layout, self.platforms),
        ]

    def _probe_problems(self, stand: Array) -> list[QpProblem]:
        """QPs at a generic configuration (random joint offsets and velocities, tilted
        supports), every foot in contact and every foot swinging, whose non-zeros seed the
        fixed pattern."""
        rng = np.random.default_rng(0)
        model = self.model.model
        q = pin.integrate(model, stand, 0.1 * rng.normal(size=model.nv))
        terms = self.model.update(q, rng.normal(size=model.nv))
        feet = len(self.model.foot_names)
        problems = []
        n_sites = self.model.layout.n_sites
        for standing in (True, False):
            contacts = ContactSet.on_ground(np.full(n_sites, standing))
            if any(p is not None for p in self.platforms):
                coupling = rng.normal(size=(n_sites, 3, n_sites, 3))
                tipping = tuple(
                    (np.arange(n_sites), rng.normal(size=n_sites), np.full(n_sites, 0.4))
                    for _ in range(self._tipping)
                )
                contacts = replace(contacts, coupling=coupling, tipping=tipping)
            for s in range(n_sites):
                contacts.frame[s] = pin.exp3(0.3 * rng.normal(size=3)).T
            targets = WbcTargets(
                position=terms.com.position,
                orientation=np.array([1.0, 0.0, 0.0, 0.0]),
                contact=np.full(feet, standing),
                forces=np.ones((feet, 3)),
                swing_position=rng.normal(size=(feet, 3)),
            )
            problems.append(self.qp.build(terms, targets, contacts))
        return problems

    @property
    def foot_names(self) -> tuple[str, ...]:
        return self.model.foot_names

    def solve(self, state: EstimatedState, targets: WbcTargets) -> WbcOutput:
        """One tick: the QP at the estimated state, for the MPC's targets.

        Args:
            state: The state estimate (its ``q``, ``v`` and board platforms are used).
            targets: The references, per foot in ``foot_names`` order.

        Raises:
            ConfigError: The targets do not fit the robot (feet, posture).
            WbcFailed: The QP has no acceptable solution.
        """
        if targets.n_feet != len(self.foot_names):
            raise ConfigError(
                f"WBC targets: field 'contact': {targets.n_feet} feet, robot "
                f"'{self.robot.name}' has {len(self.foot_names)} ({', '.join(self.foot_names)})"
            )
        if targets.posture is not None and np.shape(targets.posture) != self.posture.shape:
            raise ConfigError(
                f"WBC targets: field 'posture': {np.size(targets.posture)} angles, expected "
                f"{self.posture.size}"
            )
        start = time.perf_counter()
        terms = self.model.update(state.q, state.v)
        model_time = time.perf_counter()
        contacts = build_contact_set(
            terms,
            self.model.site_foot,
            self.foot_names,
            targets.contact,
            state.boards,
            targets.board_acceleration,
            self.platforms,
        )
        least = self.in_flight.least_forces(state.time, targets.forces[:, 2])
        if least is not None:
            contacts = changed(contacts, least_force=least)
        problem = self.qp.build(terms, targets, contacts)
        build_time = time.perf_counter()
        solution = self.qp.solve(problem)
        end = time.perf_counter()
        self.in_flight.record(state.time, solution.x[self.model.layout.torque])
        self.last_problem, self.last_solution = problem, solution
        return self._output(terms, solution, start, model_time, build_time, end)

    def _output(
        self,
        terms: ModelTerms,
        solution: QpSolution,
        start: float,
        model_time: float,
        build_time: float,
        end: float,
    ) -> WbcOutput:
        layout, dt = self.model.layout, self.settings.dt
        q, v = terms.q, terms.v
        x = solution.x
        acceleration = x[layout.acceleration]
        site_forces = x[layout.force].reshape(-1, 3)
        feet = self._site_to_foot.dot(site_forces)
        qdd = acceleration[self.motor_v]
        velocity = v[self.motor_v]
        return WbcOutput(
            torque=x[layout.torque].copy(),
            position=q[self.motor_q] + velocity * dt + 0.5 * qdd * dt**2,
            velocity=velocity + qdd * dt,
            acceleration=acceleration.copy(),
            forces=feet,
            site_forces=site_forces.copy(),
            site_positions=terms.sites.position,
            com_velocity=terms.com.velocity,
            loop_forces=x[layout.loop_force].copy(),
            status=solution.status,
            iterations=solution.iterations,
            model_ms=1e3 * (model_time - start),
            build_ms=1e3 * (build_time - model_time),
            solve_ms=1e3 * (end - build_time),
        )


def to_motor_command(
    output: WbcOutput, kp: Array | float, kd: Array | float, torque: Array | None = None
) -> MotorCommand:
    """The motor drivers' command: the QP's torques as feedforward, PD about its targets,
    :math:`\\tau_{motor} = \\tau + k_p (q^* - q) + k_d (\\dot q^* - \\dot q)` [N m].

    Args:
        output: The WBC's answer.
        kp: Joint stiffness [N m / rad], one per motor or one for all.
        kd: Joint damping [N m s / rad], one per motor or one for all.
        torque: The feedforward to send in place of the QP's [N m] (e.g. led over the
            motors' delay, :mod:`~ridempc.wbc.torque_lead`).
    """
    n = output.torque.size
    return MotorCommand(
        torque=(output.torque if torque is None else np.asarray(torque, dtype=float)).copy(),
        position=output.position.copy(),
        velocity=output.velocity.copy(),
        kp=_per_motor(kp, n),
        kd=_per_motor(kd, n),
    )


def _per_motor(gain: Array | float, n: int) -> Array:
    """A copy of ``gain``, one per motor (a scalar repeated)."""
    gain = np.asarray(gain, dtype=float)
    return gain.copy() if gain.shape == (n,) else np.broadcast_to(gain, (n,)).copy()
