"""The CasADi kinematics generated from Pinocchio agree with Pinocchio itself."""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from ridempc.robots.pinocchio_model import build_pinocchio_robot
from ridempc.trajopt.kinematics import frame_kinematics


def test_casadi_frames_match_pinocchio(robot) -> None:
    pinned = build_pinocchio_robot(robot)
    model = pinned.model
    data = model.createData()
    frames = [*robot.params.contact_sites, robot.params.imu_site]
    kinematics = frame_kinematics(model, frames)
    pin.seed(7)  # randomConfiguration draws from pinocchio's own generator
    lower = np.where(np.isfinite(model.lowerPositionLimit), model.lowerPositionLimit, -1.0)
    upper = np.where(np.isfinite(model.upperPositionLimit), model.upperPositionLimit, 1.0)
    for _ in range(10):
        q = pin.randomConfiguration(model, np.maximum(lower, -3.0), np.minimum(upper, 3.0))
        pin.framesForwardKinematics(model, data, q)
        values = kinematics(q)
        for k, name in enumerate(frames):
            placement = data.oMf[model.getFrameId(name)]
            assert np.allclose(np.asarray(values[2 * k]).ravel(), placement.translation, atol=1e-10)
            assert np.allclose(np.asarray(values[2 * k + 1]), placement.rotation, atol=1e-10)
