"""One live entity as `gz model -m NAME` shows it (`twin model`): links, frames, joints, drives,
sensors and topics, with world poses.

Frames are the recording's tf frames (`twin_cli.record.tf_tree`: every URDF link, lumped ones
included, the odometry frame of a mobile base, sensors' own frames), so a pose shown here is
the one `/tf` composes to. Under the world's lock only copies are taken (qpos, mocap poses,
the entity's records); the kinematics run afterwards on scratch data of the same model, as
`World.link_poses` does.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import mujoco
import numpy as np

from twin_cli.live.catalogue import LiveTopic, live_topics
from twin_cli.record.frames import WORLD_FRAME, prefix_template, sources_of
from twin_cli.record.tf_tree import Anchor, EntityTree, compose, entity_tree, model_names
from twin_cli.sensors import describe_sensors
from twin_cli.world.entities import element_names
from twin_cli.world.observers import world_view
from twin_cli.world.pose import Pose

if TYPE_CHECKING:
    from twin_cli.world.engine import World

JOINT_TYPES = {0: "free", 1: "ball", 2: "slide", 3: "hinge"}  # mjtJoint


def describe(world: World, name: str) -> dict[str, Any]:
    """The entity `name` now (see module docstring), JSON-ready; poses are in the world frame.

    Raises:
        EntityNotFoundError: no such entity (the message lists those that exist).
    """
    with world.lock:  # copies only
        record = world.entity(name)
        view = world_view(world)
        sources = sources_of(world, name, prefix_template(), None)
        data = view.data
        qpos, mocap_pos, mocap_quat = (
            data.qpos.copy(),
            data.mocap_pos.copy(),
            data.mocap_quat.copy(),
        )
        time = float(data.time)
        pose = world.get_pose(name).to_dict()
        states = world.joint_states(name)
        commands = world.joint_commands(name)
    model, ix = view.model, view.index[name]
    xpos, xquat = _body_poses(model, qpos, mocap_pos, mocap_quat)
    tree = entity_tree(model, model_names(model), name, ix, sources)
    frames = _frames(tree, xpos, xquat)
    topics = [t for t in live_topics(world) if t.entity == name]
    return {
        "name": name,
        "source": record.source,
        "time": time,
        "pose": pose,
        "links": [
            {"name": link, "frame": frame, **frames[frame]}
            for link, frame in tree.links.items()
            if frame in frames
        ],
        "frames": [{"name": f, **entry} for f, entry in frames.items()],
        "joints": _joints(model, ix.joints, name, states, commands),
        "drives": [_drive(p) for p in record.plugins],
        "sensors": _sensors(record.sensors, tree, topics),
        "topics": [t.to_dict() for t in topics],
    }


def _body_poses(
    model: mujoco.MjModel, qpos: np.ndarray, mocap_pos: np.ndarray, mocap_quat: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """World positions (nbody×3) and quaternions w,x,y,z (nbody×4) of every body at `qpos`."""
    scratch = mujoco.MjData(model)
    scratch.qpos[:], scratch.mocap_pos[:], scratch.mocap_quat[:] = qpos, mocap_pos, mocap_quat
    mujoco.mj_kinematics(model, scratch)
    return scratch.xpos.copy(), scratch.xquat.copy()


def _frames(tree: EntityTree, xpos: np.ndarray, xquat: np.ndarray) -> dict[str, dict[str, Any]]:
    """Each tf frame of the entity: its parent frame, whether it moves, its world pose."""
    out: dict[str, dict[str, Any]] = {}
    for edge in tree.edges:
        for frame, anchor, parent in (
            (edge.parent, edge.parent_anchor, None),
            (edge.child, edge.child_anchor, edge.parent),
        ):
            if frame == WORLD_FRAME or (parent is None and frame in out):
                continue
            entry = out.setdefault(frame, {"parent": parent, "moving": edge.moving})
            if parent is not None:
                entry["parent"], entry["moving"] = parent, edge.moving
            entry["pose"] = _world_pose(anchor, xpos, xquat)
    return out


def _world_pose(anchor: Anchor, xpos: np.ndarray, xquat: np.ndarray) -> dict[str, Any]:
    """A frame's world pose: its body's pose composed with the frame's pose in the body;
    `quat` is x, y, z, w (geometry_msgs order)."""
    body = ((*xpos[anchor.body].tolist(),), (*xquat[anchor.body].tolist(),))
    (x, y, z), (w, qx, qy, qz) = compose(body, anchor.pose)
    return {**Pose.from_quat(x, y, z, (w, qx, qy, qz)).to_dict(), "quat": [qx, qy, qz, w]}


def _joints(
    model: mujoco.MjModel, joints: np.ndarray, name: str, states: list, commands: dict
) -> list[dict[str, Any]]:
    """Each joint but the free one: type, limits, state, and for actuated ones the command
    mode held and the modes offered."""
    prefix, out = f"{name}/", []
    state_of = {s.name: s for s in states}
    for j, full in zip(
        joints.tolist(), element_names(model, model.name_jntadr[joints]), strict=True
    ):
        joint = full.removeprefix(prefix)
        if joint not in state_of:
            continue
        s, command = state_of[joint], commands.get(joint, {})
        limited = bool(model.jnt_limited[j])
        out.append(
            {
                "name": joint,
                "type": JOINT_TYPES.get(int(model.jnt_type[j]), "unknown"),
                "limits": model.jnt_range[j].tolist() if limited else None,
                "position": s.position,
                "velocity": s.velocity,
                "effort": s.effort,
                "actuated": bool(command),
                "mode": command.get("mode"),
                "target": command.get("target"),
                "modes": list(command.get("modes") or []),
            }
        )
    return out


def _drive(plugin: Any) -> dict[str, Any]:
    """A drive plugin's record as plain values, with its kind (the record's class)."""
    import dataclasses

    is_record = dataclasses.is_dataclass(plugin) and not isinstance(plugin, type)
    fields = dataclasses.asdict(plugin) if is_record else {}
    return {"kind": type(plugin).__name__, **{k: _jsonable(v) for k, v in fields.items()}}


def _jsonable(value: Any) -> Any:
    if isinstance(value, tuple | list):
        return [_jsonable(v) for v in value]
    if isinstance(value, dict):
        return {str(k): _jsonable(v) for k, v in value.items()}
    return value if isinstance(value, str | int | float | bool | type(None)) else str(value)


def _sensors(specs: tuple, tree: EntityTree, topics: list[LiveTopic]) -> list[dict[str, Any]]:
    """`twin sensors`' description of each sensor, with the tf frame its messages name and
    the live topic they come on (`ros_topic`, `ros_type`)."""
    described = describe_sensors(list(specs))
    by_sensor = {t.sensor: t for t in topics if t.sensor}
    for entry in described:
        entry["tf_frame"] = tree.sensor_frames.get(entry["name"])
        topic = by_sensor.get(entry["name"])
        entry["ros_topic"] = topic.name if topic else None
        entry["ros_type"] = topic.type if topic else None
    return described
