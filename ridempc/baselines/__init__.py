"""The papers' PD baselines, one concept per module, each with its gain file beside it.

Cassie (Segway paper, section IV-A): ``cassie_kinematics`` (sensors to CoM, feet and virtual
legs), ``cassie_statics`` (inverse statics, the feedforward), ``cassie_standing_gains`` and
``cassie_standing.toml`` (checked gains), ``cassie_standing`` (the standing controller, ``pd``
on flat ground, which the Segway and Hovershoe riders extend). ``filters``: a first-order
low-pass filter.

Nothing is imported here, so that importing one baseline does not import the others.
"""
