"""The whole-body controller's per-tick code, rewritten for speed (issue 39), against the
plain formulas it replaced: Pinocchio's own calls one by one, and NumPy written out, on
seeded random inputs."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

from ridempc.robots import load_robot
from ridempc.wbc.model import WholeBodyModel

WORLD_ALIGNED = pin.ReferenceFrame.LOCAL_WORLD_ALIGNED


@pytest.fixture(scope="module", params=["cassie", "cyberdog2"])
def model(request: pytest.FixtureRequest) -> WholeBodyModel:
    return WholeBodyModel(load_robot(request.param))


def _random_state(model: WholeBodyModel, rng: np.random.Generator) -> tuple:
    neutral = pin.neutral(model.model)
    q = pin.integrate(model.model, neutral, rng.normal(size=model.model.nv))
    return q, 2.0 * rng.normal(size=model.model.nv)


def test_model_update_matches_pinocchio_call_by_call(model: WholeBodyModel) -> None:
    """One pass of ``computeAllTerms`` gives what a separate ``crba``, ``nonLinearEffects``
    and ``forwardKinematics(q, v, 0)`` give: the mass matrix, the bias, and every point's
    drift at zero acceleration."""
    rng = np.random.default_rng(7)
    reference = model.model.createData()
    pm = model.model
    for _ in range(10):
        q, v = _random_state(model, rng)
        terms = model.update(q, v)
        mass = pin.crba(pm, reference, q)
        mass = np.triu(mass) + np.triu(mass, 1).T
        np.testing.assert_allclose(terms.mass_matrix, mass, rtol=0, atol=1e-12)
        np.testing.assert_allclose(
            terms.bias, pin.nonLinearEffects(pm, reference, q, v), rtol=0, atol=1e-10
        )
        pin.forwardKinematics(pm, reference, q, v, np.zeros(pm.nv))
        pin.computeJointJacobians(pm, reference, q)
        pin.updateFramePlacements(pm, reference)
        for k, frame in enumerate(model.site_frames):
            drift = pin.getFrameClassicalAcceleration(pm, reference, frame, WORLD_ALIGNED).linear
            jacobian = pin.getFrameJacobian(pm, reference, frame, WORLD_ALIGNED)[:3]
            np.testing.assert_allclose(terms.sites.drift[k], drift, rtol=0, atol=1e-10)
            np.testing.assert_allclose(terms.sites.jacobian[k], jacobian, rtol=0, atol=1e-12)
            np.testing.assert_allclose(terms.sites.velocity[k], jacobian @ v, atol=1e-12)
            np.testing.assert_allclose(
                terms.site_rotation[k], reference.oMf[frame].rotation, rtol=0, atol=1e-14
            )
        pin.centerOfMass(pm, reference, q, v, np.zeros(pm.nv))
        np.testing.assert_allclose(terms.com.drift, reference.acom[0], rtol=0, atol=1e-10)
        np.testing.assert_allclose(terms.com.position, reference.com[0], rtol=0, atol=1e-14)
