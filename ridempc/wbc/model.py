"""The rigid-body terms of the whole-body QP at one tick, from Pinocchio.

:class:`WholeBodyModel` is built once per robot; :meth:`WholeBodyModel.update` evaluates,
at the estimated :math:`(q, v)` (Pinocchio coordinates, base linear and angular velocity
in the base frame), everything the tasks and constraints read:

- the joint-space dynamics :math:`M(q)\\,\\ddot q + h(q, v)` with :math:`M` [kg, kg m^2]
  (armature included) and :math:`h = C(q, v)\\,v + g(q)` [N, N m];
- the passive joint torques :math:`\\tau_p = -K (q - q_{ref}) - D v` [N m]: the leaf springs
  of the description (joints with ``stiffness``, e.g. Cassie's shin and heel springs) and
  every joint's viscous ``damping``, which MuJoCo applies and Pinocchio's :math:`h` leaves
  out (checked against MuJoCo's ``qfrc_passive``; Pinocchio's MJCF reader leaves a ball
  joint's damping at zero, 0.01 N m s/rad on Cassie's achilles rods in MuJoCo);
- for each point :math:`p` (the contact sites, the base origin, the centre of mass) its
  world position, velocity :math:`\\dot p = J v`, world-aligned Jacobian :math:`J` [m or -]
  and drift :math:`\\dot J v` [m/s^2], so that :math:`\\ddot p = J \\ddot q + \\dot J v`;
- for each closed-chain point constraint (anchors :math:`a_1, a_2`),
  :math:`r = p_{a_1} - p_{a_2}`, :math:`J_{loop} = J_{a_1} - J_{a_2}` and
  :math:`\\dot J_{loop} v`, so that :math:`\\ddot r = J_{loop} \\ddot q + \\dot J_{loop} v`.

The drifts are Pinocchio's classical accelerations at :math:`\\ddot q = 0`
(``getFrameClassicalAcceleration``): the spatial acceleration's linear part plus
:math:`\\omega \\times \\dot p`. ``computeAllTerms`` leaves in its data the joints'
accelerations of its bias pass, the motion at :math:`\\ddot q = 0`, which is what
``forwardKinematics(q, v, 0)`` would compute again (checked in the WBC's tests).
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
import pinocchio as pin
from numpy.typing import NDArray

from ridempc.errors import ConfigError
from ridempc.estimation.legs import LegKinematics
from ridempc.estimation.loop_closure import LoopClosure
from ridempc.robots.pinocchio_model import PinocchioRobot, build_pinocchio_robot
from ridempc.robots.robot import Robot
from ridempc.wbc.layout import DecisionLayout

__all__ = ["ModelTerms", "PointKinematics", "WholeBodyModel"]

Array = NDArray[np.float64]
Index = NDArray[np.int64]
WORLD_ALIGNED = pin.ReferenceFrame.LOCAL_WORLD_ALIGNED


class PointKinematics(NamedTuple):
    """Position, velocity, Jacobian and drift of one point (or a stack of points).

    Attributes:
        position: World position [m], shape (3,) or (points, 3).
        velocity: World velocity :math:`J v` [m/s], same shape.
        jacobian: World-aligned linear Jacobian :math:`J` [m/rad or -], (3, nv) or
            (points, 3, nv).
        drift: :math:`\\dot J v` [m/s^2], same shape as ``position``.
    """

    position: Array
    velocity: Array
    jacobian: Array
    drift: Array


class ModelTerms(NamedTuple):
    """Everything the QP reads from the model at one :math:`(q, v)`.

    Attributes:
        q: Configuration (Pinocchio) [m, -, rad].
        v: Velocity (Pinocchio) [m/s, rad/s].
        mass_matrix: :math:`M(q)`, symmetric, nv x nv.
        bias: :math:`h(q, v) = C v + g` [N, N m].
        passive: :math:`\\tau_p = -K (q - q_{ref}) - D v` [N m].
        base_rotation: :math:`R_{WB}`.
        base_angular_velocity: :math:`\\omega_B` in the base frame [rad/s].
        base: The base origin.
        com: The centre of mass.
        sites: The contact sites, stacked in layout order.
        site_rotation: Orientation :math:`R_{WS}` of each contact site's frame, (sites, 3, 3).
        loop_residual: :math:`r` [m], stacked per closed-chain constraint.
        loop_jacobian: :math:`J_{loop}` [m/rad], (3 n_loops, nv).
        loop_drift: :math:`\\dot J_{loop} v` [m/s^2].
    """

    q: Array
    v: Array
    mass_matrix: Array
    bias: Array
    passive: Array
    base_rotation: Array
    base_angular_velocity: Array
    base: PointKinematics
    com: PointKinematics
    sites: PointKinematics
    site_rotation: Array
    loop_residual: Array
    loop_jacobian: Array
    loop_drift: Array

    @property
    def base_angular_velocity_world(self) -> Array:
        """:math:`\\omega_W = R_{WB}\\, \\omega_B` [rad/s]."""
        return np.asarray(self.base_rotation.dot(self.base_angular_velocity))


class WholeBodyModel:
    """A robot's Pinocchio model prepared for the whole-body QP.

    Args:
        robot: The robot (its description, motors and contact sites).
        pinocchio: Its Pinocchio model (built from ``robot`` if not given).

    Attributes:
        model: A copy of the Pinocchio model with a frame at each closed-chain anchor.
        legs: The feet and their contact sites (the sites' order is the layout's).
        closure: The closed-chain anchors (:class:`~ridempc.estimation.loop_closure.LoopClosure`).
        motor_v: Velocity index of each motor's joint, actuator order.
        layout: The decision vector's layout.
        mass: Total mass [kg].
        site_partner: For a line foot's second contact site, the index of the first (the
            other end of its line); -1 for the other sites.
        line_basis: For those second sites, two unit rows orthogonal to the line, in the
            site's frame, shape (sites, 2, 3) (zero elsewhere).

    Raises:
        ConfigError: A motor drives a joint that is not one-DoF, a closed chain is not
            made of point constraints, a foot has more than two contact sites (or two on
            different bodies), or the free joint is not at the base body's origin.
    """

    def __init__(self, robot: Robot, pinocchio: PinocchioRobot | None = None) -> None:
        self.robot = robot
        self.pinocchio = pinocchio or build_pinocchio_robot(robot)
        self.model: pin.Model = pin.Model(self.pinocchio.model)  # a copy: anchors add frames
        self.closure = LoopClosure.build(
            self.model, self.pinocchio.constraints, np.zeros(0, dtype=np.int64)
        )
        self.data: pin.Data = self.model.createData()
        self._points_data: pin.Data = self.model.createData()  # for foot_points
        self.legs = LegKinematics.build(robot, self.pinocchio)
        model = self.model
        motor_v = []
        for motor in robot.motors:
            joint = model.joints[model.getJointId(motor.joint)]
            if joint.nv != 1:
                raise ConfigError(f"WBC: motor '{motor.name}' drives a {joint.nv}-DoF joint")
            motor_v.append(joint.idx_v)
        self.motor_v: Index = np.array(motor_v, dtype=np.int64)
        self.site_frames: tuple[int, ...] = tuple(f for foot in self.legs.feet for f in foot.sites)
        self.base_frame = int(model.getFrameId(robot.params.base_body, pin.FrameType.BODY))
        base = model.frames[self.base_frame]
        if base.parentJoint != 1 or not base.placement.isIdentity():
            raise ConfigError(
                f"WBC: base body '{robot.params.base_body}' must carry the free joint at its origin"
            )
        self.layout = DecisionLayout(
            nv=model.nv,
            n_sites=len(self.site_frames),
            n_motors=len(motor_v),
            n_loops=len(self.closure.pairs),
        )
        self.mass = float(pin.computeTotalMass(model))
        self._stiff_v, self._stiff_q = self._spring_indices()
        self._stiffness = self.pinocchio.spring_stiffness[self._stiff_v]
        self._spring_reference = self.pinocchio.spring_reference[self._stiff_v]
        self._damping = np.array(model.damping, dtype=float)
        # M's strict lower triangle, and the upper entries it mirrors, as flat indices
        lower_rows, lower_cols = np.tril_indices(model.nv, -1)
        self._lower = lower_rows * model.nv + lower_cols
        self._mirror = lower_cols * model.nv + lower_rows
        # every frame read per tick: the base, the sites, then each closure's two anchors
        pairs = self.closure.pairs
        self._frames = (
            self.base_frame,
            *self.site_frames,
            *(a for a, _ in pairs),
            *(b for _, b in pairs),
        )
        n_sites, n_loops = len(self.site_frames), len(pairs)
        self._site_rows = slice(1, 1 + n_sites)
        self._first_anchor_rows = slice(1 + n_sites, 1 + n_sites + n_loops)
        self._second_anchor_rows = slice(1 + n_sites + n_loops, 1 + n_sites + 2 * n_loops)
        self.site_partner, self.line_basis = self._line_feet()
        # each foot's sites summed (a 0/1 matrix), and their count, for foot_points
        feet = self.legs.site_foot
        self._foot_sum = np.zeros((len(self.foot_names), len(feet)))
        self._foot_sum[feet, np.arange(len(feet))] = 1.0
        self._foot_count = np.bincount(feet, minlength=len(self.foot_names))[:, None]

    def _line_feet(self) -> tuple[Index, Array]:
        """For each site, the first site of its foot if it is a line foot's second one
        (else -1), and two unit rows orthogonal to that line in the site's own frame.

        Raises:
            ConfigError: A foot has more than two contact sites.
        """
        partner = np.full(len(self.site_frames), -1, dtype=np.int64)
        basis = np.zeros((len(self.site_frames), 2, 3))
        frames = self.model.frames
        for foot in self.legs.feet:
            if len(foot.sites) > 2:
                raise ConfigError(
                    f"WBC: foot '{foot.name}' has {len(foot.sites)} contact sites (at most 2: "
                    "a point or a line foot)"
                )
            if len(foot.sites) < 2:
                continue
            first, second = (self.site_frames.index(f) for f in foot.sites)
            a, b = frames[foot.sites[0]].placement, frames[foot.sites[1]].placement
            if frames[foot.sites[0]].parentJoint != frames[foot.sites[1]].parentJoint:
                raise ConfigError(f"WBC: the contact sites of foot '{foot.name}' are on two bodies")
            line = b.rotation.T @ (b.translation - a.translation)  # in the second site's frame
            line /= np.linalg.norm(line)
            axis = np.eye(3)[int(np.argmin(np.abs(line)))]
            across = np.cross(line, axis)
            across /= np.linalg.norm(across)
            partner[second] = first
            basis[second] = (across, np.cross(line, across))
        return partner, basis

    def _spring_indices(self) -> tuple[Index, Index]:
        """Velocity and configuration indices of the stiff (spring) joints."""
        stiff_v = np.flatnonzero(self.pinocchio.spring_stiffness > 0.0)
        v_to_q = {}
        for joint in self.model.joints[1:]:
            if joint.nv == 1 and joint.nq == 1:
                v_to_q[joint.idx_v] = joint.idx_q
        missing = [int(i) for i in stiff_v if int(i) not in v_to_q]
        if missing:
            raise ConfigError(f"WBC: springs on joints that are not one-DoF (v index {missing})")
        stiff_q = np.array([v_to_q[int(i)] for i in stiff_v], dtype=np.int64)
        return stiff_v.astype(np.int64), stiff_q

    @property
    def spring_v(self) -> Index:
        """Velocity indices of the spring joints (with stiffness in the description)."""
        return self._stiff_v

    @property
    def site_foot(self) -> Index:
        """Foot index of each contact site, layout order."""
        return self.legs.site_foot

    @property
    def foot_names(self) -> tuple[str, ...]:
        return self.legs.names

    def foot_points(self, q: Array) -> Array:
        """Each foot's point (the mean of its contact sites) in the world at configuration
        ``q`` [m], shape (feet, 3): where a swing target puts the foot."""
        model, data = self.model, self._points_data
        pin.framesForwardKinematics(model, data, np.asarray(q, dtype=float))
        sites = np.array([data.oMf[f].translation for f in self.site_frames])
        return np.asarray(self._foot_sum.dot(sites) / self._foot_count)

    def placed_foot_points(self, data: pin.Data) -> Array:
        """:meth:`foot_points` from ``data`` whose joints are already placed at the
        configuration (``forwardKinematics``, or ``centerOfMass`` with it): the same
        points without a second pass over the joints [m], shape (feet, 3)."""
        model = self.model
        sites = np.array(
            [pin.updateFramePlacement(model, data, f).translation for f in self.site_frames]
        )
        return np.asarray(self._foot_sum.dot(sites) / self._foot_count)

    def passive_torque(self, q: Array, v: Array) -> Array:
        """:math:`\\tau_p = -K (q - q_{ref}) - D v` [N m] (springs and joint damping)."""
        tau = -self._damping * v
        tau[self._stiff_v] -= self._stiffness * (q[self._stiff_q] - self._spring_reference)
        return np.asarray(tau)

    def update(self, q: Array, v: Array) -> ModelTerms:
        """Evaluate the model at :math:`(q, v)` (see the module docstring)."""
        model, data = self.model, self.data
        q = np.asarray(q, dtype=float)
        v = np.asarray(v, dtype=float)
        nv = model.nv
        # M (upper triangle), h, joint Jacobians, CoM and the joints' motion at qdd = 0
        pin.computeAllTerms(model, data, q, v)
        mass = np.array(data.M)
        flat = mass.reshape(-1)
        flat.put(self._lower, flat.take(self._mirror))  # Pinocchio fills the upper triangle
        pin.updateFramePlacements(model, data)
        pin.centerOfMass(model, data, pin.KinematicLevel.ACCELERATION, False)
        com = PointKinematics(
            np.array(data.com[0]),
            np.array(data.vcom[0]),
            np.array(data.Jcom),
            np.array(data.acom[0]),
        )
        frames = self._frames
        # each frame's placement as one 4 x 4 (one call a frame, not two): its translation
        # and, for the base and the sites (the anchors' are not read), its rotation, copied
        # contiguous so that the products that follow add up as on their own arrays
        placements = np.array([data.oMf[frame].homogeneous for frame in frames])
        positions = np.ascontiguousarray(placements[:, :3, 3])
        rotations = np.ascontiguousarray(placements[: self._site_rows.stop, :3, :3])
        jacobians = np.array(
            [pin.getFrameJacobian(model, data, frame, WORLD_ALIGNED)[:3] for frame in frames]
        )
        drifts = np.array(
            [
                pin.getFrameClassicalAcceleration(model, data, frame, WORLD_ALIGNED).linear
                for frame in frames
            ]
        )
        velocities = jacobians @ v
        sites, first, second = self._site_rows, self._first_anchor_rows, self._second_anchor_rows
        return ModelTerms(
            q=q,
            v=v,
            mass_matrix=mass,
            bias=np.array(data.nle),
            passive=self.passive_torque(q, v),
            base_rotation=rotations[0],
            base_angular_velocity=v[3:6].copy(),
            base=PointKinematics(positions[0], velocities[0], jacobians[0], drifts[0]),
            com=com,
            sites=PointKinematics(
                positions[sites], velocities[sites], jacobians[sites], drifts[sites]
            ),
            site_rotation=rotations[sites],
            loop_residual=(positions[first] - positions[second]).ravel(),
            loop_jacobian=(jacobians[first] - jacobians[second]).reshape(-1, nv),
            loop_drift=(drifts[first] - drifts[second]).ravel(),
        )
