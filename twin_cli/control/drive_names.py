"""The names a drive plugin gives its ROS interfaces: the cmd_vel topic it takes, its odometry
and tf topics and its odometry's frames, as each plugin family names them for a robot.

- gz-sim's drive systems (DiffDrive, AckermannSteering, MecanumDrive) take their twist on
  `/model/<model>/cmd_vel` (AckermannSteering's `<sub_topic>` S: `/model/<model>/S`) and publish
  odometry on `/model/<model>/odometry` and its transform on `/model/<model>/tf`, unless
  `<topic>`, `<odom_topic>` or `<tf_topic>` name another. Their transport node has no namespace,
  so a relative name is rooted at `/` (`cmd_vel` is `/cmd_vel`), and gz-transport makes a name
  valid by turning each space into `_` and dropping `@`, `~`, `:=` and a doubled or trailing
  `/`. ros_gz_bridge bridges each under the same ROS name. The odometry is in `<frame_id>`
  (default `<model>/odom`) with child `<child_frame_id>` (default `<model>/<canonical link>`);
  a name given in full is published as written. The model is the entity: gz-sim names a model
  as it is spawned, so the defaults are made from the entity's name, never the file's.
- gazebo_ros plugins, ros2_control's diff_drive_controller and vendor plugins: their names are
  relative to the entity's namespace (`/<entity>/cmd_vel`, `/<entity>/odom`), after their
  `<ros><namespace>` and remappings, as the converter read them; their frames are the
  plugin's names under the recorder's per-entity frame prefix.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

from twin_cli.names import namespace, topic_segment

GZ_PREFIX = "/model"  # gz-sim's drive systems' topics: /model/<model>/...
GZ_CMD_VEL, GZ_ODOMETRY, GZ_TF = "cmd_vel", "odometry", "tf"  # their default leaves
GZ_ODOM_FRAME = "odom"  # the default frame_id's leaf: <model>/odom


def gz_names_of(record: Any) -> Any:
    """The gz-sim names of a drive record (`converters.gazebo.gz_names.GzNames`), or None
    when it is not a gz-sim drive system."""
    return getattr(record, "gz", None)


def gz_topic(text: str) -> str:
    """A topic as a gz-sim system's transport node names it: made valid as gz-transport does
    (space → `_`; `@`, `~` and `:=` dropped; `//` → `/`; no trailing `/`) and rooted at `/`."""
    valid = text.replace(" ", "_").replace("@", "").replace("~", "").replace(":=", "")
    while "//" in valid:
        valid = valid.replace("//", "/")
    valid = valid.rstrip("/")
    return valid if valid.startswith("/") else f"/{valid}"


def gz_model_topic(entity: str, leaf: str) -> str:
    """`/model/<entity>/<leaf>`, the entity's name as one ROS topic segment."""
    return gz_topic(f"{GZ_PREFIX}/{topic_segment(entity)}/{leaf}")


def entity_topic(entity: str, topic: str) -> str:
    """A topic a gazebo_ros or ros2_control plugin names: absolute as it is, relative under the
    entity's namespace (twin's namespace for each robot)."""
    return topic if topic.startswith("/") else f"{namespace(entity)}/{topic.strip('/')}"


def cmd_vel_topic(entity: str, record: Any) -> str:
    """The topic the drive takes its twist on ("" when its plugin names none: a ros2_control
    controller, whose topics the controller's YAML names)."""
    gz = gz_names_of(record)
    if gz is not None:
        if gz.topic:
            return gz_topic(gz.topic)
        return gz_model_topic(entity, gz.sub_topic.strip("/") or GZ_CMD_VEL)
    own = getattr(record, "cmd_vel_topic", "")
    return entity_topic(entity, own) if own else ""


def odom_topic(entity: str, plugins: Sequence[object]) -> str:
    """The odometry's topic: as the first drive among the entity's plugin records names it,
    else `/<entity>/odom`."""
    for plugin in plugins:
        gz = gz_names_of(plugin)
        if gz is not None:
            return gz_topic(gz.odom_topic) if gz.odom_topic else gz_model_topic(entity, GZ_ODOMETRY)
        topic = getattr(plugin, "odom_topic", None)
        if topic:
            return entity_topic(entity, topic)
    return f"{namespace(entity)}/odom"


def tf_topic(entity: str, plugins: Sequence[object]) -> str:
    """The topic a gz-sim drive system publishes its odometry's transform on, or "" (other
    plugins put theirs on `/tf`)."""
    for plugin in plugins:
        gz = gz_names_of(plugin)
        if gz is not None:
            return gz_topic(gz.tf_topic) if gz.tf_topic else gz_model_topic(entity, GZ_TF)
    return ""


def gz_frames(entity: str, record: Any, base_link: str = "") -> tuple[str, str]:
    """(frame_id, child_frame_id) a gz-sim drive system's odometry carries: the tags as written,
    else `<entity>/odom` and `<entity>/<canonical link>` (`base_link` when given: the link the
    entity's tree is rooted at)."""
    gz = gz_names_of(record)
    link = base_link or gz.canonical_link
    return gz.frame_id or f"{entity}/{GZ_ODOM_FRAME}", gz.child_frame_id or f"{entity}/{link}"


def reply_frames(entity: str, record: Any) -> tuple[str, str]:
    """(odometry frame, base frame) as `twin odom` names them: a gz-sim system's own names for
    this entity, else the plugin's names as it gives them (no prefix: it has none)."""
    if gz_names_of(record) is not None:
        return gz_frames(entity, record)
    return record.odometry_frame, record.robot_base_frame
