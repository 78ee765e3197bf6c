"""Which geoms touch the terrain: the contact bits shared by the terrain and the boards.

MuJoCo lets two geoms touch when ``contype`` of one and ``conaffinity`` of the other share a
bit. The floor plane and every board, robot and obstacle geom use bits 1 and 2 (``contype`` 1,
``conaffinity`` 3 for ground and boards; ``contype`` 2, ``conaffinity`` 1 for the riders).
The terrain's boxes and heightfields (:mod:`ridempc.sim.terrain`) take ``contype`` 2, so
everything that touches the floor touches them too, and ``conaffinity`` 2 and 4, so riders'
geoms and a board's *tread* (bit 4) touch them.

A tread is a wheel's collision shape on the terrain in place of its own where MuJoCo's
collider gets that shape wrong at an edge: its multi-point convex collider puts the contact
of a cylinder rolling over a box's edge on the box's side face (a horizontal normal), so the
edge shoves the wheel forward instead of carrying it round. A capsule of the wheel's radius
whose segment spans the tread width touches a box face at the same two rim points as the
cylinder, and an edge along the wheel's radius (MuJoCo's capsule-box collider is exact). The
wheel's own geom then keeps ``conaffinity`` 0, so it touches the floor plane (whose
cylinder collider is exact) but not the terrain.
"""

from __future__ import annotations

__all__ = ["TERRAIN_BITS", "TREAD_BITS", "WHEEL_ON_FLOOR_BITS"]

# The terrain: touched by what touches the floor (their contype 1 against our conaffinity
# 2 is not needed: our contype 2 meets their conaffinity 3), by riders (contype 2) and treads.
TERRAIN_BITS: dict[str, int] = {"contype": 2, "conaffinity": 6}
# A wheel's tread: touches the terrain only (the floor's conaffinity 3 lacks bit 4).
TREAD_BITS: dict[str, int] = {"contype": 4, "conaffinity": 0}
# A wheel that has a tread: touches the floor, boards and riders as before, not the terrain.
WHEEL_ON_FLOOR_BITS: dict[str, int] = {"contype": 1, "conaffinity": 0}
