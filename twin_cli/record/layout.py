"""Which frames and joints of each entity the ROS topics carry, read once per compiled model.

Frames are named as a namespaced robot_state_publisher with `frame_prefix=<entity>/` names them:
the world's element names ("<entity>/<link>"), which are the URDF link names with that prefix.
A body's transform to its parent moves (goes on `/tf`) when the body has a joint, and is fixed
(`/tf_static`) otherwise; the world → root transform always goes on `/tf` (gazebo_ros publishes
model poses live). Sites are the converter's lumped links and SDF frames (kept so they can still
be named): fixed to their body, so they go on `/tf_static`. Element ids change at every
recompile, so a new layout is made whenever the world's model object changes (spawn, delete,
reset).
"""

from __future__ import annotations

from dataclasses import dataclass

import mujoco
import numpy as np

from twin_cli.world.entities import MODEL_SITE, EntityIndex, element_names

WORLD_FRAME = "world"  # gazebo_ros and Gazebo's own frame name for the world
_FREE, _BALL = mujoco.mjtJoint.mjJNT_FREE, mujoco.mjtJoint.mjJNT_BALL


@dataclass(frozen=True)
class EntityLayout:
    """One entity's frames and joints in one compiled model.

    Attributes:
        name: entity name (the topic namespace).
        root_frame: frame id of its root body.
        moving: body ids whose transform to their parent goes on `/tf` (the root first).
        moving_parents: the parent body id of each (0: the world).
        fixed: body ids fixed to a parent body of the entity (no joint): `/tf_static`.
        sites: site ids (lumped links, SDF frames) on `/tf_static`.
        joint_names: 1-DoF and ball joint names without the prefix (JointState.name).
        joint_ids: their joint ids.
        free_qpos, free_dof: the root free joint's qpos and dof addresses, or -1 (fixed base).
        description: URDF text for `/<entity>/robot_description`, or None.
        ball_joints: positions in `joint_ids` of ball joints (JointState: angle and speed).
    """

    name: str
    root_frame: str
    moving: np.ndarray
    moving_parents: np.ndarray
    fixed: np.ndarray
    sites: np.ndarray
    joint_names: tuple[str, ...]
    joint_ids: np.ndarray
    free_qpos: int
    free_dof: int
    description: str | None
    ball_joints: tuple[int, ...] = ()


@dataclass(frozen=True)
class Layout:
    """The layouts of the observed entities in `model`, and every body's frame id."""

    model: mujoco.MjModel
    entities: tuple[EntityLayout, ...]
    body_frames: tuple[str, ...]
    site_frames: tuple[str, ...]


def make_layout(
    model: mujoco.MjModel, index: dict[str, EntityIndex], descriptions: dict[str, str | None]
) -> Layout:
    """The layout of entities `index` (name → EntityIndex) in `model`."""
    bodies = element_names(model, model.name_bodyadr)
    bodies[0] = WORLD_FRAME
    sites = element_names(model, model.name_siteadr)
    entities = tuple(
        entity_layout(model, name, ix, bodies, descriptions.get(name)) for name, ix in index.items()
    )
    return Layout(model, entities, tuple(bodies), tuple(sites))


def entity_layout(
    model: mujoco.MjModel, name: str, ix: EntityIndex, frames: list[str], description: str | None
) -> EntityLayout:
    """One entity's layout (see EntityLayout)."""
    parents = model.body_parentid[ix.bodies]
    has_joint = model.body_jntnum[ix.bodies] > 0
    moving = (parents == 0) | has_joint
    site_ids = np.flatnonzero(np.isin(model.site_bodyid, ix.bodies))
    site_ids = np.array(
        [s for s in site_ids if model.site(s).name != f"{name}/{MODEL_SITE}"], dtype=np.int64
    )
    joints = np.array([j for j in ix.joints if model.jnt_type[j] != _FREE], dtype=np.int64)
    names = element_names(model, model.name_jntadr[joints])
    free = [j for j in ix.joints if model.jnt_type[j] == _FREE]
    return EntityLayout(
        name=name,
        root_frame=frames[ix.root] if ix.root >= 0 else WORLD_FRAME,
        moving=ix.bodies[moving],
        moving_parents=parents[moving],
        fixed=ix.bodies[~moving],
        sites=site_ids,
        joint_names=tuple(n.removeprefix(f"{name}/") for n in names),
        joint_ids=joints,
        free_qpos=ix.free_qpos,
        free_dof=int(model.jnt_dofadr[free[0]]) if free else -1,
        description=description,
        ball_joints=tuple(k for k, j in enumerate(joints) if is_ball(model, j)),
    )


def is_ball(model: mujoco.MjModel, joint: int) -> bool:
    """Whether joint `joint` is a ball joint (its JointState is an angle and a speed)."""
    return model.jnt_type[joint] == _BALL
