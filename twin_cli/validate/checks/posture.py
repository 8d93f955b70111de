"""The robot's start posture as every check sees it: home keyframe, then `-J` / `[robot] joints`.

A world spawns a robot in its `home` keyframe (qpos0 without one) and writes the requested joint
positions over it, mimic followers following their leaders (`twin_cli.world.posture`). Model
checks that judge a posture (overlaps at spawn, the gravity load on each joint) start from the
same one, so `twin validate -J ...` reaches them as it reaches the physics scenarios.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from twin_cli.validate.checks.base import RobotUnderTest
from twin_cli.validate.scenario import Scenario

if TYPE_CHECKING:
    import mujoco

HOME_KEY = "home"  # the converter's keyframe of the robot's initial posture


def start_data(robot: RobotUnderTest, scenario: Scenario) -> mujoco.MjData:
    """MjData of the robot compiled alone in the scenario's start posture, forward computed.

    Raises:
        PartNotFoundError, InvalidRequestError: a start joint is unknown or out of range (the
            runner checks every scenario's joints before any check runs).
    """
    import mujoco
    import numpy as np

    from twin_cli.world.posture import joint_targets

    model = robot.model
    data = mujoco.MjData(model)
    key = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_KEY, HOME_KEY)
    if key >= 0:
        mujoco.mj_resetDataKeyframe(model, data, key)
    joints = dict(scenario.robot.joints)
    targets = joint_targets(model, np.arange(model.njnt), "", joints, robot.name)
    for address, value in targets.items():
        data.qpos[address] = value
    mujoco.mj_forward(model, data)
    return data
