"""The ROS topics of a world, as robot_state_publisher and gazebo_ros publish them, per entity.

- `/clock` rosgraph_msgs/Clock: sim time (every node of a Gazebo system runs on it).
- `/tf` tf2_msgs/TFMessage: world (or a mobile base's odometry frame) → each entity's root, and
  parent → child for every URDF joint that moves, from the same copied qpos as
  `World.link_poses`, so composing them gives the world's link poses (`frames`: the tree).
- `/tf_static`: fixed joints (lumped links too), latched (transient local), republished whole
  whenever the set of entities changes (tf2's static broadcaster does the same).
- `/<entity>/joint_states` sensor_msgs/JointState: position, velocity, actuator effort, as
  `World.joint_states`, for an entity with a joint (a free body's are empty, as
  joint_state_publisher's for a URDF without movable joints; a static model has none);
  `/<entity>/robot_description` std_msgs/String, the URDF after xacro, latched;
  `/<entity>/odom` (or the name its drive gives it: gz-sim's `/model/<entity>/odometry`)
  nav_msgs/Odometry for floating bases (pose in `world` or the drive's odometry frame, twist
  in the root link's frame, as ROS defines it); a gz-sim drive system's `/model/<entity>/tf`
  (or its `<tf_topic>`) tf2_msgs/TFMessage, the odometry's one transform, as ros_gz_bridge
  hands on the system's Pose_V.
Every stamp is sim time. Messages are rosbags objects; `Message.cdr` encodes them. This
module names the topics and builds the latched messages; `live_messages` refills the per-sample
ones.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from twin_cli.names import namespace
from twin_cli.record import messages as ros
from twin_cli.record.layout import EntityLayout, Layout


@dataclass(frozen=True)
class Topic:
    """A topic: its name, message type and whether late subscribers get its last message."""

    name: str
    type: str
    latched: bool = False


@dataclass(frozen=True)
class Message:
    """One message to publish: topic, type, sim time [s] and the rosbags message object (with
    its `ros.Reencoder` when the object is refilled and re-sent: the live messages)."""

    topic: str
    type: str
    time: float
    message: Any
    reencoder: ros.Reencoder | None = None

    def cdr(self) -> bytes:
        """The message's CDR bytes."""
        if self.reencoder is not None:
            return self.reencoder()
        return ros.encode(self.message, self.type)


CLOCK = Topic("/clock", ros.CLOCK)
TF = Topic("/tf", ros.TF)
TF_STATIC = Topic("/tf_static", ros.TF, latched=True)


def topics(layout: Layout) -> list[Topic]:
    """Every topic of the layout's entities, world-wide ones first."""
    out = [CLOCK, TF, TF_STATIC]
    for e in layout.entities:
        if moves(e):
            out.append(Topic(f"{namespace(e.name)}/joint_states", ros.JOINT_STATE))
        if e.description:
            out.append(Topic(f"{namespace(e.name)}/robot_description", ros.STRING, latched=True))
        if e.free_qpos >= 0:
            out.append(Topic(e.odom_topic, ros.ODOMETRY))
        if e.free_qpos >= 0 and e.tf_topic:
            out.append(Topic(e.tf_topic, ros.TF))
    return out


def moves(e: EntityLayout) -> bool:
    """Whether the entity has a joint (a free joint too): one without is static or welded, and
    has no joint_states."""
    return bool(e.joint_names) or e.free_qpos >= 0


def latched_messages(layout: Layout, time: float) -> list[Message]:
    """`/tf_static` (all entities in one message; none while no entity has a fixed frame: an
    empty one would be the last a late subscriber gets) and every `robot_description`."""
    T = ros.types()
    stamp = ros.stamp(time)
    transforms = [
        transform_stamped(stamp, parent, child, list(pos), list(quat))
        for parent, child, (pos, quat) in layout.static
    ]
    out = []
    if transforms:
        out.append(Message(TF_STATIC.name, ros.TF, time, T[ros.TF](transforms=transforms)))
    for e in layout.entities:
        if e.description:
            text = T[ros.STRING](data=e.description)
            out.append(Message(f"{namespace(e.name)}/robot_description", ros.STRING, time, text))
    return out


def transform_stamped(stamp: Any, parent: str, child: str, pos: list, quat: list) -> Any:
    """A TransformStamped from `parent` to `child`: position x, y, z and MuJoCo's w, x, y, z
    quaternion, as Python floats."""
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
