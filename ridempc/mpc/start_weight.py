"""The rider's mass weighed at the ride's first tick, before the MPC's first plan: the legs'
spring forces against the acceleration they give her.

At :math:`t = 0` the rider stands still in the pair's start keyframe: her legs' springs are
deflected as the keyframe has them, so they push with the keyframe's forces :math:`F_0` [N]
whatever she weighs, and the motors give nothing yet (their first torques come with the
first command). The vertical specific force the IMU measures is then
:math:`f_z = F / m` [m/s^2] (world axes; :math:`F` the supports' vertical force, the legs'
and the board's), and the reading of the feet's loads over it,

.. math:: r = \\frac{\\sum_i \\ell_i\\, m_0 g / n}{m_0 f_z} = \\frac{m}{m_0}\\,
   \\frac{\\bar\\ell\\, m_0 g}{F},

(:meth:`~ridempc.mpc.payload.PayloadEstimator.reading`) is proportional to the rider's mass
:math:`m` [kg], an inertial balance: the posture, and with it :math:`F`, is the keyframe's
on every ride. The nominal rider's reading :math:`r_0` (the pair's ``start_reading``, the
nominal model's first tick in its start keyframe) calibrates it, so

.. math:: \\Delta\\hat m = m_0\\,(r / r_0 - 1),

held within :data:`~ridempc.mpc.payload.MASS_BOUND`. It is weighed once, at the first MPC
tick with a reading (the first control tick on a ride that starts on the MPC), and kept
(:meth:`~ridempc.mpc.payload.PayloadEstimator.weigh`): later readings carry her sway and the
crouch's load path, which the start's does not.

On Cassie on the Segway, ``hard`` seed 151's first 30 variants (payload -30..+30 %): read
within 0.45 kg for lighter riders (4 % of the payload, every body scaled), and within
+1.5/-3.1 kg for heavier ones (a mass on the pelvis 5-10 cm ahead or behind pitches the
pelvis, and the IMU's reading with it; docs/tuning.md, session 12). A pair weighs its rider
so with ``[stages.payload] mass_from = "start"`` and its ``start_reading`` (Cassie on the
Segway: 0.9017); none does yet: on the Segway's ``hard`` rides the mass without the centre of
mass's offset and height lost as many rides as it saved.
"""

from __future__ import annotations

from ridempc.mpc.payload import MASS_BOUND, PayloadEstimator

__all__ = ["StartWeight"]


class StartWeight:
    """The payload's mass weighed once from the first readings (module docstring).

    Args:
        reading: :math:`r_0` [-], the nominal rider's reading at its start.
    """

    def __init__(self, reading: float) -> None:
        self.reading = reading
        self.mass: float | None = None  # [kg] weighed, once

    def weigh(self, payload: PayloadEstimator) -> None:
        """Weigh the rider from ``payload``'s readings so far, if not yet weighed and a
        reading came in (every foot in contact)."""
        if self.mass is not None:
            return
        reading = payload.reading()
        if reading is None:
            return
        excess = min(MASS_BOUND, max(-MASS_BOUND, reading / self.reading - 1.0))
        self.mass = excess * payload.mass0
        payload.weigh(self.mass)
