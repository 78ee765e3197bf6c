"""Cassie on the Hovershoes or the Segway: lean-to-accelerate, stop and turn trajectories.

State :math:`x = (x_R, x_B)`: the simplified rider (:mod:`.rider`: centre of mass [m],
Z-Y-X Euler angles [rad], velocity [m/s], body angular velocity [rad/s]) and the board's
reduced model (:mod:`.platforms`); input :math:`u`: the contact forces on the rider at the
ends of each line foot, world frame [N], then the board's own inputs (the Segway's knee-bar
angle [rad]). Each contact stays at its place on its platform, which moves with the board's
state, so the feet ride along by construction; the rider's eq. (3) and the board's reduced
model are coupled through the forces (eq. 9 of the hovershoe paper gives the platform
torques). Constraints:

- collocation of the dynamics (:mod:`.problem`);
- legs: each hip-to-foot distance within the rider's band, the feet on their own sides of
  the pelvis, the pelvis heading within 0.35 rad of the platforms';
- contacts: friction pyramids on the platform normals (the inner pyramid of :math:`\\mu`,
  :mod:`ridempc.friction`), a normal force of at
  most the rider's weight, and on the Hovershoes a yaw torque per shoe within the tyres'
  grip (4 N m);
- board: platform pitch within ``pitch_limit``, speed within the board's limit, the Segway's
  knee bar within its travel;
- start: riding straight and steady at the initial speed (at rest to accelerate); end:
  riding straight and steady at the final speed and heading, the rider moving with the board.

Kinds of trajectory (``target`` is a speed :math:`v` [m/s]):

- ``accelerate``: from rest to :math:`v` (lean forward to pitch the platforms nose down);
- ``stop``: from :math:`v` to rest (lean back);
- ``turn``: at :math:`v`, a heading change of ``turn_angle`` to the left.

Cost (eq. 16 of the skateboard paper's form): tracking of a speed or heading ramp, the
rider upright over its feet at its riding height and moving with the board, small platform
pitch; effort (forces in units of the weight per contact, knee bar) and effort rate.
"""

from __future__ import annotations

import math
import time
from dataclasses import asdict, dataclass
from typing import Any

import casadi as ca
import numpy as np
from numpy.typing import NDArray

from ridempc.errors import ConfigError
from ridempc.friction import pyramid_rows
from ridempc.trajopt.platforms import WheeledBoard, platform_pushes, platform_torques
from ridempc.trajopt.problem import NodeSpec, NodeTerms, TrajectoryProblem, assemble_problem
from ridempc.trajopt.rider import RiderModel
from ridempc.trajopt.rigid_body import GRAVITY, rigid_body_rates, rigid_body_state_names
from ridempc.trajopt.rotations import euler_zyx_matrix

__all__ = ["KINDS", "RideOptions", "build_ride_problem", "ride_guess", "ride_layout", "ride_rates"]

Array = NDArray[np.float64]
KINDS = ("accelerate", "stop", "turn")


@dataclass(frozen=True)
class RideOptions:
    """Settings of the ride problems (stored with every library entry).

    Attributes:
        dt: Grid step [s]; the platforms' closed-loop pitch has poles near -80 rad/s
            (Hovershoes) and -140 rad/s (Segway), so a 0.05 s grid leaves gaps of about
            1e-2 rad/s in the pitch rate against an adaptive integrator, 0.025 s a third.
        friction: Foot friction coefficient [-].
        settle: Steady riding before and after the manoeuvre [s].
        seconds_per_speed: Manoeuvre time per m/s of speed change [s / (m/s)].
        manoeuvre_base: Manoeuvre time of a speed change on top of that [s]: the lean in
            and out. A speed change of :math:`\\Delta v` takes
            ``manoeuvre_base + seconds_per_speed`` :math:`\\Delta v`.
        turn_time: Duration of a turn [s].
        turn_angle: Heading change of a turn [rad].
        w_speed: Weight of the speed error.
        w_heading: Weight of the heading error.
        w_upright: Weight of the pelvis roll and pitch and its yaw off the board's.
        w_over_feet: Weight of the centre of mass's horizontal offset from the feet.
        w_height: Weight of the centre of mass's height off the riding keyframe's. Without
            it the height is free within the legs' band and long trajectories sank: the
            Segway's 3 and 4 m/s entries crouched 0.13 m, which put Cassie's shins on the
            knee pad, and the pad then steered the ride into a fall.
        w_velocity: Weight of the rider's velocity relative to the board's.
        w_pitch: Weight of the platforms' pitch.
        w_force: Weight of the forces (units of the weight per contact).
        w_board_input: Weight of the board's own inputs.
        w_change: Weight of the input changes per interval.
    """

    dt: float = 0.025
    friction: float = 0.6
    settle: float = 0.5
    seconds_per_speed: float = 2.0
    manoeuvre_base: float = 1.0
    turn_time: float = 3.0
    turn_angle: float = math.pi / 4
    w_speed: float = 10.0
    w_heading: float = 10.0
    w_upright: float = 10.0
    w_over_feet: float = 10.0
    w_height: float = 10.0
    w_velocity: float = 1.0
    w_pitch: float = 1.0
    w_force: float = 0.1
    w_board_input: float = 1.0
    w_change: float = 0.1


def ride_layout(rider: RiderModel, board: WheeledBoard) -> dict[str, Any]:
    """Where the rider's contacts sit: per contact its platform, and its place in that
    platform's frame [m] (the riding keyframe with each platform under its foot)."""
    platform_of = [f if board.n_platforms > 1 else 0 for f in rider.foot_of_contact]
    origins = np.zeros((board.n_platforms, 2))
    places = np.zeros((rider.n_contacts, 3))
    for i in range(board.n_platforms):
        mine = [k for k, p in enumerate(platform_of) if p == i]
        origins[i] = np.mean(rider.feet_from_com[mine, :2], axis=0)
    feet_z = float(np.mean(rider.feet_from_com[:, 2]))
    for k, p in enumerate(platform_of):
        places[k, :2] = rider.feet_from_com[k, :2] - origins[p]
        places[k, 2] = rider.feet_from_com[k, 2] - feet_z
    return {
        "platform_of": platform_of,
        "origins": origins,  # relative to the centre of mass, horizontal
        "places": places,
        "com_height": board.top - feet_z,
    }


def ride_rates(rider: RiderModel, board: WheeledBoard) -> ca.Function:
    """:math:`\\dot x = f(x, u, p)` (``p`` unused, one zero)."""
    layout = ride_layout(rider, board)
    nc, nb = rider.n_contacts, len(board.state_names)
    x = ca.SX.sym("x", 12 + nb)
    u = ca.SX.sym("u", 3 * nc + len(board.input_names))
    p = ca.SX.sym("p", 1)
    xb = x[12:]
    forces = [u[3 * k : 3 * k + 3] for k in range(nc)]
    points = _contact_points(board, xb, layout)
    torques = platform_torques(board, xb, forces, points, layout["platform_of"])
    pushes = platform_pushes(board, xb, forces, layout["platform_of"])
    rates = ca.vertcat(
        rigid_body_rates(rider.body, x[:12], forces, points, ca.SX(0, 1)),
        board.rates(xb, torques, u[3 * nc :], pushes),
    )
    return ca.Function("ride_rates", [x, u, p], [rates])


def _contact_points(board: WheeledBoard, xb: Any, layout: dict[str, Any]) -> list[Any]:
    points = []
    for place, platform in zip(layout["places"], layout["platform_of"], strict=True):
        rotation, origin = board.pose(xb, platform)
        points.append(origin + rotation @ ca.DM(place))
    return points


def _speeds(kind: str, target: float) -> tuple[float, float]:
    return {"accelerate": (0.0, target), "stop": (target, 0.0), "turn": (target, target)}[kind]


def _initial_state(rider: RiderModel, board: WheeledBoard, speed: float) -> Array:
    layout = ride_layout(rider, board)
    com = np.array([0.0, 0.0, layout["com_height"]])
    velocity = np.array([speed, 0.0, 0.0])
    return np.concatenate(
        [com, np.zeros(3), velocity, np.zeros(3), board.steady(speed, layout["origins"])]
    )


def _duration(kind: str, target: float, o: RideOptions) -> float:
    manoeuvre = o.turn_time if kind == "turn" else o.seconds_per_speed * target + o.manoeuvre_base
    steps = round((2 * o.settle + manoeuvre) / o.dt)
    return steps * o.dt


def build_ride_problem(
    rider: RiderModel,
    board: WheeledBoard,
    kind: str,
    target: float,
    options: RideOptions | None = None,
    name: str | None = None,
) -> TrajectoryProblem:
    """Build one ride trajectory's NLP (see the module docstring).

    Raises:
        ConfigError: Unknown kind, or a target outside (0, the board's speed limit].
    """
    started = time.perf_counter()
    o = options or RideOptions()
    if kind not in KINDS:
        raise ConfigError(f"unknown trajectory kind '{kind}' (valid: {', '.join(KINDS)})")
    if not 0.0 < target <= board.speed_limit:
        raise ConfigError(
            f"target {target:g} m/s is unreachable on the {board.name}: its speed limit is "
            f"{board.speed_limit:g} m/s; targets must be in (0, that]"
        )
    layout = ride_layout(rider, board)
    platform_of = layout["platform_of"]
    nc, nb, np_ = rider.n_contacts, len(board.state_names), board.n_platforms
    nx = 12 + nb
    state_names = (*rigid_body_state_names(rider.body.base), *board.state_names)
    input_names = (
        *(f"f_{c}_{a}" for c in rider.contacts for a in "xyz"),
        *board.input_names,
    )
    weight = rider.body.mass * GRAVITY
    per_contact = weight / nc
    input_scale = np.concatenate([np.full(3 * nc, per_contact), np.ones(len(board.input_names))])
    state_scale = np.ones(nx)
    start_speed, end_speed = _speeds(kind, target)
    duration = _duration(kind, target, o)
    n = round(duration / o.dt)
    times = np.arange(n + 1, dtype=np.float64) * o.dt
    end_heading = o.turn_angle if kind == "turn" else 0.0
    x0 = _initial_state(rider, board, start_speed)
    rates = ride_rates(rider, board)

    x_lo, x_hi = np.full(nx, -np.inf), np.full(nx, np.inf)
    x_lo[2], x_hi[2] = layout["com_height"] - 0.3, layout["com_height"] + 0.1
    x_lo[3:5], x_hi[3:5] = -0.5, 0.5
    state_lo, state_hi = np.tile(x_lo, (n + 1, 1)), np.tile(x_hi, (n + 1, 1))
    state_lo[0] = state_hi[0] = x0
    force_hi = np.full(3 * nc, weight)
    input_hi = np.tile(np.concatenate([force_hi, board.input_bound]), (n, 1))

    def ramp(t: float, start: float, end: float) -> float:
        s = np.clip((t - o.settle) / (duration - 2 * o.settle), 0.0, 1.0)
        return start + (end - start) * float(s)

    nodes = [
        NodeSpec(
            (k == n,),
            k,
            (ramp(times[k], start_speed, end_speed), ramp(times[k], 0.0, end_heading)),
        )
        for k in range(n + 1)
    ]
    low, high = rider.leg_range

    def node_terms(
        signature: Any, x: Any, u: Any, u_prev: Any, x_ref: Any, values: Any
    ) -> NodeTerms:
        (last,) = signature
        terms = NodeTerms()
        com, euler, vel, omega, xb = x[0:3], x[3:6], x[6:9], x[9:12], x[12:]
        rotation = euler_zyx_matrix(euler[0], euler[1], euler[2], ca)
        points = _contact_points(board, xb, layout)
        speeds = [board.speed(xb, i) for i in range(np_)]
        headings = [board.heading(xb, i) for i in range(np_)]
        mean_speed = sum(speeds) / np_
        mean_heading = sum(headings) / np_
        for i in range(np_):
            terms.add(board.pitch(xb, i), -board.pitch_limit, board.pitch_limit)
            terms.add(speeds[i], -0.1, board.speed_limit)
        for foot in range(rider.n_feet):
            mine = [k for k, f in enumerate(rider.foot_of_contact) if f == foot]
            sole = sum(points[k] for k in mine) / len(mine)
            hip = com + rotation @ ca.DM(rider.hips[foot])
            length = ca.norm_2(sole - hip)
            terms.add(length, low * rider.leg_length[foot], high * rider.leg_length[foot])
            side = float(np.sign(rider.hips[foot][1]))
            terms.add(side * (rotation.T @ (sole - com))[1], 0.05, np.inf)
        terms.add(euler[2] - mean_heading, -0.35, 0.35)
        heading_vector = ca.vertcat(ca.cos(mean_heading), ca.sin(mean_heading), 0.0)
        board_velocity = mean_speed * heading_vector
        if last:
            for i in range(np_):
                terms.add(speeds[i] - end_speed, 0.0, 0.0)
                terms.add(headings[i] - end_heading, 0.0, 0.0)
                terms.add(board.pitch_rate(xb, i), 0.0, 0.0)
            terms.add(vel - board_velocity, 0.0, 0.0)
            terms.add(omega, 0.0, 0.0)
            return terms
        forces = [u[3 * k : 3 * k + 3] for k in range(nc)]
        for k in range(nc):
            plate, _ = board.pose(xb, platform_of[k])
            local = plate.T @ forces[k]
            terms.add(ca.vertcat(*pyramid_rows(local, o.friction)), 0.0, np.inf)
        if math.isfinite(board.yaw_torque_limit):
            torques = platform_torques(board, xb, forces, points, platform_of)
            for _, yaw_torque in torques:
                terms.add(yaw_torque, -board.yaw_torque_limit, board.yaw_torque_limit)
        feet_centre = sum(points) / nc
        offset = rotation.T @ (com - feet_centre)
        tracking = (
            o.w_speed * sum((s - values[0]) ** 2 for s in speeds)
            + o.w_heading * sum((h - values[1]) ** 2 for h in headings)
            + o.w_upright * (euler[0] ** 2 + euler[1] ** 2 + (euler[2] - mean_heading) ** 2)
            + o.w_over_feet * (offset[0] ** 2 + offset[1] ** 2)
            + o.w_height * (com[2] - layout["com_height"]) ** 2
            + o.w_velocity * (ca.sumsqr(vel - board_velocity) + 0.1 * ca.sumsqr(omega))
            + o.w_pitch * sum(board.pitch(xb, i) ** 2 for i in range(np_))
        )
        scaled = u[: 3 * nc] / per_contact
        scaled_prev = u_prev[: 3 * nc] / per_contact
        effort = o.w_force * ca.sumsqr(scaled) + o.w_board_input * ca.sumsqr(u[3 * nc :])
        change = o.w_change * (
            ca.sumsqr(scaled - scaled_prev) + ca.sumsqr(u[3 * nc :] - u_prev[3 * nc :])
        )
        terms.cost = o.dt * (tracking + effort + change)
        return terms

    metadata = {
        "pair": f"{rider.body.name}-{board.name}",
        "kind": kind,
        "target": float(target),
        "options": asdict(o),
        "phases": [
            {"mode": "ride", "duration": o.settle},
            {
                "mode": {"accelerate": "lean", "stop": "brake", "turn": "turn"}[kind],
                "duration": duration - 2 * o.settle,
            },
            {"mode": "ride", "duration": o.settle},
        ],
        "contacts": list(rider.contacts),
        "board_states": list(board.state_names),
        "start_speed": start_speed,
        "end_speed": end_speed,
        "end_heading": end_heading,
    }
    return assemble_problem(
        name=name or f"{kind}-{target:.2f}",
        state_names=state_names,
        input_names=input_names,
        state_scale=state_scale,
        input_scale=input_scale,
        times=times,
        rates=rates,
        parameters=np.zeros((n, 1)),
        state_bounds=(state_lo, state_hi),
        input_bounds=(-input_hi, input_hi),
        nodes=nodes,
        node_terms=node_terms,
        metadata=metadata,
        started=started,
    )


def ride_guess(
    rider: RiderModel, board: WheeledBoard, problem: TrajectoryProblem
) -> tuple[Array, Array]:
    """Cold start: the board on the speed (or heading) ramp, the rider upright over its feet,
    its weight shared by the contacts."""
    meta = problem.metadata
    layout = ride_layout(rider, board)
    times = problem.times
    settle = float(meta["options"]["settle"])
    span = times[-1] - 2 * settle
    s = np.clip((times - settle) / span, 0.0, 1.0)
    speed = meta["start_speed"] + (meta["end_speed"] - meta["start_speed"]) * s
    heading = meta["end_heading"] * s
    velocity = np.column_stack([speed * np.cos(heading), speed * np.sin(heading)])
    dt = problem.dt
    xy = np.vstack([[0.0, 0.0], np.cumsum(0.5 * (velocity[1:] + velocity[:-1]) * dt, axis=0)])
    states = np.zeros((len(times), problem.nx))
    for k in range(len(times)):
        c, sn = np.cos(heading[k]), np.sin(heading[k])
        turn = np.array([[c, -sn], [sn, c]])
        origins = xy[k] + layout["origins"] @ turn.T
        xb = board.steady(float(speed[k]), origins)
        for i in range(board.n_platforms):
            xb[board.heading_index(i)] = heading[k]
        states[k] = np.concatenate(
            [
                [xy[k, 0], xy[k, 1], layout["com_height"], 0.0, 0.0, heading[k]],
                [velocity[k, 0], velocity[k, 1], 0.0, 0.0, 0.0, 0.0],
                xb,
            ]
        )
    inputs = np.zeros((len(times) - 1, problem.nu))
    inputs[:, 2 : 3 * rider.n_contacts : 3] = rider.body.mass * GRAVITY / rider.n_contacts
    return states, inputs
