"""The ROS topics of a world, as robot_state_publisher and gazebo_ros publish them, per entity.

- `/clock` rosgraph_msgs/Clock: sim time (every node of a Gazebo system runs on it).
- `/tf` tf2_msgs/TFMessage: world → each entity's root, and parent → child for every link that
  moves (a body with a joint), from the same copied qpos as `World.link_poses`, so composing
  them gives the world's link poses.
- `/tf_static`: fixed links and lumped links' frames, latched (transient local), republished
  whole whenever the set of entities changes (tf2's static broadcaster does the same).
- `/<entity>/joint_states` sensor_msgs/JointState: position, velocity, actuator effort, as
  `World.joint_states`; `/<entity>/robot_description` std_msgs/String, the URDF after xacro,
  latched; `/<entity>/odom` nav_msgs/Odometry for floating bases (pose in `world`, twist in the
  root link's frame, as ROS defines it).
Every stamp is sim time. Messages are rosbags objects; encoding is `messages.encode`.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from twin_cli.record import messages as ros
from twin_cli.record.layout import WORLD_FRAME, EntityLayout, Layout
from twin_cli.record.sampler import Sample


@dataclass(frozen=True)
class Topic:
    """A topic: its name, message type and whether late subscribers get its last message."""

    name: str
    type: str
    latched: bool = False


@dataclass(frozen=True)
class Message:
    """One message to publish: topic, type, sim time [s] and the rosbags message object."""

    topic: str
    type: str
    time: float
    message: Any


CLOCK = Topic("/clock", ros.CLOCK)
TF = Topic("/tf", ros.TF)
TF_STATIC = Topic("/tf_static", ros.TF, latched=True)


def topics(layout: Layout) -> list[Topic]:
    """Every topic of the layout's entities, world-wide ones first."""
    out = [CLOCK, TF, TF_STATIC]
    for e in layout.entities:
        out.append(Topic(f"/{e.name}/joint_states", ros.JOINT_STATE))
        if e.description:
            out.append(Topic(f"/{e.name}/robot_description", ros.STRING, latched=True))
        if e.free_qpos >= 0:
            out.append(Topic(f"/{e.name}/odom", ros.ODOMETRY))
    return out


def latched_messages(layout: Layout, time: float) -> list[Message]:
    """`/tf_static` (all entities in one message) and every `robot_description`."""
    T = ros.types()
    model, stamp = layout.model, ros.stamp(time)
    transforms = []
    for e in layout.entities:
        for b in e.fixed:
            parent = layout.body_frames[int(model.body_parentid[b])]
            transforms.append(
                _transform(
                    stamp, parent, layout.body_frames[b], model.body_pos[b].tolist(),
                    model.body_quat[b].tolist(),
                )
            )  # fmt: skip
        for s in e.sites:
            parent = layout.body_frames[int(model.site_bodyid[s])]
            transforms.append(
                _transform(
                    stamp, parent, layout.site_frames[s], model.site_pos[s].tolist(),
                    model.site_quat[s].tolist(),
                )
            )  # fmt: skip
    out = [Message(TF_STATIC.name, ros.TF, time, T[ros.TF](transforms=transforms))]
    for e in layout.entities:
        if e.description:
            text = T[ros.STRING](data=e.description)
            out.append(Message(f"/{e.name}/robot_description", ros.STRING, time, text))
    return out


def live_messages(sample: Sample, xpos: np.ndarray, xquat: np.ndarray) -> list[Message]:
    """`/clock`, `/tf`, and each entity's joint states (and odometry) at the sample's time.

    Runs for every sample of a recording (thousands per wall second when the loop is
    unthrottled, in the encoder process): one stamp object serves every header of the sample,
    and poses become Python floats in one `tolist` per entity instead of one per number.
    """
    T, t = ros.types(), sample.time
    layout = sample.layout
    stamp = ros.stamp(t)
    clock = Message(CLOCK.name, ros.CLOCK, t, T[ros.CLOCK](clock=stamp))
    transforms = []
    for e in layout.entities:
        transforms += _moving_transforms(layout, e, stamp, xpos, xquat)
    out = [clock, Message(TF.name, ros.TF, t, T[ros.TF](transforms=transforms))]
    for e in layout.entities:
        out.append(_joint_states(sample, e, stamp))
        if e.free_qpos >= 0:
            out.append(_odometry(sample, e, stamp))
    return out


def relative_poses(
    xpos: np.ndarray, xquat: np.ndarray, bodies: np.ndarray, parents: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Each body's pose in its parent's frame: p = R_parentᵀ (x − x_parent), q = q̄_parent q."""
    q_parent = xquat[parents]
    conj = q_parent * np.array([1.0, -1.0, -1.0, -1.0])
    offset = xpos[bodies] - xpos[parents]
    return _rotate(conj, offset), _quat_multiply(conj, xquat[bodies])


def _moving_transforms(
    layout: Layout, e: EntityLayout, stamp: Any, xpos: np.ndarray, xquat: np.ndarray
) -> list[Any]:
    pos, quat = relative_poses(xpos, xquat, e.moving, e.moving_parents)
    frames = layout.body_frames
    return [
        _transform(stamp, frames[p], frames[b], xyz, wxyz)
        for b, p, xyz, wxyz in zip(
            e.moving.tolist(), e.moving_parents.tolist(), pos.tolist(), quat.tolist(), strict=True
        )
    ]


def _joint_states(sample: Sample, e: EntityLayout, stamp: Any) -> Message:
    T, model = ros.types(), sample.layout.model
    qa, da = model.jnt_qposadr[e.joint_ids], model.jnt_dofadr[e.joint_ids]
    position, velocity = sample.qpos[qa].copy(), sample.qvel[da].copy()
    effort = sample.qfrc_actuator[da].copy()
    for k in e.ball_joints:  # as World.joint_states: rotation angle and angular speed
        position[k] = 2.0 * np.arccos(min(1.0, abs(float(sample.qpos[qa[k]]))))
        velocity[k] = np.linalg.norm(sample.qvel[da[k] : da[k] + 3])
        effort[k] = 0.0
    message = T[ros.JOINT_STATE](
        header=T["std_msgs/msg/Header"](stamp=stamp, frame_id=""),
        name=list(e.joint_names),
        position=position,
        velocity=velocity,
        effort=effort,
    )
    return Message(f"/{e.name}/joint_states", ros.JOINT_STATE, sample.time, message)


def _odometry(sample: Sample, e: EntityLayout, stamp: Any) -> Message:
    """Free-joint pose in the world; twist in the root frame (MuJoCo: linear qvel is global,
    angular qvel is local)."""
    T = ros.types()
    q = sample.qpos[e.free_qpos : e.free_qpos + 7]
    v = sample.qvel[e.free_dof : e.free_dof + 6]
    conj = q[3:7] * np.array([1.0, -1.0, -1.0, -1.0])
    linear = _rotate(conj[None], v[None, 0:3])[0]
    pose = T["geometry_msgs/msg/Pose"](
        position=T["geometry_msgs/msg/Point"](x=q[0], y=q[1], z=q[2]),
        orientation=_quaternion(q[3:7]),
    )
    twist = T["geometry_msgs/msg/Twist"](linear=_vector(linear), angular=_vector(v[3:6]))
    zeros = np.zeros(36)
    message = T[ros.ODOMETRY](
        header=T["std_msgs/msg/Header"](stamp=stamp, frame_id=WORLD_FRAME),
        child_frame_id=f"{e.root_frame}",
        pose=T["geometry_msgs/msg/PoseWithCovariance"](pose=pose, covariance=zeros),
        twist=T["geometry_msgs/msg/TwistWithCovariance"](twist=twist, covariance=zeros),
    )
    return Message(f"/{e.name}/odom", ros.ODOMETRY, sample.time, message)


def _transform(stamp: Any, parent: str, child: str, pos: list, quat: list) -> Any:
    """A TransformStamped from Python floats: position x, y, z and MuJoCo's w, x, y, z
    quaternion (one per moving link and sample: plain floats, no numpy indexing)."""
    T = ros.types()
    (x, y, z), (qw, qx, qy, qz) = pos, quat
    transform = T["geometry_msgs/msg/Transform"](
        translation=T["geometry_msgs/msg/Vector3"](x=x, y=y, z=z),
        rotation=T["geometry_msgs/msg/Quaternion"](x=qx, y=qy, z=qz, w=qw),
    )
    return T["geometry_msgs/msg/TransformStamped"](
        header=T["std_msgs/msg/Header"](stamp=stamp, frame_id=parent),
        child_frame_id=child,
        transform=transform,
    )


def _vector(v: np.ndarray) -> Any:
    return ros.types()["geometry_msgs/msg/Vector3"](x=float(v[0]), y=float(v[1]), z=float(v[2]))


def _quaternion(q: np.ndarray) -> Any:
    """ROS order x, y, z, w from MuJoCo's w, x, y, z."""
    w, x, y, z = (float(c) for c in q)
    return ros.types()["geometry_msgs/msg/Quaternion"](x=x, y=y, z=z, w=w)


def _quat_multiply(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Row-wise Hamilton products of (n×4) w,x,y,z quaternions."""
    aw, ax, ay, az = a.T
    bw, bx, by, bz = b.T
    return np.stack(
        [
            aw * bw - ax * bx - ay * by - az * bz,
            aw * bx + ax * bw + ay * bz - az * by,
            aw * by - ax * bz + ay * bw + az * bx,
            aw * bz + ax * by - ay * bx + az * bw,
        ],
        axis=1,
    )


def _rotate(q: np.ndarray, v: np.ndarray) -> np.ndarray:
    """Row-wise rotation of (n×3) vectors by (n×4) unit quaternions w,x,y,z."""
    w, u = q[:, :1], q[:, 1:]
    t = 2.0 * _cross(u, v)
    return v + w * t + _cross(u, t)


def _cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Row-wise cross products of (n×3) arrays (np.cross costs ~10 µs of checks per call)."""
    ax, ay, az = a[:, 0], a[:, 1], a[:, 2]
    bx, by, bz = b[:, 0], b[:, 1], b[:, 2]
    return np.stack([ay * bz - az * by, az * bx - ax * bz, ax * by - ay * bx], axis=1)
