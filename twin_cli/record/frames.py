"""The tf tree of an entity, as robot_state_publisher and gazebo_ros publish it for its URDF.

Frames are `<prefix><link>`; the prefix is a template (`{entity}` is the entity's name), by
default `{entity}/` (robot_state_publisher's `frame_prefix`, one namespace per entity), set by
the recorders' `frame_prefix` argument or the `TWIN_FRAME_PREFIX` environment variable ("" for
none). Every link of the URDF is a frame, under its URDF parent: the converter lumps links on
fixed joints into their parent body and keeps each as a site named after the link, and drops a
`world` link (the robot is welded instead), so each frame is anchored on a body of the compiled
model with a constant offset, and a `world` link is placed from its joint's origin. A joint
whose child moves against its parent (a body with a joint between them) goes on `/tf`, the
others on `/tf_static`. The root link hangs from `world` or, for a mobile base with a drive
plugin, from the plugin's odometry frame (REP 105), itself fixed at `world` (the plugin's
odometry source is the world pose). Entities without a URDF (MJCF, SDF) follow their model's
body tree, sites as fixed frames. Sensor sites are frames only when a message names them.

The prefix is applied once. A gazebo_ros plugin's odometry frame (`odom`) is one of the robot's
names and gets it (`bot/odom`). A gz-sim drive system names its frames in full: `<frame_id>` and
`<child_frame_id>` are kept as written, and its defaults `<model>/odom` and
`<model>/<canonical link>` are the prefix's own form (`{entity}/`), so they are made as
`<prefix>odom` and the root link's frame: exactly gz-sim's names with the default prefix, and
the same frames as `/tf` with any other.
"""

from __future__ import annotations

import math
import os
import xml.etree.ElementTree as ET
from collections.abc import Sequence
from dataclasses import dataclass
from functools import lru_cache
from typing import TYPE_CHECKING

from converters.gazebo.plugins import DIFF_DRIVE_FILES, DiffDrive
from twin_cli.control.drive_names import GZ_ODOM_FRAME, gz_names_of, odom_topic, tf_topic
from twin_cli.names import namespace

if TYPE_CHECKING:
    from twin_cli.world.engine import World

WORLD_FRAME = "world"  # gazebo_ros and Gazebo's own frame name for the world
DEFAULT_PREFIX = "{entity}/"
PREFIX_ENV = "TWIN_FRAME_PREFIX"
SENSOR_SITE = "sensor:"  # the converter's site at a sensor's frame (`sensor:<name>`)
# gazebo_ros_diff_drive's parameters (ROS 2 spelling first, then ROS 1) and its defaults
ODOMETRY_FRAME_TAGS = ("odometry_frame", "odometryFrame")
BASE_FRAME_TAGS = ("robot_base_frame", "robotBaseFrame")
DEFAULT_ODOMETRY_FRAME, DEFAULT_BASE_FRAME = "odom", "base_footprint"

Pose = tuple[tuple[float, float, float], tuple[float, float, float, float]]  # xyz, wxyz
IDENTITY: Pose = ((0.0, 0.0, 0.0), (1.0, 0.0, 0.0, 0.0))


def prefix_template(template: str | None = None) -> str:
    """The frame prefix template: `template`, else `TWIN_FRAME_PREFIX`, else `{entity}/`."""
    return os.environ.get(PREFIX_ENV, DEFAULT_PREFIX) if template is None else template


@dataclass(frozen=True)
class SensorFrame:
    """What names a sensor's frame: its link, its plugin's frame name (else the link) and
    whether it sits at the link's origin (no `<pose>`)."""

    name: str
    link: str
    frame_id: str
    at_link: bool


@dataclass(frozen=True)
class Sources:
    """What an entity's frames are named from (picklable: sent to the encoder process).

    Attributes:
        prefix: the frame prefix of its links (the template filled in).
        description: URDF text after xacro, or None (the model's body tree is used).
        drive: (odometry frame, odometry's child frame) of its drive plugin in full, the child
            "" for the root link's frame; or None (no drive).
        sensors: its sensors' frames.
        odom_topic: its odometry's topic (`odom_topic`), or "" (`/<entity>/odom`).
        tf_topic: the topic its drive publishes the odometry's transform on, or "" (none).
    """

    prefix: str
    description: str | None = None
    drive: tuple[str, str] | None = None
    sensors: tuple[SensorFrame, ...] = ()
    odom_topic: str = ""
    tf_topic: str = ""


def sources_of(world: World, name: str, template: str, description: str | None) -> Sources:
    """The sources of entity `name` (call with the world's lock held); `description` overrides
    the URDF the world kept."""
    record = world.entity(name)
    text = description if description is not None else record.description
    sensors = tuple(
        SensorFrame(s.name, s.link, s.frame_id, not any(s.pose)) for s in record.sensors
    )
    prefix = template.replace("{entity}", name)
    return Sources(
        prefix, text, odometry_frames(record.plugins, text, prefix), sensors,
        odom_topic(name, record.plugins), tf_topic(name, record.plugins),
    )  # fmt: skip


def odometry_frames(
    plugins: Sequence[object], description: str | None, prefix: str
) -> tuple[str, str] | None:
    """(odometry frame, child frame) of the first drive among an entity's plugin records, in
    full (the child "" for the root link's frame), or None: a gz-sim system's as the module
    docstring says, another plugin's odometry frame under `prefix`."""
    for plugin in plugins:
        gz = gz_names_of(plugin)
        if gz is not None:
            return gz.frame_id or prefix + GZ_ODOM_FRAME, gz.child_frame_id
    frames = record_frames(plugins)
    if any(isinstance(p, DiffDrive) and p.family == "gazebo_ros_diff_drive" for p in plugins):
        frames = drive_frames(description)
    return None if frames is None else (prefix + frames[0], "")


def unique_odom_topics(topics: dict[str, str]) -> dict[str, str]:
    """Each entity's odometry topic (entity → topic, in spawn order); a topic an earlier entity
    already publishes (two robots from one file with a fixed namespace) becomes the later
    entity's `/<entity>/odom`, so no two entities write one topic."""
    seen: set[str] = set()
    out: dict[str, str] = {}
    for name, topic in topics.items():
        out[name] = topic if topic not in seen else f"{namespace(name)}/odom"
        seen.add(out[name])
    return out


def record_frames(plugins: Sequence[object]) -> tuple[str, str] | None:
    """(odometry frame, base frame) of the first drive among an entity's plugin records (every
    drive family names them: `converters.gazebo.drive_records`), or None."""
    for plugin in plugins:
        odom, base = (
            getattr(plugin, "odometry_frame", None),
            getattr(plugin, "robot_base_frame", None),
        )
        if odom and base:
            return odom.strip("/"), base.strip("/")
    return None


@lru_cache(maxsize=64)
def drive_frames(description: str | None) -> tuple[str, str]:
    """(odometry frame, base frame) of the URDF's diff-drive plugin, else the plugin's
    defaults."""
    odom, base = DEFAULT_ODOMETRY_FRAME, DEFAULT_BASE_FRAME
    try:
        root = ET.fromstring(description) if description else None
    except ET.ParseError:
        root = None
    for plugin in () if root is None else root.iter("plugin"):
        if (plugin.get("filename") or "").rsplit("/", 1)[-1] in DIFF_DRIVE_FILES:
            odom = _first_text(plugin, ODOMETRY_FRAME_TAGS) or odom
            base = _first_text(plugin, BASE_FRAME_TAGS) or base
            break
    return odom, base


def _first_text(el: ET.Element, tags: Sequence[str]) -> str:
    for tag in tags:
        text = (el.findtext(tag) or "").strip().strip("/")
        if text:
            return text
    return ""


@dataclass(frozen=True)
class UrdfJoint:
    """A URDF joint as tf sees it: parent and child links, fixed or not, origin (xyz, wxyz)."""

    parent: str
    child: str
    fixed: bool
    origin: Pose


@lru_cache(maxsize=64)
def urdf_tree(text: str) -> tuple[tuple[str, ...], tuple[UrdfJoint, ...]] | None:
    """The links and joints of a URDF text, or None if it is not a URDF."""
    try:
        root = ET.fromstring(text)
    except ET.ParseError:
        return None
    if root.tag != "robot":
        return None
    links = tuple(el.get("name", "") for el in root.findall("link"))
    joints = []
    for el in root.findall("joint"):
        parent, child = el.find("parent"), el.find("child")
        if parent is None or child is None:
            continue
        joints.append(
            UrdfJoint(
                parent.get("link", ""), child.get("link", ""), el.get("type") == "fixed",
                _origin(el.find("origin")),
            )
        )  # fmt: skip
    return links, tuple(joints)


def _origin(el: ET.Element | None) -> Pose:
    """A URDF `<origin>`: xyz and the quaternion of its fixed-axis roll, pitch, yaw."""
    if el is None:
        return IDENTITY
    x, y, z = (float(v) for v in (el.get("xyz") or "0 0 0").split())
    roll, pitch, yaw = (float(v) / 2.0 for v in (el.get("rpy") or "0 0 0").split())
    cr, sr, cp, sp = math.cos(roll), math.sin(roll), math.cos(pitch), math.sin(pitch)
    cy, sy = math.cos(yaw), math.sin(yaw)
    quat = (
        cr * cp * cy + sr * sp * sy,
        sr * cp * cy - cr * sp * sy,
        cr * sp * cy + sr * cp * sy,
        cr * cp * sy - sr * sp * cy,
    )
    return (x, y, z), quat


def sensor_frame(sensor: SensorFrame, links: dict[str, str], prefix: str) -> str:
    """The frame a sensor's messages name: the link its plugin names; else the link it is on,
    when it sits at the link's origin; else its own frame (then published in tf)."""
    if sensor.frame_id != sensor.link and sensor.frame_id in links:
        return links[sensor.frame_id]
    if sensor.at_link and sensor.link in links:
        return links[sensor.link]
    return own_sensor_frame(sensor, links, prefix)


def own_sensor_frame(sensor: SensorFrame, links: dict[str, str], prefix: str) -> str:
    """A sensor's own frame: its plugin's frame name, else `sensor:<name>`, prefixed."""
    named = sensor.frame_id != sensor.link and sensor.frame_id not in links
    return prefix + (sensor.frame_id if named else SENSOR_SITE + sensor.name)
