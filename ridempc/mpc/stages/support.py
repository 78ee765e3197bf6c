"""Where each foot is over an MPC step, from the schedule's contacts.

The library's contacts are sites (a foot may have several: Cassie's toe line); a foot is on
the ground if any of its contacts is, in the air if all swing, else on its board.
"""

from __future__ import annotations

from collections.abc import Sequence

import mujoco

from ridempc.trajopt.schedule import Contact

__all__ = ["contacts_to_feet", "foot_support"]


def contacts_to_feet(
    model: mujoco.MjModel, feet: Sequence[str], contacts: Sequence[str]
) -> list[int]:
    """The foot (index in ``feet``, the robot's ``foot_bodies``) each library contact's
    site belongs to."""
    out = []
    for contact in contacts:
        site = model.site(contact)
        body = model.body(int(site.bodyid[0])).name
        out.append(list(feet).index(body))
    return out


def foot_support(
    contacts: Sequence[Contact], contact_foot: Sequence[int], n_feet: int
) -> tuple[Contact, ...]:
    """Per foot, where it is over the step: ``contacts`` per library contact, each on the
    foot ``contact_foot`` gives."""
    support = [Contact.SWING] * n_feet
    for contact, foot in zip(contacts, contact_foot, strict=True):
        if contact is Contact.GROUND or support[foot] is Contact.GROUND:
            support[foot] = Contact.GROUND
        elif contact is Contact.BOARD:
            support[foot] = Contact.BOARD
    return tuple(support)
