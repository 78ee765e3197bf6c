"""The quadruped-on-skateboard acceleration NLP of the skateboard paper (Sec. IV-B).

State :math:`x = (x_R, x_B)`: the SRBKM robot of eq. (1) (:mod:`.rigid_body`) and the board
(:mod:`.skateboard`); input :math:`u = (f_1, \\dots, f_4, \\dot q_j)`: world-frame contact
forces on the robot [N] and joint velocities [rad/s], eq. (2). Multiple shooting on the
contact schedule's grid (:mod:`.schedule`), Hermite-Simpson within each interval
(:mod:`.problem`), and:

- dynamics: eq. (3) for the robot, eq. (6), (7), (10), (14) for the board; the forces of
  the feet on the deck act on the board, the pushing foot's on the ground does not;
- Dubins constraint, eq. (14) with the robot's yaw rate:
  :math:`\\sin\\varphi\\, v + K_{board}\\, \\dot\\psi_R = 0` at every node;
- foot contacts, eq. (15), imposed in its integrated form at every node a foot touches:
  a foot on the deck stays at its place in the deck frame,
  :math:`R_B^\\top (p_i - o_B) = {}^C r_{B_i}` (so its velocity is the deck's, eq. 15), and
  the pushing foot on the ground stays where it landed, on the ground, beside the deck;
- friction pyramids (:math:`|f_t| \\le (\\mu/\\sqrt2) f_n` along two tangents, the Coulomb
  cone's inner pyramid, :mod:`ridempc.friction`; :math:`f_n \\ge 0`) on the surface's
  normal, no force on a swinging foot;
- joint torques of the stance legs, :math:`\\tau = -J_i(q)^\\top R_R^\\top f_i` (the massless
  leg's statics), within ``torque_fraction`` of the motor limits (12 N m on CyberDog2),
  the flat part of the torque-speed curves (:mod:`ridempc.robots.motor_curve`): the planned
  joint rates stay below its corner, which ``tests/test_trajopt_library.py`` checks;
  joint angles and speeds within the MJCF's and ``robot.toml``'s limits; board roll within
  its bottom-out angle; board speed bounded;
- swinging feet: clear of the deck (above its top while over it, beside it otherwise) and
  above the ground;
- lift-off: the pushing foot's normal force on the ground in the grid step before it lifts
  is at most ``liftoff_force`` weights per foot, so a push ends unloaded;
- support margin: while a foot swings (its lift-off and touchdown nodes included), the
  centre of mass's ground projection stays at least ``support_margin`` inside the triangle
  of the three feet on the deck, :math:`d_j(p_{xy}) \\ge m` for its three edges
  (:func:`inward_distances`);
- start: the robot in its riding keyframe on a board at rest; end: the board at the target
  speed with the robot riding along (four feet on the deck, no relative motion);
- cost, eq. (16): state tracking (board speed ramp, deck roll, trunk height, attitude,
  lateral offset), effort (forces and joint velocities) and effort rate, integrated over
  the grid.
"""

from __future__ import annotations

import time
from dataclasses import asdict, dataclass
from typing import Any

import casadi as ca
import numpy as np
from numpy.typing import NDArray

from ridempc.errors import ConfigError
from ridempc.friction import pyramid_rows
from ridempc.trajopt.problem import (
    NodeSpec,
    NodeTerms,
    TrajectoryProblem,
    assemble_problem,
)
from ridempc.trajopt.rigid_body import (
    GRAVITY,
    RigidBodyRobot,
    feet_world,
    rigid_body_rates,
    rigid_body_state_names,
)
from ridempc.trajopt.rotations import euler_rate_map, euler_zyx_matrix
from ridempc.trajopt.schedule import Contact, ContactSchedule, push_schedule
from ridempc.trajopt.skateboard import BOARD_STATE, SkateboardModel, deck_frame, skateboard_rates

__all__ = [
    "SkateOptions",
    "build_skate_problem",
    "initial_skate_state",
    "inward_distances",
    "skate_guess",
    "skate_rates",
    "skate_schedule",
    "speed_bound",
    "triangle_turn",
]

Array = NDArray[np.float64]


@dataclass(frozen=True)
class SkateOptions:
    """Settings of the acceleration problem (stored with every library entry).

    Attributes:
        dt: Grid step [s].
        friction: Foot friction coefficient :math:`\\mu` [-].
        pusher: Contact site of the pushing foot (the pair file's ``trajopt.pusher``).
        period: Push period [s] (1.2 s in the paper).
        sweep: Distance the pushing foot sweeps along the ground per push [m].
        speed_per_stride: Speed gained per push, which sets the number of strides [m/s].
        min_push: Shortest push [s].
        max_push: Longest push [s].
        clearance: Swinging foot's clearance over the deck and the ground [m].
        side_margin: Gap between the deck's edge and the pushing foot on the ground [m].
        crouch: How much lower than the keyframe the trunk is asked to ride [m].
        min_board_force: Least normal force of a foot standing on the deck, in units of
            the weight per foot [-]: keeps the centre of pressure inside the three-leg support
            triangle rather than on its diagonal edge (at 0 the optimum carried the front
            foot opposite the pusher at 6 N, and the MPC rider let it lift off the deck).
        support_margin: Least horizontal distance of the centre of mass inside the triangle
            of the three feet on the deck while the fourth swings, from its lift-off node to
            its touchdown node included [m]. Without it the optimum leaves the centre of
            mass on the triangle's diagonal when the pushing foot lands (it falls towards
            that foot, which catches it on time in the plan), and a rider whose trunk tips a
            little early falls towards the ground with the foot still in the air.
        torque_fraction: Share of the motor torque limits the stance legs' statics may
            plan [-]. The rest is the whole-body controller's, for the legs' own dynamics
            (massless here) and its feedback: at 1.0 the 1.0 m/s entry planned the pushing
            hip at its 12 N m limit, and riders fell short of each push's planned impulse.
        touchdown_step: Largest horizontal distance [m] the pushing foot may cover, along
            each axis, in the grid step before it lands on the ground: it lands nearly still
            (at most ``touchdown_step / dt`` on average over that step, 0.1 m/s) rather
            than at the trunk's speed (1.1 m/s in the 1.0 m/s entry without it), which the
            massless legs here do not mind and the simulated leg does: the push-offs end
            faster, closer to their targets, with it.
        liftoff_force: Largest normal force of the pushing foot on the ground in the grid
            step before it lifts, in units of the weight per foot [-]: the push unloads the
            foot before lifting it rather than ending at full load (lifted loaded, the foot
            drops the dog onto the diagonal foot and tips the deck to its roll stop).
        speed_margin: Board speed bound as a multiple of the target [-].
        start_speed: Speed of the board and rider at the start [m/s]: 0 from rest (an
            ``accelerate`` entry), else a rolling board pushed again (a ``repush`` entry).
        w_speed: Weight of the board speed error [(m/s)^-2 s^-1].
        w_roll: Weight of the deck roll and roll rate.
        w_heading: Weight of the board's heading (the push should go straight).
        w_height: Weight of the trunk height error.
        w_lateral: Weight of the centre of mass's offset from the deck's centre line.
        w_attitude: Weight of trunk roll, pitch and yaw relative to the deck.
        w_velocity: Weight of the trunk's velocity relative to the board's.
        w_joints: Weight of the joint angles' offset from the keyframe.
        w_force: Weight of the forces, in units of the weight per foot (eq. 16c).
        w_joint_rate: Weight of the joint velocities (eq. 16c).
        w_force_change: Weight of the force changes per interval (eq. 16d).
        w_joint_rate_change: Weight of the joint-velocity changes per interval (eq. 16d).
    """

    dt: float = 0.05
    friction: float = 0.6
    pusher: str = ""
    period: float = 1.2
    sweep: float = 0.2
    speed_per_stride: float = 0.3
    min_push: float = 0.2
    max_push: float = 0.5
    clearance: float = 0.02
    side_margin: float = 0.02
    crouch: float = 0.06
    min_board_force: float = 0.4
    support_margin: float = 0.015
    torque_fraction: float = 0.8
    touchdown_step: float = 0.005
    liftoff_force: float = 1.0
    speed_margin: float = 1.5
    start_speed: float = 0.0
    w_speed: float = 10.0
    w_roll: float = 10.0
    w_heading: float = 10.0
    w_height: float = 50.0
    w_lateral: float = 100.0
    w_attitude: float = 10.0
    w_velocity: float = 1.0
    w_joints: float = 0.1
    w_force: float = 0.1
    w_joint_rate: float = 0.01
    w_force_change: float = 0.1
    w_joint_rate_change: float = 0.01


def skate_schedule(robot: RigidBodyRobot, target: float, options: SkateOptions) -> ContactSchedule:
    """The contact schedule of one entry (see :func:`push_schedule`)."""
    if options.pusher not in robot.feet:
        raise ConfigError(
            f"pusher '{options.pusher}' is not a foot of {robot.name} "
            f"(valid: {', '.join(robot.feet)})"
        )
    return push_schedule(
        target,
        robot.n_feet,
        robot.feet.index(options.pusher),
        dt=options.dt,
        period=options.period,
        sweep=options.sweep,
        speed_per_stride=options.speed_per_stride,
        min_push=options.min_push,
        max_push=options.max_push,
        start_speed=options.start_speed,
    )


def speed_bound(robot: RigidBodyRobot, options: SkateOptions, samples: int = 512) -> float:
    """An upper bound on the board speed the pushes of a schedule can reach [m/s].

    While the pushing foot is on the ground the trunk passes it at the board's speed
    :math:`v`, so (a) the foot moves at :math:`v` relative to the trunk, along x, which its
    joints allow only up to :math:`\\max_q \\sum_j |\\partial p_x / \\partial q_j|\\,
    \\dot q_{j,max}`; and (b) in the shortest push of the schedule, ``min_push``, the foot
    sweeps :math:`v \\cdot` ``min_push``, at most the extent of its workspace along x. Both
    maxima are taken over ``samples`` joint configurations drawn (seeded) from the joint
    ranges. Beyond the smaller bound no push can accelerate the board.
    """
    pusher = robot.feet.index(options.pusher)
    q = ca.SX.sym("q", robot.n_joints)
    along_x = robot.foot_jacobian(q, pusher)[0, :]
    foot = ca.Function("foot", [q], [robot.feet_in_trunk(q)[pusher][0], along_x])
    rng = np.random.default_rng(0)
    speed, lowest, highest = 0.0, np.inf, -np.inf
    for sample in rng.uniform(robot.q_lower, robot.q_upper, size=(samples, robot.n_joints)):
        x, row = foot(sample)
        speed = max(speed, float(np.abs(np.asarray(row)).ravel() @ robot.speed_limit))
        lowest, highest = min(lowest, float(x)), max(highest, float(x))
    return min(speed, (highest - lowest) / options.min_push)


def initial_skate_state(
    robot: RigidBodyRobot, board: SkateboardModel, speed: float = 0.0
) -> tuple[Array, Array]:
    """Robot in its keyframe standing on the deck of a board at the origin, rolling along x
    at ``speed`` [m/s] with it (at rest by default).

    Returns:
        The state (robot then board) and the deck-frame positions of the contact sites,
        n_feet x 3 [m].
    """
    feet = np.array([np.asarray(f).ravel() for f in robot.feet_in_trunk(robot.q_reference)])
    trunk_z = board.deck_height + float(np.mean(robot.foot_radius - feet[:, 2]))
    trunk = np.array([0.0, 0.0, trunk_z])
    com = trunk + robot.com_in_trunk
    robot_state = np.concatenate([com, np.zeros(3), [speed], np.zeros(5), robot.q_reference])
    on_deck = feet + trunk - np.array([0.0, 0.0, board.deck_height])
    board_state = np.zeros(len(BOARD_STATE))
    board_state[BOARD_STATE.index("board_v")] = speed
    return np.concatenate([robot_state, board_state]), on_deck


def skate_rates(robot: RigidBodyRobot, board: SkateboardModel) -> ca.Function:
    """:math:`\\dot x = f(x, u, p)` with ``p`` the 0/1 deck-contact flag of each foot."""
    nr = 12 + robot.n_joints
    nf = robot.n_feet
    x = ca.SX.sym("x", nr + len(BOARD_STATE))
    u = ca.SX.sym("u", 3 * nf + robot.n_joints)
    on_deck = ca.SX.sym("on_deck", nf)
    xr, xb = x[:nr], x[nr:]
    forces = [u[3 * i : 3 * i + 3] for i in range(nf)]
    centres = feet_world(robot, xr[0:3], xr[3:6], xr[12:nr])
    rotation, _ = deck_frame(board, xb)
    normals = [on_deck[i] * rotation[:, 2] + (1 - on_deck[i]) * ca.DM([0, 0, 1]) for i in range(nf)]
    points = [c - float(r) * n for c, r, n in zip(centres, robot.foot_radius, normals, strict=True)]
    deck_forces = [on_deck[i] * forces[i] for i in range(nf)]
    rates = ca.vertcat(
        rigid_body_rates(robot, xr, forces, points, u[3 * nf :]),
        skateboard_rates(board, xb, deck_forces, points),
    )
    return ca.Function("skate_rates", [x, u, on_deck], [rates])


def triangle_turn(vertices: Array) -> float:
    """+1 if the triangle's vertices (3 x 2) run counter-clockwise, -1 otherwise."""
    a, b, c = vertices
    return float(np.sign((b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])))


def inward_distances(point: Any, vertices: list[Any], turn: float) -> Any:
    """Signed horizontal distances [m] of ``point`` (x, y) inside each edge of the triangle
    ``vertices`` (three (x, y)) whose orientation is ``turn`` (:func:`triangle_turn`):
    :math:`d_j = s\\,((b - a) \\times (p - a)) / \\lVert b - a \\rVert` for the edge
    :math:`(a, b)`; all three are positive exactly when the point is inside."""
    rows = []
    for j in range(3):
        a, b = vertices[j], vertices[(j + 1) % 3]
        edge = b - a
        cross = edge[0] * (point[1] - a[1]) - edge[1] * (point[0] - a[0])
        rows.append(turn * cross / ca.sqrt(edge[0] ** 2 + edge[1] ** 2))
    return ca.vertcat(*rows)


def _names(robot: RigidBodyRobot) -> tuple[tuple[str, ...], tuple[str, ...]]:
    states = (*rigid_body_state_names(robot.base), *(f"q_{j}" for j in robot.joints), *BOARD_STATE)
    forces = tuple(f"f_{foot}_{a}" for foot in robot.feet for a in "xyz")
    return states, (*forces, *(f"qd_{j}" for j in robot.joints))


def _node_specs(schedule: ContactSchedule, target: float, start: float = 0.0) -> list[NodeSpec]:
    """Per node: which contact constraints apply (the signature: the feet's contacts, the
    interval's, the feet on the deck while another swings (in the interval before or after
    the node), last node, first node), the node where the pushing foot landed (the
    reference) and the desired board speed (a ramp from ``start`` to the last push)."""
    n = schedule.n_intervals
    contact_of = [schedule.phases[i].contacts for i in schedule.phase_of_interval()]
    phase_of = schedule.phase_of_interval()
    ramp_end = schedule.times[sum(schedule.intervals_per_phase[:-2])]
    specs = []
    landed = 0
    for k in range(n + 1):
        feet = []
        reference = None
        for i in range(schedule.n_feet):
            kinds = {
                c[i]
                for c in (contact_of[k - 1] if k > 0 else None, contact_of[k] if k < n else None)
                if c is not None
            }
            ground = None
            if Contact.GROUND in kinds:
                if k == 0 or contact_of[k - 1][i] is not Contact.GROUND:
                    ground = "lands"
                    landed = k
                else:
                    ground = "stays"
            swing = None
            if kinds == {Contact.SWING}:
                phase = schedule.phases[phase_of[k]]
                first = sum(schedule.intervals_per_phase[: phase_of[k]])
                leaving = (k - first) / schedule.intervals_per_phase[phase_of[k]] <= 0.5
                surface = phase.swing_from if leaving else phase.swing_to
                swing = "over" if surface is Contact.BOARD else "beside"
            descends = (
                kinds == {Contact.SWING} and k + 1 < n and contact_of[k + 1][i] is Contact.GROUND
            )
            lifts = (
                k < n - 1
                and contact_of[k][i] is Contact.GROUND
                and contact_of[k + 1][i] is Contact.SWING
            )
            if descends:
                reference = k + 1  # the node where it lands
            feet.append((Contact.BOARD in kinds, ground, swing, descends, lifts))
        interval = contact_of[k] if k < n else None
        support = None
        for c in (contact_of[k - 1] if k > 0 else None, interval):
            if c is not None and Contact.SWING in c:
                support = tuple(i for i, kind in enumerate(c) if kind is Contact.BOARD)
        # Node 0 (its state fixed by its bounds) and the last node are groups of their own.
        signature = (tuple(feet), interval, support, k == n, k == 0)
        speed = start + (target - start) * min(1.0, schedule.times[k] / ramp_end)
        specs.append(NodeSpec(signature, landed if reference is None else reference, (speed,)))
    return specs


def build_skate_problem(
    robot: RigidBodyRobot,
    board: SkateboardModel,
    target: float,
    options: SkateOptions | None = None,
    name: str | None = None,
) -> TrajectoryProblem:
    """Build the acceleration NLP for one target speed.

    Args:
        robot: The SRBKM robot.
        board: The skateboard.
        target: Board speed at the end [m/s].
        options: Settings (defaults: :class:`SkateOptions`).
        name: Entry name (default ``accelerate-<target>``).

    Raises:
        ConfigError: The target is not positive or above :func:`speed_bound`.
    """
    started = time.perf_counter()
    o = options or SkateOptions()
    bound = speed_bound(robot, o)
    if not 0.0 < target <= bound:
        raise ConfigError(
            f"target {target:g} m/s is unreachable: no push of {robot.name} can help beyond "
            f"{bound:.2f} m/s (see speed_bound), and the target must be positive"
        )
    schedule = skate_schedule(robot, target, o)
    n = schedule.n_intervals
    nj, nf = robot.n_joints, robot.n_feet
    nr = 12 + nj
    nx = nr + len(BOARD_STATE)
    state_names, input_names = _names(robot)
    weight_per_foot = robot.mass * GRAVITY / nf
    state_scale = np.ones(nx)
    input_scale = np.concatenate([np.full(3 * nf, weight_per_foot), np.full(nj, 5.0)])

    x0, on_deck_place = initial_skate_state(robot, board, o.start_speed)
    masks = schedule.contact_masks()
    deck_mask = masks[Contact.BOARD]
    rates = skate_rates(robot, board)

    # Bounds.
    x_lo = np.full(nx, -np.inf)
    x_hi = np.full(nx, np.inf)
    x_lo[2], x_hi[2] = board.deck_height + 0.12, board.deck_height + 0.35
    x_lo[3:5], x_hi[3:5] = -0.6, 0.6
    x_lo[6:9], x_hi[6:9] = -3.0, 3.0
    x_lo[9:12], x_hi[9:12] = -6.0, 6.0
    x_lo[12:nr], x_hi[12:nr] = robot.q_lower + 0.01, robot.q_upper - 0.01
    b = nr
    x_lo[b + 2], x_hi[b + 2] = -1.0, 1.0
    x_lo[b + 3], x_hi[b + 3] = -0.05, o.speed_margin * target
    x_lo[b + 4], x_hi[b + 4] = -board.roll_limit, board.roll_limit
    x_lo[b + 5], x_hi[b + 5] = -6.0, 6.0
    state_lo = np.tile(x_lo, (n + 1, 1))
    state_hi = np.tile(x_hi, (n + 1, 1))
    state_lo[0] = state_hi[0] = x0
    force_bound = 2.0 * robot.mass * GRAVITY
    active = deck_mask + masks[Contact.GROUND]
    input_hi = np.hstack(
        [np.repeat(active, 3, axis=1) * force_bound, np.tile(robot.speed_limit, (n, 1))]
    )

    pusher = robot.feet.index(o.pusher)
    side = float(np.sign(on_deck_place[pusher, 1]) or 1.0)
    q_sym = ca.SX.sym("q", nj)
    jacobians = ca.Function(
        "foot_jacobians", [q_sym], [robot.foot_jacobian(q_sym, i) for i in range(nf)]
    )
    h_des = x0[2] - o.crouch
    q_ref = ca.DM(robot.q_reference)

    def node_terms(
        signature: Any, x: Any, u: Any, u_prev: Any, x_ref: Any, values: Any
    ) -> NodeTerms:
        feet, interval, support, last, _ = signature
        terms = NodeTerms()
        xr, xb = x[:nr], x[nr:]
        com, euler, vel, omega, q = xr[0:3], xr[3:6], xr[6:9], xr[9:12], xr[12:nr]
        rotation_b, origin_b = deck_frame(board, xb)
        rotation_r = euler_zyx_matrix(euler[0], euler[1], euler[2], ca)
        centres = feet_world(robot, com, euler, q)
        landed = feet_world(robot, x_ref[0:3], x_ref[3:6], x_ref[12:nr])
        yaw_rate_r = (euler_rate_map(euler[0], euler[1], ca) @ omega)[2]
        # Eq. (14): the robot turns with the board.
        terms.add(ca.sin(xb[4]) * xb[3] + yaw_rate_r / board.reduced.steer_gain, 0.0, 0.0)
        for i, (on_board, ground, swing, descends, _) in enumerate(feet):
            radius = float(robot.foot_radius[i])
            in_deck = rotation_b.T @ (centres[i] - origin_b)
            beside = board.half_width + radius + o.side_margin
            if on_board:  # eq. (15), integrated: the foot moves with the deck
                terms.add(in_deck - ca.DM(on_deck_place[i]), 0.0, 0.0)
            if ground is not None:  # still on the ground, beside the deck
                if ground == "stays":
                    terms.add(centres[i][0:2] - landed[i][0:2], 0.0, 0.0)
                terms.add(centres[i][2], radius, radius)
                terms.add(side * in_deck[1], beside, np.inf)
            if swing == "over":
                terms.add(in_deck[2], radius + o.clearance, np.inf)
            elif swing == "beside":
                terms.add(side * in_deck[1], beside, np.inf)
            if swing is not None:
                terms.add(centres[i][2], radius + o.clearance, np.inf)
            if descends:  # one step before it lands: nearly above its landing point
                reach = o.touchdown_step
                terms.add(centres[i][0:2] - landed[i][0:2], -reach, reach)
        if support is not None and len(support) == 3:
            turn = triangle_turn(on_deck_place[list(support), :2])
            inside = inward_distances(com[0:2], [centres[i][0:2] for i in support], turn)
            terms.add(inside, o.support_margin, np.inf)
        if last:  # at the target speed, riding along
            board_velocity = ca.vertcat(xb[3] * ca.cos(xb[2]), xb[3] * ca.sin(xb[2]), 0.0)
            terms.add(xb[3] - target, 0.0, 0.0)
            terms.add(vel - board_velocity, 0.0, 0.0)
            terms.add(omega, 0.0, 0.0)
            terms.add(xb[5], 0.0, 0.0)
            return terms
        jac = jacobians(q)
        for i, kind in enumerate(interval):
            if kind is Contact.SWING:
                continue
            f = u[3 * i : 3 * i + 3]
            local = (rotation_b if kind is Contact.BOARD else ca.DM.eye(3)).T @ f
            cone = ca.vertcat(*pyramid_rows(local, o.friction))
            least = o.min_board_force * weight_per_foot if kind is Contact.BOARD else 0.0
            terms.add(cone, np.array([least, 0.0, 0.0, 0.0, 0.0]), np.inf)
            if feet[i][4]:  # the last interval before a pushing foot lifts: unloaded
                terms.add(f[2], -np.inf, o.liftoff_force * weight_per_foot)
            leg = list(robot.legs[i])
            torque = jac[i][:, leg].T @ (rotation_r.T @ f)
            limit = o.torque_fraction * robot.torque_limit[leg]
            terms.add(torque, -limit, limit)
        # Cost, eq. (16): tracking (a, b), effort (c), effort rate (d).
        board_velocity = ca.vertcat(xb[3] * ca.cos(xb[2]), xb[3] * ca.sin(xb[2]), 0.0)
        com_in_deck = rotation_b.T @ (com - origin_b)
        tracking = (
            o.w_speed * (xb[3] - values[0]) ** 2
            + o.w_roll * (xb[4] ** 2 + 0.1 * xb[5] ** 2)
            + o.w_heading * xb[2] ** 2
            + o.w_height * (com[2] - h_des) ** 2
            + o.w_lateral * com_in_deck[1] ** 2
            + o.w_attitude * (euler[0] ** 2 + euler[1] ** 2 + (euler[2] - xb[2]) ** 2)
            + o.w_velocity * (ca.sumsqr(vel - board_velocity) + 0.1 * ca.sumsqr(omega))
            + o.w_joints * ca.sumsqr(q - q_ref)
        )
        forces = u[: 3 * nf] / weight_per_foot
        forces_prev = u_prev[: 3 * nf] / weight_per_foot
        effort = o.w_force * ca.sumsqr(forces) + o.w_joint_rate * ca.sumsqr(u[3 * nf :])
        change = o.w_force_change * ca.sumsqr(forces - forces_prev)
        change = change + o.w_joint_rate_change * ca.sumsqr(u[3 * nf :] - u_prev[3 * nf :])
        terms.cost = o.dt * (tracking + effort + change)
        return terms

    metadata = {
        "pair": f"{robot.name}-{board.name}",
        "kind": "repush" if o.start_speed > 0.0 else "accelerate",
        "target": float(target),
        "options": asdict(o),
        "phases": [
            {"mode": p.mode, "duration": p.duration, "contacts": [c.value for c in p.contacts]}
            for p in schedule.phases
        ],
        "feet": list(robot.feet),
        "modes": schedule.mode_names(),
        "board_states": list(BOARD_STATE),
    }
    return assemble_problem(
        name=name or f"accelerate-{target:.2f}",
        state_names=state_names,
        input_names=input_names,
        state_scale=state_scale,
        input_scale=input_scale,
        times=schedule.times,
        rates=rates,
        parameters=deck_mask,
        state_bounds=(state_lo, state_hi),
        input_bounds=(-input_hi, input_hi),
        nodes=_node_specs(schedule, target, o.start_speed),
        node_terms=node_terms,
        metadata=metadata,
        started=started,
    )


def skate_guess(
    robot: RigidBodyRobot, board: SkateboardModel, problem: TrajectoryProblem
) -> tuple[Array, Array]:
    """A cold-start guess: the board on the speed ramp, the robot riding it in its keyframe,
    its weight shared by the feet in contact, joints still."""
    options = SkateOptions(**problem.metadata["options"])
    x0, _ = initial_skate_state(robot, board, options.start_speed)
    n = problem.n_intervals
    times = problem.times
    target = float(problem.metadata["target"])
    nr = 12 + robot.n_joints
    start = options.start_speed
    speed = start + (target - start) * np.clip(times / times[-1] * 1.2, 0.0, 1.0)
    position = np.concatenate([[0.0], np.cumsum(0.5 * (speed[1:] + speed[:-1]) * np.diff(times))])
    states = np.tile(x0, (n + 1, 1))
    states[:, 0] += position
    states[:, 6] = speed
    states[:, nr] = position
    states[:, nr + 3] = speed
    inputs = np.zeros((n, problem.nu))
    masks = skate_schedule(robot, target, options).contact_masks()
    active = masks[Contact.BOARD] + masks[Contact.GROUND]
    for k in range(n):
        touching = active[k] > 0
        count = max(1, int(np.sum(touching)))
        for i in np.flatnonzero(touching):
            inputs[k, 3 * i + 2] = robot.mass * GRAVITY / count
    return states, inputs
