"""A wheel's sideways grip on the floor: how much net sideways force a platform on one wheel
(a Hovershoe) may take from the rider's feet before its wheel skids across the floor.

A wheel rolls freely along its travel, but across it the tyre holds only by Coulomb friction
with the floor: with the feet's forces :math:`f_s` on the robot at the platform's sites, its
sideways axis :math:`t_2` and normal :math:`n`, the wheel stays put sideways while

.. math:: \\Big|\\sum_s t_2^\\top f_s\\Big| \\le \\mu_g \\sum_s n^\\top f_s,

two rows per platform, :math:`\\sum_s (\\pm t_2 - \\mu_g n)^\\top f_s \\le 0`. The platform's
own weight, which presses the wheel down too, is left out: it covers the platform's own
sideways inertia in a turn (a 3.7 kg shoe at 1.5 m/s and 0.5 rad/s needs 2.8 N, its weight
gives 0.2 x 36 N = 7 N) and keeps the bound on the safe side.

Opposite sideways forces at a line foot's two ends (the twist that turns a shoe) add no net
sideways force, so these rows leave the twist alone; a squeeze of the shoes by the feet (each
foot pushing its shoe outwards, which no centroidal model sees: the two forces cancel on the
rider) is what they bound. The twist :math:`M` has its own: the tyre's two rims, :math:`w/2`
either side of its middle, hold it up to :math:`\\mu_g N w / 2` by friction, beyond which the
shoe spins on the floor (and a spinning tyre has no sideways grip left), so the whole-body QP
holds it there, plus what a planned turn's rim damping needs
(:class:`~ridempc.wbc.constraints.WheelGripConstraint`). The floor's true friction is not
known to the controllers, so :math:`\\mu_g` is the conservative :data:`WHEEL_GRIP`.
"""

from __future__ import annotations

__all__ = ["WHEEL_GRIP"]

# [-] a rubber tyre on a wet, smooth indoor floor (0.2-0.3): the slipperiest floor a wheeled
# board is ridden on; ice (0.05-0.1) is not. The riding library's turns use at most 0.08.
WHEEL_GRIP: float = 0.2
