"""Read-only views of an entity in a compiled world: root pose, joint states, link poses."""

from __future__ import annotations

import math
from dataclasses import dataclass

import mujoco
import numpy as np

from twin_cli.world import velocity_motors
from twin_cli.world.entities import EntityIndex, element_names
from twin_cli.world.pose import Pose, quat4, quat_multiply, rotate, vec3

_FREE, _BALL = mujoco.mjtJoint.mjJNT_FREE, mujoco.mjtJoint.mjJNT_BALL


@dataclass(frozen=True)
class JointState:
    """One joint of an entity.

    Attributes:
        name: joint name without the entity prefix.
        position: [rad] or [m] (ball joints: rotation angle [rad]).
        velocity: [rad/s] or [m/s] (ball joints: angular speed [rad/s]).
        effort: actuator force on the joint [N m] or [N], from the last step.
    """

    name: str
    position: float
    velocity: float
    effort: float


def root_pose(model: mujoco.MjModel, data: mujoco.MjData, index: EntityIndex, spawn: Pose) -> Pose:
    """The entity's pose now: its model frame where it has one (SDF), else its root's pose.

    The root's pose is its free joint's qpos, else its fixed root body's pose.
    """
    if index.model_site >= 0 and (index.free_qpos < 0 or model.site_bodyid[index.model_site] == 0):
        # A fixed model, or one of several unjoined links (each floats; the site marking the
        # model frame is on the world): the model frame stays where its attach frame was put.
        return spawn
    if index.free_qpos >= 0:
        q = data.qpos[index.free_qpos : index.free_qpos + 7]
        root = Pose.from_quat(q[0], q[1], q[2], q[3:7])
        return root if index.model_site < 0 else model_from_root(model, index, root)
    if index.root >= 0:
        pos, quat = model.body_pos[index.root], model.body_quat[index.root]
        return Pose.from_quat(pos[0], pos[1], pos[2], quat)
    return spawn


Twist = tuple[tuple[float, float, float], tuple[float, float, float]]
"""(linear [m/s], angular [rad/s]), both in the world frame."""


def root_twist(model: mujoco.MjModel, data: mujoco.MjData, index: EntityIndex) -> Twist:
    """The velocity of a free-floating entity's root origin, in the world frame, from its free
    joint's qvel (so it is current after a set, before any step); zero for a fixed entity."""
    if index.free_qpos < 0 or index.root < 0:
        return (0.0, 0.0, 0.0), (0.0, 0.0, 0.0)
    dof = int(model.jnt_dofadr[model.body_jntadr[index.root]])
    v = data.qvel[dof : dof + 6]
    angular = np.zeros(3)  # a free joint's angular velocity is in the body's frame
    mujoco.mju_rotVecQuat(angular, v[3:6], data.qpos[index.free_qpos + 3 : index.free_qpos + 7])
    return (float(v[0]), float(v[1]), float(v[2])), (
        float(angular[0]), float(angular[1]), float(angular[2])
    )  # fmt: skip


def joint_states(
    model: mujoco.MjModel, data: mujoco.MjData, index: EntityIndex, prefix: str
) -> list[JointState]:
    """States of the entity's joints other than its free joint and velocity motors' rotors, in
    model order; a joint's effort is its motor's (`velocity_motors.joint_efforts`)."""
    names = element_names(model, model.name_jntadr[index.joints])
    states = []
    efforts = velocity_motors.joint_efforts(model, data)
    for j, name in zip(index.joints, names, strict=True):
        kind, qa, da = model.jnt_type[j], model.jnt_qposadr[j], model.jnt_dofadr[j]
        if kind == _FREE or velocity_motors.is_rotor(name):
            continue
        if kind == _BALL:
            angle = 2.0 * math.acos(min(1.0, abs(float(data.qpos[qa]))))
            speed = float(np.linalg.norm(data.qvel[da : da + 3]))
            states.append(JointState(name.removeprefix(prefix), angle, speed, 0.0))
            continue
        effort = float(efforts[da])
        states.append(
            JointState(
                name.removeprefix(prefix), float(data.qpos[qa]), float(data.qvel[da]), effort
            )
        )
    return states


def link_poses(
    model: mujoco.MjModel, data: mujoco.MjData, index: EntityIndex, prefix: str
) -> dict[str, Pose]:
    """World poses of the entity's bodies (velocity motors' rotors excluded), computed on
    scratch data (the live data is untouched)."""
    scratch = mujoco.MjData(model)
    scratch.qpos[:] = data.qpos
    scratch.mocap_pos[:] = data.mocap_pos
    scratch.mocap_quat[:] = data.mocap_quat
    mujoco.mj_kinematics(model, scratch)
    names = element_names(model, model.name_bodyadr[index.bodies])
    return {
        name.removeprefix(prefix): Pose.at(scratch.xpos[b], scratch.xquat[b])
        for b, name in zip(index.bodies, names, strict=True)
        if not velocity_motors.is_rotor(name)
    }


def joint_names(model: mujoco.MjModel, index: EntityIndex, prefix: str) -> list[str]:
    """The entity's joint names without prefix (free joint and rotors excluded)."""
    names = element_names(model, model.name_jntadr[index.joints])
    return [
        n.removeprefix(prefix)
        for j, n in zip(index.joints, names, strict=True)
        if model.jnt_type[j] != _FREE and not velocity_motors.is_rotor(n)
    ]


def model_from_root(model: mujoco.MjModel, index: EntityIndex, root: Pose) -> Pose:
    """The model frame's pose given the root body's: root ∘ (the site's pose in the root)."""
    site_pos = vec3(model.site_pos[index.model_site])
    site_quat = quat4(model.site_quat[index.model_site])
    q_root = root.quat()
    offset = rotate(q_root, site_pos)
    position = [p + o for p, o in zip(root.position(), offset, strict=True)]
    return Pose.at(position, quat_multiply(q_root, site_quat))


def root_from_model(model: mujoco.MjModel, index: EntityIndex, pose: Pose) -> Pose:
    """The root body's pose that puts the model frame at `pose` (inverse of model_from_root)."""
    w, x, y, z = (float(v) for v in model.site_quat[index.model_site])
    q_root = quat_multiply(pose.quat(), (w, -x, -y, -z))
    offset = rotate(q_root, vec3(model.site_pos[index.model_site]))
    position = [p - o for p, o in zip(pose.position(), offset, strict=True)]
    return Pose.at(position, q_root)
