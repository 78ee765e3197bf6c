"""The whole-body QP's targets for the feet: which stand, where a lifted one swings, and the
posture the reference's joint angles give.

Where the library plans the feet (:class:`~ridempc.mpc.swing.ReferenceFeet`), a foot the
schedule lifts follows the reference's foot, carried by the estimated board, and the posture
task holds the reference's joint angles; without planned feet a lifted foot holds where it
is. A schedule that lifts every foot is taken as all standing (the QP needs a support).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import NamedTuple

import numpy as np
from numpy.typing import NDArray

from ridempc.estimation import EstimatedState
from ridempc.mpc.controller import LinearMpc
from ridempc.mpc.state_map import PlanarFrame
from ridempc.mpc.swing import VELOCITY_STEP, ReferenceFeet
from ridempc.trajopt.schedule import Contact
from ridempc.wbc import WholeBodyController

__all__ = ["FeetTargets", "FootTargets"]

Array = NDArray[np.float64]


class FootTargets(NamedTuple):
    """Per foot whether it stands; the swinging feet's positions [m] and velocities [m/s]
    (or None), and the posture's joint angles [rad] (or None: the WBC's own)."""

    contact: NDArray[np.bool_]
    swing: Array | None
    swing_velocity: Array | None
    posture: Array | None


class FeetTargets:
    """The feet's targets at a control tick.

    Args:
        feet: The reference's feet.
        wbc: The whole-body QP (its model and motor angles).
        mpc: The MPC (its reference, read at each call: a manoeuvre replaces it).
    """

    def __init__(self, feet: ReferenceFeet, wbc: WholeBodyController, mpc: LinearMpc) -> None:
        self._feet, self._wbc, self._mpc = feet, wbc, mpc

    def __call__(
        self,
        support: Sequence[Contact],
        t_ref: float,
        estimate: EstimatedState,
        frame: PlanarFrame,
    ) -> FootTargets:
        """The targets for the feet's ``support`` over this MPC step at the reference's
        time ``t_ref`` [s], in the plan's library ``frame``."""
        feet = self._feet
        contact = np.array([c is not Contact.SWING for c in support])
        swing = swing_velocity = posture = None
        if feet.plans_feet:  # the reference's feet and joint angles
            states = self._mpc.reference.states_at(np.array([t_ref, t_ref + VELOCITY_STEP]))
            posture = feet.joint_angles(states[0], self._wbc.motor_q)
            if not contact.all():
                board = estimate.boards[0] if estimate.boards else None
                swing, swing_velocity = feet.targets(states, frame, board)
        elif not contact.all():  # without planned feet, a lifted foot holds where it is
            swing = self._wbc.model.foot_points(estimate.q)
        if not contact.any():
            contact[:] = True
        return FootTargets(contact, swing, swing_velocity, posture)
