"""Small controllers and shortcuts the tests share."""

from __future__ import annotations

import numpy as np

from ridempc.controllers.base import Controller
from ridempc.controllers.stand import StandController
from ridempc.estimation import EstimatedState
from ridempc.estimation.state import BoardEstimate
from ridempc.scenarios.scenario import Command, Scenario
from ridempc.sim.motors import MotorCommand
from ridempc.sim.sensors import SensorPacket


class LimpController(Controller):
    """No torque at all: the robot must fall."""

    rate_hz = 500.0

    def update(self, sensors: SensorPacket, command: Command) -> MotorCommand:
        n = len(self.robot.motors)
        zero = np.zeros(n)
        return MotorCommand(zero, zero, zero, zero, zero)


class NanController(StandController):
    """Holds the stand, then returns NaN torques from t = 0.5 s."""

    def update(self, sensors: SensorPacket, command: Command) -> MotorCommand:
        hold = super().update(sensors, command)
        if sensors.time < 0.5:
            return hold
        return MotorCommand(hold.torque * np.nan, hold.position, hold.velocity, hold.kp, hold.kd)


class RecordingController(StandController):
    """Stand, and keep every sensor packet it was given."""

    rate_hz = 500.0

    def __init__(self, robot, board: str = "none") -> None:
        super().__init__(robot, board)
        self.packets: list[SensorPacket] = []

    def update(self, sensors: SensorPacket, command: Command) -> MotorCommand:
        self.packets.append(sensors)
        return super().update(sensors, command)


def scenario(duration: float, **fields) -> Scenario:
    return Scenario(name="test", duration=duration, **fields)


def assert_gain_edit_refused(default_file, tmp_path, old: str, new: str, field: str, build) -> None:
    """Write ``default_file`` with ``old`` replaced by ``new``; ``build(path)`` must refuse it
    with a ConfigError naming ``field`` and the file."""
    import pytest

    from ridempc.errors import ConfigError

    text = default_file.read_text()
    assert old in text
    path = tmp_path / "gains.toml"
    path.write_text(text.replace(old, new, 1))
    with pytest.raises(ConfigError, match=field.replace(".", r"\.")) as info:
        build(path)
    assert str(path) in str(info.value)


def board_estimate(t: float, boards: tuple[BoardEstimate, ...]) -> EstimatedState:
    """An estimate that carries only the time and the platforms (for the board observers)."""
    return EstimatedState(
        time=t,
        base_position=np.zeros(3),
        base_quaternion=np.array([1.0, 0.0, 0.0, 0.0]),
        base_velocity=np.zeros(3),
        base_angular_velocity=np.zeros(3),
        joint_position={},
        joint_velocity={},
        q=np.zeros(7),
        v=np.zeros(6),
        foot_names=("left", "right"),
        contact=np.ones(2, dtype=bool),
        foot_position=np.zeros((2, 3)),
        foot_velocity=np.zeros((2, 3)),
        boards=boards,
    )


def reference_problem(
    x0: np.ndarray,
    window: np.ndarray,
    dt: float,
    nu: int = 2,
    contacts: tuple = (),
    bound: float = 1.0,
):
    """An MPC problem around the state reference ``window`` from ``x0``, its dynamics unused
    (the identity, no inputs' effect), its inputs within ``bound`` and their reference zero."""
    from ridempc.mpc.problem import MpcProblem

    n, nx = len(window) - 1, len(x0)
    return MpcProblem(
        initial_state=x0,
        A=np.tile(np.eye(nx), (n, 1, 1)),
        B=np.zeros((n, nx, nu)),
        c=np.zeros((n, nx)),
        state_reference=window,
        input_reference=np.zeros((n, nu)),
        state_weights=np.ones(nx),
        input_weights=np.ones(nu),
        input_lower=-np.full((n, nu), bound),
        input_upper=np.full((n, nu), bound),
        constraint_matrix=np.zeros((n, 0, nu)),
        constraint_lower=np.zeros((n, 0)),
        constraint_upper=np.zeros((n, 0)),
        dt=dt,
        contacts=contacts,
    )


def osqp_tight(
    p: np.ndarray, q: np.ndarray, a: np.ndarray, lower: np.ndarray, upper: np.ndarray
) -> np.ndarray:
    """The dense QP :math:`\\min \\tfrac12 z^\\top P z + q^\\top z`, :math:`l \\le A z \\le u`
    solved by OSQP to 1e-10 and polished: the reference optimum."""
    import osqp
    import scipy.sparse as sp

    solver = osqp.OSQP()
    solver.setup(
        sp.csc_matrix(np.triu(p)), q, sp.csc_matrix(a), lower, upper,
        eps_abs=1e-10, eps_rel=1e-10, max_iter=100_000, polishing=True, verbose=False,
    )  # fmt: skip
    result = solver.solve(raise_error=False)
    assert result.info.status == "solved"
    return np.asarray(result.x)
