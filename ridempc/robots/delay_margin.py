"""How much PD gain a joint can take through its motor's torque delay.

Each motor driver's PD acts on one joint through the delay line of
:class:`~ridempc.sim.motors.MotorDriver`. Taken alone, a joint of inertia :math:`I`
[kg m^2] (reflected rotor and links, the rest of the robot free) under a PD of stiffness
:math:`k_p` and damping :math:`k_d` delayed by :math:`T` [s] has the loop

.. math:: L(s) = \\frac{(k_p + k_d s)\\, e^{-sT}}{I s^2},

whose phase margin at the crossover :math:`\\omega_c` (:math:`|L(j\\omega_c)| = 1`) is

.. math:: \\varphi_m = \\arctan\\frac{k_d \\omega_c}{k_p} - \\omega_c T .

The delay costs :math:`\\omega_c T` of phase at the crossover, so the crossover, set mostly by
:math:`k_d / I`, has to stay well below :math:`1/T`; the stiffness spends the damping's lead.
:func:`phase_margin` evaluates the margin of given gains; :func:`gain_bound` gives the largest
gains with a wanted margin and a wanted ratio of damping lead; :func:`best_damping` the damping
of largest margin for a given stiffness, and :func:`tracking_damping` that damping for each
delayed motor of a robot at one configuration. The delay :math:`T` counts the
delay line's whole steps and half a physics step of hold (:func:`effective_delay`).
"""

from __future__ import annotations

import math

import mujoco
import numpy as np
from numpy.typing import NDArray

from ridempc.robots.robot import Motor
from ridempc.sim.motors import delay_steps

__all__ = [
    "best_damping",
    "effective_delay",
    "gain_bound",
    "joint_inertias",
    "phase_margin",
    "tracking_damping",
]

Array = NDArray[np.float64]

# The margin a delayed joint PD is held to [rad]: 45 deg, the usual margin for a loop whose
# plant (here the delay and the leg's other modes) is known only roughly.
DEFAULT_MARGIN = math.pi / 4


def effective_delay(steps: int, timestep: float) -> float:
    """The delay a driver's PD sees [s]: ``steps`` whole physics steps of ``timestep`` [s]
    in the delay line, and half a step for holding each torque through its step."""
    return (steps + 0.5) * timestep


def phase_margin(inertia: float, kp: float, kd: float, delay: float) -> float:
    """Phase margin [rad] of the delayed joint PD loop :math:`L(s)` above.

    Args:
        inertia: Joint inertia :math:`I` [kg m^2].
        kp: Stiffness [N m / rad].
        kd: Damping [N m s / rad].
        delay: Delay :math:`T` [s].

    Returns:
        :math:`\\varphi_m` [rad] (negative: the loop is unstable).
    """
    # |L(jw)| = 1:  I^2 w^4 - kd^2 w^2 - kp^2 = 0, a quadratic in w^2
    w2 = (kd**2 + math.sqrt(kd**4 + 4.0 * inertia**2 * kp**2)) / (2.0 * inertia**2)
    w = math.sqrt(w2)
    return math.atan2(kd * w, kp) - w * delay


def gain_bound(
    inertia: float, delay: float, margin: float = DEFAULT_MARGIN, lead: float = 2.0
) -> tuple[float, float]:
    """The largest PD gains a joint can take through a delay with a given margin.

    The damping's lead at the crossover is :math:`\\arctan(k_d \\omega_c / k_p) =
    \\arctan(r)` with :math:`r` = ``lead``, and the delay takes the rest down to the margin:
    :math:`\\omega_c T = \\arctan r - \\varphi_m`. Then :math:`|L(j\\omega_c)| = 1` gives

    .. math:: k_d = \\frac{I \\omega_c}{\\sqrt{1 + r^{-2}}}, \\qquad k_p = \\frac{k_d
              \\omega_c}{r}.

    Args:
        inertia: Joint inertia :math:`I` [kg m^2].
        delay: Delay :math:`T` [s] (> 0).
        margin: Phase margin :math:`\\varphi_m` [rad].
        lead: Damping-to-stiffness ratio at the crossover :math:`r` [-] (> tan(margin)).

    Returns:
        ``(kp, kd)`` [N m / rad], [N m s / rad].
    """
    crossover = (math.atan(lead) - margin) / delay
    kd = inertia * crossover / math.sqrt(1.0 + lead**-2)
    return kd * crossover / lead, kd


def joint_inertias(model: mujoco.MjModel, data: mujoco.MjData, dofs: NDArray[np.int64]) -> Array:
    """Each joint's inertia with every other degree of freedom free [kg m^2]:
    :math:`1 / (M^{-1})_{ii}` of MuJoCo's joint-space inertia (armature included) at
    ``data``'s configuration (after ``mj_forward``)."""
    unit = np.zeros((len(dofs), model.nv))
    unit[np.arange(len(dofs)), dofs] = 1.0
    solved = np.zeros_like(unit)
    mujoco.mj_solveM(model, data, solved, unit)
    return 1.0 / solved[np.arange(len(dofs)), dofs]


def best_damping(inertia: float, kp: float, delay: float) -> float:
    """The damping of largest phase margin for a stiffness through a delay [N m s / rad].

    With the crossover :math:`\\omega_c` as the free variable (:math:`k_d = I \\sqrt{\\omega_c^4
    - a^2} / \\omega_c`, :math:`a = k_p / I`) the margin is :math:`\\varphi_m = \\arccos(a /
    \\omega_c^2) - \\omega_c T`; it is largest where its slope is zero,

    .. math:: T^2 x^3 - T^2 a^2 x - 4 a^2 = 0, \\qquad x = \\omega_c^2,

    whose one root above :math:`a` gives :math:`k_d = I \\sqrt{(x^2 - a^2) / x}`. More damping
    than this pushes the crossover out where the delay takes more than the damping gives.

    Args:
        inertia: Joint inertia :math:`I` [kg m^2].
        kp: Stiffness [N m / rad] (> 0).
        delay: Delay :math:`T` [s] (> 0).

    Returns:
        The damping :math:`k_d` [N m s / rad].
    """
    a = kp / inertia
    roots = np.roots([delay**2, 0.0, -(delay**2) * a**2, -4.0 * a**2])
    x = max(float(r.real) for r in roots if abs(r.imag) <= 1e-9 * abs(r))
    return inertia * math.sqrt((x * x - a * a) / x)


def tracking_damping(
    model: mujoco.MjModel,
    qpos: Array,
    motors: tuple[Motor, ...],
    kp: Array,
    kd: Array,
    timestep: float,
) -> Array:
    """Each motor's damping for its stiffness ``kp``: the largest margin through its delay.

    Each joint's inertia is taken at ``qpos`` with the rest of the robot free
    (:func:`joint_inertias`), each delay as the driver applies it (:func:`effective_delay` of
    the delay in whole steps of ``timestep``), and the damping is :func:`best_damping`. A motor
    without a delay keeps its damping from ``kd``: with no delay more damping only adds margin.

    Args:
        model: The robot's compiled description.
        qpos: The configuration the robot works in [MuJoCo qpos].
        motors: Its motors (actuator order).
        kp: Their stiffnesses [N m / rad].
        kd: Their dampings without a delay [N m s / rad].
        timestep: The physics step the drivers run at [s].

    Returns:
        The dampings [N m s / rad], actuator order.
    """
    data = mujoco.MjData(model)
    data.qpos[:] = qpos
    mujoco.mj_forward(model, data)
    joints = [mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, m.joint) for m in motors]
    inertias = joint_inertias(model, data, np.array([model.jnt_dofadr[j] for j in joints]))
    damping = np.array(kd, dtype=float)
    for i, motor in enumerate(motors):
        if motor.torque_delay > 0.0 and kp[i] > 0.0:
            delay = effective_delay(delay_steps(motor.torque_delay, timestep), timestep)
            damping[i] = best_damping(float(inertias[i]), float(kp[i]), delay)
    return damping
