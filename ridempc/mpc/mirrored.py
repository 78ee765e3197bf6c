"""A library reference ridden as its mirror image: the same manoeuvre with the other feet.

A left-right symmetric robot's library need hold each manoeuvre once: its mirror image
(:class:`~ridempc.trajopt.mirror.Mirror`: :math:`y \\to -y`, roll and yaw negated, each
foot and joint exchanged with its mirror) is ridden by the same MPC. On the skateboard a
re-push by one rear foot rolls and turns the board its own way; mirrored, the push is made
by the other rear foot and turns the board the other way (:mod:`ridempc.mpc.push_side`).
"""

from __future__ import annotations

from dataclasses import replace
from typing import Any

from ridempc.mpc.reference import MotionReference
from ridempc.trajopt.mirror import Mirror

__all__ = ["MIRRORED", "mirrored"]

MIRRORED: str = "mirrored"  # the name suffix of a mirrored reference


def _pusher(metadata: dict[str, Any], contacts: tuple[str, ...], mirror: Mirror) -> None:
    """The metadata's ``options.pusher`` (a contact name) made its mirror contact's."""
    options = metadata.get("options")
    if isinstance(options, dict) and options.get("pusher") in contacts:
        index = contacts.index(options["pusher"])
        metadata["options"] = {**options, "pusher": contacts[mirror.contact_source[index]]}


def mirrored(reference: MotionReference, mirror: Mirror) -> MotionReference:
    """``reference`` reflected: its states, inputs, per-contact parameters, contact schedule
    and steady-riding rates (and a settle's offsets), named ``<name>-mirrored``.

    Args:
        reference: A reference of the pair ``mirror`` was made for (its states, inputs and
            one parameter per contact, the skate pair's deck flags).
        mirror: The pair's mirror.
    """
    metadata = dict(reference.metadata)
    _pusher(metadata, reference.contact_names, mirror)
    metadata[MIRRORED] = not bool(reference.metadata.get(MIRRORED, False))
    return replace(
        reference,
        name=f"{reference.name}-{MIRRORED}",
        states=mirror.states(reference.states),
        inputs=mirror.inputs(reference.inputs),
        parameters=mirror.per_contact(reference.parameters),
        phases=tuple(replace(p, contacts=mirror.contacts(p.contacts)) for p in reference.phases),
        schedule=tuple(mirror.contacts(step) for step in reference.schedule),
        steady_rates=mirror.rates(reference.steady_rates),
        settle_states=(
            None if reference.settle_states is None else mirror.rates(reference.settle_states)
        ),
        settle_inputs=(
            None if reference.settle_inputs is None else mirror.inputs(reference.settle_inputs)
        ),
        metadata=metadata,
    )
