"""The MPC's plan in force and its records (:class:`PlanBook`).

A plan is in force from its take-up until the next one's: the whole-body QP reads it at
every tick in the library frame it was solved in, at its age in MPC steps since the state
it was solved from (:math:`(t - t_0) / \\Delta t`, :math:`\\Delta t` = 1/30 s), its first
input's forces low-passed where the pair has a force filter
(:mod:`~ridempc.mpc.force_filter`). The book keeps what each take-up tells the rest of the
loop: the contacts of the plan's first step, its problem, the QP's failures so far, how far
the state it was solved from lay from its reference, and each solve's time.
"""

from __future__ import annotations

import numpy as np

from ridempc.errors import RidempcError
from ridempc.mpc.force_filter import ForceFilter
from ridempc.mpc.plan import Plan
from ridempc.mpc.problem import MpcProblem
from ridempc.mpc.stages.build import Built, PendingSolve
from ridempc.mpc.state_map import PlanarFrame
from ridempc.trajopt.schedule import Contact

__all__ = ["STEPS_PER_S", "PlanBook"]

STEPS_PER_S: float = 30.0  # [1/s] the MPC's steps a second: the paper's 30 Hz plan


class PlanBook:
    """The plan in force, its frame and the time of the state it was solved from.

    Args:
        force_filter: The low-pass of the plan's first input's forces (None: none).
    """

    def __init__(self, force_filter: ForceFilter | None) -> None:
        self.force_filter = force_filter
        self.plan: Plan | None = None
        self.time = 0.0  # [s] of the state the plan was solved from
        self.frame = PlanarFrame()  # the library frame the plan is in
        self.contacts: tuple[Contact, ...] = ()  # per library contact, the last MPC step
        self.problem: MpcProblem | None = None  # the last one taken up (None from a process)
        self.failures = 0  # the MPC's fallbacks, as of the last plan taken up
        self.deviation = 0.0  # [-] the MPC's state from its reference (handover.deviation)
        self.ms: list[float] = []  # each tick: building the problem and solving it [ms]
        self.qp_ms: list[float] = []  # each tick's QP: updating it and solving it [ms]

    def record(self, built: Built) -> None:
        """What the take-up of ``built`` tells the loop, before its plan is checked."""
        self.contacts, self.problem = built.contacts, built.problem
        self.failures = built.failures
        self.deviation = built.deviation

    def adopt(self, solve: PendingSolve, built: Built) -> Plan:
        """The plan of ``solve`` in force from now on, timed; its forces filtered.

        Raises:
            RidempcError: The plan is not finite.
        """
        plan = built.plan
        self.ms.append(1e3 * (built.build_s + plan.solve_time))
        self.qp_ms.append(1e3 * plan.solve_time)
        if not np.all(np.isfinite(plan.states)):
            raise RidempcError(f"MPC plan not finite (status {plan.status})")
        if self.force_filter is not None:
            plan = plan._replace(first_input=self.force_filter(plan.first_input, solve.time))
        self.plan, self.time, self.frame = plan, solve.time, solve.frame
        return plan

    def age(self, now: float) -> float:
        """The plan's age at ``now`` [s] in MPC steps [-]."""
        return (now - self.time) * STEPS_PER_S
