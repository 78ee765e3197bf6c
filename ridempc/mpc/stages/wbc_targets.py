"""The whole-body QP's targets at a control tick from the plan in force
(:class:`TargetsFromPlan`).

The plan is read at its age (:class:`~ridempc.mpc.plan_targets.PlanReader`: the state
interpolated over the 1/30 s step, its first input's forces, applied at the WBC's sites
where the library's contacts are those sites, else shared evenly along each foot); the feet
stand or swing as the plan's schedule says (:class:`~ridempc.mpc.stages.feet_targets.FeetTargets`),
or, with no foot standing in a drop's flight, swing after their platforms
(:class:`~ridempc.mpc.flight.DropFlight`); on the Hovershoes each shoe's drag is its
platform's acceleration (:meth:`~ridempc.mpc.shoe_observer.ShoeObserver.drift`).
"""

from __future__ import annotations

from collections.abc import Sequence

from ridempc.estimation import EstimatedState
from ridempc.mpc.flight import DropFlight
from ridempc.mpc.landing import LandingLoads
from ridempc.mpc.plan_book import PlanBook
from ridempc.mpc.plan_targets import PlanReader
from ridempc.mpc.shoe_observer import ShoeObserver
from ridempc.mpc.stages.feet_targets import FeetTargets
from ridempc.trajopt.schedule import Contact
from ridempc.wbc import WbcTargets

__all__ = ["TargetsFromPlan"]


class TargetsFromPlan:
    """The whole-body targets for the plan in force.

    Args:
        read_plan: Reads a plan's first step as whole-body targets.
        feet_targets: The feet's targets over an MPC step.
        flight: The drop's flight (None: no ``flight`` stage).
        shoes: The shoes' observer (None: not the Hovershoes).
        sites_match: Whether the library's contacts are the WBC's sites (the plan's
            forces are then applied at each site: the centre of pressure along a foot).
        landing: Each foot's load centred after a flight's landing (None: no ``landing``).
    """

    def __init__(
        self,
        read_plan: PlanReader,
        feet_targets: FeetTargets,
        flight: DropFlight | None,
        shoes: ShoeObserver | None,
        sites_match: bool,
        landing: LandingLoads | None = None,
    ) -> None:
        self.read_plan = read_plan
        self.feet_targets = feet_targets
        self.flight = flight
        self.shoes = shoes
        self.sites_match = sites_match
        self.landing = landing

    def __call__(
        self,
        book: PlanBook,
        support: Sequence[Contact],
        t_ref: float,
        estimate: EstimatedState,
        now: float,
    ) -> WbcTargets:
        """The targets at ``now`` [s] for the plan in ``book``, the feet's ``support``
        over this MPC step at the reference's time ``t_ref`` [s]."""
        plan = book.plan
        assert plan is not None
        wanted = self.read_plan(plan, book.frame, book.age(now))
        feet = self.feet_targets(support, t_ref, estimate, book.frame)
        swing_acceleration = None
        if self.flight is not None and self.flight.flying:  # no foot stands: mpc/flight.py
            feet, swing_acceleration = self.flight.feet(feet, estimate)
        shoes = self.shoes
        site_forces = wanted.site_forces if self.sites_match else None
        if site_forces is not None and self.landing is not None:  # mpc/landing.py
            site_forces = self.landing(site_forces, now)
        return WbcTargets(
            position=wanted.position,
            orientation=wanted.orientation,
            contact=feet.contact,
            forces=wanted.forces,
            velocity=wanted.velocity,
            acceleration=wanted.acceleration,
            angular_velocity=wanted.angular_velocity,
            angular_acceleration=wanted.angular_acceleration,
            site_forces=site_forces,
            swing_position=feet.swing,
            swing_velocity=feet.swing_velocity,
            swing_acceleration=swing_acceleration,
            posture=feet.posture,
            board_acceleration=shoes.drift(estimate.boards) if shoes is not None else (),
        )
