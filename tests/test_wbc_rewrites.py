"""The whole-body controller's per-tick code, rewritten for speed (issue 39), against the
plain formulas it replaced: Pinocchio's own calls one by one, and NumPy written out, on
seeded random inputs."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

from ridempc.estimation.state import BoardEstimate
from ridempc.robots import load_robot
from ridempc.wbc.constraints import ContactAccelerationConstraint, LinearConstraint
from ridempc.wbc.contacts import ContactSet, platform_rotation
from ridempc.wbc.in_flight import TorquesInFlight
from ridempc.wbc.model import WholeBodyModel
from ridempc.wbc.platforms import RollingPlatform

WORLD_ALIGNED = pin.ReferenceFrame.LOCAL_WORLD_ALIGNED
DT = 0.002  # the WBC's tick [s]


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


def _least_forces_numpy(
    in_flight: TorquesInFlight, recent: list[np.ndarray], foot_forces: np.ndarray
) -> np.ndarray:
    """The least site forces as first written, in NumPy (``in_flight``'s docstring)."""
    lined = in_flight.site_motor >= 0
    torques = np.array(recent)
    spread = torques.max(axis=0) - torques.min(axis=0)
    least = np.zeros(len(in_flight.site_motor))
    least[lined] = spread[in_flight.site_motor[lined]] / in_flight.site_lever[lined]
    half = 0.5 * np.maximum(foot_forces[in_flight.site_foot], 0.0)
    return np.minimum(least, half)


def test_least_forces_in_plain_floats_match_numpy() -> None:
    robot = load_robot("cassie")
    in_flight = TorquesInFlight(WholeBodyModel(robot), robot, DT)
    rng = np.random.default_rng(3)
    for tick in range(200):
        torque = 20.0 * rng.normal(size=len(robot.motors))
        in_flight.record(tick * DT, torque)
        recent = [np.array(tau) for t, tau in in_flight._torques if t <= tick * DT]
        feet = 150.0 * rng.normal(size=2)
        got = in_flight.least_forces((tick + 1) * DT, feet)
        if len(recent) < 2:
            assert got is None
            continue
        assert got is not None
        np.testing.assert_array_equal(got, _least_forces_numpy(in_flight, recent, feet))


def test_platform_rotation_and_response_match_their_formulas() -> None:
    """Pinocchio's ``rpyToMatrix`` is :math:`R_z R_y R_x`; the shoe's response in plain floats
    is :math:`a^0 = (c_4 \\theta / m_s) e_x`, :math:`K = -e_x e_x^\\top / m_s`."""
    platform = RollingPlatform(mass=2.7, drive=120.0, tread=0.09, height=0.11)
    rng = np.random.default_rng(5)
    for _ in range(100):
        roll, pitch, yaw = rng.uniform(-np.pi, np.pi, size=3)
        board = BoardEstimate(("foot",), rng.normal(size=3), yaw, pitch, roll, np.zeros(3), 0.1)
        c, s = np.cos([roll, pitch, yaw]), np.sin([roll, pitch, yaw])
        rx = np.array([[1, 0, 0], [0, c[0], -s[0]], [0, s[0], c[0]]])
        ry = np.array([[c[1], 0, s[1]], [0, 1, 0], [-s[1], 0, c[1]]])
        rz = np.array([[c[2], -s[2], 0], [s[2], c[2], 0], [0, 0, 1]])
        np.testing.assert_allclose(platform_rotation(board), rz @ ry @ rx, rtol=0, atol=1e-15)
        heading = np.array([c[2], s[2], 0.0])
        response = platform.response(board)
        np.testing.assert_allclose(response.drift, 120.0 * pitch / 2.7 * heading, atol=1e-14)
        np.testing.assert_allclose(
            response.coupling, -np.outer(heading, heading) / 2.7, rtol=0, atol=1e-15
        )


def test_contact_acceleration_rows_match_the_per_site_formula(model: WholeBodyModel) -> None:
    """Every site's rows by one product with the held directions :math:`E` equal the
    docstring's per site: :math:`E_s J_s`, :math:`-E_s K_{s\\cdot}` and
    :math:`E_s (a_s - \\dot J_s v)`."""
    layout = model.layout
    constraint = ContactAccelerationConstraint(layout, model.site_partner, model.line_basis)
    rng = np.random.default_rng(9)
    n = layout.n_sites
    for _ in range(10):
        q, v = _random_state(model, rng)
        terms = model.update(q, v)
        contacts = ContactSet(
            rng.random(n) < 0.7,
            rng.normal(size=(n, 3, 3)),
            rng.normal(size=(n, 3)),
            coupling=rng.normal(size=(n, 3, n, 3)),
        )
        block = LinearConstraint(
            np.zeros((constraint.rows, layout.size)),
            np.empty(constraint.rows),
            np.empty(constraint.rows),
        )
        constraint.fill_qp_constraint(block, terms, None, contacts)  # type: ignore[arg-type]
        row = 0
        order = [s for s in range(n) if model.site_partner[s] < 0]
        order += [s for s in range(n) if model.site_partner[s] >= 0]
        for s in order:
            held = np.eye(3)
            if model.site_partner[s] >= 0:
                held = model.line_basis[s] @ terms.site_rotation[s].T
            rows = slice(row, row + len(held))
            wanted = held @ (contacts.acceleration[s] - terms.sites.drift[s])
            coupling = contacts.coupling.reshape(n, 3, 3 * n)[s]
            np.testing.assert_allclose(
                block.matrix[rows, : layout.nv], held @ terms.sites.jacobian[s], atol=1e-12
            )
            np.testing.assert_allclose(
                block.matrix[rows, layout.force], -held @ coupling, atol=1e-12
            )
            bound = wanted if contacts.active[s] else np.full(len(held), -np.inf)
            np.testing.assert_allclose(block.lower[rows], bound, atol=1e-12)
            row += len(held)
        assert row == constraint.rows


def test_foot_points_are_the_mean_of_their_sites(model: WholeBodyModel) -> None:
    """Each foot's point, by one product with the feet's 0/1 sum, equals the sum of its
    sites' positions over their count (the former ``bincount`` per axis), bit for bit."""
    rng = np.random.default_rng(13)
    data = model.model.createData()
    feet = model.site_foot
    for _ in range(20):
        q, _ = _random_state(model, rng)
        pin.framesForwardKinematics(model.model, data, q)
        sites = np.array([data.oMf[f].translation for f in model.site_frames])
        count = np.bincount(feet, minlength=len(model.foot_names))[:, None]
        sums = [np.bincount(feet, sites[:, k], len(model.foot_names)) for k in range(3)]
        np.testing.assert_array_equal(model.foot_points(q), np.stack(sums, 1) / count)


def test_placed_foot_points_are_foot_points_bit_for_bit(model: WholeBodyModel) -> None:
    """The feet's points from a data whose joints ``centerOfMass`` placed (the swing
    targets' one pass over the joints) equal :meth:`WholeBodyModel.foot_points`' own pass,
    bit for bit."""
    rng = np.random.default_rng(14)
    data = model.model.createData()
    for _ in range(20):
        q, _ = _random_state(model, rng)
        pin.centerOfMass(model.model, data, q)
        np.testing.assert_array_equal(model.placed_foot_points(data), model.foot_points(q))
