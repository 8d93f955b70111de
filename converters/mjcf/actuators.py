"""Actuated joints (transmissions / ros2_control, else all) → motors; mimic → joint equalities."""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from converters.description import Joint, RobotDescription
from converters.errors import URDFStructureError
from converters.report import Report

if TYPE_CHECKING:
    import mujoco

ACTUATABLE = ("revolute", "continuous", "prismatic")


def actuated_joints(robot: RobotDescription, report: Report) -> list[Joint]:
    """The joints that get a motor, and a report line saying how they were chosen.

    Joints named by `<transmission>` or `<ros2_control>` when the file has any; otherwise every
    revolute, continuous or prismatic joint that is not a mimic follower.
    """
    joints = {j.name: j for j in robot.joints}
    named = [n for n in robot.actuated if n in joints]
    if named:
        source = "<transmission>/<ros2_control>"
        chosen = [joints[n] for n in named]
    else:
        source = "all movable non-mimic joints (no <transmission> or <ros2_control>)"
        chosen = list(joints.values())
    chosen = [j for j in chosen if j.kind in ACTUATABLE and j.mimic is None]
    motors = chosen if named else [j for j in chosen if _effort(j) > 0]
    report.mapped("actuators", f"{len(motors)} motor(s) on joints chosen from {source}")
    return chosen


def _effort(joint: Joint) -> float:
    """The joint's effort limit [N or N·m], 0 when absent."""
    return joint.limit.effort if joint.limit and joint.limit.effort else 0.0


def add_motors(
    spec: mujoco.MjSpec, joints: list[Joint], report: Report, tagged: frozenset[str] = frozenset()
) -> None:
    """One motor per joint, named after it, with ctrlrange = forcerange = ±effort [N or N·m].

    A joint without an effort limit gets an unlimited motor when a `<ros2_control>` or
    `<transmission>` tag names it (`tagged`): Gazebo drives such joints (diff-drive wheels in
    gz_ros2_control's demos, husky) with no force bound. Untagged ones get none.
    """
    import mujoco

    limited = [j.name for j in joints if j.limit is not None and (j.limit.velocity or 0) > 0]
    if limited:
        report.mapped(
            "joint velocity limits",
            f"<limit velocity> of {len(limited)} actuated joint(s) kept for the world's commands "
            "(Gazebo's rule in effort mode; position and velocity servos stay below it)",
        )
    for joint in joints:
        effort = _effort(joint)
        if effort <= 0 and joint.name not in tagged:
            if joint.kind == "prismatic":  # revolute ones stay passive (mjcf.passive_motors)
                report.warn(f"joint '{joint.name}'", "no positive effort limit; no motor added")
            continue
        actuator = spec.add_actuator(name=joint.name, target=joint.name)
        actuator.trntype = mujoco.mjtTrn.mjTRN_JOINT
        actuator.set_to_motor()
        if effort <= 0:
            report.approximated(
                f"joint '{joint.name}'",
                "no <limit effort>: a motor without a force bound, as Gazebo drives a joint "
                "its control tag names; its velocity commands run Gazebo's joint motor, unbounded",
            )
            continue
        actuator.ctrllimited = mujoco.mjtLimited.mjLIMITED_TRUE
        actuator.ctrlrange = np.array([-effort, effort])
        actuator.forcelimited = mujoco.mjtLimited.mjLIMITED_TRUE
        actuator.forcerange = np.array([-effort, effort])


def add_mimics(spec: mujoco.MjSpec, robot: RobotDescription, report: Report) -> None:
    """Each `<mimic>`: follower = offset + multiplier · leader, as a joint equality.

    MuJoCo's joint equality constrains `joint1 = polycoef[0] + polycoef[1]·joint2 + …`
    (positions relative to qpos0, which is 0 for hinges and slides), so the follower is joint1.
    """
    import mujoco

    movable = {j.name for j in robot.joints if j.kind in ACTUATABLE}
    for joint in robot.joints:
        mimic = joint.mimic
        if mimic is None:
            continue
        if mimic.joint not in movable or joint.kind not in ACTUATABLE:
            raise URDFStructureError(
                robot.source,
                f"joint '{joint.name}' <mimic joint='{mimic.joint}'>",
                "a mimic needs a revolute, continuous or prismatic follower and leader",
                f"name one of: {', '.join(sorted(movable)) or 'none'}",
            )
        multiplier, offset = mimic.multiplier, mimic.offset
        equality = spec.add_equality(name=f"mimic_{joint.name}")
        equality.type = mujoco.mjtEq.mjEQ_JOINT
        equality.objtype = mujoco.mjtObj.mjOBJ_JOINT
        equality.name1 = joint.name
        equality.name2 = mimic.joint
        equality.data[:5] = [offset, multiplier, 0.0, 0.0, 0.0]
        report.mapped(
            f"joint '{joint.name}' <mimic>",
            f"= {offset:g} + {multiplier:g} · {mimic.joint} (joint equality)",
        )
