"""Which frames and joints of each entity the ROS topics carry, read once per compiled model.

The tf tree of each entity is `tf_tree.entity_tree`'s (the URDF's tree, frames named by
`frames`). Its moving transforms are gathered into arrays for all entities at once (each side
a body and the frame's constant pose in it), its fixed ones computed here once. Mimic joints
(MuJoCo joint equalities, `y = y0 + a0 + a1 (x − x0)`) are kept exact in the recording: the
follower's position and speed are set from its leader's before any message is made, as
robot_state_publisher's mimic joints follow theirs. Element ids change at every recompile, so a
new layout is made whenever the world's model object changes (spawn, delete, reset).
"""

from __future__ import annotations

from dataclasses import dataclass

import mujoco
import numpy as np

from twin_cli.names import namespace
from twin_cli.record.frames import Pose, Sources, unique_odom_topics
from twin_cli.record.tf_tree import Edge, EntityTree, entity_tree, model_names, static_pose
from twin_cli.world.entities import EntityIndex, element_names
from twin_cli.world.velocity_motors import is_rotor

_FREE, _BALL = mujoco.mjtJoint.mjJNT_FREE, mujoco.mjtJoint.mjJNT_BALL
_IDENTITY_QUAT = np.array([1.0, 0.0, 0.0, 0.0])
TF_TOPIC = "/tf"  # the world's tf topic: a drive's transform is among its own


@dataclass(frozen=True)
class EntityLayout:
    """One entity's frames and joints in one compiled model.

    Attributes:
        name: entity name (the topic namespace).
        tree: its tf edges and frame names.
        joint_names: 1-DoF and ball joint names without the prefix (JointState.name).
        joint_ids: their joint ids.
        free_qpos, free_dof: the root free joint's qpos and dof addresses, or -1 (fixed base).
        description: URDF text for `/<entity>/robot_description`, or None.
        ball_joints: positions in `joint_ids` of ball joints (JointState: angle and speed).
        odom_topic: its odometry's topic (its drive's name for it, else `/<entity>/odom`).
        tf_topic: where its drive publishes the odometry's transform (gz-sim's drive systems'
            `/model/<entity>/tf`), or "" (none).
    """

    name: str
    tree: EntityTree
    joint_names: tuple[str, ...]
    joint_ids: np.ndarray
    free_qpos: int
    free_dof: int
    description: str | None
    ball_joints: tuple[int, ...] = ()
    odom_topic: str = ""
    tf_topic: str = ""

    @property
    def root_frame(self) -> str:
        """The frame of its root link (odometry's child frame)."""
        return self.tree.root_frame

    @property
    def odom_frame(self) -> str:
        """The frame its odometry is in: the diff drive's odometry frame, else the world."""
        return self.tree.odom_frame


@dataclass(frozen=True)
class MovingEdges:
    """The `/tf` transforms of all entities as arrays (m edges): frame names, the bodies they
    are on and each frame's pose in its body (positions m×3, quaternions w,x,y,z m×4)."""

    parents: tuple[str, ...]
    children: tuple[str, ...]
    parent_bodies: np.ndarray
    child_bodies: np.ndarray
    parent_pos: np.ndarray
    parent_quat: np.ndarray
    child_pos: np.ndarray
    child_quat: np.ndarray


@dataclass(frozen=True)
class Mimics:
    """Mimic joints (k): follower and leader qpos and dof addresses, y0, x0, a0, a1."""

    follower_qpos: np.ndarray
    follower_dof: np.ndarray
    leader_qpos: np.ndarray
    leader_dof: np.ndarray
    follower_ref: np.ndarray
    leader_ref: np.ndarray
    offset: np.ndarray
    multiplier: np.ndarray


@dataclass(frozen=True)
class Layout:
    """The layouts of the observed entities in `model`, their `/tf` and `/tf_static`
    transforms (parent, child, pose) and mimic joints."""

    model: mujoco.MjModel
    entities: tuple[EntityLayout, ...]
    moving: MovingEdges
    static: tuple[tuple[str, str, Pose], ...]
    mimics: Mimics


def make_layout(
    model: mujoco.MjModel, index: dict[str, EntityIndex], sources: dict[str, Sources]
) -> Layout:
    """The layout of entities `index` (name → EntityIndex) in `model`, frames named from
    `sources` (name → Sources)."""
    names = model_names(model)
    odom = unique_odom_topics(
        {n: sources[n].odom_topic for n, ix in index.items() if ix.free_qpos >= 0}
    )
    entities = tuple(
        entity_layout(model, name, ix, entity_tree(model, names, name, ix, sources[name]),
                      sources[name].description, odom.get(name, ""),
                      _drive_tf(sources[name].tf_topic, ix))
        for name, ix in index.items()
    )  # fmt: skip
    edges = [edge for e in entities for edge in e.tree.edges]
    return Layout(
        model,
        entities,
        _moving([e for e in edges if e.moving]),
        _static(model, [e for e in edges if not e.moving]),
        _mimics(model, index),
    )


def _drive_tf(topic: str, ix: EntityIndex) -> str:
    """A floating base's drive tf topic; "" for none, or for `/tf` (whose transforms it has)."""
    return topic if ix.free_qpos >= 0 and topic != TF_TOPIC else ""


def entity_layout(
    model: mujoco.MjModel,
    name: str,
    ix: EntityIndex,
    tree: EntityTree,
    description: str | None,
    odom_topic: str = "",
    tf_topic: str = "",
) -> EntityLayout:
    """One entity's layout (see EntityLayout)."""
    moving = [j for j in ix.joints if model.jnt_type[j] != _FREE]
    names = element_names(model, model.name_jntadr[moving])
    kept = [k for k, n in enumerate(names) if not is_rotor(n)]  # velocity motors' rotors
    joints = np.array([moving[k] for k in kept], dtype=np.int64)
    names = [names[k] for k in kept]
    free = [j for j in ix.joints if model.jnt_type[j] == _FREE]
    return EntityLayout(
        name=name,
        tree=tree,
        joint_names=tuple(n.removeprefix(f"{name}/") for n in names),
        joint_ids=joints,
        free_qpos=ix.free_qpos,
        free_dof=int(model.jnt_dofadr[free[0]]) if free else -1,
        description=description,
        ball_joints=tuple(k for k, j in enumerate(joints) if is_ball(model, j)),
        odom_topic=odom_topic or f"{namespace(name)}/odom",
        tf_topic=tf_topic,
    )


def _moving(edges: list[Edge]) -> MovingEdges:
    def poses(side: str) -> tuple[np.ndarray, np.ndarray]:
        anchors = [getattr(e, side) for e in edges]
        pos = np.array([a.pose[0] for a in anchors], dtype=float).reshape(-1, 3)
        quat = np.array([a.pose[1] for a in anchors], dtype=float).reshape(-1, 4)
        return pos, quat

    parent_pos, parent_quat = poses("parent_anchor")
    child_pos, child_quat = poses("child_anchor")
    return MovingEdges(
        tuple(e.parent for e in edges),
        tuple(e.child for e in edges),
        np.array([e.parent_anchor.body for e in edges], dtype=np.int64),
        np.array([e.child_anchor.body for e in edges], dtype=np.int64),
        parent_pos, parent_quat, child_pos, child_quat,
    )  # fmt: skip


def _static(model: mujoco.MjModel, edges: list[Edge]) -> tuple[tuple[str, str, Pose], ...]:
    """Fixed transforms, from the body poses of the model's reference posture."""
    if not edges:
        return ()
    data = mujoco.MjData(model)
    mujoco.mj_kinematics(model, data)
    return tuple((e.parent, e.child, static_pose(data.xpos, data.xquat, e)) for e in edges)


def _mimics(model: mujoco.MjModel, index: dict[str, EntityIndex]) -> Mimics:
    """The joint equalities of the entities that are linear (a mimic's offset and multiplier)."""
    rows = []
    for ix in index.values():
        for eq in ix.equalities.tolist():
            a, b, coef = int(model.eq_obj1id[eq]), int(model.eq_obj2id[eq]), model.eq_data[eq]
            linear = not np.any(coef[2:5])
            if model.eq_type[eq] == mujoco.mjtEq.mjEQ_JOINT and b >= 0 and linear:
                rows.append((a, b, float(coef[0]), float(coef[1])))
    followers = np.array([r[0] for r in rows], dtype=np.int64)
    leaders = np.array([r[1] for r in rows], dtype=np.int64)
    return Mimics(
        model.jnt_qposadr[followers], model.jnt_dofadr[followers],
        model.jnt_qposadr[leaders], model.jnt_dofadr[leaders],
        model.qpos0[model.jnt_qposadr[followers]], model.qpos0[model.jnt_qposadr[leaders]],
        np.array([r[2] for r in rows]), np.array([r[3] for r in rows]),
    )  # fmt: skip


def is_ball(model: mujoco.MjModel, joint: int) -> bool:
    """Whether joint `joint` is a ball joint (its JointState is an angle and a speed)."""
    return model.jnt_type[joint] == _BALL
