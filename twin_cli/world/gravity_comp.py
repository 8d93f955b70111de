"""A fixed-base robot's position servos hold its weight through MuJoCo's own gravity compensation.

A position servo on a fixed arm carries the weight of the links beyond its joint. MuJoCo computes
that load itself: `gravcomp` on a body applies the force that cancels its weight, and
`actuatorgravcomp` on a joint sends the joint's share through the joint's actuator force, where
the joint's `actuatorfrcrange` (its effort limit) bounds servo and compensation together. So a
held posture does not sag by load/kp, and a joint asked for more than its effort gives exactly
its effort.

MuJoCo computes compensation only in a model compiled with a compensated body, so every body of a
fixed-base robot is compiled with OFF (a negligible share) and a command switches bodies on the
model (`switch`): a body is ON while every joint between it and the world is actuated and holds
a position command (a joint's own servo holds one from load, `native_servos`). An arm with an
effort command or a passive joint on the way falls as it does in Gazebo; a velocity servo's
integral carries its load itself, and a joint whose tags give its position servo a PID (which
Gazebo runs alone) carries its load through that PID, as there: it sags by load/kp until the
PID's integral, when it has one, takes up to its bound of the load. A body the
robot's own tags compensate (Gazebo's gravity off: 1) keeps its value.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import TYPE_CHECKING

import mujoco
import numpy as np

from converters.control_text import control_records
from converters.mjcf.export_servos import tag_pid

if TYPE_CHECKING:
    from twin_cli.world.actuation import JointCommand

ON = 1.0 - 2.0**-30
"""gravcomp of a body whose weight the servos hold (a part in 1e9 short of 1: a marker)."""
OFF = 2.0**-30
"""gravcomp of a body whose weight they do not hold (nonzero, so MuJoCo computes gravcomp)."""
_FREE = mujoco.mjtJoint.mjJNT_FREE
_JOINT = mujoco.mjtTrn.mjTRN_JOINT


def prepare(spec: mujoco.MjSpec) -> None:
    """Readies a robot spec without a free joint (a fixed base) for compensation: its bodies
    compiled OFF, its actuated joints routing compensation through their actuator force within
    their motors' effort limit (`actuatorfrcrange`). A spec with a free joint is left as it is."""
    if any(joint.type == _FREE for joint in spec.joints):
        return
    for body in spec.bodies:
        if body is not spec.worldbody and body.gravcomp == 0.0:
            body.gravcomp = OFF
    pids = _tag_pid_joints(spec)
    for actuator in spec.actuators:
        if actuator.trntype != _JOINT:
            continue
        joint = spec.joint(actuator.target)
        if joint is None or joint.name in pids or actuator.plugin.active:
            continue  # a PID (a tag's, or a plugin's such as `mujoco.pid`) holds its load alone
        joint.actgravcomp = True
        low, high = _force_range(actuator)
        if math.isfinite(low) and math.isfinite(high):
            joint.actfrclimited = mujoco.mjtLimited.mjLIMITED_TRUE
            joint.actfrcrange = np.array([low, high])


def _tag_pid_joints(spec: mujoco.MjSpec) -> set[str]:
    """The joints whose tags give their position servo a PID (a gz-sim joint controller,
    ros2_control's `position_pid`, a trajectory controller): Gazebo runs that PID alone, so the
    joint carries its load through it and sags by load/kp, as it does there."""
    return {
        joint
        for joint, record in control_records(spec).items()
        if isinstance(record, dict) and tag_pid(record.get("pid", {}), "position") is not None
    }


def _force_range(actuator: mujoco.MjsActuator) -> tuple[float, float]:
    """The actuator's force range at its joint [N m or N]: its `forcerange`, and for a plain
    motor its `ctrlrange` too (the converter's effort limit, or a PID's asymmetric output range;
    an MJCF position servo's ctrlrange is a position range)."""
    gear = float(actuator.gear[0]) or 1.0
    low, high = -math.inf, math.inf
    motor = actuator.biastype == mujoco.mjtBias.mjBIAS_NONE and actuator.dyntype in (
        mujoco.mjtDyn.mjDYN_NONE,
        mujoco.mjtDyn.mjDYN_INTEGRATOR,  # `servos.give_reference` ran first: a motor still
    )
    ranges = []
    if motor and actuator.ctrllimited == mujoco.mjtLimited.mjLIMITED_TRUE:
        ranges.append(actuator.ctrlrange)
    if actuator.forcelimited == mujoco.mjtLimited.mjLIMITED_TRUE:
        ranges.append(actuator.forcerange)
    for bounds in ranges:
        ends = sorted(float(v) * gear for v in bounds)
        low, high = max(low, ends[0]), min(high, ends[1])
    return low, high


def switch(model: mujoco.MjModel, commands: Mapping[str, JointCommand]) -> None:
    """Turns each prepared body's compensation ON or OFF for `commands` (see module doc)."""
    gravcomp = model.body_gravcomp
    bodies = np.flatnonzero((gravcomp == ON) | (gravcomp == OFF))
    if not len(bodies):
        return
    held = set()
    for key, cmd in commands.items():
        a = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_ACTUATOR, key)
        if a >= 0 and cmd.mode == "position" and model.actuator_trntype[a] == _JOINT:
            j = int(model.actuator_trnid[a, 0])
            if model.jnt_actgravcomp[j]:  # not a joint a Gazebo PID holds (`prepare`)
                held.add(j)
    for b in bodies:
        gravcomp[b] = ON if _chain_held(model, int(b), held) else OFF


def _chain_held(model: mujoco.MjModel, body: int, held: set[int]) -> bool:
    """Whether every joint from `body` down to the world is in `held`."""
    while body > 0:
        start = int(model.body_jntadr[body])
        if any(j not in held for j in range(start, start + int(model.body_jntnum[body]))):
            return False
        body = int(model.body_parentid[body])
    return True
