"""Model check on motor strength: each motor can hold its joint against gravity in its range.

Static load (the robot held, nothing moving): at qvel = qacc = 0 a motor holding a posture must
give the joint's generalized gravity force less what passive forces already give (springs,
Gazebo's turnGravityOff as MuJoCo gravcomp): qfrc_bias − qfrc_passive after `mj_forward`. A
floating robot is held by its base (its free joint is not judged), so each joint carries the
links beyond it and no more. Each motor's hinge or slide is swept over SAMPLES postures strictly
inside its range, the other joints at the start posture (`-J` included): at a stop, the stop and
not the motor would hold it. A motor whose effort limit is below the load at every sample cannot
hold its joint anywhere off its stops, so the robot sags onto them whatever it is commanded: it
fails, naming the joint, the load and the effort that holds it everywhere. One that holds only
part of its range warns (a robot may be built to rest some postures on its stops).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from twin_cli.validate.checks.base import (
    CheckResult,
    RobotUnderTest,
    Status,
    not_applicable,
    result,
)
from twin_cli.validate.checks.model_joints import HINGE, SLIDE, has_actuator, joint_effort
from twin_cli.validate.checks.posture import start_data
from twin_cli.validate.scenario import Scenario

if TYPE_CHECKING:
    import mujoco

SAMPLES = 17  # postures per joint, evenly inside its range (ends excluded)
CONTINUOUS = (-math.pi, math.pi)  # [rad] the sweep of a hinge without limits
TINY_LOAD = 1e-12  # [N m] or [N] a load this small is none (a wheel on its axle)


@dataclass(frozen=True)
class Load:
    """A motor's joint, its effort limit and the gravity load [N m] or [N] over its range."""

    joint: str
    link: str
    unit: str
    effort: float
    smallest: float
    largest: float


def _sweep(model: mujoco.MjModel, joint: int) -> np.ndarray:
    """SAMPLES positions [rad] or [m] strictly inside the joint's range (one for a slide
    without range: a slide's gravity load does not depend on where it is)."""
    if model.jnt_limited[joint]:
        lo, hi = (float(v) for v in model.jnt_range[joint])
    elif int(model.jnt_type[joint]) == HINGE:
        lo, hi = CONTINUOUS
    else:
        return np.array([np.nan])
    return lo + (np.arange(SAMPLES) + 0.5) / SAMPLES * (hi - lo)


def joint_load(model: mujoco.MjModel, start: mujoco.MjData, joint: int) -> np.ndarray:
    """|qfrc_bias − qfrc_passive| of the joint [N m] or [N] at each posture of its sweep,
    everything still and the other joints where `start` has them."""
    import mujoco

    data = mujoco.MjData(model)
    address, dof = int(model.jnt_qposadr[joint]), int(model.jnt_dofadr[joint])
    loads = []
    for q in _sweep(model, joint):
        data.qpos[:] = start.qpos
        if not np.isnan(q):
            data.qpos[address] = q
        mujoco.mj_forward(model, data)
        loads.append(abs(float(data.qfrc_bias[dof] - data.qfrc_passive[dof])))
    return np.array(loads)


def motor_loads(robot: RobotUnderTest, start: mujoco.MjData) -> list[Load]:
    """The gravity load of every motor's hinge or slide that has a positive effort limit (a
    zero or missing one is `joint_definitions`' finding)."""
    model = robot.model
    out = []
    for j in range(model.njnt):
        kind = int(model.jnt_type[j])
        effort = joint_effort(model, j)
        if kind not in (HINGE, SLIDE) or not has_actuator(model, j) or not effort:
            continue
        loads = joint_load(model, start, j)
        link = robot.link_of_body(model.body(int(model.jnt_bodyid[j])).name)
        unit = "N m" if kind == HINGE else "N"
        out.append(
            Load(model.joint(j).name, link, unit, effort, float(loads.min()), float(loads.max()))
        )
    return out


def check_gravity_hold(
    robot: RobotUnderTest, scenario: Scenario, th: dict[str, float]
) -> CheckResult:
    """Each motor's effort limit holds its joint against gravity somewhere off its stops."""
    loads = motor_loads(robot, start_data(robot, scenario))
    if not loads:
        reason = "the robot has no motor with a positive effort limit on a hinge or slide"
        return not_applicable("gravity_hold", "model", "no motor", reason)
    margin = th["min_effort_ratio"]
    hints = [_weak(load, margin) for load in loads if load.effort < margin * load.smallest]
    details = [
        f"joint '{load.joint}': effort {load.effort:.3g} {load.unit} holds only part of its "
        f"range (gravity load {load.smallest:.3g}–{load.largest:.3g} {load.unit})"
        for load in loads
        if margin * load.smallest <= load.effort < load.largest
    ]
    worst = min(load.effort / max(load.smallest, TINY_LOAD) for load in loads)
    status = Status.FAIL if hints else (Status.WARN if details else Status.PASS)
    return result(
        "gravity_hold",
        "model",
        status,
        f"{len(loads)} motor(s); weakest effort / smallest gravity load = {min(worst, 1e6):.3g}",
        f"≥ {margin:g} (holds somewhere off its stops)",
        hints=hints,
        details=details,
        value=min(worst, 1e6),
    )


def _weak(load: Load, margin: float) -> str:
    return (
        f"joint '{load.joint}': effort limit {load.effort:.3g} {load.unit} is below the gravity "
        f"load over its whole range ({load.smallest:.3g}–{load.largest:.3g} {load.unit}, the "
        f"robot held still): its motor cannot hold link '{load.link}' anywhere off its stops; "
        f"raise <limit effort> to at least {margin * load.largest:.3g} {load.unit} to hold it "
        "everywhere, or lighten what it carries"
    )
