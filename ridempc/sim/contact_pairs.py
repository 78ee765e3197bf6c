"""Explicit contact pairs for the surfaces whose friction a scenario can change (floor, decks).

MuJoCo gives a contact between two geoms of equal priority the larger of their two friction
coefficients, so a floor made slippery under a nominal tyre (both 1.0) would grip as before.
For each *surface* geom (the floor, each deck) the scene therefore compiles one explicit pair
per geom the surface can touch (what contype/conaffinity, the parent filter and the excludes
allow), with the parameters MuJoCo itself gives that contact (condim and friction the larger,
solref and solimp mixed by solmix, margin and gap the larger). MuJoCo then drops those geom
pairs from its dynamic contacts, so at the nominal friction a ride is the same as without
the pairs. A friction change sets each pair's friction (:func:`set_pair_friction`) to

.. math:: \\mu = \\mu_0 \\, \\frac{\\mu_a}{\\mu_{a0}} \\, \\frac{\\mu_b}{\\mu_{b0}}

with :math:`\\mu_0` the pair's nominal friction and :math:`\\mu_a / \\mu_{a0}`,
:math:`\\mu_b / \\mu_{b0}` each side's change: the product rule (Bullet's), because a
tyre's grip on a floor depends on both surfaces; a 0.3 floor under a nominal (1.0) tyre or
foot grips at 0.3.
"""

from __future__ import annotations

from collections.abc import Iterable

import mujoco
import numpy as np
from numpy.typing import NDArray

__all__ = ["add_surface_pairs", "can_collide", "collision_geoms", "set_pair_friction"]

_MINVAL = mujoco.mjMINVAL  # MuJoCo's own threshold for a zero solmix


def collision_geoms(model: mujoco.MjModel, bodies: Iterable[int]) -> frozenset[int]:
    """The geoms of ``bodies`` that take part in contacts (visual ones do not)."""
    wanted = set(bodies)
    return frozenset(
        g
        for g in range(model.ngeom)
        if model.geom_bodyid[g] in wanted and (model.geom_contype[g] or model.geom_conaffinity[g])
    )


def can_collide(model: mujoco.MjModel, g1: int, g2: int) -> bool:
    """Whether MuJoCo's dynamic contacts (broadphase filters) would let two geoms touch."""
    if not (
        model.geom_contype[g1] & model.geom_conaffinity[g2]
        or model.geom_contype[g2] & model.geom_conaffinity[g1]
    ):
        return False
    b1, b2 = int(model.geom_bodyid[g1]), int(model.geom_bodyid[g2])
    w1, w2 = int(model.body_weldid[b1]), int(model.body_weldid[b2])
    if w1 == w2:
        return False
    parent1 = int(model.body_weldid[model.body_parentid[w1]])
    parent2 = int(model.body_weldid[model.body_parentid[w2]])
    filter_parent = not model.opt.disableflags & mujoco.mjtDisableBit.mjDSBL_FILTERPARENT
    if filter_parent and w1 and w2 and (w1 == parent2 or w2 == parent1):
        return False
    signature = (min(b1, b2) << 16) + max(b1, b2)
    return signature not in set(model.exclude_signature.tolist())


def _mixed(model: mujoco.MjModel, g1: int, g2: int) -> dict[str, object]:
    """The parameters MuJoCo gives a dynamic contact of two geoms of equal priority."""
    s1, s2 = float(model.geom_solmix[g1]), float(model.geom_solmix[g2])
    if s1 >= _MINVAL and s2 >= _MINVAL:
        mix = s1 / (s1 + s2)
    elif s1 < _MINVAL and s2 < _MINVAL:
        mix = 0.5
    else:
        mix = 0.0 if s1 < _MINVAL else 1.0
    ref1, ref2 = model.geom_solref[g1], model.geom_solref[g2]
    if ref1[0] > 0 and ref2[0] > 0:
        solref = mix * ref1 + (1.0 - mix) * ref2
    else:
        solref = np.minimum(ref1, ref2)
    solimp = mix * model.geom_solimp[g1] + (1.0 - mix) * model.geom_solimp[g2]
    slide, spin, roll = np.maximum(model.geom_friction[g1], model.geom_friction[g2])
    return {
        "condim": int(max(model.geom_condim[g1], model.geom_condim[g2])),
        "solref": solref.tolist(),
        "solimp": solimp.tolist(),
        "friction": [slide, slide, spin, roll, roll],
        "margin": float(max(model.geom_margin[g1], model.geom_margin[g2])),
        "gap": float(max(model.geom_gap[g1], model.geom_gap[g2])),
    }


def add_surface_pairs(
    spec: mujoco.MjSpec, model: mujoco.MjModel, surfaces: Iterable[int]
) -> mujoco.MjModel:
    """Add the pairs of each surface geom to ``spec`` and recompile it.

    Args:
        spec: The scene's spec, compiled into ``model``.
        model: Its compiled model (geom ids as in ``spec.geoms``).
        surfaces: Geom ids of the surfaces (floor first, then the decks).

    Returns:
        The recompiled model (same element ids, plus the pairs, each pair's geoms in MuJoCo's
        order: by body).
    """
    geoms = {int(g.id): g for g in spec.geoms}
    if any(model.geom_priority[g] != model.geom_priority[0] for g in range(model.ngeom)):
        raise ValueError("explicit friction pairs assume geoms of equal priority")
    done: set[frozenset[int]] = set()
    for surface in surfaces:
        for other in range(model.ngeom):
            key = frozenset((surface, other))
            if key in done or not can_collide(model, surface, other):
                continue
            done.add(key)
            for g in (surface, other):
                if not geoms[g].name:
                    geoms[g].name = f"contact/geom{g}"
            spec.add_pair(
                geomname1=geoms[surface].name,
                geomname2=geoms[other].name,
                **_mixed(model, surface, other),
            )
    return spec.compile()


def set_pair_friction(
    model: mujoco.MjModel,
    nominal_pairs: NDArray[np.float64],
    nominal_geoms: NDArray[np.float64],
) -> None:
    """Each pair's friction: its nominal one times each side's change (the product rule).

    Args:
        model: The scene, its ``geom_friction`` holding each geom's current friction.
        nominal_pairs: ``pair_friction`` as compiled [-].
        nominal_geoms: ``geom_friction`` as compiled [-].
    """
    g1, g2 = model.pair_geom1, model.pair_geom2
    ratio = model.geom_friction[:, 0] / nominal_geoms[:, 0]
    model.pair_friction[:] = nominal_pairs * (ratio[g1] * ratio[g2])[:, None]
